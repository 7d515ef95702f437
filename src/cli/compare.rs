//! `unforeseen compare`: the paper's table (§VI, Fig. 8) beside the paper's values, one
//! table per protocol (zero-shot first, then continual), over one agent or over several
//! independently trained agents (`--train-seeds`).

use clap::Args;
use std::path::{Path, PathBuf};

use super::train_seeds::TrainSeedArgs;
use super::{AgentArgs, warn_replacing};
use unforeseen_harness::episodes::methods::{Method, PaperFigures};
use unforeseen_harness::episodes::protocol::Protocol;
use unforeseen_harness::episodes::protocol::ProtocolChoice;
use unforeseen_harness::maps;
use unforeseen_harness::reports::figures::{BarPanel, BarRow, bar_key, grouped_bars};
use unforeseen_harness::reports::files::{Csv, num, write_json};
use unforeseen_harness::reports::tables::{self, seed_text};
use unforeseen_harness::runs::compare::{CompareReport, METRICS, ProtocolTable, StudySetup, run_study};
use unforeseen_harness::training::seed_agents::Agent;
use unforeseen_harness::training::{DEFAULT_TRAIN_EPISODES, DEFAULT_TRAIN_MAP};

/// Arguments of `compare`.
#[derive(Debug, Clone, Args)]
pub struct CompareArgs {
    /// Training map (file or embedded name).
    #[arg(long, default_value = DEFAULT_TRAIN_MAP)]
    pub train_map: String,
    /// Test map with the unforeseen scenario (file or embedded name).
    #[arg(long, default_value = "jaywalk")]
    pub test_map: String,
    /// Training episodes when no --agent is given.
    #[arg(long, default_value_t = DEFAULT_TRAIN_EPISODES, value_parser = super::episodes)]
    pub train_episodes: u64,
    /// Evaluation episodes per method, map and agent.
    #[arg(long, default_value_t = 100, value_parser = super::episodes)]
    pub episodes: u64,
    /// Also run the ablations (bayes-rl-factored, scaled-always, scaled-no-learning).
    #[arg(long)]
    pub ablations: bool,
    /// Evaluation protocol: zero-shot (every test episode starts from the trained agent,
    /// the paper's table), continual (learning carries over between test episodes, in
    /// order) or both (zero-shot table first).
    #[arg(long, default_value = "both", value_parser = super::protocol_choice_parser())]
    pub protocol: ProtocolChoice,
    /// Output folder for compare.json, compare.csv, compare_seeds.csv and compare.svg
    /// (files from an earlier run there are replaced, with a warning).
    #[arg(long, value_name = "DIR", default_value = "out/compare")]
    pub out: PathBuf,
    /// Training seeds and the agent cache.
    #[command(flatten)]
    pub seeds: TrainSeedArgs,
    /// Trained agent, parameter overrides, seed and progress.
    #[command(flatten)]
    pub agent: AgentArgs,
}

impl Default for CompareArgs {
    fn default() -> Self {
        Self {
            train_map: DEFAULT_TRAIN_MAP.into(),
            test_map: "jaywalk".into(),
            train_episodes: DEFAULT_TRAIN_EPISODES,
            episodes: 100,
            ablations: false,
            protocol: ProtocolChoice::Both,
            out: PathBuf::from("out/compare"),
            seeds: TrainSeedArgs {
                train_seeds: None,
                cache: unforeseen_harness::training::seed_agents::DEFAULT_CACHE.into(),
                no_cache: false,
                timeout_as: unforeseen_harness::training::TimeoutAs::Truncation,
            },
            agent: AgentArgs {
                agent: None,
                set: Vec::new(),
                seed: 7,
                quiet: false,
            },
        }
    }
}

