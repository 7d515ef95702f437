//! `compare` and `batch` from Python, through the library functions the command line
//! runs ([`unforeseen_harness::runs::compare::run_study`], [`unforeseen_harness::runs::batch::run`]),
//! returned as the report objects of [`crate::reports`]: the data the command line's files
//! hold, built by the same library functions, and the table it prints.

use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList};
use unforeseen_harness::episodes::methods::Method;
use unforeseen_harness::episodes::protocol::Protocol;
use unforeseen_harness::runs::batch::{BatchConfig, ResultLine, Scenario};
use unforeseen_harness::runs::compare::{CompareReport, StudySetup};
use unforeseen_harness::runs::outputs::{Guarded, Outputs};
use unforeseen_harness::training::seed_agents::Agent;

use crate::agent::{PyAgent, method, protocol, scaled_params};
use crate::errors;
use crate::reports::{BatchResult, CompareResult};

fn agents_of(agents: &Bound<'_, PyAny>) -> PyResult<Vec<Agent>> {
    let list: Vec<PyRef<'_, PyAgent>> = if let Ok(one) = agents.extract::<PyRef<'_, PyAgent>>() {
        vec![one]
    } else {
        agents
            .extract()
            .map_err(|_| errors::value("agents: expected an Agent or a list of Agents"))?
    };
    if list.is_empty() {
        return Err(errors::value("agents: give at least one agent"));
    }
    Ok(list.iter().map(|a| Agent::from_bundle(a.bundle.clone())).collect())
}

fn protocols(names: Vec<String>) -> PyResult<Vec<Protocol>> {
    names.iter().map(|n| protocol(n)).collect()
}

/// `unforeseen compare`: its report ([`CompareResult`]), built by the one builder the
/// command line uses ([`CompareReport::new`]).
#[pyfunction]
#[pyo3(signature = (agents, train_map = "intersection", test_map = "jaywalk", episodes = 100, seed = 7, protocols = vec!["zero-shot".to_string(), "continual".to_string()], ablations = false, **params))]
#[allow(clippy::too_many_arguments)]
fn compare_report(
    py: Python<'_>,
    agents: &Bound<'_, PyAny>,
    train_map: &str,
    test_map: &str,
    episodes: u64,
    seed: u64,
    protocols: Vec<String>,
    ablations: bool,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<CompareResult> {
    let agents = agents_of(agents)?;
    let protocols = self::protocols(protocols)?;
    let p = scaled_params(params)?;
    let train = crate::maps::load(train_map, None)?;
    let test = crate::maps::load(test_map, None)?;
    let mut methods = Method::PAPER.to_vec();
    if ablations {
        methods.extend(Method::ABLATIONS);
    }
    let setup = StudySetup {
        train_map: &train,
        test_map: &test,
        params: &p,
        methods: &methods,
        protocols: &protocols,
        episodes,
        seed,
    };
    let tables = crate::interrupt::interruptible(py, |progress| {
        unforeseen_harness::runs::compare::run_study(&setup, &agents, progress)
    })?;
    let report = CompareReport::new(&setup, &agents, tables, None, None).map_err(errors::to_py)?;
    CompareResult::new(&report)
}

static RUN: AtomicU64 = AtomicU64::new(0);

/// `unforeseen batch`: its report ([`BatchResult`]): the result lines of the results
/// file (after its `run` line) and the summary file's rows.
/// `sweep` maps a `--set` key to a value or a list of values (their cross product).
#[pyfunction]
#[pyo3(signature = (maps, agents, episodes = 100, seed = 7, methods = None, protocols = vec!["zero-shot".to_string(), "continual".to_string()], sweep = None, jobs = 2))]
#[allow(clippy::too_many_arguments)]
fn batch_report(
    py: Python<'_>,
    maps: Vec<String>,
    agents: &Bound<'_, PyAny>,
    episodes: u64,
    seed: u64,
    methods: Option<Vec<String>>,
    protocols: Vec<String>,
    sweep: Option<&Bound<'_, PyDict>>,
    jobs: usize,
) -> PyResult<BatchResult> {
    crate::units::check_episodes("episodes", episodes)?;
    let agents = agents_of(agents)?;
    let protocols = self::protocols(protocols)?;
    let methods: Vec<Method> = match methods {
        Some(names) => names.iter().map(|n| method(n)).collect::<PyResult<_>>()?,
        None => Method::PAPER.iter().chain(&Method::REFERENCE).copied().collect(),
    };
    let names: Vec<String> = if maps.is_empty() {
        unforeseen_sim::embedded::names()
            .iter()
            .map(|s| s.to_string())
            .collect()
    } else {
        maps
    };
    let scenarios = names
        .iter()
        .map(|n| Ok(Scenario::of_map(crate::maps::load(n, None)?, n.clone())))
        .collect::<PyResult<Vec<_>>>()?;
    // Sweep lists as `--set key=v1,v2` (a sweep's points are labelled by that text).
    let text = |x: &Bound<'_, PyAny>| -> PyResult<String> {
        if x.is_instance_of::<PyBool>() {
            Ok(if x.extract::<bool>()? { "true" } else { "false" }.to_string())
        } else if x.is_none() {
            Err(errors::value("sweep: None is not a value"))
        } else {
            Ok(x.str()?.to_string())
        }
    };
    let mut sets = Vec::new();
    if let Some(d) = sweep {
        for (k, v) in d.iter() {
            let key: String = k.extract()?;
            let joined = if let Ok(list) = v.cast::<PyList>() {
                list.iter().map(|x| text(&x)).collect::<PyResult<Vec<_>>>()?.join(",")
            } else {
                text(&v)?
            };
            sets.push(format!("{key}={joined}"));
        }
    }
    let params = unforeseen_harness::runs::batch::sweep(&sets).map_err(errors::to_py)?;
    let axis: Vec<Option<u64>> = agents.iter().map(|a| a.train_seed).collect();
    let identity = format!(
        "python agents {}",
        agents
            .iter()
            .map(|a| unforeseen_harness::seeds::content_hash(a.bundle.to_ron_string().as_bytes()))
            .collect::<Vec<_>>()
            .join(",")
    );
    let cfg = BatchConfig {
        agents: &agents,
        train_seeds: &axis,
        scenarios: &scenarios,
        methods: &methods,
        params: &params,
        protocols: &protocols,
        episodes,
        seed,
        jobs: jobs.clamp(1, 256),
        shard: None,
        agents_identity: identity,
    };
    let out: PathBuf = std::env::temp_dir().join(format!(
        "unforeseen-python-batch-{}-{}.jsonl",
        std::process::id(),
        RUN.fetch_add(1, Ordering::Relaxed)
    ));
    let lines = crate::interrupt::interruptible(py, |progress| {
        unforeseen_harness::runs::batch::run(&cfg, &out, false, progress)
    });
    let _ = std::fs::remove_file(&out);
    BatchResult::new(&lines?)
}

