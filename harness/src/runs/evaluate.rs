//! The request of an evaluation ([`EvalRequest`]): one method on one map, or over a
//! deployment stream's maps, asked for by every front as one serde value. Its planning
//! ([`EvalRequest::plan`]) checks the fields, loads the map or stream, the parameters and
//! the agent (the batch's one choice of agents: an agent given loaded, the agent file,
//! or one trained with the run seed; none for a scripted reference) and checks the
//! output folder; the planned evaluation ([`EvalJob`]) runs and writes eval.json.

use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_sim::Map;

use crate::episodes::evaluation::{EvalReport, evaluate_map};
use crate::episodes::methods::Method;
use crate::episodes::protocol::Protocol;
use crate::error::Error;
use crate::files::write_json;
use crate::limits::check_episodes;
use crate::progress::Progress;
use crate::reports::tables::Document;
use crate::runs::batch::request::AgentFields;
use crate::runs::batch::{AgentChoice, SCRIPTED_ONLY};
use crate::runs::outputs::{Outputs, Own};
use crate::runs::stream::{Stream, StreamEvalReport, evaluate_stream};

/// The file an evaluation writes into its folder.
pub const EVAL_FILE: &str = "eval.json";

/// Every choice of an evaluation, with its defaults ([`EvalRequest::default`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EvalRequest {
    /// The map (file or embedded name). Default `jaywalk`.
    pub map: String,
    /// A deployment stream file: the episodes run over its maps instead of `map`, and
    /// the report gives the figures per map within it. Default: none.
    pub stream: Option<PathBuf>,
    /// The method. Default `scaled`.
    pub method: Method,
    /// Episodes. Default 100.
    pub episodes: u64,
    /// The protocol. Default zero-shot.
    pub protocol: Protocol,
    /// Scaled-agent parameter overrides, one `KEY=VALUE` each. Default: none.
    pub sets: Vec<String>,
    /// Evaluation seed (and, without an agent, the training seed). Default 7.
    pub seed: u64,
    /// The folder of eval.json (one from an earlier run there is replaced); none: no
    /// file. Default `out/eval`.
    pub out: Option<PathBuf>,
    /// An agent file (from `unforeseen train`); without one (or an agent given loaded),
    /// a method that needs an agent trains one on `intersection` with the default
    /// episodes and `seed`. Default: none.
    pub agent: Option<PathBuf>,
    /// Replace an output that holds something other than what this run writes there
    /// (the output guard refuses it otherwise). Default: false.
    pub force: bool,
}

impl Default for EvalRequest {
    fn default() -> Self {
        EvalRequest {
            map: crate::maps::DEFAULT_TEST_MAP.to_string(),
            stream: None,
            method: Method::Scaled,
            episodes: crate::limits::DEFAULT_EPISODES,
            protocol: Protocol::ZeroShot,
            sets: Vec::new(),
            seed: unforeseen_env::seeds::DEFAULT_SEED,
            out: Some(PathBuf::from("out/eval")),
            agent: None,
            force: false,
        }
    }
}

/// Where an evaluation, or test-time learning ([`crate::runs::learn`]), runs: one map or a stream.
#[derive(Debug, Clone)]
pub enum EvalScene {
    /// One map.
    Map(Box<Map>),
    /// A deployment stream, read from its file.
    Stream(Box<Stream>, PathBuf),
}

impl EvalScene {
    /// The scene of a job: the deployment `stream` file when given, else `map` (a file or
    /// an embedded name).
    pub fn load(map: &str, stream: Option<&PathBuf>) -> Result<EvalScene, Error> {
        Ok(match stream {
            Some(file) => EvalScene::Stream(Box::new(Stream::load(file)?), file.clone()),
            None => EvalScene::Map(Box::new(crate::maps::load(map)?)),
        })
    }

    /// The scaled agent's parameters in the scene: the map's settings (a stream's maps
    /// agree on theirs), then `sets` ([`crate::overrides::on_map`]).
    pub fn params(&self, sets: &[String]) -> Result<ScaledParams, Error> {
        let map = match self {
            EvalScene::Map(map) => map,
            EvalScene::Stream(stream, _) => &stream.maps[0].0,
        };
        crate::overrides::on_map(map, crate::overrides::pairs(sets)?)
    }

