//! Semantic checks of the junction (geometry, signal phases, outages) and of the
//! traffic rules.

use super::{Check, MAX_LIST, MAX_SPAWN_RULES, PHYSICS_HZ};
use crate::light::{LightPhase, light_at};
use crate::map::{Arm, Behaviour, CrossCycle, Junction, Light, Map, Offset, Route, Trigger};
use crate::signals::derived_cross;
use crate::traffic::MAX_DECEL;

/// Most vehicles one episode can spawn (every rule firing every time it can).
pub const MAX_VEHICLES: f64 = 100.0;

pub(super) fn check(c: &mut Check, map: &Map) {
    if let Some(j) = &map.junction {
        junction(c, map, j);
    }
    traffic(c, map);
}

fn trigger(c: &mut Check, path: &str, t: Trigger) {
    match t {
        Trigger::RedStarts | Trigger::GreenStarts => {}
        Trigger::AtTime(t) => c.non_negative(path, t),
        Trigger::CarWithin { min, max } => c.range(path, (min, max), false),
        Trigger::CarArrivesWithin(t) => c.within(path, t, (0.0, 3600.0), "s", "use real units: seconds"),
    }
}

/// Whether the light's cycle is valid (checked elsewhere): the cross checks need it.
fn cycle_ok(light: &Light, hz: f64) -> bool {
    let shortest = 1.0 / hz.clamp(PHYSICS_HZ.0, PHYSICS_HZ.1);
    !light.cycle.is_empty()
        && light.cycle.len() <= MAX_LIST
        && light
            .cycle
            .iter()
            .all(|p| p.duration.is_finite() && p.duration >= shortest && p.duration <= 1e6)
}

