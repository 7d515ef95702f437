//! Headless batch runs of scenario suites: every (scenario, method, parameter set,
//! protocol, training seed) is a unit of work; units run in parallel (rayon) and each
//! finished unit is streamed as one JSON line. Seeds derive from (seed, scenario, method,
//! episode), never from thread order, so results are identical whatever the number of
//! jobs; `--shard i/n` takes a contiguous slice of the canonical unit order, so shards
//! concatenate into the file a single run writes. A method that does not learn across
//! episodes is run once per (scenario, parameter set, seed), and its line covers every
//! protocol asked. Over training seeds, [`summarize`] gives each figure's mean, 95%
//! interval, range and worst seed, and checks the maps' expectations on the mean.
//!
//! A scenario is a map or a deployment stream ([`ScenarioKind`], [`load_stream_scenario`]):
//! a stream's unit runs its episodes over the stream's maps ([`evaluate_stream`]) and its
//! line is a line like a map's (the figures over the whole stream) with the figures per
//! map within the stream added ([`ResultLine::per_map`]); the summary follows the stream's
//! row with one row per map, and [`stream_learning`] compares each map's figures under
//! the two protocols.
//!
//! A results file starts with the [`RunIdentity`] of the run that wrote it (program
//! version, agents, map contents, methods, parameter sets, protocols, training seeds,
//! episodes, seed). `--resume` refuses a file of another run, saying what differs, and
//! keeps the lines it reuses byte for byte.
//!
//! [`BatchConfig::plan`] computes once what a run does (its units, its shard of them, its
//! identity and the lines `--resume` keeps) before any agent is needed, so a caller can
//! train only the agents the units still to run use ([`Plan::train_seeds_to_run`]), then
//! [`run_plan`] runs it.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::io::Write;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use unforeseen_agent::param_table;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_sim::{Action, Map};

use crate::agents::Agent;
use crate::error::Error;
use crate::experiments::evaluate_under;
use crate::methods::Method;
use crate::metrics::Aggregate;
use crate::progress::{NoProgress, Progress};
use crate::protocol::{Protocol, covered};
use crate::runner::EpisodeResult;
use crate::stats::Stat;
use crate::stream::{Stream, evaluate_stream, per_map};

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
    /// A deployment stream ([`crate::stream`]): each episode on the map the stream's order
    /// gives it; the unit's line adds the figures per map within the stream
    /// ([`ResultLine::per_map`]).
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
    fn content_hash(&self) -> String {
        let text = match &self.kind {
            ScenarioKind::Map(map) => serde_json::to_string(map),
            ScenarioKind::Stream(s) => serde_json::to_string(&("stream", &s.name, &s.maps, s.order)),
        };
        crate::seeds::content_hash(text.unwrap_or_default().as_bytes())
    }
}

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

/// The methods a batch runs unless told otherwise: the paper's three and the scripted
/// references (so every map reports whether it is survivable and dangerous).
pub const DEFAULT_METHODS: [Method; 5] = [
    Method::QLearning,
    Method::BayesRl,
    Method::Scaled,
    Method::BrakeOnPedestrian,
    Method::NeverBrake,
];

/// Most parameter sets one sweep may have (the cross product of its `--set` lists).
pub const MAX_PARAM_SETS: usize = 10_000;

/// Expands `--set key=v1,v2` options into the cross product of parameter sets, in the
/// order the options were given (the last varies fastest). Values equal after parsing
/// (`omega=0.5,5e-1`) count once, in the order of their first occurrence.
/// At most [`MAX_PARAM_SETS`] sets.
pub fn sweep(sets: &[String]) -> Result<Vec<ParamSet>, Error> {
    let mut out = vec![ParamSet(Vec::new())];
    let mut keys: Vec<&str> = Vec::new();
    for set in sets {
        let flag = format!("--set {set}");
        let (key, values) = set
            .split_once('=')
            .ok_or_else(|| Error::flag(&flag, "expected KEY=V1,V2,..., e.g. --set horizon=1,2,3"))?;
        let key = key.trim();
        // `epsilon` and `gate.epsilon` are one parameter.
        let canonical = param_table::lookup(key).map_or(key, |k| k.name.as_str());
        if keys.contains(&canonical) {
            return Err(Error::flag(
                &flag,
                format!("`{key}` is set twice; give all its values in one --set, e.g. --set {key}=1,2"),
            ));
        }
        keys.push(canonical);
        let listed: Vec<&str> = values.split(',').map(str::trim).collect();
        if listed.iter().any(|v| v.is_empty()) {
            return Err(Error::flag(
                &flag,
                format!("an empty value; separate values by single commas, e.g. --set {key}=1,2"),
            ));
        }
        // Equal values (after parsing: `0.5` and `5e-1`) give one parameter set, the first
        // spelling kept. A value that does not parse on its own is kept as written: the
        // error, if any, comes when the sets are applied.
        let parsed = |v: &str| {
            let mut p = ScaledParams::default();
            p.set_str(key, v).and_then(|()| p.get(key)).ok()
        };
        let mut values: Vec<&str> = Vec::new();
        let mut seen: Vec<Result<serde_json::Value, &str>> = Vec::new();
        for v in listed {
            let id = parsed(v).ok_or(v);
            if !seen.contains(&id) {
                seen.push(id);
                values.push(v);
            }
        }
        if out.len().saturating_mul(values.len()) > MAX_PARAM_SETS {
            return Err(Error::flag(
                &flag,
                format!(
                    "the sweep would have {} parameter sets (at most {MAX_PARAM_SETS}: each runs every scenario and protocol); sweep fewer values, or split the sweep over several runs",
                    out.len().saturating_mul(values.len())
                ),
            ));
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
        let sets: Vec<String> = self.0.iter().map(|(k, v)| format!("{k}={v}")).collect();
        crate::overrides::apply(ScaledParams::default(), &sets)
    }
}

/// One unit of work.
#[derive(Debug, Clone)]
pub struct Unit {
    /// Position in the canonical order.
    pub index: usize,
    /// Index into the scenarios.
    pub scenario: usize,
    /// Method.
    pub method: Method,
    /// Parameter set.
    pub params: ParamSet,
    /// The protocol the unit runs under.
    pub protocol: Protocol,
    /// Every protocol asked that the unit's results hold for (more than `protocol` only
    /// for a method that does not learn across episodes).
    pub covers: Vec<Protocol>,
    /// Training seed of the agent it runs.
    pub train_seed: Option<u64>,
}

impl Unit {
    /// The unit's identity, as its result line's [`ResultLine::key`] gives it.
    pub fn key(&self, scenarios: &[Scenario]) -> UnitKey {
        (
            scenarios[self.scenario].name().to_string(),
            self.method.name().to_string(),
            self.params.label(),
            self.protocol,
            self.train_seed,
        )
    }
}

/// All units in canonical order: scenarios, then methods, then parameter sets, then
/// protocols (one unit for a method that does not learn across episodes), then
/// training seeds (innermost, so one configuration's seeds are contiguous).
pub fn units(
    n_scenarios: usize,
    methods: &[Method],
    params: &[ParamSet],
    protocols: &[Protocol],
    train_seeds: &[Option<u64>],
) -> Result<Vec<Unit>, Error> {
    let mut out = Vec::new();
    // Parameter sets change only the scaled agent: every other method runs once, with the
    // defaults, instead of repeating identical rows for every point of a sweep.
    let defaults = [ParamSet(Vec::new())];
    for scenario in 0..n_scenarios {
        for &method in methods {
            let params = if method.is_scaled() { params } else { &defaults[..] };
            for p in params {
                let scaled = p.scaled_params()?;
                let mut seen: Vec<Protocol> = Vec::new();
                for &protocol in protocols {
                    let covers = covered(method, &scaled, protocol, protocols);
                    if seen.iter().any(|s| covers.contains(s)) {
                        continue; // already covered by an earlier unit
                    }
                    seen.extend(&covers);
                    for &train_seed in train_seeds {
                        out.push(Unit {
                            index: out.len(),
                            scenario,
                            method,
                            params: p.clone(),
                            protocol,
                            covers: covers.clone(),
                            train_seed,
                        });
                    }
                }
            }
        }
    }
    Ok(out)
}

/// A shard `i/n` (1-based): the contiguous slice `[(i-1)U/n, iU/n)` of `U` units.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// 1-based shard number.
    pub index: usize,
    /// Number of shards.
    pub count: usize,
}

