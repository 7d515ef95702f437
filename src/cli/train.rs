//! `unforeseen train`: learn on a map and write an agent file.

use clap::Args;
use std::path::PathBuf;

use super::progress::{self, Bars};
use unforeseen_harness::maps;
use unforeseen_harness::progress::Progress;
use unforeseen_harness::training::{
    DEFAULT_TRAIN_EPISODES, DEFAULT_TRAIN_MAP, TimeoutAs, TrainConfig, train_with_progress,
};

/// Arguments of `train`.
#[derive(Debug, Clone, Args)]
pub struct TrainArgs {
    /// Training map (file or embedded name).
    #[arg(long, default_value = DEFAULT_TRAIN_MAP)]
    pub map: String,
    /// Training episodes.
    #[arg(long, default_value_t = DEFAULT_TRAIN_EPISODES, value_parser = super::episodes)]
    pub episodes: u64,
    /// Run seed.
    #[arg(long, default_value_t = unforeseen_env::seeds::DEFAULT_SEED)]
    pub seed: u64,
    /// Agent file to write (RON).
    #[arg(long, value_name = "FILE", default_value = "agent.ron")]
    pub out: PathBuf,
    /// What a training episode's time-out is to Q-learning and Bayesian RL: `truncation`
    /// (they bootstrap through it) or `termination` (an absorbing end, the ablation).
    #[arg(long, value_name = "KIND", default_value = "truncation", value_parser = super::timeout_as)]
    pub timeout_as: TimeoutAs,
    /// No progress bar.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Runs `train`.
pub fn run(args: TrainArgs) -> anyhow::Result<()> {
    super::outputs::file(
        "--out",
        &args.out,
        unforeseen_harness::runs::outputs::Outputs::new().input("--map", &args.map),
    )?;
    let map = maps::load(&args.map)?;
    let cfg = TrainConfig {
        timeout_as: args.timeout_as,
        ..TrainConfig::new(args.episodes, args.seed)
    };
    let started = std::time::Instant::now();
    progress::phase(
        args.quiet,
        format_args!(
            "training {} episodes on '{}' (seed {})",
            args.episodes, map.name, args.seed
        ),
    );
    let bars = Bars::new(args.quiet);
    bars.phase("training", args.episodes);
    let trained = train_with_progress(&map, &cfg, &bars);
    bars.finish();
    let (bundle, log) = trained?;
    let tail = &log.returns[log.returns.len().saturating_sub(100)..];
    let mean = if tail.is_empty() {
        0.0
    } else {
        tail.iter().sum::<f64>() / tail.len() as f64
    };
    progress::phase(args.quiet, format_args!("writing {}", args.out.display()));
    super::warn_replacing_file(&args.out);
    unforeseen_harness::training::agent_file::save(&args.out, &bundle)?;
    outln!(
        "trained on '{}' for {} episodes in {:.1} s (mean return of the last {} with exploration: {mean:.2}); wrote {}",
        map.name,
        args.episodes,
        started.elapsed().as_secs_f64(),
        tail.len(),
        args.out.display()
    );
    Ok(())
}
