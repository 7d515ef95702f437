//! The episode runner: map -> world -> discretizer -> controller -> action -> world,
//! one decision tick at a time (docs/ARCHITECTURE.md §1), with the reward and metrics of §VI.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::time::Instant;
use unforeseen_agent::controller::Controller;
use unforeseen_discretizer::{Discretizer, State};
use unforeseen_sim::{Action, Map, Snapshot, World};

use crate::rewards::tick_reward;

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
}

/// Seeds of one episode: the world's randomness and the controller's.
#[derive(Debug, Clone, Copy)]
pub struct EpisodeSeeds {
    /// Seeds the world (light offset, spawns) and the observation noise.
    pub world: u64,
    /// Seeds the controller's own sampling, if any.
    pub controller: u64,
}

/// Runs one episode of `controller` on `map`. With `record`, every tick is returned.
pub fn run_episode(
    map: &Map,
    disc: &Discretizer,
    controller: &mut dyn Controller,
    seeds: EpisodeSeeds,
    record: bool,
) -> (EpisodeResult, Vec<Tick>) {
    let mut world = World::from_map(map, seeds.world);
    let mut noise = ChaCha8Rng::seed_from_u64(seeds.world ^ 0x6f62_7365_7276_6521);
    let mut result = EpisodeResult::default();
    let mut ticks = Vec::new();
    controller.begin_episode(seeds.controller);

    let mut snap = world.snapshot();
    let mut state = disc.state(&snap);
    let mut observed = disc.observe(state, &mut noise);
    loop {
        let started = Instant::now();
        let decision = controller.act(disc.encode(observed));
        let ns = started.elapsed().as_nanos() as u64;
        let action = Action::from_index(decision.action)
            .unwrap_or_else(|| panic!("{} chose action {} of 3", controller.name(), decision.action));
        result.decide_ns += ns;
        if decision.reasoned {
            result.reasoning_ticks += 1;
            result.reasoning_ns += ns;
        }
        if result.jaywalk_surprise.is_none() && state.p == 1 && state.l == 1 {
            result.jaywalk_surprise = decision.surprise;
        }

        let outcome = world.step(action);
        let reward = tick_reward(map, &outcome);
        result.ret += reward;
        result.ticks += 1;
        let next_snap = world.snapshot();
        let next_state = disc.state(&next_snap);
        let next_observed = disc.observe(next_state, &mut noise);
        controller.observe(reward, disc.encode(next_observed), outcome.done());
        if record {
            ticks.push(Tick {
                step: outcome.step.saturating_sub(1),
                state,
                observed,
                action,
                reasoned: decision.reasoned,
                surprise: decision.surprise,
                theta: decision.theta,
                policy: decision.policy.to_vec(),
                psi: decision.psi.as_deref().map(<[f64]>::to_vec),
                reward,
                snapshot: snap,
            });
        }
        if outcome.done() {
            result.collision = outcome.collision;
            result.success = outcome.goal && !outcome.collision;
            result.timeout = outcome.timeout;
            if record {
                // The terminal frame, for the filmstrip.
                ticks.push(Tick {
                    step: outcome.step,
                    state: next_state,
                    observed: next_observed,
                    action: Action::Maintain,
                    reasoned: false,
                    surprise: None,
                    theta: None,
                    policy: Vec::new(),
                    psi: None,
                    reward: 0.0,
                    snapshot: next_snap,
                });
            }
            break;
        }
        (snap, state, observed) = (next_snap, next_state, next_observed);
    }
    controller.end_episode();
    (result, ticks)
}
