//! The scaled agent's parameters by name: one table, generated with the parameter groups
//! of [`ScaledParams`] from their one declaration (the macros of [`crate::param_decl`],
//! used in [`crate::params`]). Each field is declared once with its
//! key, its type and its range; the struct, its serde names, its setter by key, its
//! getter and the range checks of [`ScaledParams::check`] all come from that line, so a
//! field added to a group is listed, read, set and checked by name with no other edit.
//!
//! A key is a field's serialized name (`epsilon`, `horizon`, `scaling_mode`), or
//! `group.key` (`gate.epsilon`), or an alias of [`ALIASES`]. Two entry points set a
//! parameter: [`ScaledParams::set_str`] takes the text of `--set key=value`,
//! [`ScaledParams::set`] a typed [`ParamValue`] (keyword arguments of other front ends).
//! Both find the field by key, read the value as the field's type ([`Kind`](crate::param_decl::Kind): a number, a
//! whole number, a switch, one of an enum's names, a name), check it against the field's
//! declared range ([`Rule`](crate::param_decl::Rule): a [`Bound`](crate::param_decl::Bound) or a [`NameRule`](crate::param_decl::NameRule)) and assign that one field;
//! nothing is serialized. An unknown key or a bad value is a [`SetError`] naming the key,
//! the value and what is allowed (the declared range or the enum's names), and leaves the
//! parameters unchanged.
//!
//! ```
//! use unforeseen_agent::param_decl::ParamValue;
//! use unforeseen_agent::params::{ScaledParams, ScalingMode};
//! let mut p = ScaledParams::default();
//! p.set_str("scaling_mode", "closed-form").unwrap();
//! p.set("gate.epsilon", ParamValue::Number(0.1)).unwrap();
//! assert_eq!(p.scaling.scaling_mode, ScalingMode::ClosedForm);
//! assert_eq!(p.get("epsilon").unwrap(), ParamValue::Number(0.1));
//! assert!(p.set_str("horizon", "9").unwrap_err().to_string().contains("1..=8"));
//! ```

use std::sync::OnceLock;

use crate::error::SetError;
use crate::param_decl::{Given, Key, ParamValue};
use crate::params::ScaledParams;

/// Keys accepted besides the table's: `(alias, key)`. `sample=true|false` is
/// `action_selection=sample|outcome-mode` (the default mode).
pub const ALIASES: &[(&str, &str)] = &[("sample", "action_selection")];

