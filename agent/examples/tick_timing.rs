//! Rough per-tick timing of the scaled agent on the 64-state model (criterion benches
//! live in the root crate). Run: `cargo run --release -p unforeseen-agent --example tick_timing`.
use std::time::Instant;
use unforeseen_agent::controller::Controller;
use unforeseen_agent::model::WorldModel;
use unforeseen_agent::params::{ModelPriors, QParams, ReasoningMode, ScaledParams};
use unforeseen_agent::q_learning::QLearning;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_agent::structure::Structure;

fn main() {
    let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
    let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
    for d in 1..4 {
        for _ in 0..50 {
            for u in 0..3 {
                w.observe_transition(st.encode(&[d, 1, 1, 0]), u, st.encode(&[d - 1, 1, 1, 0]));
            }
        }
    }
    w.materialize();
    let mut d0 = vec![0.0; 64];
    d0[st.encode(&[3, 1, 1, 0])] = 1.0;
    w.set_d(&d0).unwrap();
    let q = QLearning::new(64, 3, QParams::default()).unwrap();
    for (label, mode) in [
        ("triggered (feed-forward)", ReasoningMode::Triggered),
        ("always (reasoning, H=3)", ReasoningMode::Always),
    ] {
        let mut params = ScaledParams::default();
        params.scaling.reasoning = mode;
        let mut agent = ScaledAgent::new(w.clone(), &q, params).unwrap();
        let n = 20_000;
        let obs = [
            st.encode(&[3, 1, 1, 0]),
            st.encode(&[2, 1, 1, 0]),
            st.encode(&[1, 1, 1, 0]),
        ];
        let mut reasoned = 0;
        let t0 = Instant::now();
        for i in 0..n {
            if i % 3 == 0 {
                agent.begin_episode(i as u64);
            }
            reasoned += agent.act(obs[i % 3]).reasoned as usize;
        }
        let dt = t0.elapsed().as_secs_f64() / n as f64 * 1e6;
        println!("{label}: {dt:.2} us/tick, reasoned {reasoned}/{n}");
    }
}
