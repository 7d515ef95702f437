//! Shared helpers for the integration tests: one small trained agent per test binary.

#![allow(dead_code)]

use std::sync::OnceLock;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_harness::training::{TrainConfig, train};

/// Training episodes for tests: enough for Q-learning to learn to drive to the goal,
/// small enough to keep `cargo test` fast.
pub const TRAIN_EPISODES: u64 = 600;

/// A small test training configuration (faster exploration decay than the default).
pub fn small_config(seed: u64) -> TrainConfig {
    let mut cfg = TrainConfig::new(TRAIN_EPISODES, seed);
    cfg.q.epsilon_decay = 0.993;
    cfg
}

/// The agent trained on the embedded intersection map with seed 7, shared.
pub fn bundle() -> &'static AgentBundle {
    static BUNDLE: OnceLock<AgentBundle> = OnceLock::new();
    BUNDLE.get_or_init(|| {
        let map = unforeseen_harness::maps::load("intersection").expect("embedded map");
        train(&map, &small_config(7)).expect("training").0
    })
}

/// An embedded map with the paper's bins (§VI): distance edges `[0, 30, 60]` m to the goal
/// in place of the default crosswalk-anchored ones (`[0, 26, 60]` on the intersection),
/// and speed edges `[1.5, 4.5, 7.5]` m/s in place of the default `[0.5, 4.5, 7.5]`.
pub fn papers_bins(name: &str) -> unforeseen_sim::Map {
    let mut map = unforeseen_harness::maps::load(name).expect("embedded map");
    map.bins.distance_edges = unforeseen_sim::DistanceEdges::Goal(vec![0.0, 30.0, 60.0]);
    map.bins.speed_edges = vec![1.5, 4.5, 7.5];
    map
}

/// The agent trained with seed 7 on the embedded intersection with the paper's distance
/// edges ([`papers_bins`]), shared.
pub fn papers_bundle() -> &'static AgentBundle {
    static BUNDLE: OnceLock<AgentBundle> = OnceLock::new();
    BUNDLE.get_or_init(|| {
        train(&papers_bins("intersection"), &small_config(7))
            .expect("training")
            .0
    })
}

/// A map file of a tiny state space (d: 3 bins, v: 2, so 24 states) on the embedded
/// intersection, with short episodes: for tests that build many agents or episodes.
pub const TINY_MAP: &str = "Map(base: \"intersection\", name: \"tiny\", bins: (distance_edges: [0.0, 45.0], speed_edges: [4.5]), episode: (max_steps: 12))";

/// The tiny map.
pub fn tiny_map() -> unforeseen_sim::Map {
    let embedded = |base: &str| {
        let name = base.strip_suffix(".ron").unwrap_or(base);
        unforeseen_sim::embedded::source(name).map(|t| (format!("embedded:{name}"), t.to_string()))
    };
    unforeseen_sim::Map::from_str_named("tiny.ron", TINY_MAP, &embedded).expect("the tiny map is valid")
}

/// An agent trained for 30 episodes on the tiny map (seed 3), as agent-file text.
pub fn tiny_agent_text() -> &'static str {
    static TEXT: OnceLock<String> = OnceLock::new();
    TEXT.get_or_init(|| {
        let cfg = TrainConfig::new(30, 3);
        train(&tiny_map(), &cfg).expect("training").0.to_ron_string()
    })
}

/// The built binary with `args`, run to completion.
pub fn run_cli(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_unforeseen"))
        .args(args)
        .output()
        .expect("run the binary")
}

/// A run's stdout then stderr, as text.
pub fn output_text(out: &std::process::Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// The run exited with `code`, did not panic, and its output contains every needle.
pub fn assert_exit(out: &std::process::Output, code: i32, needles: &[&str]) {
    let all = output_text(out);
    assert_eq!(out.status.code(), Some(code), "exit code {code} expected:\n{all}");
    assert!(!all.contains("panicked"), "panic:\n{all}");
    for n in needles {
        assert!(all.contains(n), "message should contain {n:?}:\n{all}");
    }
}
