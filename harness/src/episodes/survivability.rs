//! Is a scenario a fair unforeseen test (§VI)? The jaywalk test means something only if
//! a careful driver survives it and a careless one does not. Two scripted witnesses
//! ([`crate::episodes::reference`]) answer that without any trained agent:
//!
//! * **survivable**: [`Method::BrakeOnPedestrian`] succeeds in at least
//!   [`SURVIVABLE_MIN_SUCCESS`] (99%) of the episodes;
//! * **dangerous**: [`Method::NeverBrake`] succeeds in at most [`DANGEROUS_MAX_SUCCESS`]
//!   (20%) of the episodes, the same bound the shipped maps put on Q-learning
//!   (`(method: QLearning, max_success: 0.2)`): if a car that drives on gets through
//!   more often than that, the map cannot show that the habit is fooled.
//!
//! `check-map` measures both on every map with pedestrian rules; `batch` checks its
//! brake-on-pedestrian and never-brake units. Both report the same warnings (returned
//! here; the command line prints them on stderr) and neither changes the exit code. Episodes use [`crate::episodes::experiments::eval_seeds`], so `check-map
//! --seed S` and `batch --seed S` meet the same pedestrians and report the same figures.

use unforeseen_sim::Map;

use crate::episodes::experiments::evaluate_scripted;
use crate::episodes::methods::Method;
use crate::episodes::metrics::Aggregate;
use crate::error::Error;
use crate::progress::NoProgress;

/// Lowest success rate of brake-on-pedestrian for a map to count as survivable.
pub const SURVIVABLE_MIN_SUCCESS: f64 = 0.99;

/// Highest success rate of never-brake for a map to count as dangerous.
pub const DANGEROUS_MAX_SUCCESS: f64 = 0.2;

/// Default episodes per witness in `check-map`.
pub const DEFAULT_EPISODES: u64 = 100;

/// How one scripted witness fared on a map.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Witness {
    /// Episodes run.
    pub episodes: u64,
    /// Success rate.
    pub success_rate: f64,
    /// Collision rate.
    pub collision_rate: f64,
    /// Time-out rate.
    pub timeout_rate: f64,
}

impl Witness {
    /// From an aggregate over `episodes` episodes.
    pub fn of(agg: &Aggregate) -> Self {
        Witness {
            episodes: agg.episodes as u64,
            success_rate: agg.success_rate,
            collision_rate: agg.collision_rate,
            timeout_rate: agg.timeout_rate,
        }
    }

    fn figures(&self) -> String {
        format!(
            "{:.1}% of {} episodes (collisions {:.1}%, time-outs {:.1}%)",
            100.0 * self.success_rate,
            self.episodes,
            100.0 * self.collision_rate,
            100.0 * self.timeout_rate
        )
    }
}

/// Runs `episodes` episodes of a scripted `method` on `map` (in parallel; seeded by
/// [`crate::episodes::experiments::eval_seeds`], so the result does not depend on the number of threads).
pub fn witness(map: &Map, method: Method, episodes: u64, seed: u64) -> Result<Witness, Error> {
    let results = evaluate_scripted(map, method, episodes, seed, &NoProgress)?;
    Ok(Witness::of(&Aggregate::of(&results)))
}

/// The warnings for map `name` given what the witnesses measured (`None`: not run).
pub fn warnings(name: &str, brake: Option<&Witness>, never_brake: Option<&Witness>) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(w) = brake.filter(|w| w.episodes > 0 && w.success_rate < SURVIVABLE_MIN_SUCCESS) {
        out.push(format!(
            "WARNING: map '{name}' may not be survivable: {} (brakes from the first tick a pedestrian is on the \
             crosswalk) succeeds in {}, under {:.0}%; in a fair unforeseen test a car that brakes as soon as \
             it sees the pedestrian can stop in time (let them step out when the car is farther away)",
            Method::BrakeOnPedestrian,
            w.figures(),
            100.0 * SURVIVABLE_MIN_SUCCESS
        ));
    }
    if let Some(w) = never_brake.filter(|w| w.episodes > 0 && w.success_rate > DANGEROUS_MAX_SUCCESS) {
        out.push(format!(
            "WARNING: map '{name}' may not be dangerous: {} (always speeds up) succeeds in {}, over {:.0}%; \
             a car that drives on should meet the pedestrian in its lane",
            Method::NeverBrake,
            w.figures(),
            100.0 * DANGEROUS_MAX_SUCCESS
        ));
    }
    out
}

/// Measures both witnesses on `map` and returns the warnings; none when the map has no
/// pedestrian rules or `episodes` is 0.
pub fn check(map: &Map, episodes: u64, seed: u64) -> Result<Vec<String>, Error> {
    if episodes == 0 || map.pedestrians.is_empty() {
        return Ok(Vec::new());
    }
    let brake = witness(map, Method::BrakeOnPedestrian, episodes, seed)?;
    let never = witness(map, Method::NeverBrake, episodes, seed)?;
    Ok(warnings(&map.name, Some(&brake), Some(&never)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn w(success_rate: f64) -> Witness {
        Witness {
            episodes: 100,
            success_rate,
            collision_rate: 1.0 - success_rate,
            timeout_rate: 0.0,
        }
    }

    #[test]
    fn thresholds() {
        assert!(warnings("m", Some(&w(0.99)), Some(&w(0.2))).is_empty());
        let both = warnings("m", Some(&w(0.98)), Some(&w(0.21)));
        assert_eq!(both.len(), 2);
        assert!(both[0].contains("not be survivable") && both[0].contains("98.0% of 100 episodes"));
        assert!(both[1].contains("not be dangerous") && both[1].contains("21.0% of 100 episodes"));
        assert!(warnings("m", None, None).is_empty());
    }
}
