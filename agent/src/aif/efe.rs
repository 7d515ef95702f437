//! Policy evaluation as pymdp's `control.compute_neg_efe_policy_inductive` (without the
//! inductive term): for each policy, from the current posterior, `τ = 1..T`:
//! `s_τ = B[u_τ] s_{τ−1}`, `o_τ = A s_τ` and
//!
//! `−G += H[o_τ] − E_{s_τ} H[A]` (state information gain) `+ o_τ · C_τ` (utility)
//! `+ o_τ · E_{s_τ}[W_A] + s_τ · E_{s_{τ−1}}[W_B]` (parameter information gain, optional),
//!
//! with `W = ln Σα − ln α + ψ(α+1) − ψ(Σα+1)` over the Dirichlet counts (pymdp's exact
//! `spm_wnorm`). `q_π = σ(γ·(−G) + ln E)`.
//!
//! `G` here is the expected free energy, lower is better (pymdp returns `neg_efe = −G`).
//! [`Preferences::Raw`] uses `C` as given, as pymdp does; [`Preferences::LnSoftmax`] uses
//! `ln softmax(C)`, as the paper's agent does (§IV, "EFE_0"): `G` then shifts by
//! `T · logsumexp(C)` per modality, the same for every policy, so `q_π` and the action agree.
//!
//! Cost per planning tick: `N · (Σ_f |B[f][..., u]| + 2 Σ_m |A_m|)` multiply-adds, where
//! `N` is the number of distinct (depth, belief) nodes of the policy tree, at most
//! `Σ_{t=1..T} M^t ≈ P · M/(M−1)` for the `P = M^T` exhaustive policies of `M`
//! multi-actions, plus one addition per prefix; `N = P · T` for given policies (pymdp
//! evaluates every policy from the root: `P · T` always).

use super::infer::{MINVAL, log_stable, xlogx};
use super::model::Model;
use super::policies::Policies;
use super::tensor::Tensor;
use crate::maths::log_softmax;
use std::collections::HashMap;
use std::rc::Rc;

/// How `C` enters the utility.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Preferences {
    /// `o · C`, `C` used as given (pymdp 1.0.4).
    #[default]
    Raw,
    /// `o · ln softmax(C)`, normalised log-preferences (the paper's agent, §IV).
    LnSoftmax,
}

/// Which terms of the EFE to include (pymdp's `use_utility`, `use_states_info_gain`,
/// `use_param_info_gain`; defaults as pymdp's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(default)]
pub struct EfeTerms {
    /// `o · C`.
    pub utility: bool,
    /// `H[o] − E_s H[A]`.
    pub states_info_gain: bool,
    /// Information gain about `pA`, `pB` (needs them in the model).
    pub param_info_gain: bool,
}

impl Default for EfeTerms {
    fn default() -> Self {
        EfeTerms {
            utility: true,
            states_info_gain: true,
            param_info_gain: false,
        }
    }
}

/// The digamma function ψ: the recurrence `ψ(x) = ψ(x+1) − 1/x` up to 10, then the
/// asymptotic series (error below 3e-14 there).
pub fn digamma(mut x: f64) -> f64 {
    let mut acc = 0.0;
    while x < 10.0 {
        acc -= 1.0 / x;
        x += 1.0;
    }
    let r = 1.0 / (x * x);
    acc + x.ln()
        - 0.5 / x
        - r * (1.0 / 12.0 - r * (1.0 / 120.0 - r * (1.0 / 252.0 - r * (1.0 / 240.0 - r * (1.0 / 132.0)))))
}

/// `W = ln Σα − ln α + ψ(α+1) − ψ(Σα+1)` over axis 0 of the counts, 0 where `α = 0`.
fn info_gain_weights(p: &Tensor) -> Tensor {
    let n0 = p.shape[0];
    let cols = p.data.len() / n0;
    let mut w = p.clone();
    for c in 0..cols {
        let sum = (0..n0)
            .map(|o| p.data[o * cols + c].max(MINVAL))
            .sum::<f64>()
            .max(MINVAL);
        for o in 0..n0 {
            let a = p.data[o * cols + c];
            let sa = a.max(MINVAL);
            w.data[o * cols + c] = if a > 0.0 {
                sum.ln() - sa.ln() + digamma(sa + 1.0) - digamma(sum + 1.0)
            } else {
                0.0
            };
        }
    }
    w
}

