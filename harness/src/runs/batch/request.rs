//! The request of a batch run ([`BatchRequest`]): every choice its user makes, as one
//! serde value that the command line builds from its flags, the Python package from
//! keyword arguments ([`crate::runs::request::from_fields`]) and the Ray driver from
//! either. Its one planning ([`BatchRequest::setup`], [`BatchRequest::plan`]) owns the
//! defaults, the checks, the choice of agents and the run's identity; its errors name
//! the request's field ([`Error::Request`]), and a front spells the field its own way.
//!
//! A planned run ([`BatchJob`]) holds the output guard until it is dropped, says which
//! agents the units still to run need and trains or loads them ([`BatchJob::agents`]),
//! then runs and writes the results file and its summary ([`BatchJob::run`]).

use serde::{Deserialize, Serialize};
use std::path::PathBuf;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_sim::Map;

use crate::episodes::methods::Method;
use crate::episodes::protocol::{Protocol, ProtocolChoice};
use crate::episodes::survivability::{Witness, careful_witness, warnings};
use crate::error::Error;
use crate::files::write_json;
use crate::limits::{MAX_JOBS, check_episodes};
use crate::progress::{CancelOnly, Progress};
use crate::runs::merge::summary_document;
use crate::runs::outputs::{Guarded, Outputs};
use crate::training::seed_agents::{Agent, DEFAULT_CACHE, TrainSeeds, train_agents};
use crate::training::{DEFAULT_TRAIN_EPISODES, DEFAULT_TRAIN_MAP, TimeoutAs, TrainConfig};

use super::identity::{SCRIPTED_ONLY, agent_file_identity, trained_agents_identity};
use super::plan::{BatchConfig, Plan};
use super::result_line::ResultLine;
use super::run::run_plan;
use super::scenario::{Scenario, ScenarioKind, load_scenarios, load_stream_scenario};
use super::summary::{SummaryRow, summarize};
use super::sweep::{ParamSet, checked_sweep};
use super::units::{DEFAULT_METHODS, Shard};
use crate::runs::outputs::summary_path;

/// Every choice of a batch run, with its defaults ([`BatchRequest::default`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BatchRequest {
    /// Map files, folders of maps (every `*.ron`, sorted) or embedded map names, in
    /// order. Default: none, which runs the embedded maps.
    pub maps: Vec<PathBuf>,
    /// A deployment stream file as the one scenario, instead of maps. Default: none.
    pub stream: Option<PathBuf>,
    /// Methods, in order. Default: none, which runs [`DEFAULT_METHODS`].
    pub methods: Vec<Method>,
    /// Protocols. Default: both.
    pub protocol: ProtocolChoice,
    /// The parameter sweep, one `KEY=V1,V2,...` per parameter: the cross product of the
    /// values ([`super::sweep()`]). Default: none (the default parameters).
    pub sets: Vec<String>,
    /// Episodes per unit. Default 100.
    pub episodes: u64,
    /// Evaluation seed (and, with neither `agent` nor `train_seeds`, the training seed).
    /// Default 7.
    pub seed: u64,
    /// Worker threads, 1 to [`MAX_JOBS`]; results do not depend on it. Default: none,
    /// which takes every core of the machine.
    pub jobs: Option<usize>,
    /// Results file (JSON Lines); the summary goes beside it ([`summary_path`]).
    /// Default `results.jsonl`.
    pub out: PathBuf,
    /// Keep the complete lines of the same run already in `out` and run only the rest.
    /// Default false.
    pub resume: bool,
    /// Replace `out` even when it holds something other than a batch's results.
    /// Default false.
    pub force: bool,
    /// Run only this shard of the canonical unit order. Default: none (every unit).
    pub shard: Option<Shard>,
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

