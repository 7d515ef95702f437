//! Is a scenario a fair unforeseen test (§VI)? The jaywalk test means something only if
//! a careful driver survives it and a careless one does not. Two scripted witnesses
//! ([`crate::episodes::BrakeOnPedestrian`], [`crate::episodes::NeverBrake`]) answer that without any trained agent:
//!
//! * **survivable**: [`Method::BrakeOnPedestrian`] succeeds in at least
//!   [`SURVIVABLE_MIN_SUCCESS`] (99%) of the episodes, cruising at the car's top speed
//!   and at each slower cruise of [`careful_cruises`] ([`careful_witness`]);
//! * **dangerous**: [`Method::NeverBrake`] succeeds in at most [`DANGEROUS_MAX_SUCCESS`]
//!   (20%) of the episodes, the same bound the shipped maps put on Q-learning
//!   (`(method: QLearning, max_success: 0.2)`): if a car that drives on gets through
//!   more often than that, the map cannot show that the habit is fooled.
//!
//! Why several cruise speeds: brake-on-pedestrian speeds up to the car's top speed, and
//! pedestrians that step out by the car's time to arrival meet it at one timing. Searches
//! found maps that it survives at the top speed and not 5 or 10% slower (in 16% to 78% of
//! the episodes, EXPERIMENTS.md, "Fair or knife-edge"), and maps it survives from 90% up
//! but not cruising lower in the top speed bin (0% to 51% there, EXPERIMENTS.md, "Actions
//! the model cannot tell apart"): such a map tests when the car happens to arrive, not
//! whether it brakes for what it sees, and a careful driver that cruises a little slower
//! dies there. The agent's states cannot tell one speed of the top bin from another, so
//! every cruise in that bin is one it may hold. A map is survivable when care alone
//! suffices.
//!
//! `check-map` measures both on every map with pedestrian rules; `batch` on the maps where
//! it ran brake-on-pedestrian and never-brake, with the careful cruises at its own
//! episodes and seed. Both report the same warnings (returned
//! here; the command line prints them on stderr) and neither changes the exit code. Episodes use [`crate::episodes::evaluation::eval_seeds`], so `check-map
//! --seed S` and `batch --seed S` meet the same pedestrians and report the same figures.

use unforeseen_sim::Map;

use crate::episodes::evaluation::run_scripted_episodes;
use crate::episodes::methods::Method;
use crate::episodes::metrics::Aggregate;
use crate::error::Error;
use crate::progress::{NoProgress, Progress};

/// Lowest success rate of brake-on-pedestrian for a map to count as survivable.
pub const SURVIVABLE_MIN_SUCCESS: f64 = 0.99;

/// Highest success rate of never-brake for a map to count as dangerous.
pub const DANGEROUS_MAX_SUCCESS: f64 = 0.2;

/// The cruise speeds, as fractions of the car's top speed, at which brake-on-pedestrian
/// must survive a map for it to count as survivable (with those of [`TOP_BIN_CRUISES`]).
pub const CAREFUL_CRUISE: [f64; 3] = [1.0, 0.95, 0.9];

/// Cruises spread evenly from the lower edge of the map's top speed bin up to (not
/// including) the slowest of [`CAREFUL_CRUISE`], where that edge is below it.
pub const TOP_BIN_CRUISES: usize = 4;

/// Every careful cruise of `map`, as fractions of its top speed: [`CAREFUL_CRUISE`], then
/// [`TOP_BIN_CRUISES`] cruises from the lower edge of the top speed bin (the last of
/// `bins.speed_edges`) toward 90%: speeds the map's own states cannot tell from the top
/// speed, so that a habit holding "maintain" anywhere in that bin is a careful cruise.
pub fn careful_cruises(map: &Map) -> Vec<f64> {
    let mut cruises = CAREFUL_CRUISE.to_vec();
    let slowest = CAREFUL_CRUISE[CAREFUL_CRUISE.len() - 1];
    let top = map.vehicle.max_speed;
    if let Some(&edge) = map.bins.speed_edges.last()
        && top > 0.0
        && edge / top < slowest
    {
        let lo = edge / top;
        cruises.extend((0..TOP_BIN_CRUISES).map(|k| lo + (slowest - lo) * k as f64 / TOP_BIN_CRUISES as f64));
    }
    cruises
}

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
    /// The cruise speed it drove at, as a fraction of the car's top speed (1 for the map
    /// as written).
    pub cruise: f64,
}

impl Witness {
    /// From an aggregate over `episodes` episodes.
    pub fn of(agg: &Aggregate) -> Self {
        Witness {
            episodes: agg.episodes as u64,
            success_rate: agg.success_rate,
            collision_rate: agg.collision_rate,
            timeout_rate: agg.timeout_rate,
            cruise: 1.0,
        }
    }

    fn figures(&self) -> String {
        let cruise = if self.cruise < 1.0 {
            format!(" cruising at {:.0}% of the car's top speed", 100.0 * self.cruise)
        } else {
            String::new()
        };
        format!(
            "{:.1}% of {} episodes{cruise} (collisions {:.1}%, time-outs {:.1}%)",
            100.0 * self.success_rate,
            self.episodes,
            100.0 * self.collision_rate,
            100.0 * self.timeout_rate
        )
    }
}

