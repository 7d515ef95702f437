//! A failure search (`unforeseen search`, `unforeseen_harness::runs::search`) with its candidates
//! evaluated by a distributed driver (`unforeseen.distributed.run_search`): the driver
//! runs the stages here ([`drive_search`], `unforeseen_harness::runs::search::run_with`) and hands
//! each stage's candidates to a Python callable, which runs them as tasks anywhere
//! ([`evaluate_search_candidates`], with the GIL released). The stage logic and the
//! outputs stay in the library, so they equal one machine's.
//!
//! A `spec` (JSON) is the command line's arguments: `map`, `space`, `method`,
//! `protocol`, `budget`, `episodes`, `seed`, `sobol_share`, `rounds`, `max_failures`,
//! `train_seeds` (a list, or null for the agent given or, without one, the run seed) and
//! `train_episodes`. Agents come as `(training seed, agent text)` pairs.

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use pyo3::prelude::*;
use pyo3::types::PyBytes;
use rayon::prelude::*;
use serde::Deserialize;
use unforeseen_harness::episodes::methods::Method;
use unforeseen_harness::episodes::protocol::Protocol;
use unforeseen_harness::error::Error;
use unforeseen_harness::runs::batch::{agent_file_identity, trained_agents_identity};
use unforeseen_harness::runs::search::{self, CandidateWire, Evaluator, SearchConfig, Space};
use unforeseen_harness::training::DEFAULT_TRAIN_MAP;
use unforeseen_harness::training::seed_agents::Agent;

use crate::agent::method;
use crate::errors;
use crate::interrupt::{interruptible, interruptible_then};
use crate::units::{check_episodes, parse_agent};

/// The arguments of `unforeseen search` that determine its results.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Spec {
    map: String,
    space: PathBuf,
    method: String,
    protocol: String,
    budget: usize,
    episodes: u64,
    seed: u64,
    sobol_share: f64,
    rounds: usize,
    max_failures: usize,
    train_seeds: Option<Vec<u64>>,
    train_episodes: u64,
}

/// A search rebuilt from its spec and agents (what [`SearchConfig`] borrows).
struct Built {
    spec: Spec,
    space: Space,
    method: Method,
    protocol: Protocol,
    agents: Vec<Agent>,
    axis: Vec<Option<u64>>,
    identity: String,
}

impl Built {
    fn new(spec: &str, agents: Vec<(Option<u64>, Vec<u8>)>, from_file: bool) -> PyResult<Built> {
        let spec: Spec = serde_json::from_str(spec).map_err(|e| errors::value(format!("search spec: {e}")))?;
        check_episodes("episodes", spec.episodes)?;
        check_episodes("train_episodes", spec.train_episodes)?;
        let method = method(&spec.method)?;
        let protocol = protocol(&spec.protocol)?;
        let base = unforeseen_harness::maps::load(&spec.map).map_err(errors::to_py)?;
        let space = Space::load(&spec.space, &base).map_err(errors::to_py)?;
        let parsed: Vec<Agent> = agents.iter().map(|(_, t)| parse_agent(t)).collect::<PyResult<_>>()?;
        let train_map = || unforeseen_harness::maps::load(DEFAULT_TRAIN_MAP).map_err(errors::to_py);
        let (agents, axis, identity) = if method.is_scripted() {
            (Vec::new(), vec![None], "none (a scripted method)".to_string())
        } else if from_file {
            let [agent] = <[Agent; 1]>::try_from(parsed).map_err(|_| errors::value("agent: give one agent file"))?;
            let identity = agent_file_identity(&agent.bundle);
            let axis = vec![agent.train_seed];
            (vec![agent], axis, identity)
        } else {
            let seeds = spec.train_seeds.clone().unwrap_or_else(|| vec![spec.seed]);
            if seeds.is_empty() {
                return Err(errors::value("--train-seeds: give at least one training seed"));
            }
            let axis: Vec<Option<u64>> = seeds.iter().map(|&s| Some(s)).collect();
            let identity = trained_agents_identity(&train_map()?, &axis, spec.train_episodes).map_err(errors::to_py)?;
            for s in &axis {
                if !parsed.iter().any(|a| a.train_seed == *s) {
                    return Err(errors::value(format!("agents: none of training seed {s:?} given")));
                }
            }
            (parsed, axis, identity)
        };
        Ok(Built {
            spec,
            space,
            method,
            protocol,
            agents,
            axis,
            identity,
        })
    }

    fn config(&self, jobs: usize, command: String) -> SearchConfig<'_> {
        SearchConfig {
            space: &self.space,
            method: self.method,
            agents: &self.agents,
            train_seeds: &self.axis,
            agents_identity: self.identity.clone(),
            protocol: self.protocol,
            budget: self.spec.budget,
            episodes: self.spec.episodes,
            seed: self.spec.seed,
            jobs: jobs.max(1),
            shard: None,
            sobol_share: self.spec.sobol_share,
            rounds: self.spec.rounds,
            max_failures: self.spec.max_failures,
            command,
        }
    }
}

