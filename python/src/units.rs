//! A batch run as units of work for a distributed driver (`unforeseen.distributed`):
//! plan a run on the driver ([`plan_batch`], the command line's `batch` planning), train
//! one agent per training seed wherever a task runs ([`train_agent`]), run a block of
//! units anywhere with the GIL released ([`run_units`]), and join the lines into the
//! results file and summary on the driver ([`finish_batch`], [`unforeseen_harness::runs::merge`]).
//!
//! A plan's `spec` (JSON) is all a task needs besides the agents: the scenarios (as
//! given, and where a node finds them), methods, parameter sets, protocols, training
//! seeds, episodes, seed and the run's identity. A task rebuilds the run from it and
//! refuses to run when what it rebuilt is not the driver's run (a node whose maps
//! differ), so every node computes the lines one machine would.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use pyo3::prelude::*;
use pyo3::types::PyBytes;
use serde_json::{Value, json};
use unforeseen_agent::persist::AgentBundle;
use unforeseen_harness::episodes::methods::Method;
use unforeseen_harness::episodes::protocol::Protocol;
use unforeseen_harness::progress::NoProgress;
use unforeseen_harness::reports::tables;
use unforeseen_harness::runs::batch::{
    BatchConfig, DEFAULT_METHODS, RunIdentity, SCRIPTED_ONLY, Scenario, agent_file_identity, checked_sweep,
    load_scenarios, run_unit, trained_agents_identity,
};
use unforeseen_harness::runs::outputs::Outputs;
use unforeseen_harness::training::seed_agents::Agent;
use unforeseen_harness::training::{DEFAULT_TRAIN_MAP, TrainConfig};

use crate::agent::method;
use crate::errors;

fn protocols_of(choice: &str) -> PyResult<Vec<Protocol>> {
    match choice {
        "both" => Ok(Protocol::ALL.to_vec()),
        "zero-shot" => Ok(vec![Protocol::ZeroShot]),
        "continual" => Ok(vec![Protocol::Continual]),
        other => Err(errors::value(format!(
            "protocol {other:?}: expected zero-shot, continual or both"
        ))),
    }
}

pub(crate) fn check_episodes(what: &str, n: u64) -> PyResult<()> {
    unforeseen_harness::limits::check_episodes(what, n).map_err(errors::to_py)?;
    Ok(())
}

/// Where a node finds a scenario: an embedded map's name, or the map file's absolute path
/// (a node's working folder is not the driver's).
fn locate(s: &Scenario) -> String {
    match s.source.strip_prefix("embedded:") {
        Some(name) => name.to_string(),
        None => std::fs::canonicalize(&s.source)
            .unwrap_or_else(|_| PathBuf::from(&s.source))
            .display()
            .to_string(),
    }
}

