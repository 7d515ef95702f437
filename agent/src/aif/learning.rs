//! Dirichlet learning as pymdp's `Agent.infer_parameters` with fpi (filtered marginals):
//!
//! * `pA_m ← pA_m + lr · Σ_t onehot(o_{t,m}) ⊗ q_t(s_{A_dependencies[m]})`;
//! * `pB_f ← pB_f + lr · Σ_{t≥1} q_t(s_f) ⊗ q_{t−1}(s_{B_dependencies[f]}) ⊗ onehot(u_{t−1,f})`;
//!
//! then `A = pA / Σ_o pA`, `B = pB / Σ_{s'} pB` (each entry floored at ε first, as
//! pymdp's `dirichlet_expected_value`). No forgetting. The paper's learning step (§V) is
//! [`crate::learning`]; this one is pymdp's.

use super::error::ModelError;
use super::infer::MINVAL;
use super::model::Model;
use super::tensor::{Tensor, outer};

fn onehot(i: usize, n: usize) -> Vec<f64> {
    let mut v = vec![0.0; n];
    v[i] = 1.0;
    v
}

/// `p / Σ_{axis 0} p`, each entry floored at ε first (pymdp's `dirichlet_expected_value`).
pub fn expected_value(p: &Tensor) -> Tensor {
    let n0 = p.shape[0];
    let cols = p.data.len() / n0;
    let mut t = p.clone();
    t.data.iter_mut().for_each(|v| *v = v.max(MINVAL));
    for c in 0..cols {
        let z: f64 = (0..n0).map(|o| t.data[o * cols + c]).sum();
        for o in 0..n0 {
            t.data[o * cols + c] /= z;
        }
    }
    t
}

/// Check a sequence: `obs[t]` one index per modality, `qs[t]` one marginal per factor.
fn check_sequence(model: &Model, obs: &[Vec<usize>], qs: &[Vec<Vec<f64>>]) -> Result<(), ModelError> {
    if obs.len() != qs.len() {
        return Err(ModelError::invalid(
            "observations",
            format!(
                "has {} steps, beliefs has {}: one belief per observation",
                obs.len(),
                qs.len()
            ),
        ));
    }
    for (t, o) in obs.iter().enumerate() {
        model.check_obs(o).map_err(|e| match e {
            ModelError::Invalid { array, problem } => {
                ModelError::invalid(format!("observations[{t}] ({array})"), problem)
            }
            e => e,
        })?;
    }
    for (t, q) in qs.iter().enumerate() {
        model.check_marginals(&format!("beliefs[{t}]"), q)?;
    }
    Ok(())
}

/// Add the counts of one sequence to `pA` and set `A` to its expected value.
pub fn update_pa(model: &mut Model, obs: &[Vec<usize>], qs: &[Vec<Vec<f64>>], lr: f64) -> Result<(), ModelError> {
    check_sequence(model, obs, qs)?;
    let Some(pa) = model.pa.as_mut() else {
        return Err(ModelError::invalid(
            "pA",
            "is absent: A learning needs Dirichlet counts pA",
        ));
    };
    for (m, p) in pa.iter_mut().enumerate() {
        let deps = &model.a_deps[m];
        for (o, q) in obs.iter().zip(qs) {
            let e = onehot(o[m], model.num_obs[m]);
            let mut xs: Vec<&[f64]> = vec![&e];
            xs.extend(deps.iter().map(|&d| q[d].as_slice()));
            let d = outer(&xs);
            p.data.iter_mut().zip(&d).for_each(|(a, b)| *a += lr * b);
        }
        model.a[m] = expected_value(p);
    }
    Ok(())
}

/// Add the transition counts of one sequence (`actions[t]` taken between `t` and `t+1`;
/// extra trailing actions are ignored) to `pB` and set `B` to its expected value.
pub fn update_pb(
    model: &mut Model,
    obs: &[Vec<usize>],
    qs: &[Vec<Vec<f64>>],
    actions: &[Vec<usize>],
    lr: f64,
) -> Result<(), ModelError> {
    check_sequence(model, obs, qs)?;
    let steps = qs.len().saturating_sub(1);
    if actions.len() < steps {
        return Err(ModelError::invalid(
            "actions",
            format!(
                "has {} steps, must have at least len(beliefs) - 1 = {steps}",
                actions.len()
            ),
        ));
    }
    for (t, u) in actions.iter().take(steps).enumerate() {
        model
            .check_action(u)
            .map_err(|e| ModelError::invalid(format!("actions[{t}]"), e.to_string()))?;
    }
    let Some(pb) = model.pb.as_mut() else {
        return Err(ModelError::invalid(
            "pB",
            "is absent: B learning needs Dirichlet counts pB",
        ));
    };
    for (f, p) in pb.iter_mut().enumerate() {
        let deps = &model.b_deps[f];
        for t in 0..steps {
            let e = onehot(actions[t][f], model.num_controls[f]);
            let mut xs: Vec<&[f64]> = vec![&qs[t + 1][f]];
            xs.extend(deps.iter().map(|&d| qs[t][d].as_slice()));
            xs.push(&e);
            let d = outer(&xs);
            p.data.iter_mut().zip(&d).for_each(|(a, b)| *a += lr * b);
        }
        model.b[f] = expected_value(p);
    }
    Ok(())
}