/// Scratch buffers of the planning kernels (no allocation per step once warm).
#[derive(Debug, Default)]
struct Kernel {
    joint: Vec<f64>,
    qo: Vec<f64>,
    tmp: Vec<f64>,
}

/// `⊗_{d ∈ deps} qs[d]` in C order, built in `buf` (the factor itself when there is one).
fn joint<'a>(buf: &'a mut Vec<f64>, qs: &'a [Vec<f64>], deps: &[usize]) -> &'a [f64] {
    if let [d] = deps {
        return &qs[*d];
    }
    buf.clear();
    buf.push(1.0);
    for &d in deps {
        let q = &qs[d];
        let len = buf.len();
        buf.resize(len * q.len(), 0.0);
        for i in (0..len).rev() {
            let v = buf[i];
            for (j, qj) in q.iter().enumerate().rev() {
                buf[i * q.len() + j] = v * qj;
            }
        }
    }
    buf
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The depth-first walk of [`Planner::efe_tree`]: the step values below each belief,
/// remembered by (depth, belief bits), since in most models many prefixes reach the same
/// belief (a deterministic move lands on the same cell from anywhere).
struct Walk<'a> {
    planner: &'a Planner,
    model: &'a Model,
    actions: &'a [Vec<usize>],
    k: &'a mut Kernel,
    memo: HashMap<(usize, Vec<u64>), Rc<Vec<f64>>>,
}

impl Walk<'_> {
    /// The `−G` step values of the subtree below a node at depth `t` whose belief is
    /// `states[t]`, in preorder (each action's step, then its subtree).
    fn steps(&mut self, states: &mut [Vec<Vec<f64>>], t: usize) -> Rc<Vec<f64>> {
        let key = (t, states[t].iter().flatten().map(|x| x.to_bits()).collect::<Vec<u64>>());
        if let Some(v) = self.memo.get(&key) {
            return Rc::clone(v);
        }
        let len = states.len() - 1;
        let mut out = Vec::new();
        for u in self.actions {
            let (head, tail) = states.split_at_mut(t + 1);
            out.push(self.planner.step(self.model, &head[t], &mut tail[0], u, t, self.k));
            if t + 1 < len {
                let sub = self.steps(states, t + 1);
                out.extend_from_slice(&sub);
            }
        }
        let out = Rc::new(out);
        self.memo.insert(key, Rc::clone(&out));
        out
    }
}

/// Sum the preorder step values `list` (from `*pos`) down to each policy of `m`
/// multi-actions per step: `G = −Σ_t step`, added from the root in step order (as
/// [`Planner::efe`] does).
#[allow(clippy::too_many_arguments)]
fn fill(list: &[f64], pos: &mut usize, acc: f64, prefix: usize, t: usize, len: usize, m: usize, g: &mut [f64]) {
    for a in 0..m {
        let acc = acc + list[*pos];
        *pos += 1;
        let index = prefix * m + a;
        if t + 1 == len {
            g[index] = -acc;
        } else {
            fill(list, pos, acc, index, t + 1, len, m, g);
        }
    }
}

/// A tensor as a matrix (axis 0 by the rest, C order) of its non-zero entries, row by
/// row in column order: its products with a vector are the dense ones' bit for bit (the
/// skipped terms are exact zeros), at the cost of the non-zeros only (pymdp's
/// environments are mostly identity and one-hot columns).
#[derive(Debug, Clone)]
struct Sparse {
    row_start: Vec<usize>,
    cols: Vec<usize>,
    vals: Vec<f64>,
}

impl Sparse {
    fn new(t: &Tensor) -> Sparse {
        let rows = t.shape.first().copied().unwrap_or(1);
        let width = t.data.len() / rows.max(1);
        let mut s = Sparse {
            row_start: vec![0],
            cols: Vec::new(),
            vals: Vec::new(),
        };
        for row in t.data.chunks_exact(width.max(1)) {
            for (c, &v) in row.iter().enumerate() {
                if v != 0.0 {
                    s.cols.push(c);
                    s.vals.push(v);
                }
            }
            s.row_start.push(s.cols.len());
        }
        s
    }

