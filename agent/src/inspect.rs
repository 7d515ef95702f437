//! `unforeseen inspect --model FILE.json`: exact filtering, free energy, surprise and
//! EFE planning on a single-factor model, for cross-checking against pymdp. Models with
//! several factors and modalities go to [`crate::aif::inspect`] ([`inspect_json`]).
//!
//! Input: `{"A": A[o][s], "B": B[u][s_next][s_prev], "C": log-preferences, "D": p(s_1),
//! "obs": [o_1..o_t], "actions": [u_1..u_{t-1}], "policy_len": H, "gamma": γ}`.
//! `C` is normalised with log_softmax before use, so `G` is the paper's G (lower is better).

use crate::error::InspectError;
use crate::maths::log_softmax;
use crate::model::GenerativeModel;
use crate::perception::free_energy;
use crate::planning::{EfeTree, policies};
use crate::surprise::{bayes_step, predict_into, surprise};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

/// The model JSON of `inspect`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[allow(non_snake_case)]
pub struct InspectModel {
    /// `A[o][s] = p(o|s)`.
    pub A: Vec<Vec<f64>>,
    /// `B[u][s_next][s_prev]`.
    pub B: Vec<Vec<Vec<f64>>>,
    /// Log preferences over observations (normalised with log_softmax before use).
    pub C: Vec<f64>,
    /// `p(s_1)`.
    pub D: Vec<f64>,
    /// Observations `o_1..o_t` (at least one).
    pub obs: Vec<usize>,
    /// Actions `u_1..u_{t-1}`.
    pub actions: Vec<usize>,
    /// Policy length H.
    pub policy_len: usize,
    /// Policy precision γ.
    pub gamma: f64,
}

impl InspectModel {
    /// A generative model in this layout (e.g. a trained agent's planning model, for
    /// `unforeseen export-model` and the pymdp comparison), with the observations,
    /// actions, horizon and precision to evaluate. `C` is written as the model's
    /// normalised log preferences, which `log_softmax` leaves unchanged.
    pub fn from_generative(
        gm: &GenerativeModel,
        obs: Vec<usize>,
        actions: Vec<usize>,
        policy_len: usize,
        gamma: f64,
    ) -> InspectModel {
        let rows = |m: &DMatrix<f64>| (0..m.nrows()).map(|i| m.row(i).iter().copied().collect()).collect();
        InspectModel {
            A: rows(&gm.a),
            B: gm.b.iter().map(rows).collect(),
            C: gm.c.clone(),
            D: gm.d.clone(),
            obs,
            actions,
            policy_len,
            gamma,
        }
    }
}

/// The report of `inspect`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[allow(non_snake_case)]
pub struct InspectReport {
    /// Posterior over `s_t` by exact filtering.
    pub qs: Vec<f64>,
    /// Free energy at step t (= `-ln p(o_t | o_1..t-1)` at the exact posterior).
    pub F: f64,
    /// Surprise `S_t` (nats).
    pub surprise: f64,
    /// All policies of length H, lexicographic.
    pub policies: Vec<Vec<usize>>,
    /// EFE per policy (lower is better).
    pub G: Vec<f64>,
    /// `σ(-γ G)`.
    pub q_pi: Vec<f64>,
    /// First-action marginal ψ.
    pub psi: Vec<f64>,
}

fn invalid(msg: String) -> InspectError {
    InspectError::Invalid(msg)
}

fn check_dist(name: &str, v: &[f64]) -> Result<(), InspectError> {
    if let Some((i, x)) = v
        .iter()
        .enumerate()
        .find(|(_, x)| x.is_nan() || **x < 0.0 || !x.is_finite())
    {
        return Err(invalid(format!(
            "{name} entry {i} is {x} (must be a finite probability >= 0)"
        )));
    }
    let z: f64 = v.iter().sum();
    if (z - 1.0).abs() > 1e-9 {
        return Err(invalid(format!("{name} sums to {z} (must be 1 within 1e-9)")));
    }
    Ok(())
}

