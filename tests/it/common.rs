//! Shared helpers for the integration tests: one small trained agent per test binary.

#![allow(dead_code)]

use std::sync::OnceLock;
use unforeseen::training::{TrainConfig, train};
use unforeseen_agent::persist::AgentBundle;

/// Training episodes for tests: enough for Q-learning to learn to drive to the goal,
/// small enough to keep `cargo test` fast.
pub const TRAIN_EPISODES: u64 = 600;

/// A small test training configuration (faster exploration decay than the default).
pub fn small_config(seed: u64) -> TrainConfig {
    let mut cfg = TrainConfig::new(TRAIN_EPISODES, seed);
    cfg.q.epsilon_decay = 0.993;
    cfg.quiet = true;
    cfg
}

/// The agent trained on the embedded intersection map with seed 7, shared.
pub fn bundle() -> &'static AgentBundle {
    static BUNDLE: OnceLock<AgentBundle> = OnceLock::new();
    BUNDLE.get_or_init(|| {
        let map = unforeseen::maps::load("intersection").expect("embedded map");
        train(&map, &small_config(7)).expect("training").0
    })
}