    fn rows(&self) -> usize {
        self.row_start.len() - 1
    }

    /// `out = M x`.
    fn matvec(&self, x: &[f64], out: &mut [f64]) {
        for (r, o) in out.iter_mut().enumerate() {
            let (a, b) = (self.row_start[r], self.row_start[r + 1]);
            *o = self.cols[a..b]
                .iter()
                .zip(&self.vals[a..b])
                .map(|(&c, v)| v * x[c])
                .sum();
        }
    }
}

/// What a model's planning needs, computed once per model (and again after learning).
#[derive(Debug, Clone)]
pub struct Planner {
    a: Vec<Sparse>,
    b_u: Vec<Vec<Sparse>>,
    h_a: Vec<Tensor>,
    c: Vec<Vec<Vec<f64>>>,
    w_a: Option<Vec<Sparse>>,
    w_b: Option<Vec<Vec<Sparse>>>,
    terms: EfeTerms,
}

impl Planner {
    /// The planner of `model` over `policy_len` steps. `C[m]` time-indexed must have at
    /// least `policy_len` rows (checked by [`super::agent::Agent::new`]).
    pub fn new(model: &Model, preferences: Preferences, terms: EfeTerms, policy_len: usize) -> Planner {
        let b_u = model
            .b
            .iter()
            .zip(&model.num_controls)
            .map(|(b, &nu)| (0..nu).map(|u| Sparse::new(&b.slice_last(u))).collect())
            .collect();
        let a = model.a.iter().map(Sparse::new).collect();
        let h_a = model
            .a
            .iter()
            .map(|a| {
                let n0 = a.shape[0];
                let cols = a.data.len() / n0;
                Tensor {
                    shape: a.shape[1..].to_vec(),
                    data: (0..cols)
                        .map(|c| -(0..n0).map(|o| xlogx(a.data[o * cols + c])).sum::<f64>())
                        .collect(),
                }
            })
            .collect();
        let c = model
            .c
            .iter()
            .map(|cm| {
                (0..policy_len)
                    .map(|t| {
                        let row = if cm.ndim() == 2 {
                            cm.slice_first(t).data
                        } else {
                            cm.data.clone()
                        };
                        match preferences {
                            Preferences::Raw => row,
                            Preferences::LnSoftmax => log_softmax(&row),
                        }
                    })
                    .collect()
            })
            .collect();
        let param = terms.param_info_gain;
        let w_a = model
            .pa
            .as_ref()
            .filter(|_| param)
            .map(|pa| pa.iter().map(|p| Sparse::new(&info_gain_weights(p))).collect());
        let w_b = model.pb.as_ref().filter(|_| param).map(|pb| {
            pb.iter()
                .zip(&model.num_controls)
                .map(|(p, &nu)| {
                    (0..nu)
                        .map(|u| Sparse::new(&info_gain_weights(&p.slice_last(u))))
                        .collect()
                })
                .collect()
        });
        Planner {
            a,
            b_u,
            h_a,
            c,
            w_a,
            w_b,
            terms,
        }
    }

    /// The `−G` contribution of one step: from `prev` through multi-action `u` to `next`
    /// (written here), at horizon step `t`.
    fn step(
        &self,
        model: &Model,
        prev: &[Vec<f64>],
        next: &mut [Vec<f64>],
        u: &[usize],
        t: usize,
        k: &mut Kernel,
    ) -> f64 {
        for (f, deps) in model.b_deps.iter().enumerate() {
            let x = joint(&mut k.joint, prev, deps);
            self.b_u[f][u[f]].matvec(x, &mut next[f]);
        }
        let mut step = 0.0;
        for (m, (a, deps)) in self.a.iter().zip(&model.a_deps).enumerate() {
            let x = joint(&mut k.joint, next, deps);
            k.qo.resize(a.rows(), 0.0);
            a.matvec(x, &mut k.qo);
            if self.terms.states_info_gain {
                let h_qo = -k.qo.iter().map(|x| xlogx(*x)).sum::<f64>();
                step += h_qo - dot(&self.h_a[m].data, x);
            }
            if self.terms.utility {
                step += dot(&k.qo, &self.c[m][t]);
            }
            if let Some(w) = &self.w_a {
                k.tmp.resize(a.rows(), 0.0);
                w[m].matvec(x, &mut k.tmp);
                step += dot(&k.qo, &k.tmp);
            }
        }
        if let Some(w) = &self.w_b {
            for (f, deps) in model.b_deps.iter().enumerate() {
                let x = joint(&mut k.joint, prev, deps);
                k.tmp.resize(next[f].len(), 0.0);
                w[f][u[f]].matvec(x, &mut k.tmp);
                step += dot(&next[f], &k.tmp);
            }
        }
        step
    }

