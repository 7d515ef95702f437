//! `unforeseen check-map`: validate map files, summarize them, and warn when a map with
//! pedestrians is not a fair unforeseen test ([`unforeseen_harness::episodes::survivability`]).

use clap::Args;
use std::path::PathBuf;

use unforeseen_harness::episodes::survivability;
use unforeseen_harness::error::Error;

/// Arguments of `check-map`.
#[derive(Debug, Clone, Args)]
pub struct CheckMapArgs {
    /// Map files to check.
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
    /// Episodes of each scripted witness (brake-on-pedestrian, never-brake) on every
    /// map with pedestrian rules; warns when the map is not survivable or not
    /// dangerous. 0 disables the check.
    #[arg(long, value_name = "N", default_value_t = survivability::DEFAULT_EPISODES, value_parser = super::episodes_or_none)]
    pub survivability_episodes: u64,
    /// Run seed of the witnesses' episodes (the same episodes as `eval`/`batch --seed`).
    #[arg(long, default_value_t = unforeseen_env::seeds::DEFAULT_SEED)]
    pub seed: u64,
}

/// Runs `check-map`: every file is checked; the command fails if any is bad. The
/// survivability warnings go to stderr and do not change the exit code.
pub fn run(args: CheckMapArgs) -> anyhow::Result<()> {
    let mut bad = 0;
    for file in &args.files {
        match unforeseen_harness::maps::load_file(file) {
            Ok(map) => {
                let disc = unforeseen_discretizer::Discretizer::new(&map)?;
                let edges: Vec<String> = disc.distance_edges().iter().map(|e| format!("{e:.3}")).collect();
                outln!(
                    "{}: ok\n{}distance bins: edges [{}] m to the goal\n",
                    file.display(),
                    map.summary(),
                    edges.join(", ")
                );
                for warning in survivability::check(&map, args.survivability_episodes, args.seed)? {
                    errln!("{}: {warning}\n", file.display());
                }
            }
            Err(e) => {
                errln!("{e}\n");
                bad += 1;
            }
        }
    }
    if bad > 0 {
        return Err(Error::MapsFailed {
            failed: bad,
            total: args.files.len(),
        }
        .into());
    }
    Ok(())
}
