//! Micro-benchmarks of the scaled agent's ticks (issue 5): one reasoning tick per
//! horizon `H`, a feed-forward tick, the end-of-episode test-time learning update, and
//! the reasoning tick as the joint state space grows.
//!
//! Run with `cargo bench --bench agent_ticks`. See BENCHMARKS.md for the figures.

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use std::time::{Duration, Instant};
use unforeseen::training::{TrainConfig, train};
use unforeseen_agent::controller::Controller;
use unforeseen_agent::model::WorldModel;
use unforeseen_agent::params::{ModelPriors, QParams, ReasoningMode, ScaledParams};
use unforeseen_agent::persist::AgentBundle;
use unforeseen_agent::q_learning::QLearning;
use unforeseen_agent::scaled::ScaledAgent;
use unforeseen_agent::structure::{Factor, Parent, Structure};
use unforeseen_discretizer::Discretizer;
use unforeseen_sim::{Action, World, embedded};

/// Training episodes of the bench setup (the default run uses 6000).
const TRAIN_EPISODES: u64 = 1500;
/// Jaywalk-like observation: d=2, v=3, L=1 (green), p=1 (pedestrian on the crosswalk).
const JAYWALK_OBS: usize = ((2 * 4 + 3) * 2 + 1) * 2 + 1;

fn bundle() -> AgentBundle {
    let map = embedded::load("intersection").expect("embedded intersection map");
    let cfg = TrainConfig {
        quiet: true,
        ..TrainConfig::new(TRAIN_EPISODES, 7)
    };
    train(&map, &cfg).expect("training").0
}

fn agent(bundle: &AgentBundle, params: ScaledParams) -> ScaledAgent {
    ScaledAgent::new(bundle.world_model.clone(), &bundle.q_learning, params).expect("scaled agent")
}

/// `reasoning_tick/H`: `begin_episode` (untimed) then one timed `act` on the jaywalk
/// observation, with reasoning forced on every tick. This is the first tick of an
/// episode (VMP window of one observation) followed by the full EFE tree of depth H and
/// the scaling loop. `reasoning_tick_mid/H` times the 4th tick of an episode instead
/// (full VMP window of 4) after three untimed ticks on the same observation.
fn reasoning_tick(c: &mut Criterion, bundle: &AgentBundle) {
    let mut g = c.benchmark_group("reasoning_tick");
    for h in 1..=5 {
        let params = ScaledParams {
            reasoning: ReasoningMode::Always,
            horizon: h,
            ..ScaledParams::default()
        };
        let mut a = agent(bundle, params);
        g.bench_with_input(BenchmarkId::from_parameter(h), &h, |b, _| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for i in 0..iters {
                    a.begin_episode(i);
                    let t = Instant::now();
                    let d = a.act(black_box(JAYWALK_OBS));
                    total += t.elapsed();
                    assert!(d.reasoned);
                    black_box(d);
                }
                total
            })
        });
    }
    g.finish();
    let mut g = c.benchmark_group("reasoning_tick_mid");
    for h in 1..=5 {
        let params = ScaledParams {
            reasoning: ReasoningMode::Always,
            horizon: h,
            ..ScaledParams::default()
        };
        let mut a = agent(bundle, params);
        g.bench_with_input(BenchmarkId::from_parameter(h), &h, |b, _| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for i in 0..iters {
                    a.begin_episode(i);
                    for _ in 0..3 {
                        black_box(a.act(JAYWALK_OBS));
                    }
                    let t = Instant::now();
                    let d = a.act(black_box(JAYWALK_OBS));
                    total += t.elapsed();
                    black_box(d);
                }
                total
            })
        });
    }
    g.finish();
}

/// `feedforward_tick`: `act` along the learned model's most likely trajectory from the
/// intersection map's start state, every tick after the first with `θ <= ε` (asserted
/// in the setup): prediction (one column copy), surprise, exact Bayes step and the
/// `π_o` lookup. The episode restarts every `CHUNK` ticks; the restart and the first
/// tick (prior D) are untimed, the next up-to-`CHUNK` ticks are timed as one block.
fn feedforward_tick(c: &mut Criterion, bundle: &AgentBundle) {
    const CHUNK: usize = 20;
    let map = embedded::load("intersection").expect("map");
    let disc = Discretizer::new(&map.bins).expect("discretizer");
    let start = disc.encode(disc.state(&World::from_map(&map, 1).snapshot()));
    let mut a = agent(bundle, ScaledParams::default());
    // Most likely chain of observations under the learned model and the agent's actions.
    let mut chain = Vec::with_capacity(CHUNK + 1);
    a.begin_episode(0);
    let mut obs = start;
    for _ in 0..=CHUNK {
        chain.push(obs);
        let d = a.act(obs);
        let b = a.model().b(d.action);
        obs = (0..b.nrows())
            .max_by(|i, j| b[(*i, obs)].total_cmp(&b[(*j, obs)]))
            .expect("states");
    }
    a.begin_episode(0);
    let reasoned: Vec<bool> = chain.iter().map(|o| a.act(*o).reasoned).collect();
    let ff = reasoned[1..].iter().filter(|r| !**r).count();
    eprintln!(
        "feedforward_tick: start state {start}, chain {:?}, feed-forward ticks {ff}/{CHUNK} after the first",
        &chain
    );
    assert_eq!(ff, CHUNK, "every tick after the first must be feed-forward");
    c.bench_function("feedforward_tick", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut done = 0u64;
            while done < iters {
                a.begin_episode(0);
                black_box(a.act(chain[0]));
                let k = (iters - done).min(CHUNK as u64) as usize;
                let t = Instant::now();
                for o in &chain[1..=k] {
                    black_box(a.act(black_box(*o)));
                }
                total += t.elapsed();
                done += k as u64;
            }
            total
        })
    });
}

