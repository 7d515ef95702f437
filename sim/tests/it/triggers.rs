//! Spawn triggers, pauses and collision timing, on small inline maps.

use crate::common;

use unforeseen_sim::{Action, LightPhase, Map, World};

fn map(src: &str) -> Map {
    Map::from_str_named("inline.ron", src, &|_| None).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn at_time_spawns_at_that_time() {
    let m = map("Map(pedestrians: [(trigger: AtTime(2.5), side: Near, speed: (1.0, 1.0))])");
    let mut w = World::from_map(&m, 0);
    w.step(Action::SlowDown);
    w.step(Action::SlowDown);
    assert!(w.snapshot().pedestrians.is_empty());
    w.step(Action::SlowDown);
    let s = w.snapshot();
    assert_eq!(s.pedestrians.len(), 1);
    let p = s.pedestrians[0];
    // Started at y = -(3.5 + 0.5) = -4.0 at t = 2.5 s, walking +y at 1 m/s.
    assert!((p.y - (-4.0 + 0.5)).abs() < 0.02, "y = {}", p.y);
    assert!((p.x - 66.0).abs() < 1e-6 && p.vy == 1.0);
    w.step(Action::SlowDown);
    assert!(w.snapshot().pedestrians[0].on_crosswalk);
    // 8 m at 1 m/s: gone after t = 10.5 s.
    for _ in 0..8 {
        w.step(Action::SlowDown);
    }
    assert!(w.snapshot().pedestrians.is_empty());
}

#[test]
fn green_starts_respects_light_and_probability() {
    let m = map(
        "Map(light: (offset: Fixed(14.0)), pedestrians: [(trigger: GreenStarts, side: Far)], episode: (max_steps: 60))",
    );
    // Red for 10 s first, then green: the rule fires at t = 10 s.
    let mut w = World::from_map(&m, 3);
    let (snaps, _) = common::run(&mut w, |_| Action::SlowDown);
    let first = snaps.iter().position(|s| !s.pedestrians.is_empty()).unwrap();
    assert_eq!(first, 11);
    assert_eq!(snaps[first].light, LightPhase::Green);
    assert!(snaps[first].pedestrians[0].vy < 0.0, "far side walks towards -y");
    let never = map("Map(pedestrians: [(trigger: GreenStarts, probability: 0.0)], episode: (max_steps: 60))");
    let mut w = World::from_map(&never, 3);
    let (snaps, _) = common::run(&mut w, |_| Action::SlowDown);
    assert!(snaps.iter().all(|s| s.pedestrians.is_empty()));
}

#[test]
fn car_within_fires_inside_the_window() {
    let m = map("Map(pedestrians: [(trigger: CarWithin(min: 20.0, max: 30.0), side: Far)])");
    let mut w = World::from_map(&m, 0);
    let near = m.crosswalk_near_x();
    loop {
        let before = w.snapshot();
        w.step(Action::Maintain);
        let s = w.snapshot();
        if !s.pedestrians.is_empty() {
            // Fired in the sub-step the car's front entered the window (30 m before).
            let walked = (4.0 - s.pedestrians[0].y) / s.pedestrians[0].vy.abs();
            let fired_at = s.time - walked;
            let car_at_fire = before.car_x + 3.0 * (fired_at - before.time);
            assert!(
                (near - car_at_fire - 30.0).abs() < 0.1,
                "fired {} m before",
                near - car_at_fire
            );
            break;
        }
        assert!(s.car_x < near - 20.0, "window passed without firing");
    }
}

#[test]
fn pause_holds_the_pedestrian_still() {
    let m = map(
        "Map(pedestrians: [(trigger: AtTime(0.0), side: Far, speed: (1.0, 1.0), pause: (after: 2.0, duration: 3.0))])",
    );
    let mut w = World::from_map(&m, 0);
    w.step(Action::SlowDown);
    w.step(Action::SlowDown);
    w.step(Action::SlowDown);
    let a = w.snapshot().pedestrians[0];
    w.step(Action::SlowDown);
    let b = w.snapshot().pedestrians[0];
    assert_eq!(a.y, 2.0);
    assert_eq!(b.y, 2.0);
    assert_eq!(b.vy, 0.0);
    w.step(Action::SlowDown);
    w.step(Action::SlowDown);
    assert!(w.snapshot().pedestrians[0].y < 2.0);
}

/// A pedestrian standing in the car's lane is hit exactly when the shapes
/// first overlap (detected within one physics sub-step, never a tick late).
#[test]
fn collision_is_reported_when_the_shapes_touch() {
    let m = map(
        "Map(pedestrians: [(trigger: AtTime(0.0), side: Near, speed: (1.0, 1.0), pause: (after: 2.25, duration: 1000.0))], episode: (max_steps: 60))",
    );
    let mut w = World::from_map(&m, 0);
    let (snaps, out) = common::run(&mut w, |_| Action::Maintain);
    assert!(out.collision && !out.goal);
    let s = snaps.last().unwrap();
    // Front meets the pedestrian's disc at x = 66 - 0.3 = 65.7 m, at t = 65.7 / 3 = 21.9 s.
    let h = 1.0 / 60.0;
    assert!(
        s.car_x >= 65.7 && s.car_x <= 65.7 + 2.0 * 3.0 * h + 1e-3,
        "car at {}",
        s.car_x
    );
    assert_eq!(out.step, 22);
    assert!((s.time - 21.9).abs() <= 2.0 * h, "t = {}", s.time);
}

#[test]
fn episode_starting_mid_red_has_a_pedestrian_already_crossing() {
    // 3 s into the red phase at time 0; the red-start pedestrian left at its start.
    let m =
        map("Map(light: (offset: Fixed(17.0)), pedestrians: [(trigger: RedStarts, side: Near, speed: (1.0, 1.0))])");
    let w = World::from_map(&m, 0);
    assert!(w.snapshot().pedestrians.is_empty(), "spawned during the first sub-step");
    let mut w = w;
    w.step(Action::SlowDown);
    let p = w.snapshot().pedestrians[0];
    // Walked 3 s + 1 s at 1 m/s from y = -4.0.
    assert!((p.y - 0.0).abs() < 0.02, "y = {}", p.y);
    // Too late in red: it would already have crossed, so nobody appears.
    let late = map("Map(light: (offset: Fixed(23.5)), pedestrians: [(trigger: RedStarts, speed: (1.0, 1.0))])");
    let mut w = World::from_map(&late, 0);
    w.step(Action::SlowDown);
    assert!(w.snapshot().pedestrians.is_empty());
}
