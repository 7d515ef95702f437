//! Whole-system benchmarks: one physics decision step and one jaywalk episode (each also
//! with the car driven by forces),
//! training throughput, and the closed loop (world + discretizer + scaled agent) at
//! 10 Hz decisions / 60 Hz physics.
//!
//! Run with `cargo bench --features bench --bench loop`. See BENCHMARKS.md for the figures.

use criterion::{BatchSize, Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::{Duration, Instant};
use unforeseen_agent::controller::Controller;
use unforeseen_agent::params::{CompetenceCheck, ScaledParams};
use unforeseen_agent::persist::AgentBundle;
use unforeseen_env::{Env, EnvConfig};
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::eval_seeds;
use unforeseen_harness::episodes::run_episode;
use unforeseen_harness::training::train;
use unforeseen_sim::{Action, Dynamics, Map, World, embedded};

mod common;
use common::{agent, bundle, criterion_config, train_cfg};

/// The map with the car driven by forces (`dynamics: Forces`, the default parameters).
fn with_forces(mut map: Map) -> Map {
    map.vehicle.dynamics = Dynamics::Forces;
    map
}

/// `physics_decision_step`: one `World::step` on the intersection map (the physics alone,
/// below `Env`) (decision_dt 1 s
/// at 60 Hz = 60 Rapier sub-steps, plus lights, spawns and events). The car speeds up
/// on the first tick and then holds its speed; a finished world is rebuilt untimed.
/// Side by side: `ideal` (velocity control, the paper's) and `forces` (the force model).
fn physics_decision_step(c: &mut Criterion) {
    let ideal = embedded::load("intersection").expect("map");
    let forces = with_forces(ideal.clone());
    let mut g = c.benchmark_group("physics_decision_step");
    for (name, map) in [("ideal", &ideal), ("forces", &forces)] {
        g.bench_function(name, |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                let mut world = World::from_map(map, 0);
                let mut seed = 0;
                let mut k = 0;
                for _ in 0..iters {
                    if world.is_done() {
                        seed += 1;
                        world = World::from_map(map, seed);
                        k = 0;
                    }
                    let action = if k == 0 { Action::SpeedUp } else { Action::Maintain };
                    let t = Instant::now();
                    black_box(world.step(black_box(action)));
                    total += t.elapsed();
                    k += 1;
                }
                total
            })
        });
    }
    g.finish();
}

/// `env_step`: one `Env::step` on the same map and actions as `physics_decision_step`:
/// the world's step plus the snapshot, the discretizer, the reward's terms and the info
/// (its difference to `physics_decision_step` is what the episode API costs per tick).
fn env_step(c: &mut Criterion) {
    let map = embedded::load("intersection").expect("map");
    let mut env = Env::new(&map, EnvConfig::default()).expect("env");
    c.bench_function("env_step", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut seed = 0;
            env.reset(seed);
            let mut k = 0;
            for _ in 0..iters {
                if env.is_done() {
                    seed += 1;
                    env.reset(seed);
                    k = 0;
                }
                let action = if k == 0 { Action::SpeedUp } else { Action::Maintain };
                let t = Instant::now();
                black_box(env.step(black_box(action.index())).expect("action"));
                total += t.elapsed();
                k += 1;
            }
            total
        })
    });
}