/// `learning_update`: `end_episode` (test-time learning §V: A, CPT and ν updates from
/// every tick's posterior, then `materialize`) on a cloned agent that just drove one
/// jaywalk episode (Triggered reasoning, as in evaluation). The clone is untimed.
fn learning_update(c: &mut Criterion, bundle: &AgentBundle) {
    let map = embedded::load("jaywalk").expect("map");
    let disc = Discretizer::new(&map.bins).expect("discretizer");
    let mut a = agent(bundle, ScaledParams::default());
    let mut world = World::from_map(&map, 3);
    a.begin_episode(3);
    let mut ticks = 0;
    loop {
        let o = disc.encode(disc.state(&world.snapshot()));
        let d = a.act(o);
        let out = world.step(Action::from_index(d.action).expect("action"));
        ticks += 1;
        let next = disc.encode(disc.state(&world.snapshot()));
        a.observe(0.0, next, out.done());
        if out.done() {
            break;
        }
    }
    eprintln!("learning_update: recorded jaywalk episode of {ticks} ticks");
    c.bench_function("learning_update", |b| {
        b.iter_batched(
            || a.clone(),
            |mut a| {
                a.end_episode();
                a
            },
            BatchSize::SmallInput,
        )
    });
}

/// A world model with the paper's structure over `sizes` (optionally a second
/// pedestrian factor), random transition counts, materialised, with random preferences.
fn synthetic_model(sizes: &[usize], rng: &mut ChaCha8Rng) -> WorldModel {
    let structure = if sizes.len() == 4 {
        Structure::paper_default([sizes[0], sizes[1], sizes[2], sizes[3]]).expect("structure")
    } else {
        let f = |name: &str, size, parents, action_parent| Factor {
            name: name.to_string(),
            size,
            parents,
            action_parent,
        };
        Structure::new(vec![
            f("d", sizes[0], vec![Parent::Prev(0), Parent::Next(1)], false),
            f("v", sizes[1], vec![Parent::Prev(1)], true),
            f("L", sizes[2], vec![Parent::Prev(2)], false),
            f(
                "p",
                sizes[3],
                vec![Parent::Prev(3), Parent::Next(2), Parent::Next(0)],
                false,
            ),
            f(
                "p2",
                sizes[4],
                vec![Parent::Prev(4), Parent::Next(2), Parent::Next(0)],
                false,
            ),
        ])
        .expect("structure")
    };
    let n = structure.joint_size();
    let mut m = WorldModel::new(structure, 3, &ModelPriors::default()).expect("model");
    for _ in 0..20 * n {
        let s = rng.random_range(0..n);
        let u = rng.random_range(0..3);
        let s2 = rng.random_range(0..n);
        m.observe_transition(s, u, s2);
    }
    m.materialize();
    let rewards: Vec<f64> = (0..n).map(|_| rng.random_range(-10.0..10.0)).collect();
    m.set_preferences(&rewards, 1.0).expect("preferences");
    m
}

/// `reasoning_tick_states/N_shape`: one reasoning tick (H = 2, first tick of an episode)
/// on synthetic models of growing joint size N.
fn reasoning_tick_states(c: &mut Criterion) {
    let shapes: [&[usize]; 9] = [
        &[4, 4, 2, 2],
        &[8, 4, 2, 2],
        &[16, 4, 2, 2],
        &[32, 4, 2, 2],
        &[4, 8, 2, 2],
        &[4, 16, 2, 2],
        &[4, 4, 2, 2, 2],
        &[8, 4, 2, 2, 2],
        &[16, 4, 2, 2, 2],
    ];
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let mut g = c.benchmark_group("reasoning_tick_states");
    for shape in shapes {
        let m = synthetic_model(shape, &mut rng);
        let n = m.n_states();
        let q = QLearning::new(n, 3, QParams::default());
        let params = ScaledParams {
            reasoning: ReasoningMode::Always,
            horizon: 2,
            ..ScaledParams::default()
        };
        let mut a = ScaledAgent::new(m, &q, params).expect("agent");
        let obs = n / 2 + 1;
        let label = shape.iter().map(|s| s.to_string()).collect::<Vec<_>>().join("x");
        g.bench_with_input(BenchmarkId::from_parameter(format!("{n}_{label}")), &obs, |b, obs| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                for i in 0..iters {
                    a.begin_episode(i);
                    let t = Instant::now();
                    let d = a.act(black_box(*obs));
                    total += t.elapsed();
                    black_box(d);
                }
                total
            })
        });
    }
    g.finish();
}

fn benches(c: &mut Criterion) {
    let bundle = bundle();
    reasoning_tick(c, &bundle);
    feedforward_tick(c, &bundle);
    learning_update(c, &bundle);
    reasoning_tick_states(c);
}

criterion_group! {
    name = agent_ticks;
    config = Criterion::default()
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_secs(1))
        .sample_size(20);
    targets = benches
}
criterion_main!(agent_ticks);