impl std::str::FromStr for Shard {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let bad = || format!("'{s}': expected I/N with 1 <= I <= N, e.g. 2/8");
        let (i, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count): (usize, usize) = (
            i.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if count == 0 || index == 0 || index > count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl Shard {
    /// The range of unit positions this shard runs.
    pub fn range(self, total: usize) -> std::ops::Range<usize> {
        ((self.index - 1) * total / self.count)..(self.index * total / self.count)
    }
}

/// One checked expectation of a map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Check {
    /// The figure checked, e.g. `success_rate`.
    pub figure: String,
    /// `min` or `max`.
    pub bound: String,
    /// The bound's value.
    pub limit: f64,
    /// What we measured.
    pub value: f64,
    /// Whether the bound held.
    pub pass: bool,
}

/// One result line of a batch (JSON Lines).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResultLine {
    /// Position in the canonical unit order of the whole run.
    pub unit: usize,
    /// Scenario (map) name.
    pub scenario: String,
    /// Map file or `embedded:NAME`.
    pub source: String,
    /// Method name.
    pub method: String,
    /// Parameter set label (`default` when no overrides).
    pub param_set: String,
    /// The overrides, key -> value.
    pub params: Vec<(String, String)>,
    /// The protocol the unit ran under (`zero-shot` or `continual`).
    pub protocol: Protocol,
    /// Every protocol asked that these results hold for: `[protocol]`, or all asked for a
    /// method that does not learn across episodes (identical results, run once).
    pub covers: Vec<Protocol>,
    /// Training seed of the agent (null for an agent file that does not record it).
    pub train_seed: Option<u64>,
    /// Training episodes of the agent (null when unknown).
    pub train_episodes: Option<u64>,
    /// Evaluation seed.
    pub seed: u64,
    /// Episodes run.
    pub episodes: u64,
    /// Mean return.
    pub mean_reward: f64,
    /// Success rate.
    pub success_rate: f64,
    /// Collision rate.
    pub collision_rate: f64,
    /// Time-out rate.
    pub timeout_rate: f64,
    /// Red-light violations per episode (the car entering the crosswalk on red).
    #[serde(default)]
    pub red_light_rate: f64,
    /// Share of ticks that reasoned.
    pub inference_rate: f64,
    /// Reasoning compute in expected-free-energy mat-vecs per tick: inference rate times
    /// the prefix-tree size U + U^2 + ... + U^H (0 for methods that do not plan by EFE).
    pub efe_matvecs_per_tick: f64,
    /// Mean decision ticks per episode.
    pub mean_ticks: f64,
    /// The map's expectations for this method and protocol, checked on this agent alone
    /// (the gate is the check on the mean over training seeds, in the summary).
    pub checks: Vec<Check>,
    /// Wall-clock µs per decision tick (the only field that varies between identical runs).
    pub timing_us_per_tick: f64,
    /// For a stream scenario, the figures of each map within the stream that episodes ran
    /// on, in the stream's order (the line's own figures are over the whole stream); left
    /// out for a map scenario.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub per_map: Vec<MapFigures>,
}

/// The figures of one map within a stream unit: its episodes of the stream only.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapFigures {
    /// The map's name.
    pub map: String,
    /// Episodes of the stream that ran on it (the same for every training seed and
    /// protocol: the stream's order derives from the evaluation seed).
    pub episodes: u64,
    /// Mean return.
    pub mean_reward: f64,
    /// Success rate.
    pub success_rate: f64,
    /// Collision rate.
    pub collision_rate: f64,
    /// Time-out rate.
    pub timeout_rate: f64,
    /// Red-light violations per episode.
    pub red_light_rate: f64,
    /// Share of ticks that reasoned.
    pub inference_rate: f64,
    /// Reasoning compute in EFE mat-vecs per tick (as [`ResultLine::efe_matvecs_per_tick`]).
    pub efe_matvecs_per_tick: f64,
    /// Mean decision ticks per episode.
    pub mean_ticks: f64,
    /// Wall-clock µs per decision tick.
    pub timing_us_per_tick: f64,
}

