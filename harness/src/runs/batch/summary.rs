//! The summary over training seeds (`results.summary.json`): each figure's mean, 95%
//! interval, range and worst seed, the expectations checked on the mean, and how each
//! map of a stream fares under the two protocols.

use serde::{Deserialize, Serialize};

use crate::episodes::protocol::Protocol;
use crate::stats::Stat;

use super::expectations::{Check, holds};
use super::result_line::ResultLine;

/// An expectation checked on the mean over training seeds, with its worst seed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryCheck {
    /// The figure checked, e.g. `success_rate`.
    pub figure: String,
    /// `min` or `max`.
    pub bound: String,
    /// The bound's value.
    pub limit: f64,
    /// The mean of the figure over training seeds (what the bound is checked on).
    pub mean: f64,
    /// Whether the bound held for the mean (the gate: a failed check fails the run).
    pub pass: bool,
    /// The seed whose value is furthest on the wrong side of the bound.
    pub worst_seed: Option<u64>,
    /// That seed's value.
    pub worst_value: f64,
    /// Whether the bound held for that seed too (informational).
    pub worst_seed_passes: bool,
}

/// The agent of a summary row with the lowest success (ties: lowest mean return).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WorstLine {
    /// Its training seed.
    pub train_seed: Option<u64>,
    /// Its success rate.
    pub success_rate: f64,
    /// Its mean return.
    pub mean_reward: f64,
}

/// One (scenario, method, parameter set, protocol) summarized over its training seeds, or
/// one map within a stream scenario's (scenario, method, parameter set, protocol).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SummaryRow {
    /// Scenario name: a map's, a stream's, or for a row within a stream its map's.
    pub scenario: String,
    /// For a row of one map within a stream, the stream's name (the row summarizes that
    /// map's episodes of the stream's units); left out otherwise.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stream: Option<String>,
    /// Map file or `embedded:NAME`.
    pub source: String,
    /// Method name.
    pub method: String,
    /// Parameter set label.
    pub param_set: String,
    /// The protocol the units ran under.
    pub protocol: Protocol,
    /// Every protocol these results hold for.
    pub covers: Vec<Protocol>,
    /// Evaluation seed.
    pub seed: u64,
    /// Episodes per agent.
    pub episodes: u64,
    /// Training seeds summarized, in order.
    pub train_seeds: Vec<Option<u64>>,
    /// Mean return, over seeds.
    pub mean_reward: Stat,
    /// Success rate, over seeds.
    pub success_rate: Stat,
    /// Collision rate, over seeds.
    pub collision_rate: Stat,
    /// Time-out rate, over seeds.
    pub timeout_rate: Stat,
    /// Red-light violations per episode, over seeds.
    pub red_light_rate: Stat,
    /// Share of ticks that reasoned, over seeds.
    pub inference_rate: Stat,
    /// EFE mat-vecs per tick, over seeds.
    pub efe_matvecs_per_tick: Stat,
    /// Mean decision ticks per episode, over seeds.
    pub mean_ticks: Stat,
    /// Wall-clock µs per tick, over seeds (the only clock-measured figure).
    pub timing_us_per_tick: Stat,
    /// The seed with the lowest success.
    pub worst_seed: WorstLine,
    /// The expectations, checked on the means.
    pub checks: Vec<SummaryCheck>,
}

/// Groups result lines by (scenario, method, parameter set, protocol), in order of first
/// appearance, and summarizes each group over its training seeds; a stream scenario's row
/// is followed by one row per map within the stream ([`ResultLine::within_stream`]), in
/// the stream's order.
pub fn summarize(lines: &[ResultLine]) -> Vec<SummaryRow> {
    let mut groups: Vec<Vec<&ResultLine>> = Vec::new();
    for l in lines {
        let same = |g: &Vec<&ResultLine>| {
            let f = g[0];
            (&f.scenario, &f.method, &f.param_set, f.protocol) == (&l.scenario, &l.method, &l.param_set, l.protocol)
        };
        match groups.iter_mut().find(|g| same(g)) {
            Some(g) => g.push(l),
            None => groups.push(vec![l]),
        }
    }
    let mut rows = Vec::new();
    for g in &groups {
        rows.push(summary_row(g));
        for f in &g[0].per_map {
            let within: Vec<ResultLine> = g.iter().filter_map(|l| l.within_stream(&f.map)).collect();
            let mut row = summary_row(&within.iter().collect::<Vec<_>>());
            row.stream = Some(g[0].scenario.clone());
            rows.push(row);
        }
    }
    rows
}

