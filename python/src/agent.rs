//! The agents from Python: training and agent files ([`unforeseen_harness::training`],
//! [`unforeseen_harness::training::agent_file`]), a controller of every method the command line has
//! ([`unforeseen_harness::episodes::Method`]) with parameters through `--set`'s path
//! ([`unforeseen_harness::overrides`]), and the library's evaluation ([`unforeseen_harness::episodes::evaluation`]).

use std::path::PathBuf;
use std::sync::Mutex;

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict};
use unforeseen_agent::controller::{Controller, Decision, Ending};
use unforeseen_agent::param_decl::ParamValue;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::runs::evaluate::EvalRequest;
use unforeseen_harness::training::TrainSeeds;
use unforeseen_sim::Map;

use crate::convert;
use crate::errors;
use crate::reports::EvalResult;

/// Every method, in the command line's order.
pub fn all_methods() -> Vec<Method> {
    let mut v = Method::PAPER.to_vec();
    v.extend(Method::ABLATIONS);
    v.extend(Method::REFERENCE);
    v
}

/// A method by its command-line name.
pub fn method(name: &str) -> PyResult<Method> {
    all_methods().into_iter().find(|m| m.name() == name).ok_or_else(|| {
        errors::value(format!(
            "unknown method '{name}'; methods: {}",
            all_methods().iter().map(|m| m.name()).collect::<Vec<_>>().join(", ")
        ))
    })
}

/// A protocol by name (`zero-shot`, `continual`).
pub fn protocol(name: &str) -> PyResult<Protocol> {
    serde_json::from_value(serde_json::Value::String(name.into()))
        .map_err(|_| errors::value(format!("unknown protocol '{name}'; protocols: zero-shot, continual")))
}

/// A keyword argument as the typed value the parameter table takes: a bool, a whole
/// number or a float (`inf` included).
fn param_value(key: &str, v: &Bound<'_, PyAny>) -> PyResult<ParamValue> {
    if v.is_instance_of::<PyBool>() {
        return Ok(ParamValue::Bool(v.extract()?));
    }
    if let Ok(i) = v.extract::<i64>() {
        return Ok(ParamValue::Int(i));
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok(ParamValue::Number(x));
    }
    Err(errors::value(format!(
        "{key}: expected a number, a bool or a string, got {}",
        v.get_type().name()?
    )))
}

/// The scaled agent's parameters: the defaults, or on `map` its settings
/// (`overrides::on_map`), with the keyword arguments `params` set through the parameter
/// table (the path `--set` takes, with its checks and messages).
pub fn scaled_params(map: Option<&Map>, params: Option<&Bound<'_, PyDict>>) -> PyResult<ScaledParams> {
    let mut p = match map {
        Some(map) => unforeseen_harness::overrides::on_map(map, []).map_err(errors::to_py)?,
        None => ScaledParams::default(),
    };
    if let Some(d) = params {
        for (k, v) in d.iter() {
            let key: String = k.extract()?;
            // Text goes the way `--set KEY=TEXT` does (the same parsing and messages);
            // numbers and bools as typed values.
            if let Ok(text) = v.extract::<String>() {
                unforeseen_harness::overrides::set_one(&mut p, &key, &text).map_err(errors::to_py)?;
            } else {
                unforeseen_harness::overrides::set_value(&mut p, &key, param_value(&key, &v)?)
                    .map_err(errors::to_py)?;
            }
        }
    }
    unforeseen_harness::overrides::apply(p, &[]).map_err(errors::to_py)
}

/// A trained agent (an agent file's content).
#[pyclass(name = "Agent", module = "unforeseen._unforeseen", frozen)]
pub struct PyAgent {
    pub bundle: AgentBundle,
    returns: Vec<f64>,
}

#[pymethods]
impl PyAgent {
    /// Writes the agent file (atomically), as `unforeseen train --out` does: a `path`
    /// that holds something other than an agent file (a map, results) raises
    /// `ValueError` naming it, unless `force`.
    #[pyo3(signature = (path, force = false))]
    fn save(&self, path: PathBuf, force: bool) -> PyResult<()> {
        use unforeseen_harness::runs::outputs::{Outputs, Own};
        Outputs::new()
            .file("path", &path, Own::Agent)
            .check(force)
            .map_err(errors::to_py)?;
        unforeseen_harness::training::agent_file::save(&path, &self.bundle).map_err(errors::to_py)
    }

    /// What the file records: map, episodes, seed, ... (strings).
    #[getter]
    fn meta(&self) -> std::collections::BTreeMap<String, String> {
        self.bundle.meta.clone()
    }

