//! `unforeseen compare`: the paper's table (§VI, Fig. 8) beside the paper's values.

use clap::Args;
use std::path::PathBuf;

use super::{AgentArgs, out_dir};
use crate::experiments::{MethodRow, compare_method};
use crate::maps;
use crate::methods::Method;
use crate::plots::{BarPanel, grouped_bars};
use crate::report::{Csv, num, write_json};

/// Training episodes by default (the paper's 6000).
pub const DEFAULT_TRAIN_EPISODES: u64 = 6000;

/// Arguments of `compare`.
#[derive(Debug, Clone, Args)]
pub struct CompareArgs {
    /// Training map (file or embedded name).
    #[arg(long, default_value = "intersection")]
    pub train_map: String,
    /// Test map with the unforeseen scenario (file or embedded name).
    #[arg(long, default_value = "jaywalk")]
    pub test_map: String,
    /// Training episodes when no --agent is given.
    #[arg(long, default_value_t = DEFAULT_TRAIN_EPISODES)]
    pub train_episodes: u64,
    /// Evaluation episodes per method and map.
    #[arg(long, default_value_t = 100)]
    pub episodes: u64,
    /// Also run the ablations (bayes-rl-factored, scaled-always, scaled-no-learning).
    #[arg(long)]
    pub ablations: bool,
    /// Output folder for compare.json, compare.csv and compare.svg.
    #[arg(long, value_name = "DIR")]
    pub out: Option<PathBuf>,
    /// Trained agent, parameter overrides, seed and progress.
    #[command(flatten)]
    pub agent: AgentArgs,
}

impl Default for CompareArgs {
    fn default() -> Self {
        Self {
            train_map: "intersection".into(),
            test_map: "jaywalk".into(),
            train_episodes: DEFAULT_TRAIN_EPISODES,
            episodes: 100,
            ablations: false,
            out: None,
            agent: AgentArgs {
                agent: None,
                set: Vec::new(),
                seed: 7,
                quiet: false,
            },
        }
    }
}

/// The whole `compare.json`.
#[derive(Debug, serde::Serialize)]
pub struct CompareReport {
    /// One row per method (the paper's three first, then any ablations).
    pub methods: Vec<MethodRow>,
    /// The paper's values for the same columns (§VI).
    pub paper: Vec<serde_json::Value>,
    /// Scaled's inference rate divided by Bayesian RL's (paper: 0.633).
    pub scaled_inference_relative_to_bayes_rl: Option<f64>,
    /// Training map name.
    pub train_map: String,
    /// Test map name.
    pub test_map: String,
    /// Run seed.
    pub seed: u64,
    /// Training episodes (from the agent file's metadata when --agent was given).
    pub train_episodes: String,
    /// Evaluation episodes per method and map.
    pub episodes: u64,
    /// How actions are chosen from the policy in evaluation.
    pub action_selection: String,
    /// The scaled agent's parameters.
    pub scaled_params: serde_json::Value,
}

