//! Mixed deployment streams: a continual run over several maps (docs/ARCHITECTURE.md §5),
//! because deployment is not one scenario a hundred times. A stream file (RON) lists maps
//! with weights and an order:
//!
//! ```ron
//! Stream(
//!     description: "mostly the training intersection, unforeseen scenarios interleaved",
//!     maps: [
//!         (map: "../intersection.ron", weight: 6),
//!         (map: "../crowd.ron", weight: 1),
//!         (map: "jaywalk", weight: 1),          // an embedded map by name
//!     ],
//!     order: Weighted,   // Weighted: each episode draws a map ∝ weight from the run seed;
//!                        // Sequence: the maps in order, each `weight` episodes in a row, repeated
//! )
//! ```
//!
//! A map is a file relative to the stream file, else an embedded map by name. Episode `k`
//! of the stream runs on the map the order gives it, with the world seed of episode `k` of
//! that map ([`crate::episodes::evaluation::eval_seeds`]); the order draws from the evaluation seed
//! alone, so every method, protocol and agent meets the same maps in the same order.
//! Results are reported per map within the stream ([`per_map`]). Syntax errors name the
//! file, line and column; semantic ones the file and field ([`StreamError`]).
//!
//! [`evaluate_stream`] runs a method over a stream (`eval --stream`, and a stream unit of
//! `batch --stream`: [`crate::runs::batch::ScenarioKind::Stream`]); [`learn_stream`] gives the
//! test-time learning curves over one (`learn --stream`).

use std::path::{Path, PathBuf};

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use unforeseen_agent::controller::Controller;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_env::{Env, EnvConfig};
use unforeseen_sim::Map;

use crate::episodes::evaluation::eval_seeds;
use crate::episodes::learning_curves::{LearnPoint, learn_over};
use crate::episodes::methods::Method;
use crate::episodes::methods::check_compatible;
use crate::episodes::metrics::Aggregate;
use crate::episodes::protocol::Protocol;
use crate::episodes::runner::{EpisodeResult, run_episode};
use crate::progress::Progress;
use unforeseen_env::seeds::episode_seed;

/// Largest stream file read (bytes).
const MAX_BYTES: u64 = 1 << 20;
/// Most maps a stream lists.
pub const MAX_MAPS: usize = 64;

/// How a stream orders its maps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Order {
    /// Each episode draws a map with probability proportional to its weight (seeded by
    /// the run seed and the stream's name).
    #[default]
    Weighted,
    /// The maps in the listed order, each `weight` episodes in a row (whole weights), repeated.
    Sequence,
}

/// One entry of a stream file.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Entry {
    /// A map file (relative to the stream file) or an embedded map's name.
    pub map: String,
    /// Weight (> 0; a whole number of episodes with [`Order::Sequence`]).
    #[serde(default = "one")]
    pub weight: f64,
}

fn one() -> f64 {
    1.0
}

#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields, rename = "Stream")]
struct StreamFile {
    #[serde(default)]
    description: String,
    maps: Vec<Entry>,
    #[serde(default)]
    order: Order,
}

/// A loaded stream: its maps and order.
#[derive(Debug, Clone)]
pub struct Stream {
    /// The stream's name (its file name without `.ron`).
    pub name: String,
    /// One line describing it.
    pub description: String,
    /// The maps, in the file's order, with their weights.
    pub maps: Vec<(Map, f64)>,
    /// The file each map was read from (None for an embedded map), in the same order:
    /// inputs no output may replace ([`crate::runs::outputs::Outputs::stream`]).
    pub files: Vec<Option<PathBuf>>,
    /// How episodes pick their map.
    pub order: Order,
}

pub use crate::error::StreamError;

