//! The experiments of §VI: evaluation of a method on a map, the comparison table
//! (Fig. 8), one traced episode (Figs. 6-7) and test-time learning curves (Fig. 9).

use rayon::prelude::*;
use serde::Serialize;
use unforeseen_agent::controller::Controller;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_discretizer::{Discretizer, State};
use unforeseen_env::{Env, EnvConfig};
use unforeseen_sim::{Action, Map};

use crate::episodes::methods::Method;
use crate::episodes::metrics::Aggregate;
use crate::episodes::protocol::Protocol;
use crate::episodes::runner::{EpisodeResult, EpisodeSeeds, Tick, run_episode};
use crate::error::Error;
use crate::progress::Progress;
use crate::seeds::episode_seed;
use crate::training::agent_file::check_compatible;

/// Seeds of evaluation episode `episode` of `method` on `map`: the world seed depends
/// on the map and episode only (every method meets the same pedestrians), the
/// controller seed on the method too.
pub fn eval_seeds(seed: u64, map: &Map, method: Method, episode: u64) -> EpisodeSeeds {
    eval_seeds_named(seed, map, method.name(), episode)
}

/// [`eval_seeds`] of the method named `method`: the seeds of a built-in method under its
/// name ([`Method::name`]), and of a method given from outside (a Python policy) under
/// the name its result lines carry, so that a line's (seed, map, method) alone says which
/// episodes it ran.
pub fn eval_seeds_named(seed: u64, map: &Map, method: &str, episode: u64) -> EpisodeSeeds {
    EpisodeSeeds {
        world: episode_seed(seed, &format!("{}/eval", map.name), episode),
        controller: episode_seed(seed, &format!("{}/eval/{method}", map.name), episode),
    }
}

/// Runs `episodes` episodes of `controller` on `map` in order (test-time learning
/// carries over from one episode to the next: the continual protocol on a controller
/// the caller built), as one phase of `progress` (`METHOD MAP`, one step per episode).
pub fn evaluate(
    map: &Map,
    controller: &mut dyn Controller,
    method: Method,
    episodes: u64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<EpisodeResult>, Error> {
    let mut env = Env::new(map, EnvConfig::default())?;
    progress.phase(&format!("{} {}", method.name(), map.name), episodes);
    let results = (0..episodes)
        .map(|ep| {
            crate::progress::step(progress)?;
            Ok(run_episode(&mut env, controller, eval_seeds(seed, map, method, ep), false)?.0)
        })
        .collect();
    progress.finish();
    results
}

/// Runs `episodes` evaluation episodes of `method` on `map` under `protocol`, advancing
/// `progress` by one per episode (the caller announces and finishes the phase). Zero-shot: a fresh controller per episode, episodes in
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
    progress: &dyn Progress,
) -> Result<Vec<EpisodeResult>, Error> {
    check_compatible(bundle, map)?;
    let make = || method.controller(bundle, params, map);
    evaluate_with(protocol, map, method, params, &make, episodes, seed, progress)
}

/// Makes a fresh controller of the method being evaluated.
pub type MakeController<'a> = dyn Fn() -> Result<Box<dyn Controller>, Error> + Sync + 'a;