impl ResultLine {
    /// The line of map `map` within this stream unit's line: its figures, episodes and
    /// scenario (the map's name); no checks. None if no episode of the unit ran on it.
    pub fn within_stream(&self, map: &str) -> Option<ResultLine> {
        let f = self.per_map.iter().find(|f| f.map == map)?;
        Some(ResultLine {
            scenario: f.map.clone(),
            episodes: f.episodes,
            mean_reward: f.mean_reward,
            success_rate: f.success_rate,
            collision_rate: f.collision_rate,
            timeout_rate: f.timeout_rate,
            red_light_rate: f.red_light_rate,
            inference_rate: f.inference_rate,
            efe_matvecs_per_tick: f.efe_matvecs_per_tick,
            mean_ticks: f.mean_ticks,
            timing_us_per_tick: f.timing_us_per_tick,
            checks: Vec::new(),
            per_map: Vec::new(),
            ..self.clone()
        })
    }
}

/// The identity of a unit, for `--resume`: (scenario, method, parameter set, protocol,
/// training seed).
pub type UnitKey = (String, String, String, Protocol, Option<u64>);

impl ResultLine {
    /// The identity of the unit, for `--resume`.
    pub fn key(&self) -> UnitKey {
        (
            self.scenario.clone(),
            self.method.clone(),
            self.param_set.clone(),
            self.protocol,
            self.train_seed,
        )
    }
}

/// Checks a map's expectations for `method` against an aggregate of a unit whose
/// results hold for the protocols `covers`: an expectation naming a protocol applies
/// only if `covers` includes it; one naming none applies to every protocol.
pub fn check_expectations(map: &Map, method: Method, covers: &[Protocol], agg: &Aggregate) -> Vec<Check> {
    let mut checks = Vec::new();
    // Names were checked when the map was loaded ([`crate::maps::check_expectation_names`]).
    let applies = |p: &Option<String>| {
        p.as_deref()
            .is_none_or(|p| Protocol::from_map_name(p).is_some_and(|p| covers.contains(&p)))
    };
    for e in map
        .expect
        .iter()
        .filter(|e| e.method == method.map_name() && applies(&e.protocol))
    {
        let mut add = |figure: &str, bound: &str, limit: Option<f64>, value: f64| {
            if let Some(limit) = limit {
                checks.push(Check {
                    figure: figure.into(),
                    bound: bound.into(),
                    limit,
                    value,
                    pass: holds(bound, limit, value),
                });
            }
        };
        add("success_rate", "min", e.min_success, agg.success_rate);
        add("success_rate", "max", e.max_success, agg.success_rate);
        add("mean_reward", "min", e.min_reward, agg.mean_reward);
        add("mean_reward", "max", e.max_reward, agg.mean_reward);
        add("collision_rate", "max", e.max_collision, agg.collision_rate);
        add("inference_rate", "max", e.max_inference_rate, agg.inference_rate);
        add("red_light_rate", "max", e.max_red_light, agg.red_light_rate);
    }
    checks
}

/// Whether `value` respects the `bound` (`min` or `max`) `limit`.
fn holds(bound: &str, limit: f64, value: f64) -> bool {
    if bound == "min" { value >= limit } else { value <= limit }
}

/// Everything a batch run needs.
pub struct BatchConfig<'a> {
    /// Trained agents; a unit runs the agent whose training seed it names.
    pub agents: &'a [Agent],
    /// The training-seed axis of the units, in order (`[agent's seed]` for one agent).
    /// With a shard, `agents` needs only the seeds of that shard's units.
    pub train_seeds: &'a [Option<u64>],
    /// Scenarios in order.
    pub scenarios: &'a [Scenario],
    /// Methods in order.
    pub methods: &'a [Method],
    /// Parameter sets in order.
    pub params: &'a [ParamSet],
    /// Protocols in order.
    pub protocols: &'a [Protocol],
    /// Episodes per unit.
    pub episodes: u64,
    /// Evaluation seed.
    pub seed: u64,
    /// Worker threads.
    pub jobs: usize,
    /// Optional shard.
    pub shard: Option<Shard>,
    /// What determines the agents, for the run's identity: an agent file's content hash
    /// ([`agent_file_identity`]) or the training recipe ([`trained_agents_identity`]).
    /// Two runs with the same text here run the same agents.
    pub agents_identity: String,
}

impl BatchConfig<'_> {
    /// The identity of this run (the first line of its results file).
    pub fn identity(&self) -> RunIdentity {
        RunIdentity::new(
            self.scenarios,
            self.methods,
            self.params,
            self.protocols,
            self.train_seeds,
            self.episodes,
            self.seed,
            &self.agents_identity,
        )
    }

    /// All units of the run, in canonical order.
    pub fn units(&self) -> Result<Vec<Unit>, Error> {
        units(
            self.scenarios.len(),
            self.methods,
            self.params,
            self.protocols,
            self.train_seeds,
        )
    }

    /// Plans the run into results file `out` (reading the lines `resume` keeps, see
    /// [`resume_lines`]). Uses everything but [`BatchConfig::agents`], so it can say
    /// which agents are needed before they are trained ([`Plan::train_seeds_to_run`]).
    pub fn plan(&self, out: &Path, resume: bool) -> Result<Plan, Error> {
        let units = self.units()?;
        let shard = self.shard.map_or(0..units.len(), |s| s.range(units.len()));
        let identity = self.identity();
        let kept = if resume {
            resume_lines(out, &identity, &units, self.scenarios)?
        } else {
            Vec::new()
        };
        Ok(Plan {
            identity,
            units,
            shard,
            kept,
        })
    }
}

