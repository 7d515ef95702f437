//! The habitual policy `π_o` (§II, §V-C) as an interface: what the scaled agent acts on
//! while the world is not surprising, and what scaling starts from when it is (§IV).
//!
//! Two implementations:
//!
//! - [`TableHabit`]: a table of Dirichlet counts `ν[s,u]` over the discrete states, with
//!   `π_o(u|s) = ν[s,u] / Σ_u ν[s,u]` (§V-C). The paper's habit is this table built from
//!   the Q-table, `ν = ν0 σ(Q[s,·]/T)` ([`TableHabit::from_q`]); any per-state policy
//!   gives one ([`TableHabit::from_probs`], `ν = ν0 π`).
//! - [`PolicyHabit`]: an external policy (a deep-RL network, a hand-written rule) that
//!   gives action probabilities `p_t(u)` for the observation it saw at tick `t`, with
//!   test-time learning as a correction on top of it (below).
//!
//! # Test-time learning on top of an external policy
//!
//! Reasoning's consolidation (§V-C, `ν[s,u] += lr q[s] π[u]`) adds counts `c[s,u]`,
//! starting at zero, per discrete state. The habit at tick `t` in state `s` is the
//! Dirichlet mean with the external policy as the prior of strength `ν0`:
//!
//! ```text
//! π_o(u | s, t) = (ν0 p_t(u) + c[s,u]) / (ν0 + Σ_u c[s,u])
//! ```
//!
//! So with no corrections the habit is the policy itself; after `n` consolidated
//! reasoning ticks in `s` that all chose `a`, `π_o(a|s,t) >= n lr / (ν0 + n lr)` whatever the
//! policy says; the policy keeps deciding where reasoning never went. This is the same
//! rule as the table's (there the prior `ν0 σ(Q/T)` and the corrections are summed into one
//! table). Under a belief `q`, `π_o(·|q, t) = Σ_s q[s] π_o(·|s, t)` with the same `p_t` in
//! every term: the policy saw the observation, the belief only says which state's
//! corrections apply.

use crate::error::AgentError;
use crate::learning;
use crate::maths::normalize_in_place;

/// The habitual policy `π_o` the scaled agent acts on and scales (§II, §IV, §V-C).
///
/// `t` is the tick of the current episode a question is about (0-based; the agent asks
/// about earlier ticks of the episode when it learns at its end).
pub trait Habit: std::fmt::Debug + Clone + Send {
    /// Number of discrete states.
    fn n_states(&self) -> usize;
    /// Number of actions.
    fn n_actions(&self) -> usize;
    /// A new episode starts (forget per-tick inputs).
    fn begin_episode(&mut self) {}
    /// `π_o(·|s)` at tick `t` into `out`.
    fn pi_o_state(&self, t: usize, s: usize, out: &mut [f64]);
    /// `π_o(·|q) = Σ_s q[s] π_o(·|s)` at tick `t` into `out`.
    fn pi_o_belief(&self, t: usize, q: &[f64], out: &mut [f64]);
    /// Consolidate what reasoning chose (§V-C): `ν[s,u] += lr q[s] π[u]`.
    fn learn(&mut self, q: &[f64], pi: &[f64], lr: f64);
    /// The habit's bounded memory (beyond the paper, like the gate's rows): in every state
    /// whose counts of reasoning (the counts [`Habit::learn`] added, beyond the prior)
    /// exceed `memory`, rescales them to `memory`: what reasoning chose there keeps its
    /// proportions, and how stiff the habit grows over a long deployment is bounded.
    /// `inf` keeps everything.
    fn bound_memory(&mut self, memory: f64);
}

/// Rescales each row of `counts` (`n_actions` wide) whose sum exceeds `memory` to `memory`.
fn rescale_rows(counts: &mut [f64], n_actions: usize, memory: f64) {
    if memory.is_finite() {
        for row in counts.chunks_mut(n_actions.max(1)) {
            let total: f64 = row.iter().sum();
            if total > memory {
                let k = memory / total;
                row.iter_mut().for_each(|c| *c *= k);
            }
        }
    }
}

/// A habit as a table of Dirichlet counts `ν[s,u]`, laid out `[s * n_actions + u]`
/// (§V-C): the paper's habit from the Q-table.
#[derive(Debug, Clone, PartialEq)]
pub struct TableHabit {
    n_actions: usize,
    /// The prior counts the table was built with (`ν - prior` is what reasoning added).
    prior: Vec<f64>,
    nu: Vec<f64>,
}

