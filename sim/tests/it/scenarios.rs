//! The shipped scenarios behave as designed: on the training map pedestrians
//! cross only on red; in jaywalk.ron (and the other unforeseen maps) a car that
//! never brakes hits the jaywalker for every seed, and a car that brakes as soon
//! as a pedestrian is on the crosswalk at a decision tick stops before the
//! crosswalk (or, for late_fast.ron's runner, slows down until they are gone),
//! is not hit, and then reaches the destination.

use crate::common::{brake_for_pedestrians, run};
use unforeseen_sim::{Action, LightPhase, World, embedded};

const SEEDS: u64 = 60;

#[test]
fn training_pedestrians_cross_only_on_red() {
    let map = embedded::load("intersection").unwrap();
    let mut seen = 0;
    for seed in 0..SEEDS {
        let mut world = World::from_map(&map, seed);
        // A car that waits before the crosswalk sees a whole light cycle.
        let (snaps, _) = run(&mut world, |_| Action::SlowDown);
        for s in &snaps {
            if s.pedestrian_on_crosswalk() {
                seen += 1;
                assert_eq!(s.light, LightPhase::Red, "seed {seed}, t = {}", s.time);
            }
        }
    }
    assert!(seen > SEEDS, "pedestrians should cross on most red phases");
}

/// A car that never brakes hits the jaywalker, whatever its speed (6 or 9 m/s).
fn never_braking_hits(name: &str, policy: fn(&unforeseen_sim::Snapshot) -> Action) {
    let map = embedded::load(name).unwrap();
    for seed in 0..SEEDS {
        let mut world = World::from_map(&map, seed);
        let (snaps, out) = run(&mut world, policy);
        let last = snaps.last().unwrap();
        assert!(
            out.collision,
            "{name} seed {seed}: no collision (car at {:.2} m, goal {})",
            last.car_x, out.goal
        );
        // The collision happens at the crosswalk, with the pedestrian in the road.
        let near = map.crosswalk_near_x();
        assert!(last.car_x >= near && last.car_x <= near + map.crosswalk.width + map.vehicle.length + 1.0);
    }
}

/// The careful driver stops before the crosswalk and is never hit.
fn braking_is_safe(name: &str) {
    braking_is_safe_stopping(name, true);
}

/// The careful driver is never hit; with `must_stop` it also comes to a full stop
/// before the crosswalk while someone is on it (a fast runner, late_fast.ron, may
/// leave the crosswalk while the car is still slowing down: then it only slows).
fn braking_is_safe_stopping(name: &str, must_stop: bool) {
    let map = embedded::load(name).unwrap();
    let near = map.crosswalk_near_x();
    for seed in 0..SEEDS {
        let mut world = World::from_map(&map, seed);
        let (snaps, out) = run(&mut world, brake_for_pedestrians);
        assert!(!out.collision, "{name} seed {seed}: hit");
        assert!(out.goal, "{name} seed {seed}: did not arrive in {} ticks", out.step);
        // It came to a full stop (or at least slowed down) before the crosswalk while
        // someone was on it.
        let limit = if must_stop { 0.0 } else { map.vehicle.max_speed - 1.0 };
        assert!(
            snaps
                .iter()
                .any(|s| s.car_speed <= limit && s.car_x < near && s.pedestrian_on_crosswalk()),
            "{name} seed {seed}: never waited"
        );
        for s in &snaps {
            if s.pedestrian_on_crosswalk() {
                assert!(
                    s.car_x < near,
                    "{name} seed {seed}: entered the crosswalk at t = {}",
                    s.time
                );
            }
        }
    }
}

fn speed_up(_: &unforeseen_sim::Snapshot) -> Action {
    Action::SpeedUp
}

/// Speed up once (to 6 m/s), then hold.
fn six_metres_per_second(s: &unforeseen_sim::Snapshot) -> Action {
    if s.car_speed < 5.0 {
        Action::SpeedUp
    } else {
        Action::Maintain
    }
}

fn keep_speed(_: &unforeseen_sim::Snapshot) -> Action {
    Action::Maintain
}

#[test]
fn jaywalk_never_braking_car_hits_the_pedestrian() {
    never_braking_hits("jaywalk", speed_up);
    never_braking_hits("jaywalk", six_metres_per_second);
}

#[test]
fn jaywalk_braking_car_stops_before_the_crosswalk() {
    braking_is_safe("jaywalk");
}

#[test]
fn jaywalker_appears_on_green_at_distance_bin_2() {
    let map = embedded::load("jaywalk").unwrap();
    for seed in 0..10 {
        let mut world = World::from_map(&map, seed);
        let (snaps, _) = run(&mut world, brake_for_pedestrians);
        let first = snaps.iter().find(|s| s.pedestrian_on_crosswalk()).unwrap();
        assert_eq!(first.light, LightPhase::Green);
        assert!(first.distance_to_goal > 30.0 && first.distance_to_goal < 60.0);
    }
}

#[test]
fn far_appearance_jaywalker_appears_on_green_at_distance_bin_3() {
    let map = embedded::load("far_appearance").unwrap();
    for seed in 0..SEEDS {
        let mut world = World::from_map(&map, seed);
        let (snaps, _) = run(&mut world, brake_for_pedestrians);
        let first = snaps.iter().find(|s| s.pedestrian_on_crosswalk()).unwrap();
        assert_eq!(first.light, LightPhase::Green);
        assert!(first.distance_to_goal > 60.0, "seed {seed}: {}", first.distance_to_goal);
    }
}

#[test]
fn other_unforeseen_scenarios() {
    for name in [
        "jaywalk_late",
        "two_pedestrians",
        "stop_midway",
        "stuck_green",
        "far_appearance",
        "slow_walker",
        "long_pause",
        "near_kerb",
    ] {
        never_braking_hits(name, speed_up);
        braking_is_safe(name);
    }
    never_braking_hits("late_fast", speed_up);
    braking_is_safe_stopping("late_fast", false);
    // With the light stuck on green even a slow car meets the jaywalker.
    never_braking_hits("stuck_green", keep_speed);
}

/// Every embedded map written back as RON (its expectations' names as bare identifiers)
/// loads to the same map, and as JSON its names are plain strings.
#[test]
fn maps_round_trip_through_ron() {
    for name in unforeseen_sim::embedded::names() {
        let map = unforeseen_sim::embedded::load(name).unwrap();
        let text = ron::to_string(&map).unwrap();
        let bases = |b: &str| unforeseen_sim::embedded::base_in(name, b);
        let again = unforeseen_sim::Map::from_str_named(&format!("{name}.ron"), &text, &bases)
            .unwrap_or_else(|e| panic!("{name}: {e}\n{text}"));
        assert_eq!(again, map, "{name}");
        if let Some(e) = map.expect.first() {
            let json = serde_json::to_value(e).unwrap();
            assert_eq!(json["method"], serde_json::Value::String(e.method.clone()));
        }
    }
}