/// What learning across episodes does to one map within a stream, for one method and
/// parameter set: the map's figures under the continual protocol against zero-shot, on
/// the same episodes of the stream, as means over training seeds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StreamLearning {
    /// The stream's name.
    pub stream: String,
    /// The map within it.
    pub map: String,
    /// Method name.
    pub method: String,
    /// Parameter set label.
    pub param_set: String,
    /// Episodes of the stream on the map, per agent.
    pub episodes: u64,
    /// Mean success rate, zero-shot.
    pub zero_shot_success: f64,
    /// Mean success rate, continual.
    pub continual_success: f64,
    /// Mean return, zero-shot.
    pub zero_shot_reward: f64,
    /// Mean return, continual.
    pub continual_reward: f64,
    /// Whether learning made the map worse: a lower mean success rate continual than
    /// zero-shot.
    pub worse: bool,
}

/// For every map within a stream and every method that learns across episodes (a row
/// per protocol), what learning does to it ([`StreamLearning`]), in the rows' order.
/// Empty unless the rows hold a stream run under both protocols.
pub fn stream_learning(rows: &[SummaryRow]) -> Vec<StreamLearning> {
    let only = |r: &SummaryRow, p: Protocol| r.stream.is_some() && r.covers == [p];
    rows.iter()
        .filter(|z| only(z, Protocol::ZeroShot))
        .filter_map(|z| {
            let c = rows.iter().find(|c| {
                only(c, Protocol::Continual)
                    && (&c.stream, &c.scenario, &c.method, &c.param_set)
                        == (&z.stream, &z.scenario, &z.method, &z.param_set)
            })?;
            Some(StreamLearning {
                stream: z.stream.clone().unwrap_or_default(),
                map: z.scenario.clone(),
                method: z.method.clone(),
                param_set: z.param_set.clone(),
                episodes: z.episodes,
                zero_shot_success: z.success_rate.mean,
                continual_success: c.success_rate.mean,
                zero_shot_reward: z.mean_reward.mean,
                continual_reward: c.mean_reward.mean,
                worse: c.success_rate.mean < z.success_rate.mean - 1e-12,
            })
        })
        .collect()
}

/// Summarizes one group of lines (all of one configuration, one per seed).
fn summary_row(group: &[&ResultLine]) -> SummaryRow {
    let first = group[0];
    let stat = |f: fn(&ResultLine) -> f64| Stat::of(&group.iter().map(|l| f(l)).collect::<Vec<_>>());
    let worst = group
        [crate::stats::worst_of(group.iter().map(|l| (l.success_rate, l.mean_reward))).expect("groups are not empty")];
    SummaryRow {
        scenario: first.scenario.clone(),
        stream: None,
        source: first.source.clone(),
        method: first.method.clone(),
        param_set: first.param_set.clone(),
        protocol: first.protocol,
        covers: first.covers.clone(),
        seed: first.seed,
        episodes: first.episodes,
        train_seeds: group.iter().map(|l| l.train_seed).collect(),
        mean_reward: stat(|l| l.mean_reward),
        success_rate: stat(|l| l.success_rate),
        collision_rate: stat(|l| l.collision_rate),
        timeout_rate: stat(|l| l.timeout_rate),
        red_light_rate: stat(|l| l.red_light_rate),
        inference_rate: stat(|l| l.inference_rate),
        efe_matvecs_per_tick: stat(|l| l.efe_matvecs_per_tick),
        mean_ticks: stat(|l| l.mean_ticks),
        timing_us_per_tick: stat(|l| l.timing_us_per_tick),
        worst_seed: WorstLine {
            train_seed: worst.train_seed,
            success_rate: worst.success_rate,
            mean_reward: worst.mean_reward,
        },
        checks: first
            .checks
            .iter()
            .enumerate()
            .map(|(i, c)| summary_check(group, i, c))
            .collect(),
    }
}

/// Check `i` (like `c`) on the mean of the group's values, with the worst seed.
fn summary_check(group: &[&ResultLine], i: usize, c: &Check) -> SummaryCheck {
    let values: Vec<(Option<u64>, f64)> = group
        .iter()
        .filter_map(|l| {
            let x = l.checks.get(i)?;
            ((&x.figure, &x.bound, x.limit) == (&c.figure, &c.bound, c.limit)).then_some((l.train_seed, x.value))
        })
        .collect();
    let mean = values.iter().map(|v| v.1).sum::<f64>() / values.len() as f64;
    let badness = |v: f64| if c.bound == "min" { -v } else { v };
    let (worst_seed, worst_value) = values
        .iter()
        .copied()
        .reduce(|w, v| if badness(v.1) > badness(w.1) { v } else { w })
        .expect("the first line has this check");
    SummaryCheck {
        figure: c.figure.clone(),
        bound: c.bound.clone(),
        limit: c.limit,
        mean,
        pass: holds(&c.bound, c.limit, mean),
        worst_seed,
        worst_value,
        worst_seed_passes: holds(&c.bound, c.limit, worst_value),
    }
}
