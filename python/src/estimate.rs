//! `unforeseen estimate` in this process (`unforeseen_harness::runs::estimate`): how rare
//! a method's failures are on a space, P(an episode fails) and P(fails | fair) with their
//! intervals, planned, trained and run by the library as the command line runs it, into
//! the same folder of outputs (`estimate.jsonl`, `summary.json`); and the same estimate
//! with its draws evaluated by a distributed driver (`unforeseen.distributed.run_estimate`):
//! [`plan_estimate`] checks the request and gives the search request whose candidates are
//! the draws (what the tasks evaluate, `evaluate_search_candidates`), [`drive_estimate`]
//! runs the estimator's stages here and hands each block of draws to a Python callable.

use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::json;
use unforeseen_harness::runs::batch::AgentChoice;
use unforeseen_harness::runs::estimate::EstimateRequest;

use crate::errors;
use crate::interrupt::interruptible;
use crate::requests::request;
use crate::search_units::{Built, PyEvaluator};
use crate::units::parse_agent;

/// `unforeseen estimate` in this process: the estimate `request` (its fields, as
/// `unforeseen.estimate` takes them) planned, its agents trained or loaded (the request's
/// agent file, or its training seeds) and the estimate run by the library, writing the
/// command line's files. Returns `summary.json`'s contents (JSON text), or for a shard
/// what it evaluated (`ShardPart`). A bad field raises `ValueError` naming it; Ctrl-C
/// raises `KeyboardInterrupt` at the next episode.
#[pyfunction]
fn estimate(py: Python<'_>, request: &Bound<'_, PyDict>) -> PyResult<String> {
    let request: EstimateRequest = crate::convert::request(request)?;
    interruptible(py, |progress| {
        let job = request.plan()?;
        let agents = job.setup.search.agents(progress)?;
        let report = job.run(&agents, progress)?;
        Ok(serde_json::to_string(&report)?)
    })
}

/// Checks the estimate `request` (its fields) before any task runs, as `unforeseen
/// estimate` checks it, writing nothing. Returns JSON text: `spec` (the request, for
/// [`drive_estimate`]), `search_spec` (the search request whose candidates are the draws,
/// for `evaluate_search_candidates`), `train` (the training seeds of the agents to
/// train), `train_map` (the training map where a node finds it), `train_episodes`,
/// `timeout_as`, and `agent` (the agent file's text when one is given, else null).
#[pyfunction]
fn plan_estimate(request: &Bound<'_, PyDict>) -> PyResult<String> {
    let request: EstimateRequest = crate::convert::request(request)?;
    let setup = request.setup().map_err(errors::to_py)?;
    let agent = match &setup.search.agents {
        AgentChoice::Given(agent) => Some(agent.bundle.to_ron_string()),
        _ => None,
    };
    Ok(json!({
        "spec": json_text(&request)?,
        "search_spec": json_text(&request.search())?,
        "train": setup.search.to_train(),
        "train_map": crate::units::locate(&request.train_map),
        "train_episodes": request.train_episodes,
        "timeout_as": request.timeout_as,
        "agent": agent,
    })
    .to_string())
}

/// The JSON text of a request.
fn json_text<T: serde::Serialize>(value: &T) -> PyResult<String> {
    serde_json::to_string(value).map_err(errors::to_py)
}

/// Runs the estimate `spec` (the request [`plan_estimate`] returns) into its folder as
/// `unforeseen estimate` does, with each block of draws evaluated by `evaluate` (a
/// callable given a list of candidate JSON texts of `search_spec`'s search, returning
/// each one's lines, as `evaluate_search_candidates` does); `agents` are `(training seed,
/// agent text)` pairs, the agent file's when the request gives one; with the request's
/// `resume`, the draws left in its folder are kept. Returns `summary.json`'s contents,
/// the command line's byte for byte. The GIL is released
/// while it runs; Ctrl-C raises `KeyboardInterrupt` once it stops, a call under way asked
/// to return early by setting `stop` when given.
#[pyfunction]
#[pyo3(signature = (spec, agents, evaluate, stop = None))]
fn drive_estimate(
    py: Python<'_>,
    spec: &str,
    agents: Vec<(Option<u64>, Vec<u8>)>,
    evaluate: Py<PyAny>,
    stop: Option<Py<PyAny>>,
) -> PyResult<String> {
    let request: EstimateRequest = request(spec)?;
    // The output guard, held until the estimate ends.
    let job = request.plan().map_err(errors::to_py)?;
    let parsed = agents.iter().map(|(_, t)| parse_agent(t)).collect::<PyResult<_>>()?;
    let built = Built::new(job.setup.search.clone(), parsed)?;
    let cfg = built.config(1, String::new());
    let remote = PyEvaluator::new(evaluate, request.out.clone());
    remote.drive(py, stop, |cancel| {
        let report = job.run_with(&cfg, cancel, Some(&remote))?;
        Ok(serde_json::to_string(&report)?)
    })
}

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(estimate, m)?)?;
    m.add_function(wrap_pyfunction!(plan_estimate, m)?)?;
    m.add_function(wrap_pyfunction!(drive_estimate, m)?)?;
    Ok(())
}
