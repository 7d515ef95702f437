//! `compare` and `batch` from Python, through the library functions the command line
//! runs ([`unforeseen_harness::runs::compare::run_study`], [`unforeseen_harness::runs::batch::BatchRequest`]),
//! returned as the report objects of [`crate::reports`]: the data the command line's files
//! hold, built by the same library functions, and the table it prints.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use unforeseen_harness::episodes::methods::Method;
use unforeseen_harness::episodes::protocol::Protocol;
use unforeseen_harness::runs::batch::{BatchRequest, ResultLine};
use unforeseen_harness::runs::compare::{CompareReport, StudySetup};
use unforeseen_harness::runs::outputs::{Guarded, Outputs};
use unforeseen_harness::training::seed_agents::Agent;

use crate::agent::{PyAgent, protocol, scaled_params};
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

/// `unforeseen batch`: the batch `request` (JSON text of its fields, the library's
/// `BatchRequest`) planned, its agents trained or loaded and its units run by the
/// library, as the command line runs it, writing the same results file and summary
/// (`out`); `agent` is an agent given loaded instead of the request's agent file.
/// Returns its report ([`BatchResult`]): the result lines (after the file's `run` line)
/// and the summary's rows. Ctrl-C raises `KeyboardInterrupt` at the next episode.
#[pyfunction]
#[pyo3(signature = (request, agent = None))]
fn batch(py: Python<'_>, request: &str, agent: Option<PyRef<'_, PyAgent>>) -> PyResult<BatchResult> {
    let request: BatchRequest = crate::units::request(request)?;
    let given = agent.map(|a| a.bundle.clone());
    let report = crate::interrupt::interruptible(py, |progress| {
        let job = request.plan(given)?;
        let agents = job.agents(progress)?;
        let workers = job.workers(&agents);
        job.run(&agents, workers.jobs, progress)
    })?;
    BatchResult::new(&report.lines)
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
    m.add_function(wrap_pyfunction!(batch, m)?)?;
    m.add_function(wrap_pyfunction!(batch_result, m)?)?;
    Ok(())
}
