//! One result line of a batch (a JSON line of the results file), with the figures per
//! map of a stream unit, and the key that identifies its unit for `--resume`.

use serde::{Deserialize, Serialize};

use crate::episodes::metrics::{Aggregate, MarginFigures};
use crate::episodes::protocol::Protocol;

use super::expectations::Check;

/// One result line of a batch (JSON Lines).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ResultLine {
    /// Position in the canonical unit order of the whole run.
    pub unit: usize,
    /// Scenario (map) name.
    pub scenario: String,
    /// Map file or `embedded:NAME`.
    pub source: String,
    /// Method name.
    pub method: String,
    /// Parameter set label (`default` when no overrides).
    pub param_set: String,
    /// The overrides, key -> value.
    pub params: Vec<(String, String)>,
    /// The protocol the unit ran under (`zero-shot` or `continual`).
    pub protocol: Protocol,
    /// Every protocol asked that these results hold for: `[protocol]`, or all asked for a
    /// method that does not learn across episodes (identical results, run once).
    pub covers: Vec<Protocol>,
    /// Training seed of the agent (null for an agent file that does not record it).
    pub train_seed: Option<u64>,
    /// Training episodes of the agent (null when unknown).
    pub train_episodes: Option<u64>,
    /// Evaluation seed.
    pub seed: u64,
    /// Episodes run.
    pub episodes: u64,
    /// Mean return.
    pub mean_reward: f64,
    /// Success rate.
    pub success_rate: f64,
    /// Collision rate.
    pub collision_rate: f64,
    /// Time-out rate.
    pub timeout_rate: f64,
    /// Red-light violations per episode (the car entering the crosswalk on red).
    #[serde(default)]
    pub red_light_rate: f64,
    /// Share of ticks that reasoned.
    pub inference_rate: f64,
    /// Reasoning compute in expected-free-energy mat-vecs per tick: inference rate times
    /// the prefix-tree size U + U^2 + ... + U^H (0 for methods that do not plan by EFE).
    pub efe_matvecs_per_tick: f64,
    /// Mean decision ticks per episode.
    pub mean_ticks: f64,
    /// The map's expectations for this method and protocol, checked on this agent alone
    /// (the gate is the check on the mean over training seeds, in the summary).
    pub checks: Vec<Check>,
    /// How close the episodes came to a collision (docs/ARCHITECTURE.md §2, "Margins").
    #[serde(flatten)]
    pub margins: MarginFigures,
    /// Wall-clock µs per decision tick (the only field that varies between identical runs).
    pub timing_us_per_tick: f64,
    /// For a stream scenario, the figures of each map within the stream that episodes ran
    /// on, in the stream's order (the line's own figures are over the whole stream); left
    /// out for a map scenario.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub per_map: Vec<MapFigures>,
}

/// The figures of one map within a stream unit: its episodes of the stream only.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapFigures {
    /// The map's name.
    pub map: String,
    /// Episodes of the stream that ran on it (the same for every training seed and
    /// protocol: the stream's order derives from the evaluation seed).
    pub episodes: u64,
    /// Mean return.
    pub mean_reward: f64,
    /// Success rate.
    pub success_rate: f64,
    /// Collision rate.
    pub collision_rate: f64,
    /// Time-out rate.
    pub timeout_rate: f64,
    /// Red-light violations per episode.
    pub red_light_rate: f64,
    /// Share of ticks that reasoned.
    pub inference_rate: f64,
    /// Reasoning compute in EFE mat-vecs per tick (as [`ResultLine::efe_matvecs_per_tick`]).
    pub efe_matvecs_per_tick: f64,
    /// Mean decision ticks per episode.
    pub mean_ticks: f64,
    /// How close its episodes came to a collision.
    #[serde(flatten)]
    pub margins: MarginFigures,
    /// Wall-clock µs per decision tick.
    pub timing_us_per_tick: f64,
}

