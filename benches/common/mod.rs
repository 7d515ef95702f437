//! Setup shared by the bench binaries: the default trained agent and criterion's
//! configuration.

use std::time::Duration;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_harness::training::{DEFAULT_TRAIN_EPISODES, TrainConfig, train};
use unforeseen_sim::embedded;

/// Training configuration with the benches' seed 7.
pub fn train_cfg(episodes: u64) -> TrainConfig {
    TrainConfig::new(episodes, 7)
}

/// The default agent: 6000 training episodes on the embedded intersection map, seed 7 —
/// the same bundle `unforeseen export-model` (without `--agent`) exports for pymdp.
pub fn bundle() -> AgentBundle {
    let map = embedded::load("intersection").expect("embedded intersection map");
    train(&map, &train_cfg(DEFAULT_TRAIN_EPISODES)).expect("training").0
}

/// A scaled agent from the bundle with `params`.
pub fn agent(bundle: &AgentBundle, params: ScaledParams) -> ScaledAgent {
    ScaledAgent::new(bundle.world_model.clone(), &bundle.q_learning, params).expect("scaled agent")
}

/// Short measurements (1 s warm-up, 2 s, 20 samples) so the suite runs in minutes.
pub fn criterion_config() -> criterion::Criterion {
    criterion::Criterion::default()
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_secs(1))
        .sample_size(20)
}
