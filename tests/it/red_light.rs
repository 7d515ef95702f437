//! The red-light rule where the planner knows it (docs/ARCHITECTURE.md §4.3): the
//! rule-aware preferences R(s) on `maps/red_light/`, rule-free maps unchanged, the
//! `max_red_light` expectation, and `batch --train-map`.

use std::path::{Path, PathBuf};
use unforeseen::batch::check_expectations;
use unforeseen::methods::Method;
use unforeseen::metrics::Aggregate;
use unforeseen::protocol::Protocol;
use unforeseen::rewards::{entered_bins, state_rewards};
use unforeseen_discretizer::{Discretizer, State};

use crate::common::{assert_exit, run_cli};

fn shipped(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("maps").join(rel)
}

fn load(rel: &str) -> unforeseen_sim::Map {
    unforeseen::maps::load(shipped(rel).to_str().unwrap()).expect("shipped map")
}

/// R at (d, v, L, p) on `map`.
fn r_at(map: &unforeseen_sim::Map, d: usize, v: usize, l: usize, p: usize) -> f64 {
    let disc = Discretizer::new(&map.bins).unwrap();
    state_rewards(map, &disc)[disc.encode(State { d, v, l, p })]
}

#[test]
fn the_planner_pays_the_red_light_rule_past_the_near_edge_on_red() {
    let map = load("red_light/intersection.ron");
    let disc = Discretizer::new(&map.bins).unwrap();
    // Edges [0, 26, 60]: d = 1 is (0, 26] m to go, from the near edge (26 m) to the goal.
    assert_eq!(map.bins.distance_edges, [0.0, 26.0, 60.0]);
    assert_eq!(entered_bins(&map, &disc), [1]);
    let (goal, crash, red) = (map.reward.goal, map.reward.crash, map.reward.red_light);
    assert_eq!((goal, crash, red), (50.0, -25.0, -100.0));
    // Hand-worked: at full speed (v = 3) past the near edge on red, nobody there: -100.
    assert_eq!(r_at(&map, 1, 3, 0, 0), -100.0);
    // The same with a pedestrian on the crosswalk: the crash risk and the rule, -125,
    // below standing there on red (-100), so the planner still prefers stopping.
    assert_eq!(r_at(&map, 1, 3, 0, 1), -125.0);
    assert_eq!(r_at(&map, 1, 0, 0, 1), -100.0);
    // Green past the edge: only the crash risk; before the edge on red: nothing; arrived: the goal.
    assert_eq!(r_at(&map, 1, 3, 1, 1), -25.0);
    assert_eq!(r_at(&map, 1, 3, 1, 0), 0.0);
    assert_eq!(r_at(&map, 2, 3, 0, 0), 0.0);
    assert_eq!(r_at(&map, 2, 0, 0, 1), 0.0);
    assert_eq!(r_at(&map, 0, 3, 0, 1), 50.0);
    // C = log_softmax(R): entering on red is 100 nats less preferred than waiting before it.
    let c = unforeseen_agent::maths::log_softmax(&state_rewards(&map, &disc));
    let at = |d, v, l, p| c[disc.encode(State { d, v, l, p })];
    assert!((at(2, 3, 0, 0) - at(1, 3, 0, 0) - 100.0).abs() < 1e-9);
}

#[test]
fn maps_without_the_rule_or_without_the_edge_keep_the_papers_preferences() {
    for name in ["intersection", "jaywalk", "stuck_green", "slow_walker"] {
        let map = unforeseen::maps::load(name).unwrap();
        let disc = Discretizer::new(&map.bins).unwrap();
        let r = state_rewards(&map, &disc);
        // Only the goal and the crash risk, as in the paper (§VI).
        assert!(
            r.iter()
                .all(|&x| x == 0.0 || x == map.reward.goal || x == map.reward.crash),
            "{name}: {r:?}"
        );
    }
    // The rule with the default bins: d = 1 holds 4 m before the crosswalk, so no state
    // says the car has entered, and R(s) stays the rule-free one bit for bit.
    let mut map = unforeseen::maps::load("intersection").unwrap();
    let disc = Discretizer::new(&map.bins).unwrap();
    let free = state_rewards(&map, &disc);
    map.reward.red_light = -100.0;
    assert!(entered_bins(&map, &disc).is_empty());
    let with_rule = state_rewards(&map, &disc);
    assert_eq!(
        free.iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
        with_rule.iter().map(|x| x.to_bits()).collect::<Vec<_>>()
    );
}

