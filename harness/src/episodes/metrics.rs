//! The metrics of §VI: training reward, test reward, success rate, collision rate,
//! inference rate (share of ticks that ran planning) and measured reasoning time; and
//! beyond the paper, red-light violations per episode (the traffic rule) and the margins
//! of how close the episodes came to a collision (docs/ARCHITECTURE.md §2, "Margins").

use unforeseen_agent::params::ScaledParams;
use unforeseen_sim::Action;

use crate::episodes::runner::EpisodeResult;

/// The size of the scaled agent's planning tree, `U + U^2 + ... + U^H` (U actions,
/// horizon H of `params`): the expected-free-energy mat-vecs one reasoning tick costs,
/// which the batch's lines multiply by the inference rate (`efe_matvecs_per_tick`).
pub fn efe_prefix_tree(params: &ScaledParams) -> usize {
    (1..=params.planning.horizon)
        .map(|k| Action::ALL.len().pow(k as u32))
        .sum()
}

/// Aggregate over a set of episodes of one method on one map.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Aggregate {
    /// Episodes aggregated.
    pub episodes: usize,
    /// Mean return.
    pub mean_reward: f64,
    /// Share of episodes that reached the goal without a collision.
    pub success_rate: f64,
    /// Share of episodes that ended in a collision.
    pub collision_rate: f64,
    /// Share of episodes that ran out of ticks.
    pub timeout_rate: f64,
    /// Red-light violations per episode (the car's front entering the crosswalk on red),
    /// mean; at most one per episode, so also the share of episodes with one. Counted on
    /// every map, whether or not its reward pays for it.
    #[serde(default)]
    pub red_light_rate: f64,
    /// Share of decision ticks that ran planning.
    pub inference_rate: f64,
    /// Mean decision ticks per episode.
    pub mean_ticks: f64,
    /// Mean wall-clock microseconds inside the controller per decision tick (all ticks).
    pub us_per_tick: f64,
    /// Mean wall-clock microseconds per reasoning tick (0 when none reasoned).
    pub us_per_reasoning_tick: f64,
    /// How close the episodes came to a collision.
    #[serde(flatten)]
    pub margins: MarginFigures,
}

/// The smallest margins over a set of episodes (docs/ARCHITECTURE.md §2, "Margins";
/// [`unforeseen_sim::margins`]), as the batch's and search's lines carry them. Each
/// smallest is none (null) when no episode had one. Files written before a key existed
/// read it as none.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct MarginFigures {
    /// Smallest clearance between the car and a pedestrian, m.
    #[serde(default)]
    pub min_clearance_m: Option<f64>,
    /// Smallest time-to-collision with a pedestrian or a vehicle, s.
    #[serde(default)]
    pub min_ttc_s: Option<f64>,
    /// Smallest stopping margin on a collision course, m (negative: the car could no
    /// longer have stopped short of the other's path).
    #[serde(default)]
    pub min_stop_margin_m: Option<f64>,
    /// Share of episodes in which braking could have stopped the car short of every
    /// collision course it was on.
    #[serde(default)]
    pub could_stop_rate: f64,
    /// Smallest clearance between the car and another vehicle, m.
    #[serde(default)]
    pub min_vehicle_clearance_m: Option<f64>,
    /// Smallest post-encroachment time car–pedestrian, s.
    #[serde(default)]
    pub min_pet_s: Option<f64>,
}

impl MarginFigures {
    /// The smallest margins of `results` (the default for an empty slice).
    pub fn of(results: &[EpisodeResult]) -> MarginFigures {
        if results.is_empty() {
            return MarginFigures::default();
        }
        let least = |f: &dyn Fn(&EpisodeResult) -> Option<f64>| results.iter().filter_map(f).reduce(f64::min);
        let could_stop = results.iter().filter(|r| r.could_stop()).count();
        MarginFigures {
            min_clearance_m: least(&|r| r.min_clearance),
            min_ttc_s: least(&|r| r.min_ttc),
            min_stop_margin_m: least(&|r| r.min_stop_margin),
            could_stop_rate: could_stop as f64 / results.len() as f64,
            min_vehicle_clearance_m: least(&|r| r.min_vehicle_clearance),
            min_pet_s: least(&|r| r.min_pet),
        }
    }
}

