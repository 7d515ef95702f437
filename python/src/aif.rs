//! The general active-inference agent of `unforeseen_agent::aif` (issue 46) for Python:
//! `AifAgent` holds a [`GatedAgent`] and converts numpy arrays in pymdp's layout to the
//! library's model and back. The pymdp-style front is `unforeseen.aif.Agent`
//! (python/unforeseen/aif.py), which converts its arguments to float64 arrays and calls
//! this class; every check (shapes, normalisation, NaN, negative counts) is the
//! library's, raised as `ValueError` naming the array.

use numpy::{PyArray1, PyArrayDyn, PyArrayMethods, PyReadonlyArray1, PyReadonlyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use unforeseen_agent::aif::action::{Sampling, Selection};
use unforeseen_agent::aif::agent::{Agent, AgentParams};
use unforeseen_agent::aif::efe::{EfeTerms, Preferences};
use unforeseen_agent::aif::error::ModelError;
use unforeseen_agent::aif::gate::{GatedAgent, Habit};
use unforeseen_agent::aif::model::{Model, ModelParts};
use unforeseen_agent::aif::tensor::Tensor;

use crate::errors;

fn bad(e: ModelError) -> PyErr {
    errors::value(e.to_string())
}

fn tensor(a: &PyReadonlyArrayDyn<'_, f64>) -> Tensor {
    let v = a.as_array();
    Tensor {
        shape: v.shape().to_vec(),
        data: v.iter().copied().collect(),
    }
}

fn tensors(list: &[PyReadonlyArrayDyn<'_, f64>]) -> Vec<Tensor> {
    list.iter().map(tensor).collect()
}

fn vector(name: &str, a: &PyReadonlyArrayDyn<'_, f64>) -> PyResult<Vec<f64>> {
    let t = tensor(a);
    if t.ndim() != 1 {
        return Err(errors::value(format!(
            "{name} has {} axes {:?}, must be a vector",
            t.ndim(),
            t.shape
        )));
    }
    Ok(t.data)
}

/// Non-negative indices, named for the error (`A_dependencies[1]`, `observation`).
fn indices(name: &str, xs: &[i64]) -> PyResult<Vec<usize>> {
    xs.iter()
        .map(|&x| usize::try_from(x).map_err(|_| errors::value(format!("{name} holds {x}, must be indices >= 0"))))
        .collect()
}

fn index_lists(name: &str, xs: Option<Vec<Vec<i64>>>) -> PyResult<Option<Vec<Vec<usize>>>> {
    xs.map(|l| {
        l.iter()
            .enumerate()
            .map(|(i, x)| indices(&format!("{name}[{i}]"), x))
            .collect()
    })
    .transpose()
}

/// Marginals, one per factor, checked against `model` (named `name` in the error).
fn marginals(model: &Model, name: &str, qs: &[PyReadonlyArray1<'_, f64>]) -> PyResult<Vec<Vec<f64>>> {
    let qs: Vec<Vec<f64>> = qs.iter().map(|q| q.as_array().to_vec()).collect();
    model.check_marginals(name, &qs).map_err(bad)?;
    Ok(qs)
}

/// Two float64 vectors (`q_pi`, `neg_efe`).
type Vectors<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

fn to_numpy<'py>(py: Python<'py>, t: &Tensor) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    PyArray1::from_vec(py, t.data.clone()).reshape(t.shape.clone())
}

fn list_out<'py>(py: Python<'py>, ts: &[Tensor]) -> PyResult<Vec<Bound<'py, PyArrayDyn<f64>>>> {
    ts.iter().map(|t| to_numpy(py, t)).collect()
}

fn vecs_out<'py>(py: Python<'py>, vs: &[Vec<f64>]) -> Vec<Bound<'py, PyArray1<f64>>> {
    vs.iter().map(|v| PyArray1::from_vec(py, v.clone())).collect()
}

