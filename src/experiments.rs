//! The experiments of §VI: evaluation of a method on a map, the comparison table
//! (Fig. 8), one traced episode (Figs. 6-7) and test-time learning curves (Fig. 9).

use indicatif::ProgressBar;
use rayon::prelude::*;
use serde::Serialize;
use unforeseen_agent::controller::Controller;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_agent::scaled::ScaledAgent;
use unforeseen_discretizer::{Discretizer, State};
use unforeseen_sim::{Action, Map};

use crate::agent_file::check_compatible;
use crate::methods::Method;
use crate::metrics::Aggregate;
use crate::progress;
use crate::protocol::Protocol;
use crate::runner::{EpisodeResult, EpisodeSeeds, Tick, run_episode};
use crate::seeds::episode_seed;

/// Seeds of evaluation episode `episode` of `method` on `map`: the world seed depends
/// on the map and episode only (every method meets the same pedestrians), the
/// controller seed on the method too.
pub fn eval_seeds(seed: u64, map: &Map, method: Method, episode: u64) -> EpisodeSeeds {
    EpisodeSeeds {
        world: episode_seed(seed, &format!("{}/eval", map.name), episode),
        controller: episode_seed(seed, &format!("{}/eval/{}", map.name, method.name()), episode),
    }
}

/// Runs `episodes` episodes of `controller` on `map` in order (test-time learning
/// carries over from one episode to the next: the continual protocol on a controller
/// the caller built).
pub fn evaluate(
    map: &Map,
    controller: &mut dyn Controller,
    method: Method,
    episodes: u64,
    seed: u64,
    quiet: bool,
) -> anyhow::Result<Vec<EpisodeResult>> {
    let disc = Discretizer::new(&map.bins)?;
    let bar = progress::bar(episodes, &format!("{} {}", method.name(), map.name), quiet);
    let results = (0..episodes)
        .map(|ep| {
            bar.inc(1);
            run_episode(map, &disc, controller, eval_seeds(seed, map, method, ep), false).0
        })
        .collect();
    bar.finish_and_clear();
    Ok(results)
}

/// Runs `episodes` evaluation episodes of `method` on `map` under `protocol`, advancing
/// `bar` by one per episode. Zero-shot: a fresh controller per episode, episodes in
/// parallel (rayon); continual: one controller, episodes in order. A method that does
/// not learn across episodes always runs zero-shot (identical results, in parallel).
/// Seeds derive from (seed, map, method, episode), so results do not depend on the
/// number of threads.
#[allow(clippy::too_many_arguments)]
pub fn evaluate_under(
    protocol: Protocol,
    map: &Map,
    bundle: &AgentBundle,
    params: &ScaledParams,
    method: Method,
    episodes: u64,
    seed: u64,
    bar: &ProgressBar,
) -> anyhow::Result<Vec<EpisodeResult>> {
    let disc = Discretizer::new(&map.bins)?;
    check_compatible(bundle, &map.name, disc.n_states())?;
    let run = |controller: &mut dyn Controller, ep: u64| {
        let result = run_episode(map, &disc, controller, eval_seeds(seed, map, method, ep), false).0;
        bar.inc(1);
        result
    };
    match protocol.effective(method, params) {
        Protocol::ZeroShot => (0..episodes)
            .into_par_iter()
            .map(|ep| Ok(run(method.controller(bundle, params)?.as_mut(), ep)))
            .collect(),
        Protocol::Continual => {
            let mut controller = method.controller(bundle, params)?;
            Ok((0..episodes).map(|ep| run(controller.as_mut(), ep)).collect())
        }
    }
}

/// One method's figures with one trained agent (a per-seed row of `compare.json`).
#[derive(Debug, Clone, Serialize)]
pub struct MethodRow {
    /// Method name.
    pub method: String,
    /// Training seed of the agent (None for an agent file that does not record it).
    pub train_seed: Option<u64>,
    /// Mean return on the training map after training.
    pub train_reward: f64,
    /// Mean return on the test (unforeseen) map.
    pub test_reward: f64,
    /// Success rate on the test map.
    pub success_rate: f64,
    /// Collision rate on the test map.
    pub collision_rate: f64,
    /// Share of test ticks that ran planning.
    pub inference_rate: f64,
    /// Mean wall-clock µs inside the controller per test tick (the only field measured
    /// with a clock, so the only one that varies between identical runs).
    pub reasoning_us_per_tick: f64,
    /// Full aggregate on the training map.
    pub train: Aggregate,
    /// Full aggregate on the test map.
    pub test: Aggregate,
}

