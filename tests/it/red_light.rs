//! The red-light rule where the planner knows it (docs/ARCHITECTURE.md §4.3): the
//! rule-aware planner on `maps/red_light/` (a preference over transitions), rule-free maps unchanged, the
//! `max_red_light` expectation, and `batch --train-map`.

use std::path::{Path, PathBuf};
use unforeseen_discretizer::{Discretizer, State};
use unforeseen_harness::episodes::Aggregate;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::episodes::{entered_bins, red_light_cost, state_rewards};
use unforeseen_harness::fixtures;
use unforeseen_harness::runs::batch::check_expectations;

use crate::common::{assert_exit, run_cli};

fn shipped(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("maps").join(rel)
}

fn load(rel: &str) -> unforeseen_sim::Map {
    unforeseen_harness::maps::load(shipped(rel).to_str().unwrap()).expect("shipped map")
}

#[test]
fn the_planner_pays_for_entering_the_crosswalk_on_red() {
    let map = load("red_light/intersection.ron");
    let disc = Discretizer::new(&map).unwrap();
    // Edges [0, 26, 60]: d = 1 is (0, 26] m to go, from the near edge (26 m) to the goal.
    assert_eq!(disc.distance_edges(), [0.0, 26.0, 60.0]);
    assert_eq!(entered_bins(&map, &disc), [1]);
    let rule = red_light_cost(&map, &disc, 1.0).expect("the rule with an edge at the near edge");
    assert_eq!(rule.cost, 100.0, "-red_light / tau_c nats");
    assert_eq!(red_light_cost(&map, &disc, 2.0).unwrap().cost, 50.0);
    let at = |d, v, l, p| disc.encode(State { d, v, l, p });
    // From: before the near edge on red or amber; to: past it on red or amber.
    assert!(rule.from[at(2, 3, 0, 0)] && rule.from[at(3, 0, 0, 1)]);
    assert!(!rule.from[at(2, 3, 1, 0)] && !rule.from[at(1, 3, 0, 0)] && !rule.from[at(0, 3, 0, 0)]);
    assert!(rule.to[at(1, 3, 0, 0)] && rule.to[at(1, 0, 0, 1)]);
    assert!(!rule.to[at(1, 3, 1, 0)] && !rule.to[at(2, 3, 0, 0)] && !rule.to[at(0, 3, 0, 0)]);
    // The state preferences stay the paper's: R(s) is the rule-free map's, bit for bit.
    let mut free = map.clone();
    free.reward.red_light = 0.0;
    assert!(red_light_cost(&free, &disc, 1.0).is_none());
    let bits = |m: &unforeseen_sim::Map| state_rewards(m, &disc).iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&map), bits(&free));
    // The trained agent carries it: its planning model has the rule, a rule-free one not.
    let cfg = unforeseen_harness::training::TrainConfig::new(5, 1);
    let (agent, _) = unforeseen_harness::training::train(&map, &cfg).unwrap();
    assert_eq!(agent.world_model.generative().transition_cost.as_ref(), Some(&rule));
    assert_eq!(
        agent.world_model.planning_generative().transition_cost.as_ref(),
        Some(&rule)
    );
    let (free_agent, _) = unforeseen_harness::training::train(&free, &cfg).unwrap();
    assert!(free_agent.world_model.generative().transition_cost.is_none());
    // ...and keeps it through its file.
    let back = unforeseen_agent::persist::AgentBundle::from_ron_str(&agent.to_ron_string()).unwrap();
    assert_eq!(back.world_model.generative().transition_cost.as_ref(), Some(&rule));
    assert!(!free_agent.to_ron_string().contains("transition_cost"));
}

#[test]
fn maps_without_the_rule_or_without_the_edge_keep_the_papers_preferences() {
    for name in ["intersection", "jaywalk", "stuck_green", "slow_walker"] {
        let map = unforeseen_harness::maps::load(name).unwrap();
        let disc = Discretizer::new(&map).unwrap();
        let r = state_rewards(&map, &disc);
        // Only the goal and the crash risk, as in the paper (§VI).
        assert!(
            r.iter()
                .all(|&x| x == 0.0 || x == map.reward.goal || x == map.reward.crash),
            "{name}: {r:?}"
        );
    }
    // The rule with the paper's edges: d = 1 holds 4 m before the crosswalk, so no state
    // says the car has entered, and R(s) stays the rule-free one bit for bit.
    let mut map = fixtures::papers_bins("intersection");
    let disc = Discretizer::new(&map).unwrap();
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
    let map = unforeseen_harness::maps::load(good.to_str().unwrap()).unwrap();
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
    let e = unforeseen_harness::maps::load(range.to_str().unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("range.ron"), "{e}");
    assert!(e.contains("expect[0].max_red_light: must be in [0, 1], got 1.5"), "{e}");
    assert!(e.contains("hint: a probability or a rate"), "{e}");
    let typed = dir.path().join("typed.ron");
    std::fs::write(
        &typed,
        "Map(base: \"jaywalk\",\n  expect: [\n    (method: Scaled, max_red_light: \"low\"),\n  ])\n",
    )
    .unwrap();
    let e = unforeseen_harness::maps::load(typed.to_str().unwrap())
        .unwrap_err()
        .to_string();
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
