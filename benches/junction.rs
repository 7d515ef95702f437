//! Decisions per second on the junction with 0, 4, 10 and 20 other vehicles (and the
//! training junction's pedestrians), side by side with the straight road, in one
//! criterion group: the closed loop of `decision_throughput` (benches/loop.rs) at 10 Hz
//! decisions / 60 Hz physics, `Env::step` (world step with the IDM traffic, snapshot,
//! discretizer) plus `ScaledAgent::act`, over 40 s episodes.
//!
//! The maps: `straight` is the embedded `intersection`; `vehicles_N` the embedded
//! `junction_training` with its pedestrians (crossing on red) and `N` vehicles that
//! appear at time 0, cycling through the routes from the south, from the north, oncoming
//! and lead, 30 m before their stop line (the lead: ahead of the car) and 10 m farther
//! for each one before it on the same route. Both start on green (`light.offset:
//! Fixed(0.0)`), so the cross traffic queues at its red line for the first 14 s. The
//! rules are added in code: 20 is more than a map file may have (`MAX_SPAWN_RULES`).
//!
//! Run with `cargo bench --features bench --bench junction`. See BENCHMARKS.md.

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::time::{Duration, Instant};
use unforeseen_agent::controller::Controller;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_env::{Env, EnvConfig};
use unforeseen_sim::{Map, Route, TrafficRule, Trigger, embedded};

mod common;
use common::{agent, bundle, criterion_config};

/// The 10 Hz, 40 s, start-on-green version of an embedded map, from map text.
fn ten_hz(base: &str) -> Map {
    let text = format!(
        "Map(base: \"{base}\", name: \"{base}_10hz\", light: (offset: Fixed(0.0)), \
         episode: (decision_dt: 0.1, max_steps: 400), traffic: [])"
    );
    Map::from_str_named("bench.ron", &text, &embedded::base).expect("bench map")
}

/// The junction with `n` vehicles appearing at time 0 (module doc).
fn junction_with(n: usize) -> Map {
    let mut map = ten_hz("junction_training");
    let routes = [Route::FromSouth, Route::FromNorth, Route::Oncoming, Route::Lead];
    map.traffic = (0..n)
        .map(|k| TrafficRule {
            route: routes[k % routes.len()],
            trigger: Trigger::AtTime(0.0),
            start: 30.0 + 10.0 * (k / routes.len()) as f64,
            ..TrafficRule::default()
        })
        .collect();
    map
}

/// Mean vehicles in the world per decision tick over the first episodes of `map` with
/// the agent driving, and the ticks per episode (for the report).
fn probe(map: &Map, bundle: &AgentBundle) -> (f64, f64) {
    let mut env = Env::new(map, EnvConfig::default()).expect("env");
    let mut agent = agent(bundle, ScaledParams::default());
    let (mut ticks, mut vehicles) = (0usize, 0usize);
    let episodes = 5;
    for seed in 0..episodes {
        let mut obs = env.reset(seed).0.index().expect("discrete");
        agent.begin_episode(seed);
        loop {
            let step = env.step(agent.act(obs).action).expect("action");
            ticks += 1;
            vehicles += env.snapshot().vehicles.len();
            if step.terminated || step.truncated {
                break;
            }
            obs = step.observation.index().expect("discrete");
        }
    }
    (vehicles as f64 / ticks as f64, ticks as f64 / episodes as f64)
}

fn junction_decisions(c: &mut Criterion) {
    let bundle = bundle();
    let maps: Vec<(String, Map)> = std::iter::once(("straight".to_string(), ten_hz("intersection")))
        .chain([0, 4, 10, 20].map(|n| (format!("vehicles_{n}"), junction_with(n))))
        .collect();
    for (name, map) in &maps {
        let (vehicles, ticks) = probe(map, &bundle);
        eprintln!("junction_decisions/{name}: {vehicles:.1} vehicles per tick, {ticks:.0} ticks per episode");
    }
    let mut g = c.benchmark_group("junction_decisions");
    g.throughput(Throughput::Elements(1));
    for (name, map) in &maps {
        let mut env = Env::new(map, EnvConfig::default()).expect("env");
        let mut agent = agent(&bundle, ScaledParams::default());
        g.bench_function(name.as_str(), |b| {
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
    }
    g.finish();
}

criterion_group! {
    name = junction;
    config = criterion_config();
    targets = junction_decisions
}
criterion_main!(junction);