fn junction(c: &mut Check, map: &Map, j: &Junction) {
    let road = &map.road;
    c.finite("junction.x", j.x);
    if !(2..=16).contains(&j.lanes) {
        c.fail(
            "junction.lanes",
            format!("must be 2..=16, got {}", j.lanes),
            "the cross street has at least one lane each way",
        );
    }
    c.within(
        "junction.lane_width",
        j.lane_width,
        (1.0, 10.0),
        "m",
        "a lane is 2.5 to 4 m wide",
    );
    c.within(
        "junction.sidewalk_width",
        j.sidewalk_width,
        (0.1, 20.0),
        "m",
        "pedestrians wait on the sidewalk",
    );
    let cw = &map.crosswalk;
    let near_x = cw.x - cw.width / 2.0;
    if j.stop_gap.is_finite() && j.stop_gap < 0.0 {
        c.fail(
            "junction.stop_gap",
            format!(
                "{} m puts the car's stop line at x = {} m, past the crosswalk's near edge (x = {near_x} m) and so past where the junction begins",
                j.stop_gap,
                near_x - j.stop_gap
            ),
            "a stop line lies before its crosswalk: give stop_gap >= 0",
        );
    } else {
        c.within(
            "junction.stop_gap",
            j.stop_gap,
            (0.0, 20.0),
            "m",
            "stop lines lie 1 to 3 m before the crosswalk",
        );
    }
    let half = f64::from(j.lanes) * j.lane_width / 2.0;
    let (x0, x1) = (j.x - half, j.x + half);
    let far_x = cw.x + cw.width / 2.0;
    if [x0, x1, far_x, road.goal_x].iter().all(|v| v.is_finite()) {
        if x0 <= far_x {
            c.fail(
                "junction.x",
                format!(
                    "the junction box (x {x0}..{x1} m) does not lie past the map's crosswalk (x {near_x}..{far_x} m), which is on the car's approach"
                ),
                &format!("put junction.x at {} m or more (or move the crosswalk)", far_x + half + 1.0),
            );
        } else if x1 >= road.goal_x {
            c.fail(
                "junction.x",
                format!(
                    "the junction box (x {x0}..{x1} m) lies outside the road the car drives (it ends at road.goal_x = {} m)",
                    road.goal_x
                ),
                "the car must cross the junction before its destination",
            );
        }
    }
    // Named by the list (its items are bare names, which have no place of their own).
    for (i, arm) in j.crosswalks.iter().enumerate() {
        let path = "junction.crosswalks";
        if *arm == Arm::West {
            c.fail(
                path,
                format!("item {i}: the near approach's crosswalk is the map's `crosswalk`"),
                "list East, South or North",
            );
        } else if j.crosswalks[..i].contains(arm) {
            c.fail(
                path,
                format!("item {i}: {arm:?} is listed twice"),
                "one crosswalk per arm at most",
            );
        }
    }
    let hz = map.episode.physics_hz;
    match &j.cross {
        CrossCycle::Derived { amber, all_red } => {
            c.within("junction.cross.amber", *amber, (0.0, 60.0), "s", "amber lasts 3 to 5 s");
            c.within(
                "junction.cross.all_red",
                *all_red,
                (0.0, 60.0),
                "s",
                "an all-red clearance lasts 1 to 3 s",
            );
            if c.out.iter().any(|p| p.path.starts_with("junction.cross")) || !cycle_ok(&map.light, hz) {
                return;
            }
            let cycle = &map.light.cycle;
            let red = |i: usize| cycle[i].phase == LightPhase::Red;
            let n = cycle.len();
            let runs = (0..n)
                .filter(|&i| red(i) && !red((i + n - 1) % n))
                .count()
                .max(usize::from(red(0)));
            let (cross, _) = derived_cross(cycle, *amber, *all_red);
            let greens = cross.cycle.iter().filter(|p| p.phase == LightPhase::Green).count();
            if greens < runs {
                // Blamed on the car's cycle: a derived cross cycle is often not written.
                c.fail(
                    "light.cycle",
                    format!(
                        "a red phase of the car's signal is too short to give the cross street (junction.cross: Derived) green after {all_red} s of all-red at each end and {amber} s of amber"
                    ),
                    "lengthen the red in light.cycle or shorten the clearance and amber",
                );
            }
        }
        CrossCycle::Cycle(phases) => {
            if phases.is_empty() || phases.len() > MAX_LIST {
                c.fail(
                    "junction.cross",
                    format!("needs 1 to {MAX_LIST} phases, got {}", phases.len()),
                    "",
                );
                return;
            }
            for (i, p) in phases.iter().enumerate() {
                c.within(
                    &format!("junction.cross[{i}].duration"),
                    p.duration,
                    (1.0 / hz.clamp(PHYSICS_HZ.0, PHYSICS_HZ.1), 1e6),
                    "s",
                    "a phase lasts at least one physics sub-step",
                );
            }
            if c.out.iter().any(|p| p.path.starts_with("junction.cross")) || !cycle_ok(&map.light, hz) {
                return;
            }
            let (ego_len, cross_len): (f64, f64) = (map.light.cycle_length(), phases.iter().map(|p| p.duration).sum());
            if (ego_len - cross_len).abs() > 1e-9 * ego_len {
                c.fail(
                    "junction.cross",
                    format!("the cross cycle lasts {cross_len} s, the car's (light.cycle) {ego_len} s"),
                    "one controller runs both: give the cycles the same length",
                );
                return;
            }
            conflicts(c, &map.light, phases);
        }
    }
    for (field, limit) in [
        ("road_speed_limit", j.road_speed_limit),
        ("cross_speed_limit", j.cross_speed_limit),
    ] {
        c.within(
            &format!("junction.{field}"),
            limit,
            (0.1, 70.0),
            "m/s",
            "50 km/h is 13.9 m/s",
        );
    }
    if j.outages.len() > MAX_LIST {
        c.fail("junction.outages", format!("more than {MAX_LIST} outages"), "");
    }
    for (i, o) in j.outages.iter().enumerate().take(MAX_LIST) {
        let path = format!("junction.outages[{i}]");
        trigger(c, &format!("{path}.start"), o.start);
        c.within(
            &format!("{path}.duration"),
            o.duration,
            (1e-9, 1e6),
            "s",
            "an outage lasts seconds to hours",
        );
    }
}

