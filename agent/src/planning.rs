//! Planning as inference (§IV): expected free energy of every policy of horizon H
//! (Prop. 1, eq. "EFE_0"), `q(π) = σ(-γ G)` (Cor. 1), the first-action marginal
//! `ψ(u) = Σ_{π: π_1 = u} q(π)`, and `Q_S(u) = -(1/γ) ln ψ(u)` (Theorem 1).
//!
//! Predictions `B[u] s` go through [`GenerativeModel::transition_into`] (factor by
//! factor for dense beliefs, §II-A); the brute-force oracle uses the dense `B`.
//!
//! All policies start from `q_t`: `s_1 = B[π_1] q_t`, `s_k = B[π_k] s_{k-1}`, `o_k = A s_k`,
//! `G(π) = Σ_k [ o_k·(ln o_k - C) + s_k·H_A ]` (risk + ambiguity), plus, where the model
//! has a preference over transitions ([`crate::model::TransitionCost`], the red-light rule),
//! each step's expected cost `cost · P(s_{k-1} ∈ from, s_k ∈ to)`.
//!
//! The tree takes two models: the first step from `q_t` goes through the *root* model's
//! `B` and every later step through the planning model's. In the agent the planning
//! model has the episode-ending states absorbing (`WorldModel::set_terminal_states`) and
//! the root model is the learned one: the car observes `q_t` while the episode goes on,
//! so even in a crash-risk state (a pedestrian on the crosswalk while the car moves in a
//! crosswalk bin) its next step follows its dynamics, and braking out of it counts. The tree shares
//! prefixes: `U + U^2 + ... + U^H` mat-vecs instead of `H U^H`. Policies are ordered
//! lexicographically (first action most significant): `[0,0], [0,1], ...`.

use crate::maths::{axpy_columns, ln, risk_sum, softmax_in_place};
use crate::model::GenerativeModel;

/// Risk and ambiguity of one future step with predicted state belief `s`
/// (Prop. 1: `risk = KL[A s || c]`, `ambiguity = s·H_A`). `obuf` is scratch of size n_obs.
pub fn step_efe(gm: &GenerativeModel, s: &[f64], obuf: &mut [f64]) -> (f64, f64) {
    let o: &[f64] = if gm.a_identity {
        s
    } else {
        axpy_columns(gm.a.as_slice(), gm.n_obs(), s, obuf);
        obuf
    };
    // Zero entries add exactly 0 (the floored log and C are finite): no branch needed.
    // Branch-free logarithms that vectorise (`maths::risk_sum`, `maths::ln_fast`).
    let risk = risk_sum(o, &gm.c);
    let ambiguity = if gm.a_identity {
        0.0
    } else {
        s.iter().zip(&gm.h_a).map(|(a, b)| a * b).sum()
    };
    (risk, ambiguity)
}

/// The long form of one step's EFE from the proof of Prop. 1 (Appendix B):
/// `Σ_{o,s} p(o|s) q(s) ln(q(o)/p(o|C)) - Σ_{o,s} p(o|s) q(s) ln p(o|s)`. Test oracle.
pub fn step_efe_long_form(gm: &GenerativeModel, s: &[f64]) -> f64 {
    let (no, ns) = (gm.n_obs(), gm.n_states());
    let qo: Vec<f64> = (0..no).map(|o| (0..ns).map(|j| gm.a[(o, j)] * s[j]).sum()).collect();
    let mut g = 0.0;
    for (o, qo_o) in qo.iter().enumerate() {
        for (j, sj) in s.iter().enumerate() {
            let w = gm.a[(o, j)] * sj;
            if w > 0.0 {
                g += w * (ln(*qo_o) - gm.c[o]) - w * ln(gm.a[(o, j)]);
            }
        }
    }
    g
}

/// All action sequences of length `horizon` in lexicographic order.
pub fn policies(n_actions: usize, horizon: usize) -> Vec<Vec<usize>> {
    let count = n_actions.pow(horizon as u32);
    (0..count)
        .map(|mut i| {
            let mut p = vec![0; horizon];
            for k in (0..horizon).rev() {
                p[k] = i % n_actions;
                i /= n_actions;
            }
            p
        })
        .collect()
}

