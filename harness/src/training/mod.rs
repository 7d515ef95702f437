//! Training (§VI): Q-learning, the world model's Dirichlet counts and Bayesian RL all
//! learn from the same episodes on the training map, driven by Q-learning's
//! epsilon-greedy exploration. This file is the training loop; [`train_agents`] trains one
//! agent per training seed (in parallel, cached on disk; `seed_agents.rs`) and [`agent_file`] reads and
//! writes a trained agent.

pub mod agent_file;
pub(crate) mod seed_agents;

pub use seed_agents::{Agent, DEFAULT_CACHE, MAX_TRAIN_SEEDS, TrainSeeds, train_agents};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::collections::BTreeMap;
use unforeseen_agent::bayes_rl::BayesRl;
use unforeseen_agent::model::WorldModel;
use unforeseen_agent::params::{BayesModel, BayesRlParams, ModelPriors, QParams};
use unforeseen_agent::persist::AgentBundle;
use unforeseen_agent::q_learning::QLearning;
use unforeseen_agent::structure::Structure;
use unforeseen_discretizer::Discretizer;
use unforeseen_env::{Env, EnvConfig};
use unforeseen_sim::{Action, Map};

use crate::episodes::rewards::{crash_model, red_light_cost, state_rewards, terminal_states};
use crate::error::Error;
use crate::progress::{NoProgress, Progress};
use unforeseen_env::seeds::episode_seed;

/// Everything training needs besides the map.
#[derive(Debug, Clone)]
pub struct TrainConfig {
    /// Training episodes (the paper uses 6000).
    pub episodes: u64,
    /// Run seed; episode seeds derive from it.
    pub seed: u64,
    /// Q-learning hyperparameters.
    pub q: QParams,
    /// Dirichlet priors of the world model.
    pub priors: ModelPriors,
    /// Bayesian-RL hyperparameters.
    pub bayes: BayesRlParams,
    /// Temperature tau_c of the preferences C = log_softmax(R / tau_c).
    pub tau_c: f64,
    /// What a time-out is to the learners (default: a truncation they bootstrap through).
    pub timeout_as: TimeoutAs,
}

impl TrainConfig {
    /// The paper's defaults (§VI) with `episodes` and `seed`.
    pub fn new(episodes: u64, seed: u64) -> Self {
        Self {
            episodes,
            seed,
            q: QParams {
                bias_action: Some(Action::SpeedUp.index()),
                ..QParams::default()
            },
            priors: ModelPriors::default(),
            bayes: BayesRlParams::default(),
            tau_c: 1.0,
            timeout_as: TimeoutAs::Truncation,
        }
    }
}

/// What a time-out (an episode cut off at `episode.max_steps` ticks) is to Q-learning's
/// and Bayesian RL's updates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TimeoutAs {
    /// A truncation: the state reached is not terminal, so Q-learning bootstraps through it
    /// and Bayesian RL records the transition to it (Gymnasium's `truncated`).
    #[default]
    Truncation,
    /// A terminal state (value 0, an absorbing transition), as if the task had ended there:
    /// the ablation that reproduces agents trained before time-outs were told apart.
    Termination,
}

impl TimeoutAs {
    /// The names `--timeout-as` takes.
    pub const NAMES: [&'static str; 2] = ["truncation", "termination"];
}

impl std::str::FromStr for TimeoutAs {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "truncation" => Ok(TimeoutAs::Truncation),
            "termination" => Ok(TimeoutAs::Termination),
            _ => Err(format!("'{s}' is not one of: {}", TimeoutAs::NAMES.join(", "))),
        }
    }
}

impl std::fmt::Display for TimeoutAs {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            TimeoutAs::Truncation => "truncation",
            TimeoutAs::Termination => "termination",
        })
    }
}

/// What training recorded: the return of every episode.
#[derive(Debug, Clone, Default)]
pub struct TrainLog {
    /// Return of every training episode (with exploration).
    pub returns: Vec<f64>,
    /// Training episodes that timed out.
    pub timeouts: u64,
}

