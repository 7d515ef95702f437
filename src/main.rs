//! The `unforeseen` command line; see `unforeseen --help`.

use clap::Parser;
use std::io::Write;
use unforeseen::cli::{Cli, error_message, exit_code, run};

fn main() {
    // Rust ignores SIGPIPE, so writing into a closed pipe (`unforeseen ... | head`) fails
    // with EPIPE. The command line's prints ignore that (`outln!`/`errln!` in `cli`): a
    // closed report stream never stops the work nor changes the exit code it earned.
    unforeseen::cli::progress::start_clock();
    unforeseen::cli::signals::install();
    let cli = Cli::parse();
    let code = match run(cli) {
        // What was printed is part of the result: a full disk under `> file` fails the run.
        Ok(()) => match (std::io::stdout().flush(), unforeseen::cli::stream_failed()) {
            (Err(e), _) if e.kind() != std::io::ErrorKind::BrokenPipe => {
                let _ = writeln!(std::io::stderr(), "error: cannot write stdout: {e}");
                1
            }
            (_, Some(why)) => {
                let _ = writeln!(std::io::stderr(), "error: {why}");
                1
            }
            _ => 0,
        },
        Err(err) => {
            let _ = writeln!(std::io::stderr(), "error: {}", error_message(&err));
            exit_code(&*err)
        }
    };
    std::process::exit(code);
}
