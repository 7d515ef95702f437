//! A failure search (`unforeseen search`, `unforeseen_harness::runs::search`) with its candidates
//! evaluated by a distributed driver (`unforeseen.distributed.run_search`): the driver
//! runs the stages here ([`drive_search`], `unforeseen_harness::runs::search::run_with`) and hands
//! each stage's candidates to a Python callable, which runs them as tasks anywhere
//! ([`evaluate_search_candidates`], with the GIL released). The stage logic and the
//! outputs stay in the library, so they equal one machine's.
//!
//! A `spec` is the search's request (the library's `SearchRequest`, as JSON text), the
//! same value `unforeseen search` builds from its flags and [`search`] runs in this
//! process; [`plan_search`] checks it and says which agents it needs. Agents come as
//! `(training seed, agent text)` pairs.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use serde_json::json;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_harness::error::Error;
use unforeseen_harness::runs::batch::AgentChoice;
use unforeseen_harness::runs::search::{CandidateWire, Evaluator, SearchConfig, SearchRequest, SearchSetup};
use unforeseen_harness::training::Agent;

use crate::agent::PyAgent;
use crate::errors;
use crate::interrupt::{interruptible, interruptible_then};
use crate::requests::request;
use crate::units::parse_agent;

/// A search rebuilt from its request and the agents given (what [`SearchConfig`]
/// borrows).
pub(crate) struct Built {
    pub(crate) setup: SearchSetup,
    agents: Vec<Agent>,
}

/// The search request `spec` (JSON text of its fields) with the agent of `agents` given
/// loaded when `from_file` (the request's agent file then not read again), and the
/// agents parsed.
fn resolve(
    spec: &str,
    agents: &[(Option<u64>, Vec<u8>)],
    from_file: bool,
) -> PyResult<(SearchRequest, Option<AgentBundle>, Vec<Agent>)> {
    let mut request: SearchRequest = request(spec)?;
    let parsed: Vec<Agent> = agents.iter().map(|(_, t)| parse_agent(t)).collect::<PyResult<_>>()?;
    let given = if from_file && !request.method.is_scripted() {
        let [agent] = <[&Agent; 1]>::try_from(parsed.iter().collect::<Vec<_>>())
            .map_err(|_| errors::value("agent: give one agent file"))?;
        request.agent = None;
        Some(agent.bundle.clone())
    } else {
        None
    };
    Ok((request, given, parsed))
}

impl Built {
    /// The setup with the agents it runs: the one given, or those of its training seeds
    /// among `parsed` (each seed must be there).
    pub(crate) fn new(setup: SearchSetup, parsed: Vec<Agent>) -> PyResult<Built> {
        let agents = match &setup.agents {
            AgentChoice::None => Vec::new(),
            AgentChoice::Given(agent) => vec![agent.as_ref().clone()],
            AgentChoice::Trained { .. } => {
                for s in &setup.train_seeds {
                    if !parsed.iter().any(|a| a.train_seed == *s) {
                        return Err(errors::value(format!("agents: none of training seed {s:?} given")));
                    }
                }
                parsed
            }
        };
        Ok(Built { setup, agents })
    }

    pub(crate) fn config(&self, jobs: usize, command: String) -> SearchConfig<'_> {
        let mut cfg = self.setup.config(&self.agents, jobs.max(1), command);
        // The tasks and the driver evaluate the whole search (a shard is refused before).
        cfg.shard = None;
        cfg
    }
}

/// Checks the search `request` (JSON text of its fields: arguments, base map, space file)
/// before any task runs, as `unforeseen search` does; `agent` is an agent given loaded
/// instead of the request's agent file. Returns JSON text: `spec` (the request, for
/// [`evaluate_search_candidates`] and [`drive_search`]), `train` (the training seeds of
/// the agents to train), `train_map` (the training map where a node finds it),
/// `train_episodes`, `timeout_as`, and `agent` (the agent's text when one is given, else
/// null).
#[pyfunction]
#[pyo3(signature = (request, agent = None))]
fn plan_search(request: &Bound<'_, PyDict>, agent: Option<PyRef<'_, PyAgent>>) -> PyResult<String> {
    let request: SearchRequest = crate::convert::request(request)?;
    let setup = request.setup(agent.map(|a| a.bundle.clone())).map_err(errors::to_py)?;
    let agent_text = match &setup.agents {
        AgentChoice::Given(agent) => Some(agent.bundle.to_ron_string()),
        _ => None,
    };
    let spec = SearchRequest {
        agent: None,
        ..request.clone()
    };
    Ok(json!({
        "spec": serde_json::to_string(&spec).map_err(errors::to_py)?,
        "train": setup.to_train(),
        "train_map": crate::units::locate(&request.train_map),
        "train_episodes": request.train_episodes,
        "timeout_as": request.timeout_as,
        "agent": agent_text,
    })
    .to_string())
}