/// A batch run planned before anything runs ([`BatchConfig::plan`]).
#[derive(Debug, Clone)]
pub struct Plan {
    /// The run's identity (the first line of its results file).
    pub identity: RunIdentity,
    /// Every unit of the run, in canonical order.
    pub units: Vec<Unit>,
    /// The positions of the units this run's shard takes (all of them without a shard).
    pub shard: Range<usize>,
    /// The lines of the results file that `--resume` keeps, in file order.
    pub kept: Vec<KeptLine>,
}

impl Plan {
    /// The units still to run: the shard's, less those whose lines are kept.
    pub fn todo(&self) -> Vec<&Unit> {
        let done: BTreeSet<usize> = self.kept.iter().map(|l| l.parsed.unit).collect();
        self.units[self.shard.clone()]
            .iter()
            .filter(|u| !done.contains(&u.index))
            .collect()
    }

    /// The training seeds of the units still to run, in the order of the run's training
    /// seeds: the agents the run needs.
    pub fn train_seeds_to_run(&self) -> Vec<u64> {
        let todo = self.todo();
        self.identity
            .train_seeds
            .iter()
            .flatten()
            .copied()
            .filter(|&s| todo.iter().any(|u| u.train_seed == Some(s)))
            .collect()
    }
}

/// What determines agents trained on `train_map` for `episodes` episodes with each of
/// `seeds` and the default training configuration, for a run's identity: their cache
/// keys (training map contents, episodes, seed, training configuration, version and
/// training code; [`crate::agents::cache_key`]).
pub fn trained_agents_identity(train_map: &Map, seeds: &[Option<u64>], episodes: u64) -> Result<String, Error> {
    let keys = seeds
        .iter()
        .flatten()
        .map(|&seed| crate::agents::cache_key(train_map, &crate::training::TrainConfig::new(episodes, seed)))
        .collect::<Result<Vec<_>, Error>>()?;
    Ok(format!(
        "trained on {} for {episodes} episodes, agents {}",
        train_map.name,
        crate::seeds::content_hash(keys.join(",").as_bytes())
    ))
}

/// What determines an agent read from a file, for a run's identity: its contents.
pub fn agent_file_identity(bundle: &AgentBundle) -> String {
    format!(
        "agent file with contents {}",
        crate::seeds::content_hash(bundle.to_ron_string().as_bytes())
    )
}

/// Runs one unit: `episodes` episodes of its method on its scenario with its agent,
/// under its protocol. A map: [`evaluate_under`] (zero-shot episodes in parallel, each
/// from a fresh controller; continual ones in order on one controller). A stream:
/// [`evaluate_stream`] (the same, over the stream's maps), and the line adds the figures
/// per map within the stream ([`per_map`]).
pub fn run_unit(cfg: &BatchConfig<'_>, unit: &Unit) -> Result<ResultLine, Error> {
    let scenario = &cfg.scenarios[unit.scenario];
    let agent = cfg
        .agents
        .iter()
        .find(|a| a.train_seed == unit.train_seed)
        .ok_or(Error::MissingAgent {
            train_seed: unit.train_seed,
        })?;
    let params = unit.params.scaled_params()?;
    let actions = Action::ALL.len();
    let tree: usize = (1..=params.planning.horizon).map(|k| actions.pow(k as u32)).sum();
    // Reasoning compute: the inference rate times the prefix tree, for the planner by EFE.
    let efe = |agg: &Aggregate| {
        if unit.method.is_scaled() {
            agg.inference_rate * tree as f64
        } else {
            0.0
        }
    };
    let (agg, per_map_figures) = match &scenario.kind {
        ScenarioKind::Map(map) => {
            let results = evaluate_under(
                unit.protocol,
                map,
                &agent.bundle,
                &params,
                unit.method,
                cfg.episodes,
                cfg.seed,
                &NoProgress,
            )?;
            (Aggregate::of(&results), Vec::new())
        }
        ScenarioKind::Stream(stream) => {
            let episodes = evaluate_stream(
                stream,
                Some(&agent.bundle),
                &params,
                unit.method,
                unit.protocol,
                cfg.episodes,
                cfg.seed,
                &NoProgress,
            )?;
            let results: Vec<EpisodeResult> = episodes.iter().map(|e| e.result.clone()).collect();
            let figures = per_map(stream, &episodes)
                .into_iter()
                .map(|row| {
                    let a = &row.aggregate;
                    MapFigures {
                        efe_matvecs_per_tick: efe(a),
                        map: row.map,
                        episodes: a.episodes as u64,
                        mean_reward: a.mean_reward,
                        success_rate: a.success_rate,
                        collision_rate: a.collision_rate,
                        timeout_rate: a.timeout_rate,
                        red_light_rate: a.red_light_rate,
                        inference_rate: a.inference_rate,
                        mean_ticks: a.mean_ticks,
                        timing_us_per_tick: a.us_per_tick,
                    }
                })
                .collect();
            (Aggregate::of(&results), figures)
        }
    };
    // A map's expectations describe the methods at their default parameters on that map
    // alone: the other points of a sweep, and streams, are reported, not gated.
    let checks = match scenario.map() {
        Some(map) if unit.params.0.is_empty() => check_expectations(map, unit.method, &unit.covers, &agg),
        _ => Vec::new(),
    };
    Ok(ResultLine {
        unit: unit.index,
        scenario: scenario.name().to_string(),
        source: scenario.source.clone(),
        method: unit.method.name().into(),
        param_set: unit.params.label(),
        params: unit.params.0.clone(),
        protocol: unit.protocol,
        covers: unit.covers.clone(),
        train_seed: unit.train_seed,
        train_episodes: agent.train_episodes,
        seed: cfg.seed,
        episodes: cfg.episodes,
        mean_reward: agg.mean_reward,
        success_rate: agg.success_rate,
        collision_rate: agg.collision_rate,
        timeout_rate: agg.timeout_rate,
        red_light_rate: agg.red_light_rate,
        inference_rate: agg.inference_rate,
        efe_matvecs_per_tick: efe(&agg),
        mean_ticks: agg.mean_ticks,
        checks,
        timing_us_per_tick: agg.us_per_tick,
        per_map: per_map_figures,
    })
}