impl Aggregate {
    /// Aggregates episode results (all zeros for an empty slice).
    pub fn of(results: &[EpisodeResult]) -> Self {
        let n = results.len();
        if n == 0 {
            return Self::default();
        }
        let share = |f: &dyn Fn(&EpisodeResult) -> bool| results.iter().filter(|r| f(r)).count() as f64 / n as f64;
        let ticks: u64 = results.iter().map(|r| u64::from(r.ticks)).sum();
        let reasoning: u64 = results.iter().map(|r| u64::from(r.reasoning_ticks)).sum();
        let decide_ns: u64 = results.iter().map(|r| r.decide_ns).sum();
        let reasoning_ns: u64 = results.iter().map(|r| r.reasoning_ns).sum();
        Self {
            episodes: n,
            mean_reward: results.iter().map(|r| r.ret).sum::<f64>() / n as f64,
            success_rate: share(&|r| r.success),
            collision_rate: share(&|r| r.collision),
            timeout_rate: share(&|r| r.timeout),
            red_light_rate: results.iter().map(|r| f64::from(r.red_lights)).sum::<f64>() / n as f64,
            inference_rate: if ticks == 0 {
                0.0
            } else {
                reasoning as f64 / ticks as f64
            },
            mean_ticks: ticks as f64 / n as f64,
            us_per_tick: if ticks == 0 {
                0.0
            } else {
                decide_ns as f64 / ticks as f64 / 1e3
            },
            us_per_reasoning_tick: if reasoning == 0 {
                0.0
            } else {
                reasoning_ns as f64 / reasoning as f64 / 1e3
            },
            margins: MarginFigures::of(results),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aggregates_by_hand() {
        let a = EpisodeResult {
            ret: 10.0,
            success: true,
            ticks: 10,
            reasoning_ticks: 5,
            red_lights: 1,
            decide_ns: 10_000,
            reasoning_ns: 9_000,
            min_clearance: Some(1.5),
            min_pet: Some(3.0),
            min_vehicle_clearance: Some(7.0),
            ..Default::default()
        };
        let b = EpisodeResult {
            ret: -20.0,
            collision: true,
            ticks: 4,
            reasoning_ticks: 0,
            decide_ns: 4_000,
            min_clearance: Some(0.0),
            min_ttc: Some(0.0),
            min_stop_margin: Some(-2.0),
            min_pet: Some(0.0),
            ..Default::default()
        };
        let agg = Aggregate::of(&[a, b]);
        assert_eq!(agg.episodes, 2);
        assert_eq!(agg.mean_reward, -5.0);
        assert_eq!(agg.success_rate, 0.5);
        assert_eq!(agg.collision_rate, 0.5);
        assert_eq!(agg.timeout_rate, 0.0);
        assert_eq!(agg.red_light_rate, 0.5);
        assert!((agg.inference_rate - 5.0 / 14.0).abs() < 1e-15);
        assert_eq!(agg.mean_ticks, 7.0);
        assert!((agg.us_per_tick - 1.0).abs() < 1e-12);
        assert!((agg.us_per_reasoning_tick - 1.8).abs() < 1e-12);
        let m = &agg.margins;
        assert_eq!(
            (m.min_clearance_m, m.min_ttc_s, m.min_stop_margin_m),
            (Some(0.0), Some(0.0), Some(-2.0))
        );
        assert_eq!((m.min_vehicle_clearance_m, m.min_pet_s), (Some(7.0), Some(0.0)));
        assert_eq!(m.could_stop_rate, 0.5);
        assert_eq!(Aggregate::of(&[]), Aggregate::default());
    }
}