    /// Returns of the training episodes (empty for a loaded agent).
    #[getter]
    fn train_returns(&self) -> Vec<f64> {
        self.returns.clone()
    }

    /// Factor sizes `[n_d, n_v, n_L, n_p]` of its world model.
    #[getter]
    fn factor_sizes(&self) -> Vec<usize> {
        self.bundle.world_model.structure().sizes()
    }

    /// A fresh controller of `method` (any name of `unforeseen eval --method`) for
    /// episodes on `map` (the scripted `brake-on-pedestrian` follows its red-light rule),
    /// with the scaled agent's parameters as keywords (`epsilon=0.3, horizon=4`: the keys
    /// of `--set`).
    #[pyo3(signature = (method = "scaled", map = "jaywalk", **params))]
    fn controller(&self, method: &str, map: &str, params: Option<&Bound<'_, PyDict>>) -> PyResult<PyController> {
        let m = self::method(method)?;
        let map = crate::maps::load(map, None)?;
        let p = scaled_params(Some(&map), params)?;
        let c = m.controller(&self.bundle, &p, &map).map_err(errors::to_py)?;
        Ok(PyController::new(c, self.factor_sizes(), m))
    }

    fn __repr__(&self) -> String {
        let g = |k: &str| self.bundle.meta.get(k).cloned().unwrap_or_else(|| "?".into());
        format!(
            "Agent(map={}, episodes={}, seed={})",
            g("map"),
            g("episodes"),
            g("seed")
        )
    }
}

/// Trains an agent on `map` (a map file or an embedded name) for `episodes` episodes
/// from `seed` (as `unforeseen train`), with the GIL released; Ctrl-C raises
/// `KeyboardInterrupt`. The arguments as [`crate::convert`] reads them.
#[pyfunction]
fn train(
    py: Python<'_>,
    map: &Bound<'_, PyAny>,
    episodes: &Bound<'_, PyAny>,
    seed: &Bound<'_, PyAny>,
) -> PyResult<PyAgent> {
    let map = convert::path("map", map)?;
    let episodes = convert::episodes("episodes", episodes)?;
    let seed = convert::seed("seed", seed)?;
    let map = crate::maps::load(&map.to_string_lossy(), None)?;
    let cfg = unforeseen_harness::training::TrainConfig::new(episodes, seed);
    let (bundle, log) = crate::interrupt::interruptible(py, |progress| {
        unforeseen_harness::training::train_with_progress(&map, &cfg, progress)
    })?;
    Ok(PyAgent {
        bundle,
        returns: log.returns,
    })
}

/// Trains one agent per seed of `seeds` on `map`, in parallel (rayon, the GIL released),
/// loading and saving them in the agent cache `cache` (`None`: no cache) as
/// `--train-seeds` does, so a notebook and the command line share agents. The seeds
/// are bounded as `--train-seeds` bounds them ([`TrainSeeds::new`]: at least one, at
/// most 1,000, each once); the cache folder is checked before any training.
#[pyfunction]
fn train_agents(
    py: Python<'_>,
    seeds: &Bound<'_, PyAny>,
    map: &Bound<'_, PyAny>,
    episodes: &Bound<'_, PyAny>,
    cache: Option<&Bound<'_, PyAny>>,
    timeout_as: &Bound<'_, PyAny>,
) -> PyResult<Vec<PyAgent>> {
    let seeds = TrainSeeds::new(convert::seeds("seeds", seeds)?).map_err(|e| errors::value(format!("seeds: {e}")))?;
    let map = convert::path("map", map)?;
    let episodes = convert::episodes("episodes", episodes)?;
    let cache = cache.map(|c| convert::path("cache", c)).transpose()?;
    let timeout_as = convert::text("timeout_as", timeout_as)?
        .parse()
        .map_err(|e: String| errors::value(format!("timeout_as: {e}")))?;
    if let Some(dir) = &cache {
        unforeseen_harness::runs::outputs::check_cache(dir).map_err(errors::to_py)?;
    }
    let map = crate::maps::load(&map.to_string_lossy(), None)?;
    let cfg = unforeseen_harness::training::TrainConfig {
        timeout_as,
        ..unforeseen_harness::training::TrainConfig::new(episodes, 0)
    };
    let agents = crate::interrupt::interruptible(py, |progress| {
        unforeseen_harness::training::train_agents(&map, &seeds.0, &cfg, cache.as_deref(), progress)
    })?;
    Ok(agents
        .into_iter()
        .map(|a| PyAgent {
            bundle: a.bundle,
            returns: Vec::new(),
        })
        .collect())
}