/// What determines a batch run's results, written as the first line of its results file
/// (`{"run": {...}}`). `--resume` continues a file only if its identity is this run's;
/// the shard is not part of it (shards of one run concatenate into one file).
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunIdentity {
    /// The program that ran the units: crate version and a fingerprint of all the source
    /// that determines results (the crates, `src/` and Cargo.lock; build.rs), so a
    /// rebuilt program with changed code does not continue another's file.
    pub program: String,
    /// The agents: an agent file's content hash, or how they were trained.
    pub agents: String,
    /// The scenarios in order: name and a hash of the map's full contents (bases merged),
    /// or of a stream's name, maps, weights and order.
    pub maps: Vec<(String, String)>,
    /// Methods in order.
    pub methods: Vec<String>,
    /// Parameter sets in order (labels).
    pub param_sets: Vec<String>,
    /// Protocols in order.
    pub protocols: Vec<Protocol>,
    /// Training seeds in order.
    pub train_seeds: Vec<Option<u64>>,
    /// Episodes per unit.
    pub episodes: u64,
    /// Evaluation seed.
    pub seed: u64,
}

impl RunIdentity {
    /// The identity of a run of these inputs.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        scenarios: &[Scenario],
        methods: &[Method],
        params: &[ParamSet],
        protocols: &[Protocol],
        train_seeds: &[Option<u64>],
        episodes: u64,
        seed: u64,
        agents: &str,
    ) -> Self {
        RunIdentity {
            program: format!(
                "unforeseen {} (code {})",
                env!("CARGO_PKG_VERSION"),
                env!("UNFORESEEN_CODE_FINGERPRINT")
            ),
            agents: agents.to_string(),
            maps: scenarios
                .iter()
                .map(|s| (s.name().to_string(), s.content_hash()))
                .collect(),
            methods: methods.iter().map(|m| m.name().to_string()).collect(),
            param_sets: params.iter().map(ParamSet::label).collect(),
            protocols: protocols.to_vec(),
            train_seeds: train_seeds.to_vec(),
            episodes,
            seed,
        }
    }

    /// One phrase per field that differs from `other` (`this` is the file's).
    pub fn differences(&self, other: &RunIdentity) -> Vec<String> {
        let a = serde_json::to_value(self).unwrap_or_default();
        let b = serde_json::to_value(other).unwrap_or_default();
        let short = |v: &serde_json::Value| {
            let t = v.to_string();
            if t.chars().count() > 160 {
                format!("{}...", t.chars().take(160).collect::<String>())
            } else {
                t
            }
        };
        let mut out = Vec::new();
        if let (Some(a), Some(b)) = (a.as_object(), b.as_object()) {
            for (k, va) in a {
                let vb = &b[k];
                if va != vb {
                    out.push(format!("{k}: the file has {}, this run {}", short(va), short(vb)));
                }
            }
        }
        out
    }

    /// The identity as the first line of a results file.
    pub(crate) fn to_line(&self) -> String {
        let mut s = serde_json::json!({ "run": self }).to_string();
        s.push('\n');
        s
    }
}

/// The first line of a results file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct IdentityLine {
    run: RunIdentity,
}

/// A result line read back from a results file, with its text as written.
#[derive(Debug, Clone, PartialEq)]
pub struct KeptLine {
    /// 1-based line number in the file.
    pub line: usize,
    /// The text of the line, newline included, kept byte for byte.
    pub raw: String,
    /// The parsed line.
    pub parsed: ResultLine,
}

/// The complete lines of a results file: its run identities (one, or one per
/// concatenated shard) and its result lines.
#[derive(Debug, Clone, Default)]
pub struct ResultsFile {
    /// Identity lines, with their line numbers.
    pub identities: Vec<(usize, RunIdentity)>,
    /// Result lines.
    pub lines: Vec<KeptLine>,
    /// The number of the last line when it was cut (no newline at the end: a killed
    /// run or a full disk); it is not read.
    pub cut_line: Option<usize>,
}

fn results_error(path: &Path, problem: String) -> Error {
    Error::Results {
        path: path.to_path_buf(),
        problem,
    }
}

/// Reads the complete lines of a results file (a missing file has none; a truncated last
/// line from a killed run or a full disk is dropped, whatever byte it ends on, even
/// inside a UTF-8 character, so that unit runs again: [`ResultsFile::cut_line`]). A
/// complete line that is not UTF-8 text (a binary file) is refused.
pub fn read_results(path: &Path) -> Result<ResultsFile, Error> {
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(ResultsFile::default()),
        Ok(m) if !m.is_file() => {
            return Err(Error::NotRegularFile {
                path: path.to_path_buf(),
            });
        }
        _ => {}
    }
    let bytes = std::fs::read(path).map_err(|e| Error::io("read", path, e))?;
    let mut file = ResultsFile::default();
    for (i, raw) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
        if !raw.ends_with(b"\n") {
            file.cut_line = Some(i + 1); // truncated by a kill or a full disk: redo that unit
            break;
        }
        let Ok(raw) = std::str::from_utf8(raw) else {
            return Err(results_error(
                path,
                format!(
                    "line {}: not text (invalid UTF-8): not a batch results file; give the results file `unforeseen batch` wrote",
                    i + 1
                ),
            ));
        };
        let body = raw.trim_end();
        if body.starts_with("{\"run\":") {
            let id: IdentityLine = serde_json::from_str(body).map_err(|e| {
                results_error(
                    path,
                    format!("line {}: not a run identity ({e}); remove the line or the file", i + 1),
                )
            })?;
            file.identities.push((i + 1, id.run));
            continue;
        }
        let parsed: ResultLine = serde_json::from_str(body).map_err(|e| {
            results_error(
                path,
                format!(
                    "line {}: not a batch result line ({e}); remove the line or the file",
                    i + 1
                ),
            )
        })?;
        file.lines.push(KeptLine {
            line: i + 1,
            raw: raw.to_string(),
            parsed,
        });
    }
    Ok(file)
}

/// The result lines of a results file (see [`read_results`]).
pub fn read_lines(path: &Path) -> Result<Vec<ResultLine>, Error> {
    Ok(read_results(path)?.lines.into_iter().map(|l| l.parsed).collect())
}

