//! Test-time learning curves (Fig. 9): the scaled agent learning across episodes in
//! order, with the gate's surprise at the event, its `P(p=1 | L=1, d=2)` and the base
//! policy's `P(slow down)` read before each episode.

use serde::Serialize;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_discretizer::{Discretizer, State};
use unforeseen_env::{Env, EnvConfig};
use unforeseen_sim::{Action, Map};

use crate::episodes::evaluation::eval_seeds;
use crate::episodes::methods::{Method, check_compatible};
use crate::episodes::runner::run_episode;
use crate::error::Error;
use crate::progress::Progress;

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
