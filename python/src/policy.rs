//! Python policies evaluated by the library's episode loop: [`PythonCall`] is a Python
//! callable asked each tick with the observation the Gymnasium env gives (int64
//! `(d, v, L, p)`, or the float32 kinematic vector), and the controllers here implement
//! the runner's [`Controller`] around it, so that a Python policy runs in the loop, and is
//! reported by the builders, of the command line's methods
//! ([`unforeseen_harness::runs::outside_methods`]). Python computes no figure.
//!
//! The one protocol a Python policy follows (`unforeseen.evaluate` documents it): a
//! callable `policy(obs) -> action`, or an object with `act(obs) -> action`; optionally
//! `reset(seed)`, called at the start of every episode with the controller seed of the
//! episode. A habit of the scaled agent (`ScaledWrapper`) is the same, with
//! `probs(obs) -> probabilities` in place of `act`.
//!
//! The GIL: the episodes run with it released; each call into Python takes it, and
//! checks for signals after the call (Ctrl-C: `KeyboardInterrupt`), as does the end of
//! every episode. The first Python exception (the policy's own, a bad return value, a
//! signal) stops the run at once (the controller answers with an action the env refuses,
//! which ends the episode) and is raised as it was.

use std::sync::Mutex;

use pyo3::prelude::*;
use unforeseen_agent::controller::{Controller, Decision, Dist, Ending};
use unforeseen_agent::habit::PolicyHabit;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_discretizer::Discretizer;
use unforeseen_env::{EnvConfig, Observation, ObservationForm};
use unforeseen_harness::error::Error;
use unforeseen_harness::progress::{Message, Progress};
use unforeseen_harness::runs::batch::load_scenarios;
use unforeseen_harness::runs::outside_methods::{ExternalMethod, ExternalRun, LinePlace, evaluate_external};

use crate::convert;
use crate::errors;
use crate::wrapper::{Habit, PyScaledHabitAgent, Wrapped};

/// The action a controller answers with once Python failed: the env refuses it, which
/// ends the episode with an error, so the run stops at once.
const STOP: usize = usize::MAX;

/// A Python callable asked each tick, and the run's first failure.
struct PythonCall {
    /// `act` (or `probs`), or the object itself where it is the callable.
    call: Py<PyAny>,
    /// The object's `reset(seed)`, if it has one.
    reset: Option<Py<PyAny>>,
    /// The observation's form.
    form: ObservationForm,
    /// Decodes the joint index into `(d, v, L, p)`.
    disc: Discretizer,
    /// The first Python exception of the run.
    failure: Mutex<Option<PyErr>>,
}

impl PythonCall {
    /// `object.<method>` if it has that method, else `object` itself if it is callable
    /// (a `TypeError` naming `what` otherwise); its `reset` if it has one.
    fn resolve(
        object: &Bound<'_, PyAny>,
        method: &str,
        what: &str,
        form: ObservationForm,
        disc: Discretizer,
    ) -> PyResult<PythonCall> {
        let callable_attr = |name: &str| -> PyResult<Option<Py<PyAny>>> {
            if !object.hasattr(name)? {
                return Ok(None);
            }
            let f = object.getattr(name)?;
            Ok(f.is_callable().then(|| f.unbind()))
        };
        let call = match callable_attr(method)? {
            Some(f) => f,
            None if object.is_callable() => object.clone().unbind(),
            None => {
                return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                    "{what}: expected a callable obs -> {}, or an object with {method}(obs), got {}",
                    if method == "act" { "action" } else { "probabilities" },
                    object.get_type().name()?
                )));
            }
        };
        Ok(PythonCall {
            call,
            reset: callable_attr("reset")?,
            form,
            disc,
            failure: Mutex::new(None),
        })
    }

    /// Whether the run already failed.
    fn failed(&self) -> bool {
        self.failure
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .is_some()
    }

    /// Keeps the run's first failure.
    fn fail(&self, e: PyErr) {
        let mut slot = self.failure.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        slot.get_or_insert(e);
    }

    /// The run's first failure, taken.
    fn take_failure(&self) -> Option<PyErr> {
        self.failure
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .take()
    }

    /// Calls `reset(seed)`, if the object has one (a failure is kept).
    fn begin(&self, seed: u64) {
        if let Some(reset) = &self.reset
            && !self.failed()
            && let Err(e) = Python::attach(|py| reset.call1(py, (seed,)).and_then(|_| py.check_signals()))
        {
            self.fail(e);
        }
    }

    /// Calls the callable with the observation of joint index `index` (or the kinematic
    /// `features`) as the Gymnasium env gives it, and reads the answer with `read`; then
    /// checks for signals. None once the run failed (the failure is kept).
    fn ask<T>(&self, index: usize, features: &[f32], read: impl FnOnce(&Bound<'_, PyAny>) -> PyResult<T>) -> Option<T> {
        if self.failed() {
            return None;
        }
        let answer = Python::attach(|py| {
            let obs = match self.form {
                ObservationForm::Discrete => Observation::Discrete {
                    state: self.disc.decode(index),
                    index,
                },
                ObservationForm::Kinematic => Observation::Kinematic(features.to_vec()),
            };
            let out = self.call.bind(py).call1((crate::env::observation(py, &obs),))?;
            let value = read(&out)?;
            py.check_signals()?;
            Ok(value)
        });
        answer.map_err(|e| self.fail(e)).ok()
    }
}

