//! The car's longitudinal physics matches kinematics: speed up reaches the
//! destination when constant-acceleration kinematics says it should, slow down
//! stops the car and never reverses it, maintain holds the speed exactly.

use crate::common;

use proptest::prelude::*;
use unforeseen_sim::{Action, Map, World};

/// Position after `t` seconds of "speed up" from `v0` at `a`, capped at `vmax`.
fn kinematic_x(x0: f64, v0: f64, a: f64, vmax: f64, t: f64) -> f64 {
    let t_acc = ((vmax - v0) / a).min(t);
    x0 + v0 * t_acc + 0.5 * a * t_acc * t_acc + vmax * (t - t_acc)
}

#[test]
fn speed_up_reaches_goal_in_predicted_time() {
    let map = Map::default(); // the intersection without pedestrians
    let v = &map.vehicle;
    let (a, v0, vmax) = (v.max_accel, v.start_speed, v.max_speed);
    let dt = map.episode.decision_dt;
    let h = 1.0 / map.episode.physics_hz;
    // Time to reach vmax, the distance covered meanwhile, then cruise.
    let t_acc = (vmax - v0) / a; // 2 s
    let x_acc = v0 * t_acc + 0.5 * a * t_acc * t_acc; // 12 m
    let t_goal = t_acc + (map.road.goal_x - v.start_x - x_acc) / vmax; // 10.667 s
    // Semi-implicit Euler at step h overshoots constant acceleration by at most
    // a·h/2 per second of acceleration: a·h·t_acc/2 = 0.05 m here.
    let tol = a * h * t_acc / 2.0 + 1e-3;

    let mut world = World::from_map(&map, 0);
    let mut tick = 0u32;
    loop {
        let out = world.step(Action::SpeedUp);
        tick += 1;
        let s = world.snapshot();
        assert!(!out.collision);
        if out.goal {
            break;
        }
        let t = tick as f64 * dt;
        let want = kinematic_x(v.start_x, v0, a, vmax, t);
        assert!(
            (s.car_x - want).abs() <= tol,
            "tick {tick}: x = {} but kinematics says {want} (tolerance {tol})",
            s.car_x
        );
        let want_v = (v0 + a * t).min(vmax);
        assert!((s.car_speed - want_v).abs() < 1e-5, "tick {tick}: v = {}", s.car_speed);
        assert!(tick < 100, "never arrived");
    }
    let expected_tick = (t_goal / dt).ceil() as u32;
    assert_eq!(tick, expected_tick, "goal at tick {tick}, kinematics says {t_goal} s");
    let s = world.snapshot();
    assert!(s.distance_to_goal <= 0.0);
    // The goal is detected in the sub-step the front crosses the line.
    assert!(
        (s.time - t_goal).abs() <= h + 1e-9,
        "goal at {} s, predicted {t_goal} s",
        s.time
    );
}

#[test]
fn slow_down_stops_and_never_reverses() {
    let map = Map::default();
    let mut world = World::from_map(&map, 0);
    let mut last_x = world.snapshot().car_x;
    for tick in 1..=10 {
        let out = world.step(Action::SlowDown);
        let s = world.snapshot();
        assert!(s.car_speed >= 0.0);
        assert!(s.car_x >= last_x, "reversed at tick {tick}");
        assert!(out.progress >= 0.0);
        if tick >= 1 {
            // 3 m/s at 3 m/s² stops within the first 1 s tick, after 1.5 m.
            assert_eq!(s.car_speed, 0.0, "tick {tick}");
            assert!((s.car_x - 1.5).abs() < 0.05, "stopped at {}", s.car_x);
        }
        last_x = s.car_x;
    }
    // It stays put: the body does not creep or drift while held.
    let x = world.snapshot().car_x;
    world.step(Action::SlowDown);
    assert_eq!(world.snapshot().car_x.to_bits(), x.to_bits());
}

#[test]
fn maintain_holds_speed_exactly() {
    let map = Map::default();
    let mut world = World::from_map(&map, 0);
    let v0 = world.snapshot().car_speed;
    for _ in 0..5 {
        world.step(Action::Maintain);
        assert_eq!(world.snapshot().car_speed.to_bits(), v0.to_bits());
    }
    assert!((world.snapshot().car_x - 15.0).abs() < 1e-3);
}

#[test]
fn finished_world_is_a_no_op() {
    let map = Map::default();
    let mut world = World::from_map(&map, 0);
    let (_, last) = common::run(&mut world, |_| Action::SpeedUp);
    assert!(last.goal && world.is_done());
    let before = world.snapshot();
    let again = world.step(Action::SlowDown);
    assert_eq!(again, last);
    assert_eq!(world.snapshot(), before);
}

#[test]
fn step_limit_times_out() {
    let map = Map::default();
    let mut world = World::from_map(&map, 0);
    let (_, last) = common::run(&mut world, |_| Action::SlowDown);
    assert!(last.timeout && !last.goal && !last.collision);
    assert_eq!(last.step, map.episode.max_steps);
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, ..ProptestConfig::default() })]

    /// Any action sequence keeps the speed on the lattice {0, 3, 6, 9} m/s
    /// (decision_dt × max_accel = 3 m/s), within [0, max_speed], and never moves the car backwards.
    #[test]
    fn speeds_stay_on_the_lattice(actions in proptest::collection::vec(0usize..3, 1..30)) {
        let map = Map::default();
        let mut world = World::from_map(&map, 1);
        let mut last_x = world.snapshot().car_x;
        for i in actions {
            let out = world.step(Action::from_index(i).unwrap());
            let s = world.snapshot();
            prop_assert!(s.car_speed >= 0.0 && s.car_speed <= map.vehicle.max_speed);
            prop_assert!(s.car_x >= last_x);
            if out.done() { break; } // the goal may be reached mid-tick
            let lattice = (s.car_speed / 3.0).round() * 3.0;
            prop_assert!((s.car_speed - lattice).abs() < 1e-5, "speed {}", s.car_speed);
            last_x = s.car_x;
        }
    }
}

#[test]
fn actions_round_trip() {
    for (i, a) in Action::ALL.iter().enumerate() {
        assert_eq!(a.index(), i);
        assert_eq!(Action::from_index(i), Some(*a));
    }
    assert_eq!(Action::from_index(3), None);
    assert_eq!(Action::SlowDown.to_string(), "slow down");
}
