//! Headless batch runs of scenario suites: every (scenario, method, parameter set) is a
//! unit of work; units run in parallel (rayon) and each finished unit is streamed as
//! one JSON line. Seeds derive from (seed, scenario, method, episode), never from thread
//! order, so results are identical whatever the number of jobs; `--shard i/n` takes a
//! contiguous slice of the canonical unit order, so shards concatenate into the file a
//! single run writes.

use anyhow::Context;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_discretizer::Discretizer;
use unforeseen_sim::{Map, MethodName};

use crate::agent_file::check_compatible;
use crate::cli::BadInput;
use crate::experiments::eval_seeds;
use crate::methods::Method;
use crate::metrics::Aggregate;
use crate::runner::run_episode;

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
    for set in sets {
        let (key, values) = set
            .split_once('=')
            .ok_or_else(|| BadInput(format!("--set {set}: expected KEY=V1,V2,..., e.g. --set horizon=1,2,3")))?;
        let values: Vec<&str> = values.split(',').map(str::trim).filter(|v| !v.is_empty()).collect();
        if values.is_empty() {
            return Err(BadInput(format!("--set {set}: no values after '='")));
        }
        out = out
            .into_iter()
            .flat_map(|base| {
                values.iter().map(move |v| {
                    let mut next = base.clone();
                    next.0.push((key.trim().to_string(), v.to_string()));
                    next
                })
            })
            .collect();
    }
    Ok(out)
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
}

/// All units in canonical order: scenarios, then methods, then parameter sets.
pub fn units(n_scenarios: usize, methods: &[Method], params: &[ParamSet]) -> Vec<Unit> {
    let mut out = Vec::new();
    for scenario in 0..n_scenarios {
        for &method in methods {
            for p in params {
                out.push(Unit {
                    index: out.len(),
                    scenario,
                    method,
                    params: p.clone(),
                });
            }
        }
    }
    out
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
    /// Run seed.
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
    /// The map's expectations for this method, checked.
    pub checks: Vec<Check>,
    /// Wall-clock µs per decision tick (the only field that varies between identical runs).
    pub timing_us_per_tick: f64,
}

impl ResultLine {
    /// The identity of the unit, for `--resume`.
    pub fn key(&self) -> (String, String, String) {
        (self.scenario.clone(), self.method.clone(), self.param_set.clone())
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

/// Checks a map's expectations for `method` against an aggregate.
pub fn check_expectations(map: &Map, method: Method, agg: &Aggregate) -> Vec<Check> {
    let mut checks = Vec::new();
    for e in map.expect.iter().filter(|e| Some(e.method) == method_name(method)) {
        let mut add = |figure: &str, bound: &str, limit: Option<f64>, value: f64| {
            if let Some(limit) = limit {
                let pass = if bound == "min" { value >= limit } else { value <= limit };
                checks.push(Check {
                    figure: figure.into(),
                    bound: bound.into(),
                    limit,
                    value,
                    pass,
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

/// Everything a batch run needs.
pub struct BatchConfig<'a> {
    /// The trained agent.
    pub bundle: &'a AgentBundle,
    /// Scenarios in order.
    pub scenarios: &'a [Scenario],
    /// Methods in order.
    pub methods: &'a [Method],
    /// Parameter sets in order.
    pub params: &'a [ParamSet],
    /// Episodes per unit.
    pub episodes: u64,
    /// Run seed.
    pub seed: u64,
    /// Worker threads.
    pub jobs: usize,
    /// Optional shard.
    pub shard: Option<Shard>,
}

/// Runs one unit: `episodes` episodes of its method on its scenario. Methods that
/// learn across episodes (the scaled agent) run them in order; the others run them in
/// parallel, each from a fresh controller.
pub fn run_unit(cfg: &BatchConfig<'_>, unit: &Unit) -> anyhow::Result<ResultLine> {
    let scenario = &cfg.scenarios[unit.scenario];
    let map = &scenario.map;
    let disc = Discretizer::new(&map.bins)?;
    check_compatible(cfg.bundle, &map.name, disc.n_states())?;
    let sets: Vec<String> = unit.params.0.iter().map(|(k, v)| format!("{k}={v}")).collect();
    let params: ScaledParams = crate::cli::params::apply(ScaledParams::default(), &sets)?;
    let run = |controller: &mut dyn unforeseen_agent::controller::Controller, ep: u64| {
        run_episode(
            map,
            &disc,
            controller,
            eval_seeds(cfg.seed, map, unit.method, ep),
            false,
        )
        .0
    };
    let results = if unit.method.learns_across_episodes(&params) {
        let mut controller = unit.method.controller(cfg.bundle, &params)?;
        (0..cfg.episodes)
            .map(|ep| run(controller.as_mut(), ep))
            .collect::<Vec<_>>()
    } else {
        (0..cfg.episodes)
            .into_par_iter()
            .map(|ep| Ok(run(unit.method.controller(cfg.bundle, &params)?.as_mut(), ep)))
            .collect::<anyhow::Result<Vec<_>>>()?
    };
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
        checks: check_expectations(map, unit.method, &agg),
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
    let all = units(cfg.scenarios.len(), cfg.methods, cfg.params);
    let range = cfg.shard.map_or(0..all.len(), |s| s.range(all.len()));
    let mine = &all[range];
    let kept: Vec<ResultLine> = if resume { read_lines(out)? } else { Vec::new() };
    let done: BTreeSet<_> = kept.iter().map(ResultLine::key).collect();
    let label = |u: &Unit| {
        (
            cfg.scenarios[u.scenario].map.name.clone(),
            u.method.name().to_string(),
            u.params.label(),
        )
    };
    let todo: Vec<&Unit> = mine.iter().filter(|u| !done.contains(&label(u))).collect();

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
