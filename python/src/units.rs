//! A batch run as units of work for a distributed driver (`unforeseen.distributed`):
//! plan a run's request on the driver ([`plan_batch`]: the library's
//! `BatchRequest::plan`, as the command line's `batch` and `unforeseen.batch` plan it), train
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
use pyo3::types::{PyBytes, PyDict};
use serde_json::{Value, json};
use unforeseen_agent::persist::AgentBundle;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::progress::NoProgress;
use unforeseen_harness::runs::batch::{
    AgentChoice, BatchConfig, BatchRequest, RunIdentity, Scenario, checked_sweep, run_unit,
};
use unforeseen_harness::training::Agent;
use unforeseen_harness::training::{TimeoutAs, TrainConfig};

use crate::agent::PyAgent;
use crate::errors;
use crate::reports::BatchResult;

pub(crate) fn check_episodes(what: &str, n: u64) -> PyResult<()> {
    unforeseen_harness::limits::check_episodes(what, n).map_err(errors::to_py)?;
    Ok(())
}

/// Where a node finds a map given as `source` (a scenario's source, or the training
/// map): an embedded map's name, or the map file's absolute path (a node's working
/// folder is not the driver's).
pub(crate) fn locate(source: &str) -> String {
    match source.strip_prefix(unforeseen_sim::EMBEDDED_PREFIX) {
        Some(name) => name.to_string(),
        None if !Path::new(source).exists() => source.to_string(),
        None => std::fs::canonicalize(source)
            .unwrap_or_else(|_| PathBuf::from(source))
            .display()
            .to_string(),
    }
}

/// Plans the batch `request` (JSON text of its fields) as `unforeseen batch` does (the
/// same request, checks, agents and run identity, `resume` keeping the lines of an
/// earlier run of it, the output guard passed), without running or training anything;
/// `agent` is an agent given loaded instead of the request's agent file. Returns JSON
/// text: `spec` (for [`run_units`]), `head` (the results file's identity line and kept
/// lines), `total` units, `kept`, `todo` (unit positions still to run) with `todo_seeds`
/// (each one's training seed), `train_seeds_to_run` with `train` (the training map where
/// a node finds it, its episodes and `timeout_as`), and `agent` (the agent's text when
/// one is given, else null).
#[pyfunction]
#[pyo3(signature = (request, agent = None))]
fn plan_batch(request: &Bound<'_, PyDict>, agent: Option<PyRef<'_, PyAgent>>) -> PyResult<String> {
    let request: BatchRequest = crate::convert::request(request)?;
    let job = request.plan(agent.map(|a| a.bundle.clone())).map_err(errors::to_py)?;
    let setup = &job.setup;
    let plan = &job.plan;
    let todo = plan.todo();
    let head: String = std::iter::once(format!("{}\n", json!({ "run": plan.identity })))
        .chain(plan.kept.iter().map(|l| l.raw.clone()))
        .collect();
    let spec = json!({
        "scenarios": setup.scenarios.iter().map(|s| json!([s.source, locate(&s.source)])).collect::<Vec<_>>(),
        "methods": setup.methods,
        "sets": request.sets,
        "protocols": setup.protocols,
        "train_seeds": setup.train_seeds,
        "episodes": setup.episodes,
        "seed": setup.seed,
        "identity": plan.identity,
    });
    let agent_text = match &setup.agents {
        AgentChoice::Given(agent) => Some(agent.bundle.to_ron_string()),
        _ => None,
    };
    Ok(json!({
        "spec": spec.to_string(),
        "head": head,
        "total": plan.units.len(),
        "kept": plan.kept.len(),
        "summary": unforeseen_harness::runs::outputs::summary_path(&request.out),
        "todo": todo.iter().map(|u| u.index).collect::<Vec<_>>(),
        "todo_seeds": todo.iter().map(|u| u.train_seed).collect::<Vec<_>>(),
        "train_seeds_to_run": job.to_train(),
        "train": {
            "map": locate(&request.train_map),
            "episodes": request.train_episodes,
            "timeout_as": request.timeout_as,
        },
        "agent": agent_text,
    })
    .to_string())
}

/// Checks the batch `request` as [`plan_batch`] does, without taking the output guard
/// (which removes an earlier run's summary): for a driver to refuse bad input before
/// anything else can fail (Ray's import).
#[pyfunction]
#[pyo3(signature = (request, agent = None))]
fn check_batch(request: &Bound<'_, PyDict>, agent: Option<PyRef<'_, PyAgent>>) -> PyResult<()> {
    let request: BatchRequest = crate::convert::request(request)?;
    request.setup(agent.map(|a| a.bundle.clone())).map_err(errors::to_py)?;
    Ok(())
}

/// Trains the agent of training seed `seed` on `train_map` (a file or an embedded name)
/// for `episodes` episodes, as `batch --train-seeds` does (no cache), with the GIL
/// released; returns the agent file's text as bytes (what a driver puts in the object
/// store once per seed).
#[pyfunction]
#[pyo3(signature = (seed, episodes, train_map = unforeseen_harness::training::DEFAULT_TRAIN_MAP, timeout_as = "truncation"))]
fn train_agent<'py>(
    py: Python<'py>,
    seed: u64,
    episodes: u64,
    train_map: &str,
    timeout_as: &str,
) -> PyResult<Bound<'py, PyBytes>> {
    check_episodes("train_episodes", episodes)?;
    let timeout_as: TimeoutAs = timeout_as
        .parse()
        .map_err(|e: String| errors::value(format!("timeout_as: {e}")))?;
    let map = unforeseen_harness::maps::load(train_map).map_err(errors::to_py)?;
    let config = TrainConfig {
        timeout_as,
        ..TrainConfig::new(episodes, 0)
    };
    let text = py
        .detach(|| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
            pool.install(|| unforeseen_harness::training::train_agents(&map, &[seed], &config, None, &NoProgress))
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
    let key = unforeseen_env::seeds::content_hash(text);
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
        let map = if source.starts_with(unforeseen_sim::EMBEDDED_PREFIX) {
            unforeseen_harness::maps::load(place).map_err(errors::to_py)?
        } else {
            unforeseen_harness::maps::load_file(Path::new(place)).map_err(errors::to_py)?
        };
        scenarios.push(Scenario::of_map(map, source.clone()));
    }
    let methods: Vec<Method> = from(&spec, "methods")?;
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
/// Returns the report `unforeseen.batch` returns ([`BatchResult`]) of its lines.
#[pyfunction]
fn finish_batch(py: Python<'_>, out: PathBuf) -> PyResult<BatchResult> {
    let parts = [out.clone()];
    let merged = py
        .detach(|| {
            let merged = unforeseen_harness::runs::merge::merge(&parts)?;
            unforeseen_harness::runs::merge::write_merged(&merged, &out)?;
            Ok::<_, unforeseen_harness::error::Error>(merged)
        })
        .map_err(errors::to_py)?;
    BatchResult::new(&merged.results())
}

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(check_batch, m)?)?;
    m.add_function(wrap_pyfunction!(plan_batch, m)?)?;
    m.add_function(wrap_pyfunction!(train_agent, m)?)?;
    m.add_function(wrap_pyfunction!(run_units, m)?)?;
    m.add_function(wrap_pyfunction!(finish_batch, m)?)?;
    Ok(())
}