    /// The scene's input files for the output guard (the stream and its maps, or the
    /// map given as `map`), with the agent file `agent` if any.
    pub fn inputs(&self, map: &str, agent: Option<&PathBuf>) -> Outputs {
        let guard = match self {
            EvalScene::Stream(stream, file) => Outputs::new().stream("stream", file, &stream.files),
            EvalScene::Map(_) => Outputs::new().input("map", map),
        };
        match agent {
            Some(agent) => guard.input("agent", agent),
            None => guard,
        }
    }
}

/// An evaluation planned ([`EvalRequest::plan`]).
#[derive(Debug, Clone)]
pub struct EvalJob {
    /// The map or stream.
    pub scene: EvalScene,
    /// The scaled agent's parameters, overrides applied.
    pub params: ScaledParams,
    /// The agent: none for a scripted reference, given, or to train.
    pub agent: AgentChoice,
    /// The request.
    pub request: EvalRequest,
}

/// An evaluation's report: of a map or of a stream.
#[derive(Debug, Clone)]
pub enum EvalOutcome {
    /// One map's report.
    Map(EvalReport),
    /// A stream's report, per map within it.
    Stream(StreamEvalReport),
}

impl EvalOutcome {
    /// The report as eval.json holds it.
    pub fn document(&self) -> Result<serde_json::Value, Error> {
        match self {
            EvalOutcome::Map(r) => r.document(),
            EvalOutcome::Stream(r) => r.document(),
        }
    }

    /// What the command line prints of it ([`eval_table`], [`eval_stream_table`]).
    pub fn table(&self) -> Document {
        match self {
            EvalOutcome::Map(r) => eval_table(r),
            EvalOutcome::Stream(r) => eval_stream_table(r),
        }
    }
}

impl EvalRequest {
    /// Checks the request and resolves it before any work: the episodes, the map or
    /// stream, the overrides, the agent (`given`: an agent given loaded, such as
    /// Python's, instead of the file `agent`) and the output folder (eval.json not an
    /// input). Trains and writes nothing.
    pub fn plan(&self, given: Option<AgentBundle>) -> Result<EvalJob, Error> {
        check_episodes("episodes", self.episodes)?;
        let fields = AgentFields::one(self.agent.as_deref(), self.seed);
        fields.check(given.is_some(), "evaluate one agent")?;
        let scene = EvalScene::load(&self.map, self.stream.as_ref())?;
        if let Some(dir) = &self.out {
            scene
                .inputs(&self.map, self.agent.as_ref())
                .files_in("out", dir, &[EVAL_FILE], &[Own::Evaluation])
                .check(self.force)?;
        }
        let params = scene.params(&self.sets)?;
        // A scripted reference decodes the map's own observations: it needs no agent.
        let scripted = self.method.is_scripted().then_some(SCRIPTED_ONLY);
        let (agent, _, _) = fields.choose(given, scripted)?;
        Ok(EvalJob {
            scene,
            params,
            agent,
            request: self.clone(),
        })
    }
}

impl EvalJob {
    /// The agent the evaluation needs: none for a scripted reference, the one given, or
    /// one trained (one phase of `progress`).
    pub fn agent(&self, progress: &dyn Progress) -> Result<Option<AgentBundle>, Error> {
        self.agent.one(progress)
    }

    /// What the evaluation is, for a progress phase: `scaled jaywalk`.
    pub fn label(&self) -> String {
        let place = match &self.scene {
            EvalScene::Map(map) => &map.name,
            EvalScene::Stream(stream, _) => &stream.name,
        };
        format!("{} {place}", self.request.method)
    }