/// The lines of `out` that `--resume` keeps for a run of identity `identity` and units
/// `units`: refuses a file written by another run (saying what differs), a file that
/// mixes runs or lacks an identity, and lines that are not units of this run or repeat one.
pub fn resume_lines(
    out: &Path,
    identity: &RunIdentity,
    units: &[Unit],
    scenarios: &[Scenario],
) -> Result<Vec<KeptLine>, Error> {
    let file = read_results(out)?;
    let fix = "give another --out, or leave out --resume to start it over (the file is replaced)";
    let Some((first_line, first)) = file.identities.first() else {
        if file.lines.is_empty() {
            return Ok(Vec::new());
        }
        return Err(results_error(
            out,
            format!("--resume: the file does not say which run wrote it (no identity line; an older version?); {fix}"),
        ));
    };
    if let Some((line, other)) = file.identities.iter().find(|(_, id)| id != first) {
        return Err(results_error(
            out,
            format!(
                "--resume: the file mixes two runs (line {line} differs from line {first_line}: {}); {fix}",
                other.differences(first).join("; ")
            ),
        ));
    }
    if first != identity {
        return Err(results_error(
            out,
            format!(
                "--resume: the file was written by another run ({}); {fix}",
                first.differences(identity).join("; ")
            ),
        ));
    }
    let mut seen: BTreeSet<usize> = BTreeSet::new();
    for l in &file.lines {
        let unit = units.get(l.parsed.unit).filter(|u| u.key(scenarios) == l.parsed.key());
        if let Some(u) = unit
            && let Some(problem) = line_problem(&l.parsed, u, identity)
        {
            return Err(results_error(
                out,
                format!(
                    "--resume: line {} (unit {}, {} {} {}) {problem}; {fix}",
                    l.line, l.parsed.unit, l.parsed.scenario, l.parsed.method, l.parsed.param_set
                ),
            ));
        }
        if unit.is_none() {
            return Err(results_error(
                out,
                format!(
                    "line {}: unit {} ({} {} {}) is not a unit of this run; {fix}",
                    l.line, l.parsed.unit, l.parsed.scenario, l.parsed.method, l.parsed.param_set
                ),
            ));
        }
        if !seen.insert(l.parsed.unit) {
            return Err(results_error(
                out,
                format!(
                    "line {}: unit {} is in the file twice; remove one of its lines",
                    l.line, l.parsed.unit
                ),
            ));
        }
    }
    Ok(file.lines)
}

/// Largest magnitude a figure of a result line may have (a return, ticks, µs per tick):
/// far above what any map allows, far below what only a corrupt line holds.
pub const MAX_FIGURE: f64 = 1e9;

/// What is wrong with result line `l` as the line of unit `u` of the run `identity`: a
/// field of its own that is not this run's (seed, episodes, parameters,
/// protocols covered), or a figure out of its range (rates in [0, 1]; others finite,
/// non-negative where they count, at most [`MAX_FIGURE`] in magnitude), its own or of a
/// map within a stream (whose episodes must add up to the line's).
pub(crate) fn line_problem(l: &ResultLine, u: &Unit, identity: &RunIdentity) -> Option<String> {
    if l.seed != identity.seed {
        return Some(format!("has seed {}, the run's header {}", l.seed, identity.seed));
    }
    if l.episodes != identity.episodes {
        return Some(format!(
            "has {} episodes, the run's header {}",
            l.episodes, identity.episodes
        ));
    }
    if l.params != u.params.0 {
        return Some(format!(
            "has parameters {:?}, the unit's are {:?}",
            l.params, u.params.0
        ));
    }
    if l.covers != u.covers {
        return Some(format!("covers {:?}, the unit covers {:?}", l.covers, u.covers));
    }
    let own = figure_problem(
        "",
        [l.success_rate, l.collision_rate, l.timeout_rate, l.inference_rate],
        [l.efe_matvecs_per_tick, l.mean_ticks, l.timing_us_per_tick],
        l.mean_reward,
    );
    if own.is_some() {
        return own;
    }
    if !l.per_map.is_empty() {
        let total: u64 = l.per_map.iter().map(|f| f.episodes).sum();
        if total != l.episodes {
            return Some(format!(
                "has per_map episodes adding up to {total}, the line's {}",
                l.episodes
            ));
        }
    }
    l.per_map.iter().find_map(|f| {
        figure_problem(
            &format!("per_map {}: ", f.map),
            [f.success_rate, f.collision_rate, f.timeout_rate, f.inference_rate],
            [f.efe_matvecs_per_tick, f.mean_ticks, f.timing_us_per_tick],
            f.mean_reward,
        )
    })
}

/// What is wrong with a line's (or one of its maps', `prefix`) figures: the rates
/// (success, collision, time-out, inference) outside [0, 1], the counts (EFE mat-vecs,
/// ticks, µs per tick) outside [0, [`MAX_FIGURE`]], or a return not finite within it.
fn figure_problem(prefix: &str, rates: [f64; 4], counts: [f64; 3], reward: f64) -> Option<String> {
    let rate_names = ["success_rate", "collision_rate", "timeout_rate", "inference_rate"];
    for (name, x) in rate_names.into_iter().zip(rates) {
        if !(0.0..=1.0).contains(&x) {
            return Some(format!("has {prefix}{name} {x}, outside [0, 1]"));
        }
    }
    let count_names = ["efe_matvecs_per_tick", "mean_ticks", "timing_us_per_tick"];
    for (name, x) in count_names.into_iter().zip(counts) {
        if !(0.0..=MAX_FIGURE).contains(&x) {
            return Some(format!("has {prefix}{name} {x}, outside [0, {MAX_FIGURE:e}]"));
        }
    }
    if !(reward.is_finite() && reward.abs() <= MAX_FIGURE) {
        return Some(format!(
            "has {prefix}mean_reward {reward}, not a finite return within ±{MAX_FIGURE:e}"
        ));
    }
    None
}

fn to_line(r: &ResultLine) -> String {
    let mut s = serde_json::to_string(r).expect("result lines serialize");
    s.push('\n');
    s
}

