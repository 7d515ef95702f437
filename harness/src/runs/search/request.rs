//! The request of a failure search ([`SearchRequest`]): every choice its user makes, as
//! one serde value that the command line builds from its flags, the Python package from
//! keyword arguments ([`crate::runs::request::from_fields`]) and the Ray driver from
//! either. Its one planning ([`SearchRequest::setup`], [`SearchRequest::plan`]) owns the
//! defaults, the checks, the choice of agents and their identity; its errors name the
//! request's field ([`Error::Request`]).

use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use unforeseen_agent::persist::AgentBundle;

use crate::episodes::methods::Method;
use crate::episodes::protocol::Protocol;
use crate::error::Error;
use crate::limits::check_episodes;
use crate::progress::Progress;
use crate::runs::batch::request::{AgentFields, resolve_jobs};
use crate::runs::batch::{AgentChoice, Shard};
use crate::runs::outputs::Guarded;
use crate::training::seed_agents::{Agent, DEFAULT_CACHE, TrainSeeds, train_agents};
use crate::training::{DEFAULT_TRAIN_EPISODES, DEFAULT_TRAIN_MAP, TimeoutAs};

use super::{DEFAULT_MAX_FAILURES, DEFAULT_ROUNDS, DEFAULT_SOBOL_SHARE, SearchConfig, Space, Summary};

/// What determines the agents of a search of a scripted method: there are none.
pub const SCRIPTED_METHOD: &str = "none (a scripted method)";

/// Every choice of a failure search, with its defaults ([`SearchRequest::default`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SearchRequest {
    /// The space file (RON; maps/README.md, "Space files"). Required.
    pub space: PathBuf,
    /// The base map (file or embedded name) that the space varies. Default `jaywalk`.
    pub map: String,
    /// The method searched for failures. Default `scaled`.
    pub method: Method,
    /// The method's evaluation protocol on each candidate. Default zero-shot.
    pub protocol: Protocol,
    /// Candidates of the Sobol and adaptive stages (minimisation tries come on top).
    /// Default 100.
    pub budget: usize,
    /// Episodes per candidate, for each witness and for the method (per training seed).
    /// Default 20.
    pub episodes: u64,
    /// Run seed: Sobol scrambling, adaptive draws and every episode derive from it.
    /// Default 7.
    pub seed: u64,
    /// Share of the budget for the Sobol stage, in (0, 1]. Default
    /// [`DEFAULT_SOBOL_SHARE`].
    pub sobol_share: f64,
    /// Rounds of the adaptive stage. Default [`DEFAULT_ROUNDS`].
    pub rounds: usize,
    /// Failures minimised and written as maps. Default [`DEFAULT_MAX_FAILURES`].
    pub max_failures: usize,
    /// Worker threads, 1 to [`MAX_JOBS`](crate::limits::MAX_JOBS); results do not depend on it. Default: none,
    /// which takes every core of the machine.
    pub jobs: Option<usize>,
    /// Evaluate only this shard of the Sobol stage. Default: none.
    pub shard: Option<Shard>,
    /// Keep the complete candidates of the same search in `out` and evaluate the rest.
    /// Default false.
    pub resume: bool,
    /// Output folder. Default `out/search`.
    pub out: PathBuf,
    /// Replace files in `out` that a search did not write. Default false.
    pub force: bool,
    /// An agent file (from `unforeseen train`). Default: none.
    pub agent: Option<PathBuf>,
    /// One agent per training seed, each trained on `train_map` (a list, or text such as
    /// `1..10`). Default: none.
    pub train_seeds: Option<TrainSeeds>,
    /// The training map (file or embedded name) of agents trained here. Default
    /// `intersection`.
    pub train_map: String,
    /// Training episodes of agents trained here. Default [`DEFAULT_TRAIN_EPISODES`].
    pub train_episodes: u64,
    /// What a training episode's time-out is to the learners. Default truncation.
    pub timeout_as: TimeoutAs,
    /// The folder of the agent cache of `train_seeds`; none: no cache. Default
    /// [`DEFAULT_CACHE`].
    pub cache: Option<PathBuf>,
}

