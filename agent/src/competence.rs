//! The competence check (beyond the paper; docs/ARCHITECTURE.md §4.11): where the surprise
//! gate leaves the habit in charge, the world model scores the habit's action first.
//!
//! The paper's agent reasons only when the world surprises it (§II) and trusts the habit
//! `π_o` everywhere else. Where the habit itself is wrong in a familiar situation (a
//! Q-table that runs a red light into a pedestrian who crosses legally; a wrapped
//! network that never starts again from a standstill), nothing is surprising and nothing
//! stops it. The check asks the world model what holding each action for `H_c` ticks
//! leads to, with the expected free energy of Prop. 1 against the agent's preferences
//! (the crash-risk states, arrival, and the red-light rule where the map's reward has it,
//! docs/ARCHITECTURE.md §4.3):
//!
//! ```text
//! G_held(u) = G(u, u, ..., u)          (H_c steps; the first through the learned B,
//!                                       the later ones through the planning model)
//! regret(a_o) = G_held(a_o) - min_u G_held(u)      (nats)
//! ```
//!
//! with `a_o` the mode of `π_o(·|q_t)`. Where `regret(a_o)` exceeds the bound, and holding
//! the best action is not predicted to crash more often than holding the habit's (the
//! agent compares with the hand-back's crash risk, so the check trades no safety for
//! progress), the agent reasons on that tick (perception, planning, scaling, as on a
//! surprising one). The
//! actions are *held*, as in the hand-back's crash-risk check ([`crate::handback`]), which
//! this generalises from the crash to every preference: a habit that holds "maintain" at a
//! standstill never arrives, however it would continue, and the tree's best continuation
//! of one "maintain" would hide that. The check's horizon can be longer than the
//! planner's, since it costs `U H_c` predictions, not `U + U² + … + U^H`: long enough to
//! see the goal from a standstill before the crosswalk.
//!
//! With `competence_rollout = feedback` the habit's own score is the better of holding its
//! action and following it (its action for `competence_commit` ticks, then its action in
//! each predicted state, [`Competence::followed_efe`]); the alternatives stay held.
//!
//! The models change only where test-time learning ends an episode, so for a one-hot belief
//! (an identity `A`, the MDP of §VI) the held scores are kept per state until then
//! ([`Competence::invalidate`]).

use crate::model::GenerativeModel;
use crate::planning::StepScratch;

/// The competence check's rollouts of held actions, with their scratch and memo.
#[derive(Debug, Clone)]
pub struct Competence {
    n_actions: usize,
    step: StepScratch,
    x: Vec<f64>,
    y: Vec<f64>,
    /// `G_held(u)` per one-hot state, `[s * n_actions + u]`; NaN where not yet computed.
    memo: Vec<f64>,
    held: Vec<f64>,
    part: Vec<f64>,
    next: Vec<f64>,
}

impl Competence {
    /// Scratch for `n_states` states, `n_obs` observations and `n_actions` actions.
    pub fn new(n_states: usize, n_obs: usize, n_actions: usize) -> Competence {
        Competence {
            n_actions,
            step: StepScratch::new(n_states, n_obs),
            x: vec![0.0; n_states],
            y: vec![0.0; n_states],
            memo: vec![f64::NAN; n_states * n_actions],
            held: vec![0.0; n_actions],
            part: vec![0.0; n_states],
            next: vec![0.0; n_states],
        }
    }

    /// Forget the memo (call when the models change).
    pub fn invalidate(&mut self) {
        self.memo.fill(f64::NAN);
    }

    /// `G` of the policy that holds `u` for `horizon` steps from belief `q`: the first step
    /// through `root`'s `B`, the later ones through `plan`'s, as the EFE tree computes the
    /// leaf of that policy ([`crate::planning::EfeTree`]; the same sums in the same order).
    pub fn held_efe(
        &mut self,
        plan: &GenerativeModel,
        root: &GenerativeModel,
        q: &[f64],
        u: usize,
        horizon: usize,
    ) -> f64 {
        self.x.copy_from_slice(q);
        let (mut g, mut crashed) = (0.0, 0.0);
        for k in 0..horizon {
            let step_model = if k == 0 { root } else { plan };
            (g, crashed) = self.step.step(plan, step_model, u, &self.x, &mut self.y, g, crashed);
            std::mem::swap(&mut self.x, &mut self.y);
        }
        g
    }

