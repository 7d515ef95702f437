//! `scaling_mode = closed-form` set by name reaches Theorem 1's closed form: on every
//! reasoning tick the policy acted upon is `π_o ψ^θ`, normalised, with no iteration.

use unforeseen_agent::controller::Controller;
use unforeseen_agent::maths::LN_FLOOR;
use unforeseen_agent::model::WorldModel;
use unforeseen_agent::params::{ModelPriors, QParams, ScaledParams, ScalingMode};
use unforeseen_agent::q_learning::QLearning;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_agent::structure::Structure;

#[test]
fn scaling_mode_closed_form_set_by_name_acts_on_the_closed_form() {
    let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
    let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
    // Some driving: each action moves the car one distance bin, at its own speed.
    for d in 1..4 {
        for (u, v) in [(0, 1), (1, 2), (2, 0)] {
            for _ in 0..5 {
                w.observe_transition(st.encode(&[d, 1, 1, 0]), u, st.encode(&[d - 1, v, 1, 0]));
            }
        }
    }
    let rewards: Vec<f64> = (0..64).map(|s| if st.decode(s)[0] == 0 { 10.0 } else { 0.0 }).collect();
    w.set_preferences(&rewards, 1.0).unwrap();
    let q = QLearning::new(64, 3, QParams::default()).unwrap();
    let mut p = ScaledParams::default();
    p.set_str("scaling_mode", "closed-form").unwrap();
    p.set_str("reasoning", "always").unwrap();
    assert_eq!(p.scaling.scaling_mode, ScalingMode::ClosedForm);
    let mut agent = ScaledAgent::new(w, &q, p).unwrap();
    agent.begin_episode(3);
    for s in (0..64).step_by(5).take(8) {
        let d = agent.act(s);
        assert!(d.reasoned && d.action < 3);
        assert_eq!(d.scaling_iters, 0, "the closed form does not iterate");
        let (th, tr) = (d.theta.unwrap(), agent.last_reasoning());
        let raw: Vec<f64> = tr
            .pi_o
            .iter()
            .zip(&tr.psi)
            .map(|(o, p)| o * p.max(LN_FLOOR).powf(th))
            .collect();
        let z: f64 = raw.iter().sum();
        for (got, want) in d.policy.iter().zip(&raw) {
            assert!((got - want / z).abs() < 1e-9, "{:?} vs {raw:?}/{z}", d.policy);
        }
    }
}
