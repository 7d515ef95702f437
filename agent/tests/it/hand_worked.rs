//! Hand-worked 2-state / 2-action examples: S, F, θ, G, q(π), ψ and one scaling step.
//!
//! Model: A[o][s] = [[0.9, 0.2], [0.1, 0.8]], B[0] = identity (stay), B[1] = swap,
//! c = [0.75, 0.25] (C = ln c, already normalised), D = [0.5, 0.5], o_1 = 0.
//!
//! Surprise (§II): p(o_1=0) = 0.9*0.5 + 0.2*0.5 = 0.55, S = -ln 0.55 = 0.597837.
//! θ = 1 - exp(-0.425 * 0.597837) = 1 - exp(-0.254081) = 1 - 0.775629 = 0.224371.
//! Posterior: q = [0.45, 0.10] / 0.55 = [9/11, 2/11]; F (W = 1, exact q) = S = 0.597837.
//! H_A = [-(0.9 ln 0.9 + 0.1 ln 0.1), -(0.2 ln 0.2 + 0.8 ln 0.8)] = [0.325083, 0.500402].
//! Policy [0]: s_1 = [9/11, 2/11], o_1 = [8.5/11, 2.5/11] = [0.772727, 0.227273];
//!   risk = 0.772727 ln(0.772727/0.75) + 0.227273 ln(0.227273/0.25) = 0.023068 - 0.021662 = 0.001407;
//!   ambiguity = 9/11*0.325083 + 2/11*0.500402 = 0.356959;  G = 0.358366.
//! Policy [1]: s_1 = [2/11, 9/11], o_1 = [3.6/11, 7.4/11] = [0.327273, 0.672727];
//!   risk = 0.327273 ln(0.436364) + 0.672727 ln(2.690909) = -0.271392 + 0.665919 = 0.394527;
//!   ambiguity = 2/11*0.325083 + 9/11*0.500402 = 0.468526;  G = 0.863053.
//! γ = 0.5: q(π) = σ([-0.179183, -0.431527]) = [1/(1+e^{-0.252344}), ...] = [0.562759, 0.437241];
//! with H = 1, ψ = q(π).
//! Scaling step: π_o = [0.8, 0.2], ψ = [0.2, 0.8], κ = 0.5: ln π' = 0.5 ln π_o + 0.5 ln ψ
//!   ∝ [ln 0.4, ln 0.4] -> π' = [0.5, 0.5]. KL[π_o||ψ] = 0.6 ln 4 = 0.831777; with θ = 0.5,
//!   ς = 0 the target is 0.415888, and KL[π'||ψ] = 0.5 ln 2.5 + 0.5 ln 0.625 = 0.223144 <= target:
//!   exactly one iteration.

use nalgebra::DMatrix;
use unforeseen_agent::model::GenerativeModel;
use unforeseen_agent::perception::free_energy;
use unforeseen_agent::planning::EfeTree;
use unforeseen_agent::scaling::{scale_closed_form, scale_iterative};
use unforeseen_agent::surprise::{bayes_step, surprise, theta};

fn model() -> GenerativeModel {
    let a = DMatrix::from_row_slice(2, 2, &[0.9, 0.2, 0.1, 0.8]);
    let b0 = DMatrix::identity(2, 2);
    let b1 = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, 1.0, 0.0]);
    GenerativeModel::new(a, vec![b0, b1], vec![0.75f64.ln(), 0.25f64.ln()], vec![0.5, 0.5])
}

fn close(a: f64, b: f64, tol: f64) {
    assert!((a - b).abs() < tol, "{a} != {b}");
}

#[test]
fn surprise_theta_posterior_and_free_energy() {
    let gm = model();
    let s = surprise(&gm, 0, &gm.d);
    close(s, 0.597837, 1e-6);
    close(theta(s, 0.425), 0.224371, 1e-6);
    let mut q = vec![0.0; 2];
    bayes_step(&gm, 0, &gm.d, &mut q);
    close(q[0], 9.0 / 11.0, 1e-12);
    let f = free_energy(&gm, &gm.d, &[0], &[], &[q]);
    close(f, 0.597837, 1e-6);
}

#[test]
fn efe_q_pi_and_psi() {
    let gm = model();
    let q = [9.0 / 11.0, 2.0 / 11.0];
    let mut tree = EfeTree::new(2, 2, 2, 1);
    tree.evaluate(&gm, &gm, &q, 0.5);
    close(tree.g[0], 0.358366, 1e-5);
    close(tree.g[1], 0.863053, 1e-5);
    close(tree.q_pi[0], 0.562759, 1e-5);
    close(tree.q_pi[1], 0.437241, 1e-5);
    close(tree.psi[0], 0.562759, 1e-5);
}

#[test]
fn one_scaling_step() {
    let mut out = [0.0; 2];
    let r = scale_iterative(&[0.8, 0.2], &[0.2, 0.8], 0.5, 0.5, 0.0, 10, &mut out, None);
    assert_eq!(r.iterations, 1);
    close(out[0], 0.5, 1e-12);
    close(r.kl_initial, 0.831777, 1e-6);
    close(r.target, 0.415888, 1e-6);
    close(r.kl_final, 0.223144, 1e-6);
    assert!(r.stopped);
    // Closed form with θ = 1 and π_o uniform is ψ itself.
    scale_closed_form(&[0.5, 0.5], &[0.2, 0.8], 1.0, &mut out);
    close(out[1], 0.8, 1e-12);
}
