//! Property tests (proptest) on random models, each built from a seeded ChaCha8 RNG.
#![allow(clippy::needless_range_loop)]

use nalgebra::DMatrix;
use proptest::prelude::*;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use unforeseen_agent::learning::{update_a, update_cpts, update_nu};
use unforeseen_agent::maths::{kl, log_softmax};
use unforeseen_agent::model::{CrashModel, GenerativeModel, WorldModel};
use unforeseen_agent::params::ModelPriors;
use unforeseen_agent::perception::{VmpWorkspace, free_energy, neg_log_evidence, vmp};
use unforeseen_agent::planning::{EfeTree, efe_brute_force, policies, step_efe, step_efe_long_form};
use unforeseen_agent::scaling::{scale_closed_form, scale_iterative};
use unforeseen_agent::structure::Structure;
use unforeseen_agent::surprise::{bayes_step, surprise};

fn dist(rng: &mut ChaCha8Rng, n: usize) -> Vec<f64> {
    let mut v: Vec<f64> = (0..n).map(|_| rng.random::<f64>() + 0.01).collect();
    let z: f64 = v.iter().sum();
    v.iter_mut().for_each(|x| *x /= z);
    v
}

fn random_model(seed: u64) -> GenerativeModel {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let ns = rng.random_range(2..6);
    let no = rng.random_range(2..5);
    let nu = rng.random_range(2..4);
    let mut a = DMatrix::zeros(no, ns);
    for s in 0..ns {
        for (o, p) in dist(&mut rng, no).into_iter().enumerate() {
            a[(o, s)] = p;
        }
    }
    let b = (0..nu)
        .map(|_| {
            let mut m = DMatrix::zeros(ns, ns);
            for s in 0..ns {
                for (s2, p) in dist(&mut rng, ns).into_iter().enumerate() {
                    m[(s2, s)] = p;
                }
            }
            m
        })
        .collect();
    let c: Vec<f64> = (0..no).map(|_| rng.random::<f64>() * 4.0 - 2.0).collect();
    let d = dist(&mut rng, ns);
    GenerativeModel::new(a, b, log_softmax(&c), d)
}

fn is_dist(v: &[f64]) -> bool {
    v.iter().all(|x| *x >= 0.0) && (v.iter().sum::<f64>() - 1.0).abs() < 1e-9
}

