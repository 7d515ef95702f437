//! Evaluation of a method on a map (§VI): the seeds of each evaluation episode, the
//! episodes run under a protocol (zero-shot in parallel, continual in order), a method's
//! row of the comparison table (Fig. 8) and eval.json's report ([`EvalReport`]).

use rayon::prelude::*;
use serde::Serialize;
use unforeseen_agent::controller::Controller;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_discretizer::Discretizer;
use unforeseen_env::{Env, EnvConfig};
use unforeseen_sim::Map;

use crate::episodes::methods::{Method, check_compatible};
use crate::episodes::metrics::Aggregate;
use crate::episodes::protocol::Protocol;
use crate::episodes::runner::{EpisodeResult, EpisodeSeeds, run_episode};
use crate::error::Error;
use crate::progress::Progress;
use unforeseen_env::seeds::episode_seed;

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
pub fn run_controller(
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
pub fn run_agent_episodes(
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
    run_episodes_with(protocol, map, method, params, &make, episodes, seed, progress)
}

/// Makes a fresh controller of the method being evaluated.
pub type MakeController<'a> = dyn Fn() -> Result<Box<dyn Controller>, Error> + Sync + 'a;

/// [`run_agent_episodes`] with the controllers made by `make` (e.g. a scripted reference,
/// which needs no trained agent).
#[allow(clippy::too_many_arguments)]
pub fn run_episodes_with(
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

/// Makes a fresh controller, for [`run_episodes_in_order`] (it may borrow, and need not be `Sync`).
pub type MakeControllerMut<'a, 'c> = dyn FnMut() -> Result<Box<dyn Controller + 'c>, Error> + 'a;

/// Runs `episodes` evaluation episodes of the method named `method` on `map` under
/// `protocol`, one at a time in order on one env observing as `config` says, with the
/// seeds of that name ([`eval_seeds_named`]), advancing `progress` by one per episode.
/// Zero-shot: a fresh controller from `make` per episode; continual: one controller
/// throughout. For controllers that must not run on several threads at once (a policy
/// given from Python: [`run_episodes_with`] runs zero-shot episodes in parallel); the results
/// are those [`run_episodes_with`] gives for the same controllers and name.
#[allow(clippy::too_many_arguments)]
pub fn run_episodes_in_order(
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
pub fn run_scripted_episodes(
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
    run_episodes_with(
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
    /// says so when it does not, [`crate::runs::evaluate::eval_table`]); not in the file.
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
        (true, _) => (run_scripted_episodes(map, method, episodes, seed, progress)?, None),
        (false, Some(b)) => (
            run_agent_episodes(protocol, map, b, params, method, episodes, seed, progress)?,
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