fn habit(name: &str) -> PyResult<Habit> {
    match name {
        "learned" => Ok(Habit::Learned),
        "prior" => Ok(Habit::Prior),
        _ => Err(errors::value(format!(
            "habit {name:?} is not one of \"learned\" (the action planned most often in the most likely state) or \"prior\" (E's first-step marginal)"
        ))),
    }
}

/// An error of a tick with a Python habit: the policy's own exception, or the model's.
struct TickError(PyErr);

impl From<ModelError> for TickError {
    fn from(e: ModelError) -> TickError {
        TickError(bad(e))
    }
}

impl From<PyErr> for TickError {
    fn from(e: PyErr) -> TickError {
        TickError(e)
    }
}

impl From<TickError> for PyErr {
    fn from(e: TickError) -> PyErr {
        e.0
    }
}

/// What a Python habit returned, as one control index per factor: an int (one factor)
/// or a sequence of ints; anything else raises `ValueError` naming `habit`.
fn habit_action(u: &Bound<'_, PyAny>) -> Result<Vec<usize>, TickError> {
    let refuse = || {
        errors::value(format!(
            "habit returned {u}, must be one control index per factor (ints >= 0)"
        ))
    };
    let raw: Vec<i64> = match u.extract::<i64>() {
        Ok(x) => vec![x],
        Err(_) => u.extract::<Vec<i64>>().map_err(|_| refuse())?,
    };
    Ok(raw
        .iter()
        .map(|&x| usize::try_from(x).map_err(|_| refuse()))
        .collect::<PyResult<Vec<_>>>()?)
}

/// A model in pymdp's layout behind the paper's surprise gate (the library's
/// `aif::gate::GatedAgent`).
#[pyclass(module = "unforeseen._unforeseen", unsendable)]
pub struct AifAgent {
    gated: GatedAgent,
    rng: ChaCha8Rng,
}