/// `G(π)` of one policy by direct rollout (brute-force oracle for the tree), eq. "EFE_0".
pub fn efe_brute_force(gm: &GenerativeModel, q_t: &[f64], policy: &[usize]) -> f64 {
    let n = gm.n_states();
    let mut s = q_t.to_vec();
    let mut next = vec![0.0; n];
    let mut obuf = vec![0.0; gm.n_obs()];
    let mut g = 0.0;
    let mut crashed = 0.0;
    for u in policy {
        if let Some(t) = &gm.transition_cost {
            // The step's cost straight from its definition, state pair by state pair.
            for (j, sj) in s.iter().enumerate().filter(|(j, _)| t.from[*j]) {
                for i in (0..n).filter(|&i| t.to[i]) {
                    g += t.cost * gm.b[*u][(i, j)] * sj;
                }
            }
        }
        if let Some(cm) = &gm.crash {
            // Straight from the definition: each state's hazard leaves the drive.
            for (j, x) in s.iter_mut().enumerate() {
                crashed += *x * cm.hazard[*u][j];
                *x *= 1.0 - cm.hazard[*u][j];
            }
        }
        axpy_columns(gm.b[*u].as_slice(), n, &s, &mut next);
        std::mem::swap(&mut s, &mut next);
        let (r, a) = step_efe(gm, &s, &mut obuf);
        g += r + a + gm.crash.as_ref().map_or(0.0, |cm| cm.risk(crashed));
    }
    g
}

/// `q(π) = σ(-γ G)` (Cor. 1) into `out`.
pub fn q_pi_into(g: &[f64], gamma: f64, out: &mut [f64]) {
    for (o, gi) in out.iter_mut().zip(g) {
        *o = -gamma * gi;
    }
    softmax_in_place(out);
}

/// `ψ(u) = Σ_{π: π_1 = u} q(π)` for lexicographically ordered policies (§IV).
pub fn psi_into(q_pi: &[f64], n_actions: usize, out: &mut [f64]) {
    let block = q_pi.len() / n_actions;
    for (u, o) in out.iter_mut().enumerate().take(n_actions) {
        *o = q_pi[u * block..(u + 1) * block].iter().sum();
    }
}

/// `Q_S(u) = -(1/γ) ln ψ(u)` (Theorem 1: ψ approximates `exp(-γ Q_S)`), floored log.
pub fn q_s(psi: &[f64], gamma: f64) -> Vec<f64> {
    let mut out = vec![0.0; psi.len()];
    q_s_into(psi, gamma, &mut out);
    out
}

/// [`q_s`] into `out`.
pub fn q_s_into(psi: &[f64], gamma: f64, out: &mut [f64]) {
    for (o, p) in out.iter_mut().zip(psi) {
        *o = -ln(*p) / gamma;
    }
}

/// Preallocated EFE tree evaluator for a fixed (n_states, n_obs, n_actions, H).
///
/// [`EfeTree::evaluate`] computes every node. [`EfeTree::evaluate_reusing`] also keeps,
/// for every internal node, the predicted belief and accumulated `G` it was computed
/// with, and skips a node's subtree when both are bit for bit those of the previous
/// evaluation (its leaves' `G` are then still in [`EfeTree::g`]): exact reuse of work
/// between ticks whose belief has not changed, or whose predictions meet again.
#[derive(Debug, Clone)]
pub struct EfeTree {
    n_states: usize,
    n_actions: usize,
    horizon: usize,
    /// `bufs[k]` is the predicted state belief at depth k (bufs[0] = q_t).
    bufs: Vec<Vec<f64>>,
    step: StepScratch,
    /// `crashed[k]`: the mass that crashed in the first k steps of the current branch.
    crashed: Vec<f64>,
    /// `q_t` of the last evaluation (the root), for [`EfeTree::evaluate_reusing`].
    memo_root: Vec<f64>,
    /// Per internal node (depths 1..H-1, breadth-first): its predicted belief...
    memo_s: Vec<f64>,
    /// ...its accumulated `G`...
    memo_g: Vec<f64>,
    /// ...and its crashed mass.
    memo_c: Vec<f64>,
    /// Whether the memo describes the last evaluation.
    memo_valid: bool,
    /// `G(π)` per policy, lexicographic.
    pub g: Vec<f64>,
    /// `q(π)`.
    pub q_pi: Vec<f64>,
    /// `ψ(u)`.
    pub psi: Vec<f64>,
    /// Predictions `B[u] s` computed by the last evaluation (`U + ... + U^H` unless reused).
    pub matvecs: usize,
    /// Predictions the last [`EfeTree::evaluate_reusing`] did not need to compute.
    pub reused: usize,
}

