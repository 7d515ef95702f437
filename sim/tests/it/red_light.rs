//! The red-light violation (`StepOutcome::red_light`): the car's front crossing the
//! crosswalk's near edge in a sub-step whose light is red. With one sub-step per decision
//! tick, the tick that reports it is exactly the sub-step of the crossing.

use unforeseen_sim::{Action, Map, World};

fn map(src: &str) -> Map {
    Map::from_str_named("inline.ron", src, &|_| None).unwrap_or_else(|e| panic!("{e}"))
}

/// A map with one physics sub-step per decision tick (0.05 s at 20 Hz) and `light`.
fn one_substep_map(light: &str) -> Map {
    map(&format!(
        "Map(light: {light}, episode: (decision_dt: 0.05, physics_hz: 20.0, max_steps: 1000))"
    ))
}

/// Drives `action` until the episode ends; returns, per tick, (front before, front
/// after, red_light).
fn drive(map: &Map, action: Action) -> Vec<(f64, f64, bool)> {
    let mut world = World::from_map(map, 1);
    let mut out = Vec::new();
    while !world.is_done() {
        let before = world.snapshot().car_x;
        let step = world.step(action);
        out.push((before, world.snapshot().car_x, step.red_light));
    }
    out
}

#[test]
fn a_violation_is_reported_exactly_on_the_sub_step_that_crosses_on_red() {
    let m = one_substep_map("(cycle: [(phase: Red, duration: 3600.0)])");
    assert_eq!(m.episode.substeps(), 1);
    let near = m.crosswalk_near_x();
    let ticks = drive(&m, Action::SpeedUp);
    let flagged: Vec<usize> = (0..ticks.len()).filter(|&i| ticks[i].2).collect();
    assert_eq!(flagged.len(), 1, "one violation per episode: {flagged:?}");
    let (before, after, _) = ticks[flagged[0]];
    assert!(
        before < near && after >= near,
        "flagged at {before}..{after}, edge {near}"
    );
    // No other sub-step crosses the edge.
    for (i, &(b, a, _)) in ticks.iter().enumerate() {
        if i != flagged[0] {
            assert!(!(b < near && a >= near));
        }
    }
}

#[test]
fn no_violation_on_green_or_amber_or_when_the_car_stops_before_the_crosswalk() {
    for phase in ["Green", "Amber"] {
        let m = one_substep_map(&format!("(cycle: [(phase: {phase}, duration: 3600.0)])"));
        assert!(drive(&m, Action::SpeedUp).iter().all(|t| !t.2), "{phase}");
    }
    // Red throughout, but the car brakes to a stop long before the edge (time-out).
    let m = one_substep_map("(cycle: [(phase: Red, duration: 3600.0)])");
    let ticks = drive(&m, Action::SlowDown);
    assert!(ticks.iter().all(|t| !t.2));
    assert!(ticks.last().unwrap().1 < m.crosswalk_near_x());
}

#[test]
fn the_light_at_the_crossing_decides_with_the_default_ticks() {
    // From the start line, speeding up, the front reaches the near edge (x = 64 m) at
    // t = 70/9 = 7.78 s. Red from 7 s: a violation in the tick 7..8 s; red from 8 s: none.
    let drive_ticks = |green: f64| {
        let m = map(&format!(
            "Map(light: (cycle: [(phase: Green, duration: {green}), (phase: Red, duration: 20.0)]))"
        ));
        let mut world = World::from_map(&m, 1);
        let mut flagged = Vec::new();
        while !world.is_done() {
            if world.step(Action::SpeedUp).red_light {
                flagged.push(world.snapshot().step);
            }
        }
        flagged
    };
    assert_eq!(drive_ticks(7.0), vec![8]);
    assert_eq!(drive_ticks(7.7), vec![8]);
    assert_eq!(drive_ticks(7.8), Vec::<u32>::new());
    assert_eq!(drive_ticks(8.0), Vec::<u32>::new());
}
