//! The margins of an episode (how close it came to a collision), against values worked
//! by hand on the default road: the car's lane at y = -1.75 m, its box 4.5 m × 1.8 m,
//! its front starting at x = 0 at 3 m/s; pedestrians are discs of 0.3 m on the
//! crosswalk at x = 66 m, starting from the near sidewalk at y = -4 m; other vehicles
//! are boxes of 4.5 m.

use crate::common;

use unforeseen_sim::{Action, Map, World};

fn map(src: &str) -> Map {
    Map::from_str_named("inline.ron", src, &|_| None).unwrap_or_else(|e| panic!("{e}"))
}

/// A pedestrian who stops in the far lane (y = +1.75 m) and stays: the car passes with
/// the box's upper edge at y = -0.85 m, so the clearance is 1.75 + 0.85 - 0.3 = 2.3 m,
/// and the car is never on a collision course (it crosses the car's lane 60 m ahead
/// of the car, which would take 20 s to get there). Her disc reaches into the car's lane
/// band (y < -0.85 m) by `e(t) = √(0.3² − a²)` along the road, `a = t − 3.15` its centre's
/// gap from the band (her centre at y = -4 + t), until t = 3.45 s; the car's front
/// reaches that chord at (66 − e)/3 s, so the post-encroachment time is the least of
/// (66 − e)/3 − t, at a = 0.2846 (where e's slope is 3): e = 0.0949 and PET = 21.968 −
/// 3.435 = 18.534 s (both tracks sampled every sub-step, 1/60 s).
#[test]
fn a_pass_by_the_far_lane_has_the_clearance_worked_by_hand() {
    let m = map(
        "Map(pedestrians: [(trigger: AtTime(0.0), side: Near, speed: (1.0, 1.0), pause: (after: 5.75, duration: 1000.0))], episode: (max_steps: 60))",
    );
    let mut w = World::from_map(&m, 0);
    w.measure_margins();
    let (_, out) = common::run(&mut w, |_| Action::Maintain);
    assert!(out.goal && !out.collision);
    let margins = w.margins().expect("measured");
    let clearance = margins.clearance.expect("a pedestrian was there");
    assert!((clearance - 2.3).abs() < 1e-3, "clearance {clearance}");
    assert_eq!((margins.ttc, margins.stop_margin), (None, None));
    assert!(margins.could_stop());
    let pet = margins.pet.expect("her path met the car's");
    assert!((pet - 18.534).abs() < 2.0 / 60.0, "PET {pet}");
    assert_eq!(margins.vehicle_clearance, None);
}

/// A lead car whose front starts 20 m ahead of the car's, creeping at 0.1 m/s: the gap
/// from the car's front to its rear is 20 - 4.5 = 15.5 m at first and closes at 3 - 0.1
/// = 2.9 m/s, so after two ticks (2 s) it is 9.7 m and the time-to-collision
/// 9.7 / 2.9 = 3.345 s; no pedestrian, so no pedestrian clearance and no PET.
#[test]
fn a_slow_lead_car_ahead_has_the_clearance_and_time_to_collision_worked_by_hand() {
    let m = map(
        "Map(junction: (), traffic: [(route: Lead, trigger: AtTime(0.0), start: 20.0, speed: (0.1, 0.1))], episode: (max_steps: 60))",
    );
    let mut w = World::from_map(&m, 0);
    w.measure_margins();
    for _ in 0..2 {
        w.step(Action::Maintain);
    }
    let margins = w.margins().expect("measured");
    let gap = margins.vehicle_clearance.expect("a vehicle was there");
    assert!((gap - 9.7).abs() < 1e-3, "clearance {gap}");
    let ttc = margins.ttc.expect("on a collision course");
    assert!((ttc - 9.7 / 2.9).abs() < 1e-3, "TTC {ttc}");
    assert_eq!((margins.clearance, margins.pet), (None, None));
}

/// A pedestrian who stops in the car's lane at t = 2.25 s: from then the car (3 m/s)
/// is on a collision course, its front meeting the disc at x = 66 - 0.3 = 65.7 m. At
/// t = 3 s the front is at 9 m: TTC = (65.7 - 9) / 3 = 18.9 s, and the stopping margin
/// 3 × 18.9 - 3² / (2 × 3) = 55.2 m. Driven on, the car hits: clearance and TTC 0, and
/// it could no longer stop.
#[test]
fn a_standing_pedestrian_ahead_has_the_time_to_collision_worked_by_hand() {
    let m = map(
        "Map(pedestrians: [(trigger: AtTime(0.0), side: Near, speed: (1.0, 1.0), pause: (after: 2.25, duration: 1000.0))], episode: (max_steps: 60))",
    );
    let mut w = World::from_map(&m, 0);
    w.measure_margins();
    for _ in 0..3 {
        w.step(Action::Maintain);
    }
    let margins = w.margins().expect("measured");
    let ttc = margins.ttc.expect("on a collision course");
    assert!((ttc - 18.9).abs() < 1e-3, "TTC {ttc}");
    let stop = margins.stop_margin.expect("on a collision course");
    assert!((stop - 55.2).abs() < 1e-2, "stopping margin {stop}");
    assert!(margins.could_stop());
    let clearance = margins.clearance.expect("a pedestrian was there");
    assert!(clearance > 50.0, "clearance {clearance}");
    let (_, out) = common::run(&mut w, |_| Action::Maintain);
    assert!(out.collision);
    let hit = w.margins().expect("measured");
    assert_eq!((hit.clearance, hit.ttc, hit.pet), (Some(0.0), Some(0.0), Some(0.0)));
    assert!(!hit.could_stop(), "{hit:?}");
}

/// Measuring changes nothing in the episode.
#[test]
fn measuring_margins_leaves_the_episode_as_it_was() {
    let m = unforeseen_sim::embedded::load("intersection").unwrap();
    let drive = |measure: bool| {
        let mut w = World::from_map(&m, 11);
        if measure {
            w.measure_margins();
        }
        common::run(&mut w, common::brake_for_pedestrians)
    };
    assert_eq!(drive(true), drive(false));
}
