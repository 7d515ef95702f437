//! Perception as inference (§III): windowed mean-field variational message passing in
//! its prediction-error (gradient) form, eq. "iterative", and the free energy `F`
//! (Definition "VFE", Lemma 1).
//!
//! Window slots `τ = 0..W-1` hold `q_τ`; slot 0 receives the prior `ŝ` (the prediction
//! from before the window, or `D`), slot `τ > 0` the forward message through
//! `B[a_{τ-1}]`, slot `τ < W-1` the backward message through `B[a_τ]`, every slot its
//! observation. For each slot, in order (coordinate updates):
//! `v_τ = ln B[a_{τ-1}] q_{τ-1} + (ln B[a_τ])^T q_{τ+1} + (ln A)^T o_τ`
//! (eq. "message passing"), prediction error `ε_τ = v_τ - ln q_τ`,
//! `ln q_τ <- ln q_τ + κ ε_τ`, `q_τ = σ(ln q_τ)`, until `max |Δq| < tol`.
//!
//! With κ = 1 each coordinate update is the exact minimiser of `F` in `q_τ`, so `F`
//! never increases; with κ in (0, 1), `q_τ` moves along the exponential-family
//! geodesic toward that minimiser, along which `KL[q || q*]` (hence `F`) is
//! non-increasing too — both are property-tested.

use crate::maths::{axpy_columns, dot_columns, lane_sum, ln_into, softmax_in_place};
use crate::model::GenerativeModel;
use crate::transition::LogBScratch;

/// Result of a VMP run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VmpOutcome {
    /// Sweeps performed.
    pub iterations: u32,
    /// Free energy at exit (nats).
    pub free_energy: f64,
    /// Whether `max |Δq| < tol` was reached.
    pub converged: bool,
}

/// Scratch buffers for [`vmp`] (preallocate once per agent).
#[derive(Debug, Clone, Default)]
pub struct VmpWorkspace {
    v: Vec<f64>,
    /// `(ln B)^T q` of one message.
    acc: Vec<f64>,
    /// `ln ŝ`, shared by slot 0's message and `F`.
    ln_s_hat: Vec<f64>,
    /// Marginals and partial messages of the factored `ln B`.
    scratch: LogBScratch,
}

/// The message `v_τ` of slot `tau` (eq. "message passing") into `v`; `acc` and `scratch`
/// are scratch. Through the factored `ln B` when the model has it (`FactoredLogB`).
#[allow(clippy::too_many_arguments)]
fn message_into(
    gm: &GenerativeModel,
    ln_s_hat: &[f64],
    obs: &[usize],
    actions: &[usize],
    qs: &[Vec<f64>],
    tau: usize,
    v: &mut [f64],
    acc: &mut [f64],
    scratch: &mut LogBScratch,
) {
    let n = gm.n_states();
    let last = obs.len() - 1;
    // Message 1: forward.
    if tau == 0 {
        v.copy_from_slice(ln_s_hat);
    } else {
        match &gm.log_factored {
            Some(lb) => lb.forward(actions[tau - 1], &qs[tau - 1], v, scratch),
            None => axpy_columns(gm.ln_b[actions[tau - 1]].as_slice(), n, &qs[tau - 1], v),
        }
    }
    // Message 2: backward, (ln B[a_τ])^T q_{τ+1}.
    if tau < last {
        match &gm.log_factored {
            Some(lb) => lb.backward(actions[tau], &qs[tau + 1], acc, scratch),
            None => dot_columns(gm.ln_b_t[actions[tau]].as_slice(), n, &qs[tau + 1], acc),
        }
        for (vi, a) in v.iter_mut().zip(acc.iter()) {
            *vi += a;
        }
    }
    // Message 3: observation, (ln A)^T o_τ = row o_τ of ln A.
    let o = obs[tau];
    for (s, vi) in v.iter_mut().enumerate() {
        *vi += gm.ln_a[(o, s)];
    }
}

/// Free energy of a window (Definition "VFE"; docs/ARCHITECTURE.md §4.5):
/// `F = Σ_τ q_τ·(ln q_τ - (ln A)^T o_τ) - q_0·ln ŝ - Σ_{τ>0} q_τ^T (ln B[a_{τ-1}]) q_{τ-1}`.
/// `F >= -ln p(o_window)` (Lemma 1), with equality at the exact posterior for W = 1.
pub fn free_energy(gm: &GenerativeModel, s_hat: &[f64], obs: &[usize], actions: &[usize], qs: &[Vec<f64>]) -> f64 {
    let mut ln_s_hat = vec![0.0; s_hat.len()];
    ln_into(s_hat, &mut ln_s_hat);
    let mut acc = vec![0.0; gm.n_states()];
    free_energy_with(gm, &ln_s_hat, obs, actions, qs, &mut acc, &mut LogBScratch::default())
}