/// Fills a row from `method`'s aggregates on the training and the test map.
pub fn method_row(method: Method, train_seed: Option<u64>, train: Aggregate, test: Aggregate) -> MethodRow {
    MethodRow {
        method: method.name().to_string(),
        train_seed,
        train_reward: train.mean_reward,
        test_reward: test.mean_reward,
        success_rate: test.success_rate,
        collision_rate: test.collision_rate,
        inference_rate: test.inference_rate,
        reasoning_us_per_tick: test.us_per_tick,
        train,
        test,
    }
}

/// Runs one recorded episode of `method` (the first evaluation episode of `seed`) and
/// returns its result and ticks.
pub fn trace(
    bundle: &AgentBundle,
    params: &ScaledParams,
    method: Method,
    map: &Map,
    seed: u64,
) -> anyhow::Result<(EpisodeResult, Vec<Tick>)> {
    let disc = Discretizer::new(&map.bins)?;
    check_compatible(bundle, &map.name, disc.n_states())?;
    let mut controller = method.controller(bundle, params)?;
    Ok(run_episode(
        map,
        &disc,
        controller.as_mut(),
        eval_seeds(seed, map, method, 0),
        true,
    ))
}

/// One point of the test-time learning curves (Fig. 9).
#[derive(Debug, Clone, Serialize)]
pub struct LearnPoint {
    /// Episode index (0 = first encounter).
    pub episode: u64,
    /// Surprise in bits on the first tick of the episode with a pedestrian on the
    /// crosswalk under a green light (None if that never happened).
    pub jaywalk_surprise_bits: Option<f64>,
    /// P(p' = 1 | p = 0, L' = 1, d' = 2): a pedestrian appearing on green at d = 2.
    pub p_appear_green_d2: f64,
    /// P(p' = 1 | p = 1, L' = 1, d' = 2): a pedestrian staying on the crosswalk on green at d = 2.
    pub p_stay_green_d2: f64,
    /// pi_o(slow down | s_jay), the base policy in the jaywalk state first met.
    pub p_slow_down: f64,
    /// Share of this episode's ticks that reasoned.
    pub inference_rate: f64,
    /// Whether the episode succeeded.
    pub success: bool,
    /// Return of the episode.
    pub reward: f64,
}

/// Runs the scaled agent (with test-time learning) for `episodes` episodes on `map`,
/// recording after each the quantities of Fig. 9.
pub fn learn(
    bundle: &AgentBundle,
    params: &ScaledParams,
    map: &Map,
    episodes: u64,
    seed: u64,
    quiet: bool,
) -> anyhow::Result<Vec<LearnPoint>> {
    let disc = Discretizer::new(&map.bins)?;
    check_compatible(bundle, &map.name, disc.n_states())?;
    let mut agent = ScaledAgent::new(
        bundle.world_model.clone(),
        &bundle.q_learning,
        ScaledParams {
            learning: true,
            ..params.clone()
        },
    )?;
    let bar = progress::bar(episodes, "learning", quiet);
    let mut jay_state: Option<usize> = None;
    let mut points = Vec::new();
    for ep in 0..episodes {
        let (result, ticks) = run_episode(map, &disc, &mut agent, eval_seeds(seed, map, Method::Scaled, ep), true);
        if jay_state.is_none() {
            jay_state = ticks
                .iter()
                .find(|t| t.state.p == 1 && t.state.l == 1)
                .map(|t| disc.encode(t.state));
        }
        let slow = Action::SlowDown.index();
        let js = jay_state.unwrap_or_else(|| {
            disc.encode(State {
                d: 2.min(disc.factor_sizes()[0] - 1),
                v: 0,
                l: 1,
                p: 1,
            })
        });
        points.push(LearnPoint {
            episode: ep,
            jaywalk_surprise_bits: result.jaywalk_surprise.map(|s| s / std::f64::consts::LN_2),
            p_appear_green_d2: pedestrian_prob(&agent, 0),
            p_stay_green_d2: pedestrian_prob(&agent, 1),
            p_slow_down: agent.pi_o(js)[slow],
            inference_rate: if result.ticks == 0 {
                0.0
            } else {
                f64::from(result.reasoning_ticks) / f64::from(result.ticks)
            },
            success: result.success,
            reward: result.ret,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(points)
}

/// P(p' = 1 | p = `p_prev`, L' = 1, d' = 2) from the agent's pedestrian CPT (factor 3,
/// parents p, L', d' in the paper's default structure).
fn pedestrian_prob(agent: &ScaledAgent, p_prev: usize) -> f64 {
    agent.model().cpt_prob(3, 1, &[p_prev, 1, 2], None)
}