impl Default for SearchRequest {
    fn default() -> Self {
        SearchRequest {
            space: PathBuf::new(),
            map: crate::maps::DEFAULT_TEST_MAP.into(),
            method: Method::Scaled,
            protocol: Protocol::ZeroShot,
            budget: 100,
            episodes: 20,
            seed: unforeseen_env::seeds::DEFAULT_SEED,
            sobol_share: DEFAULT_SOBOL_SHARE,
            rounds: DEFAULT_ROUNDS,
            max_failures: DEFAULT_MAX_FAILURES,
            jobs: None,
            shard: None,
            resume: false,
            out: PathBuf::from("out/search"),
            force: false,
            agent: None,
            train_seeds: None,
            train_map: DEFAULT_TRAIN_MAP.to_string(),
            train_episodes: DEFAULT_TRAIN_EPISODES,
            timeout_as: TimeoutAs::Truncation,
            cache: Some(PathBuf::from(DEFAULT_CACHE)),
        }
    }
}

/// A search request checked and resolved, before any file is written.
#[derive(Debug, Clone)]
pub struct SearchSetup {
    /// The request.
    pub request: SearchRequest,
    /// The space, with its base map.
    pub space: Space,
    /// The agents (none for a scripted method).
    pub agents: AgentChoice,
    /// The training seeds (`[None]` for a scripted method).
    pub train_seeds: Vec<Option<u64>>,
    /// What determines the agents, for the search's identity.
    pub agents_identity: String,
    /// Worker threads.
    pub jobs: usize,
}

impl SearchRequest {
    /// Checks the request and resolves it: loads the base map, the space (and the agent
    /// file), checks the budget and the Sobol share, chooses the agents and says what
    /// determines them. `given` is an agent given loaded instead of the file `agent`.
    /// Writes nothing.
    pub fn setup(&self, given: Option<AgentBundle>) -> Result<SearchSetup, Error> {
        check_episodes("episodes", self.episodes)?;
        check_episodes("train_episodes", self.train_episodes)?;
        let jobs = resolve_jobs(self.jobs)?;
        if self.space.as_os_str().is_empty() {
            return Err(Error::request(
                "space",
                "give a space file, e.g. maps/spaces/jaywalk.ron",
            ));
        }
        let agent_fields = AgentFields {
            agent: self.agent.as_deref(),
            train_seeds: self.train_seeds.as_ref(),
            train_map: &self.train_map,
            train_episodes: self.train_episodes,
            timeout_as: self.timeout_as,
            cache: self.cache.as_ref(),
            seed: self.seed,
        };
        agent_fields.check(given.is_some(), "search with one agent")?;
        let base = crate::maps::load(&self.map)?;
        let space = Space::load(&self.space, &base)?;
        SearchConfig::check_arguments(&space, self.budget, self.sobol_share)?;
        let (agents, train_seeds, agents_identity) =
            agent_fields.choose(given, self.method.is_scripted().then_some(SCRIPTED_METHOD))?;
        Ok(SearchSetup {
            request: self.clone(),
            space,
            agents,
            train_seeds,
            agents_identity,
            jobs,
        })
    }

    /// [`SearchRequest::setup`], then the output guard (the folder `out`, none of the
    /// inputs in it; taken and held by the job). Trains and runs nothing.
    pub fn plan(&self, given: Option<AgentBundle>) -> Result<SearchJob, Error> {
        let setup = self.setup(given)?;
        let mut guard = super::output::outputs(&self.out)
            .input("map", &self.map)
            .input("space", &self.space);
        if let Some(agent) = &self.agent {
            guard = guard.input("agent", agent);
        }
        if matches!(setup.agents, AgentChoice::Trained { .. }) {
            guard = guard.input("train_map", &self.train_map);
        }
        let guard = guard.guard(self.force || self.resume)?;
        Ok(SearchJob { setup, guard })
    }
}

impl SearchSetup {
    /// The search's configuration with `agents`, `jobs` threads, and `command` for the
    /// failure maps' comments.
    pub fn config<'a>(&'a self, agents: &'a [Agent], jobs: usize, command: String) -> SearchConfig<'a> {
        let r = &self.request;
        SearchConfig {
            space: &self.space,
            method: r.method,
            agents,
            train_seeds: &self.train_seeds,
            agents_identity: self.agents_identity.clone(),
            protocol: r.protocol,
            budget: r.budget,
            episodes: r.episodes,
            seed: r.seed,
            jobs,
            shard: r.shard,
            sobol_share: r.sobol_share,
            rounds: r.rounds,
            max_failures: r.max_failures,
            command,
        }
    }

