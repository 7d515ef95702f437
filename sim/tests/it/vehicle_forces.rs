//! The force-driven vehicle model (`dynamics: Forces`) against hand-worked physics:
//! the stopping distance after dead time and brake lag, the top speed where drive
//! equals drag plus rolling resistance, the time from 0 to 50 km/h against the
//! integrated equation of motion, energy while coasting, and the road surface (patches,
//! a patch that appears at run time).

use proptest::prelude::*;
use unforeseen_sim::dynamics::{GRAVITY, stopping_distance};
use unforeseen_sim::{Action, Dynamics, Map, SurfacePatch, Trigger, World};

/// The training intersection's car under `Forces` on an empty, long road, the governor
/// out of the way, observed every sub-step (`decision_dt` = one sub-step).
fn forces_map() -> Map {
    let mut map = Map::default();
    map.vehicle.dynamics = Dynamics::Forces;
    map.vehicle.max_speed = 70.0;
    map.road.goal_x = 100_000.0;
    map.crosswalk.x = 99_000.0;
    map.episode.decision_dt = 1.0 / map.episode.physics_hz;
    map.episode.max_steps = 1_000_000;
    map
}

/// Drive with `action` until the car stands (or `limit` sub-steps pass); the distance
/// covered, m.
fn distance_until_stopped(map: &Map, action: Action, limit: u32) -> f64 {
    let mut world = World::from_map(map, 1);
    let x0 = world.snapshot().car_x;
    for _ in 0..limit {
        world.step(action);
        if world.snapshot().car_speed == 0.0 {
            break;
        }
    }
    world.snapshot().car_x - x0
}

/// `f(v) = 0` for an increasing-then-decreasing net force, by bisection on [lo, hi].
fn root(lo: f64, hi: f64, f: impl Fn(f64) -> f64) -> f64 {
    let (mut lo, mut hi) = (lo, hi);
    for _ in 0..200 {
        let mid = (lo + hi) / 2.0;
        if f(mid) > 0.0 { lo = mid } else { hi = mid }
    }
    (lo + hi) / 2.0
}

