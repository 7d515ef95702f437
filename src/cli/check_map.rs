//! `unforeseen check-map`: validate map files and summarize them.

use clap::Args;
use std::path::PathBuf;

use super::BadInput;
use unforeseen_sim::Map;

/// Arguments of `check-map`.
#[derive(Debug, Clone, Args)]
pub struct CheckMapArgs {
    /// Map files to check.
    #[arg(required = true, value_name = "FILE")]
    pub files: Vec<PathBuf>,
}

/// Runs `check-map`: every file is checked; the command fails if any is bad.
pub fn run(args: CheckMapArgs) -> anyhow::Result<()> {
    let mut bad = 0;
    for file in &args.files {
        match Map::load(file) {
            Ok(map) => println!("{}: ok\n{}\n", file.display(), map.summary()),
            Err(e) => {
                eprintln!("{e}\n");
                bad += 1;
            }
        }
    }
    if bad > 0 {
        return Err(BadInput(format!("{bad} of {} map file(s) failed the check", args.files.len())).into());
    }
    Ok(())
}