impl Default for BatchRequest {
    fn default() -> Self {
        BatchRequest {
            maps: Vec::new(),
            stream: None,
            methods: Vec::new(),
            protocol: ProtocolChoice::Both,
            sets: Vec::new(),
            episodes: crate::limits::DEFAULT_EPISODES,
            seed: unforeseen_env::seeds::DEFAULT_SEED,
            jobs: None,
            out: PathBuf::from("results.jsonl"),
            resume: false,
            force: false,
            shard: None,
            agent: None,
            train_seeds: None,
            train_map: DEFAULT_TRAIN_MAP.to_string(),
            train_episodes: DEFAULT_TRAIN_EPISODES,
            timeout_as: TimeoutAs::Truncation,
            cache: Some(PathBuf::from(DEFAULT_CACHE)),
        }
    }
}

/// The agents a batch runs.
#[derive(Debug, Clone)]
pub enum AgentChoice {
    /// None: scripted methods only, with no agent given.
    None,
    /// One agent: an agent file's, or one given loaded.
    Given(Box<Agent>),
    /// One agent per seed, trained on `map` with `config` (its seed replaced by each),
    /// kept in the agent cache `cache` when there is one.
    Trained {
        /// The training map.
        map: Box<Map>,
        /// The training seeds.
        seeds: Vec<u64>,
        /// The training configuration.
        config: Box<TrainConfig>,
        /// The agent cache's folder.
        cache: Option<PathBuf>,
    },
}

impl AgentChoice {
    /// The one agent of a job that runs one (eval, learn, trace): none, the one given,
    /// or the one trained (one phase of `progress`).
    pub fn one(&self, progress: &dyn Progress) -> Result<Option<AgentBundle>, Error> {
        Ok(match self {
            AgentChoice::None => None,
            AgentChoice::Given(agent) => Some(agent.bundle.clone()),
            AgentChoice::Trained { map, seeds, config, .. } => train_agents(map, seeds, config, None, progress)?
                .into_iter()
                .next()
                .map(|a| a.bundle),
        })
    }
}

/// A batch request checked and resolved, before any file is written: what runs, with
/// which agents, and the identity of those agents.
#[derive(Debug, Clone)]
pub struct BatchSetup {
    /// The scenarios, in order.
    pub scenarios: Vec<Scenario>,
    /// The methods, in order.
    pub methods: Vec<Method>,
    /// The parameter sets, in order.
    pub params: Vec<ParamSet>,
    /// The protocols, in order.
    pub protocols: Vec<Protocol>,
    /// The agents.
    pub agents: AgentChoice,
    /// The training-seed axis of the units (`[agent's seed]` for one agent, `[None]` for
    /// none).
    pub train_seeds: Vec<Option<u64>>,
    /// What determines the agents, for the run's identity.
    pub agents_identity: String,
    /// Episodes per unit.
    pub episodes: u64,
    /// Evaluation seed.
    pub seed: u64,
    /// Worker threads.
    pub jobs: usize,
}

/// Worker threads asked for (`jobs`): 1 to [`MAX_JOBS`], or every core of the machine.
pub(crate) fn resolve_jobs(jobs: Option<usize>) -> Result<usize, Error> {
    match jobs {
        None => Ok(std::thread::available_parallelism()
            .map_or(1, |n| n.get())
            .min(MAX_JOBS)),
        Some(n) if (1..=MAX_JOBS).contains(&n) => Ok(n),
        Some(n) => Err(Error::OutOfRange {
            field: "jobs".into(),
            value: n.to_string(),
            expected: format!("1..={MAX_JOBS} worker threads"),
        }),
    }
}

/// The fields that say which agents a run uses, as the batch and search requests hold
/// them: one choice of agents for both.
pub(crate) struct AgentFields<'a> {
    /// An agent file.
    pub agent: Option<&'a std::path::Path>,
    /// One agent per training seed.
    pub train_seeds: Option<&'a TrainSeeds>,
    /// The training map of agents trained here.
    pub train_map: &'a str,
    /// Training episodes of agents trained here.
    pub train_episodes: u64,
    /// What a training episode's time-out is to the learners.
    pub timeout_as: TimeoutAs,
    /// The agent cache of `train_seeds`.
    pub cache: Option<&'a PathBuf>,
    /// The run seed: the training seed of the one agent trained when none is given.
    pub seed: u64,
}

