//! Issue 20: test-time learning must never make the agent less safe. With several
//! jaywalkers per episode at random times (maps/crowd.ron), the hand-back rule `θ <= ε`
//! alone let learning make a pedestrian at (green, d = 2) familiar from the ticks the car
//! waited there, and then handed the approach at speed, where the habit still sped up, to
//! the habit; and reasoning that only learning triggered, where the habit was safe, put
//! the car at the crosswalk later, in front of the next walker (agent/src/handback.rs).
//!
//! On agents trained by the library's training (the shared test agent, 600 episodes of the
//! embedded intersection; and, ignored in debug builds, the agent `unforeseen train --seed
//! 7` writes), over continual episodes of that map: no episode the agent without learning
//! survives is lost, and reasoning falls as it learns. Under the `hand-back-checked`
//! ablation, which takes every reasoning tick learning made, the shared test agent loses 11
//! of these 40 episodes (EXPERIMENTS.md, "The safe hand-back"). The default
//! (`decline-learned`) never reasons with nobody on the crosswalk.

use std::sync::OnceLock;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_env::{Env, EnvConfig};
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::episodes::{EpisodeResult, run_episode};
use unforeseen_harness::episodes::{Method, scaled_agent};
use unforeseen_harness::episodes::{eval_seeds, run_agent_episodes};
use unforeseen_harness::fixtures;
use unforeseen_harness::progress::NoProgress;
use unforeseen_harness::training::{DEFAULT_TRAIN_EPISODES, TrainConfig, train};

/// The agent `unforeseen train --seed 7` writes.
fn full_agent() -> &'static AgentBundle {
    static BUNDLE: OnceLock<AgentBundle> = OnceLock::new();
    BUNDLE.get_or_init(|| {
        let map = unforeseen_harness::maps::load("intersection").expect("embedded map");
        train(&map, &TrainConfig::new(DEFAULT_TRAIN_EPISODES, 7))
            .expect("training")
            .0
    })
}

const EPISODES: u64 = 40;

fn crowd() -> unforeseen_sim::Map {
    unforeseen_harness::maps::load_file(&fixtures::repo_path("maps/crowd.ron")).expect("maps/crowd.ron")
}

fn run(bundle: &AgentBundle, method: Method, protocol: Protocol, params: &ScaledParams) -> Vec<EpisodeResult> {
    run_agent_episodes(protocol, &crowd(), bundle, params, method, EPISODES, 7, &NoProgress).unwrap()
}

/// Episodes the agent without learning survives and `learning` loses (both meet the same
/// pedestrians: the world's seed depends on the map and the episode only).
fn lost(without: &[EpisodeResult], learning: &[EpisodeResult]) -> Vec<usize> {
    (0..without.len())
        .filter(|&k| without[k].success && !learning[k].success)
        .collect()
}