/// Net accelerating force of "speed up" at `v` under `map`'s car, N.
fn net_drive(map: &Map, v: f64) -> f64 {
    let c = &map.vehicle;
    let drive = if v > 0.0 {
        c.drive_force.min(c.power / v)
    } else {
        c.drive_force
    };
    let grip = map.road.friction * c.mass * GRAVITY;
    drive.min(grip)
        - c.rolling_resistance * c.mass * GRAVITY
        - 0.5 * map.road.air_density * c.drag_coefficient * c.frontal_area * v * v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// Braking from v on μ with dead time and lag stops the car in
    /// `v·τ_dead + lag phase + v₁²/(2 a)` within 2% plus one sub-step's travel at v,
    /// `a = min(brake/m, μ g)` (no rolling resistance and drag here, so that the law is
    /// exact in continuous time). The sub-step term is the integration's: the
    /// semi-implicit Euler step and the brake force held over a sub-step each run half a
    /// sub-step ahead of the continuous law, which matters on short stops (9 m/s, μ 0.77,
    /// 23 m/s² of brake on 800 kg stops in 6.08 m by the law, 5.93 m integrated: 0.15 m,
    /// one sub-step at 9 m/s).
    #[test]
    fn stopping_distance_is_dead_time_lag_and_friction(
        v in 9.0..20.0f64,
        mu in 0.1..0.9f64,
        lag in 0.0..0.6f64,
        dead_steps in 0u32..18,
        mass in 800.0..4000.0f64,
        brake in 2000.0..20000.0f64,
    ) {
        let mut map = forces_map();
        let c = &mut map.vehicle;
        c.start_speed = v;
        c.mass = mass;
        c.brake_force = brake;
        c.brake_lag = lag;
        c.brake_dead_time = f64::from(dead_steps) / map.episode.physics_hz;
        c.rolling_resistance = 0.0;
        c.drag_coefficient = 0.0;
        map.road.friction = mu;
        let want = stopping_distance(&map.vehicle, v, mu);
        let got = distance_until_stopped(&map, Action::SlowDown, 60 * 120);
        let sub_step = v / map.episode.physics_hz;
        prop_assert!(
            (got - want).abs() <= 0.02 * want + sub_step,
            "stopped in {got} m, the law says {want} m"
        );
    }

    /// "Speed up" levels off at the speed where the drive force equals rolling
    /// resistance plus drag (within 0.5%).
    #[test]
    fn top_speed_is_where_drive_equals_resistance(
        mass in 800.0..4000.0f64,
        power in 30_000.0..150_000.0f64,
        drag in 0.25..0.6f64,
    ) {
        let mut map = forces_map();
        map.vehicle.mass = mass;
        map.vehicle.power = power;
        map.vehicle.drag_coefficient = drag;
        map.episode.decision_dt = 1.0;
        let want = root(0.0, 200.0, |v| net_drive(&map, v));
        prop_assume!(want < 69.0); // the governor stays out of it
        let mut world = World::from_map(&map, 1);
        for _ in 0..600 {
            world.step(Action::SpeedUp);
        }
        let got = world.snapshot().car_speed;
        prop_assert!((got - want).abs() <= 0.005 * want, "top speed {got} m/s, the balance gives {want} m/s");
    }

    /// While coasting (no drive: the engine's force is 0, and brakes released after a
    /// first tick of braking), the car's kinetic energy never increases.
    #[test]
    fn energy_never_increases_while_coasting(
        v in 0.0..30.0f64,
        mu in 0.05..2.0f64,
        mass in 800.0..4000.0f64,
        rolling in 0.0..0.05f64,
        drag in 0.0..1.0f64,
        brake_first in proptest::bool::ANY,
    ) {
        let mut map = forces_map();
        map.vehicle.start_speed = v;
        map.vehicle.drive_force = 0.0;
        map.vehicle.mass = mass;
        map.vehicle.rolling_resistance = rolling;
        map.vehicle.drag_coefficient = drag;
        map.road.friction = mu;
        let mut world = World::from_map(&map, 1);
        let mut energy = 0.5 * mass * v * v;
        for k in 0..600 {
            let action = if brake_first && k < 30 { Action::SlowDown } else { Action::SpeedUp };
            world.step(action);
            let s = world.snapshot().car_speed;
            let now = 0.5 * mass * s * s;
            prop_assert!(now <= energy, "sub-step {k}: energy rose from {energy} J to {now} J");
            energy = now;
        }
    }
}

/// From rest to 50 km/h takes the time the equation of motion
/// `m dv/dt = min(F, P/v) − c_rr m g − ½ρC_dA v²` gives (integrated with RK4 at 0.1 ms),
/// within 2%.
#[test]
fn zero_to_fifty_takes_the_integrated_time() {
    let mut map = forces_map();
    map.vehicle.start_speed = 0.0;
    let target = 50.0 / 3.6;
    let accel = |v: f64| net_drive(&map, v) / map.vehicle.mass;
    let (mut v, mut t, dt) = (0.0f64, 0.0f64, 1e-4);
    while v < target {
        let k1 = accel(v);
        let k2 = accel(v + dt / 2.0 * k1);
        let k3 = accel(v + dt / 2.0 * k2);
        let k4 = accel(v + dt * k3);
        v += dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
        t += dt;
    }
    let mut world = World::from_map(&map, 1);
    let mut prev = (0.0, 0.0);
    let got = loop {
        world.step(Action::SpeedUp);
        let s = world.snapshot();
        if s.car_speed >= target {
            // Linear interpolation between the two sub-steps around 50 km/h.
            break prev.0 + (s.time - prev.0) * (target - prev.1) / (s.car_speed - prev.1);
        }
        prev = (s.time, s.car_speed);
        assert!(s.time < 60.0, "never reached 50 km/h");
    };
    assert!(
        (got - t).abs() <= 0.02 * t,
        "0-50 km/h in {got} s, the equation says {t} s"
    );
    // Hand check of the scale: 5000 N less ~190 N of resistance on 1500 kg is 3.2 m/s².
    assert!(got > 4.0 && got < 4.7, "{got}");
}