impl Stream {
    /// Loads and checks a stream file (module docs).
    pub fn load(path: &Path) -> Result<Stream, StreamError> {
        let file = path.display().to_string();
        let read = |message: String| StreamError::Read {
            file: file.clone(),
            message,
        };
        let meta = std::fs::metadata(path).map_err(|e| read(format!("cannot read: {e}")))?;
        if !meta.is_file() {
            return Err(read("not a regular file".into()));
        }
        if meta.len() > MAX_BYTES {
            return Err(read(format!("{} bytes; a stream file has at most 1 MiB", meta.len())));
        }
        let bytes = std::fs::read(path).map_err(|e| read(format!("cannot read: {e}")))?;
        let text = String::from_utf8(bytes).map_err(|_| read("not UTF-8 text".into()))?;
        let parsed: StreamFile = ron::Options::default()
            .from_str(&text)
            .map_err(|e| StreamError::Syntax {
                file: file.clone(),
                line: e.span.start.line,
                column: e.span.start.col,
                message: e.code.to_string(),
            })?;
        let invalid = |field: String, message: &str| StreamError::Invalid {
            file: file.clone(),
            field,
            message: message.to_string(),
        };
        if parsed.maps.is_empty() {
            return Err(invalid(
                "maps".into(),
                "no maps: list at least one (map: \"FILE\", weight: W)",
            ));
        }
        if parsed.description.chars().any(char::is_control) || parsed.description.len() > 1000 {
            return Err(invalid(
                "description".into(),
                "one line of at most 1000 bytes, without control characters (newlines, tabs)",
            ));
        }
        if parsed.maps.len() > MAX_MAPS {
            return Err(invalid("maps".into(), "more than 64 maps"));
        }
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        let mut maps = Vec::with_capacity(parsed.maps.len());
        let mut files = Vec::with_capacity(parsed.maps.len());
        for (i, e) in parsed.maps.iter().enumerate() {
            if !(e.weight.is_finite() && e.weight > 0.0 && e.weight <= 1e6) {
                return Err(invalid(format!("maps[{i}].weight"), "must be a number in (0, 1e6]"));
            }
            if parsed.order == Order::Sequence && e.weight.fract() != 0.0 {
                return Err(invalid(
                    format!("maps[{i}].weight"),
                    "with order: Sequence a weight is a whole number of episodes in a row",
                ));
            }
            let beside: PathBuf = dir.join(&e.map);
            let from_file = beside.exists();
            let arg = if from_file {
                beside.display().to_string()
            } else {
                e.map.clone()
            };
            let map = crate::maps::load(&arg).map_err(|source| StreamError::Map {
                file: file.clone(),
                index: i,
                source,
            })?;
            if let Some(j) = maps.iter().position(|(m, _): &(Map, f64)| m.name == map.name) {
                return Err(invalid(
                    format!("maps[{i}].map"),
                    &format!(
                        "names map '{}' again (maps[{j}]): list each map once and give it the sum of the weights",
                        map.name
                    ),
                ));
            }
            if let Some((first, _)) = maps.first()
                && first.agent != map.agent
            {
                return Err(invalid(
                    format!("maps[{i}].map"),
                    &format!(
                        "map '{}' sets other agent settings than map '{}' (maps[0]): one agent runs the whole stream, so its maps must agree on `agent`",
                        map.name, first.name
                    ),
                ));
            }
            maps.push((map, e.weight));
            files.push(from_file.then_some(beside));
        }
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "stream".into());
        Ok(Stream {
            name,
            description: parsed.description,
            maps,
            files,
            order: parsed.order,
        })
    }

    /// The map index of each of the first `episodes` episodes of the stream under `seed`.
    pub fn schedule(&self, episodes: u64, seed: u64) -> Vec<usize> {
        match self.order {
            Order::Sequence => {
                // The cycle by its cumulative weights (never spelled out: a cycle is up
                // to 64 x 1e6 episodes long).
                let ends: Vec<u64> = self
                    .maps
                    .iter()
                    .scan(0u64, |end, (_, w)| {
                        *end += *w as u64;
                        Some(*end)
                    })
                    .collect();
                let cycle = ends.last().copied().unwrap_or(1).max(1);
                (0..episodes)
                    .map(|k| ends.partition_point(|&end| end <= k % cycle).min(self.maps.len() - 1))
                    .collect()
            }
            Order::Weighted => {
                let mut rng = ChaCha8Rng::seed_from_u64(episode_seed(seed, &format!("stream/{}", self.name), 0));
                let total: f64 = self.maps.iter().map(|(_, w)| w).sum();
                (0..episodes)
                    .map(|_| {
                        let mut r = rng.random::<f64>() * total;
                        for (i, (_, w)) in self.maps.iter().enumerate() {
                            if r < *w {
                                return i;
                            }
                            r -= w;
                        }
                        self.maps.len() - 1
                    })
                    .collect()
            }
        }
    }
}

/// One episode of a stream run: which map it ran on and how it went.
#[derive(Debug, Clone, Serialize)]
pub struct StreamEpisode {
    /// Episode index within the stream.
    pub episode: u64,
    /// The map's name.
    pub map: String,
    /// How the episode went.
    pub result: EpisodeResult,
}

/// The figures of one map within a stream run.
#[derive(Debug, Clone, Serialize)]
pub struct StreamRow {
    /// The map's name.
    pub map: String,
    /// Its episodes' aggregate.
    pub aggregate: Aggregate,
}

