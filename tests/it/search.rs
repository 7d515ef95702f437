//! `unforeseen search`: space files and their errors, candidates as valid maps,
//! determinism over seeds, jobs and shards, resume, minimisation and fairness. Budgets
//! are a few candidates of a few episodes, on a small space.

use std::path::Path;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::episodes::survivability::{CAREFUL_CRUISE, at_cruise, careful_witness, witness};
use unforeseen_harness::progress::NoProgress;
use unforeseen_harness::runs::batch::Shard;
use unforeseen_harness::runs::search::{self, Fairness, SearchConfig, Space, Value, sobol_candidates};
use unforeseen_harness::training::Agent;
use unforeseen_sim::Map;

use crate::common::{assert_exit, output_text, run_cli};
use unforeseen_harness::fixtures::bundle;

/// The output guard of a search into `out`, as a job holds it.
fn guarded(out: &Path) -> unforeseen_harness::runs::outputs::Guarded {
    unforeseen_harness::runs::outputs::Outputs::new()
        .folder("out", out)
        .guard(true)
        .expect("the guard")
}

fn jaywalk() -> Map {
    unforeseen_harness::maps::load("jaywalk").expect("embedded jaywalk")
}

/// A small space: three parameters of the jaywalk.
const SMALL: &str = r#"Space(
    name: "small",
    params: [
        (field: "pedestrians[0].trigger.value", range: (2.5, 6.0)),
        (field: "pedestrians[0].side", choose: ["Near", "Far"]),
        (field: "vehicle.start_speed", range: (1.0, 5.0)),
    ],
)"#;

fn small() -> Space {
    Space::parse("small.ron", SMALL, &jaywalk()).expect("the small space is valid")
}

fn shipped() -> Space {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("maps/spaces/jaywalk.ron");
    Space::load(&path, &jaywalk()).expect("the shipped space is valid")
}

/// The diagnostics of a bad space, one per line.
fn errors(text: &str) -> String {
    Space::parse("bad.ron", text, &jaywalk())
        .expect_err("a bad space")
        .to_string()
}

#[test]
fn space_file_errors_name_the_file_line_column_and_fix() {
    let unknown =
        errors("Space(\n    params: [\n        (field: \"vehicle.start_speed\", rnage: (1.0, 2.0)),\n    ],\n)");
    assert!(unknown.starts_with("bad.ron:3:"), "{unknown}");
    assert!(
        unknown.contains("rnage") && unknown.contains("hint: the fields here are"),
        "{unknown}"
    );

    let empty = errors("Space(\n  params: [\n    (field: \"vehicle.start_speed\", range: (3.0, 1.0)),\n  ],\n)");
    assert!(empty.starts_with("bad.ron:3:13: params[0]: an empty range"), "{empty}");
    assert!(
        empty.contains("hint: write range: (low, high) with low < high"),
        "{empty}"
    );

    let outside = errors("Space(params: [\n (field: \"pedestrians[0].speed\", range: (0.5, 20.0)),\n])");
    assert!(
        outside.starts_with("bad.ron:2:10: params[0]: the range (0.5, 20) leaves the map limits [0.01, 12] m/s"),
        "{outside}"
    );
    assert!(outside.contains("hint: keep the range within"), "{outside}");

    let field = errors("Space(params: [(field: \"vehicle.top_speed\", range: (1.0, 2.0))])");
    assert!(
        field.starts_with("bad.ron:1:24: params[0]: unknown field `vehicle.top_speed`"),
        "{field}"
    );
    assert!(field.contains("vehicle.max_speed"), "{field}");

    let rule = errors("Space(params: [(field: \"pedestrians[3].speed\", range: (1.0, 2.0))])");
    assert!(rule.contains("pedestrian rule 3 does not exist"), "{rule}");

    let choice = errors("Space(params: [(field: \"pedestrians[0].side\", choose: [\"Near\", \"Left\"])])");
    assert!(
        choice.contains("unknown choice `Left`") && choice.contains("Near, Far, Random"),
        "{choice}"
    );

    let syntax = errors("Space(params: [(field: \"vehicle.start_speed\", range: (1.0, 2.0)]");
    assert!(syntax.starts_with("bad.ron:1:"), "{syntax}");
}

