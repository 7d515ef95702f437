//! The env's contract: reset/step determinism, terminated vs truncated, both observation
//! forms, the reward's terms, and refused calls (bad action, before reset, after the end).

use proptest::prelude::*;
use unforeseen_env::{Action, Env, EnvConfig, EnvError, Observation, ObservationForm, Step, kinematic};
use unforeseen_sim::{Map, embedded};

fn map(name: &str) -> Map {
    embedded::load(name).expect("embedded map")
}

/// A map from RON text over the embedded maps.
fn map_from(text: &str) -> Map {
    Map::from_str_named("test.ron", text, &embedded::base).expect("valid map")
}

fn kinematic_env(map: &Map) -> Env {
    let config = EnvConfig {
        observation: ObservationForm::Kinematic,
        pedestrian_slots: 3,
        ..EnvConfig::default()
    };
    Env::new(map, config).expect("env")
}

/// Runs `actions` (cycled) until the episode ends; returns every step.
fn rollout(env: &mut Env, seed: u64, actions: &[usize]) -> (Observation, Vec<Step>) {
    let (first, _) = env.reset(seed);
    let mut steps = Vec::new();
    for &a in actions.iter().cycle() {
        let step = env.step(a).expect("valid action");
        let over = step.terminated || step.truncated;
        steps.push(step);
        if over {
            break;
        }
    }
    (first, steps)
}

#[test]
fn running_a_red_light_pays_the_rule_term_on_that_tick_only() {
    // Red from 7 s: a car that speeds up from the start reaches the crosswalk at 7.8 s.
    let src = |red_light: f64| {
        format!(
            "Map(base: \"intersection\", pedestrians: [], light: (offset: Fixed(0.0), cycle: [(phase: Green, duration: 7.0), (phase: Red, duration: 20.0)]), reward: (red_light: {red_light:?}))"
        )
    };
    let with = map_from(&src(-30.0));
    let without = map_from(&src(0.0));
    let (_, a) = rollout(
        &mut Env::new(&with, EnvConfig::default()).unwrap(),
        3,
        &[Action::SpeedUp.index()],
    );
    let (_, b) = rollout(
        &mut Env::new(&without, EnvConfig::default()).unwrap(),
        3,
        &[Action::SpeedUp.index()],
    );
    assert_eq!(a.len(), b.len());
    let flagged: Vec<usize> = (0..a.len()).filter(|&k| a[k].info.events.red_light).collect();
    assert_eq!(flagged, vec![7], "the tick 7..8 s enters the crosswalk on red");
    for (k, (x, y)) in a.iter().zip(&b).enumerate() {
        // The world reports the violation on both maps; only the rule's map pays for it.
        assert_eq!(x.info.events, y.info.events);
        let t = x.info.reward;
        assert_eq!(x.reward, t.progress + t.time + t.goal + t.crash + t.red_light);
        assert_eq!(t.red_light, if k == 7 { -30.0 } else { 0.0 });
        assert_eq!(y.info.reward.red_light, 0.0);
        let expected = if k == 7 { y.reward - 30.0 } else { y.reward };
        assert_eq!(x.reward, expected, "tick {k}");
    }
    // A green light throughout: no violation.
    let green = map_from(
        "Map(base: \"intersection\", pedestrians: [], light: (offset: Fixed(0.0), cycle: [(phase: Green, duration: 100.0)]), reward: (red_light: -30.0))",
    );
    let (_, g) = rollout(
        &mut Env::new(&green, EnvConfig::default()).unwrap(),
        3,
        &[Action::SpeedUp.index()],
    );
    assert!(
        g.iter()
            .all(|s| !s.info.events.red_light && s.info.reward.red_light == 0.0)
    );
}

