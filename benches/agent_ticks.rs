//! Micro-benchmarks of the scaled agent's ticks: one reasoning tick per
//! horizon `H`, the reasoning ticks of real episodes replayed (`unforeseen_harness::episodes::tick_recording`), a feed-forward
//! tick, the end-of-episode test-time learning update, and the reasoning tick as the
//! joint state space grows.
//!
//! Run with `cargo bench --features bench --bench agent_ticks`. See BENCHMARKS.md for the figures.

use criterion::{BatchSize, BenchmarkId, Criterion, criterion_group, criterion_main};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;
use std::time::{Duration, Instant};
use unforeseen_agent::controller::{Controller, Ending};
use unforeseen_agent::model::WorldModel;
use unforeseen_agent::params::{CompetenceCheck, GateMode, ModelPriors, QParams, ReasoningMode, ScaledParams};
use unforeseen_agent::persist::AgentBundle;
use unforeseen_agent::q_learning::QLearning;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_agent::structure::{Factor, Parent, Structure};
use unforeseen_env::{Env, EnvConfig};
use unforeseen_harness::episodes::{TickTimes, jaywalk_family, record};
use unforeseen_sim::embedded;

mod common;
use common::{agent, bundle, criterion_config};

/// Jaywalk-like observation: d=2, v=3, L=1 (green), p=1 (pedestrian on the crosswalk).
const JAYWALK_OBS: usize = ((2 * 4 + 3) * 2 + 1) * 2 + 1;

