//! Comparison studies: the paper's table (Fig. 8, zero-shot) and its continual
//! counterpart (Fig. 9 setting), every method with every trained agent (training seed)
//! under every protocol asked, summarized over agents as a mean with a 95% interval,
//! the range and the worst seed. The per-agent rows are kept. A study is asked for by
//! one [`CompareRequest`] from every front, and writes its files
//! ([`COMPARE_FILES`]).

pub(crate) mod files;
pub(crate) mod request;
pub(crate) mod table;

pub use files::COMPARE_FILES;
pub use request::{CompareJob, CompareRequest};
pub use table::compare_table;

use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use unforeseen_agent::params::ScaledParams;
use unforeseen_sim::{Map, Reward};

use crate::episodes::evaluation::{MethodRow, method_row, run_agent_episodes};
use crate::episodes::methods::Method;
use crate::episodes::metrics::Aggregate;
use crate::episodes::protocol::Protocol;
use crate::episodes::rewards;
use crate::error::Error;
use crate::progress::{Message, Progress};
use crate::stats::Stat;
use crate::training::seed_agents::Agent;

/// What a study evaluates.
#[derive(Debug, Clone)]
pub struct StudySetup<'a> {
    /// The map the agents were trained on (the "train reward" column).
    pub train_map: &'a Map,
    /// The unforeseen test map.
    pub test_map: &'a Map,
    /// The scaled agent's parameters.
    pub params: &'a ScaledParams,
    /// Methods, in table order.
    pub methods: &'a [Method],
    /// Protocols, in table order.
    pub protocols: &'a [Protocol],
    /// Evaluation episodes per method, map and agent.
    pub episodes: u64,
    /// Evaluation seed: episode seeds derive from it, the same for every agent.
    pub seed: u64,
}

/// The agent with the lowest test success (ties: lowest test reward, then first seed).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct WorstSeed {
    /// Its training seed.
    pub train_seed: Option<u64>,
    /// Its success rate on the test map.
    pub success_rate: f64,
    /// Its mean return on the test map.
    pub test_reward: f64,
}

/// One row of a protocol's table: one method over all agents.
#[derive(Debug, Clone, Serialize)]
pub struct MethodSummary {
    /// Method name.
    pub method: String,
    /// The protocol of the table this row belongs to.
    pub protocol: Protocol,
    /// The protocol the episodes ran under: zero-shot for a method that does not learn
    /// across episodes, whose results are identical under both (run once, reported in both).
    pub computed_under: Protocol,
    /// Whether the method learns across test episodes.
    pub learns_across_episodes: bool,
    /// Evaluation seed.
    pub seed: u64,
    /// Training seeds of the agents, in order (null for an agent file that does not say).
    pub train_seeds: Vec<Option<u64>>,
    /// Training episodes per agent (null when unknown).
    pub train_episodes: Option<u64>,
    /// Evaluation episodes per agent on each of the two maps.
    pub episodes: u64,
    /// The reward the returns are paid in, on each map.
    pub reward: RewardPair,
    /// Mean return on the training map, over agents.
    pub train_reward: Stat,
    /// Mean return on the test map, over agents.
    pub test_reward: Stat,
    /// Success rate on the test map, over agents.
    pub success_rate: Stat,
    /// Collision rate on the test map, over agents.
    pub collision_rate: Stat,
    /// Red-light violations per episode on the test map, over agents.
    pub red_light_rate: Stat,
    /// Share of test ticks that ran planning, over agents.
    pub inference_rate: Stat,
    /// Wall-clock µs per test tick, over agents (the only clock-measured figure).
    pub reasoning_us_per_tick: Stat,
    /// The agent that did worst on the test map.
    pub worst_seed: WorstSeed,
    /// One row per agent, in seed order.
    pub per_seed: Vec<MethodRow>,
}

/// The reward settings of the training and the test map.
#[derive(Debug, Clone, Serialize)]
pub struct RewardPair {
    /// The training map's reward (train reward column).
    pub train_map: Reward,
    /// The test map's reward (every other column).
    pub test_map: Reward,
}

impl RewardPair {
    /// The rewards of a training and a test map.
    pub fn of(train_map: &Map, test_map: &Map) -> Self {
        RewardPair {
            train_map: train_map.reward.clone(),
            test_map: test_map.reward.clone(),
        }
    }
}

/// The table of one protocol.
#[derive(Debug, Clone, Serialize)]
pub struct ProtocolTable {
    /// The protocol.
    pub protocol: Protocol,
    /// What it means.
    pub meaning: String,
    /// One row per method.
    pub methods: Vec<MethodSummary>,
    /// Scaled's inference rate divided by Bayesian RL's, per agent, summarized (paper: 0.633).
    pub scaled_inference_relative_to_bayes_rl: Option<Stat>,
}