impl<'a> AgentFields<'a> {
    /// The fields of a job that runs one agent (eval, learn, trace): the agent file, or
    /// none, which trains one on the default training map with the default episodes and
    /// the run `seed`, not cached.
    pub fn one(agent: Option<&'a std::path::Path>, seed: u64) -> Self {
        AgentFields {
            agent,
            train_seeds: None,
            train_map: DEFAULT_TRAIN_MAP,
            train_episodes: DEFAULT_TRAIN_EPISODES,
            timeout_as: TimeoutAs::Truncation,
            cache: None,
            seed,
        }
    }
    /// Checks that the fields and an agent given loaded (`given`) name one choice of
    /// agents; `one_agent` says what one agent does, for the error when both
    /// `train_seeds` and an agent are given. Reads no file.
    pub fn check(&self, given: bool, one_agent: &str) -> Result<(), Error> {
        if self.train_seeds.is_some() && (self.agent.is_some() || given) {
            return Err(Error::request(
                "train_seeds",
                format!("give train_seeds or agent, not both (train one agent per seed, or {one_agent})"),
            ));
        }
        if self.agent.is_some() && given {
            return Err(Error::request("agent", "give one agent"));
        }
        Ok(())
    }

    /// The agents ([`AgentFields::check`]ed), their training-seed axis and what
    /// determines them: `given` (an agent given loaded) or the agent file; one per
    /// training seed; none when `scripted` (the identity of a run with scripted methods
    /// only) is given and no agent is; else one trained with the run seed, not cached.
    pub fn choose(
        &self,
        given: Option<AgentBundle>,
        scripted: Option<&str>,
    ) -> Result<(AgentChoice, Vec<Option<u64>>, String), Error> {
        let trained = |seeds: Vec<u64>, cache: Option<PathBuf>| -> Result<_, Error> {
            let map = crate::maps::load(self.train_map)?;
            let axis: Vec<Option<u64>> = seeds.iter().map(|&s| Some(s)).collect();
            let config = TrainConfig {
                timeout_as: self.timeout_as,
                ..TrainConfig::new(self.train_episodes, 0)
            };
            let identity = trained_agents_identity(&map, &axis, &config)?;
            let choice = AgentChoice::Trained {
                map: Box::new(map),
                seeds,
                config: Box::new(config),
                cache,
            };
            Ok((choice, axis, identity))
        };
        let given = match (given, self.agent) {
            (Some(bundle), _) => Some(bundle),
            (None, Some(file)) => Some(crate::training::agent_file::load(file)?),
            (None, None) => None,
        };
        match (self.train_seeds, given, scripted) {
            (Some(seeds), _, _) => trained(seeds.0.clone(), self.cache.cloned()),
            (None, Some(bundle), _) => {
                let identity = agent_file_identity(&bundle);
                let agent = Agent::from_bundle(bundle);
                let axis = vec![agent.train_seed];
                Ok((AgentChoice::Given(Box::new(agent)), axis, identity))
            }
            (None, None, Some(scripted)) => Ok((AgentChoice::None, vec![None], scripted.to_string())),
            // One agent trained with the run seed, not cached.
            (None, None, None) => trained(vec![self.seed], None),
        }
    }
}

