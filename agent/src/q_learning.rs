//! Tabular Q-learning, the base learner and first baseline (§VI): ε-greedy training,
//! Q initialised with a bias toward speeding up (the paper's velocity preference).

use crate::controller::{Controller, Decision, one_hot};
use crate::error::{AgentError, FieldError, ParamError};
use crate::maths::argmax;
use crate::params::QParams;
use crate::stored_values;
use rand::RngExt;
use serde::{Deserialize, Serialize};

/// A Q-table over `n_states x n_actions`, laid out `[s * n_actions + a]`. Reading one
/// (serde) checks every stored value (see [`QLearning::try_from`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "QLearningRepr")]
pub struct QLearning {
    n_states: usize,
    n_actions: usize,
    params: QParams,
    epsilon: f64,
    table: Vec<f64>,
}

/// The stored fields of a [`QLearning`], before they are checked.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, rename = "QLearning")]
struct QLearningRepr {
    n_states: usize,
    n_actions: usize,
    params: QParams,
    epsilon: f64,
    table: Vec<f64>,
}

impl TryFrom<QLearningRepr> for QLearning {
    type Error = FieldError;
    /// Sizes in range, parameters valid, `epsilon` in [0, 1], a table of exactly
    /// `n_states * n_actions` finite values.
    fn try_from(r: QLearningRepr) -> Result<Self, FieldError> {
        stored_values::state_action_sizes(r.n_states, r.n_actions)?;
        r.params.check().map_err(|e| FieldError::from(e).within("params"))?;
        if let Some(b) = r.params.bias_action.filter(|b| *b >= r.n_actions) {
            return Err(FieldError::new(
                "params.bias_action",
                format!("is {b}; must be below n_actions = {}", r.n_actions),
            ));
        }
        if !stored_values::bounded(r.params.bias) {
            return Err(FieldError::new(
                "params.bias",
                format!(
                    "is {}; must be at most {:e} in size",
                    r.params.bias,
                    crate::limits::MAX_VALUE
                ),
            ));
        }
        if !(0.0..=1.0).contains(&r.epsilon) {
            return Err(FieldError::new(
                "epsilon",
                format!("is {}; must be in [0, 1]", r.epsilon),
            ));
        }
        let want = stored_values::product("table", r.n_states, r.n_actions)?;
        stored_values::len(
            "table",
            r.table.len(),
            want,
            &format!("n_states x n_actions = {} x {}", r.n_states, r.n_actions),
        )?;
        stored_values::finite("table", &r.table)?;
        Ok(QLearning {
            n_states: r.n_states,
            n_actions: r.n_actions,
            params: r.params,
            epsilon: r.epsilon,
            table: r.table,
        })
    }
}

impl QLearning {
    /// A table with `Q = 0` except `Q[s, bias_action] = bias` (§VI), after checking the
    /// parameters ([`QParams::check`]), the sizes (at least one state and one action) and
    /// `bias_action < n_actions`.
    pub fn new(n_states: usize, n_actions: usize, params: QParams) -> Result<QLearning, AgentError> {
        params.check()?;
        if n_states == 0 {
            return Err(ParamError::new("n_states", 0, ">= 1").into());
        }
        if n_actions == 0 {
            return Err(ParamError::new("n_actions", 0, ">= 1").into());
        }
        if let Some(b) = params.bias_action.filter(|b| *b >= n_actions) {
            return Err(ParamError::new("bias_action", b, "< n_actions").into());
        }
        let mut table = vec![0.0; n_states * n_actions];
        if let Some(b) = params.bias_action {
            for s in 0..n_states {
                table[s * n_actions + b] = params.bias;
            }
        }
        Ok(QLearning {
            n_states,
            n_actions,
            epsilon: params.epsilon,
            params,
            table,
        })
    }

    /// The same as [`QLearning::new`] (the name earlier callers use).
    pub fn try_new(n_states: usize, n_actions: usize, params: QParams) -> Result<QLearning, AgentError> {
        QLearning::new(n_states, n_actions, params)
    }

    /// Number of states.
    pub fn n_states(&self) -> usize {
        self.n_states
    }
    /// Number of actions.
    pub fn n_actions(&self) -> usize {
        self.n_actions
    }
    /// Parameters.
    pub fn params(&self) -> &QParams {
        &self.params
    }
    /// Current exploration rate.
    pub fn epsilon(&self) -> f64 {
        self.epsilon
    }
    /// The whole table, `[s * n_actions + a]`.
    pub fn table(&self) -> &[f64] {
        &self.table
    }

    /// `Q[s, ·]`.
    pub fn q(&self, s: usize) -> &[f64] {
        &self.table[s * self.n_actions..(s + 1) * self.n_actions]
    }

    /// Greedy action, ties broken by the lowest index.
    pub fn greedy(&self, s: usize) -> usize {
        argmax(self.q(s))
    }

    /// ε-greedy action with the current ε.
    pub fn act_epsilon_greedy(&self, s: usize, rng: &mut impl rand::Rng) -> usize {
        if rng.random::<f64>() < self.epsilon {
            rng.random_range(0..self.n_actions)
        } else {
            self.greedy(s)
        }
    }

    /// `Q[s,a] += α (r + γ max_a' Q[s',a'] (0 if terminal) - Q[s,a])`. `terminal` is set
    /// only when `s_next` ends the task (goal or collision); after a time-out the value
    /// bootstraps through `s_next`, which is not terminal.
    pub fn update(&mut self, s: usize, a: usize, r: f64, s_next: usize, terminal: bool) {
        let future = if terminal {
            0.0
        } else {
            self.q(s_next).iter().copied().fold(f64::NEG_INFINITY, f64::max)
        };
        let target = r + self.params.discount * future;
        let cell = &mut self.table[s * self.n_actions + a];
        *cell += self.params.alpha * (target - *cell);
    }

    /// `ε <- max(ε_min, ε · decay)`; call once per training episode.
    pub fn decay_epsilon(&mut self) {
        self.epsilon = (self.epsilon * self.params.epsilon_decay).max(self.params.epsilon_min);
    }
}

impl Controller for QLearning {
    fn name(&self) -> &'static str {
        "q-learning"
    }
    fn begin_episode(&mut self, _seed: u64) {}
    /// Greedy; never reasons.
    fn act(&mut self, obs: usize) -> Decision {
        let action = self.greedy(obs);
        Decision {
            action,
            reasoned: false,
            policy: one_hot(self.n_actions, action),
            ..Default::default()
        }
    }
}