impl EfeTree {
    /// Buffers for `n_states` states, `n_obs` observations, `n_actions` actions, horizon `H >= 1`.
    pub fn new(n_states: usize, n_obs: usize, n_actions: usize, horizon: usize) -> Self {
        let horizon = horizon.max(1);
        let np = n_actions.pow(horizon as u32);
        let internal: usize = (1..horizon).map(|k| n_actions.pow(k as u32)).sum();
        EfeTree {
            n_states,
            n_actions,
            horizon,
            bufs: vec![vec![0.0; n_states]; horizon + 1],
            step: StepScratch::new(n_states, n_obs),
            crashed: vec![0.0; horizon + 1],
            memo_root: vec![0.0; n_states],
            memo_s: vec![0.0; internal * n_states],
            memo_g: vec![0.0; internal],
            memo_c: vec![0.0; internal],
            memo_valid: false,
            g: vec![0.0; np],
            q_pi: vec![0.0; np],
            psi: vec![0.0; n_actions],
            matvecs: 0,
            reused: 0,
        }
    }

    /// Horizon H.
    pub fn horizon(&self) -> usize {
        self.horizon
    }

    /// Evaluate `G`, `q(π)` and `ψ` from `q_t` with precision `γ` (§IV, Prop. 1, Cor. 1):
    /// the first step through `root`'s `B`, the later ones through `gm`'s (module docs).
    /// Pass the same model twice for one model throughout.
    pub fn evaluate(&mut self, gm: &GenerativeModel, root: &GenerativeModel, q_t: &[f64], gamma: f64) {
        self.memo_valid = false;
        self.run(gm, root, q_t, gamma, false);
    }

    /// [`EfeTree::evaluate`], reusing the subtrees of the previous call whose root belief
    /// and accumulated `G` are bit for bit the same (the results are those of
    /// [`EfeTree::evaluate`], bit for bit). The caller promises that `gm` is the model of
    /// the previous call, unchanged, unless it called [`EfeTree::invalidate`] since.
    pub fn evaluate_reusing(&mut self, gm: &GenerativeModel, root: &GenerativeModel, q_t: &[f64], gamma: f64) {
        self.run(gm, root, q_t, gamma, true);
    }

    /// Forget the previous evaluation (call when the model changes).
    pub fn invalidate(&mut self) {
        self.memo_valid = false;
    }

    fn run(&mut self, gm: &GenerativeModel, root: &GenerativeModel, q_t: &[f64], gamma: f64, reuse: bool) {
        self.matvecs = 0;
        self.reused = 0;
        let unchanged = reuse && self.memo_valid && same_bits(&self.memo_root, q_t);
        if unchanged {
            self.reused = self.below(0);
        } else {
            self.bufs[0].copy_from_slice(q_t);
            self.recurse(gm, root, 0, 0.0, 0, reuse);
            if reuse {
                self.memo_root.copy_from_slice(q_t);
                self.memo_valid = true;
            }
        }
        q_pi_into(&self.g, gamma, &mut self.q_pi);
        psi_into(&self.q_pi, self.n_actions, &mut self.psi);
    }

    /// Nodes in a subtree whose root sits at `depth` (the root itself not counted).
    fn below(&self, depth: usize) -> usize {
        (1..=self.horizon - depth).map(|k| self.n_actions.pow(k as u32)).sum()
    }

