//! How close an episode came to a collision (docs/ARCHITECTURE.md §2, "Margins"),
//! measured by the world after every physics sub-step when asked
//! ([`World::measure_margins`](crate::World::measure_margins)). Measuring reads the
//! poses and changes nothing in the episode.
//!
//! * **clearance**: the distance between the car's collider (its box) and a
//!   pedestrian's (its disc), parry's `distance`; 0 once they touch;
//! * **vehicle clearance**: the same between the car's box and another vehicle's;
//! * **time-to-collision**: the time until the car's collider would touch a pedestrian's
//!   or a vehicle's if the car kept its speed along its lane and the other its velocity
//!   (parry's `cast_shapes`), looked for within the episode's remaining time; none while
//!   they would not meet;
//! * **stopping margin**: on a collision course, the distance the car's front would
//!   cover until they touch (`speed × TTC`) less the car's stopping distance from its
//!   speed with braking begun now on the friction under its tyres
//!   ([`stopping_distance`](crate::dynamics::stopping_distance)): negative while the car
//!   could no longer have stopped short of the other's path;
//! * **post-encroachment time** (PET, Allen et al. 1978): the shortest time between a
//!   pedestrian's disc covering a point and the car's box covering it, over every point
//!   and sub-step the two occupied, the one before the other: 0 when they touch, the
//!   seconds by which the car missed her when she crossed its path before or after it.
//!   Measured where her disc reaches into the car's lane (the band its box sweeps); the
//!   car's reach along the road is the furthest its front has come, so the car occupies
//!   a disc's point over one interval of time, from its front reaching the disc to its
//!   rear leaving it. None while no pedestrian's path met the car's.
//!
//! An episode's margins are the smallest of each over its sub-steps, pedestrians and
//! vehicles. The clearances and the time-to-collision fall as the car comes near a
//! crash; the post-encroachment time also falls as the crossings come closer in time
//! when neither ever comes near the other (a pedestrian who crossed a minute before the
//! car arrives has a PET of a minute and a clearance of the road's length).

/// The smallest margins of an episode so far.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Margins {
    /// Smallest clearance between the car and a pedestrian, m (none while no pedestrian
    /// was in the world).
    pub clearance: Option<f64>,
    /// Smallest clearance between the car and another vehicle, m (none while no vehicle
    /// was in the world).
    pub vehicle_clearance: Option<f64>,
    /// Smallest time-to-collision with a pedestrian or a vehicle, s (none while the car
    /// was never on a collision course).
    pub ttc: Option<f64>,
    /// Smallest stopping margin, m (none while the car was never on a collision course).
    pub stop_margin: Option<f64>,
    /// Smallest post-encroachment time car–pedestrian, s (none while no pedestrian's
    /// path met the car's).
    pub pet: Option<f64>,
}

impl Margins {
    /// Whether braking could have stopped the car short of every collision course it was
    /// on (the stopping margin never negative).
    pub fn could_stop(&self) -> bool {
        self.stop_margin.is_none_or(|m| m >= 0.0)
    }
}

fn least(old: Option<f64>, new: f64) -> Option<f64> {
    Some(old.map_or(new, |o| o.min(new)))
}

/// What the world keeps while it measures an episode's margins: the smallest so far, and
/// the tracks the post-encroachment time is computed from when asked.
#[derive(Debug, Clone, Default)]
pub(crate) struct Measure {
    least: Margins,
    /// The car's reach: (time, the furthest x its front has come), one per sub-step.
    reach: Vec<(f64, f64)>,
    /// Each sub-step's pedestrian discs reaching into the car's lane: (time, the
    /// interval of the car's front over which its box overlaps the disc).
    covered: Vec<(f64, f64, f64)>,
}

impl Measure {
    /// Takes in one sub-step's clearance to a pedestrian (`vehicle` false) or a vehicle,
    /// and its time-to-collision and stopping margin when on a collision course.
    pub(crate) fn record(&mut self, vehicle: bool, clearance: f64, collision_course: Option<(f64, f64)>) {
        let m = &mut self.least;
        if vehicle {
            m.vehicle_clearance = least(m.vehicle_clearance, clearance);
        } else {
            m.clearance = least(m.clearance, clearance);
        }
        if let Some((ttc, stop_margin)) = collision_course {
            m.ttc = least(m.ttc, ttc);
            m.stop_margin = least(m.stop_margin, stop_margin);
        }
    }

    /// Takes in the car's front at time `t`.
    pub(crate) fn car_at(&mut self, t: f64, front: f64) {
        let reach = self.reach.last().map_or(front, |&(_, r)| r.max(front));
        self.reach.push((t, reach));
    }

