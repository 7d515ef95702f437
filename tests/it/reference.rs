//! The scripted references (§VI's careful driver and a car that never brakes) on the
//! real physics: brake-on-pedestrian survives the jaywalker, never-brake does not;
//! `check-map` and `batch` warn, without changing the exit code, when a map is not
//! dangerous or not survivable; `eval` runs the references without training an agent.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use unforeseen_agent::params::ScaledParams;
use unforeseen_harness::episodes::Aggregate;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::run_controller;
use unforeseen_harness::episodes::survivability::witness;
use unforeseen_harness::progress::NoProgress;
use unforeseen_harness::training::{TrainConfig, train};

const EPISODES: u64 = 20;

fn unforeseen(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_unforeseen"))
        .args(args)
        .output()
        .expect("run the binary")
}

fn shipped(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("maps")
        .join(name)
        .display()
        .to_string()
}

/// A map in `dir` based on the shipped jaywalk.ron with these pedestrians.
fn map_with(dir: &Path, name: &str, pedestrians: &str) -> PathBuf {
    let path = dir.join(format!("{name}.ron"));
    std::fs::write(
        &path,
        format!(
            "(base: {:?}, name: {name:?}, pedestrians: [{pedestrians}], expect: [])",
            shipped("jaywalk.ron")
        ),
    )
    .unwrap();
    path
}

/// Nobody steps out until the car has long arrived (~11 s): not dangerous.
fn harmless(dir: &Path) -> PathBuf {
    map_with(dir, "harmless", "(trigger: AtTime(30.0), side: Far)")
}

/// late_fast.ron's runner, 0.6 s later: first seen when braking can no longer stop the car.
fn too_late(dir: &Path) -> PathBuf {
    map_with(
        dir,
        "too_late",
        "(trigger: CarArrivesWithin(2.0), light: Green, side: Far, speed: (1.8, 2.2))",
    )
}

#[test]
fn brake_on_pedestrian_survives_the_jaywalker_and_never_brake_does_not() {
    let jaywalk = unforeseen_harness::maps::load("jaywalk").unwrap();
    let brake = witness(&jaywalk, Method::BrakeOnPedestrian, EPISODES, 7).unwrap();
    assert_eq!(brake.episodes, EPISODES);
    assert_eq!(brake.success_rate, 1.0, "{brake:?}");
    let never = witness(&jaywalk, Method::NeverBrake, EPISODES, 7).unwrap();
    assert_eq!(never.success_rate, 0.0, "{never:?}");
    assert_eq!(never.collision_rate, 1.0, "{never:?}");
}

#[test]
fn the_method_factory_builds_the_references_from_an_agent_file_too() {
    // One training episode is enough: the references read only the model's factor sizes.
    let intersection = unforeseen_harness::maps::load("intersection").unwrap();
    let cfg = TrainConfig::new(1, 7);
    let bundle = train(&intersection, &cfg).unwrap().0;
    let jaywalk = unforeseen_harness::maps::load("jaywalk").unwrap();
    for method in Method::REFERENCE {
        assert!(method.is_scripted() && !Method::PAPER.contains(&method));
        assert!(!method.learns_across_episodes(&ScaledParams::default()));
        let mut controller = method.controller(&bundle, &ScaledParams::default(), &jaywalk).unwrap();
        assert_eq!(controller.name(), method.name());
        let results = run_controller(&jaywalk, controller.as_mut(), method, EPISODES, 7, &NoProgress).unwrap();
        let agg = Aggregate::of(&results);
        assert_eq!(agg.inference_rate, 0.0, "{method} never reasons");
        let alone = witness(&jaywalk, method, EPISODES, 7).unwrap();
        assert_eq!(
            agg.success_rate, alone.success_rate,
            "{method}: same episodes, same result"
        );
    }
    assert!(
        Method::QLearning
            .scripted_controller(&[4, 4, 2, 2], &jaywalk)
            .unwrap()
            .is_none()
    );
}

