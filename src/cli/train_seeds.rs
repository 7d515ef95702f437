//! `--train-seeds`, `--cache` and `--no-cache`: the options of training-seed studies
//! shared by `compare` and `batch`, and how they turn into trained agents.

use clap::Args;
use std::path::{Path, PathBuf};

use super::progress::{self, Bars};
use unforeseen_harness::training::{Agent, DEFAULT_CACHE, TrainSeeds, train_agents};
use unforeseen_harness::training::{TimeoutAs, TrainConfig};

/// Options of a training-seed study.
#[derive(Debug, Clone, Args)]
pub struct TrainSeedArgs {
    /// Train one agent per seed and report every figure as a mean with a 95% interval
    /// over them (plus min, max and the worst seed): `1..10` (inclusive), `1,3,5` or
    /// `1..3,7`. Agents train in parallel and are cached (see --cache). Evaluation
    /// episodes still derive from --seed, the same for every agent. Without it, one
    /// agent: --agent FILE, or trained from --seed.
    #[arg(long, value_name = "SEEDS", conflicts_with = "agent")]
    pub train_seeds: Option<TrainSeeds>,
    /// Folder of the agent cache of --train-seeds: one file per agent, named by a hash
    /// of everything that determines it (training map, episodes, seed, training
    /// configuration, version and training code).
    #[arg(long, value_name = "DIR", default_value = DEFAULT_CACHE)]
    pub cache: PathBuf,
    /// Do not read or write the agent cache (train every agent afresh).
    #[arg(long)]
    pub no_cache: bool,
    /// What a training episode's time-out is to Q-learning and Bayesian RL: `truncation`
    /// (they bootstrap through it) or `termination` (an absorbing end, the ablation).
    #[arg(long, value_name = "KIND", default_value = "truncation", value_parser = super::timeout_as)]
    pub timeout_as: TimeoutAs,
}

impl TrainSeedArgs {
    /// The cache folder in use, if any.
    pub fn cache_dir(&self) -> Option<&Path> {
        (!self.no_cache).then_some(self.cache.as_path())
    }

    /// One agent per seed of `seeds`, trained on `train_map` for `episodes` episodes in
    /// parallel (or loaded from the cache).
    pub fn train(&self, seeds: &[u64], train_map: &str, episodes: u64, quiet: bool) -> anyhow::Result<Vec<Agent>> {
        let map = unforeseen_harness::maps::load(train_map)?;
        progress::phase(
            quiet,
            format_args!(
                "training {} agent(s) for {episodes} episodes on '{}' (or loading them from the cache), one line each",
                seeds.len(),
                map.name
            ),
        );
        let bars = Bars::counting(quiet, "episodes");
        Ok(train_agents(
            &map,
            seeds,
            &TrainConfig {
                timeout_as: self.timeout_as,
                ..TrainConfig::new(episodes, 0)
            },
            self.cache_dir(),
            &bars,
        )?)
    }
}