/// An action returned by a policy: an integer 0, 1 or 2.
fn read_action(out: &Bound<'_, PyAny>) -> PyResult<usize> {
    out.extract::<i64>()
        .ok()
        .and_then(|a| usize::try_from(a).ok())
        .filter(|a| *a < 3)
        .ok_or_else(|| {
            errors::value(format!(
                "the policy returned {}: expected an action 0 (maintain), 1 (speed up) or 2 (slow down)",
                out.repr().map_or_else(|_| "?".into(), |r| r.to_string())
            ))
        })
}

/// Probabilities returned by a habit: a sequence of floats (a list, a numpy array).
fn read_probs(out: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    out.extract::<Vec<f64>>().map_err(|_| {
        errors::value(format!(
            "the habit returned {}: expected action probabilities, one float per action",
            out.repr().map_or_else(|_| "?".into(), |r| r.to_string())
        ))
    })
}

/// A Python policy as the runner's controller: acts as the policy answers; never
/// reasons, never learns.
struct PlainPolicy<'a> {
    call: &'a PythonCall,
    features: Vec<f32>,
}

impl Controller for PlainPolicy<'_> {
    fn name(&self) -> &'static str {
        "python policy"
    }

    fn begin_episode(&mut self, seed: u64) {
        self.call.begin(seed);
    }

    fn see_features(&mut self, features: &[f32]) {
        self.features.clear();
        self.features.extend_from_slice(features);
    }

    fn act(&mut self, obs: usize) -> Decision {
        let action = self.call.ask(obs, &self.features, read_action).unwrap_or(STOP);
        let mut policy = [0.0; 3];
        if let Some(p) = policy.get_mut(action) {
            *p = 1.0;
        }
        Decision {
            action,
            policy: Dist::from_slice(&policy),
            ..Decision::default()
        }
    }
}

/// The scaled agent around a Python habit: the habit's probabilities asked each tick,
/// everything else (reasoning, scaling, learning) the scaled agent's.
struct WrappedPolicy<'a> {
    call: &'a PythonCall,
    features: Vec<f32>,
    agent: ScaledAgent<PolicyHabit>,
}

impl Controller for WrappedPolicy<'_> {
    fn name(&self) -> &'static str {
        "scaled wrapper"
    }

    fn begin_episode(&mut self, seed: u64) {
        self.call.begin(seed);
        self.agent.begin_episode(seed);
    }

    fn see_features(&mut self, features: &[f32]) {
        self.features.clear();
        self.features.extend_from_slice(features);
    }

    fn act(&mut self, obs: usize) -> Decision {
        let Some(probs) = self.call.ask(obs, &self.features, read_probs) else {
            return Decision {
                action: STOP,
                ..Decision::default()
            };
        };
        match self.agent.act_with(obs, &probs) {
            Ok(d) => d,
            Err(e) => {
                self.call.fail(crate::wrapper::agent_error(e));
                Decision {
                    action: STOP,
                    ..Decision::default()
                }
            }
        }
    }

    fn observe(&mut self, reward: f64, next_obs: usize, ending: Ending) {
        self.agent.observe(reward, next_obs, ending);
    }

    fn end_episode(&mut self) {
        self.agent.end_episode();
    }
}