impl TableHabit {
    /// `ν = ν0 σ(Q[s,·]/T)` from a Q-table laid out `[s * n_actions + u]`
    /// (docs/ARCHITECTURE.md §4.8).
    pub fn from_q(q_table: &[f64], n_actions: usize, nu0: f64, temperature: f64) -> TableHabit {
        TableHabit::with_prior(n_actions, learning::nu_from_q(q_table, n_actions, nu0, temperature))
    }

    /// `ν = ν0 π` from per-state probabilities `probs[s * n_actions + u]`. Each row must be
    /// finite, non-negative and sum to 1 within 1e-6; `ν0` must be positive and finite.
    pub fn from_probs(probs: &[f64], n_actions: usize, nu0: f64) -> Result<TableHabit, AgentError> {
        check_nu0(nu0)?;
        if n_actions == 0 || probs.is_empty() || !probs.len().is_multiple_of(n_actions) {
            return Err(AgentError::SizeMismatch {
                what: "habit probabilities (a whole number of rows of n_actions)".into(),
                expected: n_actions,
                found: probs.len(),
            });
        }
        for (s, row) in probs.chunks(n_actions).enumerate() {
            check_probs(row).map_err(|why| AgentError::InvalidHabit(format!("state {s}: {why}")))?;
        }
        Ok(TableHabit::with_prior(
            n_actions,
            probs.iter().map(|p| p * nu0).collect(),
        ))
    }

    fn with_prior(n_actions: usize, prior: Vec<f64>) -> TableHabit {
        TableHabit {
            n_actions,
            nu: prior.clone(),
            prior,
        }
    }

    /// The counts `ν`, `[s * n_actions + u]`.
    pub fn nu(&self) -> &[f64] {
        &self.nu
    }
}

impl Habit for TableHabit {
    fn n_states(&self) -> usize {
        self.nu.len() / self.n_actions.max(1)
    }
    fn n_actions(&self) -> usize {
        self.n_actions
    }
    fn pi_o_state(&self, _t: usize, s: usize, out: &mut [f64]) {
        learning::pi_o_state(&self.nu, self.n_actions, s, out);
    }
    fn pi_o_belief(&self, _t: usize, q: &[f64], out: &mut [f64]) {
        learning::pi_o_belief(&self.nu, self.n_actions, q, out);
    }
    fn learn(&mut self, q: &[f64], pi: &[f64], lr: f64) {
        learning::update_nu(&mut self.nu, self.n_actions, q, pi, lr);
    }
    fn bound_memory(&mut self, memory: f64) {
        let na = self.n_actions.max(1);
        for (nu, prior) in self.nu.chunks_mut(na).zip(self.prior.chunks(na)) {
            let learned: f64 = nu.iter().zip(prior).map(|(n, p)| n - p).sum();
            if learned > memory {
                let k = memory / learned;
                nu.iter_mut().zip(prior).for_each(|(n, p)| *n = p + k * (*n - p));
            }
        }
    }
}

/// An external policy as the habit: its probabilities at each tick's observation, with
/// the corrections test-time learning adds per state (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct PolicyHabit {
    n_states: usize,
    n_actions: usize,
    nu0: f64,
    /// Corrections `c[s,u]`, `[s * n_actions + u]`.
    corrections: Vec<f64>,
    /// `p_t(u)` of this episode's ticks, `[t * n_actions + u]`.
    probs: Vec<f64>,
}

impl PolicyHabit {
    /// A habit over `n_states` states and `n_actions` actions whose policy counts as `ν0`
    /// observations (the prior strength of §V-C; the scaled agent's `nu0`).
    pub fn new(n_states: usize, n_actions: usize, nu0: f64) -> Result<PolicyHabit, AgentError> {
        check_nu0(nu0)?;
        if n_states == 0 || n_actions == 0 {
            return Err(AgentError::InvalidHabit(format!(
                "{n_states} states and {n_actions} actions: need at least one of each"
            )));
        }
        Ok(PolicyHabit {
            n_states,
            n_actions,
            nu0,
            corrections: vec![0.0; n_states * n_actions],
            probs: Vec::with_capacity(256 * n_actions),
        })
    }