/// Runs `compare`.
pub fn run(args: CompareArgs) -> anyhow::Result<()> {
    let train_map = maps::load(&args.train_map)?;
    let test_map = maps::load(&args.test_map)?;
    let params = args.agent.params()?;
    let bundle = args.agent.bundle_trained_on(&args.train_map, args.train_episodes)?;
    let mut methods: Vec<Method> = Method::PAPER.to_vec();
    if args.ablations {
        methods.extend(Method::ABLATIONS);
    }
    let rows = methods
        .iter()
        .map(|&m| {
            compare_method(
                &bundle,
                &params,
                m,
                &train_map,
                &test_map,
                args.episodes,
                args.agent.seed,
                args.agent.quiet,
            )
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let inference = |name: &str| rows.iter().find(|r| r.method == name).map(|r| r.inference_rate);
    let relative = match (inference("scaled"), inference("bayes-rl")) {
        (Some(s), Some(b)) if b > 0.0 => Some(s / b),
        _ => None,
    };
    print_table(&rows, relative);

    let report = CompareReport {
        paper: Method::PAPER
            .iter()
            .filter_map(|m| m.paper().map(|p| serde_json::json!({"method": m.name(), "train_reward": p.train_reward, "test_reward": p.test_reward, "success_rate": p.success_rate, "inference_rate_relative_to_bayes_rl": p.inference_rate})))
            .collect(),
        scaled_inference_relative_to_bayes_rl: relative,
        train_map: train_map.name.clone(),
        test_map: test_map.name.clone(),
        seed: args.agent.seed,
        train_episodes: bundle.meta.get("episodes").cloned().unwrap_or_else(|| args.train_episodes.to_string()),
        episodes: args.episodes,
        action_selection: format!("{:?}", params.action_selection),
        scaled_params: serde_json::to_value(&params)?,
        methods: rows,
    };
    let dir = out_dir(&args.out, "out/compare");
    write_json(&dir.join("compare.json"), &report)?;
    let mut csv = Csv::new(&[
        "method",
        "train_reward",
        "test_reward",
        "success_rate",
        "collision_rate",
        "inference_rate",
        "reasoning_us_per_tick",
    ]);
    for r in &report.methods {
        csv.row(vec![
            r.method.clone(),
            num(r.train_reward, 3),
            num(r.test_reward, 3),
            num(r.success_rate, 4),
            num(r.collision_rate, 4),
            num(r.inference_rate, 4),
            num(r.reasoning_us_per_tick, 3),
        ]);
    }
    csv.write(&dir.join("compare.csv"))?;
    let labels: Vec<String> = report.methods.iter().map(|r| r.method.clone()).collect();
    let paper = |f: fn(&crate::methods::PaperFigures) -> f64| -> Vec<Option<f64>> {
        methods.iter().map(|m| m.paper().as_ref().map(f)).collect()
    };
    let col = |f: fn(&MethodRow) -> f64| report.methods.iter().map(f).collect::<Vec<_>>();
    type Metric = (
        &'static str,
        fn(&MethodRow) -> f64,
        fn(&crate::methods::PaperFigures) -> f64,
    );
    let metrics: [Metric; 4] = [
        ("train reward", |r| r.train_reward, |p| p.train_reward),
        ("test reward (unforeseen)", |r| r.test_reward, |p| p.test_reward),
        ("success rate", |r| r.success_rate, |p| p.success_rate),
        ("inference rate", |r| r.inference_rate, |p| p.inference_rate),
    ];
    let panels: Vec<BarPanel<'_>> = metrics
        .iter()
        .map(|(title, ours, theirs)| BarPanel {
            title,
            labels: &labels,
            ours: col(*ours),
            paper: paper(*theirs),
        })
        .collect();
    grouped_bars(&dir.join("compare.svg"), &panels)?;
    println!("wrote {}/compare.json, compare.csv, compare.svg", dir.display());
    Ok(())
}

fn print_table(rows: &[MethodRow], relative: Option<f64>) {
    println!(
        "{:<20} {:>14} {:>14} {:>14} {:>10} {:>16} {:>12}",
        "method", "train reward", "test reward", "success", "collisions", "inference rate", "µs/tick"
    );
    let paper_cell = |ours: String, paper: Option<String>| match paper {
        Some(p) => format!("{ours} ({p})"),
        None => ours,
    };
    for r in rows {
        let m = Method::PAPER
            .iter()
            .chain(&Method::ABLATIONS)
            .find(|m| m.name() == r.method)
            .and_then(|m| m.paper());
        println!(
            "{:<20} {:>14} {:>14} {:>14} {:>10} {:>16} {:>12}",
            r.method,
            paper_cell(num(r.train_reward, 1), m.map(|p| num(p.train_reward, 1))),
            paper_cell(num(r.test_reward, 1), m.map(|p| num(p.test_reward, 1))),
            paper_cell(
                format!("{:.0}%", 100.0 * r.success_rate),
                m.map(|p| format!("{:.0}%", 100.0 * p.success_rate))
            ),
            format!("{:.0}%", 100.0 * r.collision_rate),
            format!("{:.1}%", 100.0 * r.inference_rate),
            num(r.reasoning_us_per_tick, 2),
        );
    }
    println!("(paper's values in parentheses, §VI)");
    if let Some(rel) = relative {
        println!(
            "scaled reasons on {:.1}% of the ticks Bayesian RL does (paper: 63.3%)",
            100.0 * rel
        );
    }
}