/// No progress shown; cancelled once Python failed or a signal arrived (checked at the
/// end of every episode, with the GIL).
struct Watch<'a> {
    call: Option<&'a PythonCall>,
    signal: Mutex<Option<PyErr>>,
}

impl Progress for Watch<'_> {
    fn phase(&self, _name: &str, _total: u64) {}
    fn advance(&self, _n: u64) {}
    fn finish(&self) {}
    fn message(&self, _kind: Message, _line: &str) {}
    fn cancelled(&self) -> bool {
        if self.call.is_some_and(PythonCall::failed) {
            return true;
        }
        match Python::attach(|py| py.check_signals()) {
            Ok(()) => false,
            Err(e) => {
                *self.signal.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some(e);
                true
            }
        }
    }
}

/// What is evaluated: a Python policy, or the scaled agent around a habit.
enum Evaluated<'a> {
    Plain(PythonCall),
    Wrapped(&'a PyScaledHabitAgent, Option<PythonCall>),
}

/// Evaluates `policy` on `map` by the library's episode loop and reports it in the batch
/// results schema: a list of [`PolicyRun`]s, one per run (one per protocol of
/// `protocols` for a policy that learns across episodes, the scaled agent around a habit
/// with learning on; else one run whose line covers them all). `policy` follows the
/// protocol of the module docs, or is a `ScaledHabitAgent`; `observation` is the form a
/// plain policy reads (`"discrete"` or `"kinematic"`; a wrapper's own form otherwise).
/// The episodes are those of `unforeseen eval` for a method named `method` (world seeds
/// from the map and the episode, controller seeds from the name too). A Python exception
/// raised by the policy (or `KeyboardInterrupt`) is raised as it was.
#[pyfunction]
#[pyo3(signature = (policy, map, method, protocols, episodes, seed, train_seed = None, train_episodes = None, first_unit = 0, observation = "discrete"))]
#[allow(clippy::too_many_arguments)]
pub fn evaluate_policy(
    py: Python<'_>,
    policy: &Bound<'_, PyAny>,
    map: &Bound<'_, PyAny>,
    method: &Bound<'_, PyAny>,
    protocols: Vec<String>,
    episodes: &Bound<'_, PyAny>,
    seed: &Bound<'_, PyAny>,
    train_seed: Option<&Bound<'_, PyAny>>,
    train_episodes: Option<&Bound<'_, PyAny>>,
    first_unit: usize,
    observation: &str,
) -> PyResult<Vec<PolicyRun>> {
    let map = convert::path("map", map)?;
    let method = &convert::text("method", method)?;
    let episodes = convert::episodes("episodes", episodes)?;
    let seed = convert::seed("seed", seed)?;
    let train_seed = train_seed.map(|s| convert::seed("train_seed", s)).transpose()?;
    let train_episodes = train_episodes
        .map(|n| convert::episodes("train_episodes", n))
        .transpose()?;
    let protocols = protocols
        .iter()
        .map(|p| crate::agent::protocol(p))
        .collect::<PyResult<Vec<_>>>()?;
    let scenarios = load_scenarios(std::slice::from_ref(&map)).map_err(errors::to_py)?;
    let scenario = &scenarios[0];
    let disc = || -> PyResult<Discretizer> {
        Discretizer::new(scenario.map().expect("load_scenarios loads maps")).map_err(errors::to_py)
    };
    let evaluated = match policy.cast::<PyScaledHabitAgent>() {
        Ok(wrapper) => {
            let wrapper = wrapper.get();
            let call = match &wrapper.habit {
                Habit::External {
                    object: Some(object),
                    form,
                } => Some(PythonCall::resolve(object.bind(py), "probs", "habit", *form, disc()?)?),
                Habit::External { object: None, .. } => {
                    return Err(errors::value(
                        "this ScaledHabitAgent has no habit to ask each tick: build it with habit=",
                    ));
                }
                Habit::Table => None,
            };
            Evaluated::Wrapped(wrapper, call)
        }
        Err(_) => Evaluated::Plain(PythonCall::resolve(
            policy,
            "act",
            "policy",
            crate::env::observation_form(observation)?,
            disc()?,
        )?),
    };
    let (external, call) = match &evaluated {
        Evaluated::Plain(call) => (
            ExternalMethod {
                name: method,
                config: env_config(call.form),
                learns: false,
                planning: None,
            },
            Some(call),
        ),
        Evaluated::Wrapped(w, call) => (
            ExternalMethod {
                name: method,
                config: env_config(call.as_ref().map_or(ObservationForm::Discrete, |c| c.form)),
                learns: w.learns,
                planning: Some(&w.params),
            },
            call.as_ref(),
        ),
    };
    let place = LinePlace {
        first_unit,
        train_seed,
        train_episodes,
    };
    let watch = Watch {
        call,
        signal: Mutex::new(None),
    };
    let runs = py.detach(|| -> Result<Vec<ExternalRun>, Error> {
        let mut make = || fresh_controller(&evaluated);
        evaluate_external(
            scenario, &external, &mut make, &protocols, place, episodes, seed, &watch,
        )
    });
    // A Python failure (the policy's exception, a bad answer, a signal) is raised as it
    // was, before the library's error it caused.
    let failure = call.and_then(PythonCall::take_failure).or_else(|| {
        watch
            .signal
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner)
            .take()
    });
    if let Some(e) = failure {
        return Err(e);
    }
    Ok(runs
        .map_err(errors::to_py)?
        .into_iter()
        .map(|run| PolicyRun { run })
        .collect())
}

