//! Methods given from outside the library (a Python policy, or the scaled agent around a
//! Python habit): evaluated by the episode runner the built-in methods use
//! ([`evaluate_in_order`]), their figures from [`Aggregate`], and reported as the batch's
//! result lines ([`ResultLine`]), so that they sit in a results file beside the built-in
//! methods and the batch summary reads them alike. The fronts only make the controller.
//!
//! A method given from outside is known by its name alone: the name its lines carry, from
//! which its episodes' controller seeds derive ([`eval_seeds_named`]; the world seeds
//! depend on the map and the episode only, so every method meets the same pedestrians).
//! A policy given under a built-in method's name, and acting as it does, gives that
//! method's line (timing aside); its line carries no expectation checks (a map's
//! expectations are about the built-in methods) and the parameter set `default`.

use unforeseen_agent::params::ScaledParams;
use unforeseen_env::EnvConfig;

use crate::episodes::experiments::{MakeControllerMut, evaluate_in_order};
use crate::episodes::metrics::{Aggregate, efe_prefix_tree};
use crate::episodes::protocol::Protocol;
use crate::episodes::runner::EpisodeResult;
use crate::error::Error;
use crate::progress::Progress;
use crate::runs::batch::{ResultLine, Scenario};

/// A method given from outside, as the runner and its lines know it.
#[derive(Debug, Clone)]
pub struct ExternalMethod<'a> {
    /// Its name in the lines; its controller seeds derive from it ([`eval_seeds_named`]).
    ///
    /// [`eval_seeds_named`]: crate::episodes::experiments::eval_seeds_named
    pub name: &'a str,
    /// How the env observes for it (the form its policy reads).
    pub config: EnvConfig,
    /// Whether it learns across episodes: then it runs once per protocol asked, else once,
    /// its line covering every protocol asked (as the batch does for built-in methods).
    pub learns: bool,
    /// The scaled agent's parameters, for a method that plans by expected free energy (the
    /// scaled agent around a habit): its lines' reasoning compute counts that planner's
    /// prefix tree ([`efe_prefix_tree`]). None for a method that does not plan by EFE.
    pub planning: Option<&'a ScaledParams>,
}

/// Where a method's lines stand in a results file.
#[derive(Debug, Clone, Copy, Default)]
pub struct LinePlace {
    /// Unit index of the first line; the next ones follow.
    pub first_unit: usize,
    /// Training seed of the policy (None for a policy without one).
    pub train_seed: Option<u64>,
    /// Training episodes of the policy (None when unknown).
    pub train_episodes: Option<u64>,
}

/// One run of a method given from outside: its result line and its episodes.
#[derive(Debug, Clone)]
pub struct ExternalRun {
    /// The result line (the batch's schema).
    pub line: ResultLine,
    /// Every episode, in order.
    pub episodes: Vec<EpisodeResult>,
}

/// Evaluates `method` on the map of `scenario` under `protocols` (once per protocol if it
/// learns across episodes, else once for all: [`ExternalMethod::learns`]), `episodes`
/// episodes from `seed` each, in order on the calling thread ([`evaluate_in_order`]:
/// zero-shot makes a fresh controller per episode, continual one throughout), and reports
/// each run as a result line placed at `place`. A stream scenario, or no protocol, is an
/// [`Error::OutOfRange`].
#[allow(clippy::too_many_arguments)]
pub fn evaluate_external(
    scenario: &Scenario,
    method: &ExternalMethod<'_>,
    make: &mut MakeControllerMut<'_, '_>,
    protocols: &[Protocol],
    place: LinePlace,
    episodes: u64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<ExternalRun>, Error> {
    let map = scenario.map().ok_or_else(|| Error::OutOfRange {
        field: "map".into(),
        value: scenario.source.clone(),
        expected: "a map (a deployment stream runs built-in methods only)".into(),
    })?;
    let runs: Vec<(Protocol, Vec<Protocol>)> = match (method.learns, protocols.first()) {
        (_, None) => {
            return Err(Error::OutOfRange {
                field: "protocols".into(),
                value: "[]".into(),
                expected: "at least one of zero-shot, continual".into(),
            });
        }
        (true, _) => protocols.iter().map(|&p| (p, vec![p])).collect(),
        (false, Some(&first)) => vec![(first, protocols.to_vec())],
    };
    let tree = method.planning.map_or(0, efe_prefix_tree);
    progress.phase(&format!("{} {}", method.name, map.name), episodes * runs.len() as u64);
    let mut out = Vec::with_capacity(runs.len());
    for (i, (protocol, covers)) in runs.into_iter().enumerate() {
        // A method that does not learn runs as zero-shot (a fresh controller per episode),
        // whatever protocol its line names first, as the batch runs built-in methods.
        let mode = if method.learns { protocol } else { Protocol::ZeroShot };
        let results = evaluate_in_order(
            mode,
            map,
            method.config.clone(),
            method.name,
            make,
            episodes,
            seed,
            progress,
        )?;
        let agg = Aggregate::of(&results);
        let line = ResultLine {
            unit: place.first_unit + i,
            scenario: scenario.name().to_string(),
            source: scenario.source.clone(),
            method: method.name.to_string(),
            param_set: "default".into(),
            params: Vec::new(),
            protocol,
            covers,
            train_seed: place.train_seed,
            train_episodes: place.train_episodes,
            seed,
            episodes,
            mean_reward: agg.mean_reward,
            success_rate: agg.success_rate,
            collision_rate: agg.collision_rate,
            timeout_rate: agg.timeout_rate,
            red_light_rate: agg.red_light_rate,
            inference_rate: agg.inference_rate,
            efe_matvecs_per_tick: agg.inference_rate * tree as f64,
            mean_ticks: agg.mean_ticks,
            checks: Vec::new(),
            timing_us_per_tick: agg.us_per_tick,
            per_map: Vec::new(),
        };
        out.push(ExternalRun { line, episodes: results });
    }
    progress.finish();
    Ok(out)
}
