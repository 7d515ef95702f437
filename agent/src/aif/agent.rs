//! The agent on a [`Model`]: pymdp's `Agent` loop (`infer_states`,
//! `update_empirical_prior`, `infer_policies`, `sample_action`, `infer_parameters`) with
//! pymdp's defaults, every input checked.

use super::action::{Sampling, Selection, select};
use super::efe::{EfeTerms, Planner, Preferences};
use super::error::ModelError;
use super::infer;
use super::learning;
use super::model::Model;
use super::policies::Policies;
use rand::RngExt;

/// The agent's settings, pymdp's names and defaults.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AgentParams {
    /// Planning horizon T (pymdp's `policy_len`, default 1).
    pub policy_len: usize,
    /// Policy precision γ (default 1).
    pub gamma: f64,
    /// Fixed-point iterations of mean-field inference (pymdp's `num_iter`, default 16).
    pub num_iter: usize,
    /// Argmax or sample (default deterministic).
    pub action_selection: Selection,
    /// Over policies or action marginals (default full).
    pub sampling_mode: Sampling,
    /// EFE terms (default utility and state information gain).
    pub terms: EfeTerms,
    /// How `C` enters the utility (default as given, pymdp).
    pub preferences: Preferences,
}

impl Default for AgentParams {
    fn default() -> Self {
        AgentParams {
            policy_len: 1,
            gamma: 1.0,
            num_iter: 16,
            action_selection: Selection::Deterministic,
            sampling_mode: Sampling::Full,
            terms: EfeTerms::default(),
            preferences: Preferences::Raw,
        }
    }
}

/// The agent's settings as a model file gives them, beside its arrays (pymdp's argument
/// names; defaults as pymdp's `Agent`).
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
pub struct Settings {
    /// Planning horizon (default 1).
    #[serde(default = "one")]
    pub policy_len: usize,
    /// Policy precision (default 1).
    #[serde(default = "unit")]
    pub gamma: f64,
    /// Mean-field iterations (default 16).
    #[serde(default = "sixteen")]
    pub num_iter: usize,
    /// `full` (default) or `marginal`.
    #[serde(default)]
    pub sampling_mode: Sampling,
    /// `raw` (pymdp, default) or `ln_softmax` (the paper).
    #[serde(default)]
    pub preferences: Preferences,
    /// Include the parameter information gain (needs pA or pB; default false).
    #[serde(default)]
    pub use_param_info_gain: bool,
    /// Given policies `[p][t][f]` instead of all of them.
    #[serde(default)]
    pub policies: Option<Vec<Vec<Vec<usize>>>>,
}

fn one() -> usize {
    1
}
fn unit() -> f64 {
    1.0
}
fn sixteen() -> usize {
    16
}

impl Settings {
    /// The keys, for error messages.
    pub const KEYS: &'static str =
        "policy_len, gamma, num_iter, sampling_mode, preferences, use_param_info_gain, policies";

    /// Read the settings from a model file's object (other keys are ignored).
    pub fn from_json(v: &serde_json::Value) -> Result<Settings, ModelError> {
        serde_json::from_value(v.clone())
            .map_err(|e| ModelError::invalid("settings", format!("{e} (keys: {})", Settings::KEYS)))
    }

    /// The agent on `model` with these settings.
    pub fn agent(&self, model: Model) -> Result<Agent, ModelError> {
        let params = AgentParams {
            policy_len: self.policy_len,
            gamma: self.gamma,
            num_iter: self.num_iter,
            sampling_mode: self.sampling_mode,
            preferences: self.preferences,
            terms: EfeTerms {
                param_info_gain: self.use_param_info_gain,
                ..EfeTerms::default()
            },
            ..AgentParams::default()
        };
        Agent::new(model, params, self.policies.as_deref())
    }
}

/// The posterior over policies of one planning tick.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
#[allow(non_snake_case)]
pub struct PolicyPosterior {
    /// Expected free energy per policy (lower is better; pymdp's `−neg_efe`).
    pub G: Vec<f64>,
    /// `σ(−γ G + ln E)`.
    pub q_pi: Vec<f64>,
}

/// An active-inference agent on a discrete model in pymdp's layout.
#[derive(Debug, Clone)]
pub struct Agent {
    model: Model,
    params: AgentParams,
    policies: Policies,
    planner: Planner,
}

