//! The scaled agent around any habit (`unforeseen.ScaledWrapper`): the world model, the
//! surprise gate, reasoning, scaling and test-time learning of an agent file's scaled
//! agent, with `π_o` from a table of per-state probabilities ([`TableHabit`], the
//! Q-table's by default) or from an external policy's probabilities each tick
//! ([`PolicyHabit`]; [`unforeseen_agent::habit`] documents how learning corrects it).
//! Also the batch summary of a results file ([`unforeseen_harness::runs::batch::summarize`]), so that
//! lines written from Python are read the way `unforeseen batch` reads its own.

use std::path::PathBuf;
use std::sync::Mutex;

use numpy::{PyArray2, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use unforeseen_agent::controller::{Controller, Ending};
use unforeseen_agent::habit::{PolicyHabit, TableHabit};
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_env::ObservationForm;
use unforeseen_harness::episodes::Method;

use crate::agent::{PyAgent, decision_dict, scaled_params};
use crate::errors;

/// The agent, with either kind of habit.
#[derive(Clone)]
pub enum Wrapped {
    /// Around a table of probabilities per state.
    Table(Box<ScaledAgent<TableHabit>>),
    /// Around probabilities given each tick.
    Policy(Box<ScaledAgent<PolicyHabit>>),
}

impl Wrapped {
    fn controller(&mut self) -> &mut dyn Controller {
        match self {
            Wrapped::Table(a) => a.as_mut(),
            Wrapped::Policy(a) => a.as_mut(),
        }
    }

    /// The agent as the runner's controller (its habit's probabilities, for an external
    /// habit, as the last tick left them: [`crate::policy`] asks the habit instead).
    pub fn into_controller(self) -> Box<dyn Controller> {
        match self {
            Wrapped::Table(a) => a,
            Wrapped::Policy(a) => a,
        }
    }
}

/// Where the habit's probabilities come from.
pub enum Habit {
    /// The habit table given at construction.
    Table,
    /// A Python habit asked each tick (`probs(obs)` or a callable obs -> probabilities,
    /// [`crate::policy`]) with observations of `form`; without an object, the
    /// probabilities come with each `act`.
    External {
        /// The habit, if given.
        object: Option<Py<PyAny>>,
        /// The form of the observations it reads.
        form: ObservationForm,
    },
}

/// The wrapper's refusal of `e` as a `ValueError`.
pub fn agent_error(e: unforeseen_agent::error::AgentError) -> PyErr {
    errors::value(format!("scaled wrapper: {e}"))
}

/// The scaled agent of `agent` around a habit: `habit_table` (an `(n_states, n_actions)`
/// array of probabilities per state), or, without one, an external habit: the
/// probabilities passed to `act` each tick, and `habit` (a callable obs -> probabilities,
/// or an object with `probs(obs)`; observations of form `observation`), which
/// `evaluate_policy` asks each tick. Keywords are the scaled agent's parameters (the keys
/// of `--set`).
#[pyclass(name = "ScaledHabitAgent", module = "unforeseen._unforeseen", frozen)]
pub struct PyScaledHabitAgent {
    inner: Mutex<Wrapped>,
    /// The agent as built, before any episode: each evaluation starts from a copy.
    pristine: Wrapped,
    sizes: Vec<usize>,
    /// The scaled agent's parameters (the planning tree of its lines' reasoning compute).
    pub params: ScaledParams,
    /// Where the habit's probabilities come from.
    pub habit: Habit,
    /// Whether test-time learning carries over between episodes.
    pub learns: bool,
}

impl PyScaledHabitAgent {
    /// A fresh copy of the agent as built (nothing learned at test time).
    pub fn fresh(&self) -> Wrapped {
        self.pristine.clone()
    }
}

impl PyScaledHabitAgent {
    fn lock(&self) -> std::sync::MutexGuard<'_, Wrapped> {
        self.inner.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// `(d, v, L, p)` (or a joint index) as the joint index.
    fn index(&self, obs: &Bound<'_, PyAny>) -> PyResult<usize> {
        crate::agent::joint_index(&self.sizes, obs)
    }
}

#[pymethods]
impl PyScaledHabitAgent {
    #[new]
    #[pyo3(signature = (agent, habit_table = None, habit = None, observation = "discrete", **params))]
    fn new(
        agent: &PyAgent,
        habit_table: Option<PyReadonlyArray2<'_, f64>>,
        habit: Option<Py<PyAny>>,
        observation: &str,
        params: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Self> {
        let p = scaled_params(None, params)?;
        let learns = Method::Scaled.learns_across_episodes(&p);
        let form = crate::env::observation_form(observation)?;
        if habit_table.is_some() && habit.is_some() {
            return Err(errors::value("habit_table and habit: give one or the other"));
        }
        let checked = p.clone().check().map_err(|e| errors::value(e.to_string()))?;
        let model = agent.bundle.world_model.clone();
        let (n, na) = (model.n_states(), model.n_actions());
        let nu0 = checked.learning.nu0;
        let (inner, external) = match habit_table {
            Some(t) => {
                let shape = t.shape();
                if shape != [n, na] {
                    return Err(errors::value(format!(
                        "habit table of shape ({}, {}): expected ({n}, {na}) (states x actions of the agent's world model)",
                        shape[0], shape[1]
                    )));
                }
                let probs: Vec<f64> = t.as_array().iter().copied().collect();
                let habit = TableHabit::from_probs(&probs, na, nu0).map_err(agent_error)?;
                let a = ScaledAgent::with_habit(model, habit, checked).map_err(agent_error)?;
                (Wrapped::Table(Box::new(a)), false)
            }
            None => {
                let habit = PolicyHabit::new(n, na, nu0).map_err(agent_error)?;
                let a = ScaledAgent::with_habit(model, habit, checked).map_err(agent_error)?;
                (Wrapped::Policy(Box::new(a)), true)
            }
        };
        Ok(PyScaledHabitAgent {
            pristine: inner.clone(),
            inner: Mutex::new(inner),
            sizes: agent.bundle.world_model.structure().sizes(),
            params: p,
            habit: if external {
                Habit::External { object: habit, form }
            } else {
                Habit::Table
            },
            learns,
        })
    }

    /// Whether the habit's probabilities come with each `act` (no habit table).
    #[getter]
    fn external(&self) -> bool {
        matches!(self.habit, Habit::External { .. })
    }

    /// The form of the observations the external habit reads (`"discrete"` with a
    /// habit table).
    #[getter]
    fn observation(&self) -> &'static str {
        match self.habit {
            Habit::External {
                form: ObservationForm::Kinematic,
                ..
            } => "kinematic",
            _ => "discrete",
        }
    }

    /// Whether test-time learning carries over between episodes, as the library decides
    /// it for the scaled agent with these parameters
    /// ([`Method::learns_across_episodes`]: the key `learning`).
    #[getter]
    fn learns(&self) -> bool {
        self.learns
    }

    /// Starts an episode: clears beliefs and the habit's per-tick inputs, seeds sampling.
    fn begin_episode(&self, seed: u64) {
        self.lock().controller().begin_episode(seed);
    }

    /// Decides on `observed` (`(d, v, L, p)` as observed, e.g. `info["observed"]`, or a
    /// joint index) with `probs`, the habit's action probabilities at this tick's
    /// observation (required without a habit table, refused with one):
    /// `(action, decision)`, the decision as `Controller.act` gives it.
    #[pyo3(signature = (observed, probs = None))]
    fn act<'py>(
        &self,
        py: Python<'py>,
        observed: &Bound<'py, PyAny>,
        probs: Option<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<(usize, Bound<'py, PyDict>)> {
        let i = self.index(observed)?;
        let d = match (&mut *self.lock(), probs) {
            (Wrapped::Table(a), None) => a.act(i),
            (Wrapped::Table(_), Some(_)) => {
                return Err(errors::value(
                    "probs given to a wrapper built with a habit table: give one or the other",
                ));
            }
            (Wrapped::Policy(a), Some(p)) => a.act_with(i, p.as_slice()?).map_err(agent_error)?,
            (Wrapped::Policy(_), None) => {
                return Err(errors::value(
                    "probs missing: a wrapper without a habit table takes the habit's probabilities each tick",
                ));
            }
        };
        Ok((d.action, decision_dict(py, &d)?))
    }

    /// The outcome of the last action: reward, next observed state, the episode's flags.
    fn observe(
        &self,
        reward: f64,
        next_observed: &Bound<'_, PyAny>,
        terminated: bool,
        truncated: bool,
    ) -> PyResult<()> {
        let reward = crate::agent::finite_reward(reward)?;
        let i = self.index(next_observed)?;
        self.lock()
            .controller()
            .observe(reward, i, Ending::from_flags(terminated, truncated));
        Ok(())
    }

    /// Ends the episode: test-time learning (§V), the habit's corrections included.
    fn end_episode(&self) {
        self.lock().controller().end_episode();
    }

    /// The corrections test-time learning added to an external habit, `(n_states,
    /// n_actions)`; for a habit table, its counts `ν`.
    fn habit_counts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let counts = match &*self.lock() {
            Wrapped::Table(a) => a.habit().nu().to_vec(),
            Wrapped::Policy(a) => a.habit().corrections().to_vec(),
        };
        let n_states: usize = self.sizes.iter().product();
        let n_actions = counts.len() / n_states;
        let rows: Vec<Vec<f64>> = counts.chunks(n_actions).map(<[f64]>::to_vec).collect();
        PyArray2::from_vec2(py, &rows).map_err(|e| errors::value(e.to_string()))
    }

    fn __repr__(&self) -> String {
        format!(
            "ScaledHabitAgent(habit={})",
            if self.external() { "external policy" } else { "table" }
        )
    }
}