/// `unforeseen search` in this process: the search `request` (JSON text of its fields)
/// planned, its agents trained or loaded and the search run by the library, as the
/// command line runs it, writing the same folder of outputs; `agent` is an agent given
/// loaded instead of the request's agent file, `command` goes in the failure maps'
/// comments. Returns `summary.json`'s contents (JSON text). Ctrl-C raises
/// `KeyboardInterrupt` at the next episode.
#[pyfunction]
#[pyo3(signature = (request, agent = None, command = String::new()))]
fn search(
    py: Python<'_>,
    request: &Bound<'_, PyDict>,
    agent: Option<PyRef<'_, PyAgent>>,
    command: String,
) -> PyResult<String> {
    let request: SearchRequest = crate::convert::request(request)?;
    let given = agent.map(|a| a.bundle.clone());
    interruptible(py, |progress| {
        let job = request.plan(given)?;
        let agents = job.setup.agents(progress)?;
        let summary = job.run(&agents, command, progress)?;
        Ok(serde_json::to_string(&summary)?)
    })
}

/// Evaluates the candidates (JSON texts of `unforeseen_harness::runs::search::CandidateWire`) of the
/// search `spec` with its agents, on `threads` threads with the GIL released; returns
/// each candidate's lines of `candidates.jsonl`, in the order given. Raises `ValueError`
/// for input that cannot run here (a space or map that differs, a missing agent), and
/// `KeyboardInterrupt` at the next episode after Ctrl-C ([`interruptible`]).
#[pyfunction]
#[pyo3(signature = (spec, agents, candidates, from_file = false, threads = 1))]
fn evaluate_search_candidates(
    py: Python<'_>,
    spec: &str,
    agents: Vec<(Option<u64>, Vec<u8>)>,
    candidates: Vec<String>,
    from_file: bool,
    threads: usize,
) -> PyResult<Vec<Vec<String>>> {
    let (request, given, parsed) = resolve(spec, &agents, from_file)?;
    let built = Built::new(request.setup(given).map_err(errors::to_py)?, parsed)?;
    let wires: Vec<CandidateWire> = candidates
        .iter()
        .map(|c| serde_json::from_str(c).map_err(|e| errors::value(format!("candidate: {e}"))))
        .collect::<PyResult<_>>()?;
    interruptible(py, |cancel| {
        let cfg = built.config(threads, String::new());
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads.max(1)).build()?;
        pool.install(|| {
            wires
                .par_iter()
                .map(|w| unforeseen_harness::runs::search::evaluate_wire_with(&cfg, w, cancel))
                .collect::<Result<Vec<_>, Error>>()
        })
    })
}

/// Calls the driver's Python `evaluate(candidates) -> lines per candidate`.
pub(crate) struct PyEvaluator {
    evaluate: Py<PyAny>,
    /// The Python error a call raised (re-raised as is once the run stops).
    raised: Mutex<Option<PyErr>>,
    out: PathBuf,
}

impl Evaluator for PyEvaluator {
    fn evaluate(&self, candidates: &[CandidateWire]) -> Result<Vec<Vec<String>>, Error> {
        let texts: Vec<String> = candidates.iter().map(serde_json::to_string).collect::<Result<_, _>>()?;
        Python::attach(|py| {
            self.evaluate
                .call1(py, (texts,))
                .and_then(|r| r.extract::<Vec<Vec<String>>>(py))
        })
        .map_err(|e| {
            let problem = format!("evaluating candidates failed: {e}");
            self.raised.lock().unwrap_or_else(|p| p.into_inner()).get_or_insert(e);
            Error::Results {
                path: self.out.clone(),
                problem,
            }
        })
    }
}

