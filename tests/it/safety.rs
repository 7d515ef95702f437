//! Issue 20: test-time learning must never make the agent less safe. With several
//! jaywalkers per episode at random times (maps/crowd.ron), the hand-back rule
//! `θ <= ε` alone let learning make a pedestrian at (green, d = 2) familiar from the
//! ticks the car waited there, and then handed the approach at speed, where the habit
//! still sped up, to the habit (agent/src/handback.rs). On an agent trained as the CLI
//! trains it (6000 episodes, seed 7), over continual episodes of that map: no episode the
//! agent without learning survives is lost, and reasoning falls as it learns.
//!
//! Ignored by default: the full training takes minutes in a debug build. Run it with
//! `cargo test --release --test it safety -- --ignored`. On the shared small test agent
//! (600 training episodes) the claim does not hold (11 of 40 crowd episodes lost that the
//! agent without learning survives; EXPERIMENTS.md, "The safe hand-back").

use std::path::Path;
use std::sync::OnceLock;
use unforeseen::experiments::evaluate_under;
use unforeseen::methods::Method;
use unforeseen::progress::NoProgress;
use unforeseen::protocol::Protocol;
use unforeseen::runner::EpisodeResult;
use unforeseen::training::{DEFAULT_TRAIN_EPISODES, TrainConfig, train};
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;

/// The agent `unforeseen train --seed 7` writes.
fn full_agent() -> &'static AgentBundle {
    static BUNDLE: OnceLock<AgentBundle> = OnceLock::new();
    BUNDLE.get_or_init(|| {
        let map = unforeseen::maps::load("intersection").expect("embedded map");
        train(&map, &TrainConfig::new(DEFAULT_TRAIN_EPISODES, 7))
            .expect("training")
            .0
    })
}

const EPISODES: u64 = 40;

fn run(method: Method, protocol: Protocol, params: &ScaledParams) -> Vec<EpisodeResult> {
    let map = unforeseen::maps::load_file(Path::new("maps/crowd.ron")).expect("maps/crowd.ron");
    evaluate_under(protocol, &map, full_agent(), params, method, EPISODES, 7, &NoProgress).unwrap()
}

/// Episodes the agent without learning survives and `learning` loses (both meet the same
/// pedestrians: the world's seed depends on the map and the episode only).
fn lost(without: &[EpisodeResult], learning: &[EpisodeResult]) -> Vec<usize> {
    (0..without.len())
        .filter(|&k| without[k].success && !learning[k].success)
        .collect()
}

#[test]
#[ignore = "trains a full agent (6000 episodes); run with --release -- --ignored"]
fn learning_loses_no_crowd_episode_that_the_agent_without_learning_survives() {
    let params = ScaledParams::default();
    let without = run(Method::ScaledNoLearning, Protocol::ZeroShot, &params);
    let learning = run(Method::Scaled, Protocol::Continual, &params);
    assert!(
        without.iter().filter(|r| r.success).count() as u64 >= EPISODES / 2,
        "the agent without learning should survive most of the crowd"
    );
    assert_eq!(lost(&without, &learning), Vec::<usize>::new());
    let ticks = |rs: &[EpisodeResult]| rs.iter().map(|r| r.reasoning_ticks).sum::<u32>();
    let (first, last) = (ticks(&learning[..10]), ticks(&learning[learning.len() - 10..]));
    assert!(
        2 * last <= first,
        "reasoning ticks, first 10 episodes {first}, last 10 {last}: should at least halve"
    );
}
