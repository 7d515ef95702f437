//! One env per Python object: [`unforeseen_env::Env`] with Gymnasium's seeding on top.
//!
//! Seeding (what `unforeseen.UnforeseenEnv.reset` documents): `reset(seed=s)` seeds
//! Gymnasium's `np_random` with `s` and draws from it a 64-bit key; episode `k` since then
//! (`k = 0` for that reset, 1 for the next `reset()`, ...) runs with world seed
//! [`stream_seed`]`(key, k)`. The vector env does the same per env, so env `i` of a
//! vector env seeded `s` is the single env seeded `s + i`.

use numpy::{PyArray1, PyArrayMethods};
use pyo3::intern;
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::PyString;
use pyo3::types::{PyDict, PyTuple};
use unforeseen_env::{Env, EnvConfig, Info, Observation, ObservationForm, kinematic};
use unforeseen_sim::Map;

use crate::convert;
use crate::errors;
use crate::render;

/// World seed of episode `episode` of the stream keyed `key`.
pub fn stream_seed(key: u64, episode: u64) -> u64 {
    unforeseen_env::seeds::episode_seed(key, "gymnasium", episode)
}

/// [`stream_seed`] for Python: `key` and `episode` any whole numbers of `u64`.
#[pyfunction(name = "stream_seed")]
fn py_stream_seed(key: &Bound<'_, PyAny>, episode: &Bound<'_, PyAny>) -> PyResult<u64> {
    Ok(stream_seed(
        convert::seed("key", key)?,
        convert::whole("episode", episode, convert::SEEDS)?,
    ))
}

/// Parses an observation form name.
pub fn observation_form(name: &str) -> PyResult<ObservationForm> {
    match name {
        "discrete" => Ok(ObservationForm::Discrete),
        "kinematic" => Ok(ObservationForm::Kinematic),
        _ => Err(errors::value(format!(
            "observation '{name}': expected \"discrete\" (d, v, L, p) or \"kinematic\" (a float vector)"
        ))),
    }
}

/// Builds an env of `map` observing in `form` with `pedestrian_slots` and
/// `vehicle_slots` (`None`: the map's default, [`kinematic::default_vehicle_slots`]).
pub fn new_env(
    map: &Map,
    form: ObservationForm,
    pedestrian_slots: usize,
    vehicle_slots: Option<usize>,
) -> PyResult<Env> {
    Env::new(
        map,
        EnvConfig {
            observation: form,
            pedestrian_slots,
            vehicle_slots,
        },
    )
    .map_err(errors::to_py)
}

/// The slot counts given from Python: `pedestrian_slots` in 1..=[`kinematic::MAX_SLOTS`]
/// (`None`: the default 4), `vehicle_slots` in 0..=[`kinematic::MAX_SLOTS`] (`None`: the
/// map's default), each named in a `ValueError`.
pub fn slot_counts(
    pedestrian_slots: Option<&Bound<'_, PyAny>>,
    vehicle_slots: Option<&Bound<'_, PyAny>>,
) -> PyResult<(usize, Option<usize>)> {
    let pedestrians = pedestrian_slots
        .map(|n| convert::size("pedestrian_slots", n, 1..=kinematic::MAX_SLOTS))
        .transpose()?
        .unwrap_or(EnvConfig::default().pedestrian_slots);
    let vehicles = vehicle_slots
        .map(|n| convert::size("vehicle_slots", n, 0..=kinematic::MAX_SLOTS))
        .transpose()?;
    Ok((pedestrians, vehicles))
}

/// Checks an action given from Python (any integer) and returns it as an index.
pub fn action_index(action: i64) -> PyResult<usize> {
    usize::try_from(action).ok().filter(|a| *a < 3).ok_or_else(|| {
        errors::value(format!(
            "action {action} is not one of 0 (maintain), 1 (speed up), 2 (slow down)"
        ))
    })
}

/// The observation as a numpy array: int64 `(d, v, L, p)` or float32 kinematic values.
pub fn observation<'py>(py: Python<'py>, obs: &Observation) -> Bound<'py, PyAny> {
    match obs {
        Observation::Discrete { state, .. } => {
            PyArray1::from_slice(py, &[state.d as i64, state.v as i64, state.l as i64, state.p as i64]).into_any()
        }
        Observation::Kinematic(v) => PyArray1::from_slice(py, v).into_any(),
    }
}

