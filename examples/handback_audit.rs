//! Audits the scaled agent over a long continual run on one map (issue 20, EXPERIMENTS.md
//! "The safe hand-back"): reasoning ticks with and without a pedestrian on the crosswalk,
//! how many of the former the competence check made, ticks the hand-back check refused,
//! learned triggers it declined, reasoning per block of 50 episodes, and what drifts:
//! the gate's table `P(p = 1 | L, d)`, the habit's total counts `Σ ν` and its largest
//! state's `Σ_u ν[s, u]`, and the largest off-diagonal `P(o | s)` of `A`, every 50 episodes.
//!
//! ```sh
//! cargo build --release --example handback_audit
//! target/release/examples/handback_audit AGENT.ron MAP [EPISODES] [key=value ...]
//! ```
//!
//! Prints one JSON object. Episodes are seeded as `eval --seed 7` seeds them.

use std::path::Path;

use unforeseen_agent::params::ScaledParams;
use unforeseen_env::{Env, EnvConfig};
use unforeseen_harness::episodes::eval_seeds;
use unforeseen_harness::episodes::run_episode;
use unforeseen_harness::episodes::{Method, scaled_agent};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        return Err("usage: handback_audit AGENT.ron MAP [EPISODES] [key=value ...]".into());
    }
    let bundle = unforeseen_harness::training::agent_file::load(Path::new(&args[1]))?;
    let map = unforeseen_harness::maps::load(&args[2])?;
    let episodes: u64 = args.get(3).map_or(Ok(200), |s| s.parse())?;
    let mut params = ScaledParams::default();
    for kv in args.iter().skip(4) {
        let (k, v) = kv.split_once('=').ok_or("expected key=value")?;
        params.set_str(k, v)?;
    }
    let mut agent = scaled_agent(&bundle, params)?;
    let mut env = Env::new(&map, EnvConfig::default())?;
    let (mut ticks, mut reasoning, mut reasoning_no_pedestrian, mut refused, mut successes) =
        (0u64, 0u64, 0u64, 0u64, 0u64);
    let mut checked_no_pedestrian = 0u64;
    let mut declined = 0u64;
    let mut empty_reasoning = Vec::new();
    let mut per_episode = Vec::new();
    let mut drift = Vec::new();
    let snapshot = |agent: &unforeseen_agent::scaled_agent::ScaledAgent, episode: u64| {
        let table: Vec<Vec<f64>> = agent
            .gate()
            .map(|g| {
                (0..2)
                    .map(|l| (0..4).map(|d| g.probability(1, &[l, d])).collect())
                    .collect()
            })
            .unwrap_or_default();
        serde_json::json!({"episode": episode, "p_pedestrian_by_L_d": table, "nu_total": agent.nu().iter().sum::<f64>(),
            "nu_largest_state": agent.nu().chunks(3).map(|r| r.iter().sum::<f64>()).fold(0.0, f64::max),
            "a_largest_off_diagonal": largest_off_diagonal(agent.model().generative())})
    };
    for ep in 0..episodes {
        if ep % 50 == 0 {
            drift.push(snapshot(&agent, ep));
        }
        let (result, trace) = run_episode(&mut env, &mut agent, eval_seeds(7, &map, Method::Scaled, ep), true)?;
        ticks += u64::from(result.ticks);
        reasoning += u64::from(result.reasoning_ticks);
        for t in trace.iter().filter(|t| t.reasoned && t.state.p == 0) {
            reasoning_no_pedestrian += 1;
            let refused = agent.refused_history()[t.step as usize];
            let checked = agent.checked_history()[t.step as usize];
            checked_no_pedestrian += u64::from(checked);
            empty_reasoning.push(serde_json::json!({
                "episode": ep, "step": t.step, "state": [t.state.d, t.state.v, t.state.l, t.state.p],
                "theta": t.theta, "policy": t.policy, "refused_handback": refused, "competence_check": checked,
            }));
        }
        refused += agent.refused_history().iter().filter(|r| **r).count() as u64;
        declined += agent.declined_history().iter().filter(|r| **r).count() as u64;
        successes += u64::from(result.success);
        per_episode.push(result.reasoning_ticks);
    }
    drift.push(snapshot(&agent, episodes));
    let blocks: Vec<f64> = per_episode
        .chunks(50)
        .map(|c| f64::from(c.iter().sum::<u32>()) / c.len() as f64)
        .collect();
    println!(
        "{}",
        serde_json::json!({
            "map": map.name, "episodes": episodes, "successes": successes, "ticks": ticks,
            "reasoning_ticks": reasoning, "reasoning_ticks_without_pedestrian": reasoning_no_pedestrian,
            "of_them_by_the_competence_check": checked_no_pedestrian,
            "reasoning_without_pedestrian": empty_reasoning, "refused_handbacks": refused, "declined_triggers": declined, "reasoning_per_episode_by_50": blocks, "drift": drift,
        })
    );
    Ok(())
}

/// The largest `P(o | s)` with `o != s`: 0 for an exact observation model.
fn largest_off_diagonal(gm: &unforeseen_agent::model::GenerativeModel) -> f64 {
    let a = &gm.a;
    let mut largest = 0.0f64;
    for s in 0..a.ncols() {
        for o in (0..a.nrows()).filter(|&o| o != s) {
            largest = largest.max(a[(o, s)]);
        }
    }
    largest
}