/// Refuse cross phases that give the cross street right of way (green or amber) while
/// the car's signal gives it too.
fn conflicts(c: &mut Check, light: &Light, phases: &[crate::map::Phase]) {
    let ego = Light {
        offset: Offset::Fixed(0.0),
        ..light.clone()
    };
    let cross = Light {
        cycle: phases.to_vec(),
        offset: Offset::Fixed(0.0),
    };
    let mut cuts: Vec<f64> = [&ego.cycle, &cross.cycle]
        .iter()
        .flat_map(|cy| {
            cy.iter().scan(0.0, |t, p| {
                *t += p.duration;
                Some(*t)
            })
        })
        .chain([0.0])
        .collect();
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    for w in cuts.windows(2) {
        let mid = (w[0] + w[1]) / 2.0;
        let (a, b) = (light_at(&ego, 0.0, mid).0, light_at(&cross, 0.0, mid).0);
        if a != LightPhase::Red && b != LightPhase::Red {
            c.fail(
                "junction.cross",
                format!(
                    "from {} s to {} s into the cycle the car's signal shows {a} and the cross street {b}: two crossing directions would have right of way at once",
                    w[0], w[1]
                ),
                "give the cross street red while the car's signal is green or amber (or use Derived)",
            );
            return;
        }
    }
}

