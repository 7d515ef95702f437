//! How close an episode came to a collision (docs/ARCHITECTURE.md §2, "Margins"),
//! measured by the world after every physics sub-step when asked
//! ([`World::measure_margins`](crate::World::measure_margins)). Measuring reads the
//! poses and changes nothing in the episode.
//!
//! * **clearance**: the distance between the car's collider (its box) and a
//!   pedestrian's (its disc), parry's `distance`; 0 once they touch;
//! * **time-to-collision**: the time until the two colliders would touch if the car kept
//!   its speed along its lane and the pedestrian its velocity (parry's `cast_shapes`),
//!   looked for within the episode's remaining time; none while they would not meet;
//! * **stopping margin**: on a collision course, the distance the car's front would
//!   cover until they touch (`speed × TTC`) less the car's stopping distance from its
//!   speed with braking begun now on the friction under its tyres
//!   ([`stopping_distance`](crate::dynamics::stopping_distance)): negative while the car
//!   could no longer have stopped short of the pedestrian's path.
//!
//! An episode's margins are the smallest of each over its sub-steps and pedestrians.

/// The smallest margins of an episode so far.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Margins {
    /// Smallest clearance between the car and a pedestrian, m (none while no pedestrian
    /// was in the world).
    pub clearance: Option<f64>,
    /// Smallest time-to-collision, s (none while the car was never on a collision course).
    pub ttc: Option<f64>,
    /// Smallest stopping margin, m (none while the car was never on a collision course).
    pub stop_margin: Option<f64>,
}

impl Margins {
    /// Whether braking could have stopped the car short of every collision course it was
    /// on (the stopping margin never negative).
    pub fn could_stop(&self) -> bool {
        self.stop_margin.is_none_or(|m| m >= 0.0)
    }

    /// Takes in one sub-step's measurement of one pedestrian.
    pub(crate) fn record(&mut self, clearance: f64, collision_course: Option<(f64, f64)>) {
        let least = |old: Option<f64>, new: f64| Some(old.map_or(new, |o| o.min(new)));
        self.clearance = least(self.clearance, clearance);
        if let Some((ttc, stop_margin)) = collision_course {
            self.ttc = least(self.ttc, ttc);
            self.stop_margin = least(self.stop_margin, stop_margin);
        }
    }
}
