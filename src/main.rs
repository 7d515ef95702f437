//! The `unforeseen` command line; see `unforeseen --help`.

use clap::Parser;
use unforeseen::cli::{Cli, is_bad_input, run};

fn main() {
    let cli = Cli::parse();
    if let Err(err) = run(cli) {
        eprintln!("error: {err:#}");
        std::process::exit(if is_bad_input(&err) { 2 } else { 1 });
    }
}
