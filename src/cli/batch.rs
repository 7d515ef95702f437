//! `unforeseen batch`: run scenario suites headless, with expectations, sweeps and shards.

use clap::Args;
use std::path::PathBuf;

use crate::batch::{BatchConfig, ResultLine, Scenario, Shard, load_scenarios, run, sweep};
use crate::methods::Method;
use crate::survivability::{Witness, warnings};
use crate::training::{TrainConfig, train};

/// Arguments of `batch`.
#[derive(Debug, Clone, Args)]
pub struct BatchArgs {
    /// Map files or folders of maps (every *.ron); default: the embedded maps.
    #[arg(value_name = "MAP|DIR")]
    pub maps: Vec<PathBuf>,
    /// Episodes per (scenario, method, parameter set).
    #[arg(long, default_value_t = 100)]
    pub episodes: u64,
    /// Run seed.
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// Methods to run (repeatable); default: q-learning, bayes-rl, scaled and the
    /// scripted references brake-on-pedestrian and never-brake (so every map reports
    /// whether it is survivable and dangerous).
    #[arg(long = "method", value_enum)]
    pub methods: Vec<Method>,
    /// Worker threads (results do not depend on it).
    #[arg(long, default_value_t = default_jobs())]
    pub jobs: usize,
    /// Results file (JSON Lines), one line per unit as soon as it finishes.
    #[arg(long, value_name = "FILE", default_value = "results.jsonl")]
    pub out: PathBuf,
    /// Keep the complete lines already in --out and run only the missing units.
    #[arg(long)]
    pub resume: bool,
    /// Run only shard I of N (1-based) of the canonical unit order.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Sweep: `--set KEY=V1,V2,...` (repeatable; cross product). Keys as for `--set` elsewhere.
    #[arg(long = "set", value_name = "KEY=V1,V2")]
    pub sweep: Vec<String>,
    /// Training episodes when no --agent is given.
    #[arg(long, default_value_t = super::compare::DEFAULT_TRAIN_EPISODES)]
    pub train_episodes: u64,
    /// Agent file from `unforeseen train` (default: train on the embedded intersection map).
    #[arg(long, value_name = "FILE")]
    pub agent: Option<PathBuf>,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
}

fn default_jobs() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

/// Runs `batch`; fails (exit 1) when any expectation fails.
pub fn run_cli(args: BatchArgs) -> anyhow::Result<()> {
    let scenarios = load_scenarios(&args.maps)?;
    let methods = if args.methods.is_empty() {
        Method::PAPER.iter().chain(&Method::REFERENCE).copied().collect()
    } else {
        args.methods.clone()
    };
    let params = sweep(&args.sweep)?;
    for p in &params {
        let sets: Vec<String> = p.0.iter().map(|(k, v)| format!("{k}={v}")).collect();
        super::params::apply(Default::default(), &sets)?;
    }
    let bundle = match &args.agent {
        Some(path) => crate::agent_file::load(path)?,
        None => {
            let map = crate::maps::load("intersection")?;
            let cfg = TrainConfig {
                quiet: args.quiet,
                ..TrainConfig::new(args.train_episodes, args.seed)
            };
            train(&map, &cfg)?.0
        }
    };
    let cfg = BatchConfig {
        bundle: &bundle,
        scenarios: &scenarios,
        methods: &methods,
        params: &params,
        episodes: args.episodes,
        seed: args.seed,
        jobs: args.jobs,
        shard: args.shard,
    };
    let lines = run(&cfg, &args.out, args.resume, args.quiet)?;
    println!(
        "{:<22} {:<20} {:<24} {:>9} {:>10} {:>10} {:>10}",
        "scenario", "method", "parameters", "success", "collision", "reward", "inference"
    );
    let mut failures = Vec::new();
    for l in &lines {
        println!(
            "{:<22} {:<20} {:<24} {:>8.1}% {:>9.1}% {:>10.2} {:>9.1}%",
            l.scenario,
            l.method,
            l.param_set,
            100.0 * l.success_rate,
            100.0 * l.collision_rate,
            l.mean_reward,
            100.0 * l.inference_rate
        );
        for c in l.checks.iter().filter(|c| !c.pass) {
            failures.push(format!(
                "{} ({}): {} [{}] {} = {:.4} violates {} {}",
                l.scenario, l.source, l.method, l.param_set, c.figure, c.value, c.bound, c.limit
            ));
        }
    }
    for warning in survivability_warnings(&scenarios, &lines) {
        eprintln!("{warning}");
    }
    let checked: usize = lines.iter().map(|l| l.checks.len()).sum();
    println!(
        "wrote {} ({} lines); {} expectation(s) checked, {} failed",
        args.out.display(),
        lines.len(),
        checked,
        failures.len()
    );
    if !failures.is_empty() {
        for f in &failures {
            eprintln!("expectation failed: {f}");
        }
        anyhow::bail!("{} expectation(s) failed", failures.len());
    }
    Ok(())
}

/// The survivability warnings of `check-map`, from the brake-on-pedestrian and
/// never-brake units that ran (scripted methods ignore parameter sets, so the first
/// line of each is taken), for scenarios with pedestrian rules.
fn survivability_warnings(scenarios: &[Scenario], lines: &[ResultLine]) -> Vec<String> {
    let witness = |scenario: &str, method: Method| {
        lines
            .iter()
            .find(|l| l.scenario == scenario && l.method == method.name())
            .map(|l| Witness {
                episodes: l.episodes,
                success_rate: l.success_rate,
                collision_rate: l.collision_rate,
                timeout_rate: l.timeout_rate,
            })
    };
    scenarios
        .iter()
        .filter(|s| !s.map.pedestrians.is_empty())
        .flat_map(|s| {
            let name = &s.map.name;
            warnings(
                name,
                witness(name, Method::BrakeOnPedestrian).as_ref(),
                witness(name, Method::NeverBrake).as_ref(),
            )
            .into_iter()
            .map(move |w| format!("{}: {w}", s.source))
        })
        .collect()
}
