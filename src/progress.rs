//! Progress: bars drawn on a terminal; elsewhere (CI logs, pipes, files) one plain line
//! on stderr per phase of a run (training, evaluating each method, writing), with the
//! seconds since the program started, so a long run is never silent. `--quiet` turns
//! both off.

use indicatif::{ProgressBar, ProgressStyle};
use std::fmt::Display;
use std::io::IsTerminal;
use std::sync::OnceLock;
use std::time::Instant;

/// When the clock of the phase lines started.
static START: OnceLock<Instant> = OnceLock::new();

/// Starts the clock of the phase lines (the first phase line starts it otherwise).
pub fn start_clock() {
    START.get_or_init(Instant::now);
}

/// Whether phase lines are printed: not quiet, and stderr is not a terminal (where the
/// bars show progress instead).
pub fn phase_lines(quiet: bool) -> bool {
    !quiet && !std::io::stderr().is_terminal()
}

/// Prints one phase line on stderr, `[   9.4 s] training 6000 episodes on 'intersection'`,
/// when stderr is not a terminal and `quiet` is not set.
pub fn phase(quiet: bool, what: impl Display) {
    if phase_lines(quiet) {
        let t = START.get_or_init(Instant::now).elapsed().as_secs_f64();
        eprintln!("[{t:>6.1} s] {what}");
    }
}

/// A progress bar over `len` items labelled `what`; hidden when stderr is not a
/// terminal or when `quiet` is set (see [`phase`] for what is printed then).
pub fn bar(len: u64, what: &str, quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    let style = ProgressStyle::with_template("{prefix:>18} [{bar:40}] {pos}/{len} {per_sec} eta {eta}")
        .map(|s| s.progress_chars("=> "))
        .unwrap_or_else(|_| ProgressStyle::default_bar());
    bar.set_style(style);
    bar.set_prefix(what.to_string());
    bar
}