/// Plans a batch run into `out` as `unforeseen batch` does (same arguments, same run
/// identity, `resume` keeping the lines of an earlier run of it), without running or
/// training anything. Returns JSON text: `spec` (for [`run_units`]), `head` (the
/// results file's identity line and kept lines), `total` units, `kept`, `todo` (unit
/// positions still to run) with `todo_seeds` (each one's training seed),
/// `train_seeds_to_run`, and `agent` (the agent file's text with `agent`, else null).
#[pyfunction]
#[pyo3(signature = (maps, out, episodes = 100, seed = 7, methods = None, protocol = "both", sets = Vec::new(), train_seeds = None, train_episodes = unforeseen_harness::training::DEFAULT_TRAIN_EPISODES, agent = None, resume = false, force = false))]
#[allow(clippy::too_many_arguments)]
fn plan_batch(
    maps: Vec<PathBuf>,
    out: PathBuf,
    episodes: u64,
    seed: u64,
    methods: Option<Vec<String>>,
    protocol: &str,
    sets: Vec<String>,
    train_seeds: Option<Vec<u64>>,
    train_episodes: u64,
    agent: Option<PathBuf>,
    resume: bool,
    force: bool,
) -> PyResult<String> {
    check_episodes("episodes", episodes)?;
    check_episodes("train_episodes", train_episodes)?;
    let scenarios = load_scenarios(&maps).map_err(errors::to_py)?;
    // The checks of `unforeseen batch --out` (the driver writes `out` and its summary).
    let guard = maps
        .iter()
        .fold(Outputs::results("out", &out), |g, m| g.input("maps", m));
    let guard = match &agent {
        Some(a) => guard.input("agent", a),
        None => guard,
    };
    guard.check(force || resume).map_err(errors::to_py)?;
    let methods: Vec<Method> = match methods {
        Some(names) if !names.is_empty() => names.iter().map(|n| method(n)).collect::<PyResult<_>>()?,
        _ => DEFAULT_METHODS.to_vec(),
    };
    let params = checked_sweep(&sets).map_err(errors::to_py)?;
    let protocols = protocols_of(protocol)?;
    let train_map = unforeseen_harness::maps::load(DEFAULT_TRAIN_MAP).map_err(errors::to_py)?;
    let (axis, agents_identity, agent_text) = match (&train_seeds, &agent) {
        (Some(_), Some(_)) => {
            return Err(errors::value(
                "--train-seeds and --agent: give one (train agents per seed, or run one agent file)",
            ));
        }
        (Some(seeds), None) => {
            if seeds.is_empty() {
                return Err(errors::value("--train-seeds: give at least one training seed"));
            }
            let axis: Vec<Option<u64>> = seeds.iter().map(|&s| Some(s)).collect();
            let id = trained_agents_identity(&train_map, &axis, train_episodes).map_err(errors::to_py)?;
            (axis, id, None)
        }
        (None, Some(path)) => {
            let bundle = unforeseen_harness::training::agent_file::load(path).map_err(errors::to_py)?;
            let a = Agent::from_bundle(bundle.clone());
            (
                vec![a.train_seed],
                agent_file_identity(&bundle),
                Some(bundle.to_ron_string()),
            )
        }
        // Scripted methods only: no agent, as `unforeseen batch` runs them.
        (None, None) if methods.iter().all(|m| m.is_scripted()) => (vec![None], SCRIPTED_ONLY.to_string(), None),
        (None, None) => {
            let axis = vec![Some(seed)];
            let id = trained_agents_identity(&train_map, &axis, train_episodes).map_err(errors::to_py)?;
            (axis, id, None)
        }
    };
    let cfg = BatchConfig {
        agents: &[],
        train_seeds: &axis,
        scenarios: &scenarios,
        methods: &methods,
        params: &params,
        protocols: &protocols,
        episodes,
        seed,
        jobs: 1,
        shard: None,
        agents_identity,
    };
    let plan = cfg.plan(&out, resume).map_err(errors::to_py)?;
    let todo = plan.todo();
    let head: String = std::iter::once(format!("{}\n", json!({ "run": plan.identity })))
        .chain(plan.kept.iter().map(|l| l.raw.clone()))
        .collect();
    let spec = json!({
        "scenarios": scenarios.iter().map(|s| json!([s.source, locate(s)])).collect::<Vec<_>>(),
        "methods": methods.iter().map(|m| m.name()).collect::<Vec<_>>(),
        "sets": sets,
        "protocols": protocols,
        "train_seeds": axis,
        "episodes": episodes,
        "seed": seed,
        "identity": plan.identity,
    });
    Ok(json!({
        "spec": spec.to_string(),
        "head": head,
        "total": plan.units.len(),
        "kept": plan.kept.len(),
        "todo": todo.iter().map(|u| u.index).collect::<Vec<_>>(),
        "todo_seeds": todo.iter().map(|u| u.train_seed).collect::<Vec<_>>(),
        "train_seeds_to_run": plan.train_seeds_to_run(),
        "agent": agent_text,
    })
    .to_string())
}

