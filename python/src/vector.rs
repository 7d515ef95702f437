//! Many envs stepped in Rust: one call steps them all, in parallel (rayon) with the GIL
//! released, writing into buffers allocated once; numpy arrays are made from the buffers
//! (one copy each), never by a loop in Python.
//!
//! Autoreset follows one of Gymnasium's modes. NEXT_STEP (the default): the step after
//! the one that ended an env's episode resets that env (its action is ignored) and
//! returns the reset observation with reward 0 and neither flag set. SAME_STEP (what
//! Stable-Baselines3 expects): the step that ends an episode resets the env at once and
//! returns the reset observation, the final observation and info aside. Env `i` keys its episode stream like a single env
//! ([`crate::env`]): with the keys a single env seeded `s + i` draws, env `i` runs
//! exactly that env's episodes, whatever the number of threads.

use numpy::{PyArray1, PyArrayMethods, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use rayon::prelude::*;
use unforeseen_env::{Env, Info, Observation, ObservationForm, kinematic};

use crate::convert;
use crate::env::{action_index, frame_array, light_code, new_env, observation, observation_form, stream_seed};
use crate::errors;

/// Most envs of one vector env.
const MAX_ENVS: usize = 1 << 16;

/// Most threads of one vector env's own pool.
const MAX_THREADS: usize = 1024;

/// One env of the vector and its episode stream.
struct Slot {
    env: Env,
    key: u64,
    episode: u64,
    /// Its episode ended at the last step: the next step resets it.
    ended: bool,
}

impl Slot {
    /// No episode was ever started.
    fn info_missing(&self) -> bool {
        self.env.info().is_none()
    }

    /// Starts the stream's next episode, writing its observation.
    fn reset_next(&mut self, obs: &mut [f32], ints: &mut [i64]) -> Info {
        let seed = stream_seed(self.key, self.episode);
        self.episode += 1;
        self.ended = false;
        let (o, info) = self.env.reset(seed);
        write_obs(&o, obs, ints);
        info
    }
}

fn write_obs(o: &Observation, obs: &mut [f32], ints: &mut [i64]) {
    match o {
        Observation::Discrete { state, .. } => {
            ints.copy_from_slice(&[state.d as i64, state.v as i64, state.l as i64, state.p as i64])
        }
        Observation::Kinematic(v) => obs.copy_from_slice(v),
    }
}

/// What one env's tick wrote besides its observation.
#[derive(Clone)]
struct Out {
    reward: f64,
    terminated: bool,
    truncated: bool,
    /// The tick's info (under SAME_STEP, for an env that ended: its final info).
    info: Option<Info>,
    /// SAME_STEP, an env that ended this tick: its final observation and the reset's info.
    reset: Option<(Observation, Info)>,
}

/// `num_envs` envs of one map (`unforeseen._unforeseen.VectorEnv`).
#[pyclass(name = "VectorEnv", module = "unforeseen._unforeseen")]
pub struct PyVectorEnv {
    slots: Vec<Slot>,
    form: ObservationForm,
    obs_len: usize,
    /// Kinematic observations, `num_envs * obs_len`.
    obs: Vec<f32>,
    /// Discrete observations, `num_envs * 4`.
    ints: Vec<i64>,
    outs: Vec<Out>,
    actions: Vec<usize>,
    pool: Option<rayon::ThreadPool>,
    /// Autoreset in the step that ends an episode (SAME_STEP) instead of the next.
    same_step: bool,
}

#[pymethods]
impl PyVectorEnv {
    /// `num_envs` envs of `map` with map `overrides`; `num_threads` threads (default:
    /// rayon's global pool, one per core); `autoreset` "next_step" or "same_step".
    #[new]
    #[pyo3(signature = (map, num_envs, observation = "discrete", pedestrian_slots = None, overrides = None, num_threads = None, autoreset = "next_step", vehicle_slots = None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        map: &Bound<'_, PyAny>,
        num_envs: &Bound<'_, PyAny>,
        observation: &str,
        pedestrian_slots: Option<&Bound<'_, PyAny>>,
        overrides: Option<&Bound<'_, PyDict>>,
        num_threads: Option<&Bound<'_, PyAny>>,
        autoreset: &str,
        vehicle_slots: Option<&Bound<'_, PyAny>>,
    ) -> PyResult<Self> {
        let map = convert::path("map", map)?;
        let num_envs = convert::size("num_envs", num_envs, 1..=MAX_ENVS)?;
        let (pedestrian_slots, vehicle_slots) = crate::env::slot_counts(pedestrian_slots, vehicle_slots)?;
        let num_threads = num_threads
            .map(|n| convert::size("num_threads", n, 1..=MAX_THREADS))
            .transpose()?;
        let same_step = match autoreset {
            "next_step" => false,
            "same_step" => true,
            _ => {
                return Err(errors::value(format!(
                    "autoreset '{autoreset}': expected \"next_step\" or \"same_step\""
                )));
            }
        };
        let form = observation_form(observation)?;
        let map = crate::maps::load(&map.to_string_lossy(), overrides)?;
        let pool = match num_threads {
            None => None,
            Some(n) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?,
            ),
        };
        let slots = (0..num_envs)
            .map(|_| {
                Ok(Slot {
                    env: new_env(&map, form, pedestrian_slots, vehicle_slots)?,
                    key: 0,
                    episode: 0,
                    ended: true,
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        let obs_len = match form {
            ObservationForm::Discrete => 4,
            ObservationForm::Kinematic => kinematic::len(slots[0].env.slots()),
        };
        let out = Out {
            reward: 0.0,
            terminated: false,
            truncated: false,
            info: None,
            reset: None,
        };
        Ok(PyVectorEnv {
            slots,
            form,
            obs_len,
            obs: vec![
                0.0;
                if form == ObservationForm::Kinematic {
                    num_envs * obs_len
                } else {
                    0
                }
            ],
            ints: vec![
                0;
                if form == ObservationForm::Discrete {
                    num_envs * 4
                } else {
                    0
                }
            ],
            outs: vec![out; num_envs],
            actions: vec![0; num_envs],
            pool,
            same_step,
        })
    }

    /// Number of envs.
    #[getter]
    fn num_envs(&self) -> usize {
        self.slots.len()
    }

    /// Values per observation.
    #[getter]
    fn obs_len(&self) -> usize {
        self.obs_len
    }

    /// Resets every env: env `i` keys its stream with `keys[i]` and starts its episode 0.
    /// Returns `(observations, info)`.
    fn reset<'py>(&mut self, py: Python<'py>, keys: Vec<u64>) -> PyResult<Bound<'py, PyTuple>> {
        if keys.len() != self.slots.len() {
            return Err(errors::value(format!(
                "{} keys for {} envs",
                keys.len(),
                self.slots.len()
            )));
        }
        for (slot, key) in self.slots.iter_mut().zip(keys) {
            slot.key = key;
            slot.episode = 0;
            slot.ended = true;
        }
        self.run(py, true);
        let obs = self.observations(py)?;
        (obs, self.info(py, |o| o.info)?).into_pyobject(py)
    }

    /// Steps every env with `actions[i]` (int64, one per env): `(observations, rewards,
    /// terminated, truncated, info)`. NEXT_STEP: an env whose episode ended at the
    /// previous step is reset instead. SAME_STEP: an env whose episode ends now is reset
    /// now; `info` is then the reset's, and holds `final_obs` (a list: the final
    /// observation of each env that ended, else None) and `final_info` (the step's info
    /// of every env, as arrays).
    fn step<'py>(&mut self, py: Python<'py>, actions: PyReadonlyArray1<'py, i64>) -> PyResult<Bound<'py, PyTuple>> {
        let a = actions.as_slice()?;
        if a.len() != self.slots.len() {
            return Err(errors::value(format!(
                "{} actions for {} envs",
                a.len(),
                self.slots.len()
            )));
        }
        for (dst, &src) in self.actions.iter_mut().zip(a) {
            *dst = action_index(src)?;
        }
        if self.slots.iter().all(|s| s.ended && s.info_missing()) {
            return Err(pyo3::exceptions::PyRuntimeError::new_err(
                "step called before reset: call reset() first",
            ));
        }
        self.run(py, false);
        let rewards: Vec<f64> = self.outs.iter().map(|o| o.reward).collect();
        let terminated: Vec<bool> = self.outs.iter().map(|o| o.terminated).collect();
        let truncated: Vec<bool> = self.outs.iter().map(|o| o.truncated).collect();
        let info = self.info(py, |o| o.reset.as_ref().map_or(o.info, |(_, i)| Some(*i)))?;
        if self.same_step {
            let finals = self
                .outs
                .iter()
                .map(|o| o.reset.as_ref().map(|(obs, _)| observation(py, obs)))
                .collect::<Vec<_>>();
            info.set_item("final_obs", finals)?;
            info.set_item("final_info", self.info(py, |o| o.info)?)?;
        }
        (
            self.observations(py)?,
            PyArray1::from_vec(py, rewards),
            PyArray1::from_vec(py, terminated),
            PyArray1::from_vec(py, truncated),
            info,
        )
            .into_pyobject(py)
    }

    /// The frame of every env's current tick (a list of uint8 `(height, width, 3)`
    /// arrays) at `scale` pixels per metre.
    #[pyo3(signature = (scale = crate::render::DEFAULT_SCALE))]
    fn render_rgb<'py>(&self, py: Python<'py>, scale: f32) -> PyResult<Vec<Bound<'py, PyAny>>> {
        if self.slots.iter().any(Slot::info_missing) {
            return Err(pyo3::exceptions::PyRuntimeError::new_err(
                "no episode yet: call reset() before render()",
            ));
        }
        self.slots.iter().map(|s| frame_array(py, &s.env, scale)).collect()
    }
}

