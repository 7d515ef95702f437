//! # unforeseen-env: one episode of the intersection, one decision tick at a time
//!
//! [`Env`] is the way to drive an episode (docs/ARCHITECTURE.md §1): the episode runner,
//! training, the scripted references, the benches and the Python binding are all loops
//! over it, so there is one place where an episode steps.
//!
//! ```text
//! reset(seed) -> (Observation, Info)
//! step(action) -> Step { observation, reward, terminated, truncated, info }
//! ```
//!
//! * `terminated`: the episode reached a terminal state of the task (the car's front
//!   reached the destination, or the car hit a pedestrian).
//! * `truncated`: it ran out of decision ticks (`episode.max_steps`) without either; the
//!   state is not terminal, so a learner bootstraps through it (Gymnasium's convention).
//!
//! Observations come in the form the caller chooses ([`ObservationForm`]): the paper's
//! discrete factors `(d, v, L, p)` as the agent sees them, with the map's observation
//! noise (§VI; docs/ARCHITECTURE.md §3), or a continuous [kinematic vector](kinematic).
//! [`Info`] always carries the true discrete state, the events and the reward's terms.
//!
//! ```
//! use unforeseen_env::{Action, Env, EnvConfig};
//! let map = unforeseen_sim::embedded::load("jaywalk").unwrap();
//! let mut env = Env::new(&map, EnvConfig::default()).unwrap();
//! let (_obs, info) = env.reset(7);
//! assert_eq!(info.step, 0);
//! let mut total = 0.0;
//! loop {
//!     // A careful driver: brake while a pedestrian is on the crosswalk.
//!     let action = if env.state().p == 1 { Action::SlowDown } else { Action::SpeedUp };
//!     let step = env.step(action.index()).unwrap();
//!     total += step.reward;
//!     if step.terminated || step.truncated {
//!         assert!(step.info.events.goal && !step.info.events.collision);
//!         break;
//!     }
//! }
//! assert!(total > 0.0);
//! ```
//!
//! Determinism: the same map, seed and actions give bit-identical observations, rewards
//! and infos. The world's randomness (light offset, spawns) is seeded by `seed`, the
//! observation noise by a stream derived from the same seed ([`NOISE_STREAM`]).

pub mod kinematic;
pub mod reward;
pub mod seeds;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use unforeseen_discretizer::{Discretizer, DiscretizerError, State};
use unforeseen_sim::{LightPhase, Map, Margins, Snapshot, World};

pub use reward::RewardTerms;
pub use unforeseen_sim::Action;

/// XORed into the episode seed to seed the observation noise's generator, so the noise
/// is a stream of its own and does not disturb the world's draws.
pub const NOISE_STREAM: u64 = 0x6f62_7365_7276_6521;

/// Which form [`Env::reset`] and [`Env::step`] return observations in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ObservationForm {
    /// The discrete factors `(d, v, L, p)` as the agent observes them, and their joint index.
    #[default]
    Discrete,
    /// The [kinematic vector](kinematic), [`kinematic::len`] values.
    Kinematic,
}

/// How an [`Env`] observes.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EnvConfig {
    /// The observation's form. Default discrete.
    pub observation: ObservationForm,
    /// Pedestrian slots of the kinematic vector (1..=[`kinematic::MAX_SLOTS`]). Default 4.
    pub pedestrian_slots: usize,
    /// Vehicle slots of the kinematic vector (0..=[`kinematic::MAX_SLOTS`]). Default
    /// `None`: [`kinematic::default_vehicle_slots`] (4 on a map with traffic rules, 0 on
    /// one without). Not serialised when `None`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub vehicle_slots: Option<usize>,
}

impl Default for EnvConfig {
    fn default() -> Self {
        Self {
            observation: ObservationForm::Discrete,
            pedestrian_slots: 4,
            vehicle_slots: None,
        }
    }
}

/// Why an [`Env`] could not be built or stepped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum EnvError {
    /// The map's bins cannot make a discretizer.
    #[error("map '{map}': {source}")]
    Bins {
        /// The map's name.
        map: String,
        /// What is wrong with its bins.
        source: DiscretizerError,
    },
    /// The map could not be loaded (its file, line and fix, as the loader says).
    #[error("{0}")]
    Map(String),
    /// A configuration value out of range.
    #[error("{field}: {problem}")]
    Config {
        /// The field, e.g. `pedestrian_slots`.
        field: &'static str,
        /// What is wrong and the allowed range.
        problem: String,
    },
    /// An action index that is not one of the three actions.
    #[error("action {action} is not one of 0 (maintain), 1 (speed up), 2 (slow down)")]
    BadAction {
        /// The index given.
        action: usize,
    },
    /// `step` before the first `reset`.
    #[error("step called before reset: call reset(seed) to start an episode")]
    NotReset,
    /// `step` after the episode ended.
    #[error("step called after the episode ended (terminated or truncated): call reset(seed) to start the next")]
    EpisodeOver,
}