/// Validate the model and build the [`GenerativeModel`] (errors name the field).
pub fn validate(m: &InspectModel) -> Result<GenerativeModel, InspectError> {
    let no = m.A.len();
    if no == 0 {
        return Err(invalid("A has no rows (observations)".into()));
    }
    let ns = m.A[0].len();
    if ns == 0 {
        return Err(invalid("A[0] has no columns (states)".into()));
    }
    for (o, row) in m.A.iter().enumerate() {
        if row.len() != ns {
            return Err(invalid(format!(
                "A[{o}] has {} entries (expected {ns} states)",
                row.len()
            )));
        }
    }
    let a = DMatrix::from_fn(no, ns, |o, s| m.A[o][s]);
    for s in 0..ns {
        let col: Vec<f64> = a.column(s).iter().copied().collect();
        check_dist(&format!("A column {s}"), &col)?;
    }
    if m.B.is_empty() {
        return Err(invalid("B has no actions".into()));
    }
    let mut b = Vec::with_capacity(m.B.len());
    for (u, bu) in m.B.iter().enumerate() {
        if bu.len() != ns || bu.iter().any(|r| r.len() != ns) {
            return Err(invalid(format!("B[{u}] must be {ns}x{ns} (states x states)")));
        }
        let mat = DMatrix::from_fn(ns, ns, |i, j| bu[i][j]);
        for s in 0..ns {
            let col: Vec<f64> = mat.column(s).iter().copied().collect();
            check_dist(&format!("B[{u}] column {s}"), &col)?;
        }
        b.push(mat);
    }
    if m.C.len() != no {
        return Err(invalid(format!(
            "C has {} entries (expected {no} observations)",
            m.C.len()
        )));
    }
    if m.C.iter().any(|c| !c.is_finite()) {
        return Err(invalid("C has a non-finite entry".into()));
    }
    if m.D.len() != ns {
        return Err(invalid(format!("D has {} entries (expected {ns} states)", m.D.len())));
    }
    check_dist("D", &m.D)?;
    if m.obs.is_empty() {
        return Err(invalid("obs is empty (need at least one observation)".into()));
    }
    if let Some((i, o)) = m.obs.iter().enumerate().find(|(_, o)| **o >= no) {
        return Err(invalid(format!("obs[{i}] = {o} out of range ({no} observations)")));
    }
    if m.actions.len() + 1 != m.obs.len() {
        return Err(invalid(format!(
            "actions has {} entries (expected obs length - 1 = {})",
            m.actions.len(),
            m.obs.len() - 1
        )));
    }
    if let Some((i, u)) = m.actions.iter().enumerate().find(|(_, u)| **u >= m.B.len()) {
        return Err(invalid(format!(
            "actions[{i}] = {u} out of range ({} actions)",
            m.B.len()
        )));
    }
    if !(1..=8).contains(&m.policy_len) {
        return Err(invalid(format!("policy_len = {} (must be in 1..=8)", m.policy_len)));
    }
    if crate::limits::policies(m.B.len(), m.policy_len).is_none() {
        return Err(invalid(format!(
            "{} actions ^ policy_len {} is more than {} policies (limits::MAX_POLICIES)",
            m.B.len(),
            m.policy_len,
            crate::limits::MAX_POLICIES
        )));
    }
    if !(m.gamma > 0.0 && m.gamma.is_finite()) {
        return Err(invalid(format!("gamma = {} (must be finite and > 0)", m.gamma)));
    }
    Ok(GenerativeModel::new(a, b, log_softmax(&m.C), m.D.clone()))
}

/// Run `inspect` (exact filtering, F, S_t, EFE of all policies, q(π), ψ).
pub fn inspect(m: &InspectModel) -> Result<InspectReport, InspectError> {
    let gm = validate(m)?;
    let ns = gm.n_states();
    let mut q = vec![0.0; ns];
    let mut s_hat = gm.d.clone();
    for (t, o) in m.obs.iter().enumerate() {
        if t > 0 {
            let prev = q.clone();
            predict_into(&gm, Some((&prev, m.actions[t - 1])), &mut s_hat);
        }
        bayes_step(&gm, *o, &s_hat, &mut q);
    }
    let last = *m.obs.last().unwrap_or(&0);
    let f = free_energy(&gm, &s_hat, &[last], &[], std::slice::from_ref(&q));
    let s = surprise(&gm, last, &s_hat);
    let mut tree = EfeTree::new(ns, gm.n_obs(), gm.n_actions(), m.policy_len);
    tree.evaluate(&gm, &gm, &q, m.gamma);
    Ok(InspectReport {
        qs: q,
        F: f,
        surprise: s,
        policies: policies(gm.n_actions(), m.policy_len),
        G: tree.g.clone(),
        q_pi: tree.q_pi.clone(),
        psi: tree.psi.clone(),
    })
}

/// JSON in, pretty JSON out. A model whose `obs` is a list of lists (one index per
/// modality and step) is a general one in pymdp's layout ([`crate::aif::inspect`]); one
/// with a list of indices is this module's single-factor format.
pub fn inspect_json(s: &str) -> Result<String, InspectError> {
    let v: serde_json::Value = serde_json::from_str(s).map_err(|e| InspectError::Json(e.to_string()))?;
    let out = if crate::aif::inspect::is_general(&v) {
        serde_json::to_string_pretty(&crate::aif::inspect::inspect(&v)?)
    } else {
        let m: InspectModel = serde_json::from_value(v).map_err(|e| InspectError::Json(e.to_string()))?;
        serde_json::to_string_pretty(&inspect(&m)?)
    };
    out.map_err(|e| InspectError::Json(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::WorldModel;
    use crate::params::ModelPriors;
    use crate::structure::Structure;

    /// A trained factored model exported in this layout reads back to the same matrices,
    /// and `inspect` on it reproduces the agent's own EFE tree (which predicts factor by
    /// factor through the absorbing planning model).
    #[test]
    fn exported_planning_model_reproduces_the_agents_tree() {
        let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
        let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
        for s in 0..64 {
            for u in 0..3 {
                w.observe_transition(s, u, (s * 5 + u * 11) % 64);
            }
        }
        w.set_terminal_states(&[3, 40]).unwrap();
        let r: Vec<f64> = (0..64).map(|s| (s % 7) as f64 - 3.0).collect();
        w.set_preferences(&r, 1.0).unwrap();
        let gm = w.planning_generative();
        let obs = st.encode(&[2, 3, 1, 1]);
        let m = InspectModel::from_generative(gm, vec![obs], vec![], 3, 2.0);
        let json = serde_json::to_string(&m).unwrap();
        let back: InspectModel = serde_json::from_str(&json).unwrap();
        let gm2 = validate(&back).unwrap();
        assert_eq!(gm2.a, gm.a);
        assert_eq!(gm2.b, gm.b);
        assert_eq!(gm2.d, gm.d);
        for (x, y) in gm2.c.iter().zip(&gm.c) {
            assert!((x - y).abs() < 1e-12, "C changed by log_softmax: {x} vs {y}");
        }
        let report = inspect(&back).unwrap();
        let mut tree = EfeTree::new(64, 64, 3, 3);
        tree.evaluate(gm, gm, &report.qs, 2.0);
        assert!(gm.factored.is_some());
        for (a, b) in report.G.iter().zip(&tree.g) {
            assert!((a - b).abs() < 1e-10, "G {a} vs {b}");
        }
    }
}
