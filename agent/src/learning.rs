//! Learning at test time (§V): conjugate Dirichlet updates of `A`, of the factor CPTs
//! behind `B`, and of the policy counts `ν`, each adding exactly the expected counts
//! under the posteriors `q_τ` (scaled by a learning rate).
//!
//! - `a[o,s] += lr Σ_τ o_τ ⊗ q_τ` (§V-A, `α'_ij = α_ij + Σ_τ 1[o_τ = i] q(s_τ = j)`)
//! - `b_f[child | parents, u] += lr Σ_τ E_{q_{τ-1} ⊗ q_τ}[1[...]]` (§V-B, factored)
//! - `ν[u,s] += lr Σ_τ q_τ[s] π_τ[u]` (§V-C, the paper's "policy update through
//!   inference": `π_τ` is what reasoning chose at `τ`, `π'`; a one-hot `π_τ` at the action
//!   taken gives the paper's `q(s_{τ-1} = j) 1[a_τ = i]` with its action index shifted by one).
//!
//! The base policy is `π_o(u|s) = ν[u,s] / Σ_u ν[u,s]`, and `ν` starts as
//! `ν0 σ(Q[s,·]/T)` (docs/ARCHITECTURE.md §4.8).

use crate::maths::softmax_in_place;
use crate::model::WorldModel;
use crate::structure::Parent;
use nalgebra::DMatrix;

/// `a[o,s] += lr q[s]` for observation `o` (§V-A, one term of the sum), on the cells whose
/// count is positive. A cell with no count is a structural zero of `A` (`P(o | s) = 0`,
/// e.g. every off-diagonal cell of an exact observation model): the exact posterior puts
/// no mass on such an `s` given `o`, so it stays zero. Perception's floored `ln A` leaves a
/// rounding residue there (about 1e-18) which, learned, feeds back (more mass in `A`, more
/// spread in the next posteriors) and grew geometrically over a long continual run
/// (measured on seed 7's agent on stop_midway: the largest off-diagonal of an identity `A`
/// reached 0.07 after 190 episodes and beliefs blurred across neighbouring states;
/// EXPERIMENTS.md, "The safe hand-back").
pub fn update_a(counts: &mut DMatrix<f64>, o: usize, q: &[f64], lr: f64) {
    for (s, p) in q.iter().enumerate() {
        if *p != 0.0 && counts[(o, s)] > 0.0 {
            counts[(o, s)] += lr * p;
        }
    }
}