/// Runs `compare`.
pub fn run(args: CompareArgs) -> anyhow::Result<()> {
    args.agent.check_out_dir(
        &args.out,
        &["compare.json", "compare.csv", "compare_seeds.csv", "compare.svg"],
        &[&args.train_map, &args.test_map],
        None,
    )?;
    let train_map = maps::load(&args.train_map)?;
    let test_map = maps::load(&args.test_map)?;
    let params = args.agent.params()?;
    let agents = match &args.seeds.train_seeds {
        Some(seeds) => args
            .seeds
            .train(&seeds.0, &args.train_map, args.train_episodes, args.agent.quiet)?,
        None => vec![Agent::from_bundle(
            args.agent.bundle_trained_on(&args.train_map, args.train_episodes)?,
        )],
    };
    let mut methods: Vec<Method> = Method::PAPER.to_vec();
    if args.ablations {
        methods.extend(Method::ABLATIONS);
    }
    let protocols = args.protocol.protocols();
    let setup = StudySetup {
        train_map: &train_map,
        test_map: &test_map,
        params: &params,
        methods: &methods,
        protocols: &protocols,
        episodes: args.episodes,
        seed: args.agent.seed,
    };
    let tables = run_study(&setup, &agents, &super::progress::Bars::new(args.agent.quiet))?;
    let agent_cache = (args.seeds.train_seeds.is_some())
        .then(|| args.seeds.cache_dir().map(|p| p.display().to_string()))
        .flatten();
    let agent_file = args.agent.agent.as_ref().map(|p| p.display().to_string());
    let report = CompareReport::new(&setup, &agents, tables, agent_file, agent_cache)?;
    outln!("{}", tables::compare(&report));
    let dir = &args.out;
    let files = ["compare.json", "compare.csv", "compare_seeds.csv", "compare.svg"];
    warn_replacing(dir, &files);
    super::progress::phase(args.agent.quiet, format_args!("writing {}", dir.display()));
    // All four or none: a failed write (a full disk) leaves the previous run's set.
    unforeseen_harness::reports::files::all_or_none(|| -> anyhow::Result<()> {
        write_json(&dir.join("compare.json"), &report)?;
        let maps = (report.train_map.as_str(), report.test_map.as_str());
        summary_csv(&report.tables, maps).write(&dir.join("compare.csv"))?;
        seeds_csv(&report.tables, maps).write(&dir.join("compare_seeds.csv"))?;
        plot(&dir.join("compare.svg"), &report.tables)?;
        Ok(())
    })?;
    outln!(
        "wrote {}/compare.json, compare.csv, compare_seeds.csv, compare.svg",
        dir.display()
    );
    Ok(())
}

/// Formats an optional number for CSV (empty when absent).
fn opt(x: Option<f64>, digits: usize) -> String {
    x.map(|x| num(x, digits)).unwrap_or_default()
}

/// Training seeds as one CSV cell, space-separated.
fn seeds_cell(seeds: &[Option<u64>]) -> String {
    let s: Vec<String> = seeds.iter().map(|&s| seed_text(s)).collect();
    s.join(" ")
}

/// `compare.csv`: one row per (protocol, method), every metric as mean, 95% interval,
/// min and max over agents, and the worst seed.
fn summary_csv(tables: &[ProtocolTable], (train_map, test_map): (&str, &str)) -> Csv {
    let mut header: Vec<String> = [
        "protocol",
        "method",
        "computed_under",
        "agents",
        "train_seeds",
        "train_episodes",
        "episodes",
        "seed",
        "train_map",
        "test_map",
    ]
    .map(String::from)
    .to_vec();
    for (name, _) in METRICS {
        for suffix in ["", "_ci95_low", "_ci95_high", "_min", "_max"] {
            header.push(format!("{name}{suffix}"));
        }
    }
    header.extend(["worst_seed", "worst_seed_success_rate", "worst_seed_test_reward"].map(String::from));
    let mut csv = Csv::new(&header.iter().map(String::as_str).collect::<Vec<_>>());
    for m in tables.iter().flat_map(|t| &t.methods) {
        let mut row = vec![
            m.protocol.to_string(),
            m.method.clone(),
            m.computed_under.to_string(),
            m.train_seeds.len().to_string(),
            seeds_cell(&m.train_seeds),
            m.train_episodes.map(|e| e.to_string()).unwrap_or_default(),
            m.episodes.to_string(),
            m.seed.to_string(),
            train_map.to_string(),
            test_map.to_string(),
        ];
        for (name, _) in METRICS {
            let s = m.stat(name);
            row.extend([
                num(s.mean, 4),
                opt(s.ci95_low, 4),
                opt(s.ci95_high, 4),
                num(s.min, 4),
                num(s.max, 4),
            ]);
        }
        row.extend([
            m.worst_seed.train_seed.map(|s| s.to_string()).unwrap_or_default(),
            num(m.worst_seed.success_rate, 4),
            num(m.worst_seed.test_reward, 4),
        ]);
        csv.row(row);
    }
    csv
}