/// Runs the search `spec` (the request [`plan_search`] returns) into its folder `out` as
/// `unforeseen search` does, with the candidates evaluated by `evaluate` (a callable
/// given a list of candidate JSON texts, returning each one's lines, as
/// [`evaluate_search_candidates`] does); `jobs` failures are minimised at once. `command`
/// goes in the failure maps' comments. Returns `summary.json`'s contents. The GIL is
/// released while the search runs; `evaluate` is called with it held, from up to `jobs`
/// threads (never the calling one).
///
/// Ctrl-C raises `KeyboardInterrupt` once the search stops ([`interruptible_then`]): at
/// its next episode, or before its next call to `evaluate`; a call under way is asked to
/// return early by setting `stop` (e.g. a `threading.Event` that `evaluate` checks),
/// when given. The candidates finished stay in `candidates.jsonl.part` for `resume`.
#[pyfunction]
#[pyo3(signature = (spec, agents, evaluate, from_file = false, jobs = 1, command = String::new(), stop = None))]
#[allow(clippy::too_many_arguments)]
fn drive_search(
    py: Python<'_>,
    spec: &str,
    agents: Vec<(Option<u64>, Vec<u8>)>,
    evaluate: Py<PyAny>,
    from_file: bool,
    jobs: usize,
    command: String,
    stop: Option<Py<PyAny>>,
) -> PyResult<String> {
    let (request, given, parsed) = resolve(spec, &agents, from_file)?;
    // The output guard, held until the search ends.
    let job = request.plan(given).map_err(errors::to_py)?;
    let built = Built::new(job.setup.clone(), parsed)?;
    // One driver thread per failure minimised at once, waiting on its remote calls.
    let cfg = built.config(jobs.clamp(1, unforeseen_harness::limits::MAX_JOBS), command);
    cfg.check().map_err(errors::to_py)?;
    let out = request.out.clone();
    let remote = PyEvaluator::new(evaluate, out.clone());
    remote.drive(py, stop, |cancel| {
        let summary = unforeseen_harness::runs::search::run_with(
            &cfg,
            Path::new(&out),
            request.resume,
            job.guard(),
            cancel,
            Some(&remote),
        )?;
        Ok(serde_json::to_string(&summary)?)
    })
}

impl PyEvaluator {
    /// The evaluator calling `evaluate`; `out` names the run in its errors.
    pub(crate) fn new(evaluate: Py<PyAny>, out: PathBuf) -> PyEvaluator {
        PyEvaluator {
            evaluate,
            raised: Mutex::new(None),
            out,
        }
    }

    /// Runs `work` (a run that calls this evaluator) with the GIL released. Ctrl-C raises
    /// `KeyboardInterrupt` once it stops ([`interruptible_then`]), a call under way asked
    /// to return early by setting `stop` when given; an error `evaluate` raised is raised
    /// as is (not the run's report of it), unless a signal came.
    pub(crate) fn drive<F>(&self, py: Python<'_>, stop: Option<Py<PyAny>>, work: F) -> PyResult<String>
    where
        F: FnOnce(&dyn unforeseen_harness::progress::Progress) -> Result<String, Error> + Send,
    {
        let signalled = std::cell::Cell::new(false);
        let on_signal = |py: Python<'_>| {
            signalled.set(true);
            match &stop {
                Some(stop) => stop.call_method0(py, "set").map(drop),
                None => Ok(()),
            }
        };
        let done = interruptible_then(py, on_signal, work);
        let raised = self.raised.lock().unwrap_or_else(|p| p.into_inner()).take();
        match (done, raised) {
            (Err(_), Some(first)) if !signalled.get() => Err(first),
            (done, _) => done,
        }
    }
}

/// Registers the search units.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(plan_search, m)?)?;
    m.add_function(wrap_pyfunction!(search, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate_search_candidates, m)?)?;
    m.add_function(wrap_pyfunction!(drive_search, m)?)?;
    Ok(())
}
