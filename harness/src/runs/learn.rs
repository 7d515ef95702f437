//! The request of test-time learning curves ([`LearnRequest`], paper Fig. 9): one scaled
//! agent learning over repeated episodes of one map, or over a deployment stream's maps,
//! asked for by every front as one serde value. Its planning ([`LearnRequest::plan`])
//! checks the fields, loads the map or stream, the parameters and the agent (the batch's
//! one choice of agents: an agent given loaded, the agent file, or one trained with the
//! run seed) and checks the output folder; the planned job ([`LearnJob`]) runs the
//! episodes into a [`LearnReport`] (the curve and its figures per map) and writes
//! learn.csv, learn.json and learn.svg, all three or none.

use plotters::style::{BLUE, RED, RGBColor};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;

use crate::episodes::learning_curves::{LearnPoint, learn};
use crate::error::Error;
use crate::files::{Csv, all_or_none, num, write_json};
use crate::limits::check_episodes;
use crate::progress::Progress;
use crate::reports::figures::{Series, line_panels};
use crate::runs::batch::AgentChoice;
use crate::runs::batch::request::AgentFields;
use crate::runs::evaluate::EvalScene;
use crate::runs::outputs::Own;
use crate::runs::stream::learn_stream;

/// The files test-time learning writes into its folder, in order.
pub const LEARN_FILES: [&str; 3] = ["learn.csv", "learn.json", "learn.svg"];

/// What each of [`LEARN_FILES`] holds, for the output guard.
const LEARN_KINDS: [Own; 3] = [Own::Csv, Own::LearningCurves, Own::Svg];

/// Every choice of test-time learning, with its defaults ([`LearnRequest::default`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LearnRequest {
    /// The map with the unforeseen scenario (file or embedded name). Default `jaywalk`.
    pub map: String,
    /// A deployment stream file: the agent learns across its maps instead of `map`, and
    /// the report gives the figures per map within it. Default: none.
    pub stream: Option<PathBuf>,
    /// Episodes of test-time learning. Default 50.
    pub episodes: u64,
    /// Scaled-agent parameter overrides, one `KEY=VALUE` each. Default: none.
    pub sets: Vec<String>,
    /// Seed of the episodes (and, without an agent, the training seed). Default 7.
    pub seed: u64,
    /// The folder of learn.csv, learn.json and learn.svg (files from an earlier run
    /// there are replaced); none: no files. Default `out/learn`.
    pub out: Option<PathBuf>,
    /// An agent file (from `unforeseen train`); without one (or an agent given loaded),
    /// one is trained on `intersection` with the default episodes and `seed`. Default:
    /// none.
    pub agent: Option<PathBuf>,
    /// Replace an output that holds something other than what this run writes there
    /// (the output guard refuses it otherwise). Default: false.
    pub force: bool,
}

impl Default for LearnRequest {
    fn default() -> Self {
        LearnRequest {
            map: crate::maps::DEFAULT_TEST_MAP.to_string(),
            stream: None,
            episodes: 50,
            sets: Vec::new(),
            seed: unforeseen_env::seeds::DEFAULT_SEED,
            out: Some(PathBuf::from("out/learn")),
            agent: None,
            force: false,
        }
    }
}

/// Test-time learning planned ([`LearnRequest::plan`]).
#[derive(Debug, Clone)]
pub struct LearnJob {
    /// The map or stream (as an evaluation's).
    pub scene: EvalScene,
    /// The scaled agent's parameters, overrides applied (learning is on whatever they
    /// say).
    pub params: ScaledParams,
    /// The agent: given, or to train.
    pub agent: AgentChoice,
    /// The request.
    pub request: LearnRequest,
}

/// The figures of a learning curve on one map: its episodes and successes, and its
/// first and last episode.
#[derive(Debug, Clone, Serialize)]
pub struct MapLearning {
    /// The map's name.
    pub map: String,
    /// Episodes on it.
    pub episodes: usize,
    /// Of them, those that succeeded.
    pub successes: usize,
    /// Its first episode.
    pub first: LearnPoint,
    /// Its last episode.
    pub last: LearnPoint,
}

impl MapLearning {
    /// The figures of `points` on the map named `map`; none without a point.
    fn of(map: &str, points: &[&LearnPoint]) -> Option<MapLearning> {
        Some(MapLearning {
            map: map.to_string(),
            episodes: points.len(),
            successes: points.iter().filter(|p| p.success).count(),
            first: (*points.first()?).clone(),
            last: (*points.last()?).clone(),
        })
    }
}

