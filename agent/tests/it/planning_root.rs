//! The EFE tree's first step from `q_t` goes through the learned `B`, the later steps
//! through the planning model's, where the episode-ending states are absorbing
//! (`planning` module docs). Checked against a rollout written out step by step, and
//! against the old single-model tree, in which a car observed in a crash-risk state
//! saw every action end alike.

use unforeseen_agent::model::WorldModel;
use unforeseen_agent::params::ModelPriors;
use unforeseen_agent::planning::{EfeTree, efe_brute_force, policies, step_efe};
use unforeseen_agent::structure::Structure;

/// The paper's 4-factor model with its ego dynamics learned (speed up / maintain / slow
/// down change v by +1 / 0 / -1; d falls by one bin at v = 3), the pedestrian staying,
/// and two episode-ending states: arrival-like `stop` and the crash-risk `risk`.
fn model() -> (WorldModel, usize, usize) {
    let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
    let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
    for _ in 0..30 {
        for d in 1..4 {
            for v in 0..4 {
                for (u, dv) in [(0, 0i32), (1, 1), (2, -1)] {
                    let v2 = (v as i32 + dv).clamp(0, 3) as usize;
                    let d2 = if v2 == 3 { d - 1 } else { d };
                    w.observe_transition(st.encode(&[d, v, 1, 1]), u, st.encode(&[d2, v2, 1, 1]));
                }
            }
        }
    }
    // Crash-risk: a pedestrian on the crosswalk (d = 1) while the car moves.
    let risk = st.encode(&[1, 1, 1, 1]);
    let terminal: Vec<usize> = (0..64)
        .filter(|&s| {
            let x = st.decode(s);
            x[0] == 0 || (x[0] == 1 && x[1] > 0 && x[3] == 1)
        })
        .collect();
    w.set_terminal_states(&terminal).unwrap();
    let rewards: Vec<f64> = (0..64)
        .map(|s| {
            if terminal.contains(&s) && st.decode(s)[0] == 1 {
                -25.0
            } else {
                0.0
            }
        })
        .collect();
    w.set_preferences(&rewards, 1.0).unwrap();
    let safe = st.encode(&[1, 0, 1, 1]);
    (w, risk, safe)
}

#[test]
fn first_step_is_learned_later_steps_absorb() {
    let (w, risk, safe) = model();
    let (plan, live) = (w.planning_generative(), w.generative());
    for root in [risk, safe] {
        let mut q = vec![0.0; 64];
        q[root] = 1.0;
        let mut tree = EfeTree::new(64, 64, 3, 3);
        tree.evaluate(plan, live, &q, 1.0);
        let mut obuf = vec![0.0; 64];
        for (i, p) in policies(3, 3).iter().enumerate() {
            // s_1 = B_live[π_1] q_t, then the planning model for π_2, π_3.
            let s1: Vec<f64> = (0..64)
                .map(|r| (0..64).map(|c| live.b[p[0]][(r, c)] * q[c]).sum())
                .collect();
            let (risk1, amb1) = step_efe(plan, &s1, &mut obuf);
            let expected = risk1 + amb1 + efe_brute_force(plan, &s1, &p[1..]);
            assert!(
                (tree.g[i] - expected).abs() < 1e-10,
                "{p:?}: {} vs {expected}",
                tree.g[i]
            );
        }
        let total: f64 = tree.psi.iter().sum();
        assert!((total - 1.0).abs() < 1e-12);
    }
}

#[test]
fn braking_out_of_a_crash_risk_state_counts() {
    let (w, risk, _) = model();
    let mut q = vec![0.0; 64];
    q[risk] = 1.0;
    // Old behaviour: one absorbing model throughout; the root never moves, so every
    // first action has the same G and psi is uniform.
    let mut old = EfeTree::new(64, 64, 3, 3);
    old.evaluate(w.planning_generative(), w.planning_generative(), &q, 1.0);
    for p in &old.psi {
        assert!((p - 1.0 / 3.0).abs() < 1e-12, "{:?}", old.psi);
    }
    // Now: slowing down (action 2) leaves the crash-risk state and is preferred.
    let mut tree = EfeTree::new(64, 64, 3, 3);
    tree.evaluate(w.planning_generative(), w.generative(), &q, 1.0);
    assert!(tree.psi[2] > 0.9, "{:?}", tree.psi);
}
