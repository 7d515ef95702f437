//! A map's expectations (`expect` in the map file) checked against a unit's figures.

use serde::{Deserialize, Serialize};
use unforeseen_sim::Map;

use crate::episodes::methods::Method;
use crate::episodes::metrics::Aggregate;
use crate::episodes::protocol::Protocol;

/// One checked expectation of a map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Check {
    /// The figure checked, e.g. `success_rate`.
    pub figure: String,
    /// `min` or `max`.
    pub bound: String,
    /// The bound's value.
    pub limit: f64,
    /// What we measured.
    pub value: f64,
    /// Whether the bound held.
    pub pass: bool,
}

/// Checks a map's expectations for `method` against an aggregate of a unit whose
/// results hold for the protocols `covers`: an expectation naming a protocol applies
/// only if `covers` includes it; one naming none applies to every protocol.
pub fn check_expectations(map: &Map, method: Method, covers: &[Protocol], agg: &Aggregate) -> Vec<Check> {
    let mut checks = Vec::new();
    // Names were checked when the map was loaded ([`crate::maps::check_expectation_names`]).
    let applies = |p: &Option<String>| {
        p.as_deref()
            .is_none_or(|p| Protocol::from_map_name(p).is_some_and(|p| covers.contains(&p)))
    };
    for e in map
        .expect
        .iter()
        .filter(|e| e.method == method.map_name() && applies(&e.protocol))
    {
        let mut add = |figure: &str, bound: &str, limit: Option<f64>, value: f64| {
            if let Some(limit) = limit {
                checks.push(Check {
                    figure: figure.into(),
                    bound: bound.into(),
                    limit,
                    value,
                    pass: holds(bound, limit, value),
                });
            }
        };
        add("success_rate", "min", e.min_success, agg.success_rate);
        add("success_rate", "max", e.max_success, agg.success_rate);
        add("mean_reward", "min", e.min_reward, agg.mean_reward);
        add("mean_reward", "max", e.max_reward, agg.mean_reward);
        add("collision_rate", "max", e.max_collision, agg.collision_rate);
        add("inference_rate", "max", e.max_inference_rate, agg.inference_rate);
        add("red_light_rate", "max", e.max_red_light, agg.red_light_rate);
        add("timeout_rate", "max", e.max_timeout, agg.timeout_rate);
    }
    checks
}

/// Whether `value` respects the `bound` (`min` or `max`) `limit`.
pub(super) fn holds(bound: &str, limit: f64, value: f64) -> bool {
    if bound == "min" { value >= limit } else { value <= limit }
}
