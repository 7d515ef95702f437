//! The episode runner: a [`Controller`] driving an [`Env`] (map -> world -> discretizer
//! -> controller -> action -> world, one decision tick at a time; docs/ARCHITECTURE.md
//! §1), with the metrics of §VI.

use std::time::Instant;
use unforeseen_agent::controller::{Controller, Ending};
use unforeseen_discretizer::State;
use unforeseen_env::Env;
use unforeseen_sim::{Action, Snapshot};

use crate::error::EpisodeError;

/// One decision tick of an episode, as shown by `trace`.
#[derive(Debug, Clone)]
pub struct Tick {
    /// Decision tick index, from 0.
    pub step: u32,
    /// The true discrete state before acting.
    pub state: State,
    /// What the agent observed (differs from `state` only with observation noise).
    pub observed: State,
    /// The action taken.
    pub action: Action,
    /// Whether this tick ran planning (reasoning) rather than the feed-forward policy.
    pub reasoned: bool,
    /// Surprise S_t in nats, for methods that compute it.
    pub surprise: Option<f64>,
    /// Normalized surprise theta_t = 1 - exp(-Omega S_t).
    pub theta: Option<f64>,
    /// The distribution the action was taken from.
    pub policy: Vec<f64>,
    /// The planner's action distribution `psi` (§IV), on ticks that planned.
    pub psi: Option<Vec<f64>>,
    /// Reward paid for this tick.
    pub reward: f64,
    /// This tick's action took the car's front into the crosswalk on red (a violation).
    pub red_light: bool,
    /// The world before acting (for the filmstrip).
    pub snapshot: Snapshot,
}

/// How an episode went.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct EpisodeResult {
    /// Sum of tick rewards.
    pub ret: f64,
    /// Reached the destination without a collision.
    pub success: bool,
    /// Hit a pedestrian.
    pub collision: bool,
    /// Ran out of decision ticks.
    pub timeout: bool,
    /// Red-light violations: ticks in which the car's front entered the crosswalk on red
    /// ([`unforeseen_env::Events::red_light`]; at most one, since the car never reverses).
    #[serde(default)]
    pub red_lights: u32,
    /// Decision ticks taken.
    pub ticks: u32,
    /// Ticks on which the controller reasoned (ran planning).
    pub reasoning_ticks: u32,
    /// Wall-clock nanoseconds spent inside `Controller::act` (all ticks).
    pub decide_ns: u64,
    /// Wall-clock nanoseconds spent inside `Controller::act` on reasoning ticks.
    pub reasoning_ns: u64,
    /// Surprise (nats) on the first tick at which a pedestrian was on the crosswalk
    /// while the light was green, if any and if the method computes surprise.
    pub jaywalk_surprise: Option<f64>,
    /// Smallest clearance between the car's collider and a pedestrian's, m (0 in a
    /// collision; none when no pedestrian appeared; [`unforeseen_sim::margins`]).
    #[serde(default)]
    pub min_clearance: Option<f64>,
    /// Smallest time-to-collision at constant velocities, s (none when the car was never
    /// on a collision course).
    #[serde(default)]
    pub min_ttc: Option<f64>,
    /// Smallest stopping margin on a collision course, m: the distance to the contact
    /// less the stopping distance (negative: the car could no longer have stopped).
    #[serde(default)]
    pub min_stop_margin: Option<f64>,
    /// Smallest clearance between the car's collider and another vehicle's, m (none when
    /// no vehicle appeared).
    #[serde(default)]
    pub min_vehicle_clearance: Option<f64>,
    /// Smallest post-encroachment time car–pedestrian, s (none when no pedestrian's path
    /// met the car's).
    #[serde(default)]
    pub min_pet: Option<f64>,
}

impl EpisodeResult {
    /// Whether braking could have stopped the car short of every collision course it
    /// was on ([`unforeseen_sim::Margins::could_stop`]).
    pub fn could_stop(&self) -> bool {
        self.min_stop_margin.is_none_or(|m| m >= 0.0)
    }
}

