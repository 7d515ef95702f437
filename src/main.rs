//! The `unforeseen` command line; see `unforeseen --help`.

use clap::Parser;
use std::io::Write;
use unforeseen::cli::{Cli, exit_code, run};

fn main() {
    // Rust ignores SIGPIPE, so writing into a closed pipe (`unforeseen ... | head`) fails
    // with EPIPE. The command line's prints ignore that (`outln!`/`errln!` in `cli`): a
    // closed report stream never stops the work nor changes the exit code it earned.
    unforeseen::cli::progress::start_clock();
    unforeseen::cli::signals::install();
    let cli = Cli::parse();
    let code = match run(cli) {
        Ok(()) => 0,
        Err(err) => {
            let _ = writeln!(std::io::stderr(), "error: {err:#}");
            exit_code(&*err)
        }
    };
    let _ = std::io::stdout().flush();
    std::process::exit(code);
}