/// The Q-table's habit probabilities `σ(Q[s,·]/T)` of `agent`, `(n_states, n_actions)`,
/// computed as the scaled agent computes them (`T` is `nu_temperature`, a keyword like
/// the scaled agent's parameters).
#[pyfunction]
#[pyo3(signature = (agent, **params))]
fn q_table_habit<'py>(
    py: Python<'py>,
    agent: &PyAgent,
    params: Option<&Bound<'_, PyDict>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let p = scaled_params(None, params)?;
    let q = &agent.bundle.q_learning;
    let probs = unforeseen_agent::learning::nu_from_q(q.table(), q.n_actions(), 1.0, p.learning.nu_temperature);
    let rows: Vec<Vec<f64>> = probs.chunks(q.n_actions()).map(<[f64]>::to_vec).collect();
    let arr = PyArray2::from_vec2(py, &rows).map_err(|e| errors::value(e.to_string()))?;
    Ok(arr)
}

/// The batch summary over training seeds of a results file (`unforeseen batch`'s
/// `results.summary.json` rows), as JSON text: lines written by `unforeseen.evaluate`
/// are read by the same code as the command line's. The file is read against the run
/// its identity names (`runs::merge::read_run`): a file of two runs is refused, and a
/// partial run (a shard, a run cut short) too, listing the missing units, unless
/// `partial`.
#[pyfunction]
#[pyo3(signature = (path, partial = false))]
fn summarize_json(py: Python<'_>, path: PathBuf, partial: bool) -> PyResult<String> {
    let run = py
        .detach(|| unforeseen_harness::runs::merge::read_run(&path, partial))
        .map_err(errors::to_py)?;
    serde_json::to_string(&unforeseen_harness::runs::batch::summarize(&run.lines)).map_err(errors::to_py)
}

/// Registers the classes and functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScaledHabitAgent>()?;
    m.add_function(wrap_pyfunction!(q_table_habit, m)?)?;
    m.add_function(wrap_pyfunction!(summarize_json, m)?)?;
    Ok(())
}