    fn recurse(
        &mut self,
        gm: &GenerativeModel,
        root: &GenerativeModel,
        depth: usize,
        g_acc: f64,
        idx: usize,
        reuse: bool,
    ) {
        let n = self.n_states;
        let step_model = if depth == 0 { root } else { gm };
        for u in 0..self.n_actions {
            let (lo, hi) = self.bufs.split_at_mut(depth + 1);
            let (g, crashed) = self
                .step
                .step(gm, step_model, u, &lo[depth], &mut hi[0], g_acc, self.crashed[depth]);
            self.crashed[depth + 1] = crashed;
            self.matvecs += 1;
            let child = idx * self.n_actions + u;
            if depth + 1 == self.horizon {
                self.g[child] = g;
                continue;
            }
            if reuse {
                // Internal nodes are numbered breadth-first: depth d starts after U + ... + U^(d-1).
                let node = (1..depth + 1).map(|k| self.n_actions.pow(k as u32)).sum::<usize>() + child;
                let (ms, mg, mc) = (
                    &mut self.memo_s[node * n..(node + 1) * n],
                    &mut self.memo_g[node],
                    &mut self.memo_c[node],
                );
                let crashed = self.crashed[depth + 1];
                if self.memo_valid
                    && mg.to_bits() == g.to_bits()
                    && mc.to_bits() == crashed.to_bits()
                    && same_bits(ms, &self.bufs[depth + 1])
                {
                    self.reused += self.below(depth + 1);
                    continue;
                }
                ms.copy_from_slice(&self.bufs[depth + 1]);
                *mg = g;
                *mc = crashed;
            }
            self.recurse(gm, root, depth + 1, g, child, reuse);
        }
    }
}

/// Scratch of one step of a branch of the EFE tree ([`StepScratch::step`]), shared by the
/// tree and the competence check's held policies ([`crate::competence`]).
#[derive(Debug, Clone)]
pub struct StepScratch {
    obuf: Vec<f64>,
    scratch: Vec<f64>,
    /// The belief masked to a [`crate::model::TransitionCost`]'s `from` states, and its
    /// prediction.
    masked: Vec<f64>,
    masked_next: Vec<f64>,
    /// The part of a belief that does not crash in the step ([`crate::model::CrashModel`]).
    survive: Vec<f64>,
}

impl StepScratch {
    /// Scratch for `n_states` states and `n_obs` observations.
    pub fn new(n_states: usize, n_obs: usize) -> StepScratch {
        StepScratch {
            obuf: vec![0.0; n_obs],
            scratch: vec![0.0; n_states],
            masked: vec![0.0; n_states],
            masked_next: vec![0.0; n_states],
            survive: vec![0.0; n_states],
        }
    }

    /// One step of a policy (Prop. 1): from belief `from`, after `crashed` mass has
    /// crashed on the branch so far, action `u` through `step_model`'s `B` into `to`.
    /// Returns `G` accumulated to `g` with the step's risk and ambiguity under `gm`'s
    /// preferences, its crash risk ([`crate::model::CrashModel`]) and its transition cost,
    /// and the crashed mass after the step. With a crash model the crashing part of the
    /// belief leaves the drive first.
    #[allow(clippy::too_many_arguments)]
    pub fn step(
        &mut self,
        gm: &GenerativeModel,
        step_model: &GenerativeModel,
        u: usize,
        from: &[f64],
        to: &mut [f64],
        g: f64,
        crashed: f64,
    ) -> (f64, f64) {
        let hit = match &gm.crash {
            Some(cm) => {
                let hit = cm.split(u, from, &mut self.survive);
                step_model.transition_into(u, &self.survive, to, &mut self.scratch);
                hit
            }
            None => {
                step_model.transition_into(u, from, to, &mut self.scratch);
                0.0
            }
        };
        let crashed = crashed + hit;
        let (r, a) = step_efe(gm, to, &mut self.obuf);
        let mut g = g + r + a;
        if let Some(cm) = &gm.crash {
            g += cm.risk(crashed);
        }
        if step_model.transition_cost.is_some() {
            g += step_model.transition_cost_of(u, from, &mut self.masked, &mut self.masked_next, &mut self.scratch);
        }
        (g, crashed)
    }