impl BatchRequest {
    /// Checks the request and resolves it: loads the scenarios (and the agent file),
    /// expands the sweep, chooses the agents and says what determines them. `given` is
    /// an agent given loaded instead of the file `agent` (Python's `Agent`). Writes
    /// nothing.
    pub fn setup(&self, given: Option<AgentBundle>) -> Result<BatchSetup, Error> {
        check_episodes("episodes", self.episodes)?;
        check_episodes("train_episodes", self.train_episodes)?;
        let jobs = resolve_jobs(self.jobs)?;
        if self.stream.is_some() && !self.maps.is_empty() {
            return Err(Error::request("stream", "give maps or a stream, not both"));
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
        agent_fields.check(given.is_some(), "run one agent")?;
        let scenarios = match &self.stream {
            Some(file) => vec![load_stream_scenario(file)?],
            None => load_scenarios(&self.maps)?,
        };
        let methods = if self.methods.is_empty() {
            DEFAULT_METHODS.to_vec()
        } else {
            self.methods.clone()
        };
        let params = checked_sweep(&self.sets)?;
        let protocols = self.protocol.protocols();
        let scripted_only = methods.iter().all(|m| m.is_scripted());
        let (agents, train_seeds, agents_identity) =
            agent_fields.choose(given, scripted_only.then_some(SCRIPTED_ONLY))?;
        Ok(BatchSetup {
            scenarios,
            methods,
            params,
            protocols,
            agents,
            train_seeds,
            agents_identity,
            episodes: self.episodes,
            seed: self.seed,
            jobs,
        })
    }

    /// [`BatchRequest::setup`], then the output guard (`out` and its summary, none of
    /// them an input; taken and held by the job) and the plan: the units, the shard, the
    /// identity and the lines `resume` keeps. Trains and runs nothing.
    pub fn plan(&self, given: Option<AgentBundle>) -> Result<BatchJob, Error> {
        let setup = self.setup(given)?;
        let mut guard = Outputs::results("out", &self.out);
        if let Some(agent) = &self.agent {
            guard = guard.input("agent", agent);
        }
        for s in &setup.scenarios {
            guard = match (&s.kind, &self.stream) {
                (ScenarioKind::Stream(stream), Some(file)) => guard.stream("stream", file, &stream.files),
                _ => guard.input("maps", &s.source),
            };
        }
        let guard = guard.guard(self.force || self.resume)?;
        let plan = setup.config(&[], setup.jobs, self.shard).plan(&self.out, self.resume)?;
        Ok(BatchJob {
            setup,
            plan,
            out: self.out.clone(),
            shard: self.shard,
            _guard: guard,
        })
    }
}

impl BatchSetup {
    /// The run's configuration with `agents` on `jobs` threads.
    pub fn config<'a>(&'a self, agents: &'a [Agent], jobs: usize, shard: Option<Shard>) -> BatchConfig<'a> {
        BatchConfig {
            agents,
            train_seeds: &self.train_seeds,
            scenarios: &self.scenarios,
            methods: &self.methods,
            params: &self.params,
            protocols: &self.protocols,
            episodes: self.episodes,
            seed: self.seed,
            jobs,
            shard,
            agents_identity: self.agents_identity.clone(),
        }
    }
}

/// A batch run planned ([`BatchRequest::plan`]), holding its output guard.
pub struct BatchJob {
    /// The request resolved.
    pub setup: BatchSetup,
    /// The plan: units, shard, identity, kept lines.
    pub plan: Plan,
    /// The results file.
    pub out: PathBuf,
    /// The shard run.
    pub shard: Option<Shard>,
    _guard: Guarded,
}

/// Worker threads for a run, bounded by memory ([`BatchJob::workers`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Workers {
    /// The threads to run on.
    pub jobs: usize,
    /// When fewer than asked: the bytes of one copy of the learners and the bytes
    /// available.
    pub bounded: Option<(u64, u64)>,
}

/// A batch run's outcome: its lines, its summary, and what a front reports of them.
#[derive(Debug, Clone)]
pub struct BatchReport {
    /// Every line of the results file after its identity, in canonical order.
    pub lines: Vec<ResultLine>,
    /// The summary's rows over training seeds.
    pub rows: Vec<SummaryRow>,
    /// The summary file written beside the results.
    pub summary: PathBuf,
    /// Expectations checked on the mean over training seeds.
    pub checked: usize,
    /// One message per expectation failed ([`crate::runs::batch::table::expectation_failures`]).
    pub failures: Vec<String>,
    /// The survivability warnings of the maps on which the scripted references ran, as
    /// `check-map` gives them ([`survivability_warnings`]).
    pub survivability: Vec<String>,
}

impl BatchJob {
    /// The training seeds of the agents the units still to run need, when the run trains
    /// its agents (none for an agent given, or scripted methods only).
    pub fn to_train(&self) -> Vec<u64> {
        match &self.setup.agents {
            AgentChoice::Trained { .. } => self.plan.train_seeds_to_run(),
            _ => Vec::new(),
        }
    }