    /// Records the policy's probabilities for the next tick (tick `ticks()` of the
    /// episode). They must be `n_actions` finite non-negative numbers summing to 1 within
    /// 1e-6; they are used as given.
    pub fn push(&mut self, probs: &[f64]) -> Result<(), AgentError> {
        if probs.len() != self.n_actions {
            return Err(AgentError::SizeMismatch {
                what: "habit probabilities (one per action)".into(),
                expected: self.n_actions,
                found: probs.len(),
            });
        }
        check_probs(probs).map_err(AgentError::InvalidHabit)?;
        self.probs.extend_from_slice(probs);
        Ok(())
    }

    /// Ticks of this episode with probabilities recorded.
    pub fn ticks(&self) -> usize {
        self.probs.len() / self.n_actions
    }

    /// The corrections `c[s,u]` test-time learning has added, `[s * n_actions + u]`.
    pub fn corrections(&self) -> &[f64] {
        &self.corrections
    }

    /// `p_t`; uniform for a tick without recorded probabilities.
    fn p(&self, t: usize) -> std::borrow::Cow<'_, [f64]> {
        match self.probs.get(t * self.n_actions..(t + 1) * self.n_actions) {
            Some(p) => p.into(),
            None => vec![1.0 / self.n_actions as f64; self.n_actions].into(),
        }
    }
}

impl Habit for PolicyHabit {
    fn n_states(&self) -> usize {
        self.n_states
    }
    fn n_actions(&self) -> usize {
        self.n_actions
    }
    fn begin_episode(&mut self) {
        self.probs.clear();
    }
    fn pi_o_state(&self, t: usize, s: usize, out: &mut [f64]) {
        let p = self.p(t);
        let c = &self.corrections[s * self.n_actions..(s + 1) * self.n_actions];
        for ((o, p), c) in out.iter_mut().zip(p.iter()).zip(c) {
            *o = self.nu0 * p + c;
        }
        normalize_in_place(out);
    }
    fn pi_o_belief(&self, t: usize, q: &[f64], out: &mut [f64]) {
        let p = self.p(t);
        out.iter_mut().for_each(|v| *v = 0.0);
        let mut row = vec![0.0; self.n_actions];
        for (s, w) in q.iter().enumerate() {
            if *w != 0.0 {
                let c = &self.corrections[s * self.n_actions..(s + 1) * self.n_actions];
                for ((r, p), c) in row.iter_mut().zip(p.iter()).zip(c) {
                    *r = self.nu0 * p + c;
                }
                let z: f64 = row.iter().sum();
                for (o, r) in out.iter_mut().zip(&row) {
                    *o += w * r / z;
                }
            }
        }
    }
    fn learn(&mut self, q: &[f64], pi: &[f64], lr: f64) {
        learning::update_nu(&mut self.corrections, self.n_actions, q, pi, lr);
    }
    fn bound_memory(&mut self, memory: f64) {
        rescale_rows(&mut self.corrections, self.n_actions, memory);
    }
}

fn check_nu0(nu0: f64) -> Result<(), AgentError> {
    if nu0 > 0.0 && nu0.is_finite() {
        Ok(())
    } else {
        Err(AgentError::InvalidHabit(format!(
            "prior strength nu0 = {nu0}: must be positive and finite"
        )))
    }
}