/// Plans the batch ([`BatchConfig::plan`]) and runs it ([`run_plan`]).
pub fn run(cfg: &BatchConfig<'_>, out: &Path, resume: bool, progress: &dyn Progress) -> Result<Vec<ResultLine>, Error> {
    run_plan(cfg, &cfg.plan(out, resume)?, out, progress)
}

/// Runs a planned batch, streaming each finished unit to `out` after the run's identity
/// and the lines the plan keeps, then rewrites `out` in canonical order (kept lines byte
/// for byte). Returns all lines of the file in canonical order. One phase of `progress`
/// (`batch units`, one step per unit).
pub fn run_plan(
    cfg: &BatchConfig<'_>,
    plan: &Plan,
    out: &Path,
    progress: &dyn Progress,
) -> Result<Vec<ResultLine>, Error> {
    let identity = &plan.identity;
    let todo = plan.todo();

    // The identity and the kept lines, then the new lines as they finish.
    let head: String = std::iter::once(identity.to_line())
        .chain(plan.kept.iter().map(|l| l.raw.clone()))
        .collect();
    crate::report::write_atomic(out, head.as_bytes())?;
    let file = std::fs::OpenOptions::new()
        .append(true)
        .open(out)
        .map_err(|e| Error::io("append to", out, e))?;
    let sink = Mutex::new(file);
    progress.phase("batch units", todo.len() as u64);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(cfg.jobs.max(1)).build()?;
    let fresh: Vec<KeptLine> = pool.install(|| {
        todo.par_iter()
            .map(|u| {
                let line = run_unit(cfg, u)?;
                let raw = to_line(&line);
                let mut f = sink.lock().expect("result file lock");
                f.write_all(raw.as_bytes())
                    .and_then(|()| f.flush())
                    .map_err(|e| Error::io("write", out, e))?;
                progress.advance(1);
                Ok(KeptLine {
                    line: 0,
                    raw,
                    parsed: line,
                })
            })
            .collect::<Result<Vec<_>, Error>>()
    })?;
    progress.finish();
    let mut lines: Vec<KeptLine> = plan.kept.iter().cloned().chain(fresh).collect();
    lines.sort_by_key(|l| l.parsed.unit);
    let text: String = std::iter::once(identity.to_line())
        .chain(lines.iter().map(|l| l.raw.clone()))
        .collect();
    crate::report::write_atomic(out, text.as_bytes())?;
    Ok(lines.into_iter().map(|l| l.parsed).collect())
}

/// An expectation checked on the mean over training seeds, with its worst seed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryCheck {
    /// The figure checked, e.g. `success_rate`.
    pub figure: String,
    /// `min` or `max`.
    pub bound: String,
    /// The bound's value.
    pub limit: f64,
    /// The mean of the figure over training seeds (what the bound is checked on).
    pub mean: f64,
    /// Whether the bound held for the mean (the gate: a failed check fails the run).
    pub pass: bool,
    /// The seed whose value is furthest on the wrong side of the bound.
    pub worst_seed: Option<u64>,
    /// That seed's value.
    pub worst_value: f64,
    /// Whether the bound held for that seed too (informational).
    pub worst_seed_passes: bool,
}

/// The agent of a summary row with the lowest success (ties: lowest mean return).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WorstLine {
    /// Its training seed.
    pub train_seed: Option<u64>,
    /// Its success rate.
    pub success_rate: f64,
    /// Its mean return.
    pub mean_reward: f64,
}

/// One (scenario, method, parameter set, protocol) summarized over its training seeds, or
/// one map within a stream scenario's (scenario, method, parameter set, protocol).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryRow {
    /// Scenario name: a map's, a stream's, or for a row within a stream its map's.
    pub scenario: String,
    /// For a row of one map within a stream, the stream's name (the row summarizes that
    /// map's episodes of the stream's units); left out otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stream: Option<String>,
    /// Map file or `embedded:NAME`.
    pub source: String,
    /// Method name.
    pub method: String,
    /// Parameter set label.
    pub param_set: String,
    /// The protocol the units ran under.
    pub protocol: Protocol,
    /// Every protocol these results hold for.
    pub covers: Vec<Protocol>,
    /// Evaluation seed.
    pub seed: u64,
    /// Episodes per agent.
    pub episodes: u64,
    /// Training seeds summarized, in order.
    pub train_seeds: Vec<Option<u64>>,
    /// Mean return, over seeds.
    pub mean_reward: Stat,
    /// Success rate, over seeds.
    pub success_rate: Stat,
    /// Collision rate, over seeds.
    pub collision_rate: Stat,
    /// Time-out rate, over seeds.
    pub timeout_rate: Stat,
    /// Red-light violations per episode, over seeds.
    pub red_light_rate: Stat,
    /// Share of ticks that reasoned, over seeds.
    pub inference_rate: Stat,
    /// EFE mat-vecs per tick, over seeds.
    pub efe_matvecs_per_tick: Stat,
    /// Mean decision ticks per episode, over seeds.
    pub mean_ticks: Stat,
    /// Wall-clock µs per tick, over seeds (the only clock-measured figure).
    pub timing_us_per_tick: Stat,
    /// The seed with the lowest success.
    pub worst_seed: WorstLine,
    /// The expectations, checked on the means.
    pub checks: Vec<SummaryCheck>,
}

/// Groups result lines by (scenario, method, parameter set, protocol), in order of first
/// appearance, and summarizes each group over its training seeds; a stream scenario's row
/// is followed by one row per map within the stream ([`ResultLine::within_stream`]), in
/// the stream's order.
pub fn summarize(lines: &[ResultLine]) -> Vec<SummaryRow> {
    let mut groups: Vec<Vec<&ResultLine>> = Vec::new();
    for l in lines {
        let same = |g: &Vec<&ResultLine>| {
            let f = g[0];
            (&f.scenario, &f.method, &f.param_set, f.protocol) == (&l.scenario, &l.method, &l.param_set, l.protocol)
        };
        match groups.iter_mut().find(|g| same(g)) {
            Some(g) => g.push(l),
            None => groups.push(vec![l]),
        }
    }
    let mut rows = Vec::new();
    for g in &groups {
        rows.push(summary_row(g));
        for f in &g[0].per_map {
            let within: Vec<ResultLine> = g.iter().filter_map(|l| l.within_stream(&f.map)).collect();
            let mut row = summary_row(&within.iter().collect::<Vec<_>>());
            row.stream = Some(g[0].scenario.clone());
            rows.push(row);
        }
    }
    rows
}

