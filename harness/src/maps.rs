//! Finding a map: a file path, or the name of a map embedded in the binary
//! (`intersection`, `jaywalk`, ...), so the default run needs no files at all. Every
//! map loaded here has its expectations' names checked against this program's
//! [`Method`]s and [`Protocol`]s ([`check_expectation_names`]) and its agent settings
//! against the scaled agent's parameters ([`check_agent_settings`]).

use std::path::Path;
use unforeseen_sim::embedded::{self, LookupError};
use unforeseen_sim::{Diagnostic, EMBEDDED_PREFIX, Map, MapError};

use crate::episodes::methods::Method;
use crate::episodes::protocol::Protocol;

/// The map the jobs test on unless given one: the embedded jaywalk (the paper's
/// unforeseen event).
pub const DEFAULT_TEST_MAP: &str = "jaywalk";

/// Loads `arg` as a map file if such a path exists, else as an embedded map name
/// (with or without `.ron`), [`embedded::find`], and checks its expectations' names.
pub fn load(arg: &str) -> Result<Map, LookupError> {
    let map = embedded::find(arg)?;
    let file = if Path::new(arg).exists() {
        arg.to_string()
    } else {
        format!("{EMBEDDED_PREFIX}{}", arg.strip_suffix(".ron").unwrap_or(arg))
    };
    check_expectation_names(&map, &file)?;
    check_agent_settings(&map, &file)?;
    Ok(map)
}

/// Loads a map file ([`Map::load`]) and checks its expectations' names
/// ([`check_expectation_names`]).
pub fn load_file(path: &Path) -> Result<Map, MapError> {
    let map = Map::load(path)?;
    check_expectation_names(&map, &path.display().to_string())?;
    check_agent_settings(&map, &path.display().to_string())?;
    Ok(map)
}

/// Checks that every expectation of `map` names a method ([`Method::map_name`]) and, if
/// it names one, a protocol ([`Protocol::map_name`]) of this program. `file` names the
/// map in the diagnostics (one per bad name, with its field, e.g. `expect[2].method`,
/// and the allowed names).
pub fn check_expectation_names(map: &Map, file: &str) -> Result<(), MapError> {
    let diagnostic = |path: String, what: &str, name: &str, allowed: Vec<&str>| Diagnostic {
        file: file.to_string(),
        position: None,
        path,
        message: format!("unknown {what} `{name}`"),
        hint: Some(format!("expected one of: {}", allowed.join(", "))),
    };
    let mut problems = Vec::new();
    for (i, e) in map.expect.iter().enumerate() {
        if Method::from_map_name(&e.method).is_none() {
            let allowed = Method::all().iter().map(|m| m.map_name()).collect();
            problems.push(diagnostic(format!("expect[{i}].method"), "method", &e.method, allowed));
        }
        if let Some(p) = &e.protocol
            && Protocol::from_map_name(p).is_none()
        {
            let allowed = Protocol::ALL.iter().map(|p| p.map_name()).collect();
            problems.push(diagnostic(format!("expect[{i}].protocol"), "protocol", p, allowed));
        }
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(MapError::new(problems))
    }
}

/// Checks that every setting of `map`'s `agent` section is a parameter of the scaled
/// agent with a value it takes, and that together they are consistent
/// ([`crate::overrides::on_map`] applies them). `file` names the map in the diagnostics
/// (one per bad setting, with its field, e.g. `agent.gate_baseline`, and what is allowed).
pub fn check_agent_settings(map: &Map, file: &str) -> Result<(), MapError> {
    let diagnostic = |path: String, e: &dyn std::fmt::Display| Diagnostic {
        file: file.to_string(),
        position: None,
        path,
        message: e.to_string(),
        hint: Some(
            "the keys and values of `--set` (unforeseen batch --help; maps/README.md, \"The agent's settings\")".into(),
        ),
    };
    let mut p = unforeseen_agent::params::ScaledParams::default();
    let mut problems = Vec::new();
    for (key, value) in &map.agent {
        if let Err(e) = p.set_str(key, value) {
            problems.push(diagnostic(format!("agent.{key}"), &e));
        }
    }
    if problems.is_empty()
        && let Err(e) = p.check_ref()
    {
        problems.push(diagnostic("agent".into(), &e));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(MapError::new(problems))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Map {
        Map::from_str_named("bad.ron", text, &|_| None).expect("the map parses")
    }

    #[test]
    fn expectation_names_are_checked_against_methods_and_protocols() {
        let map = parse("Map(expect: [(method: Scaled), (method: NeverBrake, protocol: Continual)])");
        assert_eq!(check_expectation_names(&map, "bad.ron"), Ok(()));
        let map = parse(
            "Map(expect: [(method: Scaled), (method: Scald, min_success: 0.5), (method: QLearning, protocol: Continuous)])",
        );
        let err = check_expectation_names(&map, "bad.ron").unwrap_err();
        let lines: Vec<String> = err.diagnostics().iter().map(ToString::to_string).collect();
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert!(
            lines[0].starts_with(
                "bad.ron: expect[1].method: unknown method `Scald` (hint: expected one of: QLearning, BayesRl, Scaled,"
            ),
            "{}",
            lines[0]
        );
        assert_eq!(
            lines[1],
            "bad.ron: expect[2].protocol: unknown protocol `Continuous` (hint: expected one of: ZeroShot, Continual)"
        );
    }

    #[test]
    fn agent_settings_are_checked_against_the_scaled_agents_parameters() {
        let map = parse(r#"Map(agent: {"gate_baseline": "foreseen", "competence_regret": "5"})"#);
        assert_eq!(check_agent_settings(&map, "bad.ron"), Ok(()));
        let map = parse(r#"Map(agent: {"gate_baseline": "forseen", "competense": "regret"})"#);
        let err = check_agent_settings(&map, "bad.ron").unwrap_err();
        let lines: Vec<String> = err.diagnostics().iter().map(ToString::to_string).collect();
        assert_eq!(lines.len(), 2, "{lines:?}");
        assert!(
            lines[0].starts_with("bad.ron: agent.competense: unknown parameter `competense`"),
            "{}",
            lines[0]
        );
        assert!(lines[0].contains("competence"), "suggests the key: {}", lines[0]);
        assert!(
            lines[1].starts_with("bad.ron: agent.gate_baseline: parameter `gate_baseline` = forseen is invalid"),
            "{}",
            lines[1]
        );
        assert!(lines[1].contains("foreseen"), "lists the values: {}", lines[1]);
    }

    #[test]
    fn every_method_and_protocol_has_a_map_name() {
        for &m in Method::all() {
            assert_eq!(Method::from_map_name(m.map_name()), Some(m));
        }
        for p in Protocol::ALL {
            assert_eq!(Protocol::from_map_name(p.map_name()), Some(p));
        }
    }

    #[test]
    fn embedded_maps_name_known_methods_and_protocols() {
        for name in embedded::names() {
            load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }
}