    /// The training seeds of the agents to train (none for an agent given or a scripted
    /// method).
    pub fn to_train(&self) -> &[u64] {
        match &self.agents {
            AgentChoice::Trained { seeds, .. } => seeds,
            _ => &[],
        }
    }

    /// The search's agents: the one given, or one per training seed trained in parallel
    /// on the search's threads (or loaded from the agent cache), one phase of `progress`.
    pub fn agents(&self, progress: &dyn Progress) -> Result<Vec<Agent>, Error> {
        match &self.agents {
            AgentChoice::None => Ok(Vec::new()),
            AgentChoice::Given(agent) => Ok(vec![agent.as_ref().clone()]),
            AgentChoice::Trained {
                map,
                seeds,
                config,
                cache,
            } => {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(self.jobs).build()?;
                pool.install(|| train_agents(map, seeds, config, cache.as_deref(), progress))
            }
        }
    }
}

/// A search planned ([`SearchRequest::plan`]), holding its output guard.
pub struct SearchJob {
    /// The request resolved.
    pub setup: SearchSetup,
    guard: Guarded,
}

impl SearchJob {
    /// Runs the search with `agents` ([`SearchSetup::agents`]) into the request's `out`
    /// ([`super::run`]); `command` goes in the failure maps' comments.
    pub fn run(&self, agents: &[Agent], command: String, progress: &dyn Progress) -> Result<Summary, Error> {
        let cfg = self.setup.config(agents, self.setup.jobs, command);
        cfg.check()?;
        let r = &self.setup.request;
        super::run(&cfg, Path::new(&r.out), r.resume, &self.guard, progress)
    }

    /// The output guard held by the job (for a driver that runs the stages itself:
    /// [`super::run_with`]).
    pub fn guard(&self) -> &Guarded {
        &self.guard
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runs::request::from_fields;

    #[test]
    fn a_bad_field_is_named_by_the_request() {
        let fields = |v: serde_json::Value| v.as_object().cloned().unwrap();
        let e = from_fields::<SearchRequest>(fields(serde_json::json!({"protocol": "both"}))).unwrap_err();
        assert!(e.to_string().starts_with("protocol: "), "{e}");
        let e = from_fields::<SearchRequest>(fields(serde_json::json!({"budget": -1}))).unwrap_err();
        assert!(e.to_string().starts_with("budget: "), "{e}");
        let e = SearchRequest::default().setup(None).unwrap_err();
        assert!(e.to_string().starts_with("space: "), "{e}");
        let e = SearchRequest {
            space: "maps/spaces/jaywalk.ron".into(),
            train_seeds: Some(TrainSeeds(vec![1])),
            agent: Some("agent.ron".into()),
            ..SearchRequest::default()
        }
        .setup(None)
        .unwrap_err();
        assert!(e.to_string().starts_with("train_seeds: "), "{e}");
    }

    #[test]
    fn the_training_map_is_part_of_the_agents_identity() {
        let setup = |train_map: &str| {
            SearchRequest {
                space: concat!(env!("CARGO_MANIFEST_DIR"), "/../maps/spaces/jaywalk.ron").into(),
                train_seeds: Some(TrainSeeds(vec![1, 2])),
                train_map: train_map.into(),
                ..SearchRequest::default()
            }
            .setup(None)
        };
        let default = setup(DEFAULT_TRAIN_MAP).unwrap().agents_identity;
        assert!(default.starts_with("trained on intersection for "), "{default}");
        // Agents trained elsewhere are other agents: a folder of one search does not resume the other.
        let other = setup("junction_training").unwrap().agents_identity;
        assert!(other.starts_with("trained on junction_training for "), "{other}");
        assert_ne!(default, other);
        let e = setup("no_such_map.ron").unwrap_err();
        assert!(e.to_string().contains("no_such_map.ron"), "{e}");
        assert!(e.is_user_input(), "{e}");
    }
}