/// Trains the agent of training seed `seed` on the training map for `episodes` episodes,
/// as `batch --train-seeds` does (no cache), with the GIL released; returns the agent
/// file's text as bytes (what a driver puts in the object store once per seed).
#[pyfunction]
fn train_agent<'py>(py: Python<'py>, seed: u64, episodes: u64) -> PyResult<Bound<'py, PyBytes>> {
    check_episodes("train_episodes", episodes)?;
    let map = unforeseen_harness::maps::load(DEFAULT_TRAIN_MAP).map_err(errors::to_py)?;
    let text = py
        .detach(|| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
            pool.install(|| {
                unforeseen_harness::training::seed_agents::train_agents(
                    &map,
                    &[seed],
                    &TrainConfig::new(episodes, 0),
                    None,
                    &NoProgress,
                )
            })
            .map(|mut a| a.remove(0).bundle.to_ron_string())
        })
        .map_err(errors::to_py)?;
    Ok(PyBytes::new(py, text.as_bytes()))
}

/// Agents parsed in this process, by the hash of their text: a worker process runs many
/// tasks of the same seeds, and parsing an agent costs more than hashing it.
static PARSED: Mutex<Option<HashMap<String, Agent>>> = Mutex::new(None);

/// Most agents [`PARSED`] keeps (a few MB each).
const MAX_PARSED: usize = 16;

pub(crate) fn parse_agent(text: &[u8]) -> PyResult<Agent> {
    let key = unforeseen_harness::seeds::content_hash(text);
    let mut parsed = PARSED.lock().unwrap_or_else(|e| e.into_inner());
    let map = parsed.get_or_insert_with(HashMap::new);
    if let Some(a) = map.get(&key) {
        return Ok(a.clone());
    }
    let text = std::str::from_utf8(text).map_err(|_| errors::value("agent: not agent-file text (invalid UTF-8)"))?;
    let bundle = AgentBundle::from_ron_str(text).map_err(|e| errors::value(format!("agent: {e}")))?;
    let agent = Agent::from_bundle(bundle);
    if map.len() >= MAX_PARSED {
        map.clear();
    }
    map.insert(key, agent.clone());
    Ok(agent)
}

fn field<'a>(spec: &'a Value, name: &str) -> PyResult<&'a Value> {
    spec.get(name)
        .ok_or_else(|| errors::value(format!("spec: no field {name:?}; give the spec plan_batch returned")))
}

fn from<T: serde::de::DeserializeOwned>(spec: &Value, name: &str) -> PyResult<T> {
    serde_json::from_value(field(spec, name)?.clone()).map_err(|e| errors::value(format!("spec: field {name:?}: {e}")))
}