/// Finite, non-negative, summing to 1 within 1e-6.
fn check_probs(p: &[f64]) -> Result<(), String> {
    if let Some((u, x)) = p.iter().enumerate().find(|(_, x)| !(x.is_finite() && **x >= 0.0)) {
        return Err(format!(
            "probability of action {u} is {x}; probabilities must be finite and >= 0"
        ));
    }
    let z: f64 = p.iter().sum();
    if (z - 1.0).abs() > 1e-6 {
        return Err(format!(
            "probabilities {p:?} sum to {z}; they must sum to 1 (give a softmax, not logits)"
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_from_probs_is_the_q_table_habit_bit_for_bit() {
        // σ(Q/T) given as probabilities, times ν0, is the table nu_from_q builds.
        let q = [1.0, 2.5, -0.5, 0.3, 0.3, 0.9];
        let from_q = TableHabit::from_q(&q, 3, 10.0, 2.0);
        let mut probs = q.map(|x| x / 2.0);
        probs.chunks_mut(3).for_each(crate::maths::softmax_in_place);
        let from_p = TableHabit::from_probs(&probs, 3, 10.0).unwrap();
        assert_eq!(from_q, from_p);
    }

    #[test]
    fn policy_habit_is_the_policy_until_reasoning_corrects_it() {
        let mut h = PolicyHabit::new(2, 3, 10.0).unwrap();
        h.push(&[0.2, 0.7, 0.1]).unwrap();
        let mut out = [0.0; 3];
        h.pi_o_state(0, 1, &mut out);
        for (o, p) in out.iter().zip([0.2, 0.7, 0.1]) {
            assert!((o - p).abs() < 1e-15);
        }
        // Twenty consolidated ticks of "slow down" in state 1 (lr 1): (10·0.1 + 20) / 30.
        for _ in 0..20 {
            h.learn(&[0.0, 1.0], &[0.0, 0.0, 1.0], 1.0);
        }
        h.pi_o_state(0, 1, &mut out);
        assert!((out[2] - 21.0 / 30.0).abs() < 1e-12, "{out:?}");
        // State 0 was never corrected: still the policy.
        h.pi_o_state(0, 0, &mut out);
        assert!((out[1] - 0.7).abs() < 1e-15);
        // A belief mixes the states' habits.
        h.pi_o_belief(0, &[0.5, 0.5], &mut out);
        assert!((out[2] - 0.5 * (0.1 + 21.0 / 30.0)).abs() < 1e-12);
    }

    #[test]
    fn bounded_memory_by_hand() {
        // Prior ν0 = 10 over (0.2, 0.7, 0.1) in both states.
        let probs = [0.2, 0.7, 0.1, 0.2, 0.7, 0.1];
        let mut table = TableHabit::from_probs(&probs, 3, 10.0).unwrap();
        let mut policy = PolicyHabit::new(2, 3, 10.0).unwrap();
        policy.push(&[0.2, 0.7, 0.1]).unwrap();
        // 30 ticks of reasoning in state 1: 20 chose "slow down", 10 "maintain".
        for k in 0..30 {
            let pi = if k < 20 { [0.0, 0.0, 1.0] } else { [1.0, 0.0, 0.0] };
            table.learn(&[0.0, 1.0], &pi, 1.0);
            policy.learn(&[0.0, 1.0], &pi, 1.0);
        }
        let mut unbounded = table.clone();
        unbounded.bound_memory(f64::INFINITY);
        assert_eq!(unbounded, table, "inf keeps everything");
        // Memory 15: the 30 counts become 10 and 5, the prior stays: (2 + 5, 7, 1 + 10) / 25.
        table.bound_memory(15.0);
        policy.bound_memory(15.0);
        let mut out = [0.0; 3];
        for h in [&table as &dyn HabitView, &policy] {
            h.state(1, &mut out);
            for (o, want) in out.iter().zip([7.0 / 25.0, 7.0 / 25.0, 11.0 / 25.0]) {
                assert!((o - want).abs() < 1e-12, "{out:?}");
            }
            // State 0 was never reasoned in: the prior.
            h.state(0, &mut out);
            assert!((out[1] - 0.7).abs() < 1e-12);
        }
        assert!((table.nu()[3..].iter().sum::<f64>() - 25.0).abs() < 1e-12);
        assert!((policy.corrections()[3..].iter().sum::<f64>() - 15.0).abs() < 1e-12);
        // Below the memory nothing changes.
        let before = table.clone();
        table.bound_memory(15.0);
        assert_eq!(before, table);
    }

    /// `π_o(·|s)` at tick 0, for either habit.
    trait HabitView {
        fn state(&self, s: usize, out: &mut [f64]);
    }
    impl<H: Habit> HabitView for H {
        fn state(&self, s: usize, out: &mut [f64]) {
            self.pi_o_state(0, s, out);
        }
    }

    #[test]
    fn bad_probabilities_are_refused_with_the_reason() {
        let mut h = PolicyHabit::new(2, 3, 10.0).unwrap();
        let e = h.push(&[0.5, 0.6, 0.1]).unwrap_err().to_string();
        assert!(e.contains("sum to") && e.contains("softmax"), "{e}");
        let e = h.push(&[f64::NAN, 0.5, 0.5]).unwrap_err().to_string();
        assert!(e.contains("action 0"), "{e}");
        assert!(h.push(&[0.5, 0.5]).is_err());
        assert!(PolicyHabit::new(2, 3, 0.0).is_err());
        assert!(TableHabit::from_probs(&[0.5, 0.5, 0.0, 1.0], 3, 10.0).is_err());
        assert_eq!(h.ticks(), 0);
    }
}
