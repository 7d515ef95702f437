//! The paper's gate on any model (§II, §VI): each tick the agent infers its state, scores
//! its surprise (the VFE of the observation under its prediction, in bits; `−log2 p(o)`
//! for one factor) and plans only when the surprise exceeds ε. Otherwise it acts from its
//! habit:
//!
//! * [`Habit::Prior`]: the given `E`'s first-step action marginal (pymdp's prior over
//!   policies as a habit);
//! * [`Habit::Learned`]: the action it planned most often before in the same most likely
//!   state (counts on (argmax state per factor, multi-action)); a state never planned in
//!   is planned in;
//! * any other policy, through [`GatedAgent::step_with`]: a function of the observation
//!   and the posterior that returns the action (e.g. a Python policy, the `ScaledWrapper`
//!   pattern).
//!
//! With ε < 0 the gate is open on every tick: the agent is pymdp's.

use super::action::marginals;
use super::agent::{Agent, PolicyPosterior};
use super::error::ModelError;
use crate::maths::argmax;
use rand::RngExt;
use std::collections::BTreeMap;

/// What the agent does when not surprised.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Habit {
    /// The first-step marginal of the model's `E` (needs `E`).
    Prior,
    /// The action most often planned before in this most likely state.
    Learned,
}

/// One tick of the gated loop.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Tick {
    /// The multi-action taken.
    pub action: Vec<usize>,
    /// Surprise of the observation, in bits.
    pub surprise_bits: f64,
    /// Whether the agent planned (the gate was open).
    pub planned: bool,
    /// The posterior over policies, when it planned.
    pub q_pi: Option<Vec<f64>>,
}

/// An [`Agent`] behind the surprise gate.
#[derive(Debug, Clone)]
pub struct GatedAgent {
    agent: Agent,
    epsilon_bits: f64,
    habit: Habit,
    counts: BTreeMap<Vec<usize>, BTreeMap<Vec<usize>, u64>>,
    prior: Vec<Vec<f64>>,
}

impl GatedAgent {
    /// Gate `agent` at `epsilon_bits` (finite; negative: always plan) with `habit`.
    pub fn new(agent: Agent, epsilon_bits: f64, habit: Habit) -> Result<GatedAgent, ModelError> {
        if habit == Habit::Prior && agent.model().e().is_none() {
            return Err(ModelError::invalid(
                "habit",
                "is `prior`, but the model has no E (give E, or use the learned habit)",
            ));
        }
        let prior = agent.initial_prior();
        let mut gated = GatedAgent {
            agent,
            epsilon_bits: 0.0,
            habit,
            counts: BTreeMap::new(),
            prior,
        };
        gated.set_epsilon_bits(epsilon_bits)?;
        Ok(gated)
    }

    /// The threshold ε, bits.
    pub fn epsilon_bits(&self) -> f64 {
        self.epsilon_bits
    }

    /// Set ε (finite; negative: always plan), e.g. plan on every tick while training the
    /// habit, then gate at test (the learned habit is kept).
    pub fn set_epsilon_bits(&mut self, epsilon_bits: f64) -> Result<(), ModelError> {
        if !epsilon_bits.is_finite() {
            return Err(ModelError::invalid(
                "epsilon",
                format!("is {epsilon_bits}, must be finite (bits; negative: plan on every tick)"),
            ));
        }
        self.epsilon_bits = epsilon_bits;
        Ok(())
    }

    /// The agent behind the gate.
    pub fn agent(&self) -> &Agent {
        &self.agent
    }

    /// Mutable access, e.g. to learn `A`, `B` between episodes.
    pub fn agent_mut(&mut self) -> &mut Agent {
        &mut self.agent
    }

    /// Start an episode: the prior is `D` again (the learned habit is kept).
    pub fn reset(&mut self) {
        self.prior = self.agent.initial_prior();
    }

    fn habit_action(&self, qs: &[Vec<f64>]) -> Option<Vec<usize>> {
        match self.habit {
            Habit::Prior => {
                let e = self.agent.model().e()?;
                let m = marginals(e, self.agent.policies(), self.agent.model().num_controls());
                Some(m.iter().map(|mf| argmax(mf)).collect())
            }
            Habit::Learned => {
                let key: Vec<usize> = qs.iter().map(|q| argmax(q)).collect();
                let c = self.counts.get(&key)?;
                // Most counts; ties to the lowest multi-action (BTreeMap order).
                let best = c.values().copied().max()?;
                c.iter().find(|(_, n)| **n == best).map(|(u, _)| u.clone())
            }
        }
    }

    /// One tick: infer the state from `obs`, score the surprise, plan or act from habit,
    /// and predict the next state. Also returns the posterior `qs`.
    pub fn step(&mut self, obs: &[usize], rng: &mut impl RngExt) -> Result<(Tick, Vec<Vec<f64>>), ModelError> {
        self.tick(obs, rng, |gated, _, qs| Ok(gated.habit_action(qs)))
    }

    /// One tick as [`GatedAgent::step`], with `habit` in place of the agent's own: when the
    /// surprise does not exceed ε it is called with the observation and the posterior
    /// `qs` and returns the multi-action to take (one control per factor; any other is
    /// refused naming `habit`). Planned actions still add to the learned habit's counts.
    /// `habit`'s own error type carries through; the model's errors convert into it.
    pub fn step_with<E: From<ModelError>>(
        &mut self,
        obs: &[usize],
        rng: &mut impl RngExt,
        habit: impl FnOnce(&[usize], &[Vec<f64>]) -> Result<Vec<usize>, E>,
    ) -> Result<(Tick, Vec<Vec<f64>>), E> {
        self.tick(obs, rng, |gated, obs, qs| {
            let u = habit(obs, qs)?;
            gated
                .agent
                .model()
                .check_action(&u)
                .map_err(|e| ModelError::invalid("habit", format!("returned the action {u:?}: {e}")))?;
            Ok(Some(u))
        })
    }

    /// The tick itself; `habit` (asked only when the gate is closed) gives the action or
    /// `None` to plan.
    fn tick<E: From<ModelError>>(
        &mut self,
        obs: &[usize],
        rng: &mut impl RngExt,
        habit: impl FnOnce(&GatedAgent, &[usize], &[Vec<f64>]) -> Result<Option<Vec<usize>>, E>,
    ) -> Result<(Tick, Vec<Vec<f64>>), E> {
        let qs = self.agent.infer_states(obs, &self.prior)?;
        let surprise_bits = self.agent.vfe(obs, &self.prior, &qs) / std::f64::consts::LN_2;
        let habit = if surprise_bits > self.epsilon_bits {
            None
        } else {
            habit(self, obs, &qs)?
        };
        let (action, q_pi) = match habit {
            Some(u) => (u, None),
            None => {
                let PolicyPosterior { q_pi, .. } = self.agent.infer_policies(&qs);
                let u = self.agent.sample_action(&q_pi, rng);
                let key: Vec<usize> = qs.iter().map(|q| argmax(q)).collect();
                *self.counts.entry(key).or_default().entry(u.clone()).or_default() += 1;
                (u, Some(q_pi))
            }
        };
        self.prior = self.agent.update_empirical_prior(&action, &qs)?;
        let planned = q_pi.is_some();
        Ok((
            Tick {
                action,
                surprise_bits,
                planned,
                q_pi,
            },
            qs,
        ))
    }
}
