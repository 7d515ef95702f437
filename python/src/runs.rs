//! `compare` and `batch` from Python, through the requests the command line runs
//! ([`CompareRequest`], [`BatchRequest`]),
//! returned as the report objects of [`crate::reports`]: the data the command line's files
//! hold, built by the same library functions, and the table it prints.

use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use unforeseen_harness::runs::batch::{BatchRequest, ResultLine};
use unforeseen_harness::runs::compare::CompareRequest;
use unforeseen_harness::runs::outputs::{Guarded, Outputs, Own};
use unforeseen_harness::training::Agent;

use crate::agent::PyAgent;
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

/// `unforeseen compare`: the compare `request` (its fields as keyword arguments, read by
/// [`crate::convert::request`] into the library's `CompareRequest`) planned, its agents trained or loaded and the study run by the
/// library, as the command line runs it, writing the same files into `out` (when the
/// request has one); `agents` are agents given loaded (an `Agent` or a list) instead of
/// the request's agent file or training seeds. Returns its report ([`CompareResult`]).
/// Ctrl-C raises `KeyboardInterrupt` at the next episode.
#[pyfunction]
#[pyo3(signature = (request, agents = None))]
fn compare(py: Python<'_>, request: &Bound<'_, PyDict>, agents: Option<&Bound<'_, PyAny>>) -> PyResult<CompareResult> {
    let request: CompareRequest = crate::convert::request(request)?;
    let given = match agents {
        Some(a) => agents_of(a)?,
        None => Vec::new(),
    };
    let report = crate::interrupt::interruptible(py, |progress| {
        let job = request.plan(given)?;
        let agents = job.agents(progress)?;
        let report = job.run(&agents, progress)?;
        job.write(&report)?;
        Ok(report)
    })?;
    CompareResult::new(&report)
}

/// `unforeseen batch`: the batch `request` (its fields as keyword arguments, read by
/// [`crate::convert::request`] into the library's `BatchRequest`) planned, its agents trained or loaded and its units run by the
/// library, as the command line runs it, writing the same results file and summary
/// (`out`); `agent` is an agent given loaded instead of the request's agent file.
/// Returns its report ([`BatchResult`]): the result lines (after the file's `run` line)
/// and the summary's rows. Ctrl-C raises `KeyboardInterrupt` at the next episode.
#[pyfunction]
#[pyo3(signature = (request, agent = None))]
fn batch(py: Python<'_>, request: &Bound<'_, PyDict>, agent: Option<PyRef<'_, PyAgent>>) -> PyResult<BatchResult> {
    let request: BatchRequest = crate::convert::request(request)?;
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
/// with a `ValueError`, an `out` that is one of `inputs` (map files), or, unless `force`,
/// one that holds something other than result lines: when `append`, a batch run's file
/// is accepted (the lines go beside its lines); when replacing, it is refused (its run
/// would be lost). Holds the lock on it until [`ResultsGuard::release`] (or until
/// collected).
#[pyclass(module = "unforeseen._unforeseen")]
pub struct ResultsGuard {
    held: Option<Guarded>,
}

#[pymethods]
impl ResultsGuard {
    #[new]
    #[pyo3(signature = (out, inputs, force = false, append = false))]
    fn new(out: PathBuf, inputs: Vec<PathBuf>, force: bool, append: bool) -> PyResult<ResultsGuard> {
        let own = if append { Own::Results } else { Own::ResultLines };
        let guard = inputs
            .iter()
            .fold(Outputs::new().file("out", &out, own), |g, m| g.input("maps", m));
        let held = guard.guard(force).map_err(errors::to_py)?;
        Ok(ResultsGuard { held: Some(held) })
    }

    /// Releases the lock (a second writer may then take it).
    fn release(&mut self) {
        self.held = None;
    }
}

/// Writes `text` to `path` as every job of the library writes its files
/// ([`unforeseen_harness::files::write_atomic`]: a temporary file beside it,
/// renamed over it), so a reader never sees half of it.
#[pyfunction]
fn write_atomic(py: Python<'_>, path: &Bound<'_, PyAny>, text: &str) -> PyResult<()> {
    let path = crate::convert::path("path", path)?;
    py.detach(|| unforeseen_harness::files::write_atomic(&path, text.as_bytes()))
        .map_err(errors::to_py)
}

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<ResultsGuard>()?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(batch, m)?)?;
    m.add_function(wrap_pyfunction!(batch_result, m)?)?;
    m.add_function(wrap_pyfunction!(write_atomic, m)?)?;
    Ok(())
}