#[pymethods]
impl AifAgent {
    /// Builds and validates the model and the agent; errors name the array.
    #[new]
    #[pyo3(signature = (A, B, C, D, E, pA, pB, A_dependencies, B_dependencies, policies, policy_len, gamma, alpha, num_iter, action_selection, sampling_mode, use_utility, use_states_info_gain, use_param_info_gain, preferences, epsilon, habit_name, seed))]
    #[allow(non_snake_case, clippy::too_many_arguments)]
    fn new(
        A: Vec<PyReadonlyArrayDyn<'_, f64>>,
        B: Vec<PyReadonlyArrayDyn<'_, f64>>,
        C: Option<Vec<PyReadonlyArrayDyn<'_, f64>>>,
        D: Option<Vec<PyReadonlyArrayDyn<'_, f64>>>,
        E: Option<PyReadonlyArrayDyn<'_, f64>>,
        pA: Option<Vec<PyReadonlyArrayDyn<'_, f64>>>,
        pB: Option<Vec<PyReadonlyArrayDyn<'_, f64>>>,
        A_dependencies: Option<Vec<Vec<i64>>>,
        B_dependencies: Option<Vec<Vec<i64>>>,
        policies: Option<Vec<Vec<Vec<i64>>>>,
        policy_len: usize,
        gamma: f64,
        alpha: f64,
        num_iter: usize,
        action_selection: &str,
        sampling_mode: &str,
        use_utility: bool,
        use_states_info_gain: bool,
        use_param_info_gain: bool,
        preferences: &str,
        epsilon: f64,
        habit_name: &str,
        seed: u64,
    ) -> PyResult<Self> {
        let d = D
            .map(|ds| {
                ds.iter()
                    .enumerate()
                    .map(|(f, x)| vector(&format!("D[{f}]"), x))
                    .collect::<PyResult<Vec<_>>>()
            })
            .transpose()?;
        let parts = ModelParts {
            A: tensors(&A),
            B: tensors(&B),
            C: C.as_deref().map(tensors),
            D: d,
            E: E.as_ref().map(|e| vector("E", e)).transpose()?,
            pA: pA.as_deref().map(tensors),
            pB: pB.as_deref().map(tensors),
            A_dependencies: index_lists("A_dependencies", A_dependencies)?,
            B_dependencies: index_lists("B_dependencies", B_dependencies)?,
        };
        let model = Model::new(parts).map_err(bad)?;
        let action_selection = match action_selection {
            "deterministic" => Selection::Deterministic,
            "stochastic" => Selection::Stochastic { alpha },
            other => {
                return Err(errors::value(format!(
                    "action_selection {other:?} is not \"deterministic\" or \"stochastic\""
                )));
            }
        };
        let sampling_mode = match sampling_mode {
            "full" => Sampling::Full,
            "marginal" => Sampling::Marginal,
            other => {
                return Err(errors::value(format!(
                    "sampling_mode {other:?} is not \"full\" or \"marginal\""
                )));
            }
        };
        let preferences = match preferences {
            "raw" => Preferences::Raw,
            "ln_softmax" => Preferences::LnSoftmax,
            other => {
                return Err(errors::value(format!(
                    "preferences {other:?} is not \"raw\" (pymdp: C as given) or \"ln_softmax\" (the paper)"
                )));
            }
        };
        let params = AgentParams {
            policy_len,
            gamma,
            num_iter,
            action_selection,
            sampling_mode,
            terms: EfeTerms {
                utility: use_utility,
                states_info_gain: use_states_info_gain,
                param_info_gain: use_param_info_gain,
            },
            preferences,
        };
        let policies = policies
            .map(|ps| {
                ps.iter()
                    .enumerate()
                    .map(|(p, steps)| {
                        steps
                            .iter()
                            .enumerate()
                            .map(|(t, u)| indices(&format!("policies[{p}][{t}]"), u))
                            .collect::<PyResult<Vec<_>>>()
                    })
                    .collect::<PyResult<Vec<_>>>()
            })
            .transpose()?;
        let agent = Agent::new(model, params, policies.as_deref()).map_err(bad)?;
        let gated = GatedAgent::new(agent, epsilon, habit(habit_name)?).map_err(bad)?;
        Ok(AifAgent {
            gated,
            rng: ChaCha8Rng::seed_from_u64(seed),
        })
    }