impl Agent {
    /// An agent on `model` with exhaustive policies of `params.policy_len`, or the given
    /// `policies` (`[p][t][f]`, whose length then sets the horizon).
    pub fn new(model: Model, params: AgentParams, policies: Option<&[Vec<Vec<usize>>]>) -> Result<Agent, ModelError> {
        let policies = match policies {
            None => Policies::exhaustive(&model.num_controls, params.policy_len)?,
            Some(list) => Policies::given(list, &model.num_controls)?,
        };
        let params = AgentParams {
            policy_len: policies.policy_len(),
            ..params
        };
        if !(params.gamma.is_finite() && params.gamma > 0.0) {
            return Err(ModelError::invalid(
                "gamma",
                format!("is {}, must be finite and > 0", params.gamma),
            ));
        }
        if params.num_iter == 0 {
            return Err(ModelError::invalid("num_iter", "is 0, must be at least 1"));
        }
        if let Selection::Stochastic { alpha } = params.action_selection
            && !(alpha.is_finite() && alpha > 0.0)
        {
            return Err(ModelError::invalid(
                "alpha",
                format!("is {alpha}, must be finite and > 0"),
            ));
        }
        for (m, c) in model.c.iter().enumerate() {
            if c.ndim() == 2 && c.shape[0] < params.policy_len {
                return Err(ModelError::invalid(
                    format!("C[{m}]"),
                    format!(
                        "is time-indexed over {} steps, must cover policy_len = {}",
                        c.shape[0], params.policy_len
                    ),
                ));
            }
        }
        if let Some(e) = &model.e
            && e.len() != policies.len()
        {
            return Err(ModelError::Shape {
                array: "E".into(),
                axis: "axis 0".into(),
                found: e.len(),
                expected: policies.len(),
                why: "the number of policies".into(),
            });
        }
        if params.terms.param_info_gain && model.pa.is_none() && model.pb.is_none() {
            return Err(ModelError::invalid("param_info_gain", "needs pA or pB in the model"));
        }
        let planner = Planner::new(&model, params.preferences, params.terms, params.policy_len);
        Ok(Agent {
            model,
            params,
            policies,
            planner,
        })
    }

    /// The model (with its learned `A`, `B`, `pA`, `pB`).
    pub fn model(&self) -> &Model {
        &self.model
    }
    /// The settings.
    pub fn params(&self) -> &AgentParams {
        &self.params
    }
    /// The policies.
    pub fn policies(&self) -> &Policies {
        &self.policies
    }

    /// `D`: the empirical prior of the first step.
    pub fn initial_prior(&self) -> Vec<Vec<f64>> {
        self.model.d.clone()
    }

    /// The posterior over each factor given one observation per modality (fpi).
    pub fn infer_states(&self, obs: &[usize], prior: &[Vec<f64>]) -> Result<Vec<Vec<f64>>, ModelError> {
        self.model.check_obs(obs)?;
        self.model.check_marginals("prior", prior)?;
        Ok(infer::fpi(&self.model, obs, prior, self.params.num_iter))
    }

    /// The variational free energy of `qs` at this step, in nats (the surprise).
    pub fn vfe(&self, obs: &[usize], prior: &[Vec<f64>], qs: &[Vec<f64>]) -> f64 {
        infer::vfe(&self.model, obs, prior, qs)
    }

    /// The prior of the next step after `action` (pymdp's `update_empirical_prior`).
    pub fn update_empirical_prior(&self, action: &[usize], qs: &[Vec<f64>]) -> Result<Vec<Vec<f64>>, ModelError> {
        self.model.check_action(action)?;
        self.model.check_marginals("qs", qs)?;
        Ok(infer::expected_state(&self.model, qs, action))
    }

    /// `G` and `q_π` of every policy from the posterior `qs`.
    pub fn infer_policies(&self, qs: &[Vec<f64>]) -> PolicyPosterior {
        let (g, q_pi) = self.planner.evaluate(
            &self.model,
            qs,
            &self.policies,
            self.params.gamma,
            self.model.e.as_deref(),
        );
        PolicyPosterior { G: g, q_pi }
    }

    /// The multi-action to take from `q_pi` (the rng is used only when stochastic).
    pub fn sample_action(&self, q_pi: &[f64], rng: &mut impl RngExt) -> Vec<usize> {
        select(
            q_pi,
            &self.policies,
            &self.model.num_controls,
            self.params.action_selection,
            self.params.sampling_mode,
            rng,
        )
    }

    /// Dirichlet learning from one sequence (`obs[t]`, `beliefs[t]`, `actions[t]` between
    /// `t` and `t+1`): `A` when the model has `pA` and `lr_pa` is given, `B` likewise.
    pub fn infer_parameters(
        &mut self,
        beliefs: &[Vec<Vec<f64>>],
        obs: &[Vec<usize>],
        actions: &[Vec<usize>],
        lr_pa: Option<f64>,
        lr_pb: Option<f64>,
    ) -> Result<(), ModelError> {
        for (name, lr) in [("lr_pA", lr_pa), ("lr_pB", lr_pb)] {
            if let Some(lr) = lr
                && !(lr.is_finite() && lr >= 0.0)
            {
                return Err(ModelError::invalid(name, format!("is {lr}, must be finite and >= 0")));
            }
        }
        let mut model = self.model.clone();
        if let Some(lr) = lr_pa {
            learning::update_pa(&mut model, obs, beliefs, lr)?;
        }
        if let Some(lr) = lr_pb {
            learning::update_pb(&mut model, obs, beliefs, actions, lr)?;
        }
        self.planner = Planner::new(
            &model,
            self.params.preferences,
            self.params.terms,
            self.params.policy_len,
        );
        self.model = model;
        Ok(())
    }
}
