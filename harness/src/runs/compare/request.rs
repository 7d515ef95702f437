//! The request of a comparison study ([`CompareRequest`]): the paper's table (§VI) asked
//! for by every front as one serde value. Its planning ([`CompareRequest::plan`]) checks
//! the fields, loads the maps and the parameters, chooses the agents (with the batch's
//! one choice of agents) and checks the output folder; the planned study
//! ([`CompareJob`]) trains or loads its agents, runs and writes compare.json,
//! compare.csv, compare_seeds.csv and compare.svg ([`super::files`]).

use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use unforeseen_agent::params::ScaledParams;
use unforeseen_sim::Map;

use crate::episodes::methods::Method;
use crate::episodes::protocol::{Protocol, ProtocolChoice};
use crate::error::Error;
use crate::limits::check_episodes;
use crate::progress::Progress;
use crate::runs::batch::AgentChoice;
use crate::runs::batch::request::AgentFields;
use crate::runs::outputs::{Outputs, Own};
use crate::training::seed_agents::{Agent, DEFAULT_CACHE, TrainSeeds, train_agents};
use crate::training::{DEFAULT_TRAIN_EPISODES, DEFAULT_TRAIN_MAP, TimeoutAs};

use super::files::COMPARE_FILES;
use super::{CompareReport, StudySetup, run_study};

/// Every choice of a comparison study, with its defaults ([`CompareRequest::default`]:
/// the paper's table, as `unforeseen` with no command runs it).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CompareRequest {
    /// The training map (file or embedded name). Default `intersection`.
    pub train_map: String,
    /// The test map with the unforeseen scenario (file or embedded name). Default
    /// `jaywalk`.
    pub test_map: String,
    /// Training episodes of agents trained here. Default [`DEFAULT_TRAIN_EPISODES`].
    pub train_episodes: u64,
    /// Evaluation episodes per method, map and agent. Default 100.
    pub episodes: u64,
    /// Also run the ablations ([`Method::ABLATIONS`]). Default false.
    pub ablations: bool,
    /// Protocols. Default both (the zero-shot table first).
    pub protocol: ProtocolChoice,
    /// Scaled-agent parameter overrides, one `KEY=VALUE` each. Default: none.
    pub sets: Vec<String>,
    /// Evaluation seed (and, with neither `agent` nor `train_seeds`, the training seed).
    /// Default 7.
    pub seed: u64,
    /// The folder of compare.json, compare.csv, compare_seeds.csv and compare.svg (files
    /// from an earlier run there are replaced); none: no files. Default `out/compare`.
    pub out: Option<PathBuf>,
    /// An agent file (from `unforeseen train`). Default: none.
    pub agent: Option<PathBuf>,
    /// One agent per training seed, each trained on `train_map`. Default: none.
    pub train_seeds: Option<TrainSeeds>,
    /// What a training episode's time-out is to the learners. Default truncation.
    pub timeout_as: TimeoutAs,
    /// The folder of the agent cache of `train_seeds`; none: no cache. Default
    /// [`DEFAULT_CACHE`].
    pub cache: Option<PathBuf>,
    /// Replace an output that holds something other than what this run writes there
    /// (the output guard refuses it otherwise). Default: false.
    pub force: bool,
}

impl Default for CompareRequest {
    fn default() -> Self {
        CompareRequest {
            train_map: DEFAULT_TRAIN_MAP.to_string(),
            test_map: crate::maps::DEFAULT_TEST_MAP.to_string(),
            train_episodes: DEFAULT_TRAIN_EPISODES,
            episodes: crate::limits::DEFAULT_EPISODES,
            ablations: false,
            protocol: ProtocolChoice::Both,
            sets: Vec::new(),
            seed: unforeseen_env::seeds::DEFAULT_SEED,
            out: Some(PathBuf::from("out/compare")),
            agent: None,
            train_seeds: None,
            timeout_as: TimeoutAs::Truncation,
            cache: Some(PathBuf::from(DEFAULT_CACHE)),
            force: false,
        }
    }
}

/// A comparison study planned ([`CompareRequest::plan`]): its maps, parameters, methods,
/// protocols and agents, its output folder checked.
#[derive(Debug, Clone)]
pub struct CompareJob {
    /// The training map.
    pub train_map: Map,
    /// The test map.
    pub test_map: Map,
    /// The scaled agent's parameters, overrides applied.
    pub params: ScaledParams,
    /// The methods, in table order.
    pub methods: Vec<Method>,
    /// The protocols, in table order.
    pub protocols: Vec<Protocol>,
    /// The agents.
    pub agents: AgentChoice,
    /// Agents given loaded (Python's), instead of `agents`.
    given: Vec<Agent>,
    /// The request.
    pub request: CompareRequest,
}