/// Every parameter, sorted by group, then by key.
pub fn keys() -> &'static [Key] {
    static KEYS: OnceLock<Vec<Key>> = OnceLock::new();
    KEYS.get_or_init(|| {
        let mut all = ScaledParams::entries();
        all.sort_by(|a, b| (&a.group, &a.name).cmp(&(&b.group, &b.name)));
        all
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

impl ScaledParams {
    /// The value of the parameter `key` (enums by their kebab-case names).
    pub fn get(&self, key: &str) -> Result<ParamValue, SetError> {
        let k = lookup(key)?;
        self.group_get(&k.group, &k.name).ok_or_else(|| SetError::UnknownKey {
            key: key.to_string(),
            known: key_names(),
        })
    }

    /// Sets the parameter `key` to a typed value: a number or a whole number for a number,
    /// a whole number for a count, a bool for a switch, a name for an enum or a factor
    /// name (and text is read as `--set` reads it). Checks the field's declared range. On
    /// error the parameters are unchanged.
    pub fn set(&mut self, key: &str, value: ParamValue) -> Result<(), SetError> {
        self.set_given(key, Given::Value(&value), || value.to_string())
    }

    /// Sets the parameter `key` from text (`--set key=value`): a number, a whole number,
    /// `true`/`false` (also `yes`/`no`, `1`/`0`) or a name, as the field's type calls for;
    /// `inf` where a range allows it. Checks the field's declared range. On error the
    /// parameters are unchanged.
    pub fn set_str(&mut self, key: &str, text: &str) -> Result<(), SetError> {
        let text = text.trim();
        self.set_given(key, Given::Text(text), || text.to_string())
    }

    /// Sets `key` on a copy (the field's declared type and range), checks the rule between
    /// fields where `key` is the one it names, and keeps the copy only if both pass.
    fn set_given(&mut self, key: &str, given: Given<'_>, shown: impl Fn() -> String) -> Result<(), SetError> {
        let k = lookup(key)?;
        let bad = |problem: String| SetError::BadValue {
            key: key.to_string(),
            value: shown(),
            problem,
        };
        let mut next = self.clone();
        next.group_set(&k.group, &k.name, given)
            .ok_or_else(|| SetError::UnknownKey {
                key: key.to_string(),
                known: key_names(),
            })?
            .map_err(bad)?;
        if let Some(e) = next.cross_problem().filter(|e| e.name == k.name) {
            return Err(bad(format!("must be {}", e.expected)));
        }
        *self = next;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::param_decl::{NameRule, Rule, ValueKind};
    use crate::params::{GateMode, ScalingMode};
    use proptest::strategy::BoxedStrategy;

    /// A value of each key other than its default, as `--set` text and typed.
    fn other_value(p: &ScaledParams, key: &str) -> (String, ParamValue) {
        let k = lookup(key).unwrap();
        match (p.get(key).unwrap(), k.kind) {
            (ParamValue::Bool(b), _) => ((!b).to_string(), ParamValue::Bool(!b)),
            (ParamValue::Int(n), _) => {
                let x = if n == 1 { 2 } else { 1 };
                (x.to_string(), ParamValue::Int(x))
            }
            (ParamValue::Number(x), _) => {
                let x = x * 0.5;
                (x.to_string(), ParamValue::Number(x))
            }
            // Not `d` or `L`: those are pooled over by default.
            (ParamValue::Name(s), _) if key == "gate_factor" => {
                let x = if s == "v" { "p" } else { "v" };
                (x.to_string(), ParamValue::Name(x.into()))
            }
            (ParamValue::Name(_), _) if key == "persistence_ignores" => ("d".into(), ParamValue::Name("d".into())),
            (ParamValue::Name(s), ValueKind::OneOf(names)) => {
                let x = names.iter().find(|v| **v != s).unwrap().to_string();
                (x.clone(), ParamValue::Name(x))
            }
            (other, kind) => panic!("{key}: unexpected {other} of {kind:?}"),
        }
    }

    #[test]
    fn keys_are_unique_and_every_number_has_a_range() {
        let names = key_names();
        for (i, k) in names.iter().enumerate() {
            assert!(!names[..i].contains(k), "key {k} twice");
        }
        assert_eq!(names.len(), 37);
        for k in keys() {
            if matches!(k.kind, ValueKind::Number | ValueKind::Whole) {
                assert!(k.bound.is_some(), "{} has no range", k.name);
            }
        }
    }

    #[test]
    fn every_key_round_trips_as_text_and_typed() {
        for k in keys() {
            let base = ScaledParams::default();
            let (text, value) = other_value(&base, &k.name);
            let mut by_text = base.clone();
            by_text.set_str(&k.name, &text).unwrap();
            assert_ne!(by_text, base, "{} did not change", k.name);
            assert_eq!(by_text.get(&k.name).unwrap(), value, "{}", k.name);
            let mut typed = base.clone();
            typed.set(&k.dotted(), value.clone()).unwrap();
            assert_eq!(typed, by_text, "{}: typed and text differ", k.name);
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
        let e = p.set("gamma", ParamValue::Name("big".into())).unwrap_err().to_string();
        assert!(
            e.contains("gamma") && e.contains("big") && e.contains("finite and > 0"),
            "{e}"
        );
        let e = p.set_str("learning", "maybe").unwrap_err().to_string();
        assert!(e.contains("learning") && e.contains("true or false"), "{e}");
        let e = p.set_str("gate_factor", "a b").unwrap_err().to_string();
        assert!(e.contains("gate_factor") && e.contains("no spaces"), "{e}");
        let e = p.set_str("max_scaling_iters", "4294967297").unwrap_err().to_string();
        assert!(e.contains("max_scaling_iters") && e.contains("1..=10000"), "{e}");
        let e = p.set("horizon", ParamValue::Int(-1)).unwrap_err().to_string();
        assert!(e.contains("horizon") && e.contains("-1") && e.contains("1..=8"), "{e}");
        let e = p.set_str("persistence_ignores", "d+p").unwrap_err().to_string();
        assert!(
            e.contains("persistence_ignores") && e.contains("not gate_factor"),
            "{e}"
        );
        assert_eq!(p, ScaledParams::default(), "a failed set changes nothing");
        // The rule between the two names is the pooled list's: the watched factor may be
        // renamed onto a pooled one, which `check` then refuses.
        p.set_str("gate_factor", "d").unwrap();
        assert_eq!(p.check_ref().unwrap_err().name, "persistence_ignores");
    }

    #[test]
    fn spellings_of_earlier_versions_are_accepted() {
        let mut p = ScaledParams::default();
        p.set_str("sample", "true").unwrap();
        assert_eq!(p.get("action_selection").unwrap(), ParamValue::Name("sample".into()));
        p.set_str("sample", "no").unwrap();
        assert_eq!(
            p.get("action_selection").unwrap(),
            ParamValue::Name("outcome-mode".into())
        );
        p.set("sample", ParamValue::Bool(true)).unwrap();
        assert_eq!(p.get("action_selection").unwrap(), ParamValue::Name("sample".into()));
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

    /// A value to set: typed and as text, whether the key's declared type and range admit
    /// it, and what `get` returns after it is set.
    #[derive(Debug, Clone)]
    struct Case {
        value: ParamValue,
        text: String,
        admissible: bool,
        back: ParamValue,
    }

    /// Values of every type a key can have, admissible or not: numbers over the whole
    /// `f64` line and around the unit interval, counts around their ranges, switches,
    /// enums' names, factor names, and text that is none of these.
    fn cases(k: &'static Key) -> BoxedStrategy<Case> {
        use proptest::prelude::*;
        let other = "\\?[a-z]{0,6}".prop_map(|s| Case {
            value: ParamValue::Name(s.clone()),
            text: s,
            admissible: false,
            back: ParamValue::Bool(false),
        });
        let bound = k.bound;
        match k.kind {
            ValueKind::Number => {
                let b = bound.unwrap();
                let x = prop_oneof![
                    proptest::num::f64::ANY,
                    -2.0..2.0f64,
                    Just(f64::INFINITY),
                    Just(0.0),
                    Just(1.0)
                ];
                let number = x.prop_map(move |x| Case {
                    value: ParamValue::Number(x),
                    text: x.to_string(),
                    admissible: b.admits(x),
                    back: ParamValue::Number(x),
                });
                prop_oneof![4 => number, 1 => other].boxed()
            }
            ValueKind::Whole => {
                let b = bound.unwrap();
                let n = prop_oneof![-5i64..20_000, any::<i64>()];
                let whole = n.prop_map(move |n| Case {
                    value: ParamValue::Int(n),
                    text: n.to_string(),
                    admissible: b.admits(n as f64),
                    back: ParamValue::Int(n),
                });
                prop_oneof![4 => whole, 1 => other].boxed()
            }
            ValueKind::Switch => {
                let switch = any::<bool>().prop_map(|b| Case {
                    value: ParamValue::Bool(b),
                    text: b.to_string(),
                    admissible: true,
                    back: ParamValue::Bool(b),
                });
                prop_oneof![switch, other].boxed()
            }
            ValueKind::OneOf(names) => {
                let name = proptest::sample::select(names).prop_map(|n| Case {
                    value: ParamValue::Name(n.into()),
                    text: n.into(),
                    admissible: true,
                    back: ParamValue::Name(n.into()),
                });
                prop_oneof![name, other].boxed()
            }
            ValueKind::Text => {
                let list = k.range != NameRule::Factor.range();
                // A list (persistence_ignores) may not name the gate's factor: that rule
                // between two keys is not this key's range.
                let gate = match ScaledParams::default().get("gate_factor") {
                    Ok(ParamValue::Name(g)) if list => g,
                    _ => String::new(),
                };
                let name = "[A-Za-z_][a-z0-9_]{0,3}"
                    .prop_filter("`none` is the empty list", |s| s != "none")
                    .prop_filter("not the gate's factor", move |s| *s != gate);
                let names = proptest::collection::btree_set(name, 1..4);
                let good = names.prop_map(move |set| {
                    let names: Vec<String> = set.into_iter().collect();
                    let s = if list { names.join("+") } else { names[0].clone() };
                    Case {
                        value: ParamValue::Name(s.clone()),
                        text: s.clone(),
                        admissible: true,
                        back: ParamValue::Name(s),
                    }
                });
                let bad = ("[a-z]{1,3}", 0..3usize).prop_map(|(a, form)| {
                    let s = [format!("{a}+{a}"), format!("{a} x"), format!("{a}++x")][form].clone();
                    Case {
                        value: ParamValue::Name(s.clone()),
                        text: s,
                        admissible: false,
                        back: ParamValue::Bool(false),
                    }
                });
                prop_oneof![good, bad].boxed()
            }
        }
    }

    fn setting() -> impl proptest::strategy::Strategy<Value = (&'static Key, Case)> {
        use proptest::prelude::*;
        (0..keys().len()).prop_flat_map(|i| {
            let k = &keys()[i];
            cases(k).prop_map(move |c| (k, c))
        })
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config::with_cases(2000))]

        /// For every key, an admissible value (typed or as text) is set and read back; an
        /// inadmissible one is refused with an error naming the key, what is allowed (the
        /// declared range, the enum's names) and the value, and changes nothing.
        #[test]
        fn set_then_get_returns_every_admissible_value_and_refuses_the_rest((k, case) in setting()) {
            let base = ScaledParams::default();
            let (mut typed, mut text) = (base.clone(), base.clone());
            let by_value = typed.set(&k.name, case.value.clone());
            let by_text = text.set_str(&k.dotted(), &case.text);
            if case.admissible {
                by_value.unwrap();
                by_text.unwrap();
                proptest::prop_assert_eq!(typed.get(&k.name).unwrap(), case.back.clone());
                proptest::prop_assert_eq!(text.get(&k.name).unwrap(), case.back);
            } else {
                let allowed = match k.kind {
                    ValueKind::OneOf(names) => names.join(", "),
                    ValueKind::Switch => "true or false".into(),
                    _ => k.range.unwrap().to_string(),
                };
                for (e, given) in [(by_value.unwrap_err(), case.value.to_string()), (by_text.unwrap_err(), case.text)] {
                    let e = e.to_string();
                    proptest::prop_assert!(e.contains(&format!("`{}`", k.name)) || e.contains(&format!("`{}`", k.dotted())), "{}", e);
                    proptest::prop_assert!(e.contains(&allowed) && e.contains(&format!("= {given} ")), "{}", e);
                }
                proptest::prop_assert_eq!(&typed, &base);
                proptest::prop_assert_eq!(&text, &base);
            }
        }
    }

    /// The enums' declared names are the names serde reads and writes.
    #[test]
    fn declared_enum_names_are_the_serialized_names() {
        let p = ScaledParams::default();
        for k in keys() {
            let ValueKind::OneOf(names) = k.kind else { continue };
            for name in names {
                let mut q = p.clone();
                q.set_str(&k.name, name).unwrap();
                let json = serde_json::to_value(&q).unwrap();
                assert_eq!(json[&k.group][&k.name], serde_json::json!(name), "{}", k.name);
                let back: ScaledParams = serde_json::from_value(json).unwrap();
                assert_eq!(back, q);
            }
        }
    }
}