/// Loads and checks an agent file (errors name the file, the field and the fix).
#[pyfunction]
fn load_agent(path: PathBuf) -> PyResult<PyAgent> {
    let bundle = unforeseen_harness::training::agent_file::load(&path).map_err(errors::to_py)?;
    Ok(PyAgent {
        bundle,
        returns: Vec::new(),
    })
}

/// A scripted reference (`brake-on-pedestrian`, `never-brake`) for episodes on `map`
/// (its observations, and its red-light rule): it needs no agent.
#[pyfunction]
#[pyo3(signature = (method, map = "jaywalk"))]
fn scripted_controller(method: &str, map: &str) -> PyResult<PyController> {
    let m = self::method(method)?;
    let map = crate::maps::load(map, None)?;
    let sizes = unforeseen_discretizer::Discretizer::new(&map)
        .map_err(errors::to_py)?
        .factor_sizes()
        .to_vec();
    let c = m
        .scripted_controller(&sizes, &map)
        .map_err(errors::to_py)?
        .ok_or_else(|| {
            errors::value(format!(
                "{method} needs a trained agent: use agent.controller('{method}')"
            ))
        })?;
    Ok(PyController::new(c, sizes, m))
}

/// One method's controller: `act` decides, `observe` takes the outcome, `end_episode`
/// learns (the scaled agent's test-time learning).
#[pyclass(name = "Controller", module = "unforeseen._unforeseen")]
pub struct PyController {
    inner: Mutex<Box<dyn Controller>>,
    sizes: Vec<usize>,
    name: &'static str,
}

impl PyController {
    fn new(c: Box<dyn Controller>, sizes: Vec<usize>, method: Method) -> Self {
        let name = method.name();
        PyController {
            inner: Mutex::new(c),
            sizes,
            name,
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Box<dyn Controller>> {
        self.inner.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
    }

    /// An observation as the joint index: an int, or `(d, v, L, p)`.
    fn index(&self, obs: &Bound<'_, PyAny>) -> PyResult<usize> {
        joint_index(&self.sizes, obs)
    }
}

/// `reward` if it is a finite number, else a `ValueError` (a NaN or an infinite reward
/// would poison what test-time learning keeps).
pub fn finite_reward(reward: f64) -> PyResult<f64> {
    if reward.is_finite() {
        Ok(reward)
    } else {
        Err(errors::value(format!("reward {reward}: expected a finite number")))
    }
}

/// An observation as the joint index of a model with factor `sizes`: an int in
/// `0..product(sizes)`, or one integer per factor (`(d, v, L, p)`, e.g. `info["observed"]`);
/// a bool is refused, as the observation or as a factor.
pub fn joint_index(sizes: &[usize], obs: &Bound<'_, PyAny>) -> PyResult<usize> {
    let n: usize = sizes.iter().product();
    let is_bool = |x: &Bound<'_, PyAny>| x.is_instance_of::<pyo3::types::PyBool>();
    if is_bool(obs) {
        return Err(errors::value(format!(
            "observation {obs}: a bool is not an observation; expected a joint index in 0..{n} or (d, v, L, p)"
        )));
    }
    if let Ok(i) = obs.extract::<i64>() {
        return usize::try_from(i).ok().filter(|i| *i < n).ok_or_else(|| {
            errors::value(format!(
                "observation {i}: expected a joint index in 0..{n} or (d, v, L, p)"
            ))
        });
    }
    // At most one factor more than the model has is read: an endless iterator is refused.
    let factors: Vec<i64> = obs
        .try_iter()
        .and_then(|it| {
            it.take(sizes.len() + 1)
                .map(|x| {
                    let x = x?;
                    if is_bool(&x) {
                        return Err(errors::value("a bool is not a factor's value"));
                    }
                    x.extract::<i64>()
                })
                .collect::<PyResult<Vec<_>>>()
        })
        .map_err(|_| {
            errors::value(format!(
                "observation {obs}: expected a joint index or (d, v, L, p), e.g. info['observed']"
            ))
        })?;
    if factors.len() != sizes.len() {
        return Err(errors::value(format!(
            "observation {obs}: expected {} factors (d, v, L, p)",
            sizes.len()
        )));
    }
    let mut index = 0;
    for (&f, &size) in factors.iter().zip(sizes) {
        let f = usize::try_from(f)
            .ok()
            .filter(|f| *f < size)
            .ok_or_else(|| errors::value(format!("observation {obs}: factor sizes are {sizes:?}")))?;
        index = index * size + f;
    }
    Ok(index)
}

/// A decision record as the dict `act` returns.
pub fn decision_dict<'py>(py: Python<'py>, d: &Decision) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("action", d.action)?;
    out.set_item("reasoned", d.reasoned)?;
    out.set_item("surprise", d.surprise)?;
    out.set_item("theta", d.theta)?;
    out.set_item("policy", d.policy.to_vec())?;
    out.set_item("psi", d.psi.as_deref().map(<[f64]>::to_vec))?;
    out.set_item("scaling_iters", d.scaling_iters)?;
    Ok(out)
}