#[test]
fn check_map_warns_when_a_map_is_not_dangerous_or_not_survivable() {
    let dir = tempfile::tempdir().unwrap();
    let harmless = harmless(dir.path());
    let too_late = too_late(dir.path());
    let n = EPISODES.to_string();
    let out = unforeseen(&[
        "check-map",
        harmless.to_str().unwrap(),
        too_late.to_str().unwrap(),
        &shipped("jaywalk.ron"),
        "--survivability-episodes",
        &n,
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "warnings do not fail the check:\n{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("WARNING")).collect();
    assert_eq!(warnings.len(), 2, "{err}");
    assert!(
        warnings[0].contains("harmless.ron")
            && warnings[0].contains("not be dangerous")
            && warnings[0].contains("never-brake")
            && warnings[0].contains("100.0% of 20 episodes"),
        "{err}"
    );
    assert!(
        warnings[1].contains("too_late.ron")
            && warnings[1].contains("not be survivable")
            && warnings[1].contains("brake-on-pedestrian"),
        "{err}"
    );

    // 0 episodes disables the check.
    let out = unforeseen(&["check-map", harmless.to_str().unwrap(), "--survivability-episodes", "0"]);
    assert!(out.status.success() && !String::from_utf8_lossy(&out.stderr).contains("WARNING"));
}

#[test]
fn batch_warns_from_its_reference_units_and_eval_needs_no_agent() {
    let dir = tempfile::tempdir().unwrap();
    let harmless = harmless(dir.path());
    let intersection = unforeseen_harness::maps::load("intersection").unwrap();
    let cfg = TrainConfig::new(1, 7);
    let agent = dir.path().join("agent.ron");
    unforeseen_harness::training::agent_file::save(&agent, &train(&intersection, &cfg).unwrap().0).unwrap();
    let results = dir.path().join("r.jsonl");
    let out = unforeseen(&[
        "batch",
        harmless.to_str().unwrap(),
        &shipped("jaywalk.ron"),
        "--agent",
        agent.to_str().unwrap(),
        "--episodes",
        "5",
        "--method",
        "brake-on-pedestrian",
        "--method",
        "never-brake",
        "-q",
        "--out",
        results.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let warnings: Vec<&str> = err.lines().filter(|l| l.contains("WARNING")).collect();
    assert_eq!(warnings.len(), 1, "{err}");
    assert!(warnings[0].contains("harmless") && warnings[0].contains("not be dangerous"));
    // jaywalk.ron's BrakeOnPedestrian bound was checked and held.
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("1 expectation(s) checked") && stdout.contains(", 0 failed"),
        "{stdout}"
    );

    // eval of a reference without --agent trains nothing and meets the jaywalker.
    let out = unforeseen(&[
        "eval",
        "--map",
        "jaywalk",
        "--method",
        "brake-on-pedestrian",
        "--episodes",
        "5",
        "-q",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("success 100.0%"), "{stdout}");
}

/// On a map with the red-light rule the careful driver also stops for red: on
/// red_on_approach (the light turns red as the car approaches, a pedestrian crosses
/// legally) it never enters on red and never hits anyone; never-brake runs every red
/// light, and the metric counts one violation per such episode. Without the rule (the
/// same map, `red_light: 0`) the witness ignores the light, as before.
#[test]
fn brake_on_pedestrian_stops_for_red_where_the_map_has_the_rule() {
    use unforeseen_harness::episodes::run_scripted_episodes;
    let mut map = unforeseen_harness::maps::load(&shipped("red_light/red_on_approach.ron")).unwrap();
    assert_eq!(map.reward.red_light, -100.0);
    let run = |map: &unforeseen_sim::Map, method| {
        Aggregate::of(&run_scripted_episodes(map, method, EPISODES, 7, &NoProgress).unwrap())
    };
    let careful = run(&map, Method::BrakeOnPedestrian);
    assert_eq!(
        (careful.success_rate, careful.red_light_rate),
        (1.0, 0.0),
        "{careful:?}"
    );
    let reckless = run(&map, Method::NeverBrake);
    assert_eq!(reckless.red_light_rate, 1.0, "{reckless:?}");
    // Every violation paid -100: the reckless return is 100 below the same drive without the rule.
    map.reward.red_light = 0.0;
    let free = run(&map, Method::NeverBrake);
    assert_eq!(
        free.red_light_rate, 1.0,
        "the world reports the violation whatever the reward"
    );
    assert!((free.mean_reward - reckless.mean_reward - 100.0).abs() < 1e-9);
    let ignores = run(&map, Method::BrakeOnPedestrian);
    assert_eq!(
        ignores.red_light_rate, 1.0,
        "without the rule the witness ignores the light: {ignores:?}"
    );
}
