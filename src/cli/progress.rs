//! Progress on the command line: bars drawn on a terminal; elsewhere (CI logs, pipes,
//! files) one plain line on stderr per phase of a run (training, evaluating each method,
//! writing), with the seconds since the program started, so a long run is never silent.
//! `--quiet` turns both off. [`Bars`] is the library's [`Progress`] drawn this way.

use indicatif::{ProgressBar, ProgressStyle};
use std::fmt::Display;
use std::io::IsTerminal;
use std::sync::{Mutex, OnceLock};
use std::time::Instant;

use unforeseen_harness::progress::{Message, Progress};
use unforeseen_harness::runs::batch::AgentChoice;

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
        errln!("[{t:>6.1} s] {what}");
    }
}

/// The phase line of a run that trains its agents first: `count` agents, one per training
/// seed (`per_seed`; loaded from the agent cache where it has them), or the one agent
/// trained with the run `seed`, for `episodes` episodes on the map named `map`.
pub fn training(quiet: bool, per_seed: bool, count: usize, episodes: u64, map: &str, seed: u64) {
    if per_seed {
        phase(
            quiet,
            format_args!(
                "training {count} agent(s) for {episodes} episodes on '{map}' (or loading them from the cache), one line each"
            ),
        );
    } else {
        phase(
            quiet,
            format_args!("training {episodes} episodes on '{map}' (seed {seed})"),
        );
    }
}

/// The phase line of a job that runs one agent ([`AgentChoice::one`]), when that agent
/// is trained here with the run `seed`.
pub fn training_one(quiet: bool, agent: &AgentChoice, seed: u64) {
    if let AgentChoice::Trained { map, config, .. } = agent {
        training(quiet, false, 1, config.episodes, &map.name, seed);
    }
}

/// A progress bar over `len` items labelled `what`, counting `unit` (e.g. `episodes`;
/// empty for none); hidden when stderr is not a terminal or when `quiet` is set (see
/// [`phase`] for what is printed then).
fn bar(len: u64, what: &str, unit: &str, quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(len);
    let unit = if unit.is_empty() {
        String::new()
    } else {
        format!(" {unit}")
    };
    let template = format!("{{prefix:>18}} [{{bar:40}}] {{pos}}/{{len}}{unit} {{per_sec}} eta {{eta}}");
    let style = ProgressStyle::with_template(&template)
        .map(|s| s.progress_chars("=> "))
        .unwrap_or_else(|_| ProgressStyle::default_bar());
    bar.set_style(style);
    bar.set_prefix(what.to_string());
    bar
}

/// The library's [`Progress`] on the command line: each phase a bar on a terminal
/// (several threads advance the same bar), nothing otherwise; status lines as phase
/// lines ([`phase`]); finished items above the bar on a terminal, as plain lines
/// otherwise; warnings always, even with `--quiet`.
#[derive(Debug)]
pub struct Bars {
    quiet: bool,
    unit: &'static str,
    bar: Mutex<ProgressBar>,
}

impl Bars {
    /// Bars unless `quiet`.
    pub fn new(quiet: bool) -> Self {
        Self {
            quiet,
            unit: "",
            bar: Mutex::new(ProgressBar::hidden()),
        }
    }

    /// Bars whose counts are in `unit` (e.g. `episodes`).
    pub fn counting(quiet: bool, unit: &'static str) -> Self {
        Self {
            unit,
            ..Self::new(quiet)
        }
    }

    fn current(&self) -> ProgressBar {
        self.bar.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }
}

impl Progress for Bars {
    fn phase(&self, name: &str, total: u64) {
        let next = bar(total, name, self.unit, self.quiet);
        let old = std::mem::replace(&mut *self.bar.lock().unwrap_or_else(|e| e.into_inner()), next);
        old.finish_and_clear();
    }

    fn advance(&self, n: u64) {
        self.current().inc(n);
    }

    fn finish(&self) {
        self.current().finish_and_clear();
    }

    fn message(&self, kind: Message, line: &str) {
        let bar = self.current();
        match kind {
            Message::Status => phase(self.quiet, line),
            Message::Item if self.quiet => {}
            Message::Item | Message::Warning if bar.is_hidden() => errln!("{line}"),
            Message::Item => bar.println(line),
            Message::Warning => bar.suspend(|| errln!("{line}")),
        }
    }
}
