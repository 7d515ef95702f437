//! `--set KEY=VALUE` overrides of the scaled agent's parameters, used by the commands
//! and by sweeps ([`crate::runs::batch::sweep()`]). Keys and values go through the agent's one
//! table of parameters ([`unforeseen_agent::param_table`]): every field of
//! [`ScaledParams`] is a key (flat, e.g. `epsilon`, or dotted, e.g. `gate.epsilon`). A bad
//! key or value is an [`Error::Override`] naming the setting and what is allowed (an
//! enum's values, a number's range and its reason); the command line spells the setting
//! as its flag, `--set`.

use unforeseen_agent::error::SetError;
use unforeseen_agent::param_decl::ParamValue;
use unforeseen_agent::param_table;
use unforeseen_agent::params::ScaledParams;
use unforeseen_sim::Map;

use crate::error::Error;

/// The keys `--set` accepts, sorted by group, then key (derived from [`ScaledParams`]'s fields).
pub fn keys() -> Vec<&'static str> {
    param_table::key_names()
}

/// The help text of `--set`: the keys, grouped, with their defaults.
pub fn help() -> String {
    let p = ScaledParams::default();
    let mut groups: Vec<(String, Vec<String>)> = Vec::new();
    for k in param_table::keys() {
        let shown = match p.get(&k.name) {
            Ok(ParamValue::Name(s)) => format!("{}={s:?}", k.name),
            Ok(v) => format!("{}={v}", k.name),
            Err(_) => k.name.clone(),
        };
        match groups.iter_mut().find(|(g, _)| *g == k.group) {
            Some((_, list)) => list.push(shown),
            None => groups.push((k.group.clone(), vec![shown])),
        }
    }
    let lines: Vec<String> = groups
        .iter()
        .map(|(g, list)| format!("{g}: {}", list.join(", ")))
        .collect();
    format!(
        "Scaled-agent parameter overrides, e.g. `--set omega=0.3 --set horizon=2` or `--set gate.epsilon=0.1` \
         (ranges: agent/src/params.rs). Keys and defaults by group: {}. Also `sample=true|false` \
         (action_selection=sample|outcome-mode).",
        lines.join("; ")
    )
}

/// The [`Error::Override`] of a setting that [`ScaledParams::set_str`] refused.
pub fn override_error(key: &str, value: &str, e: SetError) -> Error {
    let setting = match e {
        SetError::UnknownKey { .. } => key.to_string(),
        SetError::BadValue { .. } => format!("{key}={value}"),
    };
    Error::Override {
        setting,
        problem: e.to_string(),
    }
}

/// Applies `KEY=VALUE` overrides in order, then checks the result (ranges and bounds
/// of [`ScaledParams::check`]).
pub fn apply(p: ScaledParams, sets: &[String]) -> Result<ScaledParams, Error> {
    apply_pairs(p, pairs(sets)?)
}

/// `KEY=VALUE` overrides as `(key, value)` pairs; a setting without `=` is an error
/// naming it and the keys.
pub fn pairs(sets: &[String]) -> Result<Vec<(&str, &str)>, Error> {
    sets.iter()
        .map(|set| {
            let (key, value) = set.split_once('=').ok_or_else(|| {
                Error::flag(
                    format!("--set {set}"),
                    format!(
                        "expected KEY=VALUE, e.g. --set omega=0.425 (keys: {})",
                        keys().join(", ")
                    ),
                )
            })?;
            Ok((key.trim(), value.trim()))
        })
        .collect()
}

/// Applies `(key, value)` overrides in order (as [`set_one`]), then checks the result
/// (ranges and bounds of [`ScaledParams::check`]).
pub fn apply_pairs<'a>(
    mut p: ScaledParams,
    pairs: impl IntoIterator<Item = (&'a str, &'a str)>,
) -> Result<ScaledParams, Error> {
    for (key, value) in pairs {
        set_one(&mut p, key, value)?;
    }
    p.check_ref().map_err(|e| Error::Override {
        setting: e.name.to_string(),
        problem: e.to_string(),
    })?;
    Ok(p)
}

/// The scaled agent's parameters on `map`: the defaults, then the map's own settings
/// (its `agent` section, checked when it was loaded: [`crate::maps::check_agent_settings`]),
/// then `pairs` (a run's `--set`), which win; checked as [`apply_pairs`].
pub fn on_map<'a>(map: &'a Map, pairs: impl IntoIterator<Item = (&'a str, &'a str)>) -> Result<ScaledParams, Error> {
    let own = map.agent.iter().map(|(k, v)| (k.as_str(), v.as_str()));
    apply_pairs(ScaledParams::default(), own.chain(pairs))
}

/// Sets one parameter by name (as [`ScaledParams::set_str`]).
pub fn set_one(p: &mut ScaledParams, key: &str, value: &str) -> Result<(), Error> {
    p.set_str(key, value).map_err(|e| override_error(key, value, e))
}

/// Sets one parameter by name to a typed value (as [`ScaledParams::set`]; for keyword
/// arguments of other front ends). The same checks and messages as [`set_one`].
pub fn set_value(p: &mut ScaledParams, key: &str, value: ParamValue) -> Result<(), Error> {
    let shown = value.to_string();
    p.set(key, value).map_err(|e| override_error(key, &shown, e))
}

#[cfg(test)]
mod tests {
    use super::*;
    use unforeseen_agent::params::{CompetenceRollout, GateBaseline};

    /// The defaults, then the map's settings, then the run's: the run's win, and a map
    /// without settings gives the defaults.
    #[test]
    fn a_maps_settings_lie_between_the_defaults_and_the_runs() {
        let mut map = Map::default();
        assert_eq!(on_map(&map, []).unwrap(), ScaledParams::default());
        map.agent.insert("gate_baseline".into(), "foreseen".into());
        map.agent.insert("competence_rollout".into(), "feedback".into());
        let p = on_map(&map, []).unwrap();
        assert_eq!(p.gate.gate_baseline, GateBaseline::Foreseen);
        assert_eq!(p.gate.competence_rollout, CompetenceRollout::Feedback);
        let p = on_map(&map, [("gate_baseline", "none")]).unwrap();
        assert_eq!(p.gate.gate_baseline, GateBaseline::None);
        assert_eq!(p.gate.competence_rollout, CompetenceRollout::Feedback);
        map.agent.insert("competence_commit".into(), "0".into());
        let e = on_map(&map, []).unwrap_err().to_string();
        assert!(e.contains("competence_commit"), "{e}");
    }
}