/// The map agents train on unless told otherwise (embedded).
pub const DEFAULT_TRAIN_MAP: &str = "intersection";

/// Training episodes by default (the paper's 6000).
pub const DEFAULT_TRAIN_EPISODES: u64 = 6000;

/// Trains all learners on `map` and bundles them (with the preferences set from the
/// map's rewards) for evaluation or for saving as an agent file.
pub fn train(map: &Map, cfg: &TrainConfig) -> Result<(AgentBundle, TrainLog), Error> {
    train_with_progress(map, cfg, &NoProgress)
}

/// [`train`], advancing `progress` by one per episode; the caller announces and finishes
/// the phase (several agents training in parallel can share one).
pub fn train_with_progress(
    map: &Map,
    cfg: &TrainConfig,
    progress: &dyn Progress,
) -> Result<(AgentBundle, TrainLog), Error> {
    let disc = Discretizer::new(map)?;
    let n = disc.n_states();
    let n_actions = Action::ALL.len();
    let mut q = QLearning::try_new(n, n_actions, cfg.q.clone())?;
    let structure = Structure::paper_default(disc.factor_sizes())?;
    let structure_for_bayes = structure.clone();
    let mut model = WorldModel::new(structure, n_actions, &cfg.priors)?;
    let mut bayes = BayesRl::new(n, n_actions, cfg.bayes.clone())?;
    let factored = BayesRlParams {
        model: BayesModel::Factored(structure_for_bayes),
        ..cfg.bayes.clone()
    };
    let mut bayes_factored = BayesRl::new(n, n_actions, factored)?;
    let mut log = TrainLog::default();
    let stream = format!("{}/train", map.name);
    let mut env = Env::new(map, EnvConfig::default())?;
    for episode in 0..cfg.episodes {
        let seed = episode_seed(cfg.seed, &stream, episode);
        // Training observes the true state (fully observed, whatever the map's noise).
        let (_, info) = env.reset(seed);
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x6578_706c_6f72_6521);
        let mut s = disc.encode(info.state);
        model.observe_initial(s);
        let mut ret = 0.0;
        loop {
            let a = q.act_epsilon_greedy(s, &mut rng);
            let step = env.step(a)?;
            let r = step.reward;
            let s_next = disc.encode(step.info.state);
            let terminal = match cfg.timeout_as {
                TimeoutAs::Truncation => step.terminated,
                TimeoutAs::Termination => step.terminated || step.truncated,
            };
            q.update(s, a, r, s_next, terminal);
            model.observe_transition(s, a, s_next);
            bayes.observe_transition(s, a, r, s_next, terminal);
            bayes_factored.observe_transition(s, a, r, s_next, terminal);
            ret += r;
            s = s_next;
            if step.terminated || step.truncated {
                log.timeouts += u64::from(step.truncated);
                break;
            }
        }
        q.decay_epsilon();
        log.returns.push(ret);
        crate::progress::step(progress)?;
    }
    model.materialize();
    model.set_preferences(&state_rewards(map, &disc), cfg.tau_c)?;
    model.set_terminal_states(&terminal_states(map, &disc))?;
    model.set_transition_cost(red_light_cost(map, &disc, cfg.tau_c))?;
    model.set_crash_model(Some(crash_model(map, &disc, cfg.tau_c)))?;
    let mut meta = BTreeMap::new();
    meta.insert("map".into(), map.name.clone());
    meta.insert("episodes".into(), cfg.episodes.to_string());
    meta.insert("seed".into(), cfg.seed.to_string());
    meta.insert("timeout_as".into(), cfg.timeout_as.to_string());
    meta.insert("timeouts".into(), log.timeouts.to_string());
    meta.insert("factor_sizes".into(), format!("{:?}", disc.factor_sizes()));
    meta.insert("unforeseen_version".into(), env!("CARGO_PKG_VERSION").into());
    let mut bundle = AgentBundle::new(q, model, bayes, meta);
    bundle.bayes_rl_factored = Some(bayes_factored);
    Ok((bundle, log))
}