impl CompareRequest {
    /// Checks the request and resolves it before any work: the episodes, the maps, the
    /// overrides, the agents (`given`: agents given loaded, such as Python's, instead of
    /// `agent` or `train_seeds`) and the output folder (none of its files an input).
    /// Trains and writes nothing.
    pub fn plan(&self, given: Vec<Agent>) -> Result<CompareJob, Error> {
        check_episodes("episodes", self.episodes)?;
        check_episodes("train_episodes", self.train_episodes)?;
        let fields = AgentFields {
            agent: self.agent.as_deref(),
            train_seeds: self.train_seeds.as_ref(),
            train_map: &self.train_map,
            train_episodes: self.train_episodes,
            timeout_as: self.timeout_as,
            cache: self.cache.as_ref(),
            seed: self.seed,
        };
        fields.check(!given.is_empty(), "compare one agent")?;
        if let Some(dir) = &self.out {
            let mut guard = Outputs::new()
                .input("train_map", &self.train_map)
                .input("test_map", &self.test_map);
            if let Some(agent) = &self.agent {
                guard = guard.input("agent", agent);
            }
            guard
                .files_in(
                    "out",
                    dir,
                    &COMPARE_FILES,
                    &[Own::Comparison, Own::Csv, Own::Csv, Own::Svg],
                )
                .check(self.force)?;
        }
        let train_map = crate::maps::load(&self.train_map)?;
        let test_map = crate::maps::load(&self.test_map)?;
        let params = crate::overrides::on_map(&test_map, crate::overrides::pairs(&self.sets)?)?;
        let agents = if given.is_empty() {
            fields.choose(None, None)?.0
        } else {
            AgentChoice::None
        };
        let mut methods = Method::PAPER.to_vec();
        if self.ablations {
            methods.extend(Method::ABLATIONS);
        }
        Ok(CompareJob {
            train_map,
            test_map,
            params,
            methods,
            protocols: self.protocol.protocols(),
            agents,
            given,
            request: self.clone(),
        })
    }
}

impl CompareJob {
    /// The study's agents: those given, the agent file's, or those trained (in parallel,
    /// or loaded from the agent cache), one phase of `progress`.
    pub fn agents(&self, progress: &dyn Progress) -> Result<Vec<Agent>, Error> {
        match &self.agents {
            AgentChoice::None => Ok(self.given.clone()),
            AgentChoice::Given(agent) => Ok(vec![agent.as_ref().clone()]),
            AgentChoice::Trained {
                map,
                seeds,
                config,
                cache,
            } => train_agents(map, seeds, config, cache.as_deref(), progress),
        }
    }

    /// Runs the study over `agents` ([`CompareJob::agents`]; [`run_study`], one phase of
    /// `progress`) and builds its report ([`CompareReport::new`]). Writes nothing.
    pub fn run(&self, agents: &[Agent], progress: &dyn Progress) -> Result<CompareReport, Error> {
        let setup = StudySetup {
            train_map: &self.train_map,
            test_map: &self.test_map,
            params: &self.params,
            methods: &self.methods,
            protocols: &self.protocols,
            episodes: self.request.episodes,
            seed: self.request.seed,
        };
        let tables = run_study(&setup, agents, progress)?;
        let agent_file = self.request.agent.as_ref().map(|p| p.display().to_string());
        let agent_cache = match (&self.agents, &self.request.train_seeds) {
            (AgentChoice::Trained { cache: Some(dir), .. }, Some(_)) => Some(dir.display().to_string()),
            _ => None,
        };
        CompareReport::new(&setup, agents, tables, agent_file, agent_cache)
    }

    /// Writes the report's files into the request's `out` folder, all four or none
    /// (`files.rs`); the paths written, none without an `out`.
    pub fn write(&self, report: &CompareReport) -> Result<Vec<PathBuf>, Error> {
        match &self.request.out {
            Some(dir) => super::files::write(dir, report),
            None => Ok(Vec::new()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runs::request::from_fields;

    fn fields(v: serde_json::Value) -> serde_json::Map<String, serde_json::Value> {
        v.as_object().cloned().unwrap()
    }

    #[test]
    fn a_bad_field_is_named_by_the_request() {
        let e = from_fields::<CompareRequest>(fields(serde_json::json!({"protocol": "twice"}))).unwrap_err();
        assert!(e.to_string().starts_with("protocol: "), "{e}");
        let e = from_fields::<CompareRequest>(fields(serde_json::json!({"agents": 3}))).unwrap_err();
        assert!(e.to_string().starts_with("agents: not a field"), "{e}");
        let e = CompareRequest {
            episodes: 0,
            ..CompareRequest::default()
        }
        .plan(Vec::new())
        .unwrap_err();
        assert!(e.to_string().starts_with("episodes"), "{e}");
        let e = CompareRequest {
            train_seeds: Some(TrainSeeds(vec![1, 2])),
            agent: Some(PathBuf::from("agent.ron")),
            ..CompareRequest::default()
        }
        .plan(Vec::new())
        .unwrap_err();
        assert!(e.to_string().starts_with("train_seeds: "), "{e}");
    }

    #[test]
    fn an_output_that_is_an_input_is_refused_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let map = dir.path().join("compare.csv");
        std::fs::write(&map, unforeseen_sim::embedded::source("jaywalk").unwrap()).unwrap();
        let e = CompareRequest {
            test_map: map.display().to_string(),
            out: Some(dir.path().to_path_buf()),
            ..CompareRequest::default()
        }
        .plan(Vec::new())
        .unwrap_err();
        assert!(e.to_string().contains("test_map"), "{e}");
    }
}