    /// The posterior over each factor after `observation` (one index per modality),
    /// from `empirical_prior` (default D): pymdp's fpi.
    #[pyo3(signature = (observation, empirical_prior=None))]
    fn infer_states<'py>(
        &self,
        py: Python<'py>,
        observation: Vec<i64>,
        empirical_prior: Option<Vec<PyReadonlyArray1<'py, f64>>>,
    ) -> PyResult<Vec<Bound<'py, PyArray1<f64>>>> {
        let agent = self.gated.agent();
        let obs = indices("observation", &observation)?;
        let prior = match empirical_prior {
            Some(p) => marginals(agent.model(), "empirical_prior", &p)?,
            None => agent.initial_prior(),
        };
        Ok(vecs_out(py, &agent.infer_states(&obs, &prior).map_err(bad)?))
    }

    /// The variational free energy (nats) of `qs` after `observation` from `empirical_prior`.
    fn vfe(
        &self,
        observation: Vec<i64>,
        empirical_prior: Vec<PyReadonlyArray1<'_, f64>>,
        qs: Vec<PyReadonlyArray1<'_, f64>>,
    ) -> PyResult<f64> {
        let agent = self.gated.agent();
        let obs = indices("observation", &observation)?;
        agent.model().check_obs(&obs).map_err(bad)?;
        let prior = marginals(agent.model(), "empirical_prior", &empirical_prior)?;
        let qs = marginals(agent.model(), "qs", &qs)?;
        Ok(agent.vfe(&obs, &prior, &qs))
    }

    /// `(q_pi, neg_efe)` of every policy from the posterior `qs` (pymdp's order and sign).
    fn infer_policies<'py>(&self, py: Python<'py>, qs: Vec<PyReadonlyArray1<'py, f64>>) -> PyResult<Vectors<'py>> {
        let agent = self.gated.agent();
        let qs = marginals(agent.model(), "qs", &qs)?;
        let post = agent.infer_policies(&qs);
        let neg: Vec<f64> = post.G.iter().map(|g| -g).collect();
        Ok((PyArray1::from_vec(py, post.q_pi), PyArray1::from_vec(py, neg)))
    }

    /// The multi-action (one control per factor) from `q_pi`.
    fn sample_action<'py>(
        &mut self,
        py: Python<'py>,
        q_pi: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray1<i64>>> {
        let agent = self.gated.agent();
        let q = q_pi.as_array().to_vec();
        if q.len() != agent.policies().len() {
            return Err(errors::value(format!(
                "q_pi has {} entries, must have one per policy ({})",
                q.len(),
                agent.policies().len()
            )));
        }
        if q.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(errors::value("q_pi holds a NaN, infinite or negative entry"));
        }
        let u = agent.sample_action(&q, &mut self.rng);
        Ok(PyArray1::from_vec(py, u.iter().map(|&x| x as i64).collect()))
    }

    /// The prior of the next step after `action` from `qs`.
    fn update_empirical_prior<'py>(
        &self,
        py: Python<'py>,
        action: Vec<i64>,
        qs: Vec<PyReadonlyArray1<'py, f64>>,
    ) -> PyResult<Vec<Bound<'py, PyArray1<f64>>>> {
        let agent = self.gated.agent();
        let u = indices("action", &action)?;
        let qs = marginals(agent.model(), "qs", &qs)?;
        Ok(vecs_out(py, &agent.update_empirical_prior(&u, &qs).map_err(bad)?))
    }

    /// Dirichlet learning from one sequence: `beliefs[t][f]`, `observations[t][m]`,
    /// `actions[t][f]` (taken between t and t+1); `A` when `lr_pA` is given, `B` likewise.
    #[pyo3(signature = (beliefs, observations, actions, lr_pA, lr_pB))]
    #[allow(non_snake_case)]
    fn infer_parameters(
        &mut self,
        beliefs: Vec<Vec<Vec<f64>>>,
        observations: Vec<Vec<i64>>,
        actions: Vec<Vec<i64>>,
        lr_pA: Option<f64>,
        lr_pB: Option<f64>,
    ) -> PyResult<()> {
        let obs = observations
            .iter()
            .enumerate()
            .map(|(t, o)| indices(&format!("observations at t={t}"), o))
            .collect::<PyResult<Vec<_>>>()?;
        let acts = actions
            .iter()
            .enumerate()
            .map(|(t, u)| indices(&format!("actions[{t}]"), u))
            .collect::<PyResult<Vec<_>>>()?;
        self.gated
            .agent_mut()
            .infer_parameters(&beliefs, &obs, &acts, lr_pA, lr_pB)
            .map_err(bad)
    }

    /// One tick of the gated loop: `(action, info)` with `info` the surprise (bits),
    /// whether it planned, `q_pi` when it did, and the posterior `qs`. With `habit` (a
    /// callable `(observation, qs) -> action`), it acts from that policy instead of its
    /// own habit when the gate is closed; its exception propagates, and an action that
    /// is not one control index per factor raises `ValueError` naming `habit`.
    #[pyo3(signature = (observation, habit=None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        observation: Vec<i64>,
        habit: Option<Bound<'py, PyAny>>,
    ) -> PyResult<(Bound<'py, PyArray1<i64>>, Bound<'py, PyDict>)> {
        let obs = indices("observation", &observation)?;
        let (tick, qs) = match habit {
            None => self.gated.step(&obs, &mut self.rng).map_err(bad)?,
            Some(policy) => self
                .gated
                .step_with(&obs, &mut self.rng, |o, qs| {
                    let o: Vec<i64> = o.iter().map(|&x| x as i64).collect();
                    let u = policy.call1((o, vecs_out(py, qs)))?;
                    habit_action(&u)
                })
                .map_err(PyErr::from)?,
        };
        let info = PyDict::new(py);
        info.set_item("surprise", tick.surprise_bits)?;
        info.set_item("planned", tick.planned)?;
        if let Some(q) = tick.q_pi {
            info.set_item("q_pi", PyArray1::from_vec(py, q))?;
        }
        info.set_item("qs", vecs_out(py, &qs))?;
        let action = PyArray1::from_vec(py, tick.action.iter().map(|&x| x as i64).collect());
        Ok((action, info))
    }

    /// ε in bits (negative: plan on every tick); setting it keeps the learned habit.
    #[getter]
    fn epsilon(&self) -> f64 {
        self.gated.epsilon_bits()
    }

    #[setter]
    fn set_epsilon(&mut self, epsilon: f64) -> PyResult<()> {
        self.gated.set_epsilon_bits(epsilon).map_err(bad)
    }

    /// Start an episode: the prior is D again (the learned habit is kept).
    fn reset(&mut self) {
        self.gated.reset();
    }

    /// The utility of `observation` under C (`Σ_m C_m[o_m]`, a time-indexed C's first row).
    fn utility(&self, observation: Vec<i64>) -> PyResult<f64> {
        let obs = indices("observation", &observation)?;
        self.gated.agent().model().utility(&obs).map_err(bad)
    }

    /// The model's arrays by pymdp's name (`A`, `B`, `C`, `pA`, `pB`; None when absent).
    fn arrays<'py>(&self, py: Python<'py>, name: &str) -> PyResult<Option<Vec<Bound<'py, PyArrayDyn<f64>>>>> {
        let m = self.gated.agent().model();
        let ts = match name {
            "A" => Some(m.a()),
            "B" => Some(m.b()),
            "C" => Some(m.c()),
            "pA" => m.pa(),
            "pB" => m.pb(),
            other => return Err(errors::value(format!("no array {other:?}: one of A, B, C, pA, pB"))),
        };
        ts.map(|t| list_out(py, t)).transpose()
    }

    /// D, one prior per factor.
    #[getter(D)]
    fn d<'py>(&self, py: Python<'py>) -> Vec<Bound<'py, PyArray1<f64>>> {
        vecs_out(py, self.gated.agent().model().d())
    }

    /// E, the prior over policies (None: uniform).
    #[getter(E)]
    fn e<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        self.gated
            .agent()
            .model()
            .e()
            .map(|e| PyArray1::from_vec(py, e.to_vec()))
    }

    /// The policies, `[p][t][f]`.
    #[getter]
    fn policies(&self) -> Vec<Vec<Vec<usize>>> {
        self.gated.agent().policies().to_vec()
    }

    /// States per factor.
    #[getter]
    fn num_states(&self) -> Vec<usize> {
        self.gated.agent().model().num_states().to_vec()
    }

    /// Outcomes per modality.
    #[getter]
    fn num_obs(&self) -> Vec<usize> {
        self.gated.agent().model().num_obs().to_vec()
    }

    /// Controls per factor.
    #[getter]
    fn num_controls(&self) -> Vec<usize> {
        self.gated.agent().model().num_controls().to_vec()
    }

    /// The factors each modality depends on.
    #[getter(A_dependencies)]
    fn a_dependencies(&self) -> Vec<Vec<usize>> {
        self.gated.agent().model().a_dependencies().to_vec()
    }

    /// The parents of each factor.
    #[getter(B_dependencies)]
    fn b_dependencies(&self) -> Vec<Vec<usize>> {
        self.gated.agent().model().b_dependencies().to_vec()
    }

    /// The planning horizon.
    #[getter]
    fn policy_len(&self) -> usize {
        self.gated.agent().params().policy_len
    }
}

/// Registers the class.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<AifAgent>()
}