/// The report of a method run over a stream (`eval --stream`'s eval.json), built by
/// [`StreamEvalReport::new`] alone; printed by [`crate::runs::evaluate::eval_stream_table`].
#[derive(Debug, Clone, Serialize)]
pub struct StreamEvalReport {
    /// The method.
    pub method: Method,
    /// The stream's name.
    pub stream: String,
    /// The stream file, as given.
    pub stream_file: String,
    /// The protocol asked.
    pub protocol: Protocol,
    /// The protocol the results hold for ([`Protocol::effective`]).
    pub computed_under: Protocol,
    /// Whether the method learns across episodes with these parameters (the printed line
    /// says so when it does not); not in the file.
    #[serde(skip)]
    pub learns_across_episodes: bool,
    /// Evaluation seed.
    pub seed: u64,
    /// The training seed the agent file records (null for a scripted method, or an
    /// agent file that does not say).
    pub train_seed: Option<String>,
    /// The figures per map within the stream ([`per_map`]).
    pub per_map: Vec<StreamRow>,
    /// Every episode, in order.
    pub episodes: Vec<StreamEpisode>,
}

impl StreamEvalReport {
    /// The report of `episodes`, the run of `method` under `protocol` (with the scaled
    /// agent's parameters `params`) over `stream`, read from `file`, from `seed` with the
    /// agent `bundle` (none for a scripted reference).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        stream: &Stream,
        file: &Path,
        method: Method,
        protocol: Protocol,
        params: &ScaledParams,
        seed: u64,
        bundle: Option<&AgentBundle>,
        episodes: Vec<StreamEpisode>,
    ) -> Self {
        StreamEvalReport {
            method,
            stream: stream.name.clone(),
            stream_file: file.display().to_string(),
            protocol,
            computed_under: protocol.effective(method, params),
            learns_across_episodes: method.learns_across_episodes(params),
            seed,
            train_seed: bundle.and_then(|b| b.meta.get("seed").cloned()),
            per_map: per_map(stream, &episodes),
            episodes,
        }
    }

    /// The report as eval.json holds it: a JSON object with its keys sorted at every level.
    pub fn document(&self) -> Result<serde_json::Value, crate::error::Error> {
        Ok(serde_json::to_value(self)?)
    }
}