/// Runs the units at positions `units` of the run `spec` describes ([`plan_batch`]) with
/// the agents given as `(training seed, agent text)` pairs, on `threads` threads with the
/// GIL released. Returns each unit's result line (JSON text with its newline), in the
/// order asked. Raises `ValueError` for input that cannot run here (maps on this node
/// that differ from the driver's, a missing agent, a unit not in the run): such a task
/// fails the same way on every node, so it is not to be retried.
#[pyfunction]
#[pyo3(signature = (spec, agents, units, threads = 1))]
fn run_units(
    py: Python<'_>,
    spec: &str,
    agents: Vec<(Option<u64>, Vec<u8>)>,
    units: Vec<usize>,
    threads: usize,
) -> PyResult<Vec<String>> {
    let spec: Value = serde_json::from_str(spec).map_err(|e| errors::value(format!("spec: not JSON ({e})")))?;
    let located: Vec<(String, String)> = from(&spec, "scenarios")?;
    let mut scenarios = Vec::new();
    for (source, place) in &located {
        let map = if source.starts_with("embedded:") {
            unforeseen_harness::maps::load(place).map_err(errors::to_py)?
        } else {
            unforeseen_harness::maps::load_file(Path::new(place)).map_err(errors::to_py)?
        };
        scenarios.push(Scenario::of_map(map, source.clone()));
    }
    let names: Vec<String> = from(&spec, "methods")?;
    let methods: Vec<Method> = names.iter().map(|n| method(n)).collect::<PyResult<_>>()?;
    let sets: Vec<String> = from(&spec, "sets")?;
    let params = checked_sweep(&sets).map_err(errors::to_py)?;
    let protocols: Vec<Protocol> = from(&spec, "protocols")?;
    let axis: Vec<Option<u64>> = from(&spec, "train_seeds")?;
    let identity: RunIdentity = from(&spec, "identity")?;
    let agents = agents
        .iter()
        .map(|(seed, text)| {
            let a = parse_agent(text)?;
            if a.train_seed != *seed {
                return Err(errors::value(format!(
                    "agent given for training seed {seed:?} has training seed {:?}",
                    a.train_seed
                )));
            }
            Ok(a)
        })
        .collect::<PyResult<Vec<_>>>()?;
    let cfg = BatchConfig {
        agents: &agents,
        train_seeds: &axis,
        scenarios: &scenarios,
        methods: &methods,
        params: &params,
        protocols: &protocols,
        episodes: from(&spec, "episodes")?,
        seed: from(&spec, "seed")?,
        jobs: threads.clamp(1, 256),
        shard: None,
        agents_identity: identity.agents.clone(),
    };
    let here = cfg.identity();
    if here != identity {
        return Err(errors::value(format!(
            "this node's run differs from the driver's ({}); give every node the same maps (a shared folder, or Ray's runtime_env working_dir) and the same unforeseen build",
            here.differences(&identity)
                .join("; ")
                .replace("the file has", "this node has")
                .replace("this run", "the driver")
        )));
    }
    let all = cfg.units().map_err(errors::to_py)?;
    let todo = units
        .iter()
        .map(|&i| {
            all.get(i)
                .ok_or_else(|| errors::value(format!("unit {i}: the run has {} units", all.len())))
        })
        .collect::<PyResult<Vec<_>>>()?;
    let lines = py.detach(|| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(cfg.jobs).build()?;
        pool.install(|| {
            todo.iter()
                .map(|u| {
                    let line = run_unit(&cfg, u)?;
                    let mut s = serde_json::to_string(&line)?;
                    s.push('\n');
                    Ok(s)
                })
                .collect::<Result<Vec<String>, unforeseen_harness::error::Error>>()
        })
    });
    lines.map_err(errors::to_py)
}

/// Joins the results file `out` a driver wrote (the plan's `head`, then the new lines in
/// the order they finished) into the file one machine writes: every unit once, in
/// canonical order, and its summary beside it, both atomically ([`unforeseen_harness::runs::merge`]).
/// Returns JSON text: `lines` (the result lines), `summary` (its path), `checked`,
/// `failed`, `failures` (one message per expectation failed on the mean over seeds) and
/// `table` (the summary table `unforeseen batch` prints), both as the command line has them
/// ([`unforeseen_harness::reports::tables`]).
#[pyfunction]
fn finish_batch(py: Python<'_>, out: PathBuf) -> PyResult<String> {
    let parts = [out.clone()];
    let report = py
        .detach(|| {
            let merged = unforeseen_harness::runs::merge::merge(&parts)?;
            let report = unforeseen_harness::runs::merge::write_merged(&merged, &out)?;
            Ok::<_, unforeseen_harness::error::Error>((merged, report))
        })
        .map_err(errors::to_py)?;
    let (merged, report) = report;
    let failures = tables::expectation_failures(&report.rows);
    serde_json::to_string(&json!({
        "lines": merged.results(),
        "summary": report.summary.display().to_string(),
        "checked": report.checked,
        "failed": report.failed,
        "failures": failures,
        "table": tables::batch_summary(&report.rows).to_string(),
    }))
    .map_err(errors::to_py)
}

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(plan_batch, m)?)?;
    m.add_function(wrap_pyfunction!(train_agent, m)?)?;
    m.add_function(wrap_pyfunction!(run_units, m)?)?;
    m.add_function(wrap_pyfunction!(finish_batch, m)?)?;
    Ok(())
}
