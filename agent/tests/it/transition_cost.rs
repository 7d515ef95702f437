//! The preference over transitions (`TransitionCost`, the red-light rule of
//! docs/ARCHITECTURE.md §4.3) in the expected free energy, hand-worked.

use nalgebra::DMatrix;
use unforeseen_agent::maths::log_softmax;
use unforeseen_agent::model::{GenerativeModel, TransitionCost};
use unforeseen_agent::planning::{EfeTree, efe_brute_force, policies};

/// Two states, "before the edge on red" (0) and "past it on red" (1); "go" (action 0)
/// moves 0 -> 1 with probability 0.8, "stop" (1) never. With the rule at 100 nats, a step
/// of "go" from state 0 costs 0.8 x 100 = 80 beside its risk, "stop" nothing; the tree
/// agrees with the brute-force rollout on every policy, and the planner stops.
#[test]
fn the_transition_cost_enters_g_as_hand_worked() {
    let go = DMatrix::from_row_slice(2, 2, &[0.2, 0.0, 0.8, 1.0]);
    let stop = DMatrix::identity(2, 2);
    let c = log_softmax(&[0.0, 0.0]);
    let plain = GenerativeModel::new(DMatrix::identity(2, 2), vec![go, stop], c, vec![1.0, 0.0]);
    let mut gm = plain.clone();
    gm.transition_cost = Some(TransitionCost {
        from: vec![true, false],
        to: vec![false, true],
        cost: 100.0,
    });
    let (mut a, mut b, mut scratch) = (vec![0.0; 2], vec![0.0; 2], Vec::new());
    assert!((gm.transition_cost_of(0, &[1.0, 0.0], &mut a, &mut b, &mut scratch) - 80.0).abs() < 1e-12);
    assert_eq!(gm.transition_cost_of(1, &[1.0, 0.0], &mut a, &mut b, &mut scratch), 0.0);
    assert_eq!(gm.transition_cost_of(0, &[0.0, 1.0], &mut a, &mut b, &mut scratch), 0.0);
    assert_eq!(
        plain.transition_cost_of(0, &[1.0, 0.0], &mut a, &mut b, &mut scratch),
        0.0
    );
    let q = [1.0, 0.0];
    assert!((efe_brute_force(&gm, &q, &[0]) - efe_brute_force(&plain, &q, &[0]) - 80.0).abs() < 1e-9);
    let mut tree = EfeTree::new(2, 2, 2, 2);
    tree.evaluate(&gm, &gm, &q, 0.5);
    for (i, p) in policies(2, 2).iter().enumerate() {
        let bf = efe_brute_force(&gm, &q, p);
        assert!(
            (tree.g[i] - bf).abs() < 1e-9,
            "{p:?}: tree {} brute force {bf}",
            tree.g[i]
        );
    }
    // go, go: 80 on the first step, then 0.2 x 0.8 x 100 = 16 on the second.
    assert!((tree.g[0] - efe_brute_force(&plain, &q, &[0, 0]) - 96.0).abs() < 1e-9);
    // stop, go: 0.8 x 100 on the second step.
    assert!((tree.g[2] - efe_brute_force(&plain, &q, &[1, 0]) - 80.0).abs() < 1e-9);
    assert!(tree.psi[1] > 0.99, "the planner stops: {:?}", tree.psi);
    // Reusing the tree gives the same bits.
    let g = tree.g.clone();
    tree.evaluate_reusing(&gm, &gm, &q, 0.5);
    tree.evaluate_reusing(&gm, &gm, &q, 0.5);
    assert_eq!(g, tree.g);
}
