//! The `unforeseen` command line; see `unforeseen --help`.

use clap::Parser;
use unforeseen::cli::{Cli, exit_code, run};

fn main() {
    // Rust ignores SIGPIPE, so printing into a closed pipe (`unforeseen check-map maps/ | head`)
    // fails and `println!` panics; end quietly instead, as command-line tools do.
    let default_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let payload = info.payload();
        let message = (payload.downcast_ref::<String>().map(String::as_str))
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or_default();
        if message.contains("Broken pipe") {
            std::process::exit(0);
        }
        default_hook(info);
    }));
    unforeseen::cli::progress::start_clock();
    let cli = Cli::parse();
    if let Err(err) = run(cli) {
        eprintln!("error: {err:#}");
        std::process::exit(exit_code(&*err));
    }
}
