//! Action selection as pymdp's `Agent.sample_action`: `Full` takes the policy (argmax, or
//! a sample from `σ(α ln q_π)`) and returns its first multi-action; `Marginal` sums `q_π`
//! onto each factor's first action (`control.get_marginals`) and takes each factor's
//! argmax (or sample). Ties go to the lowest index, as `jnp.argmax`.

use super::infer::log_stable;
use super::policies::Policies;
use crate::maths::{argmax, softmax_in_place};
use rand::RngExt;

/// Argmax or sample.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Selection {
    /// The most probable (pymdp's default).
    Deterministic,
    /// A sample from `σ(alpha · ln p)`.
    Stochastic {
        /// Action precision (pymdp's `alpha`, default 1).
        alpha: f64,
    },
}

/// Over policies or over each factor's action marginal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sampling {
    /// Pick a policy, act its first step (pymdp's default).
    #[default]
    Full,
    /// Pick each factor's first action from its marginal.
    Marginal,
}

/// `p(u_f)` of the first step for each factor: `Σ_π q_π [π_0f = u]`.
pub fn marginals(q_pi: &[f64], policies: &Policies, num_controls: &[usize]) -> Vec<Vec<f64>> {
    let mut m: Vec<Vec<f64>> = num_controls.iter().map(|&n| vec![0.0; n]).collect();
    for (p, q) in q_pi.iter().enumerate() {
        for (f, &u) in policies.step(p, 0).iter().enumerate() {
            m[f][u] += q;
        }
    }
    m
}

fn pick(p: &[f64], selection: Selection, rng: &mut impl RngExt) -> usize {
    match selection {
        Selection::Deterministic => argmax(p),
        Selection::Stochastic { alpha } => {
            let mut w: Vec<f64> = p.iter().map(|x| alpha * log_stable(*x)).collect();
            softmax_in_place(&mut w);
            let r: f64 = rng.random();
            let mut acc = 0.0;
            for (i, wi) in w.iter().enumerate() {
                acc += wi;
                if r < acc {
                    return i;
                }
            }
            w.len() - 1
        }
    }
}

/// The multi-action to take (one action per factor).
pub fn select(
    q_pi: &[f64],
    policies: &Policies,
    num_controls: &[usize],
    selection: Selection,
    sampling: Sampling,
    rng: &mut impl RngExt,
) -> Vec<usize> {
    match sampling {
        Sampling::Full => policies.step(pick(q_pi, selection, rng), 0).to_vec(),
        Sampling::Marginal => marginals(q_pi, policies, num_controls)
            .iter()
            .map(|m| pick(m, selection, rng))
            .collect(),
    }
}