/// The frame of `env`'s current tick as a uint8 `(height, width, 3)` array, at `scale`
/// pixels per metre (checked: 0.5..=50).
pub fn frame_array<'py>(py: Python<'py>, env: &Env, scale: f32) -> PyResult<Bound<'py, PyAny>> {
    if !(0.5..=50.0).contains(&scale) {
        return Err(errors::value(format!(
            "scale {scale}: expected 0.5..=50 pixels per metre"
        )));
    }
    let (rgb, h, w) = render::frame(env.map(), env.snapshot(), scale);
    Ok(PyArray1::from_vec(py, rgb).reshape([h, w, 3])?.into_any())
}

/// Light phase as a small integer: 0 green, 1 amber, 2 red.
pub fn light_code(light: unforeseen_sim::LightPhase) -> i64 {
    match light {
        unforeseen_sim::LightPhase::Green => 0,
        unforeseen_sim::LightPhase::Amber => 1,
        unforeseen_sim::LightPhase::Red => 2,
    }
}

/// The light's name as an interned Python string.
fn light_str(py: Python<'_>, light: unforeseen_sim::LightPhase) -> &Bound<'_, PyString> {
    match light {
        unforeseen_sim::LightPhase::Green => intern!(py, "green"),
        unforeseen_sim::LightPhase::Amber => intern!(py, "amber"),
        unforeseen_sim::LightPhase::Red => intern!(py, "red"),
    }
}

/// The info dict's keys in order, and the reward terms' keys.
const INFO_KEYS: [&str; 11] = [
    "step",
    "collision",
    "goal",
    "timeout",
    "red_light",
    "state",
    "observed",
    "light",
    "light_code",
    "light_time_left",
    "reward_terms",
];
const TERM_KEYS: [&str; 5] = ["progress", "time", "goal", "crash", "red_light"];

/// A dict with `keys` (values `None`), made once: copying it and replacing the values
/// skips the resizes of filling a new dict key by key (a step's info is built every tick).
fn template<'py>(
    py: Python<'py>,
    cell: &'static PyOnceLock<Py<PyDict>>,
    keys: &[&str],
) -> PyResult<Bound<'py, PyDict>> {
    let t = cell.get_or_try_init(py, || {
        let d = PyDict::new(py);
        for k in keys {
            d.set_item(PyString::intern(py, k), py.None())?;
        }
        PyResult::Ok(d.unbind())
    })?;
    t.bind(py).copy()
}

/// Every joint state of `env` as a `(d, v, L, p)` tuple, by joint index (made once per
/// env, so that a step's info shares them instead of building two tuples a tick).
fn state_tuples(py: Python<'_>, env: &Env) -> PyResult<Vec<Py<PyTuple>>> {
    let disc = env.discretizer();
    (0..disc.n_states())
        .map(|i| {
            let s = disc.decode(i);
            Ok((s.d as i64, s.v as i64, s.l as i64, s.p as i64)
                .into_pyobject(py)?
                .unbind())
        })
        .collect()
}

/// The info dict (documented on `UnforeseenEnv`); `states` from [`state_tuples`].
fn info_dict<'py>(py: Python<'py>, env: &Env, states: &[Py<PyTuple>], info: &Info) -> PyResult<Bound<'py, PyDict>> {
    static INFO: PyOnceLock<Py<PyDict>> = PyOnceLock::new();
    static TERMS: PyOnceLock<Py<PyDict>> = PyOnceLock::new();
    let state = |s| states[env.discretizer().encode(s)].bind(py);
    let d = template(py, &INFO, &INFO_KEYS)?;
    d.set_item(intern!(py, "step"), info.step)?;
    d.set_item(intern!(py, "collision"), info.events.collision)?;
    d.set_item(intern!(py, "goal"), info.events.goal)?;
    d.set_item(intern!(py, "timeout"), info.events.timeout)?;
    d.set_item(intern!(py, "red_light"), info.events.red_light)?;
    d.set_item(intern!(py, "state"), state(info.state))?;
    d.set_item(intern!(py, "observed"), state(info.observed))?;
    d.set_item(intern!(py, "light"), light_str(py, info.light))?;
    d.set_item(intern!(py, "light_code"), light_code(info.light))?;
    d.set_item(intern!(py, "light_time_left"), info.light_time_left)?;
    let terms = template(py, &TERMS, &TERM_KEYS)?;
    terms.set_item(intern!(py, "progress"), info.reward.progress)?;
    terms.set_item(intern!(py, "time"), info.reward.time)?;
    terms.set_item(intern!(py, "goal"), info.reward.goal)?;
    terms.set_item(intern!(py, "crash"), info.reward.crash)?;
    terms.set_item(intern!(py, "red_light"), info.reward.red_light)?;
    d.set_item(intern!(py, "reward_terms"), terms)?;
    Ok(d)
}

