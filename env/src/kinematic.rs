//! The kinematic observation: a fixed-length vector of the car's motion, the light and
//! a fixed number of pedestrian slots, in SI units and the map's coordinates (x along
//! the road towards the destination, y across it, the car's lane at negative y).
//!
//! | index | value | unit |
//! |---|---|---|
//! | 0 | x of the car's front bumper | m |
//! | 1 | the car's speed along +x | m/s |
//! | 2 | distance from the car's front to the destination line (`road.goal_x - x`; <= 0 once arrived) | m |
//! | 3, 4, 5 | the light is green, amber, red (one-hot) | 0/1 |
//! | 6 | time until the light changes | s |
//! | 7 + 5k .. 7 + 5k + 5 | pedestrian slot `k`: present (0/1), x (m), y (m), vx (m/s), vy (m/s) | |
//!
//! Slot `k` holds the `k`-th pedestrian in the world in order of appearance (pedestrians
//! leave the world when they reach the far sidewalk); an empty slot is all zeros.
//! [`bounds`] gives each value's range on a map (what a Gymnasium `Box` declares).

use unforeseen_sim::{LightPhase, Map, Snapshot};

/// Values before the pedestrian slots.
pub const HEAD: usize = 7;
/// Values per pedestrian slot.
pub const PER_SLOT: usize = 5;
/// Most pedestrian slots an env may have.
pub const MAX_SLOTS: usize = 100;

/// Length of the vector with `slots` pedestrian slots.
pub const fn len(slots: usize) -> usize {
    HEAD + PER_SLOT * slots
}

/// Writes the vector of `snap` into `out` (length [`len`]`(slots)`).
///
/// # Panics
/// If `out.len() != len(slots)`.
pub fn write(map: &Map, snap: &Snapshot, slots: usize, out: &mut [f32]) {
    assert_eq!(out.len(), len(slots), "kinematic vector of {slots} slots");
    let light = |p| if snap.light == p { 1.0 } else { 0.0 };
    out[..HEAD].copy_from_slice(&[
        snap.car_x as f32,
        snap.car_speed as f32,
        (map.road.goal_x - snap.car_x) as f32,
        light(LightPhase::Green),
        light(LightPhase::Amber),
        light(LightPhase::Red),
        snap.light_time_left as f32,
    ]);
    for (k, slot) in out[HEAD..].chunks_exact_mut(PER_SLOT).enumerate() {
        match snap.pedestrians.get(k) {
            Some(p) => slot.copy_from_slice(&[1.0, p.x as f32, p.y as f32, p.vx as f32, p.vy as f32]),
            None => slot.fill(0.0),
        }
    }
}

/// The range `(low, high)` of every value of the vector on `map`, with a margin of 1 (m,
/// m/s or s) on the physical values so that f32 rounding never leaves it.
pub fn bounds(map: &Map, slots: usize) -> (Vec<f32>, Vec<f32>) {
    let v = &map.vehicle;
    let overshoot = v.max_speed * map.episode.decision_dt;
    let (x_lo, x_hi) = (v.start_x.min(map.road.goal_x), map.road.goal_x + overshoot);
    let longest_phase = map.light.cycle.iter().map(|p| p.duration).fold(0.0, f64::max);
    let half = map.road.half_width();
    let rules = &map.pedestrians;
    let max_of = |f: &dyn Fn(&unforeseen_sim::SpawnRule) -> f64| rules.iter().map(f).fold(0.0, f64::max);
    let reach = half + max_of(&|r| r.start_back);
    let ped_speed = max_of(&|r| r.speed.0.max(r.speed.1));
    let ped_x_lo = rules
        .iter()
        .map(|r| map.crosswalk.x + r.x_offset.0.min(r.x_offset.1))
        .fold(0.0, f64::min);
    let ped_x_hi = rules
        .iter()
        .map(|r| map.crosswalk.x + r.x_offset.0.max(r.x_offset.1))
        .fold(0.0, f64::max);
    let m = 1.0;
    let mut low = vec![x_lo - m, 0.0, map.road.goal_x - x_hi - m, 0.0, 0.0, 0.0, 0.0];
    let mut high = vec![
        x_hi + m,
        v.max_speed + m,
        map.road.goal_x - x_lo + m,
        1.0,
        1.0,
        1.0,
        longest_phase + m,
    ];
    for _ in 0..slots {
        // vx is 0 on every shipped map (pedestrians walk straight across); its range is
        // the walking speed's, like vy's, so the space stays valid for any direction.
        low.extend([0.0, ped_x_lo - m, -reach - m, -ped_speed - m, -ped_speed - m]);
        high.extend([1.0, ped_x_hi + m, reach + m, ped_speed + m, ped_speed + m]);
    }
    let f32s = |v: Vec<f64>| v.into_iter().map(|x| x as f32).collect();
    (f32s(low), f32s(high))
}
