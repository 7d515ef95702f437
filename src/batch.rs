//! Headless batch runs of scenario suites: every (scenario, method, parameter set,
//! protocol, training seed) is a unit of work; units run in parallel (rayon) and each
//! finished unit is streamed as one JSON line. Seeds derive from (seed, scenario, method,
//! episode), never from thread order, so results are identical whatever the number of
//! jobs; `--shard i/n` takes a contiguous slice of the canonical unit order, so shards
//! concatenate into the file a single run writes. A method that does not learn across
//! episodes is run once per (scenario, parameter set, seed), and its line covers every
//! protocol asked. Over training seeds, [`summarize`] gives each figure's mean, 95%
//! interval, range and worst seed, and checks the maps' expectations on the mean.

use anyhow::Context;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use unforeseen_agent::params::ScaledParams;
use unforeseen_sim::{Map, MethodName};

use crate::agents::Agent;
use crate::cli::BadInput;
use crate::experiments::evaluate_under;
use crate::methods::Method;
use crate::metrics::Aggregate;
use crate::protocol::{Protocol, covered};
use crate::stats::Stat;

/// A scenario of the suite: a map and where it came from.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// The map.
    pub map: Map,
    /// File it was read from, or `embedded:NAME`.
    pub source: String,
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

/// Expands `--set key=v1,v2` options into the cross product of parameter sets, in the
/// order the options were given (the last varies fastest).
pub fn sweep(sets: &[String]) -> Result<Vec<ParamSet>, BadInput> {
    let mut out = vec![ParamSet(Vec::new())];
    let mut keys: Vec<&str> = Vec::new();
    for set in sets {
        let (key, values) = set
            .split_once('=')
            .ok_or_else(|| BadInput(format!("--set {set}: expected KEY=V1,V2,..., e.g. --set horizon=1,2,3")))?;
        let key = key.trim();
        if keys.contains(&key) {
            return Err(BadInput(format!(
                "--set {set}: `{key}` is set twice; give all its values in one --set, e.g. --set {key}=1,2"
            )));
        }
        keys.push(key);
        let values: Vec<&str> = values.split(',').map(str::trim).collect();
        if values.iter().any(|v| v.is_empty()) {
            return Err(BadInput(format!(
                "--set {set}: an empty value; separate values by single commas, e.g. --set {key}=1,2"
            )));
        }
        if let Some(v) = values
            .iter()
            .enumerate()
            .find_map(|(i, v)| values[..i].contains(v).then_some(v))
        {
            return Err(BadInput(format!("--set {set}: the value {v} is listed twice")));
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

impl ParamSet {
    /// The scaled agent's parameters with these overrides applied (checked).
    pub fn scaled_params(&self) -> anyhow::Result<ScaledParams> {
        let sets: Vec<String> = self.0.iter().map(|(k, v)| format!("{k}={v}")).collect();
        crate::cli::params::apply(ScaledParams::default(), &sets)
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
            scenarios[self.scenario].map.name.clone(),
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
) -> anyhow::Result<Vec<Unit>> {
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

fn method_name(m: Method) -> Option<MethodName> {
    match m {
        Method::QLearning => Some(MethodName::QLearning),
        Method::BayesRl => Some(MethodName::BayesRl),
        Method::Scaled => Some(MethodName::Scaled),
        Method::BrakeOnPedestrian => Some(MethodName::BrakeOnPedestrian),
        _ => None,
    }
}

/// Checks a map's expectations for `method` against an aggregate of a unit whose
/// results hold for the protocols `covers`: an expectation naming a protocol applies
/// only if `covers` includes it; one naming none applies to every protocol.
pub fn check_expectations(map: &Map, method: Method, covers: &[Protocol], agg: &Aggregate) -> Vec<Check> {
    let mut checks = Vec::new();
    let applies = |p: Option<unforeseen_sim::ProtocolName>| p.is_none_or(|p| covers.contains(&Protocol::from_map(p)));
    for e in map
        .expect
        .iter()
        .filter(|e| Some(e.method) == method_name(method) && applies(e.protocol))
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
}

impl BatchConfig<'_> {
    /// All units of the run, in canonical order.
    pub fn units(&self) -> anyhow::Result<Vec<Unit>> {
        units(
            self.scenarios.len(),
            self.methods,
            self.params,
            self.protocols,
            self.train_seeds,
        )
    }

    /// The units of this run's shard (all units without one).
    pub fn shard_units(&self) -> anyhow::Result<Vec<Unit>> {
        let all = self.units()?;
        let range = self.shard.map_or(0..all.len(), |s| s.range(all.len()));
        Ok(all[range].to_vec())
    }
}

/// Runs one unit: `episodes` episodes of its method on its scenario with its agent,
/// under its protocol ([`evaluate_under`]: zero-shot episodes in parallel, each from a
/// fresh controller; continual ones in order on one controller).
pub fn run_unit(cfg: &BatchConfig<'_>, unit: &Unit) -> anyhow::Result<ResultLine> {
    let scenario = &cfg.scenarios[unit.scenario];
    let map = &scenario.map;
    let agent = cfg
        .agents
        .iter()
        .find(|a| a.train_seed == unit.train_seed)
        .ok_or_else(|| anyhow::anyhow!("no agent with training seed {:?} was given", unit.train_seed))?;
    let params = unit.params.scaled_params()?;
    let hidden = indicatif::ProgressBar::hidden();
    let results = evaluate_under(
        unit.protocol,
        map,
        &agent.bundle,
        &params,
        unit.method,
        cfg.episodes,
        cfg.seed,
        &hidden,
    )?;
    let agg = Aggregate::of(&results);
    let tree: usize = (1..=params.horizon).map(|k| 3usize.pow(k as u32)).sum();
    let plans_by_efe = unit.method.is_scaled();
    Ok(ResultLine {
        unit: unit.index,
        scenario: map.name.clone(),
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
        inference_rate: agg.inference_rate,
        efe_matvecs_per_tick: if plans_by_efe {
            agg.inference_rate * tree as f64
        } else {
            0.0
        },
        mean_ticks: agg.mean_ticks,
        // A map's expectations describe the methods at their default parameters: the
        // other points of a sweep are reported, not gated.
        checks: if unit.params.0.is_empty() {
            check_expectations(map, unit.method, &unit.covers, &agg)
        } else {
            Vec::new()
        },
        timing_us_per_tick: agg.us_per_tick,
    })
}

/// Reads the complete lines of an existing results file (a truncated last line from a
/// killed run is dropped).
pub fn read_lines(path: &Path) -> anyhow::Result<Vec<ResultLine>> {
    let text = match std::fs::read_to_string(path) {
        Ok(t) => t,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    let mut lines = Vec::new();
    for (i, line) in text.split_inclusive('\n').enumerate() {
        if !line.ends_with('\n') {
            break; // truncated by a kill: redo that unit
        }
        let parsed: ResultLine = serde_json::from_str(line.trim_end()).map_err(|e| {
            BadInput(format!(
                "{}:{}: not a batch result line ({e}); remove the line or the file",
                path.display(),
                i + 1
            ))
        })?;
        lines.push(parsed);
    }
    Ok(lines)
}

fn to_line(r: &ResultLine) -> String {
    let mut s = serde_json::to_string(r).expect("result lines serialize");
    s.push('\n');
    s
}

/// Runs the batch, streaming each finished unit to `out` (appending after the lines
/// kept by `resume`), then rewrites `out` in canonical order. Returns all lines of
/// this shard in canonical order.
pub fn run(cfg: &BatchConfig<'_>, out: &Path, resume: bool, quiet: bool) -> anyhow::Result<Vec<ResultLine>> {
    let mine = cfg.shard_units()?;
    let kept: Vec<ResultLine> = if resume { read_lines(out)? } else { Vec::new() };
    let done: BTreeSet<UnitKey> = kept.iter().map(ResultLine::key).collect();
    let todo: Vec<&Unit> = mine.iter().filter(|u| !done.contains(&u.key(cfg.scenarios))).collect();

    // Keep only complete lines, then stream new ones as they finish.
    crate::report::write_atomic(out, kept.iter().map(to_line).collect::<String>().as_bytes())?;
    let file = std::fs::OpenOptions::new()
        .append(true)
        .open(out)
        .with_context(|| format!("cannot append to {}", out.display()))?;
    let sink = Mutex::new(file);
    let bar = crate::progress::bar(todo.len() as u64, "batch units", quiet);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(cfg.jobs.max(1)).build()?;
    let fresh: Vec<ResultLine> = pool.install(|| {
        todo.par_iter()
            .map(|u| {
                let line = run_unit(cfg, u)?;
                let mut f = sink.lock().expect("result file lock");
                f.write_all(to_line(&line).as_bytes())?;
                f.flush()?;
                bar.inc(1);
                Ok(line)
            })
            .collect::<anyhow::Result<Vec<_>>>()
    })?;
    bar.finish_and_clear();
    let mut lines: Vec<ResultLine> = kept.into_iter().chain(fresh).collect();
    lines.sort_by_key(|l| l.unit);
    crate::report::write_atomic(out, lines.iter().map(to_line).collect::<String>().as_bytes())?;
    Ok(lines)
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

/// One (scenario, method, parameter set, protocol) summarized over its training seeds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryRow {
    /// Scenario (map) name.
    pub scenario: String,
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
/// appearance, and summarizes each group over its training seeds.
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
    groups.iter().map(|g| summary_row(g)).collect()
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
/// embedded maps when none are given.
pub fn load_scenarios(paths: &[PathBuf]) -> anyhow::Result<Vec<Scenario>> {
    if paths.is_empty() {
        return unforeseen_sim::embedded::names()
            .iter()
            .map(|n| {
                Ok(Scenario {
                    map: unforeseen_sim::embedded::load(n)?,
                    source: format!("embedded:{n}"),
                })
            })
            .collect();
    }
    let mut scenarios = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut found: Vec<PathBuf> = std::fs::read_dir(p)
                .with_context(|| format!("cannot list {}", p.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|f| f.extension().is_some_and(|x| x == "ron"))
                .collect();
            found.sort();
            for f in found {
                scenarios.push(Scenario {
                    map: Map::load(&f)?,
                    source: f.display().to_string(),
                });
            }
        } else if p.exists() {
            scenarios.push(Scenario {
                map: Map::load(p)?,
                source: p.display().to_string(),
            });
        } else {
            let map = crate::maps::load(&p.to_string_lossy())?;
            scenarios.push(Scenario {
                source: format!("embedded:{}", map.name),
                map,
            });
        }
    }
    Ok(scenarios)
}