impl PyVectorEnv {
    /// Steps (or, with `reset_all`, resets) every env, in parallel, GIL released.
    fn run(&mut self, py: Python<'_>, reset_all: bool) {
        let (obs_len, form) = (self.obs_len, self.form);
        let slots = &mut self.slots;
        let outs = &mut self.outs;
        let actions = &self.actions;
        let kin = form == ObservationForm::Kinematic;
        let (obs, ints) = (&mut self.obs, &mut self.ints);
        let pool = self.pool.as_ref();
        let same_step = self.same_step;
        py.detach(move || {
            let mut work = move || {
                let n = slots.len();
                let obs_chunks: Vec<&mut [f32]> = if kin {
                    obs.chunks_exact_mut(obs_len).collect()
                } else {
                    (0..n).map(|_| <&mut [f32]>::default()).collect()
                };
                let int_chunks: Vec<&mut [i64]> = if kin {
                    (0..n).map(|_| <&mut [i64]>::default()).collect()
                } else {
                    ints.chunks_exact_mut(4).collect()
                };
                slots
                    .par_iter_mut()
                    .zip(outs.par_iter_mut())
                    .zip(obs_chunks.into_par_iter().zip(int_chunks.into_par_iter()))
                    .zip(actions.par_iter())
                    .for_each(|(((slot, out), (o, i)), &action)| {
                        if reset_all || slot.ended {
                            let info = slot.reset_next(o, i);
                            *out = Out {
                                reward: 0.0,
                                terminated: false,
                                truncated: false,
                                info: Some(info),
                                reset: None,
                            };
                            return;
                        }
                        let step = slot.env.step(action).expect("a valid action on a running episode");
                        slot.ended = step.terminated || step.truncated;
                        let reset = if same_step && slot.ended {
                            let info = slot.reset_next(o, i);
                            Some((step.observation, info))
                        } else {
                            write_obs(&step.observation, o, i);
                            None
                        };
                        *out = Out {
                            reward: step.reward,
                            terminated: step.terminated,
                            truncated: step.truncated,
                            info: Some(step.info),
                            reset,
                        };
                    });
            };
            match pool {
                Some(p) => p.install(work),
                None => work(),
            }
        });
    }