/// Add the expected factor-CPT counts of one transition `q_prev --u--> q_next` under the
/// mean-field pairwise posterior `q_prev ⊗ q_next` (§V-B, factored form). Each factor
/// receives total mass `lr`. Call [`WorldModel::materialize`] afterwards.
///
/// Under `q_prev ⊗ q_next` the expected count of a CPT cell of factor `f` is
/// `lr · m_prev(previous-time parents) · m_next(next-time parents, child)`, with `m_prev`
/// and `m_next` the marginals of `q_prev` and `q_next` over those factors; computing
/// the marginals costs `O(N)` per factor instead of the `O(N²)` sum over state pairs.
pub fn update_cpts(model: &mut WorldModel, q_prev: &[f64], u: usize, q_next: &[f64], lr: f64) {
    let st = model.structure().clone();
    let na = model.n_actions();
    let mut vals = vec![0; st.factors().len()];
    for (f, fac) in st.factors().iter().enumerate() {
        // The previous-time parents (marginal of q_prev) and the next-time parents plus
        // the child (marginal of q_next), each in parent order.
        let sizes: Vec<usize> = fac
            .parents
            .iter()
            .map(|p| match p {
                Parent::Prev(g) | Parent::Next(g) => st.factors()[*g].size,
            })
            .collect();
        let prev_vars: Vec<usize> = fac
            .parents
            .iter()
            .filter_map(|p| if let Parent::Prev(g) = p { Some(*g) } else { None })
            .collect();
        let mut next_vars: Vec<usize> = fac
            .parents
            .iter()
            .filter_map(|p| if let Parent::Next(g) = p { Some(*g) } else { None })
            .collect();
        next_vars.push(f);
        let marginal = |q: &[f64], vars: &[usize], vals: &mut Vec<usize>| {
            let len: usize = vars.iter().map(|g| st.factors()[*g].size).product();
            let mut m = vec![0.0; len];
            for (s, p) in q.iter().enumerate() {
                if *p != 0.0 {
                    st.decode_into(s, vals);
                    let i = vars.iter().fold(0, |i, g| i * st.factors()[*g].size + vals[*g]);
                    m[i] += p;
                }
            }
            m
        };
        let m_prev = marginal(q_prev, &prev_vars, &mut vals);
        let m_next = marginal(q_next, &next_vars, &mut vals);
        // Every parent configuration (mixed radix in parent order) and child value.
        let n_parent_cfgs: usize = sizes.iter().product();
        let mut pv = vec![0; sizes.len()];
        for cfg in 0..n_parent_cfgs {
            let mut rest = cfg;
            for k in (0..sizes.len()).rev() {
                pv[k] = rest % sizes[k];
                rest /= sizes[k];
            }
            let (mut ip, mut inx) = (0, 0);
            for (k, p) in fac.parents.iter().enumerate() {
                match p {
                    Parent::Prev(_) => ip = ip * sizes[k] + pv[k],
                    Parent::Next(_) => inx = inx * sizes[k] + pv[k],
                }
            }
            let wp = m_prev[ip];
            if wp == 0.0 {
                continue;
            }
            let row = st.config_from_parent_values(f, &pv, Some(u), na) * fac.size;
            let counts = model.cpt_counts_mut(f);
            for child in 0..fac.size {
                counts[row + child] += lr * wp * m_next[inx * fac.size + child];
            }
        }
    }
}

/// `ν[s,u] += lr q[s] π[u]` for the policy `π` chosen from belief `q` (§V-C). `nu` is laid
/// out `[s * n_actions + u]`; each tick adds total mass `lr` (when `q` and `π` sum to 1).
pub fn update_nu(nu: &mut [f64], n_actions: usize, q: &[f64], pi: &[f64], lr: f64) {
    for (s, p) in q.iter().enumerate() {
        if *p != 0.0 {
            for (c, a) in nu[s * n_actions..(s + 1) * n_actions].iter_mut().zip(pi) {
                *c += lr * p * a;
            }
        }
    }
}

/// `π_o(·|s) = ν[s,·] / Σ_u ν[s,u]` (Dirichlet mean, §V-C) into `out`.
pub fn pi_o_state(nu: &[f64], n_actions: usize, s: usize, out: &mut [f64]) {
    out.copy_from_slice(&nu[s * n_actions..(s + 1) * n_actions]);
    crate::maths::normalize_in_place(out);
}

/// `π_o(·|q) = Σ_s q[s] π_o(·|s)` (the base policy under a belief, docs/ARCHITECTURE.md §5).
pub fn pi_o_belief(nu: &[f64], n_actions: usize, q: &[f64], out: &mut [f64]) {
    out.iter_mut().for_each(|v| *v = 0.0);
    for (s, p) in q.iter().enumerate() {
        if *p != 0.0 {
            let row = &nu[s * n_actions..(s + 1) * n_actions];
            let z: f64 = row.iter().sum();
            for (o, r) in out.iter_mut().zip(row) {
                *o += p * r / z;
            }
        }
    }
}

/// `ν = ν0 σ(Q[s,·]/T)` per state (docs/ARCHITECTURE.md §4.8, end of training), laid out `[s * n_actions + u]`.
pub fn nu_from_q(q_table: &[f64], n_actions: usize, nu0: f64, temperature: f64) -> Vec<f64> {
    let mut nu: Vec<f64> = q_table.iter().map(|q| q / temperature).collect();
    for row in nu.chunks_mut(n_actions) {
        softmax_in_place(row);
        row.iter_mut().for_each(|v| *v *= nu0);
    }
    nu
}