/// One run of a Python policy (`evaluate_policy`): its result line, as data and as the
/// results file's line, and its episodes.
#[pyclass(name = "PolicyRun", module = "unforeseen._unforeseen", frozen)]
pub struct PolicyRun {
    run: ExternalRun,
}

#[pymethods]
impl PolicyRun {
    /// The result line as a dict (the batch results schema).
    #[getter]
    fn line<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::reports::to_py(py, &serde_json::to_value(&self.run.line).map_err(errors::to_py)?)
    }

    /// The result line as the results file holds it (JSON, without the newline): the
    /// bytes `unforeseen batch` writes for a line of the same figures.
    #[getter]
    fn line_text(&self) -> PyResult<String> {
        serde_json::to_string(&self.run.line).map_err(errors::to_py)
    }

    /// Every episode, in order, as eval.json holds them (dicts).
    #[getter]
    fn episodes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::reports::to_py(py, &serde_json::to_value(&self.run.episodes).map_err(errors::to_py)?)
    }

    fn __repr__(&self) -> String {
        let l = &self.run.line;
        format!(
            "PolicyRun(method={}, scenario={}, protocol={}, episodes={})",
            l.method,
            l.scenario,
            l.protocol.name(),
            l.episodes
        )
    }
}

/// A fresh controller of what is evaluated: the scaled agent as built, for a wrapper.
fn fresh_controller<'a>(evaluated: &'a Evaluated<'_>) -> Result<Box<dyn Controller + 'a>, Error> {
    Ok(match evaluated {
        Evaluated::Plain(call) => Box::new(PlainPolicy {
            call,
            features: Vec::new(),
        }),
        Evaluated::Wrapped(w, Some(call)) => match w.fresh() {
            Wrapped::Policy(agent) => Box::new(WrappedPolicy {
                call,
                features: Vec::new(),
                agent: *agent,
            }),
            table => table.into_controller(),
        },
        Evaluated::Wrapped(w, None) => w.fresh().into_controller(),
    })
}

/// An env observing in `form`, with the Gymnasium env's pedestrian slots.
fn env_config(form: ObservationForm) -> EnvConfig {
    EnvConfig {
        observation: form,
        ..EnvConfig::default()
    }
}

/// `(name, source)` of the scenario of each of `maps` (embedded names or map files), as
/// the batch's result lines carry them (`"jaywalk"`, `"embedded:jaywalk"`), by the
/// batch's own lookup ([`load_scenarios`]), which refuses a map listed twice.
#[pyfunction]
fn scenario_sources(maps: &Bound<'_, PyAny>) -> PyResult<Vec<(String, String)>> {
    let maps = convert::paths("maps", maps)?;
    let scenarios = load_scenarios(&maps).map_err(|e| errors::value(format!("maps: {}", errors::message(&e))))?;
    Ok(scenarios
        .iter()
        .map(|s| (s.name().to_string(), s.source.clone()))
        .collect())
}

/// Registers the class and the function.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PolicyRun>()?;
    m.add_function(wrap_pyfunction!(evaluate_policy, m)?)?;
    m.add_function(wrap_pyfunction!(scenario_sources, m)?)?;
    Ok(())
}
