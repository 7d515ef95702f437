//! State inference as pymdp's `fpi` (`algos.run_factorized_fpi`): the posterior over the
//! current state factors from one observation per modality and the empirical prior.
//!
//! * One factor: one exact pass, `q = σ(Σ_m ln A_m[o_m, :] + ln prior)` (Bayes' rule).
//! * Several: the mean-field fixed point, from `ln q_f = 0`, `num_iter` simultaneous
//!   updates `ln q_f = Σ_m E_{q_{\f}}[ln A_m[o_m, ...]] + ln prior_f` (pymdp: 16); a
//!   modality on one factor adds the same `ln A_m[o_m, :]` every pass, computed once.
//!
//! Logs are pymdp's `log_stable`, `ln(max(x, ε))` with ε = `f64::EPSILON`. The paper's
//! agent perceives with VMP over a window instead ([`crate::perception`], §III); on one
//! step of a single-factor model both give the exact posterior.

use super::model::Model;
use super::tensor::{Tensor, contract};
use crate::maths::softmax_in_place;

/// pymdp's `MINVAL` (`jnp.finfo(float).eps`): the floor under every logarithm.
pub const MINVAL: f64 = f64::EPSILON;

/// `ln(max(x, MINVAL))` (pymdp's `log_stable`).
#[inline]
pub fn log_stable(x: f64) -> f64 {
    x.max(MINVAL).ln()
}

/// `x ln x` with `0 ln 0 = 0` (pymdp's `stable_xlogx`), with [`crate::maths::ln_fast`]
/// (within 2 ulp of `ln`).
#[inline]
pub fn xlogx(x: f64) -> f64 {
    if x == 0.0 {
        0.0
    } else {
        x * crate::maths::ln_fast(x.max(MINVAL))
    }
}

/// `ln A_m[o_m, ...]` per modality: a tensor over `A_dependencies[m]`.
pub fn log_likelihoods(model: &Model, obs: &[usize]) -> Vec<Tensor> {
    model
        .a
        .iter()
        .zip(obs)
        .map(|(a, &o)| {
            let mut t = a.slice_first(o);
            t.data.iter_mut().for_each(|v| *v = log_stable(*v));
            t
        })
        .collect()
}

/// The posterior over each factor given `obs` (one index per modality) and `prior`.
pub fn fpi(model: &Model, obs: &[usize], prior: &[Vec<f64>], num_iter: usize) -> Vec<Vec<f64>> {
    let ll = log_likelihoods(model, obs);
    if model.num_factors() == 1 {
        let mut log_q: Vec<f64> = prior[0].iter().map(|p| log_stable(*p)).collect();
        let mut total = vec![0.0; log_q.len()];
        for l in &ll {
            total.iter_mut().zip(&l.data).for_each(|(t, v)| *t += v);
        }
        log_q.iter_mut().zip(&total).for_each(|(q, t)| *q += t);
        softmax_in_place(&mut log_q);
        return vec![log_q];
    }
    let log_prior: Vec<Vec<f64>> = prior
        .iter()
        .map(|p| p.iter().map(|x| log_stable(*x)).collect())
        .collect();
    // Modalities on one factor add a constant to it; the others are marginalised each pass.
    let mut constant: Vec<Vec<f64>> = log_prior.clone();
    let mut joint = Vec::new();
    for (l, deps) in ll.iter().zip(&model.a_deps) {
        if let [f] = deps[..] {
            constant[f].iter_mut().zip(&l.data).for_each(|(c, v)| *c += v);
        } else {
            joint.push((l, deps.as_slice()));
        }
    }
    let mut log_q: Vec<Vec<f64>> = prior.iter().map(|p| vec![0.0; p.len()]).collect();
    let mut q = log_q.clone();
    let mut idx = Vec::new();
    for _ in 0..num_iter {
        for (qf, lf) in q.iter_mut().zip(&log_q) {
            qf.copy_from_slice(lf);
            softmax_in_place(qf);
        }
        for (lf, cf) in log_q.iter_mut().zip(&constant) {
            lf.copy_from_slice(cf);
        }
        for (l, deps) in &joint {
            // Odometer over the joint of `deps` (last fastest, C order).
            idx.clear();
            idx.resize(deps.len(), 0);
            for &v in &l.data {
                for (k, &f) in deps.iter().enumerate() {
                    let others: f64 = deps
                        .iter()
                        .zip(&idx)
                        .enumerate()
                        .filter(|(k2, _)| *k2 != k)
                        .map(|(_, (&d, &i))| q[d][i])
                        .product();
                    log_q[f][idx[k]] += v * others;
                }
                for k in (0..deps.len()).rev() {
                    idx[k] += 1;
                    if idx[k] < l.shape[k] {
                        break;
                    }
                    idx[k] = 0;
                }
            }
        }
    }
    log_q
        .into_iter()
        .map(|mut l| {
            softmax_in_place(&mut l);
            l
        })
        .collect()
}

/// `s' = B[f][..., u_f] · q` per factor, over its parents' marginals (pymdp's
/// `compute_expected_state`, mean field for several parents).
pub fn expected_state(model: &Model, qs: &[Vec<f64>], u: &[usize]) -> Vec<Vec<f64>> {
    model
        .b_deps
        .iter()
        .enumerate()
        .map(|(f, deps)| {
            let mut xs: Vec<&[f64]> = vec![&[]];
            xs.extend(deps.iter().map(|&d| qs[d].as_slice()));
            contract(&model.b[f].slice_last(u[f]), &xs, Some(0))
        })
        .collect()
}

/// `o_m = A_m · q` per modality (pymdp's `compute_expected_obs`).
pub fn expected_obs(model: &Model, qs: &[Vec<f64>]) -> Vec<Vec<f64>> {
    model
        .a
        .iter()
        .zip(&model.a_deps)
        .map(|(a, deps)| {
            let mut xs: Vec<&[f64]> = vec![&[]];
            xs.extend(deps.iter().map(|&d| qs[d].as_slice()));
            contract(a, &xs, Some(0))
        })
        .collect()
}

/// The variational free energy of `qs` at one step, in nats (pymdp's `calc_vfe` for one
/// time slice): `Σ_f KL[q_f ‖ prior_f] − Σ_m E_q[ln A_m[o_m, ...]]`. For the exact
/// single-factor posterior it equals the surprise `−ln p(o)` under the prediction.
pub fn vfe(model: &Model, obs: &[usize], prior: &[Vec<f64>], qs: &[Vec<f64>]) -> f64 {
    let mut f = 0.0;
    for (q, p) in qs.iter().zip(prior) {
        for (qi, pi) in q.iter().zip(p) {
            f += xlogx(*qi) - qi * log_stable(*pi);
        }
    }
    for (ll, deps) in log_likelihoods(model, obs).iter().zip(&model.a_deps) {
        let xs: Vec<&[f64]> = deps.iter().map(|&d| qs[d].as_slice()).collect();
        f -= contract(ll, &xs, None)[0];
    }
    f
}
