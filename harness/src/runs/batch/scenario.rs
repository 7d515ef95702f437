//! The scenarios of a batch: a map or a deployment stream, loaded from files, folders
//! or embedded names, with their names checked unique.

use std::path::{Path, PathBuf};
use unforeseen_sim::{EMBEDDED_PREFIX, Map};

use crate::error::Error;
use crate::runs::stream::Stream;

/// A scenario of the suite: a map or a deployment stream, and where it came from.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// What its units run on.
    pub kind: ScenarioKind,
    /// File it was read from, or `embedded:NAME`.
    pub source: String,
}

/// What a scenario's units run on.
#[derive(Debug, Clone)]
pub enum ScenarioKind {
    /// One map: every episode on it (boxed: a map is several times a stream's size).
    Map(Box<Map>),
    /// A deployment stream ([`crate::runs::stream`]): each episode on the map the stream's order
    /// gives it; the unit's line adds the figures per map within the stream
    /// ([`ResultLine::per_map`](super::ResultLine::per_map)).
    Stream(Stream),
}

impl Scenario {
    /// A scenario of one map, read from `source`.
    pub fn of_map(map: Map, source: impl Into<String>) -> Scenario {
        Scenario {
            kind: ScenarioKind::Map(Box::new(map)),
            source: source.into(),
        }
    }

    /// A scenario of a deployment stream, read from the stream file `source`.
    pub fn of_stream(stream: Stream, source: impl Into<String>) -> Scenario {
        Scenario {
            kind: ScenarioKind::Stream(stream),
            source: source.into(),
        }
    }

    /// The scenario's name (the map's, or the stream's), which its result lines carry.
    pub fn name(&self) -> &str {
        match &self.kind {
            ScenarioKind::Map(map) => &map.name,
            ScenarioKind::Stream(stream) => &stream.name,
        }
    }

    /// The map of a map scenario (None for a stream).
    pub fn map(&self) -> Option<&Map> {
        match &self.kind {
            ScenarioKind::Map(map) => Some(map.as_ref()),
            ScenarioKind::Stream(_) => None,
        }
    }

    /// The map of a map scenario, to change (None for a stream).
    pub fn map_mut(&mut self) -> Option<&mut Map> {
        match &mut self.kind {
            ScenarioKind::Map(map) => Some(map.as_mut()),
            ScenarioKind::Stream(_) => None,
        }
    }

    /// A hash of everything of the scenario that determines results: the map's full
    /// contents (bases merged), or the stream's name, maps, weights and order.
    pub(super) fn content_hash(&self) -> String {
        let text = match &self.kind {
            ScenarioKind::Map(map) => serde_json::to_string(map),
            ScenarioKind::Stream(s) => serde_json::to_string(&("stream", &s.name, &s.maps, s.order)),
        };
        unforeseen_env::seeds::content_hash(text.unwrap_or_default().as_bytes())
    }
}

/// Loads scenarios from files and folders (every `*.ron` in a folder, sorted), or the
/// embedded maps when none are given. Two scenarios with one name (the same map listed
/// twice, or maps named alike in different folders) are an [`Error::DuplicateScenario`]:
/// results and `--resume` tell scenarios apart by name.
pub fn load_scenarios(paths: &[PathBuf]) -> Result<Vec<Scenario>, Error> {
    let scenarios = read_scenarios(paths)?;
    for (i, s) in scenarios.iter().enumerate() {
        if let Some(first) = scenarios[..i].iter().find(|f| f.name() == s.name()) {
            return Err(Error::DuplicateScenario {
                name: s.name().to_string(),
                first: first.source.clone(),
                second: s.source.clone(),
            });
        }
    }
    Ok(scenarios)
}

/// The scenarios of `paths`, in order, possibly with repeated names.
fn read_scenarios(paths: &[PathBuf]) -> Result<Vec<Scenario>, Error> {
    if paths.is_empty() {
        return unforeseen_sim::embedded::names()
            .iter()
            .map(|n| {
                Ok(Scenario::of_map(
                    unforeseen_sim::embedded::load(n)?,
                    format!("{EMBEDDED_PREFIX}{n}"),
                ))
            })
            .collect();
    }
    let mut scenarios = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(p)
                .map_err(|e| Error::io("list", p, e))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| f.extension().is_some_and(|x| x == "ron"))
                .collect();
            found.sort();
            if found.is_empty() {
                return Err(Error::flag(
                    p.display().to_string(),
                    "a folder with no map files (*.ron): nothing to run; give map files or a folder of them",
                ));
            }
            for f in found {
                scenarios.push(Scenario::of_map(crate::maps::load_file(&f)?, f.display().to_string()));
            }
        } else if p.exists() {
            scenarios.push(Scenario::of_map(crate::maps::load_file(p)?, p.display().to_string()));
        } else {
            let map = crate::maps::load(&p.to_string_lossy())?;
            let source = format!("{EMBEDDED_PREFIX}{}", map.name);
            scenarios.push(Scenario::of_map(map, source));
        }
    }
    Ok(scenarios)
}

/// The one scenario of a batch over the deployment stream in `file` ([`Stream::load`]).
pub fn load_stream_scenario(file: &Path) -> Result<Scenario, Error> {
    Ok(Scenario::of_stream(Stream::load(file)?, file.display().to_string()))
}
