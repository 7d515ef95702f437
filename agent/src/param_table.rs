//! The scaled agent's parameters by name: one table, derived from the serialized
//! [`ScaledParams`] (its groups and their fields), so that a field added to a group is
//! listed, read and set by name with no other edit.
//!
//! A key is a field's serialized name (`epsilon`, `horizon`, `scaling_mode`), or
//! `group.key` (`gate.epsilon`), or an alias of [`ALIASES`]. Two entry points set a
//! parameter, both through serde: [`ScaledParams::set_value`] takes a typed
//! [`serde_json::Value`] (keyword arguments of other front ends),
//! [`ScaledParams::set_str`] takes the text of `--set key=value` and turns it into the
//! value the field's current type calls for, then goes through `set_value`. Setting
//! serializes the parameters to a `serde_json::Value`, replaces the field, deserializes
//! the whole back and checks the field's range ([`ScaledParams::bounds`]); an unknown key
//! or a bad value is a [`SetError`] naming the key and what is allowed.
//!
//! ```
//! use unforeseen_agent::params::{ScaledParams, ScalingMode};
//! let mut p = ScaledParams::default();
//! p.set_str("scaling_mode", "closed-form").unwrap();
//! p.set_value("gate.epsilon", serde_json::json!(0.1)).unwrap();
//! assert_eq!(p.scaling.scaling_mode, ScalingMode::ClosedForm);
//! assert_eq!(p.get("epsilon").unwrap(), serde_json::json!(0.1));
//! assert!(p.set_str("horizon", "9").unwrap_err().to_string().contains("1..=8"));
//! ```

use std::sync::OnceLock;

use serde_json::Value;

use crate::error::SetError;
use crate::params::{Bound, ScaledParams};

/// One parameter of the table: the group it belongs to (a field of [`ScaledParams`]) and
/// its key (the group's field, as serialized).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Key {
    /// The group, e.g. `gate`.
    pub group: String,
    /// The key, e.g. `epsilon`.
    pub name: String,
}

impl Key {
    /// `group.key`, e.g. `gate.epsilon`.
    pub fn dotted(&self) -> String {
        format!("{}.{}", self.group, self.name)
    }
}

/// Keys accepted besides the table's: `(alias, key)`. `sample=true|false` is
/// `action_selection=sample|outcome-mode` (the default mode).
pub const ALIASES: &[(&str, &str)] = &[("sample", "action_selection")];

fn tree(p: &ScaledParams) -> Value {
    serde_json::to_value(p).unwrap_or(Value::Null)
}

/// Every parameter, sorted by group, then by key (the order of the serialized object).
pub fn keys() -> &'static [Key] {
    static KEYS: OnceLock<Vec<Key>> = OnceLock::new();
    KEYS.get_or_init(|| {
        let Value::Object(groups) = tree(&ScaledParams::default()) else {
            return Vec::new();
        };
        groups
            .iter()
            .flat_map(|(group, fields)| {
                fields.as_object().into_iter().flatten().map(move |(name, _)| Key {
                    group: group.clone(),
                    name: name.clone(),
                })
            })
            .collect()
    })
}

/// Every key (flat), in the order of [`keys`]: what `--set` and error messages list.
pub fn key_names() -> Vec<&'static str> {
    keys().iter().map(|k| k.name.as_str()).collect()
}

/// The parameter `key` names (flat, dotted or an alias).
pub fn lookup(key: &str) -> Result<&'static Key, SetError> {
    let k = key.trim();
    let k = ALIASES.iter().find(|(a, _)| *a == k).map_or(k, |(_, to)| *to);
    let found = match k.split_once('.') {
        Some((g, n)) => keys().iter().find(|x| x.group == g && x.name == n),
        None => keys().iter().find(|x| x.name == k),
    };
    found.ok_or_else(|| SetError::UnknownKey {
        key: key.to_string(),
        known: key_names(),
    })
}

fn shown(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        other => other.to_string(),
    }
}

impl ScaledParams {
    /// The value of the parameter `key`, as serialized (enums by their kebab-case names).
    pub fn get(&self, key: &str) -> Result<Value, SetError> {
        let k = lookup(key)?;
        Ok(tree(self)[&k.group][&k.name].clone())
    }

