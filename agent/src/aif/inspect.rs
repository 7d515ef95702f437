//! `unforeseen inspect --model` on a model in pymdp's layout with any number of factors
//! and modalities: the model's keys ([`Model::from_json`]) plus the run below, and the
//! report of the last step.

use super::action::marginals;
use super::agent::Settings;
use super::error::ModelError;
use super::model::Model;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// What to run on the model: the observations and actions, and the agent's settings.
#[derive(Debug, Clone, PartialEq, Deserialize)]
pub struct Run {
    /// Observations `o_1..o_t`, one index per modality each (at least one step).
    pub obs: Vec<Vec<usize>>,
    /// Actions `u_1..u_{t-1}`, one per state factor each.
    #[serde(default)]
    pub actions: Vec<Vec<usize>>,
    /// The agent's settings (pymdp's names).
    #[serde(flatten)]
    pub settings: Settings,
}

/// The report of the last step.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[allow(non_snake_case)]
pub struct Report {
    /// Posterior per factor at the last step.
    pub qs: Vec<Vec<f64>>,
    /// Its variational free energy (nats); `−ln p(o_t | past)` for one factor.
    pub vfe: f64,
    /// The same in bits (the gate's surprise).
    pub surprise_bits: f64,
    /// Every policy, `[p][t][f]`.
    pub policies: Vec<Vec<Vec<usize>>>,
    /// EFE per policy (lower is better; pymdp's `−neg_efe`).
    pub G: Vec<f64>,
    /// Posterior over policies.
    pub q_pi: Vec<f64>,
    /// First-step action marginals per factor.
    pub action_marginals: Vec<Vec<f64>>,
    /// The action (deterministic, in `sampling_mode`).
    pub action: Vec<usize>,
}

/// Whether `v` is a run of this module: its `obs` is a list of lists (the single-factor
/// format of [`crate::inspect`] has a list of indices).
pub fn is_general(v: &Value) -> bool {
    v.get("obs")
        .and_then(Value::as_array)
        .and_then(|o| o.first())
        .is_some_and(Value::is_array)
}

/// Run `v` (model keys and [`Run`] keys) and report its last step.
pub fn inspect(v: &Value) -> Result<Report, ModelError> {
    let model = Model::from_json(v)?;
    let run: Run = serde_json::from_value(v.clone())
        .map_err(|e| ModelError::invalid("run", format!("{e} (keys: obs, actions, {})", Settings::KEYS)))?;
    if run.obs.is_empty() {
        return Err(ModelError::invalid("obs", "is empty, must hold at least one step"));
    }
    if run.actions.len() + 1 != run.obs.len() {
        return Err(ModelError::invalid(
            "actions",
            format!(
                "has {} steps, must have len(obs) - 1 = {}",
                run.actions.len(),
                run.obs.len() - 1
            ),
        ));
    }
    let agent = run.settings.agent(model)?;
    let mut prior = agent.initial_prior();
    let mut qs = Vec::new();
    for (t, o) in run.obs.iter().enumerate() {
        if t > 0 {
            prior = agent
                .update_empirical_prior(&run.actions[t - 1], &qs)
                .map_err(|e| ModelError::invalid(format!("actions[{}]", t - 1), e.to_string()))?;
        }
        qs = agent
            .infer_states(o, &prior)
            .map_err(|e| ModelError::invalid(format!("obs[{t}]"), e.to_string()))?;
    }
    let last = run.obs.last().expect("checked non-empty");
    let vfe = agent.vfe(last, &prior, &qs);
    let post = agent.infer_policies(&qs);
    // Deterministic selection never draws from the generator.
    let mut rng = <rand_chacha::ChaCha8Rng as rand::SeedableRng>::seed_from_u64(0);
    let action = agent.sample_action(&post.q_pi, &mut rng);
    Ok(Report {
        action_marginals: marginals(&post.q_pi, agent.policies(), agent.model().num_controls()),
        policies: agent.policies().to_vec(),
        qs,
        vfe,
        surprise_bits: vfe / std::f64::consts::LN_2,
        G: post.G,
        q_pi: post.q_pi,
        action,
    })
}