#[test]
fn every_point_is_a_valid_map_or_a_rejection_with_a_reason() {
    let space = shipped();
    let dims = space.params.len();
    let mut points: Vec<Vec<f64>> = vec![vec![0.0; dims], vec![0.999_999; dims], vec![1.0; dims]];
    points.extend(sobol_candidates(&space, 3, 0..200).into_iter().map(|c| c.point));
    for (i, p) in points.iter().enumerate() {
        let values = space.values_at(p);
        match space.apply(&values, &format!("p{i}")) {
            Ok(map) => {
                // The loader reads the map it writes back as the same map.
                let text = search::map_ron(&map).expect("writes");
                let again = Map::from_str_named("again.ron", &text, &|_| None).expect("a valid map");
                assert_eq!(again, map);
            }
            Err(reason) => assert!(!reason.is_empty(), "point {i}: a rejection without a reason"),
        }
    }
    // A range whose points can break the map's rules: rejected, with the loader's reason.
    let risky = "Space(params: [(field: \"pedestrians[0].speed\", range: (11.0, 12.0))])";
    let space = Space::parse("risky.ron", risky, &jaywalk()).expect("within the limits");
    let reason = space
        .apply(&[Value::Num(11.9)], "risky")
        .expect_err("11.9..12.1 m/s exceeds the speed limit");
    assert!(reason.contains("pedestrians[0].speed"), "{reason}");
}

#[test]
fn the_same_seed_gives_the_same_candidates() {
    let space = shipped();
    let a = sobol_candidates(&space, 7, 0..64);
    assert_eq!(a, sobol_candidates(&space, 7, 0..64));
    assert_ne!(a, sobol_candidates(&space, 8, 0..64));
    // A slice of the sequence is the same candidates as in the whole.
    assert_eq!(&a[10..20], &sobol_candidates(&space, 7, 10..20)[..]);
}

fn config<'a>(space: &'a Space, agents: &'a [Agent], seeds: &'a [Option<u64>], jobs: usize) -> SearchConfig<'a> {
    SearchConfig {
        space,
        method: Method::QLearning,
        agents,
        train_seeds: seeds,
        agents_identity: "test agent".into(),
        protocol: Protocol::ZeroShot,
        budget: 8,
        episodes: 3,
        seed: 5,
        jobs,
        shard: None,
        sobol_share: 0.5,
        rounds: 2,
        max_failures: 1,
        command: "test".into(),
    }
}