    /// Sets the parameter `key` to `value` (the value's JSON type must fit the field:
    /// a number for a number, a string for an enum or a name, a bool for a switch), then
    /// checks the field's range. On error the parameters are unchanged.
    pub fn set_value(&mut self, key: &str, value: Value) -> Result<(), SetError> {
        let k = lookup(key)?;
        let bad = |problem: String| SetError::BadValue {
            key: key.to_string(),
            value: shown(&value),
            problem,
        };
        let bound = ScaledParams::bound_of(&k.name);
        if let (Some(b), Some(x)) = (bound, value.as_f64())
            && !b.admits(x)
        {
            return Err(bad(format!("must be {}", b.expected())));
        }
        let mut t = tree(self);
        let was = t[&k.group][&k.name].clone();
        t[&k.group][&k.name] = value.clone();
        let next: ScaledParams = match serde_json::from_value(t) {
            Ok(next) => next,
            Err(e) => {
                let msg = e.to_string();
                let problem = if msg.contains("unknown variant") {
                    format!("must be one of: {}", self.variants(k, &msg).join(", "))
                } else if was.is_boolean() {
                    "must be true or false".to_string()
                } else if let Some(b) = bound {
                    format!("{msg}; must be {}", b.expected())
                } else {
                    msg
                };
                return Err(bad(problem));
            }
        };
        if let Some(e) = next.problems().into_iter().find(|e| e.name == k.name) {
            return Err(bad(format!("must be {}", e.expected)));
        }
        *self = next;
        Ok(())
    }

    /// Sets the parameter `key` from text (`--set key=value`): a number, a whole number,
    /// `true`/`false` (also `yes`/`no`, `1`/`0`) or a name, as the field's type calls for;
    /// `inf` where a range allows it. Then as [`ScaledParams::set_value`].
    pub fn set_str(&mut self, key: &str, text: &str) -> Result<(), SetError> {
        let text = text.trim();
        let k = lookup(key)?;
        let bad = |what: &str| {
            let range = ScaledParams::bound_of(&k.name).map_or("", Bound::expected);
            SetError::BadValue {
                key: key.to_string(),
                value: text.to_string(),
                problem: format!("'{text}' is not {what}; must be {range}"),
            }
        };
        let value = match self.get(key)? {
            Value::Bool(_) => match text.to_ascii_lowercase().as_str() {
                "true" | "yes" | "1" => Value::Bool(true),
                "false" | "no" | "0" => Value::Bool(false),
                _ => Value::String(text.to_string()),
            },
            Value::Number(n) if n.is_u64() => match text.parse::<u64>() {
                Ok(x) => Value::from(x),
                Err(_) => return Err(bad("a whole number")),
            },
            Value::Number(_) => match text.parse::<f64>() {
                Ok(x) if x.is_finite() => Value::from(x),
                // JSON has no infinity: a field that admits one reads it from text.
                Ok(_) => Value::String(text.to_string()),
                Err(_) => return Err(bad("a number")),
            },
            _ => Value::String(text.to_string()),
        };
        self.set_value(key, value)
    }