#[test]
fn the_same_seed_and_actions_give_bit_identical_steps() {
    let m = map("two_pedestrians");
    for form in [ObservationForm::Discrete, ObservationForm::Kinematic] {
        let config = EnvConfig {
            observation: form,
            ..EnvConfig::default()
        };
        let mut a = Env::new(&m, config.clone()).unwrap();
        let mut b = Env::new(&m, config).unwrap();
        let actions = [1, 1, 0, 2, 1, 0];
        let (fa, ra) = rollout(&mut a, 11, &actions);
        // b runs another episode first: reset starts afresh.
        rollout(&mut b, 12, &actions);
        let (fb, rb) = rollout(&mut b, 11, &actions);
        assert_eq!(fa, fb);
        assert_eq!(ra.len(), rb.len());
        for (x, y) in ra.iter().zip(&rb) {
            assert_eq!(x.reward.to_bits(), y.reward.to_bits());
            assert_eq!(x, y);
        }
    }
}

#[test]
fn a_random_light_offset_depends_on_the_seed() {
    let m = map_from("Map(base: \"intersection\", name: \"random_light\", light: (offset: Random))");
    let mut env = kinematic_env(&m);
    let first: Vec<_> = (0..8).map(|seed| env.reset(seed).1.light_time_left.to_bits()).collect();
    let mut distinct = first.clone();
    distinct.sort_unstable();
    distinct.dedup();
    assert!(distinct.len() > 1, "eight seeds, one light offset: {first:?}");
}

#[test]
fn a_time_out_truncates_and_the_goal_or_a_collision_terminates() {
    // Braking from the start: the car stops and the episode runs out of ticks.
    let m = map("intersection");
    let mut env = Env::new(&m, EnvConfig::default()).unwrap();
    let (_, steps) = rollout(&mut env, 1, &[Action::SlowDown.index()]);
    let last = steps.last().unwrap();
    assert!(last.truncated && !last.terminated, "{last:?}");
    assert!(last.info.events.timeout && !last.info.events.goal && !last.info.events.collision);
    assert_eq!(steps.len(), m.episode.max_steps as usize);
    assert!(steps[..steps.len() - 1].iter().all(|s| !s.terminated && !s.truncated));

    // Full speed on the intersection: where it meets no pedestrian crossing on red, the
    // goal terminates.
    let arrivals: Vec<Step> = (0..10)
        .filter_map(|seed| rollout(&mut env, seed, &[Action::SpeedUp.index()]).1.pop())
        .filter(|last| last.info.events.goal)
        .collect();
    assert!(!arrivals.is_empty(), "some of ten full-speed episodes arrive");
    for last in &arrivals {
        assert!(
            last.terminated && !last.truncated && !last.info.events.collision,
            "{last:?}"
        );
        assert_eq!(last.info.reward.goal, m.reward.goal);
        assert!(last.info.state.d == 0, "arrived: d = 0");
    }

    // Full speed into the jaywalker: a collision terminates.
    let j = map("jaywalk");
    let mut env = Env::new(&j, EnvConfig::default()).unwrap();
    let (_, steps) = rollout(&mut env, 1, &[Action::SpeedUp.index()]);
    let last = steps.last().unwrap();
    assert!(
        last.terminated && !last.truncated && last.info.events.collision,
        "{last:?}"
    );
    assert_eq!(last.info.reward.crash, j.reward.crash);
    assert_eq!(last.info.reward.goal, 0.0);
}

#[test]
fn the_discrete_observation_is_the_observed_state_and_its_index() {
    let m = map("jaywalk");
    let mut env = Env::new(&m, EnvConfig::default()).unwrap();
    let (first, info) = env.reset(5);
    let disc = env.discretizer().clone();
    assert_eq!(
        first,
        Observation::Discrete {
            state: info.observed,
            index: disc.encode(info.observed)
        }
    );
    assert_eq!(info.state, info.observed, "no noise on this map");
    assert_eq!(info.state, disc.state(env.snapshot()));
    let step = env.step(1).unwrap();
    assert_eq!(step.observation.index(), Some(disc.encode(step.info.observed)));
    assert_eq!(step.observation.kinematic(), None);
}

#[test]
fn observation_noise_corrupts_the_observation_not_the_true_state() {
    let m = map_from("Map(base: \"jaywalk\", name: \"noisy\", bins: (observation_noise: 0.3))");
    let mut env = Env::new(&m, EnvConfig::default()).unwrap();
    let (mut differ, mut ticks) = (0, 0);
    for seed in 0..5 {
        let (_, steps) = rollout(&mut env, seed, &[1, 0, 2]);
        for s in &steps {
            ticks += 1;
            differ += usize::from(s.info.observed != s.info.state);
            assert_eq!(s.observation.index(), Some(env.discretizer().encode(s.info.observed)));
        }
    }
    // P(all four factors right) = 0.7^4 = 0.24, so most observations differ.
    assert!(
        differ > ticks / 2,
        "{differ} of {ticks} observations differ from the state"
    );
}