/// The file's text without the one clock-measured figure of each line.
fn untimed(path: &Path) -> String {
    let text = std::fs::read_to_string(path).expect("read");
    text.lines()
        .map(|l| {
            let mut v: serde_json::Value = serde_json::from_str(l).expect("json");
            if let Some(o) = v.as_object_mut() {
                o.remove("timing_us_per_tick");
            }
            v.to_string()
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn summary_untimed(path: &Path) -> String {
    std::fs::read_to_string(path.join("summary.json")).expect("summary")
}

#[test]
fn one_and_two_jobs_write_identical_outputs_and_minimised_failures_fail() {
    let space = small();
    let agents = [Agent::from_bundle(bundle().clone())];
    let seeds = [agents[0].train_seed];
    let dir = tempfile::tempdir().expect("tempdir");
    let (one, two) = (dir.path().join("one"), dir.path().join("two"));
    let s1 = search::run(
        &config(&space, &agents, &seeds, 1),
        &one,
        false,
        &guarded(&one),
        &NoProgress,
    )
    .expect("runs");
    let s2 = search::run(
        &config(&space, &agents, &seeds, 2),
        &two,
        false,
        &guarded(&two),
        &NoProgress,
    )
    .expect("runs");
    assert_eq!(
        untimed(&one.join("candidates.jsonl")),
        untimed(&two.join("candidates.jsonl"))
    );
    let strip = |s: String, d: &Path| s.replace(&d.display().to_string(), "DIR");
    assert_eq!(strip(summary_untimed(&one), &one), strip(summary_untimed(&two), &two));
    assert_eq!(s1.counts, s2.counts);
    std::fs::metadata(one.join("search.svg")).expect("the figure is written");
    // Every line after the identity is a batch result line.
    let lines = search::read_result_lines(&one.join("candidates.jsonl")).expect("batch lines");
    assert!(
        lines.len().is_multiple_of(3) && lines.len() >= 3 * s1.counts.evaluated,
        "{}",
        lines.len()
    );
    // Every line names the careful cruise that decided its candidate's survivability, at
    // the survivable witness's success; the summary states the failure threshold.
    let text = std::fs::read_to_string(one.join("candidates.jsonl")).expect("read");
    let parsed: Vec<search::CandidateLine> = text
        .lines()
        .skip(1)
        .map(|l| serde_json::from_str(l).expect("a candidate line"))
        .collect();
    for l in &parsed {
        let c = l.careful_cruise.expect("the deciding cruise");
        let witness = parsed
            .iter()
            .find(|w| w.candidate == l.candidate && w.role == search::Role::SurvivableWitness)
            .expect("the witness's line");
        assert_eq!(c.success_rate, witness.result.success_rate, "{l:?}");
        assert!(c.fraction > 0.0 && c.fraction <= 1.0 && c.speed_mps > 0.0, "{c:?}");
    }
    assert_eq!(s1.failure_threshold.failure_success, Some(0.5));
    assert_eq!(s1.failure_threshold.witness_episodes, 3);
    // q-learning drives on in the jaywalk: the search finds a fair failure, and the
    // minimised scenario is one measured to fail, fairly.
    assert!(
        !s1.failures.is_empty(),
        "q-learning should fail somewhere fair: {:?}",
        s1.counts
    );
    for f in &s1.failures {
        assert!(
            f.brake_on_pedestrian_success >= 0.99 && f.never_brake_success <= 0.2,
            "{f:?}"
        );
        assert!(f.method_success.iter().all(|&(_, s)| s < 0.5), "{f:?}");
        // The written map is that scenario: re-run as batch would, it fails again.
        let map = unforeseen_harness::maps::load_file(&f.file).expect("a valid map file");
        let results = unforeseen_harness::episodes::run_agent_episodes(
            Protocol::ZeroShot,
            &map,
            bundle(),
            &Default::default(),
            Method::QLearning,
            3,
            5,
            &NoProgress,
        )
        .expect("runs");
        let agg = unforeseen_harness::episodes::Aggregate::of(&results);
        assert_eq!(Some(agg.success_rate), f.method_success.first().map(|s| s.1));
        assert!(
            witness(&map, Method::BrakeOnPedestrian, 3, 5)
                .expect("runs")
                .success_rate
                >= 0.99
        );
    }
}

#[test]
fn shards_concatenate_into_the_sobol_part_of_one_run_and_resume_finishes_it() {
    let space = small();
    let agents = [Agent::from_bundle(bundle().clone())];
    let seeds = [agents[0].train_seed];
    let dir = tempfile::tempdir().expect("tempdir");
    let whole = dir.path().join("whole");
    search::run(
        &config(&space, &agents, &seeds, 2),
        &whole,
        false,
        &guarded(&whole),
        &NoProgress,
    )
    .expect("runs");
    let mut parts = String::new();
    for i in 1..=2 {
        let d = dir.path().join(format!("shard{i}"));
        let cfg = SearchConfig {
            shard: Some(Shard { index: i, count: 2 }),
            ..config(&space, &agents, &seeds, 2)
        };
        let s = search::run(&cfg, &d, false, &guarded(&d), &NoProgress).expect("runs");
        assert_eq!(
            s.counts.adaptive + s.counts.minimise,
            0,
            "a shard runs only the Sobol stage"
        );
        parts.push_str(&std::fs::read_to_string(d.join("candidates.jsonl")).expect("read"));
    }
    let joined = dir.path().join("joined");
    std::fs::create_dir_all(&joined).expect("mkdir");
    std::fs::write(joined.join("candidates.jsonl"), &parts).expect("write");
    // The shards' lines are the whole run's Sobol lines, in order.
    let sobol_of = |text: String| -> Vec<String> {
        text.lines()
            .filter(|l| l.contains("\"stage\":\"sobol\""))
            .map(str::to_string)
            .collect()
    };
    assert_eq!(
        sobol_of(untimed(&joined.join("candidates.jsonl"))),
        sobol_of(untimed(&whole.join("candidates.jsonl")))
    );
    // Resumed, the concatenation becomes the whole run's file.
    search::run(
        &config(&space, &agents, &seeds, 1),
        &joined,
        true,
        &guarded(&joined),
        &NoProgress,
    )
    .expect("resumes");
    assert_eq!(
        untimed(&joined.join("candidates.jsonl")),
        untimed(&whole.join("candidates.jsonl"))
    );

    // A killed run (cut mid-line) resumes to the same file; the kept lines stay as written.
    let killed = dir.path().join("killed");
    std::fs::create_dir_all(&killed).expect("mkdir");
    let full = std::fs::read_to_string(whole.join("candidates.jsonl")).expect("read");
    let cut = &full[..full.len() * 3 / 5];
    std::fs::write(killed.join("candidates.jsonl"), cut).expect("write");
    search::run(
        &config(&space, &agents, &seeds, 2),
        &killed,
        true,
        &guarded(&killed),
        &NoProgress,
    )
    .expect("resumes");
    let resumed = std::fs::read_to_string(killed.join("candidates.jsonl")).expect("read");
    let complete = &cut[..cut.rfind('\n').expect("lines") + 1];
    assert!(
        resumed.starts_with(&complete[..complete.len() / 2]),
        "kept lines are copied byte for byte"
    );
    assert_eq!(
        untimed(&killed.join("candidates.jsonl")),
        untimed(&whole.join("candidates.jsonl"))
    );

    // Another run's file is refused, saying what differs.
    let other = SearchConfig {
        seed: 6,
        ..config(&space, &agents, &seeds, 1)
    };
    let err = search::run(&other, &whole, true, &guarded(&whole), &NoProgress).expect_err("another search");
    assert!(err.to_string().contains("seed: the file has 5, this run 6"), "{err}");
}

#[test]
fn fairness_of_known_maps() {
    let of = |map: &Map| {
        let b = witness(map, Method::BrakeOnPedestrian, 10, 7).expect("runs");
        let n = witness(map, Method::NeverBrake, 10, 7).expect("runs");
        Fairness::of(b.success_rate, n.success_rate)
    };
    assert_eq!(of(&jaywalk()), Fairness::Fair);
    // The same jaywalker stepping out 1.5 s before the car arrives: nobody can stop.
    let mut late = jaywalk();
    late.pedestrians[0].trigger = unforeseen_sim::Trigger::CarArrivesWithin(1.5);
    late.pedestrians[0].side = unforeseen_sim::Side::Near;
    assert_eq!(of(&late), Fairness::NotSurvivable);
    // Nobody on the road: driving on is safe.
    let mut empty = jaywalk();
    empty.pedestrians.clear();
    assert_eq!(of(&empty), Fairness::NotDangerous);
}

/// A map that brake-on-pedestrian survives only at the car's exact top speed (found by a
/// search, maps/search/knife_edge/) is not survivable: cruising at 95% of that speed the
/// same driver dies in most episodes, so the search does not count a failure there.
#[test]
fn a_map_survivable_only_at_top_speed_is_not_fair() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("maps/search/knife_edge/wide_c0787.ron");
    let map = unforeseen_harness::maps::load_file(&file).expect("a shipped map");
    let at_top = witness(&map, Method::BrakeOnPedestrian, 20, 7).expect("runs");
    assert!(at_top.success_rate >= 0.99, "{at_top:?}");
    let (careful, agg) = careful_witness(&map, 20, 7, &NoProgress).expect("runs");
    assert!(careful.success_rate < 0.5 && careful.cruise < 1.0, "{careful:?}");
    assert_eq!(agg.success_rate, careful.success_rate);
    // The shipped jaywalk is survivable at every careful cruise.
    let (jay, _) = careful_witness(&jaywalk(), 20, 7, &NoProgress).expect("runs");
    assert!(jay.success_rate >= 0.99, "{jay:?}");
}

/// A map that brake-on-pedestrian survives from 90% of the car's top speed up but not
/// cruising lower in the top speed bin (found by a search, maps/search/knife_edge/) is
/// not survivable: the agent's states cannot tell those speeds from the top speed.
#[test]
fn a_map_survivable_only_high_in_the_top_speed_bin_is_not_fair() {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("maps/search/knife_edge/top_speed_c0558.ron");
    let map = unforeseen_harness::maps::load_file(&file).expect("a shipped map");
    for fraction in CAREFUL_CRUISE {
        let w = witness(&at_cruise(&map, fraction), Method::BrakeOnPedestrian, 20, 7).expect("runs");
        assert!(w.success_rate >= 0.99, "{fraction}: {w:?}");
    }
    let (careful, _) = careful_witness(&map, 20, 7, &NoProgress).expect("runs");
    let edge = map.bins.speed_edges.last().expect("speed bins") / map.vehicle.max_speed;
    assert!(careful.success_rate < 0.5, "{careful:?}");
    assert!((edge..0.9).contains(&careful.cruise), "{careful:?}");
}

#[test]
fn the_cli_exits_2_on_bad_space_files() {
    let dir = tempfile::tempdir().expect("tempdir");
    let bad = dir.path().join("bad.ron");
    std::fs::write(
        &bad,
        "Space(\n    params: [\n        (field: \"vehicle.max_brake\", range: (0.0, 3.0)),\n    ],\n)\n",
    )
    .expect("write");
    let out = dir.path().join("out");
    let run = |space: &Path| {
        run_cli(&[
            "search",
            "--space",
            space.to_str().expect("utf-8"),
            "--method",
            "brake-on-pedestrian",
            "--budget",
            "2",
            "--episodes",
            "1",
            "-q",
            "--out",
            out.to_str().expect("utf-8"),
        ])
    };
    let shown = format!(
        "{}:3:17: params[0]: the range (0, 3) leaves the map limits",
        bad.display()
    );
    assert_exit(&run(&bad), 2, &[&shown, "hint: keep the range within [0.1, 20]"]);
    std::fs::write(
        &bad,
        "Space(params: [(field: \"vehicle.start_speed\", range: (1.0, 2.0), step: 1)])",
    )
    .expect("write");
    assert_exit(&run(&bad), 2, &[&format!("{}:1:", bad.display()), "step"]);
    assert_exit(
        &run(&dir.path().join("missing.ron")),
        2,
        &["missing.ron", "cannot read the space file"],
    );
    assert!(
        !out.join("candidates.jsonl").exists(),
        "nothing is written for a bad space"
    );
}

/// `maps/spaces/dynamics.ron` on the ice map sets the road's and the patch's friction,
/// the patch's start (its length kept, then set), the mass and the brakes, and its
/// candidates load as maps; a patch the base map does not have is an error.
#[test]
fn the_dynamics_space_sets_surface_and_brakes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base = Map::load(&root.join("maps/ice_before_crosswalk.ron")).unwrap();
    let space = Space::load(&root.join("maps/spaces/dynamics.ron"), &base).expect("valid");
    let values = space.values_at(&vec![0.0; space.params.len()]);
    let map = space.apply(&values, "low").expect("the lowest corner is a valid map");
    assert_eq!(map.road.friction, 0.3);
    let patch = map.road.surface[0];
    assert_eq!((patch.from, patch.to, patch.friction), (0.0, 2.0, 0.05));
    assert_eq!((map.vehicle.mass, map.vehicle.brake_force), (1000.0, 3000.0));
    assert_eq!((map.vehicle.brake_dead_time, map.vehicle.brake_lag), (0.0, 0.0));
    let err = Space::parse(
        "bad.ron",
        "Space(params: [(field: \"road.surface[1].friction\", range: (0.1, 0.2))])",
        &base,
    )
    .expect_err("the ice map has one patch")
    .to_string();
    assert!(err.contains("1 surface patch(es), not 2"), "{err}");
}

/// `maps/spaces/junction.ron` on the red-runner junction varies the base's vehicle and a
/// space's own: the lowest corner gives the base's runner a route from the south that
/// runs the red at the lowest timing, speed and start, and no second vehicle; the highest
/// corner one stalled car from the south arm's opposite side and a careful oncoming
/// left-turner; a traffic rule the base and the space do not have is an error.
#[test]
fn the_junction_space_sets_the_vehicle_rules() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base = Map::load(&root.join("maps/junction/red_runner.ron")).unwrap();
    let n = base.traffic.len();
    let space = Space::load(&root.join("maps/spaces/junction.ron"), &base).expect("valid");
    let low = space
        .apply(&space.values_at(&vec![0.0; space.params.len()]), "low")
        .expect("the lowest corner is a valid map");
    assert_eq!(low.traffic.len(), n, "no copy of the space's vehicle at copies 0");
    let runner = low.traffic[n - 1];
    assert_eq!(runner.route, unforeseen_sim::Route::FromSouth);
    assert_eq!(runner.behaviour, unforeseen_sim::Behaviour::RunsRed);
    assert_eq!(runner.trigger, unforeseen_sim::Trigger::CarArrivesWithin(2.0));
    assert_eq!((runner.speed.0, runner.start), (6.0, 20.0));
    let high = space
        .apply(&space.values_at(&vec![0.999; space.params.len()]), "high")
        .expect("the highest corner is a valid map");
    assert_eq!(high.traffic.len(), n + 1, "one copy of the space's vehicle");
    assert_eq!(high.traffic[n - 1].route, unforeseen_sim::Route::OncomingLeft);
    assert!(
        matches!(high.traffic[n - 1].behaviour, unforeseen_sim::Behaviour::Stalls { at, .. } if (at - 7.992).abs() < 1e-9),
        "{:?}",
        high.traffic[n - 1].behaviour
    );
    let second = high.traffic[n];
    assert_eq!(second.route, unforeseen_sim::Route::OncomingLeft);
    assert_eq!(second.behaviour, unforeseen_sim::Behaviour::Careful);
    let err = Space::parse(
        "bad.ron",
        "Space(params: [(field: \"traffic[9].speed\", range: (5.0, 6.0))])",
        &base,
    )
    .expect_err("the base has fewer traffic rules")
    .to_string();
    assert!(err.contains(&format!("the base map has {n} traffic rule(s)")), "{err}");
    let err = Space::parse(
        "bad.ron",
        "Space(params: [(field: \"traffic[0].behaviour\", choose: [\"Reckless\"])])",
        &base,
    )
    .expect_err("no such behaviour")
    .to_string();
    assert!(err.contains("the choices are Careful, RunsRed"), "{err}");
}