/// A test-time learning curve ([`LearnJob::run`]): one point per episode (learn.json),
/// and its figures per map.
#[derive(Debug, Clone)]
pub struct LearnReport {
    /// One point per episode, in order.
    pub points: Vec<LearnPoint>,
    /// The figures per map: one for a map's curve (over every episode), one per map of
    /// a stream that had episodes, in the stream's order.
    pub per_map: Vec<MapLearning>,
    /// The stream's name, for a stream's curve.
    pub stream: Option<String>,
}

impl LearnRequest {
    /// Checks the request and resolves it before any work: the episodes, the map or
    /// stream, the output folder (none of its files an input), the overrides and the
    /// agent (`given`: an agent given loaded, such as Python's, instead of the file
    /// `agent`). Trains and writes nothing.
    pub fn plan(&self, given: Option<AgentBundle>) -> Result<LearnJob, Error> {
        check_episodes("episodes", self.episodes)?;
        let fields = AgentFields::one(self.agent.as_deref(), self.seed);
        fields.check(given.is_some(), "learn with one agent")?;
        let scene = EvalScene::load(&self.map, self.stream.as_ref())?;
        if let Some(dir) = &self.out {
            scene
                .inputs(&self.map, self.agent.as_ref())
                .files_in("out", dir, &LEARN_FILES, &LEARN_KINDS)
                .check(self.force)?;
        }
        let params = scene.params(&self.sets)?;
        let (agent, _, _) = fields.choose(given, None)?;
        Ok(LearnJob {
            scene,
            params,
            agent,
            request: self.clone(),
        })
    }
}

impl LearnJob {
    /// The agent that learns: the one given, or one trained (one phase of `progress`).
    pub fn agent(&self, progress: &dyn Progress) -> Result<AgentBundle, Error> {
        self.agent.one(progress)?.ok_or_else(|| Error::Agent {
            problem: "test-time learning needs a trained agent".into(),
            fix: "give an agent file, or let one be trained".into(),
        })
    }

    /// What the agent learns on: `'jaywalk'`, or `the stream 'deployment' (6 maps)`.
    pub fn on(&self) -> String {
        match &self.scene {
            EvalScene::Map(map) => format!("'{}'", map.name),
            EvalScene::Stream(stream, _) => format!("the stream '{}' ({} maps)", stream.name, stream.maps.len()),
        }
    }

    /// Runs the episodes with `bundle` ([`LearnJob::agent`]), one phase of `progress`,
    /// and reports the curve. Writes nothing.
    pub fn run(&self, bundle: &AgentBundle, progress: &dyn Progress) -> Result<LearnReport, Error> {
        let (episodes, seed) = (self.request.episodes, self.request.seed);
        match &self.scene {
            EvalScene::Map(map) => {
                let points = learn(bundle, &self.params, map, episodes, seed, progress)?;
                let all: Vec<&LearnPoint> = points.iter().collect();
                let per_map = MapLearning::of(&map.name, &all).into_iter().collect();
                Ok(LearnReport {
                    points,
                    per_map,
                    stream: None,
                })
            }
            EvalScene::Stream(stream, _) => {
                let points = learn_stream(stream, bundle, &self.params, episodes, seed, progress)?;
                let per_map = stream
                    .maps
                    .iter()
                    .filter_map(|(map, _)| {
                        let on: Vec<&LearnPoint> = points.iter().filter(|p| p.map == map.name).collect();
                        MapLearning::of(&map.name, &on)
                    })
                    .collect();
                Ok(LearnReport {
                    points,
                    per_map,
                    stream: Some(stream.name.clone()),
                })
            }
        }
    }

    /// Writes learn.csv, learn.json and learn.svg into the request's `out` folder, all
    /// three or none: a failed write (a full disk) leaves the previous run's set. The
    /// paths written, none without an `out`.
    pub fn write(&self, report: &LearnReport) -> Result<Vec<PathBuf>, Error> {
        let Some(dir) = &self.request.out else {
            return Ok(Vec::new());
        };
        let paths: Vec<PathBuf> = LEARN_FILES.iter().map(|n| dir.join(n)).collect();
        all_or_none(|| -> Result<(), Error> {
            curve_csv(&report.points).write(&paths[0])?;
            write_json(&paths[1], &report.points)?;
            plot(&paths[2], &report.points)
        })?;
        Ok(paths)
    }
}