/// Runs `episodes` episodes of a scripted `method` on `map` (in parallel; seeded by
/// [`crate::episodes::evaluation::eval_seeds`], so the result does not depend on the number of threads).
pub fn witness(map: &Map, method: Method, episodes: u64, seed: u64) -> Result<Witness, Error> {
    let results = run_scripted_episodes(map, method, episodes, seed, &NoProgress)?;
    Ok(Witness::of(&Aggregate::of(&results)))
}

/// The map a driver cruising at `fraction` of the car's top speed meets: the same map
/// (and name, so the same pedestrians) with that top speed, never below the start speed.
/// brake-on-pedestrian speeds up until the top speed, so this is its cruise.
pub fn at_cruise(map: &Map, fraction: f64) -> Map {
    let mut slower = map.clone();
    let v = &mut slower.vehicle;
    v.max_speed = (fraction * v.max_speed).max(v.start_speed);
    slower
}

/// brake-on-pedestrian's [`aggregate`](Aggregate) on `map` at each of its
/// [`careful_cruises`], and the worst of them (the lowest success; the fastest cruise on a
/// tie): a map is survivable when this witness succeeds in at least
/// [`SURVIVABLE_MIN_SUCCESS`]. Each cruise's episodes derive from `seed` as
/// [`witness`]'s do.
pub fn careful_witness(
    map: &Map,
    episodes: u64,
    seed: u64,
    progress: &dyn Progress,
) -> Result<(Witness, Aggregate), Error> {
    let mut worst: Option<(Witness, Aggregate)> = None;
    for fraction in careful_cruises(map) {
        let agg = Aggregate::of(&run_scripted_episodes(
            &at_cruise(map, fraction),
            Method::BrakeOnPedestrian,
            episodes,
            seed,
            progress,
        )?);
        let w = Witness {
            cruise: fraction,
            ..Witness::of(&agg)
        };
        if worst.as_ref().is_none_or(|(b, _)| w.success_rate < b.success_rate) {
            worst = Some((w, agg));
        }
    }
    Ok(worst.expect("CAREFUL_CRUISE is not empty, so neither are the careful cruises"))
}

/// The warnings for map `name` given what the witnesses measured (`None`: not run).
pub fn warnings(name: &str, brake: Option<&Witness>, never_brake: Option<&Witness>) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(w) = brake.filter(|w| w.episodes > 0 && w.success_rate < SURVIVABLE_MIN_SUCCESS) {
        out.push(format!(
            "WARNING: map '{name}' may not be survivable: {} (brakes from the first tick a pedestrian is on the \
             crosswalk) succeeds in {}, under {:.0}%; in a fair unforeseen test a car that brakes as soon as \
             it sees the pedestrian can stop in time, at its top speed or a little slower (let them step out \
             when the car is farther away)",
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
    let (brake, _) = careful_witness(map, episodes, seed, &NoProgress)?;
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
            cruise: 1.0,
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
        let slower = Witness { cruise: 0.9, ..w(0.5) };
        assert!(
            warnings("m", Some(&slower), None)[0]
                .contains("50.0% of 100 episodes cruising at 90% of the car's top speed")
        );
    }

    #[test]
    fn the_careful_cruises_span_the_top_speed_bin() {
        // Default bins (top edge 7.5 m/s), top speed 9 m/s: the bin starts at 5/6 of it,
        // and four cruises reach from there toward 90% in steps of (0.9 - 5/6) / 4.
        let mut map = Map::default();
        map.vehicle.max_speed = 9.0;
        map.bins.speed_edges = vec![0.5, 4.5, 7.5];
        let want = [1.0, 0.95, 0.9, 7.5 / 9.0, 0.85, 26.0 / 30.0, 53.0 / 60.0];
        let got = careful_cruises(&map);
        assert_eq!(got.len(), want.len());
        for (g, w) in got.iter().zip(want) {
            assert!((g - w).abs() < 1e-12, "{got:?}");
        }
        // A top bin that starts at 90% of the top speed or above adds nothing.
        map.vehicle.max_speed = 8.0;
        assert_eq!(careful_cruises(&map), CAREFUL_CRUISE.to_vec());
        map.bins.speed_edges.clear();
        assert_eq!(careful_cruises(&map), CAREFUL_CRUISE.to_vec());
    }

    #[test]
    fn a_slower_cruise_is_the_same_map_with_a_lower_top_speed_never_below_the_start() {
        let map = Map::default();
        let slow = at_cruise(&map, 0.9);
        assert_eq!(slow.vehicle.max_speed, 0.9 * map.vehicle.max_speed);
        assert_eq!((&slow.name, &slow.pedestrians), (&map.name, &map.pedestrians));
        assert_eq!(at_cruise(&map, 1e-6).vehicle.max_speed, map.vehicle.start_speed);
    }
}