#[test]
fn max_red_light_bounds_the_violations_per_episode() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("good.ron");
    std::fs::write(
        &good,
        "Map(base: \"jaywalk\", expect: [(method: QLearning, max_red_light: 0.1, protocol: ZeroShot)])",
    )
    .unwrap();
    let map = unforeseen::maps::load(good.to_str().unwrap()).unwrap();
    assert_eq!(map.expect[0].max_red_light, Some(0.1));
    let agg = |rate| Aggregate {
        episodes: 10,
        red_light_rate: rate,
        ..Aggregate::default()
    };
    let check = |rate| check_expectations(&map, Method::QLearning, &[Protocol::ZeroShot], &agg(rate));
    let pass = check(0.1);
    assert_eq!(pass.len(), 1);
    assert_eq!(
        (pass[0].figure.as_str(), pass[0].bound.as_str()),
        ("red_light_rate", "max")
    );
    assert!(pass[0].pass);
    assert!(!check(0.2)[0].pass);
    assert!(check_expectations(&map, Method::Scaled, &[Protocol::ZeroShot], &agg(1.0)).is_empty());
}

#[test]
fn a_bad_max_red_light_names_the_file_the_place_and_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let range = dir.path().join("range.ron");
    std::fs::write(
        &range,
        "Map(base: \"jaywalk\",\n  expect: [\n    (method: Scaled, max_red_light: 1.5),\n  ])\n",
    )
    .unwrap();
    let e = unforeseen::maps::load(range.to_str().unwrap()).unwrap_err().to_string();
    assert!(e.contains("range.ron"), "{e}");
    assert!(e.contains("expect[0].max_red_light: must be in [0, 1], got 1.5"), "{e}");
    assert!(e.contains("hint: a probability or a rate"), "{e}");
    let typed = dir.path().join("typed.ron");
    std::fs::write(
        &typed,
        "Map(base: \"jaywalk\",\n  expect: [\n    (method: Scaled, max_red_light: \"low\"),\n  ])\n",
    )
    .unwrap();
    let e = unforeseen::maps::load(typed.to_str().unwrap()).unwrap_err().to_string();
    assert!(e.contains("typed.ron:3:"), "the line of the field: {e}");
    let out = run_cli(&["check-map", "--survivability-episodes", "0", range.to_str().unwrap()]);
    assert_exit(&out, 2, &["range.ron", "expect[0].max_red_light", "hint:"]);
}

#[test]
fn batch_trains_on_the_train_map() {
    let dir = tempfile::tempdir().unwrap();
    let jay = shipped("red_light/jaywalk.ron");
    let run = |name: &str, train_map: Option<&Path>| {
        let out = dir.path().join(format!("{name}.jsonl"));
        let cache = dir.path().join(format!("{name}-agents"));
        let mut args = vec![
            "batch".to_string(),
            jay.display().to_string(),
            "--train-seeds".into(),
            "1".into(),
            "--train-episodes".into(),
            "40".into(),
            "--episodes".into(),
            "2".into(),
            "--method".into(),
            "q-learning".into(),
            "--jobs".into(),
            "1".into(),
            "-q".into(),
            "--cache".into(),
            cache.display().to_string(),
            "--out".into(),
            out.display().to_string(),
        ];
        if let Some(m) = train_map {
            args.extend(["--train-map".into(), m.display().to_string()]);
        }
        let refs: Vec<&str> = args.iter().map(String::as_str).collect();
        let res = run_cli(&refs);
        assert_exit(&res, 0, &[]);
        let cached: Vec<String> = std::fs::read_dir(&cache)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        let first = std::fs::read_to_string(&out)
            .unwrap()
            .lines()
            .next()
            .unwrap()
            .to_string();
        (cached, first)
    };
    let (default_agents, default_run) = run("default", None);
    let train = shipped("red_light/intersection.ron");
    let (rule_agents, rule_run) = run("rule", Some(&train));
    assert!(
        default_agents.iter().all(|f| f.starts_with("intersection-seed1-")),
        "{default_agents:?}"
    );
    assert!(
        rule_agents.len() == 1 && rule_agents[0].starts_with("intersection_red_light-seed1-"),
        "{rule_agents:?}"
    );
    assert!(default_run.contains("trained on intersection for"), "{default_run}");
    assert!(rule_run.contains("trained on intersection_red_light for"), "{rule_run}");
    // An agent file and a training map are two answers to one question.
    let out = run_cli(&["batch", "--agent", "a.ron", "--train-map", "intersection"]);
    assert_exit(&out, 2, &["cannot be used with"]);
}