    /// `G` of policy `p` (lower is better) from the posterior `qs`.
    pub fn efe(&self, model: &Model, qs: &[Vec<f64>], policies: &Policies, p: usize) -> f64 {
        let mut k = Kernel::default();
        let mut prev: Vec<Vec<f64>> = qs.to_vec();
        let mut next = prev.clone();
        let mut neg_efe = 0.0;
        for t in 0..policies.policy_len() {
            neg_efe += self.step(model, &prev, &mut next, policies.step(p, t), t, &mut k);
            std::mem::swap(&mut prev, &mut next);
        }
        -neg_efe
    }

    /// `G` of every exhaustive policy by walking the tree of their prefixes: each prefix's
    /// step is computed once, not once per policy through it, and once per distinct
    /// (depth, belief) when prefixes meet. The sums are the same additions in the same
    /// order as [`Planner::efe`]'s, so the values are bit for bit its.
    fn efe_tree(&self, model: &Model, qs: &[Vec<f64>], policy_len: usize) -> Vec<f64> {
        let nc = &model.num_controls;
        let per_step: usize = nc.iter().product();
        let actions: Vec<Vec<usize>> = (0..per_step)
            .map(|mut a| {
                let mut u = vec![0; nc.len()];
                for f in (0..nc.len()).rev() {
                    u[f] = a % nc[f];
                    a /= nc[f];
                }
                u
            })
            .collect();
        let mut g = vec![0.0; per_step.pow(policy_len as u32)];
        // One belief per depth, reused along the walk.
        let mut states: Vec<Vec<Vec<f64>>> = vec![qs.to_vec(); policy_len + 1];
        let mut k = Kernel::default();
        let mut walk = Walk {
            planner: self,
            model,
            actions: &actions,
            k: &mut k,
            memo: HashMap::new(),
        };
        let list = walk.steps(&mut states, 0);
        fill(&list, &mut 0, 0.0, 0, 0, policy_len, per_step, &mut g);
        g
    }

    /// `G` of every policy, and `q_π = σ(−γ G + ln E)` (`E` uniform when `None`).
    pub fn evaluate(
        &self,
        model: &Model,
        qs: &[Vec<f64>],
        policies: &Policies,
        gamma: f64,
        e: Option<&[f64]>,
    ) -> (Vec<f64>, Vec<f64>) {
        let g: Vec<f64> = if policies.is_exhaustive() {
            self.efe_tree(model, qs, policies.policy_len())
        } else {
            (0..policies.len()).map(|p| self.efe(model, qs, policies, p)).collect()
        };
        let n = g.len() as f64;
        let mut q: Vec<f64> = g
            .iter()
            .enumerate()
            .map(|(p, gp)| gamma * -gp + log_stable(e.map_or(1.0 / n, |e| e[p])))
            .collect();
        crate::maths::softmax_in_place(&mut q);
        (g, q)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn digamma_known_values() {
        let euler = 0.577_215_664_901_532_9;
        assert!((digamma(1.0) + euler).abs() < 1e-13);
        assert!((digamma(0.5) + euler + 2.0 * 2f64.ln()).abs() < 1e-13);
        assert!((digamma(10.0) - 2.251_752_589_066_721).abs() < 1e-13);
        // scipy.special.digamma(1e-3)
        assert!((digamma(1e-3) + 1_000.575_571_931_810_3).abs() < 1e-9);
    }
}