/// `compare_seeds.csv`: one row per (protocol, method, training seed).
fn seeds_csv(tables: &[ProtocolTable], (train_map, test_map): (&str, &str)) -> Csv {
    let mut header = vec![
        "protocol",
        "method",
        "computed_under",
        "train_seed",
        "train_map",
        "test_map",
    ];
    header.extend(METRICS.iter().map(|(name, _)| *name));
    let mut csv = Csv::new(&header);
    for m in tables.iter().flat_map(|t| &t.methods) {
        for r in &m.per_seed {
            let mut row = vec![
                m.protocol.to_string(),
                m.method.clone(),
                m.computed_under.to_string(),
                r.train_seed.map(|s| s.to_string()).unwrap_or_default(),
                train_map.to_string(),
                test_map.to_string(),
            ];
            row.extend(METRICS.iter().map(|(_, f)| num(f(r), 4)));
            csv.row(row);
        }
    }
    csv
}

/// `compare.svg`: one row of bar panels per protocol (train reward, test reward, success,
/// inference rate), ours with 95% interval whiskers over agents beside the paper's.
fn plot(path: &Path, tables: &[ProtocolTable]) -> anyhow::Result<()> {
    type PaperOf = fn(&PaperFigures) -> f64;
    let panels: [(&str, &str, PaperOf); 4] = [
        ("train reward (training map)", "train_reward", |p| p.train_reward),
        ("test reward (test map)", "test_reward", |p| p.test_reward),
        ("success rate (test map)", "success_rate", |p| p.success_rate),
        ("inference rate (test map)", "inference_rate", |p| p.inference_rate),
    ];
    let labels: Vec<Vec<String>> = tables
        .iter()
        .map(|t| t.methods.iter().map(|m| m.method.clone()).collect())
        .collect();
    let rows: Vec<BarRow<'_>> = tables
        .iter()
        .zip(&labels)
        .map(|(t, labels)| {
            let n = t.methods.first().map_or(0, |m| m.train_seeds.len());
            BarRow {
                title: format!("{} protocol: {}", t.protocol, t.protocol.meaning()),
                key: bar_key(n, t.protocol == Protocol::ZeroShot),
                panels: panels
                    .iter()
                    .map(|&(title, metric, paper)| BarPanel {
                        title,
                        labels,
                        ours: t.methods.iter().map(|m| m.stat(metric).mean).collect(),
                        interval: t
                            .methods
                            .iter()
                            .map(|m| m.stat(metric).ci95_low.zip(m.stat(metric).ci95_high))
                            .collect(),
                        paper: t
                            .methods
                            .iter()
                            .map(|m| {
                                let p = m
                                    .method
                                    .parse::<Method>()
                                    .ok()
                                    .and_then(Method::paper)
                                    .filter(|_| t.protocol == Protocol::ZeroShot);
                                p.as_ref().map(paper)
                            })
                            .collect(),
                    })
                    .collect(),
            }
        })
        .collect();
    Ok(grouped_bars(path, &rows)?)
}