/// `learn.csv`: one row per episode (the map it ran on, the figures of Fig. 9, the
/// reasoning ticks, success and return).
fn curve_csv(points: &[LearnPoint]) -> Csv {
    let mut csv = Csv::new(&[
        "episode",
        "map",
        "event_surprise_bits",
        "p_pedestrian_green_d2",
        "p_stay_green_d2",
        "p_slow_down",
        "reasoning_ticks",
        "inference_rate",
        "success",
        "reward",
    ]);
    let opt = |x: Option<f64>, d| x.map(|v| num(v, d)).unwrap_or_default();
    for p in points {
        csv.row(vec![
            p.episode.to_string(),
            p.map.clone(),
            opt(p.event_surprise_bits, 4),
            opt(p.p_pedestrian_green_d2, 5),
            num(p.p_stay_green_d2, 5),
            num(p.p_slow_down, 5),
            p.reasoning_ticks.to_string(),
            num(p.inference_rate, 4),
            p.success.to_string(),
            num(p.reward, 3),
        ]);
    }
    csv
}

/// `learn.svg`: the three panels of Fig. 9 against the episode (the surprise at the
/// event, the pedestrian on green at d = 2 in the gate and the planner, the policy in the
/// event state).
fn plot(path: &Path, points: &[LearnPoint]) -> Result<(), Error> {
    let x = |f: &dyn Fn(&LearnPoint) -> Option<f64>| -> Vec<(f64, f64)> {
        points
            .iter()
            .filter_map(|p| f(p).map(|y| (p.episode as f64, y)))
            .collect()
    };
    line_panels(
        path,
        "episode of test-time learning",
        &[
            (
                "(a) surprise at the event (bits)",
                vec![Series {
                    label: "gate's surprise at the first pedestrian on green",
                    points: x(&|p| p.event_surprise_bits),
                    color: RED,
                }],
            ),
            (
                "(b) pedestrian on green at d = 2",
                vec![
                    Series {
                        label: "gate: P(p=1 | L=1, d=2)",
                        points: x(&|p| p.p_pedestrian_green_d2),
                        color: BLUE,
                    },
                    Series {
                        label: "planner: P(p'=1 | p=1, L'=1, d'=2)",
                        points: x(&|p| Some(p.p_stay_green_d2)),
                        color: RGBColor(0, 150, 0),
                    },
                ],
            ),
            (
                "(c) policy: pi_o(slow down | event state)",
                vec![Series {
                    label: "P(slow down)",
                    points: x(&|p| Some(p.p_slow_down)),
                    color: BLUE,
                }],
            ),
        ],
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runs::request::from_fields;

    #[test]
    fn a_bad_field_is_named_by_the_request() {
        let fields = |v: serde_json::Value| v.as_object().cloned().unwrap();
        let e = from_fields::<LearnRequest>(fields(serde_json::json!({"episodes": "many"}))).unwrap_err();
        assert!(e.to_string().starts_with("episodes: "), "{e}");
        let e = from_fields::<LearnRequest>(fields(serde_json::json!({"method": "scaled"}))).unwrap_err();
        assert!(e.to_string().starts_with("method: not a field"), "{e}");
        let e = LearnRequest {
            episodes: 0,
            ..LearnRequest::default()
        }
        .plan(None)
        .unwrap_err();
        assert!(e.to_string().starts_with("episodes"), "{e}");
        let e = LearnRequest {
            sets: vec!["epsilon=2".into()],
            out: None,
            ..LearnRequest::default()
        }
        .plan(None)
        .unwrap_err();
        assert!(matches!(e, Error::Override { .. }), "{e}");
    }

    #[test]
    fn an_output_that_is_an_input_is_refused_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let map = dir.path().join("learn.csv");
        std::fs::write(&map, unforeseen_sim::embedded::source("jaywalk").unwrap()).unwrap();
        // Refused at planning: nothing loaded beyond the map, nothing trained or written.
        let e = LearnRequest {
            map: map.display().to_string(),
            out: Some(dir.path().to_path_buf()),
            ..LearnRequest::default()
        }
        .plan(None)
        .unwrap_err();
        assert!(e.to_string().contains("given as map"), "{e}");
        assert!(!dir.path().join("learn.json").exists());
    }
}
