//! Test-time scaling (§IV, Theorem 1 "Test-Time Scaling Law", eqs.
//! "gradient_descent_equations" and "stopping_criterion").
//!
//! From `π' = π_o(·|s_t)`: `e = ln ψ - ln π'`, `ln π' <- ln π' + κ_π e`, `π' = σ(ln π')`,
//! stopping when `KL[π' || ψ] <= (1 - θ) KL[π_o || ψ] + ς` (or after `max_iters`).
//! With κ_π = 1 (the paper's step) one iteration lands on ψ; smaller steps let the
//! stopping rule bite. The closed form of Theorem 1 is `π' ∝ π_o ψ^θ`.

use crate::maths::{kl, ln, normalize_in_place, softmax_in_place};

/// Result of the iterative scaling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScalingOutcome {
    /// Iterations performed.
    pub iterations: u32,
    /// `KL[π_o || ψ]`.
    pub kl_initial: f64,
    /// `KL[π' || ψ]` at exit.
    pub kl_final: f64,
    /// The stopping target `(1 - θ) KL[π_o || ψ] + ς`.
    pub target: f64,
    /// Whether the stopping rule held at exit (false only if `max_iters` ran out).
    pub stopped: bool,
}

/// The right-hand side of eq. "stopping_criterion": `(1 - θ) KL[π_o || ψ] + ς`.
#[inline]
pub fn stopping_target(kl_initial: f64, theta: f64, varsigma: f64) -> f64 {
    (1.0 - theta) * kl_initial + varsigma
}

/// Iterative scaling (eq. "gradient_descent_equations" with step `kappa` in (0, 1]) into
/// `out` (length = actions). `trace` (if any) receives `KL[π' || ψ]` before each step and at exit.
#[allow(clippy::too_many_arguments)]
pub fn scale_iterative(
    pi_o: &[f64],
    psi: &[f64],
    theta: f64,
    kappa: f64,
    varsigma: f64,
    max_iters: u32,
    out: &mut [f64],
    mut trace: Option<&mut Vec<f64>>,
) -> ScalingOutcome {
    out.copy_from_slice(pi_o);
    let kl_initial = kl(pi_o, psi);
    let target = stopping_target(kl_initial, theta, varsigma);
    let mut current = kl_initial;
    let mut iterations = 0;
    while current > target && iterations < max_iters {
        if let Some(t) = trace.as_deref_mut() {
            t.push(current);
        }
        for (p, s) in out.iter_mut().zip(psi) {
            let lp = ln(*p);
            *p = lp + kappa * (ln(*s) - lp);
        }
        softmax_in_place(out);
        iterations += 1;
        current = kl(out, psi);
    }
    if let Some(t) = trace {
        t.push(current);
    }
    ScalingOutcome {
        iterations,
        kl_initial,
        kl_final: current,
        target,
        stopped: current <= target,
    }
}

/// Closed form of Theorem 1: `π' ∝ π_o exp(-γ θ Q_S) = π_o ψ^θ`, into `out`, with `ψ`
/// floored at [`crate::maths::LN_FLOOR`] (as `ln ψ` is everywhere).
pub fn scale_closed_form(pi_o: &[f64], psi: &[f64], theta: f64, out: &mut [f64]) {
    for ((o, p), s) in out.iter_mut().zip(pi_o).zip(psi) {
        *o = p * s.max(crate::maths::LN_FLOOR).powf(theta);
    }
    normalize_in_place(out);
}