/// `maps/spaces/junction_timed.ron` on the red-runner junction times the base's vehicle to
/// the car: the lowest corner is a runner from the south that starts 2.5 s before the car
/// arrives, 30 m out at 9 m/s; the highest an oncoming left-turner that does not yield,
/// started 5 s out, 55 m away at 12.9 m/s (values rounded to 0.001).
#[test]
fn the_timed_junction_space_sets_the_vehicle_rule() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let base = Map::load(&root.join("maps/junction/red_runner.ron")).unwrap();
    let space = Space::load(&root.join("maps/spaces/junction_timed.ron"), &base).expect("valid");
    let corner = |u: f64, name: &str| {
        let map = space
            .apply(&space.values_at(&vec![u; space.params.len()]), name)
            .expect("a corner is a valid map");
        assert_eq!(map.traffic.len(), base.traffic.len(), "the space adds no vehicle");
        map.traffic[0]
    };
    let low = corner(0.0, "low");
    assert_eq!(low.route, unforeseen_sim::Route::FromSouth);
    assert_eq!(low.behaviour, unforeseen_sim::Behaviour::RunsRed);
    assert_eq!(low.trigger, unforeseen_sim::Trigger::CarArrivesWithin(2.5));
    assert_eq!((low.speed.0, low.start), (9.0, 30.0));
    let high = corner(0.999, "high");
    assert_eq!(high.route, unforeseen_sim::Route::OncomingLeft);
    assert_eq!(high.behaviour, unforeseen_sim::Behaviour::DoesNotYield);
    let unforeseen_sim::Trigger::CarArrivesWithin(t) = high.trigger else {
        panic!("{:?}", high.trigger)
    };
    assert!((t - 4.998).abs() < 1e-9 && (high.speed.0 - 12.896).abs() < 1e-9 && (high.start - 54.975).abs() < 1e-9);
}