/// Seeds of one episode: the world's randomness and the controller's.
#[derive(Debug, Clone, Copy)]
pub struct EpisodeSeeds {
    /// Seeds the world (light offset, spawns) and the observation noise ([`Env::reset`]).
    pub world: u64,
    /// Seeds the controller's own sampling, if any.
    pub controller: u64,
}

/// Runs one episode of `controller` in `env` (a loop over [`Env::reset`] and
/// [`Env::step`]): the controller acts on the discrete observation's joint index (an env
/// that observes kinematically also gives it the vector first,
/// [`Controller::see_features`]). With `record`, every tick is returned, and the terminal
/// frame after them. The episode's margins are measured ([`Env::measure_margins`]).
pub fn run_episode(
    env: &mut Env,
    controller: &mut dyn Controller,
    seeds: EpisodeSeeds,
    record: bool,
) -> Result<(EpisodeResult, Vec<Tick>), EpisodeError> {
    env.measure_margins(true);
    let (mut obs, mut info) = env.reset(seeds.world);
    let mut index = obs.index().unwrap_or_else(|| env.discretizer().encode(info.observed));
    let mut result = EpisodeResult::default();
    let mut ticks = Vec::new();
    controller.begin_episode(seeds.controller);
    loop {
        if let Some(features) = obs.kinematic() {
            controller.see_features(features);
        }
        let started = Instant::now();
        let decision = controller.act(index);
        let ns = started.elapsed().as_nanos() as u64;
        result.decide_ns += ns;
        if decision.reasoned {
            result.reasoning_ticks += 1;
            result.reasoning_ns += ns;
        }
        if result.jaywalk_surprise.is_none() && info.state.p == 1 && info.state.l == 1 {
            result.jaywalk_surprise = decision.surprise;
        }
        let before = record.then(|| env.snapshot().clone());
        let step = env.step(decision.action).map_err(|source| EpisodeError {
            controller: controller.name().to_string(),
            source,
        })?;
        result.ret += step.reward;
        result.ticks += 1;
        result.red_lights += u32::from(step.info.events.red_light);
        let next_index = step
            .observation
            .index()
            .unwrap_or_else(|| env.discretizer().encode(step.info.observed));
        let ending = Ending::from_flags(step.terminated, step.truncated);
        controller.observe(step.reward, next_index, ending);
        if let Some(snapshot) = before {
            ticks.push(Tick {
                step: info.step,
                state: info.state,
                observed: info.observed,
                action: Action::from_index(decision.action).unwrap_or(Action::Maintain),
                reasoned: decision.reasoned,
                surprise: decision.surprise,
                theta: decision.theta,
                policy: decision.policy.to_vec(),
                psi: decision.psi.as_deref().map(<[f64]>::to_vec),
                reward: step.reward,
                red_light: step.info.events.red_light,
                snapshot,
            });
        }
        if ending.is_over() {
            let events = step.info.events;
            result.collision = events.collision;
            result.success = events.goal && !events.collision;
            result.timeout = events.timeout;
            if let Some(m) = env.margins() {
                (result.min_clearance, result.min_ttc, result.min_stop_margin) = (m.clearance, m.ttc, m.stop_margin);
                (result.min_vehicle_clearance, result.min_pet) = (m.vehicle_clearance, m.pet);
            }
            if record {
                // The terminal frame, for the filmstrip.
                ticks.push(Tick {
                    step: step.info.step,
                    state: step.info.state,
                    observed: step.info.observed,
                    action: Action::Maintain,
                    reasoned: false,
                    surprise: None,
                    theta: None,
                    policy: Vec::new(),
                    psi: None,
                    reward: 0.0,
                    red_light: false,
                    snapshot: env.snapshot().clone(),
                });
            }
            break;
        }
        (info, index, obs) = (step.info, next_index, step.observation);
    }
    controller.end_episode();
    Ok((result, ticks))
}