    /// Runs the evaluation with `bundle` ([`EvalJob::agent`]) as one phase of `progress`
    /// and reports it. Writes nothing.
    pub fn run(&self, bundle: Option<&AgentBundle>, progress: &dyn Progress) -> Result<EvalOutcome, Error> {
        let r = &self.request;
        progress.phase(&self.label(), r.episodes);
        match &self.scene {
            EvalScene::Map(map) => Ok(EvalOutcome::Map(evaluate_map(
                map,
                r.method,
                r.protocol,
                bundle,
                &self.params,
                r.episodes,
                r.seed,
                progress,
            )?)),
            EvalScene::Stream(stream, file) => {
                let episodes = evaluate_stream(
                    stream,
                    bundle,
                    &self.params,
                    r.method,
                    r.protocol,
                    r.episodes,
                    r.seed,
                    progress,
                )?;
                Ok(EvalOutcome::Stream(StreamEvalReport::new(
                    stream,
                    file,
                    r.method,
                    r.protocol,
                    &self.params,
                    r.seed,
                    bundle,
                    episodes,
                )))
            }
        }
    }

    /// Writes eval.json into the request's `out` folder; the path written, none without
    /// an `out`.
    pub fn write(&self, outcome: &EvalOutcome) -> Result<Option<PathBuf>, Error> {
        let Some(dir) = &self.request.out else {
            return Ok(None);
        };
        let path = dir.join(EVAL_FILE);
        write_json(&path, &outcome.document()?)?;
        Ok(Some(path))
    }
}

/// `eval`'s line: the method on the map under its protocol (noting a method that does
/// not learn across episodes), and its figures over every episode.
pub fn eval_table(report: &EvalReport) -> Document {
    let agg = &report.aggregate;
    let mut doc = Document::default();
    doc.line(format!(
        "{} on '{}' ({}): reward {:.2}, success {:.1}%, collisions {:.1}%, red lights {:.1}%, timeouts {:.1}%, inference rate {:.1}%, {:.2} µs/tick over {} episodes",
        report.method,
        report.map,
        protocol_note(report.method, report.protocol, report.learns_across_episodes),
        agg.mean_reward,
        100.0 * agg.success_rate,
        100.0 * agg.collision_rate,
        100.0 * agg.red_light_rate,
        100.0 * agg.timeout_rate,
        100.0 * agg.inference_rate,
        agg.us_per_tick,
        agg.episodes
    ));
    doc
}

/// `eval --stream`'s lines: the method on the stream under its protocol, then one line
/// per map within the stream.
pub fn eval_stream_table(report: &StreamEvalReport) -> Document {
    let mut doc = Document::default();
    doc.line(format!(
        "{} on stream '{}' ({}), per map:",
        report.method,
        report.stream,
        protocol_note(report.method, report.protocol, report.learns_across_episodes)
    ));
    for r in &report.per_map {
        let a = &r.aggregate;
        doc.line(format!(
            "  {:<20} {:>4} episodes: success {:.1}%, collisions {:.1}%, reward {:.2}, inference rate {:.1}%",
            r.map,
            a.episodes,
            100.0 * a.success_rate,
            100.0 * a.collision_rate,
            a.mean_reward,
            100.0 * a.inference_rate
        ));
    }
    doc
}

/// The protocol in words, noting a method that does not learn across episodes (so both
/// protocols give its results).
fn protocol_note(method: Method, protocol: Protocol, learns_across_episodes: bool) -> String {
    if learns_across_episodes {
        protocol.to_string()
    } else {
        format!("{protocol}; {method} does not learn across episodes, so both protocols give these results")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runs::request::from_fields;

    #[test]
    fn a_bad_field_is_named_by_the_request() {
        let fields = |v: serde_json::Value| v.as_object().cloned().unwrap();
        let e = from_fields::<EvalRequest>(fields(serde_json::json!({"method": "swerve"}))).unwrap_err();
        assert!(e.to_string().starts_with("method: "), "{e}");
        let e = EvalRequest {
            episodes: 0,
            ..EvalRequest::default()
        }
        .plan(None)
        .unwrap_err();
        assert!(e.to_string().starts_with("episodes"), "{e}");
    }

    #[test]
    fn a_scripted_reference_needs_no_agent_and_nothing_is_trained() {
        let job = EvalRequest {
            method: Method::BrakeOnPedestrian,
            out: None,
            ..EvalRequest::default()
        }
        .plan(None)
        .unwrap();
        assert!(matches!(job.agent, AgentChoice::None));
        let outcome = job.run(None, &crate::progress::NoProgress).unwrap();
        let EvalOutcome::Map(report) = outcome else {
            panic!("a map's evaluation")
        };
        assert_eq!(report.episodes.len(), 100);
    }
}