#[test]
fn the_kinematic_observation_follows_its_documented_layout() {
    let m = map("two_pedestrians");
    let mut env = kinematic_env(&m);
    let (low, high) = kinematic::bounds(&m, kinematic::Slots::pedestrians(3));
    assert_eq!(low.len(), kinematic::len(kinematic::Slots::pedestrians(3)));
    let mut seen_pedestrian = false;
    for seed in 0..4 {
        let (_, steps) = rollout(&mut env, seed, &[1, 1, 2, 0]);
        let last = steps.last().unwrap();
        let v = last.observation.kinematic().unwrap();
        let snap = env.snapshot();
        assert_eq!(v[0], snap.car_x as f32);
        assert_eq!(v[1], snap.car_speed as f32);
        assert_eq!(v[2], (m.road.goal_x - snap.car_x) as f32);
        assert_eq!(v[3] + v[4] + v[5], 1.0, "the light is one-hot");
        assert_eq!(v[6], snap.light_time_left as f32);
        for s in &steps {
            let v = s.observation.kinematic().unwrap();
            for (i, x) in v.iter().enumerate() {
                assert!(
                    low[i] <= *x && *x <= high[i],
                    "value {i} = {x} outside [{}, {}]",
                    low[i],
                    high[i]
                );
            }
            for slot in v[kinematic::HEAD..].chunks(kinematic::PER_SLOT) {
                if slot[0] == 1.0 {
                    seen_pedestrian = true;
                    assert!(slot[4] != 0.0 || slot[3] == 0.0, "pedestrians walk across (vx 0)");
                } else {
                    assert!(slot.iter().all(|x| *x == 0.0), "an empty slot is zeros: {slot:?}");
                }
            }
        }
        let mut buf = vec![0.0; kinematic::len(kinematic::Slots::pedestrians(3))];
        env.kinematic_into(&mut buf);
        assert_eq!(buf, v);
    }
    assert!(seen_pedestrian, "two_pedestrians shows pedestrians in some slot");
}

#[test]
fn vehicle_slots_hold_the_nearest_vehicles_within_bounds() {
    // Without traffic rules there are no vehicle slots: the layout is the pedestrians'.
    let plain = kinematic_env(&map("jaywalk"));
    assert_eq!(plain.slots(), kinematic::Slots::pedestrians(3));
    let m = map("junction_training");
    let mut env = kinematic_env(&m);
    let slots = env.slots();
    assert_eq!(slots.vehicles, kinematic::DEFAULT_VEHICLE_SLOTS);
    let (low, high) = kinematic::bounds(&m, slots);
    assert_eq!(low.len(), kinematic::len(slots));
    let (cy, start) = (
        m.road.car_lane_y(),
        kinematic::HEAD + kinematic::PER_SLOT * slots.pedestrians,
    );
    let mut filled = 0;
    for seed in 0..6 {
        let (_, steps) = rollout(&mut env, seed, &[0, 0, 1, 2]);
        let v = steps.last().unwrap().observation.kinematic().unwrap().to_vec();
        let snap = env.snapshot();
        let mut dists: Vec<f64> = (snap.vehicles.iter())
            .map(|o| (o.x - snap.car_x).hypot(o.y - cy))
            .filter(|d| *d <= kinematic::VEHICLE_RANGE)
            .collect();
        dists.sort_by(f64::total_cmp);
        for (j, slot) in v[start..].chunks(kinematic::PER_VEHICLE).enumerate() {
            match dists.get(j) {
                Some(d) => {
                    filled += 1;
                    assert_eq!(slot[0], 1.0);
                    let got = (f64::from(slot[1]) - snap.car_x).hypot(f64::from(slot[2]) - cy);
                    assert!((got - d).abs() < 1e-3, "slot {j}: {got} m, the {j}-th nearest is {d} m");
                    let speed = f64::from(slot[3]).hypot(f64::from(slot[4]));
                    assert!((f64::from(slot[5]).cos() * speed - f64::from(slot[3])).abs() < 1e-3);
                }
                None => assert!(slot.iter().all(|x| *x == 0.0), "an empty slot is zeros: {slot:?}"),
            }
        }
        for s in &steps {
            let v = s.observation.kinematic().unwrap();
            for (i, x) in v.iter().enumerate() {
                assert!(
                    low[i] <= *x && *x <= high[i],
                    "value {i} = {x} outside [{}, {}]",
                    low[i],
                    high[i]
                );
            }
        }
    }
    assert!(filled > 0, "the training junction shows vehicles in some slot");
    let too_many = EnvConfig {
        vehicle_slots: Some(kinematic::MAX_SLOTS + 1),
        ..EnvConfig::default()
    };
    assert!(matches!(
        Env::new(&m, too_many),
        Err(EnvError::Config {
            field: "vehicle_slots",
            ..
        })
    ));
    let none = EnvConfig {
        observation: ObservationForm::Kinematic,
        vehicle_slots: Some(0),
        ..EnvConfig::default()
    };
    assert_eq!(Env::new(&m, none).unwrap().slots(), kinematic::Slots::pedestrians(4));
}