    /// `G` of the habit followed for `horizon` steps from belief `q`: its action `a` now
    /// and for the `commit - 1` steps after (the first through `root`'s `B`: the habit acts
    /// on the belief), then from each predicted state `s` the action `act[s]` it takes
    /// there, through `plan`'s ([`StepScratch::step_feedback`]). With `act[s] = a`
    /// everywhere, or `commit >= horizon`, it is [`Competence::held_efe`]'s `G`.
    pub fn followed_efe(
        &mut self,
        plan: &GenerativeModel,
        root: &GenerativeModel,
        q: &[f64],
        (a, act): (usize, &[usize]),
        (commit, horizon): (usize, usize),
    ) -> f64 {
        self.x.copy_from_slice(q);
        let (mut g, mut crashed) = (0.0, 0.0);
        for k in 0..horizon {
            let step_model = if k == 0 { root } else { plan };
            (g, crashed) = if k < commit.max(1) {
                self.step.step(plan, step_model, a, &self.x, &mut self.y, g, crashed)
            } else {
                let scratch = (self.part.as_mut_slice(), self.next.as_mut_slice());
                self.step
                    .step_feedback(plan, plan, act, &self.x, &mut self.y, scratch, g, crashed)
            };
            std::mem::swap(&mut self.x, &mut self.y);
        }
        g
    }

    /// `regret(a) = G_held(a) - min_u G_held(u)` (module docs) for belief `q`; `one_hot`,
    /// the state `q` is certain of, if any, keeps the scores until
    /// [`Competence::invalidate`].
    #[allow(clippy::too_many_arguments)]
    pub fn regret(
        &mut self,
        plan: &GenerativeModel,
        root: &GenerativeModel,
        q: &[f64],
        one_hot: Option<usize>,
        a: usize,
        horizon: usize,
    ) -> f64 {
        let na = self.n_actions;
        match one_hot {
            Some(s) if !self.memo[s * na].is_nan() => {
                self.held.copy_from_slice(&self.memo[s * na..(s + 1) * na]);
            }
            _ => {
                for u in 0..na {
                    self.held[u] = self.held_efe(plan, root, q, u, horizon);
                }
                if let Some(s) = one_hot {
                    self.memo[s * na..(s + 1) * na].copy_from_slice(&self.held);
                }
            }
        }
        let best = self.held.iter().copied().fold(f64::INFINITY, f64::min);
        self.held[a] - best
    }

