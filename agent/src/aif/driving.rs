//! The driving agent's planning model in pymdp's layout (docs/ARCHITECTURE.md §4.12): the
//! paper's planner ([`crate::planning::EfeTree`]) as one model among others of this module.
//!
//! * [`exported`]: what `unforeseen export-model` writes: one factor of the agent's
//!   states, `A`, the planning `B` (episode-ending states absorbing), `C = ln c`, `D`.
//!   It leaves out the tree's root step and crash terms, so its `G` is not the agent's.
//! * [`equivalent`]: the same with those two expressed in the layout, so that the general
//!   agent's `G` (with [`super::efe::Preferences::Raw`]) is the tree's:
//!   - a crashed state, absorbing, entered with `B[u][crashed, s] = hazard[u][s]` (the rest
//!     of a column scaled by `1 − hazard[u][s]`) and seen as its own outcome, whose
//!     preference is the crash model's `crashed`: the tree's risk term of the crashed mass
//!     `m`, `m (ln m − crashed)`, is then the KL risk of that outcome;
//!   - a second factor, the step (root, then later; one control, root → later), on which
//!     the states' `B` depends (`B_dependencies = [[0, 1], [1]]`): the root step's `B` is
//!     the learned one, the later steps' the planning one. Its belief starts one-hot on
//!     root, so the mean-field prediction over the two factors is exact.
//!
//!   A transition cost (the red-light rule) is refused: it is a linear cost on a pair of
//!   consecutive states, and every outcome of pymdp's EFE enters the risk with its own
//!   entropy, so an outcome "the rule was broken" would add `Σ o ln o` of it to `G`.
//!
//! The beliefs of [`equivalent`]'s agent are `[q ++ [0], [1, 0]]` for the tree's `q`.
//! `agent/examples/driving_through_aif.rs` measures both on a trained agent.

use super::error::ModelError;
use super::model::{Model, ModelParts};
use super::tensor::Tensor;
use crate::model::GenerativeModel;

/// `B[s', s, u]` of `gm` as a tensor of pymdp's layout.
fn b_tensor(gm: &GenerativeModel) -> Tensor {
    let (n, na) = (gm.n_states(), gm.n_actions());
    let mut t = Tensor::filled(vec![n, n, na], 0.0);
    for u in 0..na {
        for s in 0..n {
            for s2 in 0..n {
                t.data[(s2 * n + s) * na + u] = gm.b[u][(s2, s)];
            }
        }
    }
    t
}

/// `A[o, s]` of `gm`, with `extra` more outcomes and states (zero).
fn a_tensor(gm: &GenerativeModel, extra: usize) -> Tensor {
    let (no, n) = (gm.n_obs(), gm.n_states());
    let cols = n + extra;
    let mut t = Tensor::filled(vec![no + extra, cols], 0.0);
    for o in 0..no {
        for s in 0..n {
            t.data[o * cols + s] = gm.a[(o, s)];
        }
    }
    t
}

fn vector(data: Vec<f64>) -> Tensor {
    Tensor {
        shape: vec![data.len()],
        data,
    }
}

/// The exported model of `plan` (one factor, no root step, no crash terms), validated.
pub fn exported(plan: &GenerativeModel) -> Result<Model, ModelError> {
    Model::new(ModelParts {
        A: vec![a_tensor(plan, 0)],
        B: vec![b_tensor(plan)],
        C: Some(vec![vector(plan.c.clone())]),
        D: Some(vec![plan.d.clone()]),
        ..ModelParts::default()
    })
}

/// The planning model of the tree that takes its first step through `root` and the later
/// ones through `plan` (with `plan`'s crash model), in pymdp's layout (module docs);
/// refused when either has a transition cost or when the two differ in size.
pub fn equivalent(plan: &GenerativeModel, root: &GenerativeModel) -> Result<Model, ModelError> {
    if plan.transition_cost.is_some() || root.transition_cost.is_some() {
        return Err(ModelError::invalid(
            "transition_cost",
            "is a cost on pairs of consecutive states, which pymdp's EFE cannot express (an outcome for it adds its entropy to G)",
        ));
    }
    let (n, no, na) = (plan.n_states(), plan.n_obs(), plan.n_actions());
    if (root.n_states(), root.n_obs(), root.n_actions()) != (n, no, na) {
        return Err(ModelError::invalid(
            "root",
            format!(
                "has {} states, {} outcomes, {} actions; the planning model {n}, {no}, {na}: they must agree",
                root.n_states(),
                root.n_obs(),
                root.n_actions()
            ),
        ));
    }
    let hazard = |u: usize, s: usize| plan.crash.as_ref().map_or(0.0, |c| c.hazard[u][s]);
    let crashed = n;
    let mut b = Tensor::filled(vec![n + 1, n + 1, 2, na], 0.0);
    let at = |s2: usize, s: usize, step: usize, u: usize| ((s2 * (n + 1) + s) * 2 + step) * na + u;
    for (step, gm) in [root, plan].into_iter().enumerate() {
        for u in 0..na {
            for s in 0..n {
                let h = hazard(u, s);
                for s2 in 0..n {
                    b.data[at(s2, s, step, u)] = (1.0 - h) * gm.b[u][(s2, s)];
                }
                b.data[at(crashed, s, step, u)] = h;
            }
            b.data[at(crashed, crashed, step, u)] = 1.0;
        }
    }
    // The step factor, [step', step, u]: root -> later, later -> later.
    let steps = Tensor {
        shape: vec![2, 2, 1],
        data: vec![0.0, 0.0, 1.0, 1.0],
    };
    let mut a = a_tensor(plan, 1);
    a.data[no * (n + 1) + crashed] = 1.0;
    let mut c = plan.c.clone();
    c.push(plan.crash.as_ref().map_or(0.0, |cm| cm.crashed));
    let mut d = plan.d.clone();
    d.push(0.0);
    Model::new(ModelParts {
        A: vec![a],
        B: vec![b, steps],
        C: Some(vec![vector(c)]),
        D: Some(vec![d, vec![1.0, 0.0]]),
        A_dependencies: Some(vec![vec![0]]),
        B_dependencies: Some(vec![vec![0, 1], vec![1]]),
        ..ModelParts::default()
    })
}