#[test]
fn refused_calls_leave_the_env_unchanged() {
    let m = map("jaywalk");
    let mut env = Env::new(&m, EnvConfig::default()).unwrap();
    assert_eq!(env.step(0), Err(EnvError::NotReset));
    env.reset(3);
    assert_eq!(env.step(3), Err(EnvError::BadAction { action: 3 }));
    assert_eq!(env.step(usize::MAX), Err(EnvError::BadAction { action: usize::MAX }));
    let after_bad: Vec<_> = (0..5).map(|_| env.step(1).unwrap()).collect();
    let mut clean = Env::new(&m, EnvConfig::default()).unwrap();
    clean.reset(3);
    let straight: Vec<_> = (0..5).map(|_| clean.step(1).unwrap()).collect();
    assert_eq!(after_bad, straight);
    while !env.is_done() {
        env.step(1).unwrap();
    }
    assert_eq!(env.step(0), Err(EnvError::EpisodeOver));
    assert!(
        EnvError::BadAction { action: 7 }
            .to_string()
            .contains("0 (maintain), 1 (speed up), 2 (slow down)")
    );
    let bad = EnvConfig {
        pedestrian_slots: 0,
        ..EnvConfig::default()
    };
    assert!(matches!(
        Env::new(&m, bad),
        Err(EnvError::Config {
            field: "pedestrian_slots",
            ..
        })
    ));
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// For any seed and actions: the reward is the sum of its terms, the time term is paid
    /// every tick, at most one of goal and collision happens, only the last step ends the
    /// episode, and the kinematic values stay within their bounds.
    #[test]
    fn every_step_keeps_the_laws(seed in any::<u64>(), actions in proptest::collection::vec(0usize..3, 1..12)) {
        let m = map("two_pedestrians");
        let mut env = kinematic_env(&m);
        let (low, high) = kinematic::bounds(&m, kinematic::Slots::pedestrians(3));
        let (_, steps) = rollout(&mut env, seed, &actions);
        for (k, s) in steps.iter().enumerate() {
            let t = s.info.reward;
            prop_assert_eq!(s.reward, t.progress + t.time + t.goal + t.crash + t.red_light);
            prop_assert_eq!(t.red_light, 0.0);
            prop_assert_eq!(t.time, -m.reward.step_cost);
            prop_assert!(!(s.info.events.goal && s.info.events.collision));
            prop_assert_eq!(s.terminated || s.truncated, k + 1 == steps.len());
            prop_assert_eq!(s.info.step as usize, k + 1);
            let v = s.observation.kinematic().unwrap();
            for (i, x) in v.iter().enumerate() {
                prop_assert!(low[i] <= *x && *x <= high[i], "value {} = {} outside [{}, {}]", i, x, low[i], high[i]);
            }
        }
    }
}