    /// The agents the units still to run need: the one given, or those of
    /// [`BatchJob::to_train`] trained in parallel on the run's threads (or loaded from
    /// the agent cache), one phase of `progress`.
    pub fn agents(&self, progress: &dyn Progress) -> Result<Vec<Agent>, Error> {
        match &self.setup.agents {
            AgentChoice::None => Ok(Vec::new()),
            AgentChoice::Given(agent) => Ok(vec![agent.as_ref().clone()]),
            AgentChoice::Trained { map, config, cache, .. } => {
                let seeds = self.to_train();
                if seeds.is_empty() {
                    return Ok(Vec::new());
                }
                let pool = rayon::ThreadPoolBuilder::new().num_threads(self.setup.jobs).build()?;
                pool.install(|| train_agents(map, &seeds, config, cache.as_deref(), progress))
            }
        }
    }

    /// The run's threads for `agents`: fewer than asked when that many workers' copies of
    /// the learners (each running episode learns on its own copy) would take more than
    /// half the memory available. Results do not depend on it.
    pub fn workers(&self, agents: &[Agent]) -> Workers {
        let states = agents.iter().map(|a| a.bundle.bayes_rl.n_states()).max().unwrap_or(0);
        memory_bound_jobs(self.setup.jobs, states, available_bytes())
    }

    /// Runs the units still to run with `agents` ([`BatchJob::agents`]) on `jobs`
    /// threads ([`BatchJob::workers`]), streaming each line to the results file, then
    /// writes the summary beside it. One phase of `progress`.
    pub fn run(&self, agents: &[Agent], jobs: usize, progress: &dyn Progress) -> Result<BatchReport, Error> {
        let cfg = self.setup.config(agents, jobs, self.shard);
        let lines = run_plan(&cfg, &self.plan, &self.out, progress)?;
        let rows = summarize(&lines);
        let summary = summary_path(&self.out);
        let shard = self.shard.map(String::from);
        write_json(
            &summary,
            &summary_document(&self.out, shard.as_deref(), &self.plan.identity, &rows),
        )?;
        Ok(BatchReport {
            checked: rows.iter().map(|r| r.checks.len()).sum(),
            failures: crate::runs::batch::table::expectation_failures(&rows),
            survivability: survivability_warnings(&self.setup.scenarios, &lines, progress)?,
            lines,
            rows,
            summary,
        })
    }
}

/// Bytes of one copy of an agent's learners with `states` joint states (the world model
/// and Bayesian RL keep dense N x N matrices per action: about 370 bytes x N²).
fn learner_bytes(states: usize) -> u64 {
    370 * (states as u64).pow(2)
}

/// The memory the system says is available (`MemAvailable` of /proc/meminfo), if known.
fn available_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// `jobs`, or fewer when that many copies of learners of `states` states would take more
/// than half of `available` bytes.
fn memory_bound_jobs(jobs: usize, states: usize, available: Option<u64>) -> Workers {
    let per = learner_bytes(states);
    let Some(available) = available else {
        return Workers { jobs, bounded: None };
    };
    let fit = ((available / 2) / per.max(1)).max(1) as usize;
    if jobs > fit {
        Workers {
            jobs: fit,
            bounded: Some((per, available)),
        }
    } else {
        Workers { jobs, bounded: None }
    }
}