/// What a result line says of its unit, beside the figures: where it sits in the run,
/// what ran and with which agent and seeds.
#[derive(Debug, Clone)]
pub struct UnitLabel {
    /// Position in the canonical unit order of the whole run.
    pub unit: usize,
    /// Scenario (map) name.
    pub scenario: String,
    /// Map file or `embedded:NAME`.
    pub source: String,
    /// Method name.
    pub method: String,
    /// Parameter set label (`default` when no overrides).
    pub param_set: String,
    /// The overrides, key -> value.
    pub params: Vec<(String, String)>,
    /// The protocol the unit ran under.
    pub protocol: Protocol,
    /// Every protocol these results hold for.
    pub covers: Vec<Protocol>,
    /// Training seed of the agent.
    pub train_seed: Option<u64>,
    /// Training episodes of the agent.
    pub train_episodes: Option<u64>,
    /// Evaluation seed.
    pub seed: u64,
}

impl ResultLine {
    /// The one builder of a result line (the batch's units, the search's evaluations and
    /// methods given from outside all make theirs here): `label`, the figures of `agg`
    /// with the reasoning compute of a method whose reasoning tick costs `reasoning_tree`
    /// EFE mat-vecs ([`Method::reasoning_tree`](crate::episodes::methods::Method::reasoning_tree)),
    /// the map's `checks`, and for a stream the figures `per_map`.
    pub fn new(
        label: UnitLabel,
        agg: &Aggregate,
        reasoning_tree: usize,
        checks: Vec<Check>,
        per_map: Vec<MapFigures>,
    ) -> ResultLine {
        ResultLine {
            unit: label.unit,
            scenario: label.scenario,
            source: label.source,
            method: label.method,
            param_set: label.param_set,
            params: label.params,
            protocol: label.protocol,
            covers: label.covers,
            train_seed: label.train_seed,
            train_episodes: label.train_episodes,
            seed: label.seed,
            episodes: agg.episodes as u64,
            mean_reward: agg.mean_reward,
            success_rate: agg.success_rate,
            collision_rate: agg.collision_rate,
            timeout_rate: agg.timeout_rate,
            red_light_rate: agg.red_light_rate,
            inference_rate: agg.inference_rate,
            efe_matvecs_per_tick: agg.inference_rate * reasoning_tree as f64,
            mean_ticks: agg.mean_ticks,
            checks,
            margins: agg.margins.clone(),
            timing_us_per_tick: agg.us_per_tick,
            per_map,
        }
    }
}

impl MapFigures {
    /// The figures of `map` within a stream unit: those of `agg`, its episodes on the
    /// map, with the reasoning compute as in [`ResultLine::new`].
    pub fn new(map: String, agg: &Aggregate, reasoning_tree: usize) -> MapFigures {
        MapFigures {
            map,
            episodes: agg.episodes as u64,
            mean_reward: agg.mean_reward,
            success_rate: agg.success_rate,
            collision_rate: agg.collision_rate,
            timeout_rate: agg.timeout_rate,
            red_light_rate: agg.red_light_rate,
            inference_rate: agg.inference_rate,
            efe_matvecs_per_tick: agg.inference_rate * reasoning_tree as f64,
            mean_ticks: agg.mean_ticks,
            margins: agg.margins.clone(),
            timing_us_per_tick: agg.us_per_tick,
        }
    }
}

impl ResultLine {
    /// The line of map `map` within this stream unit's line: its figures, episodes and
    /// scenario (the map's name); no checks. None if no episode of the unit ran on it.
    pub fn within_stream(&self, map: &str) -> Option<ResultLine> {
        let f = self.per_map.iter().find(|f| f.map == map)?;
        Some(ResultLine {
            scenario: f.map.clone(),
            episodes: f.episodes,
            mean_reward: f.mean_reward,
            success_rate: f.success_rate,
            collision_rate: f.collision_rate,
            timeout_rate: f.timeout_rate,
            red_light_rate: f.red_light_rate,
            inference_rate: f.inference_rate,
            efe_matvecs_per_tick: f.efe_matvecs_per_tick,
            mean_ticks: f.mean_ticks,
            margins: f.margins.clone(),
            timing_us_per_tick: f.timing_us_per_tick,
            checks: Vec::new(),
            per_map: Vec::new(),
            ..self.clone()
        })
    }
}

/// The identity of a unit, for `--resume`: (scenario, method, parameter set, protocol,
/// training seed).
pub type UnitKey = (String, String, String, Protocol, Option<u64>);

impl ResultLine {
    /// The identity of the unit, for `--resume`.
    pub fn key(&self) -> UnitKey {
        (
            self.scenario.clone(),
            self.method.clone(),
            self.param_set.clone(),
            self.protocol,
            self.train_seed,
        )
    }
}