/// `reasoning_tick/H`: `begin_episode` (untimed) then one timed `act` on the jaywalk
/// observation, with reasoning forced on every tick. This is the first tick of an
/// episode (VMP window of one observation) followed by the full EFE tree of depth H and
/// the scaling loop. `reasoning_tick_mid/H` times the 4th tick of an episode instead
/// (full VMP window of 4) after three untimed ticks on the same observation; its belief
/// is then bit for bit the 3rd tick's, so the EFE tree reuses the previous tick's whole
/// tree (`EfeTree::evaluate_reusing`) and this measures VMP and scaling. For what
/// reasoning ticks cost in episodes, see `reasoning_tick_replay/H`.
fn reasoning_tick(c: &mut Criterion, bundle: &AgentBundle) {
    for (group, untimed_ticks) in [("reasoning_tick", 0), ("reasoning_tick_mid", 3)] {
        let mut g = c.benchmark_group(group);
        for h in 1..=5 {
            let mut params = ScaledParams::default();
            params.scaling.reasoning = ReasoningMode::Always;
            params.planning.horizon = h;
            let mut a = agent(bundle, params);
            g.bench_with_input(BenchmarkId::from_parameter(h), &h, |b, _| {
                b.iter_custom(|iters| {
                    let mut total = Duration::ZERO;
                    for i in 0..iters {
                        a.begin_episode(i);
                        for _ in 0..untimed_ticks {
                            black_box(a.act(JAYWALK_OBS));
                        }
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
    }
}

/// Evaluation episodes per map recorded for `reasoning_tick_replay` (seed 7, zero-shot).
const REPLAY_EPISODES: u64 = 10;

/// `reasoning_tick_replay/H`: the reasoning ticks the scaled agent (default parameters,
/// horizon H) really meets in zero-shot evaluation episodes on the jaywalk family of
/// maps (`unforeseen_harness::episodes::tick_recording`: 10 episodes per map, `eval`'s seeds for seed 7), replayed
/// one episode after the other on one agent; only the reasoning ticks are timed, each
/// alone (VMP over its real window, the EFE tree with the reuse of the previous tick's
/// subtrees, scaling). One iteration is one reasoning tick; criterion's figure is the
/// mean over the ticks of a sample. The setup also prints the distribution over ticks
/// (median, p10-p90), each tick the fastest of 5 replays.
fn reasoning_tick_replay(c: &mut Criterion, bundle: &AgentBundle) {
    let maps = jaywalk_family().expect("jaywalk family");
    let mut g = c.benchmark_group("reasoning_tick_replay");
    for h in 1..=5 {
        let mut params = ScaledParams::default();
        params.planning.horizon = h;
        let rec = record(bundle, &params, &maps, REPLAY_EPISODES, 7).expect("recording");
        let mut a = agent(bundle, params);
        let mut fastest: Option<TickTimes> = None;
        let mut digest = 0;
        for _ in 0..5 {
            let mut t = TickTimes::default();
            digest = rec.replay(&mut a, |r, e| t.push(r, e)).digest;
            match &mut fastest {
                None => fastest = Some(t),
                Some(f) => f
                    .reasoning_ns
                    .iter_mut()
                    .zip(&t.reasoning_ns)
                    .for_each(|(f, t)| *f = (*f).min(*t)),
            }
        }
        let fastest = fastest.unwrap_or_default();
        eprintln!(
            "reasoning_tick_replay/{h}: {} episodes on {} maps ({} successful), {} ticks, {} reasoning, digest {digest:016x}; per reasoning tick (fastest of 5 replays): {}",
            rec.episodes.len(),
            maps.len(),
            rec.episodes.iter().filter(|e| e.success).count(),
            rec.ticks(),
            rec.reasoning_ticks(),
            fastest.reasoning()
        );
        g.bench_with_input(BenchmarkId::from_parameter(h), &h, |b, _| {
            let mut episode = 0;
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                let mut done = 0u64;
                while done < iters {
                    rec.replay_one(episode, &mut a, |reasoned, elapsed| {
                        if reasoned && done < iters {
                            total += elapsed;
                            done += 1;
                        }
                    });
                    episode = (episode + 1) % rec.episodes.len();
                }
                total
            })
        });
    }
    g.finish();
}

/// `feedforward_tick`: `act` on the feed-forward path (`θ <= ε`: prediction by one
/// column copy, surprise, exact Bayes step, `π_o` lookup; no VMP, no planning).
/// The observations are those of a real intersection episode driven by the agent with
/// default parameters; for the timing, ε is raised to 0.999 so that every tick of the
/// replay after the first takes the feed-forward path (asserted in the setup); the code
/// path is the same one a default tick with `θ <= ε` takes. The episode restarts every
/// replay; the restart and the first tick (prior D) are untimed, the rest is timed as
/// one block.
fn feedforward_tick(c: &mut Criterion, bundle: &AgentBundle) {
    let map = embedded::load("intersection").expect("map");
    let mut env = Env::new(&map, EnvConfig::default()).expect("env");
    let mut probe = agent(bundle, ScaledParams::default());
    let mut o = env.reset(1).0.index().expect("discrete");
    probe.begin_episode(1);
    let mut chain = Vec::new();
    let mut natural_ff = 0;
    loop {
        chain.push(o);
        let d = probe.act(o);
        natural_ff += usize::from(!d.reasoned);
        let step = env.step(d.action).expect("action");
        if step.terminated || step.truncated {
            break;
        }
        o = step.observation.index().expect("discrete");
    }
    // The paper's feed-forward tick: no surprise reaches ε, and no competence check.
    let mut never = ScaledParams::default();
    never.gate.epsilon = 0.999;
    never.gate.competence = CompetenceCheck::SurpriseOnly;
    let mut a = agent(bundle, never);
    a.begin_episode(0);
    let ff = chain.iter().map(|o| a.act(*o)).skip(1).filter(|d| !d.reasoned).count();
    eprintln!(
        "feedforward_tick: intersection episode of {} ticks {:?}, {natural_ff} feed-forward at default epsilon, {ff}/{} after the first at epsilon 0.999",
        chain.len(),
        &chain,
        chain.len() - 1
    );
    assert_eq!(ff, chain.len() - 1, "every tick after the first must be feed-forward");
    let len = chain.len() - 1;
    c.bench_function("feedforward_tick", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            let mut done = 0u64;
            while done < iters {
                a.begin_episode(0);
                black_box(a.act(chain[0]));
                let k = (iters - done).min(len as u64) as usize;
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
    let mut env = Env::new(&map, EnvConfig::default()).expect("env");
    let mut a = agent(bundle, ScaledParams::default());
    let mut o = env.reset(3).0.index().expect("discrete");
    a.begin_episode(3);
    let mut ticks = 0;
    loop {
        let d = a.act(o);
        let step = env.step(d.action).expect("action");
        ticks += 1;
        o = step.observation.index().expect("discrete");
        let ending = Ending::from_flags(step.terminated, step.truncated);
        a.observe(step.reward, o, ending);
        if ending.is_over() {
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

/// The paper's structure over `sizes` (`[d, v, L, p]`), with a fifth entry a second
/// pedestrian factor `p2 <- (p2, L', d')`.
fn paper_structure(sizes: &[usize]) -> Structure {
    let base = Structure::paper_default([sizes[0], sizes[1], sizes[2], sizes[3]]).expect("structure");
    if sizes.len() == 4 {
        return base;
    }
    let mut factors = base.factors().to_vec();
    factors.push(Factor {
        name: "p2".into(),
        size: sizes[4],
        parents: vec![Parent::Prev(4), Parent::Next(2), Parent::Next(0)],
        action_parent: false,
    });
    Structure::new(factors).expect("structure")
}

/// A world model of `structure` with random transition counts and preferences.
fn synthetic_model(structure: Structure, rng: &mut ChaCha8Rng) -> WorldModel {
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

/// `reasoning_tick_states/{factored,dense}/N_shape`: one reasoning tick (H = 3, first
/// tick of an episode) on synthetic models of growing joint size N: `factored` has the
/// paper's structure (predictions factor by factor), `dense` is the flat joint model of
/// the same N (one factor `s' <- (s, u)`, dense `N x N` predictions).
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
        let factored = paper_structure(shape);
        let n = factored.joint_size();
        let label = shape.iter().map(|s| s.to_string()).collect::<Vec<_>>().join("x");
        let models = [
            ("factored", factored),
            ("dense", Structure::flat(n).expect("flat structure")),
        ];
        for (kind, structure) in models {
            let m = synthetic_model(structure, &mut rng);
            assert_eq!(m.generative().factored.is_some(), kind == "factored");
            let q = QLearning::new(n, 3, QParams::default()).expect("Q-table");
            // The flat model has no pedestrian factor to gate on or to pool (reasoning is
            // forced anyway): one-step gate, no persistence pooling.
            let mut params = ScaledParams::default();
            params.scaling.reasoning = ReasoningMode::Always;
            if kind == "dense" {
                params.gate.mode = GateMode::OneStep;
                params.planning.persistence_ignores = String::new();
            }
            let mut a = ScaledAgent::new(m, &q, params).expect("agent");
            let obs = n / 2 + 1;
            g.bench_with_input(BenchmarkId::new(kind, format!("{n}_{label}")), &obs, |b, obs| {
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
    }
    g.finish();
}

fn benches(c: &mut Criterion) {
    let bundle = bundle();
    reasoning_tick(c, &bundle);
    reasoning_tick_replay(c, &bundle);
    feedforward_tick(c, &bundle);
    learning_update(c, &bundle);
    reasoning_tick_states(c);
}

criterion_group! {
    name = agent_ticks;
    config = criterion_config();
    targets = benches
}
criterion_main!(agent_ticks);