/// `search --train-map` (and `estimate --train-map`): the agents train on the map given, a
/// file or an embedded name; the map enters their identity and cache key as batch's does,
/// so a search of agents trained elsewhere does not resume this one; its default is the
/// request's; a missing map is refused naming the file, writing nothing; an agent file
/// and a training map are refused together.
#[test]
fn search_and_estimate_train_on_the_train_map() {
    let dir = tempfile::tempdir().unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let space = root.join("maps/spaces/jaywalk.ron");
    let short = dir.path().join("short.ron");
    std::fs::write(
        &short,
        "Map(base: \"intersection\", name: \"short_intersection\", episode: (max_steps: 60))",
    )
    .unwrap();
    let cache = dir.path().join("agents");
    let run = |out: &str, extra: &[&str]| {
        let out = dir.path().join(out);
        let mut args = vec![
            "search",
            "--space",
            space.to_str().unwrap(),
            "--method",
            "q-learning",
            "--train-seeds",
            "1",
            "--train-episodes",
            "20",
            "--budget",
            "2",
            "--episodes",
            "1",
            "--max-failures",
            "0",
            "--jobs",
            "1",
            "-q",
            "--cache",
            cache.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        (run_cli(&args), out)
    };
    let identity = |out: &Path| {
        let text = std::fs::read_to_string(out.join("candidates.jsonl")).unwrap();
        let first: serde_json::Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
        first["search"]["agents"].as_str().unwrap().to_string()
    };
    let (res, trained) = run("short", &["--train-map", short.to_str().unwrap()]);
    assert_exit(&res, 0, &[]);
    let (res, default) = run("default", &[]);
    assert_exit(&res, 0, &[]);
    assert!(
        identity(&trained).starts_with("trained on short_intersection for 20 episodes"),
        "{}",
        identity(&trained)
    );
    assert!(identity(&default).starts_with("trained on intersection for 20 episodes"));
    let mut cached: Vec<String> = std::fs::read_dir(&cache)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    cached.sort();
    assert!(
        cached.len() == 2
            && cached[0].starts_with("intersection-seed1-")
            && cached[1].starts_with("short_intersection-seed1-"),
        "one cached agent per training map: {cached:?}"
    );
    // The default search does not resume the folder of agents trained on the other map.
    let (res, _) = run("short", &["--resume"]);
    assert_exit(&res, 2, &["--resume", "another search", "short_intersection"]);

    // The flags' default is the request's.
    let help = output_text(&run_cli(&["search", "--help"]));
    let default_map = unforeseen_harness::runs::search::SearchRequest::default().train_map;
    assert!(
        help.contains("--train-map <MAP>") && help.contains(&format!("[default: {default_map}]")),
        "{help}"
    );
    let help = output_text(&run_cli(&["estimate", "--help"]));
    assert!(help.contains("--train-map <MAP>"), "{help}");

    // A missing training map: refused naming it, nothing written; with an agent file: refused.
    let missing = dir.path().join("no_such_train_map.ron");
    for command in ["search", "estimate"] {
        let out = dir.path().join(format!("{command}-missing"));
        let res = run_cli(&[
            command,
            "--space",
            space.to_str().unwrap(),
            "--method",
            "q-learning",
            "--train-map",
            missing.to_str().unwrap(),
            "-q",
            "--out",
            out.to_str().unwrap(),
        ]);
        assert_exit(&res, 2, &["no_such_train_map.ron", "no such map file", "pass a path"]);
        assert!(!out.exists(), "{command}: nothing written for a missing training map");
        let res = run_cli(&[
            command,
            "--space",
            space.to_str().unwrap(),
            "--agent",
            "a.ron",
            "--train-map",
            "intersection",
        ]);
        assert_exit(&res, 2, &["cannot be used with"]);
    }
}