/// Runs `episodes` episodes of the stream with `method` under `protocol`: zero-shot, each
/// episode from the trained agent (episodes in parallel, rayon); continual, one controller
/// learning across the stream in order. Episode `k` on map `m` uses the world seed of
/// episode `k` of `m`, so results do not depend on the number of threads. Without a
/// `bundle`, `method` is a scripted reference. Advances `progress` by one per episode
/// (the caller announces and finishes the phase).
#[allow(clippy::too_many_arguments)]
pub fn evaluate_stream(
    stream: &Stream,
    bundle: Option<&AgentBundle>,
    params: &ScaledParams,
    method: Method,
    protocol: Protocol,
    episodes: u64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<StreamEpisode>, crate::error::Error> {
    let new_env = |m: usize| Env::new(&stream.maps[m].0, EnvConfig::default());
    for (m, (map, _)) in stream.maps.iter().enumerate() {
        if let Some(b) = bundle {
            check_compatible(b, map)?;
        }
        new_env(m)?;
    }
    let make = |map: &Map| -> Result<Box<dyn Controller>, crate::error::Error> {
        match bundle {
            Some(b) => method.controller(b, params, map),
            None => {
                let sizes = unforeseen_discretizer::Discretizer::new(map)?.factor_sizes();
                method
                    .scripted_controller(&sizes, map)?
                    .ok_or_else(|| crate::error::Error::NotScripted {
                        method: method.to_string(),
                    })
            }
        }
    };
    let run = |env: &mut Env,
               controller: &mut dyn Controller,
               k: usize,
               m: usize|
     -> Result<StreamEpisode, crate::error::Error> {
        let map = &stream.maps[m].0;
        let result = run_episode(env, controller, eval_seeds(seed, map, method, k as u64), false)?.0;
        crate::progress::step(progress)?;
        Ok(StreamEpisode {
            episode: k as u64,
            map: map.name.clone(),
            result,
        })
    };
    let schedule = stream.schedule(episodes, seed);
    let continual = bundle.is_some() && protocol.effective(method, params) == Protocol::Continual;
    if continual {
        let mut controller = make(&stream.maps[0].0)?;
        let mut envs = (0..stream.maps.len()).map(new_env).collect::<Result<Vec<_>, _>>()?;
        return schedule
            .iter()
            .enumerate()
            .map(|(k, &m)| run(&mut envs[m], controller.as_mut(), k, m))
            .collect();
    }
    // Zero-shot: independent episodes, each worker building the envs of the maps it meets.
    schedule
        .par_iter()
        .enumerate()
        .map_init(
            || -> Vec<Option<Env>> { (0..stream.maps.len()).map(|_| None).collect() },
            |envs, (k, &m)| {
                if envs[m].is_none() {
                    envs[m] = Some(new_env(m)?);
                }
                let env = envs[m].as_mut().expect("built above");
                run(env, make(&stream.maps[m].0)?.as_mut(), k, m)
            },
        )
        .collect()
}

/// The figures per map of a stream run, in the stream's order (maps no episode drew are left out).
pub fn per_map(stream: &Stream, episodes: &[StreamEpisode]) -> Vec<StreamRow> {
    stream
        .maps
        .iter()
        .filter_map(|(map, _)| {
            let results: Vec<EpisodeResult> = episodes
                .iter()
                .filter(|e| e.map == map.name)
                .map(|e| e.result.clone())
                .collect();
            (!results.is_empty()).then(|| StreamRow {
                map: map.name.clone(),
                aggregate: Aggregate::of(&results),
            })
        })
        .collect()
}

/// The test-time learning curves of the scaled agent over `episodes` episodes of the
/// stream (the learning curves of [`crate::episodes::learn`], `learn_over`, on the stream's schedule): one agent
/// learning across the stream in order, each point naming its map.
pub fn learn_stream(
    stream: &Stream,
    bundle: &AgentBundle,
    params: &ScaledParams,
    episodes: u64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<LearnPoint>, crate::error::Error> {
    let maps: Vec<&Map> = stream.maps.iter().map(|(m, _)| m).collect();
    learn_over(bundle, params, &maps, &stream.schedule(episodes, seed), seed, progress)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn loads_weights_and_sequences_and_reports_bad_files_with_place() {
        let dir = tempfile::tempdir().unwrap();
        let ok = write(
            dir.path(),
            "mix.ron",
            "Stream(maps: [(map: \"intersection\", weight: 3), (map: \"jaywalk\")], order: Sequence)",
        );
        let s = Stream::load(&ok).unwrap();
        assert_eq!(s.name, "mix");
        assert_eq!(s.schedule(9, 7), vec![0, 0, 0, 1, 0, 0, 0, 1, 0]);
        let w = write(
            dir.path(),
            "w.ron",
            "Stream(maps: [(map: \"intersection\", weight: 9), (map: \"jaywalk\", weight: 1)])",
        );
        let s = Stream::load(&w).unwrap();
        let sched = s.schedule(1000, 7);
        assert_eq!(sched, s.schedule(1000, 7));
        let jay = sched.iter().filter(|&&m| m == 1).count();
        assert!((50..150).contains(&jay), "{jay} of 1000 on the weight-1 map");
        let syntax = write(
            dir.path(),
            "bad.ron",
            "Stream(\n  maps: [(map: \"jaywalk\", weight: )],\n)",
        );
        let e = Stream::load(&syntax).unwrap_err().to_string();
        assert!(e.starts_with(&format!("{}:2:", syntax.display())), "{e}");
        let weight = write(dir.path(), "z.ron", "Stream(maps: [(map: \"jaywalk\", weight: 0)])");
        assert!(
            Stream::load(&weight)
                .unwrap_err()
                .to_string()
                .contains("maps[0].weight")
        );
        let missing = write(dir.path(), "m.ron", "Stream(maps: [(map: \"nowhere.ron\")])");
        assert!(Stream::load(&missing).unwrap_err().to_string().contains("maps[0]"));
        let empty = write(dir.path(), "e.ron", "Stream(maps: [])");
        assert!(Stream::load(&empty).unwrap_err().to_string().contains("no maps"));
        let twice = write(
            dir.path(),
            "t.ron",
            "Stream(maps: [(map: \"jaywalk\"), (map: \"jaywalk\")])",
        );
        assert!(Stream::load(&twice).unwrap_err().to_string().contains("again"));
        write(
            dir.path(),
            "gated.ron",
            "Map(base: \"jaywalk\", name: \"gated\", agent: {\"gate_baseline\": \"foreseen\"})",
        );
        let disagree = write(
            dir.path(),
            "d.ron",
            "Stream(maps: [(map: \"jaywalk\"), (map: \"gated.ron\")])",
        );
        let e = Stream::load(&disagree).unwrap_err().to_string();
        assert!(e.contains("maps[1].map") && e.contains("agent"), "{e}");
        let fraction = write(
            dir.path(),
            "f.ron",
            "Stream(maps: [(map: \"jaywalk\", weight: 1.5)], order: Sequence)",
        );
        assert!(
            Stream::load(&fraction)
                .unwrap_err()
                .to_string()
                .contains("whole number")
        );
    }
}