/// [`evaluate_under`] with the controllers made by `make` (e.g. a scripted reference,
/// which needs no trained agent).
#[allow(clippy::too_many_arguments)]
pub fn evaluate_with(
    protocol: Protocol,
    map: &Map,
    method: Method,
    params: &ScaledParams,
    make: &MakeController<'_>,
    episodes: u64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<EpisodeResult>, Error> {
    let new_env = || Env::new(map, EnvConfig::default());
    let run = |env: &mut Env, controller: &mut dyn Controller, ep: u64| -> Result<EpisodeResult, Error> {
        let result = run_episode(env, controller, eval_seeds(seed, map, method, ep), false)?.0;
        crate::progress::step(progress)?;
        Ok(result)
    };
    match protocol.effective(method, params) {
        Protocol::ZeroShot => (0..episodes)
            .into_par_iter()
            .map_init(new_env, |env, ep| {
                let env = env.as_mut().map_err(|e| e.clone())?;
                run(env, make()?.as_mut(), ep)
            })
            .collect(),
        Protocol::Continual => {
            let mut controller = make()?;
            let mut env = new_env()?;
            (0..episodes).map(|ep| run(&mut env, controller.as_mut(), ep)).collect()
        }
    }
}

/// Makes a fresh controller, for [`evaluate_in_order`] (it may borrow, and need not be `Sync`).
pub type MakeControllerMut<'a, 'c> = dyn FnMut() -> Result<Box<dyn Controller + 'c>, Error> + 'a;

/// Runs `episodes` evaluation episodes of the method named `method` on `map` under
/// `protocol`, one at a time in order on one env observing as `config` says, with the
/// seeds of that name ([`eval_seeds_named`]), advancing `progress` by one per episode.
/// Zero-shot: a fresh controller from `make` per episode; continual: one controller
/// throughout. For controllers that must not run on several threads at once (a policy
/// given from Python: [`evaluate_with`] runs zero-shot episodes in parallel); the results
/// are those [`evaluate_with`] gives for the same controllers and name.
#[allow(clippy::too_many_arguments)]
pub fn evaluate_in_order(
    protocol: Protocol,
    map: &Map,
    config: EnvConfig,
    method: &str,
    make: &mut MakeControllerMut<'_, '_>,
    episodes: u64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<EpisodeResult>, Error> {
    let mut env = Env::new(map, config)?;
    let mut controller = make()?;
    (0..episodes)
        .map(|ep| {
            if protocol == Protocol::ZeroShot && ep > 0 {
                controller = make()?;
            }
            let result = run_episode(
                &mut env,
                controller.as_mut(),
                eval_seeds_named(seed, map, method, ep),
                false,
            )?
            .0;
            crate::progress::step(progress)?;
            Ok(result)
        })
        .collect()
}

/// Runs `episodes` episodes of a scripted reference `method` ([`Method::REFERENCE`]) on
/// `map`; it needs no trained agent and does not learn, so every protocol is zero-shot.
pub fn evaluate_scripted(
    map: &Map,
    method: Method,
    episodes: u64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<EpisodeResult>, Error> {
    let sizes = Discretizer::new(map)?.factor_sizes();
    let make = || {
        method
            .scripted_controller(&sizes, map)?
            .ok_or_else(|| Error::NotScripted {
                method: method.to_string(),
            })
    };
    evaluate_with(
        Protocol::ZeroShot,
        map,
        method,
        &ScaledParams::default(),
        &make,
        episodes,
        seed,
        progress,
    )
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
    /// Red-light violations per episode on the test map.
    pub red_light_rate: f64,
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
        red_light_rate: test.red_light_rate,
        inference_rate: test.inference_rate,
        reasoning_us_per_tick: test.us_per_tick,
        train,
        test,
    }
}

/// Runs evaluation episode `episode` of `method` (seeded as in [`evaluate_under`]) with
/// its ticks recorded, and returns its result and ticks. Under the continual protocol the
/// controller first runs evaluation episodes `0..episode` in order and learns from them,
/// so the traced episode is exactly the one a continual evaluation meets at that index.
pub fn trace(
    bundle: &AgentBundle,
    params: &ScaledParams,
    method: Method,
    map: &Map,
    seed: u64,
    protocol: Protocol,
    episode: u64,
) -> Result<(EpisodeResult, Vec<Tick>), Error> {
    let mut env = Env::new(map, EnvConfig::default())?;
    check_compatible(bundle, map)?;
    let mut controller = method.controller(bundle, params, map)?;
    if protocol.effective(method, params) == Protocol::Continual {
        for ep in 0..episode {
            run_episode(&mut env, controller.as_mut(), eval_seeds(seed, map, method, ep), false)?;
        }
    }
    Ok(run_episode(
        &mut env,
        controller.as_mut(),
        eval_seeds(seed, map, method, episode),
        true,
    )?)
}

/// One point of the test-time learning curves (Fig. 9): what the agent brings into
/// episode `episode` (probabilities read before it), and how the episode went.
#[derive(Debug, Clone, Serialize)]
pub struct LearnPoint {
    /// Episode index (0 = first encounter).
    pub episode: u64,
    /// The map the episode ran on (one map for a map's curve; the stream's draw for a
    /// stream's, [`crate::runs::stream::learn_stream`]).
    pub map: String,
    /// The gate's surprise in bits on the first tick of the episode with a pedestrian on
    /// the crosswalk under a green light (Fig. 9a; None if that never happened).
    pub event_surprise_bits: Option<f64>,
    /// The gate's `P(p=1 | L=1, d=2)`, a pedestrian on the crosswalk under green at d = 2
    /// (Fig. 9b; None with the one-step gate).
    pub p_pedestrian_green_d2: Option<f64>,
    /// The planning model's persistence `P(p'=1 | p=1, L'=1, d'=2)`.
    pub p_stay_green_d2: f64,
    /// `pi_o(slow down | s_event)`, the base policy in the event state first met (Fig. 9c).
    pub p_slow_down: f64,
    /// Ticks of this episode that reasoned.
    pub reasoning_ticks: u32,
    /// Share of this episode's ticks that reasoned.
    pub inference_rate: f64,
    /// Whether the episode succeeded.
    pub success: bool,
    /// Return of the episode.
    pub reward: f64,
}

/// Runs the scaled agent (with test-time learning, the continual protocol) for `episodes`
/// episodes on `map`, recording the quantities of Fig. 9 in the paper's units, as one
/// phase of `progress` (`learning`, one step per episode).
pub fn learn(
    bundle: &AgentBundle,
    params: &ScaledParams,
    map: &Map,
    episodes: u64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<LearnPoint>, Error> {
    learn_over(bundle, params, &[map], &vec![0; episodes as usize], seed, progress)
}

/// [`learn`] over several maps: one scaled agent learning across the episodes in order,
/// episode `k` on `maps[schedule[k]]` with the seeds of episode `k` of that map
/// ([`eval_seeds`]). The event state of Fig. 9c is the first one met on any map.
pub fn learn_over(
    bundle: &AgentBundle,
    params: &ScaledParams,
    maps: &[&Map],
    schedule: &[usize],
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<LearnPoint>, Error> {
    let mut envs = Vec::with_capacity(maps.len());
    for map in maps {
        check_compatible(bundle, map)?;
        envs.push(Env::new(map, EnvConfig::default())?);
    }
    let discs: Vec<Discretizer> = envs.iter().map(|e| e.discretizer().clone()).collect();
    let mut agent = crate::episodes::methods::scaled_agent(bundle, {
        let mut p = params.clone();
        p.learning.enabled = true;
        p
    })?;
    progress.phase("learning", schedule.len() as u64);
    let mut event_state: Option<usize> = None;
    let mut points = Vec::new();
    let slow = Action::SlowDown.index();
    for (ep, &m) in schedule.iter().enumerate() {
        let (map, env, disc) = (maps[m], &mut envs[m], &discs[m]);
        let p_pedestrian_green_d2 = pedestrian_on_green_d2(&agent);
        let p_stay_green_d2 = agent.model().cpt_prob(3, 1, &[1, 1, 2], None);
        let before = agent.nu().to_vec();
        let (result, ticks) = run_episode(env, &mut agent, eval_seeds(seed, map, Method::Scaled, ep as u64), true)?;
        if event_state.is_none() {
            event_state = ticks
                .iter()
                .find(|t| t.state.p == 1 && t.state.l == 1)
                .map(|t| disc.encode(t.state));
        }
        let es = event_state.unwrap_or_else(|| {
            disc.encode(State {
                d: 2.min(disc.factor_sizes()[0] - 1),
                v: 0,
                l: 1,
                p: 1,
            })
        });
        let row = &before[es * Action::ALL.len()..(es + 1) * Action::ALL.len()];
        points.push(LearnPoint {
            episode: ep as u64,
            map: map.name.clone(),
            event_surprise_bits: result.jaywalk_surprise.map(|s| s / std::f64::consts::LN_2),
            p_pedestrian_green_d2,
            p_stay_green_d2,
            p_slow_down: row[slow] / row.iter().sum::<f64>(),
            reasoning_ticks: result.reasoning_ticks,
            inference_rate: if result.ticks == 0 {
                0.0
            } else {
                f64::from(result.reasoning_ticks) / f64::from(result.ticks)
            },
            success: result.success,
            reward: result.ret,
        });
        crate::progress::step(progress)?;
    }
    progress.finish();
    Ok(points)
}

/// The gate's `P(p=1 | L=1, d=2)` (Fig. 9b), if the agent gates on the state and its
/// gate conditions on factors named `L` and `d`.
fn pedestrian_on_green_d2(agent: &ScaledAgent) -> Option<f64> {
    let gate = agent.gate()?;
    let factors = agent.model().structure().factors();
    let values = gate
        .given()
        .iter()
        .map(|g| match factors[*g].name.as_str() {
            "L" => Some(1),
            "d" => Some(2),
            _ => None,
        })
        .collect::<Option<Vec<usize>>>()?;
    Some(gate.probability(1, &values))
}

/// The report of one method evaluated on one map (eval.json), built by [`evaluate_map`]
/// alone, which the command line and the Python package both call.
#[derive(Debug, Clone, Serialize)]
pub struct EvalReport {
    /// The method.
    pub method: Method,
    /// The map's name.
    pub map: String,
    /// The protocol asked.
    pub protocol: Protocol,
    /// The protocol the results hold for: zero-shot for a method that does not learn
    /// across episodes, whatever was asked ([`Protocol::effective`]).
    pub computed_under: Protocol,
    /// Whether the method learns across episodes with these parameters (the printed line
    /// says so when it does not, [`crate::reports::tables::eval`]); not in the file.
    #[serde(skip)]
    pub learns_across_episodes: bool,
    /// Evaluation seed (episode seeds derive from it).
    pub seed: u64,
    /// The training seed the agent file records (null for a scripted method, or an
    /// agent file that does not say).
    pub train_seed: Option<String>,
    /// The map's reward settings.
    pub reward: unforeseen_sim::Reward,
    /// The figures over every episode.
    pub aggregate: Aggregate,
    /// Every episode, in order.
    pub episodes: Vec<EpisodeResult>,
}

impl EvalReport {
    /// The report as eval.json holds it: a JSON object with its keys sorted at every
    /// level (the layout eval.json has always had).
    pub fn document(&self) -> Result<serde_json::Value, Error> {
        Ok(serde_json::to_value(self)?)
    }
}

/// Evaluates `method` on `map` for `episodes` episodes from `seed` under `protocol`, as
/// one phase of `progress`, and reports it ([`EvalReport`]): a scripted reference
/// ([`Method::REFERENCE`]) needs no agent and ignores `bundle`; every other method runs
/// the agent `bundle` with the scaled agent's parameters `params`, and without one is an
/// [`Error::Agent`].
#[allow(clippy::too_many_arguments)]
pub fn evaluate_map(
    map: &Map,
    method: Method,
    protocol: Protocol,
    bundle: Option<&AgentBundle>,
    params: &ScaledParams,
    episodes: u64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<EvalReport, Error> {
    let (results, train_seed) = match (method.is_scripted(), bundle) {
        (true, _) => (evaluate_scripted(map, method, episodes, seed, progress)?, None),
        (false, Some(b)) => (
            evaluate_under(protocol, map, b, params, method, episodes, seed, progress)?,
            b.meta.get("seed").cloned(),
        ),
        (false, None) => {
            return Err(Error::Agent {
                problem: format!("{method} needs a trained agent"),
                fix: "give an agent file, or train one first".into(),
            });
        }
    };
    Ok(EvalReport {
        method,
        map: map.name.clone(),
        protocol,
        computed_under: protocol.effective(method, params),
        learns_across_episodes: method.learns_across_episodes(params),
        seed,
        train_seed,
        reward: map.reward.clone(),
        aggregate: Aggregate::of(&results),
        episodes: results,
    })
}