/// `episode`: one jaywalk episode (`run_episode`, no recording) of a fresh scaled agent
/// built from the trained bundle (construction untimed), including its end-of-episode
/// test-time learning. Side by side: the default agent, the paper's (the competence
/// check off), and the default agent on jaywalk with the car driven by forces.
fn episode(c: &mut Criterion, bundle: &AgentBundle) {
    let map = embedded::load("jaywalk").expect("map");
    let forces = with_forces(map.clone());
    let mut env = Env::new(&map, EnvConfig::default()).expect("env");
    let mut forces_env = Env::new(&forces, EnvConfig::default()).expect("env");
    let params = ScaledParams::default();
    let seeds = eval_seeds(7, &map, Method::Scaled, 0);
    let mut probe = Method::Scaled.controller(bundle, &params, &map).expect("controller");
    let (r, _) = run_episode(&mut env, probe.as_mut(), seeds, false).expect("episode");
    eprintln!(
        "episode: {} ticks, {} reasoning, return {:.1}, success {}",
        r.ticks, r.reasoning_ticks, r.ret, r.success
    );
    // Side by side: the default agent, and the paper's (the competence check off).
    let mut paper = ScaledParams::default();
    paper.gate.competence = CompetenceCheck::SurpriseOnly;
    let mut g = c.benchmark_group("episode");
    for (name, params) in [("default", &params), ("surprise_only", &paper)] {
        g.bench_function(name, |b| {
            b.iter_batched(
                || Method::Scaled.controller(bundle, params, &map).expect("controller"),
                |mut ctl| run_episode(&mut env, ctl.as_mut(), seeds, false).expect("episode"),
                BatchSize::SmallInput,
            )
        });
    }
    let forces_seeds = eval_seeds(7, &forces, Method::Scaled, 0);
    g.bench_function("forces", |b| {
        b.iter_batched(
            || Method::Scaled.controller(bundle, &params, &forces).expect("controller"),
            |mut ctl| run_episode(&mut forces_env, ctl.as_mut(), forces_seeds, false).expect("episode"),
            BatchSize::SmallInput,
        )
    });
    g.finish();
}

/// `training_throughput`: `train` for 100 episodes on the intersection map
/// (Q-learning + world model + flat and factored Bayesian RL, as the default run does).
fn training_throughput(c: &mut Criterion) {
    let map = embedded::load("intersection").expect("map");
    let cfg = train_cfg(100);
    let mut g = c.benchmark_group("training_throughput");
    g.throughput(Throughput::Elements(100));
    g.bench_function("100_episodes", |b| b.iter(|| train(&map, &cfg).expect("train")));
    g.finish();
}

/// `decision_throughput`: the closed loop on the intersection map with
/// `decision_dt = 0.1` (10 Hz decisions, 6 Rapier sub-steps per decision at 60 Hz) and
/// `max_steps = 400` (same 40 s horizon): `Env::step` (world step, snapshot, discretizer)
/// plus `ScaledAgent::act` (surprise-triggered reasoning, default parameters). One element
/// is one decision tick; episode restarts (`Env::reset`, `begin_episode`) are untimed and
/// no test-time learning runs.
fn decision_throughput(c: &mut Criterion, bundle: &AgentBundle) {
    let mut map = embedded::load("intersection").expect("map");
    map.episode.decision_dt = 0.1;
    map.episode.max_steps = 400;
    let mut env = Env::new(&map, EnvConfig::default()).expect("env");
    let mut agent = agent(bundle, ScaledParams::default());
    // Reasoning share of the loop (for the report).
    {
        let (obs, _) = env.reset(0);
        let mut obs = obs.index().expect("discrete");
        agent.begin_episode(0);
        let (mut ticks, mut reasoned) = (0, 0);
        loop {
            let d = agent.act(obs);
            ticks += 1;
            reasoned += u32::from(d.reasoned);
            let step = env.step(d.action).expect("action");
            if step.terminated || step.truncated {
                break;
            }
            obs = step.observation.index().expect("discrete");
        }
        eprintln!("decision_throughput: episode 0 has {ticks} ticks, {reasoned} reasoning");
    }
    let mut g = c.benchmark_group("decision_throughput");
    g.throughput(Throughput::Elements(1));
    g.bench_function("10hz_decisions_60hz_physics", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut seed = 0;
            let mut obs = env.reset(seed).0.index().expect("discrete");
            agent.begin_episode(seed);
            let mut t = Instant::now();
            for _ in 0..iters {
                let d = agent.act(obs);
                let step = env.step(d.action).expect("action");
                obs = step.observation.index().expect("discrete");
                if step.terminated || step.truncated {
                    total += t.elapsed();
                    seed += 1;
                    obs = env.reset(seed).0.index().expect("discrete");
                    agent.begin_episode(seed);
                    t = Instant::now();
                }
            }
            total + t.elapsed()
        })
    });
    g.finish();
}

fn benches(c: &mut Criterion) {
    let bundle = bundle();
    physics_decision_step(c);
    env_step(c);
    episode(c, &bundle);
    training_throughput(c);
    decision_throughput(c, &bundle);
}

criterion_group! {
    name = system;
    config = criterion_config();
    targets = benches
}
criterion_main!(system);
