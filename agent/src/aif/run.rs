//! The gated loop over episodes in a [`Process`]: what `unforeseen run-model` runs.
//!
//! Each episode resets the process and the agent's prior, then runs `steps` ticks of
//! [`GatedAgent::step`]. Its return is the utility of what the agent observed,
//! `Σ_t Σ_m C_m[o_{t,m}]` (a time-indexed `C` scores with its first row). With `learn`,
//! after each episode the agent updates the `pA`, `pB` its model carries (pymdp's
//! Dirichlet rule, lr 1) from the episode's beliefs: test-time learning.

use super::error::ModelError;
use super::gate::GatedAgent;
use super::process::Process;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// What to run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunConfig {
    /// Episodes (at least 1).
    pub episodes: usize,
    /// Ticks per episode (at least 1).
    pub steps: usize,
    /// Seed of the process's and the agent's draws.
    pub seed: u64,
    /// Learn `pA`/`pB` after each episode (when the model has them).
    pub learn: bool,
}

/// One episode's outcome.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct EpisodeSummary {
    /// Utility of the observations.
    #[serde(rename = "return")]
    pub ret: f64,
    /// Ticks on which the agent planned.
    pub planned: usize,
    /// Ticks.
    pub ticks: usize,
    /// Mean surprise per tick, bits.
    pub mean_surprise_bits: f64,
}

/// Every episode and the totals.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RunSummary {
    /// Per episode.
    pub episodes: Vec<EpisodeSummary>,
    /// Mean return per episode.
    pub mean_return: f64,
    /// Planned ticks over all ticks.
    pub planned_fraction: f64,
}

/// Run `agent` in `process` (checked: the two agree on factors, states, modalities and
/// controls).
pub fn run(agent: &mut GatedAgent, process: &mut Process, cfg: RunConfig) -> Result<RunSummary, ModelError> {
    let (m, w) = (agent.agent().model(), process.world());
    if m.num_states() != w.num_states() || m.num_obs() != w.num_obs() || m.num_controls() != w.num_controls() {
        return Err(ModelError::invalid(
            "env",
            format!(
                "has states {:?}, observations {:?}, controls {:?}; the model has {:?}, {:?}, {:?}: they must agree",
                w.num_states(),
                w.num_obs(),
                w.num_controls(),
                m.num_states(),
                m.num_obs(),
                m.num_controls()
            ),
        ));
    }
    if cfg.episodes == 0 || cfg.steps == 0 {
        return Err(ModelError::invalid("run", "episodes and steps must be at least 1"));
    }
    let mut rng = ChaCha8Rng::seed_from_u64(cfg.seed);
    let mut episodes = Vec::with_capacity(cfg.episodes);
    for _ in 0..cfg.episodes {
        agent.reset();
        let mut obs = process.reset(&mut rng);
        let (mut beliefs, mut seen, mut acts) = (Vec::new(), Vec::new(), Vec::new());
        let (mut ret, mut planned, mut surprise) = (0.0, 0, 0.0);
        for _ in 0..cfg.steps {
            ret += agent.agent().model().utility(&obs)?;
            let (tick, qs) = agent.step(&obs, &mut rng)?;
            planned += usize::from(tick.planned);
            surprise += tick.surprise_bits;
            beliefs.push(qs);
            seen.push(obs.clone());
            acts.push(tick.action.clone());
            obs = process.step(&tick.action, &mut rng)?;
        }
        if cfg.learn {
            let model = agent.agent().model();
            let (la, lb) = (model.pa().map(|_| 1.0), model.pb().map(|_| 1.0));
            if la.is_some() || lb.is_some() {
                agent.agent_mut().infer_parameters(&beliefs, &seen, &acts, la, lb)?;
            }
        }
        episodes.push(EpisodeSummary {
            ret,
            planned,
            ticks: cfg.steps,
            mean_surprise_bits: surprise / cfg.steps as f64,
        });
    }
    let ticks: usize = episodes.iter().map(|e| e.ticks).sum();
    let planned: usize = episodes.iter().map(|e| e.planned).sum();
    Ok(RunSummary {
        mean_return: episodes.iter().map(|e| e.ret).sum::<f64>() / episodes.len() as f64,
        planned_fraction: planned as f64 / ticks as f64,
        episodes,
    })
}