/// One env of a map (`unforeseen._unforeseen.Env`; the Gymnasium class wraps it).
#[pyclass(name = "Env", module = "unforeseen._unforeseen")]
pub struct PyEnv {
    env: Env,
    states: Vec<Py<PyTuple>>,
    key: u64,
    episode: u64,
}

impl PyEnv {
    /// Starts an episode with world seed `seed`: `(observation, info)`.
    fn reset_with<'py>(&mut self, py: Python<'py>, seed: u64) -> PyResult<Bound<'py, PyTuple>> {
        let (obs, info) = self.env.reset(seed);
        (observation(py, &obs), info_dict(py, &self.env, &self.states, &info)?).into_pyobject(py)
    }
}

#[pymethods]
impl PyEnv {
    /// An env of `map` (file or embedded name) with map `overrides` (dict);
    /// `vehicle_slots` `None` is the map's default.
    #[new]
    #[pyo3(signature = (map, observation = "discrete", pedestrian_slots = None, overrides = None, vehicle_slots = None))]
    fn new(
        py: Python<'_>,
        map: &Bound<'_, PyAny>,
        observation: &str,
        pedestrian_slots: Option<&Bound<'_, PyAny>>,
        overrides: Option<&Bound<'_, PyDict>>,
        vehicle_slots: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let map = convert::path("map", map)?;
        let (pedestrian_slots, vehicle_slots) = slot_counts(pedestrian_slots, vehicle_slots)?;
        let form = observation_form(observation)?;
        let map = crate::maps::load(&map.to_string_lossy(), overrides)?;
        let env = new_env(&map, form, pedestrian_slots, vehicle_slots)?;
        Ok(PyEnv {
            states: state_tuples(py, &env)?,
            env,
            key: 0,
            episode: 0,
        })
    }

    /// The map's name.
    #[getter]
    fn map_name(&self) -> String {
        self.env.map().name.clone()
    }

    /// The map as JSON (every field, in SI units).
    #[getter]
    fn map_json(&self) -> PyResult<String> {
        serde_json::to_string(self.env.map()).map_err(errors::to_py)
    }

    /// "discrete" or "kinematic".
    #[getter]
    fn observation(&self) -> &'static str {
        match self.env.config().observation {
            ObservationForm::Discrete => "discrete",
            ObservationForm::Kinematic => "kinematic",
        }
    }

    /// Sizes of the discrete factors `[n_d, n_v, n_L, n_p]`.
    #[getter]
    fn factor_sizes(&self) -> Vec<usize> {
        self.env.discretizer().factor_sizes().to_vec()
    }

    /// Length of the kinematic vector.
    #[getter]
    fn kinematic_len(&self) -> usize {
        kinematic::len(self.env.slots())
    }

    /// Pedestrian slots of the kinematic vector.
    #[getter]
    fn pedestrian_slots(&self) -> usize {
        self.env.slots().pedestrians
    }

    /// Vehicle slots of the kinematic vector (the configured count, or the map's default).
    #[getter]
    fn vehicle_slots(&self) -> usize {
        self.env.slots().vehicles
    }

    /// `(low, high)` of the kinematic vector (float32 arrays; [`kinematic::bounds`]).
    fn kinematic_bounds<'py>(&self, py: Python<'py>) -> (Bound<'py, PyArray1<f32>>, Bound<'py, PyArray1<f32>>) {
        let (lo, hi) = kinematic::bounds(self.env.map(), self.env.slots());
        (PyArray1::from_vec(py, lo), PyArray1::from_vec(py, hi))
    }

    /// Seconds per decision tick.
    #[getter]
    fn decision_dt(&self) -> f64 {
        self.env.map().episode.decision_dt
    }

    /// Decision ticks before a time-out.
    #[getter]
    fn max_steps(&self) -> u32 {
        self.env.map().episode.max_steps
    }

    /// Starts an episode with world seed `seed` exactly (named `world_seed` in errors,
    /// as `reset(options={"world_seed": ...})` gives it): `(observation, info)`.
    fn reset<'py>(&mut self, py: Python<'py>, seed: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyTuple>> {
        let seed = convert::seed("world_seed", seed)?;
        self.reset_with(py, seed)
    }

    /// Keys the episode stream (see the module docs); the next `reset_next` is episode 0.
    fn set_stream(&mut self, key: &Bound<'_, PyAny>) -> PyResult<()> {
        let key = convert::seed("key", key)?;
        self.key = key;
        self.episode = 0;
        Ok(())
    }

    /// Starts the stream's next episode: `(observation, info)`.
    fn reset_next<'py>(&mut self, py: Python<'py>) -> PyResult<Bound<'py, PyTuple>> {
        let seed = stream_seed(self.key, self.episode);
        self.episode += 1;
        self.reset_with(py, seed)
    }

    /// The world seed the last `reset_next` used, if any.
    #[getter]
    fn stream_position(&self) -> (u64, u64) {
        (self.key, self.episode)
    }

    /// One decision tick: `(observation, reward, terminated, truncated, info)`.
    fn step<'py>(&mut self, py: Python<'py>, action: i64) -> PyResult<Bound<'py, PyTuple>> {
        let step = self.env.step(action_index(action)?).map_err(errors::to_py)?;
        (
            observation(py, &step.observation),
            step.reward,
            step.terminated,
            step.truncated,
            info_dict(py, &self.env, &self.states, &step.info)?,
        )
            .into_pyobject(py)
    }

    /// Whether the episode ended (or none started).
    #[getter]
    fn done(&self) -> bool {
        self.env.is_done()
    }

    /// The kinematic vector now, whatever the observation form.
    fn kinematic<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f32>>> {
        self.started()?;
        let mut v = vec![0.0; self.kinematic_len()];
        self.env.kinematic_into(&mut v);
        Ok(PyArray1::from_vec(py, v))
    }

    /// A top-down frame, uint8 `(height, width, 3)`, at `scale` pixels per metre.
    #[pyo3(signature = (scale = render::DEFAULT_SCALE))]
    fn render_rgb<'py>(&self, py: Python<'py>, scale: f32) -> PyResult<Bound<'py, PyAny>> {
        self.started()?;
        frame_array(py, &self.env, scale)
    }

    /// The frame as one line of text.
    fn render_ansi(&self) -> PyResult<String> {
        self.started()?;
        Ok(render::ansi(self.env.map(), self.env.snapshot()))
    }
}