/// What learning across episodes does to one map within a stream, for one method and
/// parameter set: the map's figures under the continual protocol against zero-shot, on
/// the same episodes of the stream, as means over training seeds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StreamLearning {
    /// The stream's name.
    pub stream: String,
    /// The map within it.
    pub map: String,
    /// Method name.
    pub method: String,
    /// Parameter set label.
    pub param_set: String,
    /// Episodes of the stream on the map, per agent.
    pub episodes: u64,
    /// Mean success rate, zero-shot.
    pub zero_shot_success: f64,
    /// Mean success rate, continual.
    pub continual_success: f64,
    /// Mean return, zero-shot.
    pub zero_shot_reward: f64,
    /// Mean return, continual.
    pub continual_reward: f64,
    /// Whether learning made the map worse: a lower mean success rate continual than
    /// zero-shot.
    pub worse: bool,
}

/// For every map within a stream and every method that learns across episodes (a row
/// per protocol), what learning does to it ([`StreamLearning`]), in the rows' order.
/// Empty unless the rows hold a stream run under both protocols.
pub fn stream_learning(rows: &[SummaryRow]) -> Vec<StreamLearning> {
    let only = |r: &SummaryRow, p: Protocol| r.stream.is_some() && r.covers == [p];
    rows.iter()
        .filter(|z| only(z, Protocol::ZeroShot))
        .filter_map(|z| {
            let c = rows.iter().find(|c| {
                only(c, Protocol::Continual)
                    && (&c.stream, &c.scenario, &c.method, &c.param_set)
                        == (&z.stream, &z.scenario, &z.method, &z.param_set)
            })?;
            Some(StreamLearning {
                stream: z.stream.clone().unwrap_or_default(),
                map: z.scenario.clone(),
                method: z.method.clone(),
                param_set: z.param_set.clone(),
                episodes: z.episodes,
                zero_shot_success: z.success_rate.mean,
                continual_success: c.success_rate.mean,
                zero_shot_reward: z.mean_reward.mean,
                continual_reward: c.mean_reward.mean,
                worse: c.success_rate.mean < z.success_rate.mean - 1e-12,
            })
        })
        .collect()
}

/// Summarizes one group of lines (all of one configuration, one per seed).
fn summary_row(group: &[&ResultLine]) -> SummaryRow {
    let first = group[0];
    let stat = |f: fn(&ResultLine) -> f64| Stat::of(&group.iter().map(|l| f(l)).collect::<Vec<_>>());
    let worst = group
        .iter()
        .copied()
        .reduce(|w, l| {
            let worse =
                l.success_rate < w.success_rate || (l.success_rate == w.success_rate && l.mean_reward < w.mean_reward);
            if worse { l } else { w }
        })
        .expect("groups are not empty");
    SummaryRow {
        scenario: first.scenario.clone(),
        stream: None,
        source: first.source.clone(),
        method: first.method.clone(),
        param_set: first.param_set.clone(),
        protocol: first.protocol,
        covers: first.covers.clone(),
        seed: first.seed,
        episodes: first.episodes,
        train_seeds: group.iter().map(|l| l.train_seed).collect(),
        mean_reward: stat(|l| l.mean_reward),
        success_rate: stat(|l| l.success_rate),
        collision_rate: stat(|l| l.collision_rate),
        timeout_rate: stat(|l| l.timeout_rate),
        red_light_rate: stat(|l| l.red_light_rate),
        inference_rate: stat(|l| l.inference_rate),
        efe_matvecs_per_tick: stat(|l| l.efe_matvecs_per_tick),
        mean_ticks: stat(|l| l.mean_ticks),
        timing_us_per_tick: stat(|l| l.timing_us_per_tick),
        worst_seed: WorstLine {
            train_seed: worst.train_seed,
            success_rate: worst.success_rate,
            mean_reward: worst.mean_reward,
        },
        checks: first
            .checks
            .iter()
            .enumerate()
            .map(|(i, c)| summary_check(group, i, c))
            .collect(),
    }
}

/// Check `i` (like `c`) on the mean of the group's values, with the worst seed.
fn summary_check(group: &[&ResultLine], i: usize, c: &Check) -> SummaryCheck {
    let values: Vec<(Option<u64>, f64)> = group
        .iter()
        .filter_map(|l| {
            let x = l.checks.get(i)?;
            ((&x.figure, &x.bound, x.limit) == (&c.figure, &c.bound, c.limit)).then_some((l.train_seed, x.value))
        })
        .collect();
    let mean = values.iter().map(|v| v.1).sum::<f64>() / values.len() as f64;
    let badness = |v: f64| if c.bound == "min" { -v } else { v };
    let (worst_seed, worst_value) = values
        .iter()
        .copied()
        .reduce(|w, v| if badness(v.1) > badness(w.1) { v } else { w })
        .expect("the first line has this check");
    SummaryCheck {
        figure: c.figure.clone(),
        bound: c.bound.clone(),
        limit: c.limit,
        mean,
        pass: holds(&c.bound, c.limit, mean),
        worst_seed,
        worst_value,
        worst_seed_passes: holds(&c.bound, c.limit, worst_value),
    }
}

/// Where the summary of results file `out` goes: `results.jsonl` -> `results.summary.json`.
pub fn summary_path(out: &Path) -> PathBuf {
    out.with_extension("summary.json")
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
                    format!("embedded:{n}"),
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
            let source = format!("embedded:{}", map.name);
            scenarios.push(Scenario::of_map(map, source));
        }
    }
    Ok(scenarios)
}

/// The one scenario of a batch over the deployment stream in `file` ([`Stream::load`]).
pub fn load_stream_scenario(file: &Path) -> Result<Scenario, Error> {
    Ok(Scenario::of_stream(Stream::load(file)?, file.display().to_string()))
}
