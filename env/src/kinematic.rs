//! The kinematic observation: a fixed-length vector of the car's motion, the light, a
//! fixed number of pedestrian slots and a fixed number of vehicle slots, in SI units and
//! the map's coordinates (x along the road towards the destination, y across it, the
//! car's lane at negative y).
//!
//! With `P` pedestrian slots and `V` vehicle slots ([`Slots`]):
//!
//! | index | value | unit |
//! |---|---|---|
//! | 0 | x of the car's front bumper | m |
//! | 1 | the car's speed along +x | m/s |
//! | 2 | distance from the car's front to the destination line (`road.goal_x - x`; <= 0 once arrived) | m |
//! | 3, 4, 5 | the light is green, amber, red (one-hot) | 0/1 |
//! | 6 | time until the light changes | s |
//! | 7 + 5k .. 7 + 5k + 5 | pedestrian slot `k`: present (0/1), x (m), y (m), vx (m/s), vy (m/s) | |
//! | 7 + 5P + 6j .. 7 + 5P + 6j + 6 | vehicle slot `j`: present (0/1), x (m), y (m), vx (m/s), vy (m/s), heading (rad) | |
//!
//! Slot `k` holds the `k`-th pedestrian in the world in order of appearance (pedestrians
//! leave the world when they reach the far sidewalk). Vehicle slot `j` holds the `j`-th
//! nearest other vehicle whose centre is within [`VEHICLE_RANGE`] of the car: nearest
//! by the Euclidean distance from the centre of the car's front bumper (x, the car's
//! lane centre y) to the vehicle's centre, equal distances in the world's order of
//! appearance; its x, y are its centre, vx, vy its velocity and heading its direction
//! of travel (0 along +x, counter-clockwise, in [-π, π]). An empty slot is all zeros.
//! Without vehicle slots (`V = 0`, the default on a map without traffic rules:
//! [`default_vehicle_slots`]) the vector is the pedestrian layout alone.
//! [`bounds`] gives each value's range on a map (what a Gymnasium `Box` declares).

use unforeseen_sim::{LightPhase, Map, Snapshot};

/// Values before the pedestrian slots.
pub const HEAD: usize = 7;
/// Values per pedestrian slot.
pub const PER_SLOT: usize = 5;
/// Values per vehicle slot.
pub const PER_VEHICLE: usize = 6;
/// Most pedestrian slots, and most vehicle slots, an env may have.
pub const MAX_SLOTS: usize = 100;
/// Vehicle slots on a map with traffic rules unless configured.
pub const DEFAULT_VEHICLE_SLOTS: usize = 4;
/// Vehicles whose centre is farther than this from the car's front are not observed, m.
pub const VEHICLE_RANGE: f64 = 100.0;

/// How many slots of each kind the vector has.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Slots {
    /// Pedestrian slots.
    pub pedestrians: usize,
    /// Vehicle slots.
    pub vehicles: usize,
}

impl Slots {
    /// `pedestrians` pedestrian slots and no vehicle slots.
    pub const fn pedestrians(pedestrians: usize) -> Slots {
        Slots {
            pedestrians,
            vehicles: 0,
        }
    }
}

/// Vehicle slots unless configured: [`DEFAULT_VEHICLE_SLOTS`] on a map with traffic
/// rules, none on one without (whose vector is then the pedestrian layout alone).
pub fn default_vehicle_slots(map: &Map) -> usize {
    if map.traffic.is_empty() {
        0
    } else {
        DEFAULT_VEHICLE_SLOTS
    }
}

/// Length of the vector with `slots`.
pub const fn len(slots: Slots) -> usize {
    HEAD + PER_SLOT * slots.pedestrians + PER_VEHICLE * slots.vehicles
}

/// Writes the vector of `snap` into `out` (length [`len`]`(slots)`).
///
/// # Panics
/// If `out.len() != len(slots)`.
pub fn write(map: &Map, snap: &Snapshot, slots: Slots, out: &mut [f32]) {
    assert_eq!(out.len(), len(slots), "kinematic vector of {slots:?}");
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
    let (peds, vehicles) = out[HEAD..].split_at_mut(PER_SLOT * slots.pedestrians);
    for (k, slot) in peds.chunks_exact_mut(PER_SLOT).enumerate() {
        match snap.pedestrians.get(k) {
            Some(p) => slot.copy_from_slice(&[1.0, p.x as f32, p.y as f32, p.vx as f32, p.vy as f32]),
            None => slot.fill(0.0),
        }
    }
    if slots.vehicles == 0 {
        return;
    }
    let (cx, cy) = (snap.car_x, map.road.car_lane_y());
    let mut near: Vec<(f64, usize)> = (snap.vehicles.iter().enumerate())
        .map(|(i, o)| ((o.x - cx).hypot(o.y - cy), i))
        .filter(|(d, _)| *d <= VEHICLE_RANGE)
        .collect();
    near.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    for (j, slot) in vehicles.chunks_exact_mut(PER_VEHICLE).enumerate() {
        match near.get(j).map(|&(_, i)| &snap.vehicles[i]) {
            Some(o) => slot.copy_from_slice(&[
                1.0,
                o.x as f32,
                o.y as f32,
                (o.speed * o.heading.cos()) as f32,
                (o.speed * o.heading.sin()) as f32,
                o.heading as f32,
            ]),
            None => slot.fill(0.0),
        }
    }
}

/// The range `(low, high)` of every value of the vector on `map`, with a margin of 1 (m,
/// m/s or s) on the physical values so that f32 rounding never leaves it.
pub fn bounds(map: &Map, slots: Slots) -> (Vec<f32>, Vec<f32>) {
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
    for _ in 0..slots.pedestrians {
        // vx is 0 on every shipped map (pedestrians walk straight across); its range is
        // the walking speed's, like vy's, so the space stays valid for any direction.
        low.extend([0.0, ped_x_lo - m, -reach - m, -ped_speed - m, -ped_speed - m]);
        high.extend([1.0, ped_x_hi + m, reach + m, ped_speed + m, ped_speed + m]);
    }
    // A vehicle is observed within VEHICLE_RANGE of the car's front, and drives no
    // faster than the fastest desired speed of its rules (IDM approaches it from below).
    let car_y = map.road.car_lane_y();
    let r = VEHICLE_RANGE;
    let vehicle_speed = map.traffic.iter().map(|t| t.speed.0.max(t.speed.1)).fold(0.0, f64::max);
    let heading = std::f64::consts::PI;
    for _ in 0..slots.vehicles {
        low.extend([
            0.0,
            x_lo - r - m,
            car_y - r - m,
            -vehicle_speed - m,
            -vehicle_speed - m,
            -heading - m,
        ]);
        high.extend([
            1.0,
            x_hi + r + m,
            car_y + r + m,
            vehicle_speed + m,
            vehicle_speed + m,
            heading + m,
        ]);
    }
    let f32s = |v: Vec<f64>| v.into_iter().map(|x| x as f32).collect();
    (f32s(low), f32s(high))
}