    fn observations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let n = self.slots.len();
        Ok(match self.form {
            ObservationForm::Discrete => PyArray1::from_slice(py, &self.ints).reshape([n, 4])?.into_any(),
            ObservationForm::Kinematic => PyArray1::from_slice(py, &self.obs)
                .reshape([n, self.obs_len])?
                .into_any(),
        })
    }

    /// The info of every env as arrays (one entry per env; documented on the Python
    /// class), each env's info picked from its tick's output by `pick`.
    fn info<'py>(&self, py: Python<'py>, pick: impl Fn(&Out) -> Option<Info>) -> PyResult<Bound<'py, PyDict>> {
        let n = self.slots.len();
        let infos: Vec<Info> = self
            .outs
            .iter()
            .map(|o| pick(o).expect("run fills every info"))
            .collect();
        let d = PyDict::new(py);
        let col = |f: &dyn Fn(&Info) -> i64| PyArray1::from_vec(py, infos.iter().map(f).collect::<Vec<_>>());
        let flag = |f: &dyn Fn(&Info) -> bool| PyArray1::from_vec(py, infos.iter().map(f).collect::<Vec<_>>());
        let real = |f: &dyn Fn(&Info) -> f64| PyArray1::from_vec(py, infos.iter().map(f).collect::<Vec<_>>());
        let states = |f: &dyn Fn(&Info) -> unforeseen_discretizer::State| -> PyResult<Bound<'py, PyAny>> {
            let v: Vec<i64> = infos
                .iter()
                .flat_map(|i| {
                    let s = f(i);
                    [s.d as i64, s.v as i64, s.l as i64, s.p as i64]
                })
                .collect();
            Ok(PyArray1::from_vec(py, v).reshape([n, 4])?.into_any())
        };
        d.set_item("step", col(&|i| i64::from(i.step)))?;
        d.set_item("collision", flag(&|i| i.events.collision))?;
        d.set_item("goal", flag(&|i| i.events.goal))?;
        d.set_item("timeout", flag(&|i| i.events.timeout))?;
        d.set_item("red_light", flag(&|i| i.events.red_light))?;
        d.set_item("state", states(&|i| i.state)?)?;
        d.set_item("observed", states(&|i| i.observed)?)?;
        d.set_item("light_code", col(&|i| light_code(i.light)))?;
        d.set_item("light_time_left", real(&|i| i.light_time_left))?;
        let terms = PyDict::new(py);
        terms.set_item("progress", real(&|i| i.reward.progress))?;
        terms.set_item("time", real(&|i| i.reward.time))?;
        terms.set_item("goal", real(&|i| i.reward.goal))?;
        terms.set_item("crash", real(&|i| i.reward.crash))?;
        terms.set_item("red_light", real(&|i| i.reward.red_light))?;
        d.set_item("reward_terms", terms)?;
        Ok(d)
    }
}

/// Registers the class.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyVectorEnv>()
}