fn check_learning_loses_nothing(bundle: &AgentBundle) {
    let params = ScaledParams::default();
    let without = run(bundle, Method::ScaledNoLearning, Protocol::ZeroShot, &params);
    let learning = run(bundle, Method::Scaled, Protocol::Continual, &params);
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

#[test]
fn learning_loses_no_crowd_episode_that_the_test_agent_without_learning_survives() {
    check_learning_loses_nothing(fixtures::bundle());
}

#[test]
#[ignore = "trains a full agent (6000 episodes); run with --release -- --ignored"]
fn learning_loses_no_crowd_episode_that_the_full_agent_without_learning_survives() {
    check_learning_loses_nothing(full_agent());
}

/// Per episode of a continual run of the shared test agent on `map` with hand-back rule
/// `handback`, per tick: (reasoned, declined, θ, a pedestrian on the crosswalk).
fn continual_ticks(map: &unforeseen_sim::Map, handback: &str, episodes: u64) -> Vec<Vec<(bool, bool, f64, bool)>> {
    continual_ticks_with(map, &[("handback", handback)], episodes)
}

/// [`continual_ticks`] with the parameters `settings` (key, value) changed.
fn continual_ticks_with(
    map: &unforeseen_sim::Map,
    settings: &[(&str, &str)],
    episodes: u64,
) -> Vec<Vec<(bool, bool, f64, bool)>> {
    let mut params = ScaledParams::default();
    for (key, value) in settings {
        params.set_str(key, value).unwrap();
    }
    let mut agent = scaled_agent(fixtures::bundle(), params).unwrap();
    let mut env = Env::new(map, EnvConfig::default()).unwrap();
    (0..episodes)
        .map(|ep| {
            let (_, trace) = run_episode(&mut env, &mut agent, eval_seeds(7, map, Method::Scaled, ep), true).unwrap();
            trace
                .iter()
                .zip(agent.declined_history())
                .map(|(t, declined)| (t.reasoned, *declined, t.theta.unwrap(), t.state.p == 1))
                .collect()
        })
        .collect()
}

/// Under `risk-checked`, a tick the learned trigger fires on only because of test-time
/// learning goes to the habit where the check finds the habit safe: such ticks exist once
/// the agent has learned (never in the first episode), each has `θ > ε` and did not
/// reason; the ablation `hand-back-checked` declines none.
#[test]
fn triggers_only_learning_made_go_to_a_safe_habit() {
    let epsilon = ScaledParams::default().gate.epsilon;
    let episodes = continual_ticks(&crowd(), "risk-checked", 15);
    assert!(
        episodes[0].iter().all(|(_, declined, _, _)| !declined),
        "nothing learned yet"
    );
    let declined: Vec<_> = episodes.iter().flatten().filter(|(_, d, _, _)| *d).collect();
    assert!(
        !declined.is_empty(),
        "the crowd makes the gate fire where the trained one would not"
    );
    for (reasoned, _, theta, _) in declined {
        assert!(!reasoned && *theta > epsilon, "theta {theta}, reasoned {reasoned}");
    }
    let ablation = continual_ticks(&crowd(), "hand-back-checked", 15);
    assert!(ablation.iter().flatten().all(|(_, d, _, _)| !d));
}

/// Reasoning ticks over 40 continual episodes on `map` (a file or an embedded name) whose
/// true state has nobody on the crosswalk, with the parameters `settings` changed.
fn empty_road_reasoning(map: &str, settings: &[(&str, &str)]) -> usize {
    let map = unforeseen_harness::maps::load(map).unwrap();
    let episodes = continual_ticks_with(&map, settings, 40);
    episodes
        .iter()
        .flatten()
        .filter(|(reasoned, _, _, pedestrian)| *reasoned && !pedestrian)
        .count()
}

/// `decline-learned` (issue 20's "no reasoning on ticks without a pedestrian"): over 40
/// continual episodes the gate and the hand-back never make the agent reason with nobody
/// on the crosswalk, on the training map and on slow_walker, under either crash model,
/// where `risk-checked` with the paper's crash-risk states does (it takes the reasoning
/// learning made wherever the check finds the habit at risk). The competence check is off
/// here: it reasons on empty roads by design, where the habit would not arrive or would
/// run a red (docs/ARCHITECTURE.md §4.11).
#[test]
fn decline_learned_never_reasons_on_an_empty_road() {
    let slow_walker = fixtures::repo_path("maps/slow_walker.ron").display().to_string();
    for crash in ["hazard", "states"] {
        for map in ["intersection", slow_walker.as_str()] {
            let settings = [
                ("handback", "decline-learned"),
                ("crash_model", crash),
                ("competence", "surprise-only"),
            ];
            assert_eq!(empty_road_reasoning(map, &settings), 0, "{map}, {crash}");
        }
    }
    let settings = [
        ("handback", "risk-checked"),
        ("crash_model", "states"),
        ("competence", "surprise-only"),
    ];
    assert!(empty_road_reasoning(&slow_walker, &settings) > 0);
}