/// The report of result lines a Python policy's evaluation wrote (`unforeseen.evaluate`),
/// given as the JSON text of their list: summarized and printed as `unforeseen batch`
/// summarizes and prints its own lines ([`BatchResult`]).
#[pyfunction]
fn batch_result(lines: &str) -> PyResult<BatchResult> {
    let lines: Vec<ResultLine> =
        serde_json::from_str(lines).map_err(|e| errors::value(format!("result lines: {e}")))?;
    BatchResult::new(&lines)
}

/// The output guard of a results file `out` written from Python (`evaluate`): refuses,
/// with a `ValueError`, an `out` that is one of `inputs` (map files) or holds something
/// other than batch results (unless `force`), and holds the lock on it until
/// [`ResultsGuard::release`] (or until collected).
#[pyclass(module = "unforeseen._unforeseen")]
pub struct ResultsGuard {
    held: Option<Guarded>,
}

#[pymethods]
impl ResultsGuard {
    #[new]
    #[pyo3(signature = (out, inputs, force = false))]
    fn new(out: PathBuf, inputs: Vec<PathBuf>, force: bool) -> PyResult<ResultsGuard> {
        let guard = inputs
            .iter()
            .fold(Outputs::results("out", &out), |g, m| g.input("maps", m));
        let held = guard.guard(force).map_err(errors::to_py)?;
        Ok(ResultsGuard { held: Some(held) })
    }

    /// Releases the lock (a second writer may then take it).
    fn release(&mut self) {
        self.held = None;
    }
}

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ResultsGuard>()?;
    m.add_function(wrap_pyfunction!(compare_report, m)?)?;
    m.add_function(wrap_pyfunction!(batch_report, m)?)?;
    m.add_function(wrap_pyfunction!(batch_result, m)?)?;
    Ok(())
}
