//! The planning tick of the general agent (`unforeseen_agent::aif`) on the models of
//! pymdp's environments (`agent/tests/data/pymdp/`): `aif_tick/{model}/{policy_len}` times
//! `infer_states` + `infer_policies` + `sample_action` from the rollout's second
//! observation, with the gate open. `scripts/pymdp_envs_bench.py` sets these beside
//! pymdp's; see BENCHMARKS.md.
//!
//! Run with `cargo bench --features bench --bench aif`.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use serde_json::Value;
use std::hint::black_box;
use unforeseen_agent::aif::agent::{Agent, AgentParams};
use unforeseen_agent::aif::model::Model;

// The benches' shared setup; this bench takes only criterion's configuration from it.
#[allow(dead_code)]
mod common;
use common::criterion_config;

const MODELS: [(&str, &str); 4] = [
    ("tmaze", include_str!("../agent/tests/data/pymdp/tmaze.json")),
    (
        "generalized_tmaze",
        include_str!("../agent/tests/data/pymdp/generalized_tmaze.json"),
    ),
    ("grid_world", include_str!("../agent/tests/data/pymdp/grid_world.json")),
    (
        "cue_chaining",
        include_str!("../agent/tests/data/pymdp/cue_chaining.json"),
    ),
];

fn aif_tick(c: &mut Criterion) {
    let mut g = c.benchmark_group("aif_tick");
    for (name, text) in MODELS {
        let r: Value = serde_json::from_str(text).expect("reference JSON");
        let model = Model::from_json(&r["model"]).expect("model");
        let obs: Vec<usize> = serde_json::from_value(r["rollout"][1]["obs"].clone()).expect("obs");
        let first: Vec<usize> = serde_json::from_value(r["rollout"][0]["obs"].clone()).expect("obs");
        let action: Vec<usize> = serde_json::from_value(r["rollout"][0]["action"].clone()).expect("action");
        for policy_len in 1..=3 {
            let params = AgentParams {
                policy_len,
                ..AgentParams::default()
            };
            let agent = Agent::new(model.clone(), params, None).expect("agent");
            let qs0 = agent.infer_states(&first, &agent.initial_prior()).expect("qs");
            let prior = agent.update_empirical_prior(&action, &qs0).expect("prior");
            let mut rng = ChaCha8Rng::seed_from_u64(0);
            g.bench_with_input(BenchmarkId::new(name, policy_len), &policy_len, |b, _| {
                b.iter(|| {
                    let qs = agent.infer_states(black_box(&obs), &prior).expect("qs");
                    let post = agent.infer_policies(&qs);
                    black_box(agent.sample_action(&post.q_pi, &mut rng))
                })
            });
        }
    }
    g.finish();
}

criterion_group! {
    name = benches;
    config = criterion_config();
    targets = aif_tick
}
criterion_main!(benches);
