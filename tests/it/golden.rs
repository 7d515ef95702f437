//! Golden digests: a few trajectories and decisions, hashed bit for bit, so that no
//! refactoring can change what an agent learns or decides without this test saying so
//! (in the spirit of rapier's snapshot-portability test). A digest covers, per tick, the
//! true and the observed state, the action, whether it reasoned, the surprise, theta, the
//! policy, psi and the reward as exact bits, and the car's position and speed; and the
//! trained agent's tables.
//!
//! When a change is meant to alter behaviour, the new digests are printed by the failing
//! assertion; update them in the same commit and say why in its message.

use crate::common;
use std::fmt::Write;
use unforeseen::experiments::trace;
use unforeseen::methods::Method;
use unforeseen::protocol::Protocol;
use unforeseen::runner::{EpisodeResult, Tick};
use unforeseen::seeds::content_hash;
use unforeseen_agent::params::ScaledParams;

fn bits(x: f64) -> String {
    format!("{:016x}", x.to_bits())
}

fn opt_bits(x: Option<f64>) -> String {
    x.map_or_else(|| "-".into(), bits)
}

fn push_episode(out: &mut String, result: &EpisodeResult, ticks: &[Tick]) {
    for t in ticks {
        let _ = write!(
            out,
            "{} {:?} {:?} {} {} {} {} [",
            t.step,
            t.state,
            t.observed,
            t.action.index(),
            t.reasoned,
            opt_bits(t.surprise),
            opt_bits(t.theta)
        );
        for p in &t.policy {
            out.push_str(&bits(*p));
        }
        out.push_str("] [");
        for p in t.psi.iter().flatten() {
            out.push_str(&bits(*p));
        }
        let _ = writeln!(
            out,
            "] {} {} {} {}",
            bits(t.reward),
            bits(t.snapshot.car_x),
            bits(t.snapshot.car_speed),
            t.snapshot.pedestrians.len()
        );
    }
    let _ = writeln!(
        out,
        "= {} {} {} {} {} {} {}",
        bits(result.ret),
        result.success,
        result.collision,
        result.timeout,
        result.ticks,
        result.reasoning_ticks,
        opt_bits(result.jaywalk_surprise)
    );
}

/// The trained agent's tables (Q-table, world-model counts, Bayesian-RL counts), without
/// its metadata.
fn agent_digest() -> String {
    let mut bundle = common::bundle().clone();
    bundle.meta.clear();
    content_hash(bundle.to_ron_string().as_bytes())
}

/// Every method's episodes 0..3 on `map` zero-shot, and the scaled agent's episode 5 of a
/// continual run (after learning from episodes 0..5).
fn episodes_digest(map: &unforeseen_sim::Map) -> String {
    let bundle = common::bundle();
    let params = ScaledParams::default();
    let mut out = String::new();
    let methods = [
        Method::QLearning,
        Method::BayesRl,
        Method::Scaled,
        Method::ScaledNoLearning,
        Method::BrakeOnPedestrian,
        Method::NeverBrake,
    ];
    for method in methods {
        for ep in 0..3 {
            let (result, ticks) = trace(bundle, &params, method, map, 7, Protocol::ZeroShot, ep).unwrap();
            let _ = writeln!(out, "{} {ep}", method.name());
            push_episode(&mut out, &result, &ticks);
        }
    }
    let (result, ticks) = trace(bundle, &params, Method::Scaled, map, 7, Protocol::Continual, 5).unwrap();
    out.push_str("scaled continual 5\n");
    push_episode(&mut out, &result, &ticks);
    content_hash(out.as_bytes())
}

/// The jaywalk with observation noise, so the noisy observation path is covered too.
fn noisy_jaywalk() -> unforeseen_sim::Map {
    let text = "Map(base: \"jaywalk\", name: \"noisy_jaywalk\", bins: (observation_noise: 0.1))";
    let embedded = |base: &str| {
        let name = base.strip_suffix(".ron").unwrap_or(base);
        unforeseen_sim::embedded::source(name).map(|t| (format!("embedded:{name}"), t.to_string()))
    };
    unforeseen_sim::Map::from_str_named("noisy_jaywalk.ron", text, &embedded).expect("valid map")
}

#[test]
fn trained_agent_and_decisions_are_unchanged() {
    let agent = agent_digest();
    let intersection = episodes_digest(&unforeseen::maps::load("intersection").unwrap());
    let jaywalk = episodes_digest(&unforeseen::maps::load("jaywalk").unwrap());
    let noisy = episodes_digest(&noisy_jaywalk());
    let got = [agent.as_str(), intersection.as_str(), jaywalk.as_str(), noisy.as_str()];
    assert_eq!(got, GOLDEN, "agent, intersection, jaywalk, noisy jaywalk digests");
}

/// Digests of [`trained_agent_and_decisions_are_unchanged`]: the agent, then the episodes
/// on the intersection, the jaywalk and the noisy jaywalk.
const GOLDEN: [&str; 4] = [
    "10356990b4c98627",
    "72e903b779f23fb4",
    "fd86969ccbedd97b",
    "35e3e279adc323a8",
];