    /// One step of a feedback policy: from belief `from`, the mass in each state `s` takes
    /// action `act[s]` (a state-feedback policy, as a habit is; with one action everywhere
    /// this is [`StepScratch::step`]'s step). Each action's part of the belief crashes,
    /// pays the transition cost and moves through `step_model`'s `B` on its own; `to` is
    /// their sum, and the step's risk and ambiguity are those of `to` under `gm`'s
    /// preferences. Returns as [`StepScratch::step`]. `part` and `next` are scratch of
    /// `n_states`.
    #[allow(clippy::too_many_arguments)]
    pub fn step_feedback(
        &mut self,
        gm: &GenerativeModel,
        step_model: &GenerativeModel,
        act: &[usize],
        from: &[f64],
        to: &mut [f64],
        (part, next): (&mut [f64], &mut [f64]),
        g: f64,
        crashed: f64,
    ) -> (f64, f64) {
        to.fill(0.0);
        let (mut hit, mut cost) = (0.0, 0.0);
        for u in 0..gm.n_actions() {
            let mut any = false;
            for ((p, x), a) in part.iter_mut().zip(from).zip(act) {
                *p = if *a == u { *x } else { 0.0 };
                any |= *p != 0.0;
            }
            if !any {
                continue;
            }
            if step_model.transition_cost.is_some() {
                cost +=
                    step_model.transition_cost_of(u, part, &mut self.masked, &mut self.masked_next, &mut self.scratch);
            }
            if let Some(cm) = &gm.crash {
                hit += cm.split(u, part, &mut self.survive);
                part.copy_from_slice(&self.survive);
            }
            step_model.transition_into(u, part, next, &mut self.scratch);
            to.iter_mut().zip(next.iter()).for_each(|(t, n)| *t += n);
        }
        let crashed = crashed + hit;
        let (r, a) = step_efe(gm, to, &mut self.obuf);
        let mut g = g + r + a;
        if let Some(cm) = &gm.crash {
            g += cm.risk(crashed);
        }
        (g + cost, crashed)
    }
}

/// Whether two slices hold the same bits.
fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::maths::log_softmax;
    use nalgebra::DMatrix;

    /// `evaluate_reusing` gives `evaluate`'s bits whether it reuses everything (same
    /// belief), some subtrees (a belief whose predictions are the same: states 0 and 1 have
    /// the same columns in every `B[u]`), or nothing; `invalidate` forgets the memo.
    #[test]
    fn reusing_subtrees_gives_the_same_bits() {
        let (ns, nu) = (5, 3);
        let b: Vec<DMatrix<f64>> = (0..nu)
            .map(|u| {
                DMatrix::from_fn(ns, ns, |i, j| {
                    let j = j.max(1); // columns 0 and 1 are equal
                    1.0 + ((i * 7 + j * 3 + u * 5) % 11) as f64
                })
            })
            .map(|m| {
                let z = m.row_sum();
                DMatrix::from_fn(ns, ns, |i, j| m[(i, j)] / z[j])
            })
            .collect();
        let c = log_softmax(&[0.5, -1.0, 2.0, 0.0, -3.0]);
        let gm = GenerativeModel::new(DMatrix::identity(ns, ns), b, c, vec![0.2; ns]);
        let beliefs = [
            vec![0.25, 0.25, 0.3, 0.1, 0.1],
            vec![0.25, 0.25, 0.3, 0.1, 0.1],
            // 0.25 c + 0.25 c and 0.5 c are the same bits: the same predictions.
            vec![0.5, 0.0, 0.3, 0.1, 0.1],
            vec![0.5, 0.1, 0.1, 0.2, 0.1],
        ];
        let mut plain = EfeTree::new(ns, ns, nu, 3);
        let mut memo = EfeTree::new(ns, ns, nu, 3);
        let mut reused = Vec::new();
        for q in &beliefs {
            plain.evaluate(&gm, &gm, q, 1.5);
            memo.evaluate_reusing(&gm, &gm, q, 1.5);
            for (a, b) in plain.g.iter().zip(&memo.g).chain(plain.psi.iter().zip(&memo.psi)) {
                assert_eq!(a.to_bits(), b.to_bits());
            }
            assert_eq!(memo.matvecs + memo.reused, plain.matvecs);
            reused.push(memo.reused);
        }
        // Nothing, everything, the subtrees below depth 1, nothing.
        assert_eq!(reused, vec![0, 39, 36, 0]);
        memo.invalidate();
        memo.evaluate_reusing(&gm, &gm, &beliefs[3], 1.5);
        assert_eq!(memo.reused, 0);
    }
}