/// What happened in a decision tick; at most one of `collision` and `goal` holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
pub struct Events {
    /// The car hit a pedestrian (terminates the episode).
    pub collision: bool,
    /// The car's front reached the destination without a collision (terminates it).
    pub goal: bool,
    /// The tick limit was reached without goal or collision (truncates it).
    pub timeout: bool,
    /// The car's front entered the crosswalk (crossed its near edge) while the light was
    /// red (not amber), a traffic-rule violation; it does not end the episode. Reported
    /// on every map; the reward pays `reward.red_light` for it ([`RewardTerms::red_light`]).
    #[serde(default)]
    pub red_light: bool,
}

/// What an observer may know besides the observation: the true state, the events and the
/// reward's terms. After `reset` the events and terms are zero.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Info {
    /// Decision ticks done.
    pub step: u32,
    /// The true discrete state.
    pub state: State,
    /// The discrete state as observed (differs from `state` only with observation noise).
    pub observed: State,
    /// The light shown now (amber counts as red in the discrete state).
    pub light: LightPhase,
    /// Seconds until the light changes.
    pub light_time_left: f64,
    /// What the last tick did.
    pub events: Events,
    /// The last tick's reward, term by term (they sum to [`Step::reward`]).
    pub reward: RewardTerms,
}

/// An observation in the form of the env's [`EnvConfig::observation`].
#[derive(Debug, Clone, PartialEq)]
pub enum Observation {
    /// The observed factors and their joint index `((d·n_v + v)·2 + L)·2 + p`.
    Discrete {
        /// The factors.
        state: State,
        /// Their joint index.
        index: usize,
    },
    /// The kinematic vector ([`kinematic`] documents the layout and units).
    Kinematic(Vec<f32>),
}

impl Observation {
    /// The joint index of a discrete observation.
    pub fn index(&self) -> Option<usize> {
        match self {
            Observation::Discrete { index, .. } => Some(*index),
            Observation::Kinematic(_) => None,
        }
    }

    /// The values of a kinematic observation.
    pub fn kinematic(&self) -> Option<&[f32]> {
        match self {
            Observation::Discrete { .. } => None,
            Observation::Kinematic(v) => Some(v),
        }
    }
}

/// The result of one [`Env::step`].
#[derive(Debug, Clone, PartialEq)]
pub struct Step {
    /// The observation after the tick.
    pub observation: Observation,
    /// The tick's reward (§VI; [`RewardTerms::total`]).
    pub reward: f64,
    /// The episode reached a terminal state (goal or collision).
    pub terminated: bool,
    /// The episode ran out of ticks without reaching one.
    pub truncated: bool,
    /// The true state, events and reward terms.
    pub info: Info,
}

/// One episode of a map at a time: [`Env::reset`] starts one, [`Env::step`] advances it
/// by one decision tick (`episode.decision_dt` seconds of Rapier sub-steps).
pub struct Env {
    map: Map,
    disc: Discretizer,
    config: EnvConfig,
    slots: kinematic::Slots,
    world: Option<World>,
    noise: ChaCha8Rng,
    snapshot: Option<Snapshot>,
    info: Option<Info>,
    /// Whether each episode's margins are measured ([`Env::measure_margins`]).
    margins: bool,
}

impl std::fmt::Debug for Env {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Env")
            .field("map", &self.map.name)
            .field("config", &self.config)
            .field("info", &self.info)
            .finish_non_exhaustive()
    }
}

impl Env {
    /// An env of `map` (as returned by the map loaders, so already validated) observing
    /// as `config` says. Call [`Env::reset`] before stepping.
    pub fn new(map: &Map, config: EnvConfig) -> Result<Env, EnvError> {
        let disc = Discretizer::new(map).map_err(|source| EnvError::Bins {
            map: map.name.clone(),
            source,
        })?;
        if !(1..=kinematic::MAX_SLOTS).contains(&config.pedestrian_slots) {
            return Err(EnvError::Config {
                field: "pedestrian_slots",
                problem: format!(
                    "must be in 1..={}, got {}",
                    kinematic::MAX_SLOTS,
                    config.pedestrian_slots
                ),
            });
        }
        let vehicles = config
            .vehicle_slots
            .unwrap_or_else(|| kinematic::default_vehicle_slots(map));
        if vehicles > kinematic::MAX_SLOTS {
            return Err(EnvError::Config {
                field: "vehicle_slots",
                problem: format!("must be in 0..={}, got {vehicles}", kinematic::MAX_SLOTS),
            });
        }
        Ok(Env {
            map: map.clone(),
            disc,
            slots: kinematic::Slots {
                pedestrians: config.pedestrian_slots,
                vehicles,
            },
            config,
            world: None,
            noise: ChaCha8Rng::seed_from_u64(0),
            snapshot: None,
            info: None,
            margins: false,
        })
    }

