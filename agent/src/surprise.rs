//! Surprise and the reasoning trigger (§II, Lemma 1; §IV normalised surprise θ).
//!
//! After action `a_{t-1}` and observation `o_t`:
//! `ŝ = B[a_{t-1}] q_{t-1}` (ŝ = D at t = 1), `S_t = -ln Σ_s A[o_t,s] ŝ[s]`,
//! `θ_t = 1 - exp(-Ω S_t)`, and reasoning is engaged iff `θ_t > ε`.

use crate::model::GenerativeModel;

/// State prediction `ŝ_t = B[a_{t-1}] q_{t-1}`, or `D` when `prev` is `None` (§II; docs/ARCHITECTURE.md §4.4).
pub fn predict_into(gm: &GenerativeModel, prev: Option<(&[f64], usize)>, out: &mut [f64]) {
    match prev {
        None => out.copy_from_slice(&gm.d),
        Some((q, u)) => crate::maths::axpy_columns(gm.b[u].as_slice(), gm.n_states(), q, out),
    }
}

/// Evidence `p(o_t | ŝ) = Σ_s A[o_t,s] ŝ[s]` (the argument of the log in Lemma 1).
pub fn evidence(gm: &GenerativeModel, o: usize, s_hat: &[f64]) -> f64 {
    if gm.a_identity {
        return s_hat[o];
    }
    s_hat.iter().enumerate().map(|(s, p)| gm.a[(o, s)] * p).sum()
}

/// Surprise `S_t = -ln Σ_s A[o_t,s] ŝ[s]` in nats (§II, Lemma 1), floored log.
pub fn surprise(gm: &GenerativeModel, o: usize, s_hat: &[f64]) -> f64 {
    -crate::maths::ln(evidence(gm, o, s_hat))
}

/// Normalised surprise `θ = 1 - exp(-Ω S)` in [0, 1) (§IV, eq. before "stopping_criterion").
#[inline]
pub fn theta(surprise: f64, omega: f64) -> f64 {
    1.0 - (-omega * surprise).exp()
}

/// One exact Bayes filtering step `q_t ∝ A[o_t,:] ∘ ŝ_t` (the feed-forward perception of
/// §II's footnote; equals VMP with window 1). Returns the evidence `Σ_s A[o_t,s] ŝ[s]`.
/// If the evidence is 0, `q_t ∝ A[o_t,:]` (the observation alone).
pub fn bayes_step(gm: &GenerativeModel, o: usize, s_hat: &[f64], out: &mut [f64]) -> f64 {
    if gm.a_identity {
        out.iter_mut().for_each(|v| *v = 0.0);
        out[o] = 1.0;
        return s_hat[o];
    }
    let mut z = 0.0;
    for (s, v) in out.iter_mut().enumerate() {
        *v = gm.a[(o, s)] * s_hat[s];
        z += *v;
    }
    if z > 0.0 {
        out.iter_mut().for_each(|v| *v /= z);
    } else {
        for (s, v) in out.iter_mut().enumerate() {
            *v = gm.a[(o, s)];
        }
        crate::maths::normalize_in_place(out);
    }
    z
}