    /// `G_held(u)` of every action from the last [`Competence::regret`].
    pub fn held(&self) -> &[f64] {
        &self.held
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{CrashModel, TransitionCost, WorldModel};
    use crate::params::ModelPriors;
    use crate::planning::EfeTree;
    use crate::structure::Structure;

    /// The paper's state space with some data, an arrival state and a crash-risk state as
    /// terminal states, the map's rewards as preferences, and optionally a transition
    /// cost and a crash model.
    fn model(cost: bool, crash: bool) -> WorldModel {
        let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
        let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
        for k in 0..60 {
            let (d, v): (usize, usize) = (1 + k % 3, k % 4);
            let u = k % 3;
            let v2 = match u {
                1 => (v + 1).min(3),
                2 => v.saturating_sub(1),
                _ => v,
            };
            let d2 = if v2 > 1 && k % 2 == 0 { d - 1 } else { d };
            w.observe_transition(
                st.encode(&[d, v, k % 2, (k / 3) % 2]),
                u,
                st.encode(&[d2, v2, k % 2, (k / 5) % 2]),
            );
        }
        w.materialize();
        let harm = st.encode(&[1, 1, 1, 1]);
        let goal = st.encode(&[0, 0, 1, 0]);
        w.set_terminal_states(&[harm, goal]).unwrap();
        let mut rewards = vec![0.0; 64];
        rewards[harm] = -25.0;
        rewards[goal] = 50.0;
        w.set_preferences(&rewards, 1.0).unwrap();
        if cost {
            let from = (0..64).map(|s| st.decode(s)[0] == 2 && st.decode(s)[2] == 0).collect();
            let to = (0..64).map(|s| st.decode(s)[0] == 1 && st.decode(s)[2] == 0).collect();
            w.set_transition_cost(Some(TransitionCost { from, to, cost: 100.0 }))
                .unwrap();
        }
        if crash {
            let hazard = (0..3)
                .map(|u| {
                    (0..64)
                        .map(|s| if s == harm { 0.2 + 0.3 * u as f64 } else { 0.0 })
                        .collect()
                })
                .collect();
            w.set_crash_model(Some(CrashModel {
                hazard,
                crashed: -80.0,
                neutral: -5.0,
            }))
            .unwrap();
            w.plan_with_crash_model(true);
        }
        w
    }

    fn beliefs() -> Vec<Vec<f64>> {
        let mut out = Vec::new();
        for s in [5, 21, 38, 50, 63] {
            let mut q = vec![0.0; 64];
            q[s] = 1.0;
            out.push(q);
        }
        out.push((0..64).map(|s| (1 + s % 7) as f64).map(|x| x / 256.0).collect());
        let z: f64 = out[5].iter().sum();
        out[5].iter_mut().for_each(|x| *x /= z);
        out
    }

    /// Holding an action is one of the tree's policies: with the tree's horizon, the held
    /// `G` is that leaf's, bit for bit, with and without a transition cost and a crash model.
    #[test]
    fn held_efe_is_the_trees_leaf_of_the_held_policy() {
        for (cost, crash) in [(false, false), (true, false), (false, true), (true, true)] {
            let w = model(cost, crash);
            let (plan, root) = (w.planning_generative(), w.generative());
            let mut c = Competence::new(64, 64, 3);
            for horizon in 1..=3 {
                let mut tree = EfeTree::new(64, 64, 3, horizon);
                for q in beliefs() {
                    tree.evaluate(plan, root, &q, 0.5);
                    for u in 0..3 {
                        // The policy (u, u, ..., u) in lexicographic order.
                        let leaf = (0..horizon).fold(0, |i, _| i * 3 + u);
                        let held = c.held_efe(plan, root, &q, u, horizon);
                        assert_eq!(held.to_bits(), tree.g[leaf].to_bits(), "H {horizon} u {u}");
                    }
                }
            }
        }
    }

    /// The regret is never negative, 0 for the best held action, and the memo of a
    /// one-hot belief returns what a fresh computation does until invalidated.
    #[test]
    fn regret_is_relative_to_the_best_held_action_and_the_memo_is_exact() {
        let w = model(true, false);
        let (plan, root) = (w.planning_generative(), w.generative());
        let mut memo = Competence::new(64, 64, 3);
        let mut fresh = Competence::new(64, 64, 3);
        for (i, q) in beliefs().iter().enumerate() {
            let one_hot = q.iter().position(|&x| x == 1.0);
            for a in 0..3 {
                let r = memo.regret(plan, root, q, one_hot, a, 6);
                assert!(r >= 0.0, "belief {i} action {a}: {r}");
                assert_eq!(r.to_bits(), fresh.regret(plan, root, q, None, a, 6).to_bits());
            }
            let best = (0..3)
                .min_by(|&a, &b| memo.held()[a].total_cmp(&memo.held()[b]))
                .unwrap();
            assert_eq!(memo.regret(plan, root, q, one_hot, best, 6), 0.0);
        }
        // A stale memo is kept until invalidated: a different horizon reads the old scores.
        let q = &beliefs()[0];
        let six = memo.regret(plan, root, q, Some(5), 1, 6);
        assert_eq!(memo.regret(plan, root, q, Some(5), 1, 2), six);
        memo.invalidate();
        assert_eq!(
            memo.regret(plan, root, q, Some(5), 1, 2).to_bits(),
            fresh.regret(plan, root, q, None, 1, 2).to_bits()
        );
    }

    /// Following the habit: with one action everywhere it is holding that action, bit for
    /// bit (with a transition cost and a crash model too); with the actions differing by
    /// state, two steps worked by hand: the first through the learned `B` with the action
    /// now, the second from each state with its own action, `to = Σ_s x[s] B[act[s]][·, s]`,
    /// each step adding the risk and ambiguity of its prediction (Prop. 1).
    #[test]
    fn following_the_habit_is_holding_where_it_holds_and_mixes_its_actions_elsewhere() {
        for (cost, crash) in [(false, false), (true, true)] {
            let w = model(cost, crash);
            let (plan, root) = (w.planning_generative(), w.generative());
            let mut c = Competence::new(64, 64, 3);
            for q in beliefs() {
                for u in 0..3 {
                    let held = c.held_efe(plan, root, &q, u, 5);
                    let followed = c.followed_efe(plan, root, &q, (u, &[u; 64]), (1, 5));
                    let committed = c.followed_efe(plan, root, &q, (u, &[(u + 1) % 3; 64]), (5, 5));
                    assert_eq!(committed.to_bits(), held.to_bits(), "u {u}");
                    assert_eq!(followed.to_bits(), held.to_bits(), "u {u}");
                }
            }
        }
        let w = model(false, false);
        let (plan, root) = (w.planning_generative(), w.generative());
        let act: Vec<usize> = (0..64).map(|s| s % 3).collect();
        let mut c = Competence::new(64, 64, 3);
        let mut obuf = vec![0.0; 64];
        for s0 in [5, 21, 38] {
            let first = 2;
            let x: Vec<f64> = (0..64).map(|s| root.b[first][(s, s0)]).collect();
            let to: Vec<f64> = (0..64)
                .map(|s2| (0..64).map(|s| x[s] * plan.b[act[s]][(s2, s)]).sum())
                .collect();
            let (r1, a1) = crate::planning::step_efe(plan, &x, &mut obuf);
            let (r2, a2) = crate::planning::step_efe(plan, &to, &mut obuf);
            let mut q = vec![0.0; 64];
            q[s0] = 1.0;
            let followed = c.followed_efe(plan, root, &q, (first, &act), (1, 2));
            let want = r1 + a1 + r2 + a2;
            assert!((followed - want).abs() < 1e-9, "s0 {s0}: {followed} against {want}");
            let held = c.held_efe(plan, root, &q, first, 2);
            assert!(
                (followed - held).abs() > 1e-6,
                "s0 {s0}: following differs from holding"
            );
        }
    }
}