/// Ice under the braking car lengthens its stop to what the ice's μ gives (without
/// rolling resistance and drag, which the law leaves out), and the friction is what the
/// patch says only where it lies.
#[test]
fn an_ice_patch_lengthens_the_stop() {
    let mut map = forces_map();
    map.vehicle.start_speed = 9.0;
    map.vehicle.rolling_resistance = 0.0;
    map.vehicle.drag_coefficient = 0.0;
    let dry = distance_until_stopped(&map, Action::SlowDown, 600);
    map.road.surface = vec![SurfacePatch {
        from: -10.0,
        to: 200.0,
        friction: 0.1,
        trigger: None,
    }];
    let ice = distance_until_stopped(&map, Action::SlowDown, 6000);
    let want = stopping_distance(&map.vehicle, 9.0, 0.1);
    assert!(ice > 3.0 * dry, "dry {dry} m, ice {ice} m");
    assert!((ice - want).abs() < 0.02 * want, "ice {ice} m, law {want} m");
    let world = World::from_map(&map, 1);
    assert_eq!(world.friction_at(100.0), 0.1);
    assert_eq!(world.friction_at(300.0), 0.8);
}

/// A patch with a trigger is absent until the trigger holds, then stays; a later patch
/// lies over an earlier one.
#[test]
fn a_triggered_patch_appears_at_its_time() {
    let mut map = forces_map();
    map.episode.decision_dt = 1.0;
    map.road.surface = vec![
        SurfacePatch {
            from: 0.0,
            to: 50.0,
            friction: 0.4,
            trigger: None,
        },
        SurfacePatch {
            from: 20.0,
            to: 30.0,
            friction: 0.1,
            trigger: Some(Trigger::AtTime(2.0)),
        },
    ];
    let mut world = World::from_map(&map, 1);
    assert_eq!(world.surface().count(), 1);
    assert_eq!(world.friction_at(25.0), 0.4);
    world.step(Action::Maintain);
    world.step(Action::Maintain);
    assert_eq!(world.friction_at(25.0), 0.4, "not before t = 2 s");
    world.step(Action::Maintain);
    assert_eq!(world.surface().count(), 2);
    assert_eq!(world.friction_at(25.0), 0.1);
    assert_eq!(world.friction_at(10.0), 0.4);
}

/// "Maintain" under forces holds the tick's starting speed against drag and rolling
/// resistance (a cruise controller), and mass matters for "speed up".
#[test]
fn maintain_holds_speed_and_mass_matters() {
    let mut map = forces_map();
    map.episode.decision_dt = 1.0;
    map.vehicle.start_speed = 8.0;
    let mut world = World::from_map(&map, 1);
    for _ in 0..10 {
        world.step(Action::Maintain);
        assert!(
            (world.snapshot().car_speed - 8.0).abs() < 1e-3,
            "{}",
            world.snapshot().car_speed
        );
    }
    let gain = |mass: f64| {
        let mut m = map.clone();
        m.vehicle.mass = mass;
        let mut w = World::from_map(&m, 1);
        w.step(Action::SpeedUp);
        w.snapshot().car_speed - 8.0
    };
    let (light, heavy) = (gain(1500.0), gain(3500.0));
    assert!(light > 2.0 * heavy, "1500 kg gains {light} m/s, 3500 kg {heavy} m/s");
}

/// The same map, seed and actions give bit-identical trajectories under forces, on
/// whichever thread they run (positions and speeds compared as bits).
#[test]
fn trajectories_are_bit_identical_across_threads() {
    let mut map = Map::default();
    map.vehicle.dynamics = Dynamics::Forces;
    map.road.surface = vec![SurfacePatch {
        from: 44.0,
        to: 64.0,
        friction: 0.1,
        trigger: Some(Trigger::CarWithin { min: 0.0, max: 30.0 }),
    }];
    let run = |seed: u64| {
        let mut world = World::from_map(&map, seed);
        let mut bits = Vec::new();
        let mut k = 0usize;
        while !world.is_done() {
            world.step(Action::ALL[(k * 7 + seed as usize) % 3]);
            let s = world.snapshot();
            bits.push((s.car_x.to_bits(), s.car_speed.to_bits(), s.surface.len()));
            k += 1;
        }
        bits
    };
    let here: Vec<_> = (0..4).map(run).collect();
    let threads: Vec<_> = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..4).map(|seed| scope.spawn(move || run(seed))).collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    assert_eq!(here, threads);
    assert!(
        here.iter().any(|t| t.iter().any(|&(_, _, n)| n == 1)),
        "the patch appears"
    );
}