/// [`free_energy`] given `ln ŝ`, with scratch `acc` (length n_states) and `scratch`.
fn free_energy_with(
    gm: &GenerativeModel,
    ln_s_hat: &[f64],
    obs: &[usize],
    actions: &[usize],
    qs: &[Vec<f64>],
    acc: &mut [f64],
    scratch: &mut LogBScratch,
) -> f64 {
    let n = gm.n_states();
    let mut f = 0.0;
    for (tau, q) in qs.iter().enumerate().take(obs.len()) {
        let o = obs[tau];
        // Σ_s q (ln q - ln A[o, s]); zero entries add exactly 0 (the floored logs are finite).
        ln_into(q, acc);
        let ln_a = gm.ln_a.row(o);
        f += lane_sum(n, |s| q[s] * (acc[s] - ln_a[s]));
        if tau == 0 {
            f -= q
                .iter()
                .zip(ln_s_hat)
                .map(|(p, l)| if *p > 0.0 { p * l } else { 0.0 })
                .sum::<f64>();
        } else if let Some(lb) = &gm.log_factored {
            f -= lb.quadratic(actions[tau - 1], q, &qs[tau - 1], scratch);
        } else {
            // acc[j] = (column j of ln B[a_{τ-1}]) · q_τ.
            dot_columns(gm.ln_b_t[actions[tau - 1]].as_slice(), n, q, acc);
            for (qj, a) in qs[tau - 1].iter().zip(acc.iter()) {
                if *qj != 0.0 {
                    f -= qj * a;
                }
            }
        }
    }
    f
}

/// Windowed VMP (§III eqs. "message passing", "iterative"). `obs` has one entry per slot,
/// `actions[τ]` is the action between slots `τ` and `τ+1` (`obs.len() - 1` entries),
/// `qs` holds the initial beliefs (e.g. the filtered ones) and receives the posteriors.
/// `on_sweep` (if any) receives `F` after every sweep (used by the monotonicity tests).
#[allow(clippy::too_many_arguments)]
pub fn vmp(
    gm: &GenerativeModel,
    s_hat: &[f64],
    obs: &[usize],
    actions: &[usize],
    qs: &mut [Vec<f64>],
    kappa: f64,
    tol: f64,
    max_iters: u32,
    ws: &mut VmpWorkspace,
    mut on_sweep: Option<&mut dyn FnMut(f64)>,
) -> VmpOutcome {
    let n = gm.n_states();
    ws.v.resize(n, 0.0);
    ws.acc.resize(n, 0.0);
    ws.ln_s_hat.resize(n, 0.0);
    ln_into(s_hat, &mut ws.ln_s_hat);
    let w = obs.len();
    let mut iterations = 0;
    let mut converged = false;
    while iterations < max_iters {
        iterations += 1;
        let mut change: f64 = 0.0;
        for tau in 0..w {
            message_into(
                gm,
                &ws.ln_s_hat,
                obs,
                actions,
                qs,
                tau,
                &mut ws.v,
                &mut ws.acc,
                &mut ws.scratch,
            );
            let q = &mut qs[tau];
            // ε = v - ln q ; ln q <- ln q + κ ε ; q = σ(ln q). Store the new logits in v.
            // `ln q` by the table logarithm (`maths::ln_fast`); the softmax keeps `std`'s `exp`
            // (a vectorised `exp` here changed which action wins in the planner's exact ties,
            // see BENCHMARKS.md).
            ln_into(q, &mut ws.acc);
            for (vi, lq) in ws.v.iter_mut().zip(ws.acc.iter()) {
                *vi = lq + kappa * (*vi - lq);
            }
            softmax_in_place(&mut ws.v);
            for (qi, vi) in q.iter_mut().zip(&ws.v) {
                change = change.max((*qi - *vi).abs());
                *qi = *vi;
            }
        }
        if let Some(cb) = on_sweep.as_deref_mut() {
            cb(free_energy_with(
                gm,
                &ws.ln_s_hat,
                obs,
                actions,
                qs,
                &mut ws.acc,
                &mut ws.scratch,
            ));
        }
        if change < tol {
            converged = true;
            break;
        }
    }
    VmpOutcome {
        iterations,
        free_energy: free_energy_with(gm, &ws.ln_s_hat, obs, actions, qs, &mut ws.acc, &mut ws.scratch),
        converged,
    }
}

/// Exact `-ln p(o_window | ŝ, actions)` by the forward algorithm (the oracle of Lemma 1).
pub fn neg_log_evidence(gm: &GenerativeModel, s_hat: &[f64], obs: &[usize], actions: &[usize]) -> f64 {
    let n = gm.n_states();
    let mut pred = s_hat.to_vec();
    let mut q = vec![0.0; n];
    let mut total = 0.0;
    for (tau, o) in obs.iter().enumerate() {
        if tau > 0 {
            crate::maths::axpy_columns(gm.b[actions[tau - 1]].as_slice(), n, &q, &mut pred);
        }
        let z = crate::surprise::bayes_step(gm, *o, &pred, &mut q);
        total -= z.ln();
    }
    total
}