/// The survivability warnings of `check-map` for the map scenarios with pedestrian
/// rules on which the batch ran the scripted references, each prefixed with the
/// scenario's source: never-brake's from its line among `lines`, brake-on-pedestrian's
/// from the careful cruises `check-map` drives ([`careful_witness`]), at the episodes
/// and seed of its line (whose figures are the top-speed cruise's), so that batch and
/// `check-map --seed S` give one verdict. Scripted methods ignore parameter sets,
/// protocols and training seeds, so the first line of each is taken. Stops when
/// `progress` asks ([`Error::Interrupted`]).
pub fn survivability_warnings(
    scenarios: &[Scenario],
    lines: &[ResultLine],
    progress: &dyn Progress,
) -> Result<Vec<String>, Error> {
    let line = |scenario: &str, method: Method| {
        lines
            .iter()
            .find(|l| l.scenario == scenario && l.method == method.name())
    };
    let mut out = Vec::new();
    for (s, map) in scenarios.iter().filter_map(|s| s.map().map(|map| (s, map))) {
        if map.pedestrians.is_empty() {
            continue;
        }
        let name = &map.name;
        let brake = match line(name, Method::BrakeOnPedestrian) {
            Some(l) => Some(careful_witness(map, l.episodes, l.seed, &CancelOnly(progress))?.0),
            None => None,
        };
        let never_brake = line(name, Method::NeverBrake).map(|l| Witness {
            episodes: l.episodes,
            success_rate: l.success_rate,
            collision_rate: l.collision_rate,
            timeout_rate: l.timeout_rate,
            cruise: 1.0,
        });
        out.extend(
            warnings(name, brake.as_ref(), never_brake.as_ref())
                .into_iter()
                .map(|w| format!("{}: {w}", s.source)),
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runs::request::from_fields;

    #[test]
    fn jobs_are_bounded_by_the_memory_of_the_learners_copies() {
        // 64 states (the embedded maps): 1.5 MB a copy, never a bound.
        assert_eq!(memory_bound_jobs(16, 64, Some(1 << 30)).jobs, 16);
        // A million states would be 370 TB a copy: one worker.
        let w = memory_bound_jobs(16, 1 << 20, Some(1 << 30));
        assert_eq!((w.jobs, w.bounded.map(|b| b.1)), (1, Some(1 << 30)));
        assert_eq!(memory_bound_jobs(16, 1 << 20, None).jobs, 16);
    }

    #[test]
    fn a_bad_field_is_named_by_the_request() {
        let fields = |v: serde_json::Value| v.as_object().cloned().unwrap();
        let e = from_fields::<BatchRequest>(fields(serde_json::json!({"train_seeds": "3..1"}))).unwrap_err();
        assert!(e.to_string().starts_with("train_seeds: "), "{e}");
        assert!(e.is_user_input());
        let e = from_fields::<BatchRequest>(fields(serde_json::json!({"protocol": "sometimes"}))).unwrap_err();
        assert!(e.to_string().starts_with("protocol: "), "{e}");
        let e = from_fields::<BatchRequest>(fields(serde_json::json!({"episodez": 3}))).unwrap_err();
        assert!(e.to_string().starts_with("episodez: not a field"), "{e}");
        let r =
            from_fields::<BatchRequest>(fields(serde_json::json!({"train_seeds": [1, 2], "shard": "1/2"}))).unwrap();
        assert_eq!(r.train_seeds.map(|s| s.0), Some(vec![1, 2]));
        assert_eq!(r.shard, Some(Shard { index: 1, count: 2 }));
    }

    #[test]
    fn what_a_time_out_is_to_the_learners_is_part_of_the_agents_identity() {
        let identity = |timeout_as| {
            BatchRequest {
                train_seeds: Some(TrainSeeds(vec![1, 2])),
                timeout_as,
                ..BatchRequest::default()
            }
            .setup(None)
            .unwrap()
            .agents_identity
        };
        // Agents trained otherwise are other agents: a file of one run does not resume the other.
        assert_ne!(identity(TimeoutAs::Truncation), identity(TimeoutAs::Termination));
    }

    #[test]
    fn conflicting_fields_are_refused_before_any_work() {
        let r = BatchRequest {
            train_seeds: Some(TrainSeeds(vec![1])),
            agent: Some(PathBuf::from("agent.ron")),
            ..BatchRequest::default()
        };
        let e = r.setup(None).unwrap_err();
        assert!(e.to_string().starts_with("train_seeds: "), "{e}");
        let e = BatchRequest {
            jobs: Some(0),
            ..BatchRequest::default()
        }
        .setup(None)
        .unwrap_err();
        assert!(e.to_string().starts_with("jobs 0: "), "{e}");
    }
}