/// Checks a search's spec (its arguments, base map and space file) before any task
/// runs; returns whether its method is scripted (needs no agents).
#[pyfunction]
fn check_search(spec: &str) -> PyResult<bool> {
    let spec: Spec = serde_json::from_str(spec).map_err(|e| errors::value(format!("search spec: {e}")))?;
    check_episodes("episodes", spec.episodes)?;
    check_episodes("train_episodes", spec.train_episodes)?;
    protocol(&spec.protocol)?;
    let base = unforeseen_harness::maps::load(&spec.map).map_err(errors::to_py)?;
    Space::load(&spec.space, &base).map_err(errors::to_py)?;
    Ok(method(&spec.method)?.is_scripted())
}

fn protocol(name: &str) -> PyResult<Protocol> {
    match name {
        "zero-shot" => Ok(Protocol::ZeroShot),
        "continual" => Ok(Protocol::Continual),
        other => Err(errors::value(format!(
            "protocol {other:?}: expected zero-shot or continual"
        ))),
    }
}

/// An agent file's text as the search reads it (`--agent FILE`), for the object store.
#[pyfunction]
fn search_agent_text<'py>(py: Python<'py>, path: PathBuf) -> PyResult<Bound<'py, PyBytes>> {
    let bundle = unforeseen_harness::training::agent_file::load(&path).map_err(errors::to_py)?;
    Ok(PyBytes::new(py, bundle.to_ron_string().as_bytes()))
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
    let built = Built::new(spec, agents, from_file)?;
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
                .map(|w| search::evaluate_wire_with(&cfg, w, cancel))
                .collect::<Result<Vec<_>, Error>>()
        })
    })
}

/// Calls the driver's Python `evaluate(candidates) -> lines per candidate`.
struct PyEvaluator {
    evaluate: Py<PyAny>,
    /// The Python error a call raised (re-raised as is once the search stops).
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

/// Runs the search `spec` into folder `out` as `unforeseen search` does, with the
/// candidates evaluated by `evaluate` (a callable given a list of candidate JSON texts,
/// returning each one's lines, as [`evaluate_search_candidates`] does); `jobs` failures
/// are minimised at once. `command` goes in the failure maps' comments. Returns
/// `summary.json`'s contents. The GIL is released while the search runs; `evaluate` is
/// called with it held, from up to `jobs` threads (never the calling one).
///
/// Ctrl-C raises `KeyboardInterrupt` once the search stops ([`interruptible_then`]): at
/// its next episode, or before its next call to `evaluate`; a call under way is asked to
/// return early by setting `stop` (e.g. a `threading.Event` that `evaluate` checks),
/// when given. The candidates finished stay in `candidates.jsonl` for `resume`.
#[pyfunction]
#[pyo3(signature = (spec, agents, evaluate, out, resume = false, from_file = false, jobs = 1, command = String::new(), stop = None))]
#[allow(clippy::too_many_arguments)]
fn drive_search(
    py: Python<'_>,
    spec: &str,
    agents: Vec<(Option<u64>, Vec<u8>)>,
    evaluate: Py<PyAny>,
    out: PathBuf,
    resume: bool,
    from_file: bool,
    jobs: usize,
    command: String,
    stop: Option<Py<PyAny>>,
) -> PyResult<String> {
    let built = Built::new(spec, agents, from_file)?;
    // One driver thread per failure minimised at once, waiting on its remote calls.
    let cfg = built.config(jobs.clamp(1, unforeseen_harness::limits::MAX_JOBS), command);
    cfg.check().map_err(errors::to_py)?;
    let _guard = search::output::outputs(&out)
        .input("map", &built.spec.map)
        .input("space", &built.spec.space)
        .guard(resume)
        .map_err(errors::to_py)?;
    let remote = PyEvaluator {
        evaluate,
        raised: Mutex::new(None),
        out: out.clone(),
    };
    let signalled = std::cell::Cell::new(false);
    let on_signal = |py: Python<'_>| {
        signalled.set(true);
        match &stop {
            Some(stop) => stop.call_method0(py, "set").map(drop),
            None => Ok(()),
        }
    };
    let done = interruptible_then(py, on_signal, |cancel| {
        let summary = search::run_with(&cfg, Path::new(&out), resume, cancel, Some(&remote))?;
        Ok(serde_json::to_string(&summary)?)
    });
    // The error `evaluate` raised as is (not the search's report of it), unless a signal
    // came: then the signal's exception.
    let raised = remote.raised.into_inner().unwrap_or_else(|p| p.into_inner());
    match (done, raised) {
        (Err(_), Some(first)) if !signalled.get() => Err(first),
        (done, _) => done,
    }
}

/// Registers the search units.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(check_search, m)?)?;
    m.add_function(wrap_pyfunction!(search_agent_text, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate_search_candidates, m)?)?;
    m.add_function(wrap_pyfunction!(drive_search, m)?)?;
    Ok(())
}