fn random_window(gm: &GenerativeModel, seed: u64, w: usize) -> (Vec<usize>, Vec<usize>, Vec<Vec<f64>>) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x9e37);
    let obs = (0..w).map(|_| rng.random_range(0..gm.n_obs())).collect();
    let acts = (0..w - 1).map(|_| rng.random_range(0..gm.n_actions())).collect();
    let qs = (0..w).map(|_| dist(&mut rng, gm.n_states())).collect();
    (obs, acts, qs)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]

    #[test]
    fn vmp_bounds_and_monotone_free_energy(seed in any::<u64>(), w in 1usize..5, kappa in 0.1f64..=1.0) {
        let gm = random_model(seed);
        let (obs, acts, mut qs) = random_window(&gm, seed, w);
        let f0 = free_energy(&gm, &gm.d, &obs, &acts, &qs);
        let mut trace = vec![f0];
        let mut cb = |f: f64| trace.push(f);
        let mut ws = VmpWorkspace::default();
        let out = vmp(&gm, &gm.d, &obs, &acts, &mut qs, kappa, 1e-10, 200, &mut ws, Some(&mut cb));
        for q in &qs { prop_assert!(is_dist(q)); }
        // Lemma 1: F >= -ln p(o_window).
        let nle = neg_log_evidence(&gm, &gm.d, &obs, &acts);
        prop_assert!(out.free_energy >= nle - 1e-9, "F {} < -ln p {}", out.free_energy, nle);
        // F never increases over sweeps (coordinate updates, any κ in (0, 1]).
        for pair in trace.windows(2) {
            prop_assert!(pair[1] <= pair[0] + 1e-10, "F increased: {:?}", pair);
        }
        // W = 1: at the fixed point, F = S_t.
        if w == 1 && out.converged {
            prop_assert!((out.free_energy - surprise(&gm, obs[0], &gm.d)).abs() < 1e-8);
            let mut exact = vec![0.0; gm.n_states()];
            bayes_step(&gm, obs[0], &gm.d, &mut exact);
            for (a, b) in exact.iter().zip(&qs[0]) { prop_assert!((a - b).abs() < 1e-8); }
        }
    }

    /// With a crash model (docs/ARCHITECTURE.md §4.3) the prefix tree still equals the
    /// brute-force rollout, and a hazard of zero everywhere changes no bit of `G`.
    #[test]
    fn crash_model_tree_equals_brute_force(seed in any::<u64>(), h in 1usize..4, gamma in 0.1f64..16.0) {
        let plain = random_model(seed);
        let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(2));
        let q = dist(&mut rng, plain.n_states());
        let (ns, nu) = (plain.n_states(), plain.n_actions());
        let floor = plain.c.iter().copied().fold(f64::INFINITY, f64::min);
        let crash = |hazard: Vec<Vec<f64>>| CrashModel { hazard, crashed: floor - 5.0, neutral: floor };
        let mut zero = plain.clone();
        zero.crash = Some(crash(vec![vec![0.0; ns]; nu]));
        let mut gm = plain.clone();
        gm.crash = Some(crash((0..nu).map(|_| (0..ns).map(|_| rng.random::<f64>()).collect()).collect()));
        let (mut t_plain, mut t_zero, mut t_crash) = (
            EfeTree::new(ns, plain.n_obs(), nu, h),
            EfeTree::new(ns, plain.n_obs(), nu, h),
            EfeTree::new(ns, plain.n_obs(), nu, h),
        );
        t_plain.evaluate(&plain, &plain, &q, gamma);
        t_zero.evaluate(&zero, &zero, &q, gamma);
        t_crash.evaluate(&gm, &gm, &q, gamma);
        for (i, p) in policies(nu, h).iter().enumerate() {
            prop_assert_eq!(t_zero.g[i].to_bits(), t_plain.g[i].to_bits());
            let bf = efe_brute_force(&gm, &q, p);
            prop_assert!((bf - t_crash.g[i]).abs() < 1e-9, "tree {} brute force {}", t_crash.g[i], bf);
        }
        prop_assert!(is_dist(&t_crash.psi));
    }

    #[test]
    fn efe_decompositions_and_prefix_tree(seed in any::<u64>(), h in 1usize..4, gamma in 0.1f64..16.0) {
        let gm = random_model(seed);
        let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(1));
        let q = dist(&mut rng, gm.n_states());
        let mut tree = EfeTree::new(gm.n_states(), gm.n_obs(), gm.n_actions(), h);
        tree.evaluate(&gm, &gm, &q, gamma);
        let pols = policies(gm.n_actions(), h);
        prop_assert_eq!(pols.len(), tree.g.len());
        let expected_matvecs: usize = (1..=h).map(|k| gm.n_actions().pow(k as u32)).sum();
        prop_assert_eq!(tree.matvecs, expected_matvecs);
        for (i, p) in pols.iter().enumerate() {
            // Prefix tree equals brute-force enumeration.
            let bf = efe_brute_force(&gm, &q, p);
            prop_assert!((bf - tree.g[i]).abs() < 1e-10);
            // G = Σ (risk + ambiguity) = Σ long form of Prop. 1's proof.
            let mut s = q.clone();
            let mut long = 0.0;
            let mut decomposed = 0.0;
            let mut obuf = vec![0.0; gm.n_obs()];
            for u in p {
                s = (&gm.b[*u] * nalgebra::DVector::from_vec(s)).as_slice().to_vec();
                long += step_efe_long_form(&gm, &s);
                let o = (&gm.a * nalgebra::DVector::from_vec(s.clone())).as_slice().to_vec();
                let c: Vec<f64> = gm.c.iter().map(|x| x.exp()).collect();
                let amb: f64 = s.iter().zip(&gm.h_a).map(|(a, b)| a * b).sum();
                decomposed += kl(&o, &c) + amb;
                let (r, a) = step_efe(&gm, &s, &mut obuf);
                prop_assert!((r - kl(&o, &c)).abs() < 1e-10 && (a - amb).abs() < 1e-10);
            }
            prop_assert!((long - tree.g[i]).abs() < 1e-9, "long {} tree {}", long, tree.g[i]);
            prop_assert!((decomposed - tree.g[i]).abs() < 1e-9);
        }
        prop_assert!(is_dist(&tree.q_pi));
        prop_assert!(is_dist(&tree.psi));
    }

    #[test]
    fn scaling_properties(seed in any::<u64>(), theta in 0.0f64..1.0, kappa in 0.05f64..=1.0, varsigma in 0.0f64..0.2) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let n = rng.random_range(2..5);
        let pi_o = dist(&mut rng, n);
        let psi = dist(&mut rng, n);
        let mut out = vec![0.0; n];
        // θ = 0 leaves π' = π_o.
        let r0 = scale_iterative(&pi_o, &psi, 0.0, kappa, varsigma, 100, &mut out, None);
        prop_assert_eq!(r0.iterations, 0);
        prop_assert_eq!(&out, &pi_o);
        // KL[π'||ψ] never increases and the stopping rule holds at exit.
        let mut trace = Vec::new();
        let r = scale_iterative(&pi_o, &psi, theta, kappa, varsigma, 10_000, &mut out, Some(&mut trace));
        prop_assert!(is_dist(&out));
        for pair in trace.windows(2) { prop_assert!(pair[1] <= pair[0] + 1e-12); }
        prop_assert!(r.stopped && r.kl_final <= r.target + 1e-15);
        // θ -> 1 (ς = 0): π' -> ψ.
        let r1 = scale_iterative(&pi_o, &psi, 1.0 - 1e-12, kappa, 0.0, 100_000, &mut out, None);
        prop_assert!(r1.kl_final < 1e-9);
        for (a, b) in out.iter().zip(&psi) { prop_assert!((a - b).abs() < 1e-4); }
        // Closed form: θ = 0 gives π_o, θ = 1 gives ∝ π_o ψ; always a distribution.
        scale_closed_form(&pi_o, &psi, theta, &mut out);
        prop_assert!(is_dist(&out));
        scale_closed_form(&pi_o, &psi, 0.0, &mut out);
        for (a, b) in out.iter().zip(&pi_o) { prop_assert!((a - b).abs() < 1e-12); }
    }

    #[test]
    fn dirichlet_updates_add_expected_counts(seed in any::<u64>(), lr in 0.1f64..3.0) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let st = Structure::paper_default([3, 2, 2, 2]).unwrap();
        let n = st.joint_size();
        let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
        let before: Vec<Vec<f64>> = (0..4).map(|f| w.cpt_counts(f).to_vec()).collect();
        // Sparse random beliefs (a few states) to keep the oracle cheap.
        let mut q_prev = vec![0.0; n];
        let mut q_next = vec![0.0; n];
        for _ in 0..3 { q_prev[rng.random_range(0..n)] += 1.0; q_next[rng.random_range(0..n)] += 1.0; }
        q_prev.iter_mut().for_each(|x| *x /= 3.0);
        q_next.iter_mut().for_each(|x| *x /= 3.0);
        let u = rng.random_range(0..3);
        update_cpts(&mut w, &q_prev, u, &q_next, lr);
        // Oracle: the same expectation computed through observe_transition on one-hot pairs.
        let mut oracle = WorldModel::new(st.clone(), 3, &ModelPriors { transition_concentration: 0.0, ..Default::default() }).unwrap();
        let mut expected: Vec<Vec<f64>> = (0..4).map(|f| vec![0.0; oracle.cpt_counts(f).len()]).collect();
        for s in 0..n { for s2 in 0..n {
            let wgt = q_prev[s] * q_next[s2] * lr;
            if wgt == 0.0 { continue; }
            let snap: Vec<Vec<f64>> = (0..4).map(|f| oracle.cpt_counts(f).to_vec()).collect();
            oracle.observe_transition(s, u, s2);
            for f in 0..4 { for (k, (a, b)) in oracle.cpt_counts(f).iter().zip(&snap[f]).enumerate() { expected[f][k] += wgt * (a - b); } }
        }}
        for f in 0..4 {
            let total: f64 = w.cpt_counts(f).iter().zip(&before[f]).map(|(a, b)| a - b).sum();
            prop_assert!((total - lr).abs() < 1e-9);
            for (k, e) in expected[f].iter().enumerate() {
                prop_assert!((w.cpt_counts(f)[k] - before[f][k] - e).abs() < 1e-12);
            }
        }
        w.materialize();
        for a in 0..3 { for s in 0..n { prop_assert!((w.b(a).column(s).sum() - 1.0).abs() < 1e-9); } }
        // A and ν counts.
        let mut a_counts = DMatrix::from_element(n, n, 1.0);
        update_a(&mut a_counts, 2, &q_prev, lr);
        let total = (n * n) as f64;
        prop_assert!((a_counts.row(2).sum() - n as f64 - lr).abs() < 1e-9 && (a_counts.sum() - total - lr).abs() < 1e-9);
        // A structural zero of A (an exact observation model's off-diagonal) stays zero.
        let mut exact = DMatrix::identity(n, n) * 1000.0;
        update_a(&mut exact, 2, &q_prev, lr);
        for s in (0..n).filter(|&s| s != 2) {
            prop_assert_eq!(exact[(2, s)], 0.0);
        }
        prop_assert!((exact[(2, 2)] - 1000.0 - lr * q_prev[2]).abs() < 1e-9);
        // ν from a one-hot policy (the action taken) and from a spread one (π' of reasoning).
        let mut nu = vec![1.0; n * 3];
        let mut one_hot = [0.0; 3];
        one_hot[u] = 1.0;
        update_nu(&mut nu, 3, &q_prev, &one_hot, lr);
        for s in 0..n {
            prop_assert!((nu[s * 3 + u] - 1.0 - lr * q_prev[s]).abs() < 1e-12);
        }
        let pi = [0.2, 0.3, 0.5];
        let mut nu = vec![1.0; n * 3];
        update_nu(&mut nu, 3, &q_prev, &pi, lr);
        prop_assert!((nu.iter().sum::<f64>() - 3.0 * n as f64 - lr).abs() < 1e-9);
        for s in 0..n {
            for (a, p) in pi.iter().enumerate() {
                prop_assert!((nu[s * 3 + a] - 1.0 - lr * q_prev[s] * p).abs() < 1e-12);
            }
        }
    }
}