    /// Whether the episodes from the next [`Env::reset`] on measure their margins
    /// ([`unforeseen_sim::margins`]: how close they come to a collision); measuring
    /// changes nothing in an episode.
    pub fn measure_margins(&mut self, on: bool) {
        self.margins = on;
    }

    /// The current episode's smallest margins so far (none unless measured).
    pub fn margins(&self) -> Option<Margins> {
        self.world.as_ref().and_then(World::margins)
    }

    /// The map.
    pub fn map(&self) -> &Map {
        &self.map
    }

    /// The discretizer built from the map's bins (factor sizes, joint index).
    pub fn discretizer(&self) -> &Discretizer {
        &self.disc
    }

    /// The configuration.
    pub fn config(&self) -> &EnvConfig {
        &self.config
    }

    /// The kinematic vector's slots (the configured vehicle slots, or the map's default).
    pub fn slots(&self) -> kinematic::Slots {
        self.slots
    }

    /// Starts an episode: the world's randomness (light offset, spawns) from `seed`, the
    /// observation noise from `seed ^ NOISE_STREAM`.
    pub fn reset(&mut self, seed: u64) -> (Observation, Info) {
        let mut world = World::from_map(&self.map, seed);
        if self.margins {
            world.measure_margins();
        }
        self.noise = ChaCha8Rng::seed_from_u64(seed ^ NOISE_STREAM);
        self.world = Some(world);
        let info = self.look(Events::default(), RewardTerms::default());
        (self.observation(), info)
    }

    /// Advances one decision tick with `action` (0 maintain, 1 speed up, 2 slow down)
    /// held throughout. Errors on a bad action, before the first reset and after the
    /// episode ended; the env is unchanged then.
    pub fn step(&mut self, action: usize) -> Result<Step, EnvError> {
        let action = Action::from_index(action).ok_or(EnvError::BadAction { action })?;
        let world = self.world.as_mut().ok_or(EnvError::NotReset)?;
        if world.is_done() {
            return Err(EnvError::EpisodeOver);
        }
        let outcome = world.step(action);
        let events = Events {
            collision: outcome.collision,
            goal: outcome.goal,
            timeout: outcome.timeout,
            red_light: outcome.red_light,
        };
        let terms = RewardTerms::of(&self.map, &outcome);
        let info = self.look(events, terms);
        Ok(Step {
            observation: self.observation(),
            reward: terms.total(),
            terminated: events.collision || events.goal,
            truncated: events.timeout,
            info,
        })
    }

    /// Whether the current episode has ended (or none was started).
    pub fn is_done(&self) -> bool {
        self.world.as_ref().is_none_or(World::is_done)
    }

    /// The world after the last tick (car, light, pedestrians), for observers and figures.
    ///
    /// # Panics
    /// Before the first [`Env::reset`].
    pub fn snapshot(&self) -> &Snapshot {
        self.snapshot.as_ref().expect("Env::snapshot called before reset")
    }

    /// The true discrete state after the last tick.
    ///
    /// # Panics
    /// Before the first [`Env::reset`].
    pub fn state(&self) -> State {
        self.last().state
    }

    /// The observed discrete state after the last tick.
    ///
    /// # Panics
    /// Before the first [`Env::reset`].
    pub fn observed(&self) -> State {
        self.last().observed
    }

    fn last(&self) -> &Info {
        self.info.as_ref().expect("Env::state called before reset")
    }

    /// The info of the last reset or step, if any.
    pub fn info(&self) -> Option<&Info> {
        self.info.as_ref()
    }

    /// The kinematic vector after the last tick, written into `out`
    /// ([`kinematic::len`]`(`[`Env::slots`]`)` values), whatever the observation form.
    ///
    /// # Panics
    /// If `out` has another length, or before the first reset.
    pub fn kinematic_into(&self, out: &mut [f32]) {
        kinematic::write(&self.map, self.snapshot(), self.slots, out);
    }

    /// Snapshot, true and observed state after a reset or a tick.
    fn look(&mut self, events: Events, reward: RewardTerms) -> Info {
        let world = self.world.as_ref().expect("look after reset");
        let snapshot = world.snapshot();
        let state = self.disc.state(&snapshot);
        let observed = self.disc.observe(state, &mut self.noise);
        let info = Info {
            step: snapshot.step,
            state,
            observed,
            light: snapshot.light,
            light_time_left: snapshot.light_time_left,
            events,
            reward,
        };
        self.snapshot = Some(snapshot);
        self.info = Some(info);
        info
    }

    fn observation(&self) -> Observation {
        match self.config.observation {
            ObservationForm::Discrete => Observation::Discrete {
                state: self.observed(),
                index: self.disc.encode(self.observed()),
            },
            ObservationForm::Kinematic => {
                let mut v = vec![0.0; kinematic::len(self.slots)];
                self.kinematic_into(&mut v);
                Observation::Kinematic(v)
            }
        }
    }
}