fn traffic(c: &mut Check, map: &Map) {
    if map.traffic.len() > MAX_SPAWN_RULES {
        c.fail(
            "traffic",
            format!(
                "{} traffic rules is too many (at most {MAX_SPAWN_RULES})",
                map.traffic.len()
            ),
            "every rule is checked every physics sub-step; merge rules or split the scenario",
        );
        return;
    }
    for (i, r) in map.traffic.iter().enumerate() {
        let path = format!("traffic[{i}]");
        let cross = matches!(r.route, Route::FromSouth | Route::FromNorth);
        if (cross || r.route == Route::OncomingLeft) && map.junction.is_none() {
            c.fail(
                &format!("{path}.route"),
                format!(
                    "the route {:?} crosses the junction's box, but the map has no junction",
                    r.route
                ),
                "add a `junction` section or use Lead or Oncoming",
            );
        }
        trigger(c, &format!("{path}.trigger"), r.trigger);
        c.probability(&format!("{path}.probability"), r.probability, false);
        c.range_within(
            &format!("{path}.delay"),
            r.delay,
            false,
            Some(((0.0, 3600.0), "s", "a delay of seconds to an hour")),
        );
        c.range_within(
            &format!("{path}.speed"),
            r.speed,
            true,
            Some(((0.1, 70.0), "m/s", "70 m/s is 252 km/h")),
        );
        c.within(&format!("{path}.start"), r.start, (0.0, 1000.0), "m", "");
        if let Some(j) = &map.junction
            && r.speed.1.is_finite()
        {
            let (street, field, limit) = if cross {
                ("cross street", "cross_speed_limit", j.cross_speed_limit)
            } else {
                ("road", "road_speed_limit", j.road_speed_limit)
            };
            if r.speed.1 > limit {
                c.fail(
                    &format!("{path}.speed"),
                    format!(
                        "up to {} m/s is above the {street}'s limit of {limit} m/s (junction.{field})",
                        r.speed.1
                    ),
                    &format!("keep the speed at or below {limit} m/s, or raise junction.{field}"),
                );
            }
        }
        let road_left = map.road.goal_x - map.vehicle.start_x;
        if r.route == Route::Lead && r.start.is_finite() && road_left.is_finite() && r.start >= road_left {
            c.fail(
                &format!("{path}.start"),
                format!(
                    "a lead vehicle {} m ahead of the car's front would appear outside the road, which ends {road_left} m ahead of the car's start (road.goal_x)",
                    r.start
                ),
                &format!("give start below {road_left} m"),
            );
        }
        if r.route == Route::Lead && r.start.is_finite() && r.length.is_finite() && r.start < r.length {
            c.fail(
                &format!("{path}.start"),
                format!(
                    "a lead vehicle {} m long appearing {} m ahead of the car's front would overlap the car",
                    r.length, r.start
                ),
                "give start at least the vehicle's length",
            );
        }
        c.within(
            &format!("{path}.length"),
            r.length,
            (1.0, 20.0),
            "m",
            "a car is about 4.5 m long",
        );
        let lane = match (cross, &map.junction) {
            (true, Some(j)) => j.lane_width,
            _ => map.road.lane_width,
        };
        c.within(
            &format!("{path}.width"),
            r.width,
            (0.5, 4.0),
            "m",
            "a car is about 1.8 m wide",
        );
        if r.width.is_finite() && lane.is_finite() && r.width > lane {
            c.fail(
                &format!("{path}.width"),
                format!("the vehicle ({} m) is wider than its lane ({lane} m)", r.width),
                "narrow the vehicle or widen the lane",
            );
        }
        c.within(
            &format!("{path}.accel"),
            r.accel,
            (0.1, 10.0),
            "m/s²",
            "IDM's A is about 1 to 2 m/s²",
        );
        c.within(
            &format!("{path}.brake"),
            r.brake,
            (0.1, MAX_DECEL),
            "m/s²",
            "IDM's b is about 1.5 to 3 m/s²",
        );
        c.within(
            &format!("{path}.headway"),
            r.headway,
            (0.1, 10.0),
            "s",
            "IDM's T is about 1 to 2 s",
        );
        c.within(
            &format!("{path}.min_gap"),
            r.min_gap,
            (0.1, 20.0),
            "m",
            "IDM's s0 is about 2 m",
        );
        match r.behaviour {
            Behaviour::Careful | Behaviour::RunsRed | Behaviour::DoesNotYield => {}
            Behaviour::Stalls { at, hold } => {
                c.within(
                    &format!("{path}.behaviour.at"),
                    at,
                    (0.0, 1000.0),
                    "m",
                    "metres past the stop line",
                );
                if hold.is_nan() || hold < 0.0 {
                    c.fail(
                        &format!("{path}.behaviour.hold"),
                        format!("must be >= 0 s, got {hold}"),
                        "leave it out to stall for ever",
                    );
                }
            }
            Behaviour::BrakesHard { after, decel, hold } => {
                c.within(&format!("{path}.behaviour.after"), after, (0.0, 3600.0), "s", "");
                c.within(
                    &format!("{path}.behaviour.decel"),
                    decel,
                    (0.1, MAX_DECEL),
                    "m/s²",
                    "a dry road allows about 9 m/s²",
                );
                c.within(&format!("{path}.behaviour.hold"), hold, (0.0, 3600.0), "s", "");
            }
        }
    }
    let episode = f64::from(map.episode.max_steps) * map.episode.decision_dt;
    let cycle = map.light.cycle_length();
    let most: f64 = (map.traffic.iter())
        .map(|r| match r.trigger {
            Trigger::RedStarts | Trigger::GreenStarts if cycle > 0.0 && episode.is_finite() => {
                map.light.cycle.len() as f64 * ((episode / cycle).floor() + 2.0)
            }
            Trigger::RedStarts | Trigger::GreenStarts => f64::INFINITY,
            _ => 1.0,
        })
        .sum();
    if most > MAX_VEHICLES {
        c.fail(
            "traffic",
            format!("the rules can spawn up to {most:.0} vehicles in one episode (at most {MAX_VEHICLES})"),
            "lengthen the light cycle, shorten the episode or use fewer RedStarts/GreenStarts rules",
        );
    }
}