impl PyEnv {
    fn started(&self) -> PyResult<()> {
        if self.env.info().is_none() {
            return Err(pyo3::exceptions::PyRuntimeError::new_err(
                "no episode yet: call reset() before render()",
            ));
        }
        Ok(())
    }
}

/// Ticks [`rust_loop`] runs between two looks at Ctrl-C (well under a millisecond).
const TICKS_PER_LOOK: u64 = 1024;

/// Steps `steps` decision ticks of `map` in Rust alone, with the actions of `actions`
/// in turn, starting a new episode (world seeds `stream_seed(seed, k)`) whenever one ends;
/// the GIL is released and Ctrl-C raises `KeyboardInterrupt` within about 50 ms
/// ([`crate::interrupt`]); `overrides` as for `Env`. Returns `(ticks, seconds,
/// episodes)`: the Rust loop's own speed, for the benches.
#[pyfunction]
#[pyo3(signature = (map, actions, steps, seed = None, observation = "discrete", overrides = None))]
pub fn rust_loop(
    py: Python<'_>,
    map: &Bound<'_, PyAny>,
    actions: Vec<i64>,
    steps: &Bound<'_, PyAny>,
    seed: Option<&Bound<'_, PyAny>>,
    observation: &str,
    overrides: Option<&Bound<'_, PyDict>>,
) -> PyResult<(u64, f64, u64)> {
    let map = convert::path("map", map)?;
    let steps = convert::whole("steps", steps, convert::SEEDS)?;
    let seed = seed.map(|s| convert::seed("seed", s)).transpose()?.unwrap_or(0);
    let form = observation_form(observation)?;
    let map = crate::maps::load(&map.to_string_lossy(), overrides)?;
    let mut env = new_env(&map, form, 4, None)?;
    let actions = actions.into_iter().map(action_index).collect::<PyResult<Vec<_>>>()?;
    if actions.is_empty() {
        return Err(errors::value("actions: give at least one action"));
    }
    crate::interrupt::interruptible(py, |progress| {
        let started = std::time::Instant::now();
        let mut episodes = 0;
        env.reset(stream_seed(seed, 0));
        for t in 0..steps {
            if t % TICKS_PER_LOOK == 0 && progress.cancelled() {
                return Err(unforeseen_harness::error::Error::Interrupted);
            }
            let step = env.step(actions[t as usize % actions.len()])?;
            std::hint::black_box(&step);
            if step.terminated || step.truncated {
                episodes += 1;
                env.reset(stream_seed(seed, episodes));
            }
        }
        Ok((steps, started.elapsed().as_secs_f64(), episodes))
    })
}

/// Registers the env class and functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyEnv>()?;
    m.add_function(wrap_pyfunction!(py_stream_seed, m)?)?;
    m.add_function(wrap_pyfunction!(rust_loop, m)?)?;
    Ok(())
}
