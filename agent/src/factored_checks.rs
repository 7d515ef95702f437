//! Cross-checks of the factored transition ([`crate::transition`]) against the dense
//! matrices of the world model ([`crate::model`]) and the planner's rollouts
//! ([`crate::planning`]). A test-only module of its own, so that `transition` (which
//! `model` uses) does not depend on `model` or `planning`, even in its tests.

use crate::model::WorldModel;
use crate::params::ModelPriors;
use crate::structure::Structure;
use crate::transition::LogBScratch;
use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn random_model(structure: Structure, seed: u64, terminal: &[usize]) -> WorldModel {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n = structure.joint_size();
    let mut w = WorldModel::new(structure, 3, &ModelPriors::default()).unwrap();
    for _ in 0..20 * n {
        let (s, a, s2) = (rng.random_range(0..n), rng.random_range(0..3), rng.random_range(0..n));
        w.observe_transition(s, a, s2);
    }
    w.set_terminal_states(terminal).unwrap();
    w
}

#[test]
fn cost_is_n_times_the_sum_of_sizes() {
    let w = random_model(Structure::paper_default([4, 4, 2, 2]).unwrap(), 1, &[]);
    let ft = w.generative().factored.as_ref().unwrap();
    assert_eq!(ft.cost(), 64 * (4 + 4 + 2 + 2));
}

fn dense_apply(m: &nalgebra::DMatrix<f64>, x: &[f64]) -> Vec<f64> {
    (0..m.nrows())
        .map(|i| (0..m.ncols()).map(|j| m[(i, j)] * x[j]).sum())
        .collect()
}

/// With a fifth factor (a second pedestrian `p2 <- (p2, L', d')`) the factored
/// product still equals the definition.
#[test]
fn five_factor_structure_matches_the_definition() {
    let st = Structure::new(crate::transition::tests::five_factors()).unwrap();
    let w = random_model(st, 9, &[0, 50]);
    let x: Vec<f64> = (0..72).map(|i| (i as f64 + 1.0) / (72.0 * 73.0 / 2.0)).collect();
    let mut out = vec![0.0; 72];
    let mut scratch = Vec::new();
    for u in 0..3 {
        let gm = w.generative();
        gm.factored.as_ref().unwrap().apply(u, &x, &mut out, &mut scratch);
        let want = dense_apply(&w.b_by_definition()[u], &x);
        for (a, b) in out.iter().zip(&want) {
            assert!((a - b).abs() < 1e-14, "{a} vs {b}");
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    /// The factored `ln B` (forward and backward messages, `F`'s quadratic form) equals
    /// the dense floored `ln B` to rounding, for random sizes, counts and beliefs; the
    /// model attaches it to the generative model (no entry of these `B` is under the floor).
    #[test]
    fn factored_log_b_equals_dense_ln_b(
        sizes in prop::array::uniform4(1usize..5),
        seed in 0u64..1000,
        u in 0usize..3,
    ) {
        let st = Structure::paper_default(sizes).unwrap();
        let n = st.joint_size();
        let w = random_model(st, seed, &[]);
        let gm = w.generative();
        let lb = gm.log_factored.as_ref().expect("every B entry is above the floor");
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
        let mut draw = || {
            let mut x: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
            let z: f64 = x.iter().sum();
            x.iter_mut().for_each(|v| *v /= z);
            x
        };
        let (qa, qb) = (draw(), draw());
        let ln_b = &gm.ln_b[u];
        let (mut out, mut scratch) = (vec![0.0; n], LogBScratch::default());
        lb.forward(u, &qa, &mut out, &mut scratch);
        for (i, o) in out.iter().enumerate() {
            let want: f64 = (0..n).map(|j| ln_b[(i, j)] * qa[j]).sum();
            prop_assert!((o - want).abs() < 1e-12 * want.abs().max(1.0), "{o} vs {want}");
        }
        lb.backward(u, &qb, &mut out, &mut scratch);
        for (j, o) in out.iter().enumerate() {
            let want: f64 = (0..n).map(|i| ln_b[(i, j)] * qb[i]).sum();
            prop_assert!((o - want).abs() < 1e-12 * want.abs().max(1.0), "{o} vs {want}");
        }
        let want: f64 = (0..n).map(|i| (0..n).map(|j| qb[i] * ln_b[(i, j)] * qa[j]).sum::<f64>()).sum();
        let got = lb.quadratic(u, &qb, &qa, &mut scratch);
        prop_assert!((got - want).abs() < 1e-12 * want.abs().max(1.0), "{got} vs {want}");
    }

    /// The factor-by-factor product equals the dense joint `B[u] x` (and the planning
    /// model's absorbing `B[u] x`) for random sizes, counts, beliefs and terminal sets.
    #[test]
    fn factored_equals_dense(
        sizes in prop::array::uniform4(1usize..5),
        seed in 0u64..1000,
        u in 0usize..3,
        n_terminal in 0usize..4,
    ) {
        let st = Structure::paper_default(sizes).unwrap();
        let n = st.joint_size();
        let terminal: Vec<usize> = (0..n_terminal.min(n)).map(|i| (i * 7 + seed as usize) % n).collect();
        let w = random_model(st, seed, &terminal);
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0xabc);
        let mut x: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
        let z: f64 = x.iter().sum();
        x.iter_mut().for_each(|v| *v /= z);
        let mut scratch = Vec::new();
        // The oracle: B entry by entry from the CPT means, and its absorbing version.
        let b = &w.b_by_definition()[u];
        let mut b_plan = b.clone();
        for &t in &terminal {
            b_plan.column_mut(t).fill(0.0);
            b_plan[(t, t)] = 1.0;
        }
        for (gm, oracle) in [(w.generative(), b), (w.planning_generative(), &b_plan)] {
            let ft = gm.factored.as_ref().unwrap();
            let mut out = vec![0.0; n];
            ft.apply(u, &x, &mut out, &mut scratch);
            let want = dense_apply(oracle, &x);
            for (a, b) in out.iter().zip(&want) {
                prop_assert!((a - b).abs() < 1e-14, "{a} vs {b}");
            }
            prop_assert!((out.iter().sum::<f64>() - 1.0).abs() < 1e-12);
            // The materialised dense B is the same matrix.
            prop_assert!((&gm.b[u] - oracle).amax() < 1e-15);
        }
    }

    /// The EFE tree on a factored planning model (which predicts factor by factor)
    /// equals the brute-force rollout through the dense `B` (§IV, eq. "EFE_0").
    #[test]
    fn efe_tree_with_factored_b_equals_dense_rollout(seed in 0u64..1000, h in 1usize..4) {
        let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
        let mut w = random_model(st, seed, &[5, 17, 60]);
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let r: Vec<f64> = (0..64).map(|_| rng.random::<f64>() * 10.0 - 5.0).collect();
        w.set_preferences(&r, 1.0).unwrap();
        let mut q: Vec<f64> = (0..64).map(|_| rng.random::<f64>()).collect();
        let z: f64 = q.iter().sum();
        q.iter_mut().for_each(|v| *v /= z);
        let gm = w.planning_generative();
        let mut tree = crate::planning::EfeTree::new(64, 64, 3, h);
        tree.evaluate(gm, gm, &q, 1.0);
        for (i, p) in crate::planning::policies(3, h).iter().enumerate() {
            let bf = crate::planning::efe_brute_force(gm, &q, p);
            prop_assert!((bf - tree.g[i]).abs() < 1e-10, "{:?}: {bf} vs {}", p, tree.g[i]);
        }
    }
}