    /// Takes in a pedestrian's disc (centre `x`, lateral gap `gap` from the car's lane
    /// band, `radius`) at time `t`, for a car of `length`: the car's box overlaps the
    /// disc while its front is within `(x − e, x + length + e)`, `e = √(radius² − gap²)`.
    pub(crate) fn pedestrian_at(&mut self, t: f64, x: f64, gap: f64, radius: f64, length: f64) {
        if gap < radius {
            let e = (radius * radius - gap * gap).sqrt();
            self.covered.push((t, x - e, x + length + e));
        }
    }

    /// The smallest margins so far, the post-encroachment time computed from the tracks.
    pub(crate) fn margins(&self) -> Margins {
        let mut m = self.least;
        m.pet = pet(&self.reach, &self.covered);
        m
    }
}

/// The post-encroachment time of the car's `reach` (times, non-decreasing fronts) and the
/// pedestrians' `covered` samples: for each, the car occupies the disc from the first
/// time its front passes the interval's start until the first time it reaches its end;
/// a sample before that interval counts the time to its start, one after it the time
/// since its end, one within it 0. None when the car never reached a sample's disc.
pub(crate) fn pet(reach: &[(f64, f64)], covered: &[(f64, f64, f64)]) -> Option<f64> {
    let first_past = |x: f64| reach.get(reach.partition_point(|&(_, r)| r <= x)).map(|&(t, _)| t);
    let first_at = |x: f64| reach.get(reach.partition_point(|&(_, r)| r < x)).map(|&(t, _)| t);
    covered
        .iter()
        .filter_map(|&(t, from, to)| {
            let enters = first_past(from)?;
            match first_at(to) {
                _ if t < enters => Some(enters - t),
                Some(leaves) if t >= leaves => Some(t - leaves),
                _ => Some(0.0),
            }
        })
        .reduce(f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A car at 10 m/s from x = 0 (its front), sampled every 0.1 s for 10 s.
    fn reach() -> Vec<(f64, f64)> {
        (0..=100).map(|k| (k as f64 / 10.0, k as f64)).collect()
    }

    /// A disc whose front interval is (50, 55): the car's front passes 50 at t = 5.1 s
    /// (the first sample beyond it) and reaches 55 at t = 5.5 s.
    #[test]
    fn the_post_encroachment_time_is_the_gap_to_the_cars_interval() {
        let r = reach();
        assert_eq!(pet(&r, &[(2.0, 50.0, 55.0)]), Some(5.1 - 2.0));
        assert_eq!(pet(&r, &[(5.3, 50.0, 55.0)]), Some(0.0));
        assert!((pet(&r, &[(7.5, 50.0, 55.0)]).unwrap() - 2.0).abs() < 1e-12);
        // The smallest over samples; a disc the car never reaches counts nothing.
        assert_eq!(
            pet(&r, &[(2.0, 50.0, 55.0), (4.0, 50.0, 55.0), (1.0, 200.0, 205.0)]),
            Some(5.1 - 4.0)
        );
        assert_eq!(pet(&r, &[(1.0, 200.0, 205.0)]), None);
        // A car that stopped inside the disc's interval never leaves it.
        let stopped: Vec<(f64, f64)> = (0..=100).map(|k| (k as f64 / 10.0, (k as f64).min(52.0))).collect();
        assert_eq!(pet(&stopped, &[(9.0, 50.0, 55.0)]), Some(0.0));
    }

    /// The interval a disc blocks: a disc of 0.5 m whose centre is 0.3 m outside the lane
    /// band reaches 0.4 m into the car's path along the road on either side.
    #[test]
    fn a_disc_at_the_lane_edge_covers_its_chord() {
        let mut m = Measure::default();
        m.pedestrian_at(1.0, 10.0, 0.3, 0.5, 4.5);
        m.pedestrian_at(1.0, 10.0, 0.6, 0.5, 4.5);
        assert_eq!(m.covered.len(), 1);
        let (_, from, to) = m.covered[0];
        assert!((from - 9.6).abs() < 1e-12 && (to - 14.9).abs() < 1e-12, "{from} {to}");
    }

    /// The reach is the furthest front so far.
    #[test]
    fn the_reach_never_falls_back() {
        let mut m = Measure::default();
        for (t, x) in [(0.0, 1.0), (0.1, 2.0), (0.2, 1.9), (0.3, 2.5)] {
            m.car_at(t, x);
        }
        assert_eq!(m.reach, vec![(0.0, 1.0), (0.1, 2.0), (0.2, 2.0), (0.3, 2.5)]);
    }
}