    /// The values an enum parameter admits, by their canonical names: the names serde's
    /// error lists, each read and written back (so aliases collapse into their variant).
    fn variants(&self, k: &Key, msg: &str) -> Vec<String> {
        let Some((_, list)) = msg.split_once("expected") else {
            return Vec::new();
        };
        let mut out: Vec<String> = Vec::new();
        for name in list.split('`').skip(1).step_by(2) {
            let mut t = tree(self);
            t[&k.group][&k.name] = Value::String(name.to_string());
            if let Ok(p) = serde_json::from_value::<ScaledParams>(t)
                && let Some(s) = tree(&p)[&k.group][&k.name].as_str()
                && !out.iter().any(|o| o == s)
            {
                out.push(s.to_string());
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{GateMode, ScalingMode};
    use serde_json::json;

    /// A value of each key other than its default, as `--set` text and as JSON.
    fn other_value(p: &ScaledParams, key: &str) -> (String, Value) {
        match p.get(key).unwrap() {
            Value::Bool(b) => ((!b).to_string(), Value::Bool(!b)),
            Value::Number(n) if n.is_u64() => {
                let x = if n.as_u64() == Some(1) { 2 } else { 1 };
                (x.to_string(), json!(x))
            }
            Value::Number(n) => {
                let x = n.as_f64().unwrap() * 0.5;
                (x.to_string(), json!(x))
            }
            // Not `d` or `L`: those are pooled over by default.
            Value::String(s) if key == "gate_factor" => {
                let x = if s == "v" { "p" } else { "v" };
                (x.to_string(), json!(x))
            }
            Value::String(_) if key == "persistence_ignores" => ("d".into(), json!("d")),
            Value::String(s) => {
                // An enum: its other variant, from the allowed values the error lists.
                let err = p.clone().set_str(key, "no-such-value").unwrap_err().to_string();
                let list = err.split("one of: ").nth(1).unwrap().to_string();
                let x = list.split(", ").find(|v| *v != s).unwrap().to_string();
                (x.clone(), json!(x))
            }
            other => panic!("{key}: unexpected {other}"),
        }
    }

    #[test]
    fn keys_are_unique_and_every_number_has_a_range() {
        let names = key_names();
        for (i, k) in names.iter().enumerate() {
            assert!(!names[..i].contains(k), "key {k} twice");
        }
        assert_eq!(names.len(), 35);
        let p = ScaledParams::default();
        for k in keys() {
            if p.get(&k.name).unwrap().is_number() {
                assert!(ScaledParams::bound_of(&k.name).is_some(), "{} has no range", k.name);
            }
        }
        for (k, _, _) in p.bounds() {
            assert!(names.contains(&k), "range of unknown key {k}");
        }
    }

    #[test]
    fn every_key_round_trips_as_text_and_as_json() {
        for k in keys() {
            let base = ScaledParams::default();
            let (text, value) = other_value(&base, &k.name);
            let mut by_text = base.clone();
            by_text.set_str(&k.name, &text).unwrap();
            assert_ne!(by_text, base, "{} did not change", k.name);
            assert_eq!(by_text.get(&k.name).unwrap(), value, "{}", k.name);
            let mut by_json = base.clone();
            by_json.set_value(&k.dotted(), value.clone()).unwrap();
            assert_eq!(by_json, by_text, "{}: JSON and text differ", k.name);
            by_text.check_ref().unwrap();
        }
    }

    #[test]
    fn unknown_keys_and_bad_values_name_key_and_allowed_values() {
        let mut p = ScaledParams::default();
        let e = p.set_str("colour", "red").unwrap_err().to_string();
        assert!(
            e.contains("colour") && e.contains("omega") && e.contains("scaling_mode"),
            "{e}"
        );
        let e = p.set_str("scaling_mode", "closed").unwrap_err().to_string();
        assert!(
            e.contains("scaling_mode") && e.contains("iterative, closed-form"),
            "{e}"
        );
        let e = p.set_str("horizon", "9").unwrap_err().to_string();
        assert!(
            e.contains("horizon") && e.contains("1..=8") && e.contains("policies"),
            "{e}"
        );
        let e = p.set_str("horizon", "two").unwrap_err().to_string();
        assert!(
            e.contains("horizon") && e.contains("whole number") && e.contains("1..=8"),
            "{e}"
        );
        let e = p.set_str("omega", "inf").unwrap_err().to_string();
        assert!(e.contains("omega") && e.contains("finite and > 0"), "{e}");
        let e = p.set_value("gamma", json!("big")).unwrap_err().to_string();
        assert!(e.contains("gamma") && e.contains("finite and > 0"), "{e}");
        let e = p.set_str("learning", "maybe").unwrap_err().to_string();
        assert!(e.contains("learning") && e.contains("true or false"), "{e}");
        let e = p.set_str("gate_factor", "a b").unwrap_err().to_string();
        assert!(e.contains("gate_factor") && e.contains("no spaces"), "{e}");
        let e = p.set_str("max_scaling_iters", "4294967297").unwrap_err().to_string();
        assert!(e.contains("max_scaling_iters") && e.contains("1..=10000"), "{e}");
        assert_eq!(p, ScaledParams::default(), "a failed set changes nothing");
    }

    #[test]
    fn spellings_of_earlier_versions_are_accepted() {
        let mut p = ScaledParams::default();
        p.set_str("sample", "true").unwrap();
        assert_eq!(p.get("action_selection").unwrap(), json!("sample"));
        p.set_str("sample", "no").unwrap();
        assert_eq!(p.get("action_selection").unwrap(), json!("outcome-mode"));
        p.set_str("gate", "one-step").unwrap();
        assert_eq!(p.gate.mode, GateMode::OneStep);
        p.set_str("persistence_ignores", "none").unwrap();
        assert_eq!(p.planning.persistence_ignores, "");
        p.set_str("gate_memory", "inf").unwrap();
        assert_eq!(p.gate.gate_memory, f64::INFINITY);
        p.set_str("omega", "0.3").unwrap();
        assert_eq!(p.gate.gate_memory, f64::INFINITY, "inf survives setting another key");
        p.set_str("gate_memory", "20").unwrap();
        assert_eq!(p.gate.gate_memory, 20.0);
        p.set_str("scaling.scaling_mode", "closed-form").unwrap();
        assert_eq!(p.scaling.scaling_mode, ScalingMode::ClosedForm);
        // Numbers keep their bits through text (as `--set` parsed them before).
        p.set_str("epsilon", "0.1").unwrap();
        assert_eq!(p.gate.epsilon.to_bits(), "0.1".parse::<f64>().unwrap().to_bits());
    }
}
