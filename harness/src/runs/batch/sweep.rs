//! Parameter sweeps: `key=v1,v2` sets (a request's `sets`, the command line's `--set`) expanded into the cross product of
//! named parameter sets ([`ParamSet`]), checked against the scaled agent's parameters.

use serde::{Deserialize, Serialize};
use unforeseen_agent::param_table;
use unforeseen_agent::params::ScaledParams;
use unforeseen_sim::Map;

use crate::error::Error;

/// One named set of parameter overrides of a sweep (`[]` = the defaults).
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct ParamSet(pub Vec<(String, String)>);

impl ParamSet {
    /// Canonical label, e.g. `horizon=2,omega=0.2` (`default` when empty).
    pub fn label(&self) -> String {
        if self.0.is_empty() {
            "default".into()
        } else {
            self.0
                .iter()
                .map(|(k, v)| format!("{k}={v}"))
                .collect::<Vec<_>>()
                .join(",")
        }
    }
}

/// Most parameter sets one sweep may have (the cross product of its sets' lists).
pub const MAX_PARAM_SETS: usize = 10_000;

/// Expands `key=v1,v2` sets into the cross product of parameter sets, in the
/// order the options were given (the last varies fastest). Values equal after parsing
/// (`omega=0.5,5e-1`) count once, in the order of their first occurrence.
/// At most [`MAX_PARAM_SETS`] sets.
pub fn sweep(sets: &[String]) -> Result<Vec<ParamSet>, Error> {
    let mut out = vec![ParamSet(Vec::new())];
    let mut keys: Vec<&str> = Vec::new();
    for set in sets {
        // Errors name the request's field, `sets`, and the set given.
        let bad = |problem: String| Error::Request {
            field: "sets".into(),
            value: Some(set.clone()),
            problem,
        };
        let (key, values) = set
            .split_once('=')
            .ok_or_else(|| bad("expected KEY=V1,V2,..., e.g. horizon=1,2,3".into()))?;
        let key = key.trim();
        // `epsilon` and `gate.epsilon` are one parameter.
        let canonical = param_table::lookup(key).map_or(key, |k| k.name.as_str());
        if keys.contains(&canonical) {
            return Err(bad(format!(
                "`{key}` is set twice; give all its values in one set, e.g. {key}=1,2"
            )));
        }
        keys.push(canonical);
        let listed: Vec<&str> = values.split(',').map(str::trim).collect();
        if listed.iter().any(|v| v.is_empty()) {
            return Err(bad(format!(
                "an empty value; separate values by single commas, e.g. {key}=1,2"
            )));
        }
        // Equal values (after parsing: `0.5` and `5e-1`) give one parameter set, the first
        // spelling kept. A value that does not parse on its own is kept as written: the
        // error, if any, comes when the sets are applied.
        let parsed = |v: &str| {
            let mut p = ScaledParams::default();
            p.set_str(key, v).and_then(|()| p.get(key)).ok()
        };
        let mut values: Vec<&str> = Vec::new();
        let mut seen: Vec<Result<unforeseen_agent::param_decl::ParamValue, &str>> = Vec::new();
        for v in listed {
            let id = parsed(v).ok_or(v);
            if !seen.contains(&id) {
                seen.push(id);
                values.push(v);
            }
        }
        if out.len().saturating_mul(values.len()) > MAX_PARAM_SETS {
            return Err(bad(format!(
                "the sweep would have {} parameter sets (at most {MAX_PARAM_SETS}: each runs every scenario and protocol); sweep fewer values, or split the sweep over several runs",
                out.len().saturating_mul(values.len())
            )));
        }
        out = out
            .into_iter()
            .flat_map(|base| {
                values.iter().map(move |v| {
                    let mut next = base.clone();
                    next.0.push((key.to_string(), v.to_string()));
                    next
                })
            })
            .collect();
    }
    Ok(out)
}

/// [`sweep`], with every parameter set checked against the scaled agent's parameters
/// ([`ParamSet::scaled_params`]).
pub fn checked_sweep(sets: &[String]) -> Result<Vec<ParamSet>, Error> {
    let params = sweep(sets)?;
    for p in &params {
        p.scaled_params()?;
    }
    Ok(params)
}

impl ParamSet {
    /// The scaled agent's parameters with these overrides applied (checked).
    pub fn scaled_params(&self) -> Result<ScaledParams, Error> {
        crate::overrides::apply_pairs(ScaledParams::default(), self.pairs())
    }

    /// The scaled agent's parameters on `map`: its own settings, then these overrides
    /// ([`crate::overrides::on_map`]).
    pub fn on_map(&self, map: &Map) -> Result<ScaledParams, Error> {
        crate::overrides::on_map(map, self.pairs())
    }

    fn pairs(&self) -> impl Iterator<Item = (&str, &str)> {
        self.0.iter().map(|(k, v)| (k.as_str(), v.as_str()))
    }
}