/// A metric of a per-agent row, by name (the columns of the tables, CSV and plots).
pub type Metric = (&'static str, fn(&MethodRow) -> f64);

/// The summarized metrics, in column order.
pub const METRICS: [Metric; 7] = [
    ("train_reward", |r| r.train_reward),
    ("test_reward", |r| r.test_reward),
    ("success_rate", |r| r.success_rate),
    ("collision_rate", |r| r.collision_rate),
    ("inference_rate", |r| r.inference_rate),
    ("reasoning_us_per_tick", |r| r.reasoning_us_per_tick),
    ("red_light_rate", |r| r.red_light_rate),
];

impl MethodSummary {
    /// The summary of a metric by name (one of [`METRICS`]).
    pub fn stat(&self, metric: &str) -> &Stat {
        match metric {
            "train_reward" => &self.train_reward,
            "test_reward" => &self.test_reward,
            "success_rate" => &self.success_rate,
            "collision_rate" => &self.collision_rate,
            "inference_rate" => &self.inference_rate,
            "reasoning_us_per_tick" => &self.reasoning_us_per_tick,
            "red_light_rate" => &self.red_light_rate,
            _ => panic!("unknown metric {metric}"),
        }
    }
}

/// One evaluation: an agent, a method, the protocol it really runs under, a map.
type Job = (usize, Method, Protocol, usize);

/// Every distinct evaluation the study needs (a method that does not learn across
/// episodes is evaluated once, zero-shot, whatever the protocols).
fn jobs(setup: &StudySetup<'_>, n_agents: usize) -> Vec<Job> {
    let mut out: Vec<Job> = Vec::new();
    for agent in 0..n_agents {
        for &method in setup.methods {
            for &protocol in setup.protocols {
                let eff = protocol.effective(method, setup.params);
                for map in 0..2 {
                    if !out.contains(&(agent, method, eff, map)) {
                        out.push((agent, method, eff, map));
                    }
                }
            }
        }
    }
    out
}

/// The whole `compare.json` (schema 2: one table per protocol, each row summarized over
/// training seeds with its per-seed rows kept), built by [`CompareReport::new`] alone,
/// which the command line and the Python package both call.
#[derive(Debug, serde::Serialize)]
pub struct CompareReport {
    /// Schema version of this file.
    pub schema: u32,
    /// The protocols, in table order.
    pub protocols: Vec<Protocol>,
    /// One table per protocol.
    pub tables: Vec<ProtocolTable>,
    /// What each column measures and on which map (train reward on the training map,
    /// every other column on the test map).
    pub columns: serde_json::Value,
    /// The paper's values for the same columns (§VI, zero-shot; null where the paper
    /// gives none, as for the collision rate).
    pub paper: Vec<serde_json::Value>,
    /// Training map name.
    pub train_map: String,
    /// Test map name.
    pub test_map: String,
    /// The reward settings of both maps (`train_map`, `test_map`).
    pub reward: RewardPair,
    /// Each map's reward in words (`rewards::describe`: training map, test map), as the
    /// printed tables give it ([`crate::runs::compare::compare_table`]); not in the file.
    #[serde(skip)]
    pub reward_described: (String, String),
    /// Evaluation seed (episode seeds derive from it, the same for every agent).
    pub seed: u64,
    /// Training seeds of the agents (null for an agent file that does not say).
    pub train_seeds: Vec<Option<u64>>,
    /// Agent file given with --agent, if any.
    pub agent_file: Option<String>,
    /// Agent cache folder used by --train-seeds, if any.
    pub agent_cache: Option<String>,
    /// Training episodes per agent (null when unknown).
    pub train_episodes: Option<u64>,
    /// Evaluation episodes per method, map and agent.
    pub episodes: u64,
    /// How actions are chosen from the policy in evaluation.
    pub action_selection: String,
    /// The scaled agent's parameters.
    pub scaled_params: serde_json::Value,
}

impl CompareReport {
    /// The report of the comparison `setup` over `agents`, whose tables [`run_study`]
    /// computed: the one builder of compare.json. `agent_file` is the agent file the
    /// agent came from, if any; `agent_cache` the agent cache folder of a training-seed
    /// study, if one was used.
    pub fn new(
        setup: &StudySetup<'_>,
        agents: &[Agent],
        tables: Vec<ProtocolTable>,
        agent_file: Option<String>,
        agent_cache: Option<String>,
    ) -> Result<Self, Error> {
        Ok(CompareReport {
            schema: 2,
            protocols: setup.protocols.to_vec(),
            tables,
            columns: columns(&setup.train_map.name, &setup.test_map.name, setup.episodes),
            paper: paper_rows(),
            train_map: setup.train_map.name.clone(),
            test_map: setup.test_map.name.clone(),
            reward: RewardPair::of(setup.train_map, setup.test_map),
            reward_described: (rewards::describe(setup.train_map), rewards::describe(setup.test_map)),
            seed: setup.seed,
            train_seeds: agents.iter().map(|a| a.train_seed).collect(),
            agent_file,
            agent_cache,
            train_episodes: agents.first().and_then(|a| a.train_episodes),
            episodes: setup.episodes,
            action_selection: format!("{:?}", setup.params.scaling.action_selection),
            scaled_params: serde_json::to_value(setup.params)?,
        })
    }
}

/// The paper's values, one row per method of [`Method::PAPER`] with the columns of the
/// table (null where the paper gives none: the collision and red-light rates).
fn paper_rows() -> Vec<serde_json::Value> {
    Method::PAPER
        .iter()
        .filter_map(|m| {
            m.paper().map(|p| {
                serde_json::json!({"method": m.name(), "train_reward": p.train_reward, "test_reward": p.test_reward,
                    "success_rate": p.success_rate, "collision_rate": null, "red_light_rate": null,
                    "inference_rate_relative_to_bayes_rl": p.inference_rate})
            })
        })
        .collect()
}

/// What each column of the table measures, on which map and over how many episodes.
fn columns(train_map: &str, test_map: &str, episodes: u64) -> serde_json::Value {
    let on_test = |what: &str| format!("{what} on the test map '{test_map}', {episodes} episodes per method and agent");
    serde_json::json!({
        "train_reward": format!("mean return on the training map '{train_map}' after training, {episodes} episodes per method and agent"),
        "test_reward": on_test("mean return"),
        "success_rate": on_test("share of episodes reaching the destination without a collision"),
        "collision_rate": format!("{}; the paper gives no value", on_test("share of episodes that hit a pedestrian")),
        "red_light_rate": format!("{}; not in the paper", on_test("red-light violations per episode: the car's front entering the crosswalk on red (at most one per episode)")),
        "inference_rate": on_test("share of decision ticks that ran planning"),
        "reasoning_us_per_tick": on_test("wall-clock µs per tick inside the controller"),
    })
}

/// Runs the study: every job in parallel (rayon; zero-shot episodes are parallel too),
/// then one table per protocol. Results do not depend on the number of threads. One
/// phase of `progress` (`evaluating`, one step per episode), with a [`Message::Status`]
/// line when it starts and one as each method's evaluations are done.
pub fn run_study(
    setup: &StudySetup<'_>,
    agents: &[Agent],
    progress: &dyn Progress,
) -> Result<Vec<ProtocolTable>, Error> {
    let jobs = jobs(setup, agents.len());
    progress.phase("evaluating", jobs.len() as u64 * setup.episodes);
    let names = |xs: Vec<String>| xs.join(", ");
    progress.message(
        Message::Status,
        &format!(
            "evaluating {} on '{}' (training map) and '{}' (test map), {}: {} runs of {} episodes",
            names(setup.methods.iter().map(|m| m.name().to_string()).collect()),
            setup.train_map.name,
            setup.test_map.name,
            names(setup.protocols.iter().map(|p| p.to_string()).collect()),
            jobs.len(),
            setup.episodes
        ),
    );
    // Runs left per method, for one line as each method finishes.
    let left: std::sync::Mutex<BTreeMap<Method, usize>> = std::sync::Mutex::new(BTreeMap::new());
    for job in &jobs {
        *left.lock().expect("progress counts").entry(job.1).or_default() += 1;
    }
    let maps = [setup.train_map, setup.test_map];
    let aggregates = jobs
        .par_iter()
        .map(|&(agent, method, protocol, map)| {
            let results = run_agent_episodes(
                protocol,
                maps[map],
                &agents[agent].bundle,
                setup.params,
                method,
                setup.episodes,
                setup.seed,
                progress,
            )?;
            let mut left = left.lock().expect("progress counts");
            let n = left.entry(method).or_default();
            *n = n.saturating_sub(1);
            if *n == 0 {
                progress.message(Message::Status, &format!("evaluated {method}"));
            }
            Ok(((agent, method, protocol, map), Aggregate::of(&results)))
        })
        .collect::<Result<BTreeMap<Job, Aggregate>, Error>>()?;
    progress.finish();
    Ok(setup
        .protocols
        .iter()
        .map(|&protocol| table(setup, agents, protocol, &aggregates))
        .collect())
}

/// The table of `protocol` from the evaluations.
fn table(
    setup: &StudySetup<'_>,
    agents: &[Agent],
    protocol: Protocol,
    aggregates: &BTreeMap<Job, Aggregate>,
) -> ProtocolTable {
    let methods: Vec<MethodSummary> = setup
        .methods
        .iter()
        .map(|&method| {
            let eff = protocol.effective(method, setup.params);
            let rows: Vec<MethodRow> = agents
                .iter()
                .enumerate()
                .map(|(i, a)| {
                    let agg = |map| aggregates[&(i, method, eff, map)].clone();
                    method_row(method, a.train_seed, agg(0), agg(1))
                })
                .collect();
            summarize(setup, agents, method, protocol, rows)
        })
        .collect();
    ProtocolTable {
        protocol,
        meaning: protocol.meaning().into(),
        scaled_inference_relative_to_bayes_rl: relative_inference(&methods),
        methods,
    }
}

/// Summarizes one method's per-agent rows.
fn summarize(
    setup: &StudySetup<'_>,
    agents: &[Agent],
    method: Method,
    protocol: Protocol,
    rows: Vec<MethodRow>,
) -> MethodSummary {
    let stat = |f: fn(&MethodRow) -> f64| Stat::of(&rows.iter().map(f).collect::<Vec<_>>());
    MethodSummary {
        method: method.name().into(),
        protocol,
        computed_under: protocol.effective(method, setup.params),
        learns_across_episodes: method.learns_across_episodes(setup.params),
        seed: setup.seed,
        train_seeds: agents.iter().map(|a| a.train_seed).collect(),
        train_episodes: agents.first().and_then(|a| a.train_episodes),
        episodes: setup.episodes,
        reward: RewardPair::of(setup.train_map, setup.test_map),
        train_reward: stat(METRICS[0].1),
        test_reward: stat(METRICS[1].1),
        success_rate: stat(METRICS[2].1),
        collision_rate: stat(METRICS[3].1),
        inference_rate: stat(METRICS[4].1),
        reasoning_us_per_tick: stat(METRICS[5].1),
        red_light_rate: stat(METRICS[6].1),
        worst_seed: worst_seed(&rows),
        per_seed: rows,
    }
}

/// The row with the lowest test success (ties: lowest test reward, then the first;
/// [`crate::stats::worst_of`]).
pub fn worst_seed(rows: &[MethodRow]) -> WorstSeed {
    let i = crate::stats::worst_of(rows.iter().map(|r| (r.success_rate, r.test_reward)))
        .expect("a study has at least one agent");
    let worst = &rows[i];
    WorstSeed {
        train_seed: worst.train_seed,
        success_rate: worst.success_rate,
        test_reward: worst.test_reward,
    }
}

/// Scaled's test inference rate over Bayesian RL's, agent by agent, summarized.
fn relative_inference(methods: &[MethodSummary]) -> Option<Stat> {
    let rows = |name: &str| methods.iter().find(|m| m.method == name).map(|m| &m.per_seed);
    let (scaled, bayes) = (rows("scaled")?, rows("bayes-rl")?);
    let ratios: Vec<f64> = scaled
        .iter()
        .zip(bayes)
        .filter(|(_, b)| b.inference_rate > 0.0)
        .map(|(s, b)| s.inference_rate / b.inference_rate)
        .collect();
    (!ratios.is_empty()).then(|| Stat::of(&ratios))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(seed: u64, success: f64, reward: f64) -> MethodRow {
        let test = Aggregate {
            success_rate: success,
            mean_reward: reward,
            ..Aggregate::default()
        };
        method_row(Method::Scaled, Some(seed), Aggregate::default(), test)
    }

    #[test]
    fn the_worst_seed_has_the_lowest_success_then_reward() {
        let rows = [
            row(1, 0.9, 10.0),
            row(2, 0.5, 30.0),
            row(3, 0.5, 20.0),
            row(4, 0.5, 20.0),
        ];
        let w = worst_seed(&rows);
        assert_eq!((w.train_seed, w.success_rate, w.test_reward), (Some(3), 0.5, 20.0));
    }

    #[test]
    fn non_learners_are_evaluated_once_for_both_protocols() {
        let map = unforeseen_sim::Map::default();
        let params = ScaledParams::default();
        let setup = StudySetup {
            train_map: &map,
            test_map: &map,
            params: &params,
            methods: &[Method::QLearning, Method::Scaled],
            protocols: &Protocol::ALL,
            episodes: 1,
            seed: 0,
        };
        let jobs = jobs(&setup, 2);
        // Per agent: q-learning zero-shot on 2 maps, scaled zero-shot and continual on 2 maps.
        assert_eq!(jobs.len(), 2 * (2 + 4));
        assert!(
            !jobs
                .iter()
                .any(|j| j.1 == Method::QLearning && j.2 == Protocol::Continual)
        );
    }
}