#[pymethods]
impl PyController {
    /// The method's name (as `unforeseen eval --method` spells it).
    #[getter]
    fn name(&self) -> &'static str {
        self.name
    }

    /// Starts an episode: clears beliefs, seeds the controller's own sampling.
    fn begin_episode(&self, seed: u64) {
        self.lock().begin_episode(seed);
    }

    /// Decides on `observation` (joint index or `(d, v, L, p)`): `(action, decision)`,
    /// the decision a dict with `surprise`, `theta`, `reasoned`, `policy` (the
    /// distribution the action came from), `psi` (the planner's, on ticks that planned)
    /// and `scaling_iters`.
    fn act<'py>(&self, py: Python<'py>, observation: &Bound<'py, PyAny>) -> PyResult<(usize, Bound<'py, PyDict>)> {
        let i = self.index(observation)?;
        let d = self.lock().act(i);
        Ok((d.action, decision_dict(py, &d)?))
    }

    /// The outcome of the last action: reward, next observation and the episode's flags.
    fn observe(
        &self,
        reward: f64,
        next_observation: &Bound<'_, PyAny>,
        terminated: bool,
        truncated: bool,
    ) -> PyResult<()> {
        let reward = finite_reward(reward)?;
        let i = self.index(next_observation)?;
        self.lock()
            .observe(reward, i, Ending::from_flags(terminated, truncated));
        Ok(())
    }

    /// Ends the episode (the scaled agent's test-time learning runs here).
    fn end_episode(&self) {
        self.lock().end_episode();
    }

    fn __repr__(&self) -> String {
        format!("Controller({})", self.name)
    }
}

/// `(world, controller)` seeds of evaluation episode `episode` of the method named
/// `method` on `map`, as `unforeseen eval` uses them: a built-in method's, or a Python
/// policy's under the name its lines carry
/// ([`unforeseen_harness::episodes::eval_seeds_named`]).
#[pyfunction]
fn eval_seeds(
    seed: &Bound<'_, PyAny>,
    map: &Bound<'_, PyAny>,
    method: &Bound<'_, PyAny>,
    episode: &Bound<'_, PyAny>,
) -> PyResult<(u64, u64)> {
    let seed = convert::seed("seed", seed)?;
    let map = convert::path("map", map)?;
    let method = convert::text("method", method)?;
    let episode = convert::whole("episode", episode, convert::SEEDS)?;
    let map = crate::maps::load(&map.to_string_lossy(), None)?;
    let s = unforeseen_harness::episodes::eval_seeds_named(seed, &map, &method, episode);
    Ok((s.world, s.controller))
}

/// `unforeseen eval`: the eval `request` (its fields as keyword arguments, read by
/// [`convert::request`] into the library's `EvalRequest`) planned, its agent trained or loaded and its episodes run by the
/// library with the GIL released, as the command line runs it, writing the same
/// eval.json into `out` (when the request has one); `agent` is an agent given loaded
/// instead of the request's agent file. Returns its report ([`EvalResult`]).
#[pyfunction]
#[pyo3(signature = (request, agent = None))]
fn evaluate(py: Python<'_>, request: &Bound<'_, PyDict>, agent: Option<&PyAgent>) -> PyResult<EvalResult> {
    let request: EvalRequest = convert::request(request)?;
    let given = agent.map(|a| a.bundle.clone());
    let outcome = crate::interrupt::interruptible(py, |progress| {
        let job = request.plan(given)?;
        let bundle = job.agent(progress)?;
        let outcome = job.run(bundle.as_ref(), progress)?;
        job.write(&outcome)?;
        Ok(outcome)
    })?;
    EvalResult::new(&outcome)
}

/// Registers the classes and functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAgent>()?;
    m.add_class::<PyController>()?;
    m.add_function(wrap_pyfunction!(train, m)?)?;
    m.add_function(wrap_pyfunction!(load_agent, m)?)?;
    m.add_function(wrap_pyfunction!(train_agents, m)?)?;
    m.add_function(wrap_pyfunction!(scripted_controller, m)?)?;
    m.add_function(wrap_pyfunction!(eval_seeds, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate, m)?)?;
    Ok(())
}
