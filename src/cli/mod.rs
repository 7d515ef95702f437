//! The command line (clap). Each command lives in its own file; progress bars and
//! phase lines are drawn by [`progress`]. Library errors become messages here, and only
//! here is the exit code decided ([`exit_code`]): 2 for input the user can fix (maps,
//! agent files, results files, flags: [`unforeseen_harness::error::Error::is_user_input`] and the map
//! errors), 1 for any other failure.

use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_harness::limits::MAX_EPISODES;

use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::{Protocol, ProtocolChoice};
use unforeseen_harness::progress::Progress;
use unforeseen_harness::training::{DEFAULT_TRAIN_MAP, TrainConfig, train_with_progress};

/// `println!` that never panics or stops the program when stdout's reader has gone (a
/// closed pipe, `| head`): what is printed is a report of the work, and a closed report
/// stream must not change what the program does or its exit code.
/// Any other failure to write (a full disk under `> file`) is remembered
/// ([`stream_failed`]) and fails the run at its end, naming the stream.
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        $crate::cli::wrote("stdout", writeln!(std::io::stdout(), $($arg)*));
    }};
}

/// `eprintln!` that never panics when stderr's reader has gone (see `outln!`).
macro_rules! errln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        $crate::cli::wrote("stderr", writeln!(std::io::stderr(), $($arg)*));
    }};
}

/// The first failure to write stdout or stderr other than a closed pipe.
static STREAM_FAILED: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// Records the outcome of a write to `stream` (`stdout`, `stderr`): a closed reader
/// (EPIPE) is ignored, any other failure remembered for [`stream_failed`].
pub fn wrote(stream: &str, result: std::io::Result<()>) {
    if let Err(e) = result
        && e.kind() != std::io::ErrorKind::BrokenPipe
    {
        let mut failed = STREAM_FAILED.lock().unwrap_or_else(|e| e.into_inner());
        failed.get_or_insert_with(|| format!("cannot write {stream}: {e}"));
    }
}

/// Why writing stdout or stderr failed (not a closed pipe: a full disk, an I/O error),
/// if it did: `main` then fails a run that otherwise succeeded (exit 1).
pub fn stream_failed() -> Option<String> {
    STREAM_FAILED.lock().unwrap_or_else(|e| e.into_inner()).clone()
}

pub mod batch;
pub mod check_map;
pub mod compare;
pub mod estimate;
pub mod eval;
pub mod export_model;
pub mod inspect;
pub mod learn;
pub mod merge;
pub mod outputs;
pub mod params;
pub mod plot_sweep;
pub mod progress;
pub mod run_model;
pub mod search;
pub mod signals;
pub mod trace;
pub mod train;
pub mod train_seeds;

/// What each command writes by default (`--out` changes it), shown under `--help`.
const OUTPUTS: &str = "\
Outputs (default places; --out changes them; a rerun replaces them, with a warning,
except batch, which replaces its results unless --resume completes them; a file there
of another kind is refused unless --force; no output may be an input):
  compare       out/compare/: compare.json, compare.csv, compare_seeds.csv, compare.svg
                (agents trained with --train-seeds are cached in out/agents/)
  train         agent.ron
  eval          out/eval/eval.json
  trace         out/trace/: trace.csv, theta.svg, filmstrip.svg (and --html FILE: a replay page)
  learn         out/learn/: learn.csv, learn.json, learn.svg
  batch         results.jsonl and results.summary.json
  merge         results.jsonl and results.summary.json
  plot-sweep    sweep.svg
  export-model  out/model.json
  search        out/search/: candidates.jsonl, summary.json, search.svg, failures/*.ron
  estimate      out/estimate/: estimate.jsonl, summary.json
Progress: bars on a terminal; otherwise one line per phase on stderr (-q: none).
Architecture and equations: docs/ARCHITECTURE.md in the repository.";

/// Active inference as the test-time scaling law for physical AI agents, on a Rapier 2D
/// intersection. With no command, runs `compare` on the embedded default maps.
#[derive(Debug, Parser)]
#[command(name = "unforeseen", version, about, long_about = None, after_help = OUTPUTS)]
pub struct Cli {
    /// What to run (default: `compare` on the embedded maps).
    #[command(subcommand)]
    pub command: Option<Command>,
}

/// The commands. Each takes a negative number as the value of a flag (`--episodes -5`
/// reaches the flag's own check and its message, not clap's tip).
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Train on a map and compare Q-learning, Bayesian RL and the scaled agent on a test map (the paper's table).
    #[command(allow_negative_numbers = true)]
    Compare(compare::CompareArgs),
    /// Train Q-learning, the world model and Bayesian RL on a map; write an agent file.
    #[command(allow_negative_numbers = true)]
    Train(train::TrainArgs),
    /// Evaluate one method of a trained agent on a map.
    #[command(allow_negative_numbers = true)]
    Eval(eval::EvalArgs),
    /// Run one episode step by step: table, CSV, surprise plot and filmstrip.
    #[command(allow_negative_numbers = true)]
    Trace(trace::TraceArgs),
    /// Test-time learning curves over repeated episodes (paper Fig. 9).
    #[command(allow_negative_numbers = true)]
    Learn(learn::LearnArgs),
    /// Validate map files and print a readable summary.
    #[command(allow_negative_numbers = true)]
    CheckMap(check_map::CheckMapArgs),
    /// Run scenario suites headless: every map x method x parameter set, in parallel, as JSON Lines, with expectations.
    #[command(allow_negative_numbers = true)]
    Batch(batch::BatchArgs),
    /// Merge the shard files of one batch run (from Slurm, Kubernetes, GNU parallel, Ray) into one results file and summary.
    #[command(allow_negative_numbers = true)]
    Merge(merge::MergeArgs),
    /// Plot a sweep's results (success and reward against reasoning compute) as SVG.
    #[command(allow_negative_numbers = true)]
    PlotSweep(plot_sweep::PlotSweepArgs),
    /// Cross-check the agent's math on a model given as JSON in pymdp's layout (any number of factors and modalities).
    #[command(allow_negative_numbers = true)]
    Inspect(inspect::InspectArgs),
    /// Run the surprise-gated agent on a model in pymdp's layout, in a world given in the same layout.
    #[command(allow_negative_numbers = true)]
    RunModel(run_model::RunModelArgs),
    /// Search a space of map variations for the fair scenarios where a method fails.
    #[command(allow_negative_numbers = true)]
    Search(search::SearchArgs),
    /// Estimate how rare a method's failures are on a space: P(an episode fails) and P(fails | fair), with intervals.
    #[command(allow_negative_numbers = true)]
    Estimate(estimate::EstimateArgs),
    /// Write a trained agent's planning model in the `inspect` JSON layout (for pymdp).
    #[command(allow_negative_numbers = true)]
    ExportModel(export_model::ExportModelArgs),
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> anyhow::Result<()> {
    cap_rayon_threads();
    match cli
        .command
        .unwrap_or_else(|| Command::Compare(compare::CompareArgs::default()))
    {
        Command::Compare(args) => compare::run(args),
        Command::Train(args) => train::run(args),
        Command::Eval(args) => eval::run(args),
        Command::Trace(args) => trace::run(args),
        Command::Learn(args) => learn::run(args),
        Command::CheckMap(args) => check_map::run(args),
        Command::Inspect(args) => inspect::run(args),
        Command::RunModel(args) => run_model::run(args),
        Command::ExportModel(args) => export_model::run(args),
        Command::Batch(args) => batch::run_cli(args),
        Command::Merge(args) => merge::run(args),
        Command::PlotSweep(args) => plot_sweep::run(args),
        Command::Search(args) => search::run(args),
        Command::Estimate(args) => estimate::run(args),
    }
}

/// The exit code for an error (a library error, or an [`anyhow::Error`] as `&*err`): 2
/// when it or anything in its chain of causes is input the user can fix
/// ([`unforeseen_harness::error::in_chain`]), 1 otherwise.
pub fn exit_code(err: &(dyn std::error::Error + 'static)) -> i32 {
    if unforeseen_harness::error::in_chain(err) { 2 } else { 1 }
}

/// A failed command's message: the error and its causes (`outer: inner: ...`), with a
/// parameter override spelt as the flag it came from (`--set epsilon=2: ...`), a
/// request's field as its flag (`train_seeds: ...` as `--train-seeds: ...`), and the
/// fields the output guard names (`out`, `agent`, the maps, ...) as their flags.
pub fn error_message(err: &anyhow::Error) -> String {
    use unforeseen_harness::error::Error;
    let text = format!("{err:#}");
    match err.downcast_ref::<Error>() {
        Some(Error::Override { .. }) => format!("--set {text}"),
        Some(Error::Request { field, .. } | Error::OutOfRange { field, .. }) => match text.strip_prefix(field.as_str())
        {
            Some(rest) => format!("{}{rest}", flag_of(field)),
            None => text,
        },
        Some(Error::Flag { .. }) => spell_guard_fields(text),
        _ => text,
    }
}

/// The fields of a request that the output guard names (inputs and outputs), longest
/// first.
const GUARDED_FIELDS: [&str; 8] = ["stream", "agent", "space", "cache", "maps", "html", "map", "out"];

/// A message of the output guard with the fields it names (at its start, in "given as
/// FIELD" and in "give FIELD ...") spelt as their flags.
fn spell_guard_fields(mut text: String) -> String {
    for field in GUARDED_FIELDS {
        let flag = flag_of(field);
        if let Some(rest) = text.strip_prefix(&format!("{field} ")) {
            text = format!("{flag} {rest}");
        }
        text = text
            .replace(&format!("given as {field} "), &format!("given as {flag} "))
            .replace(&format!("give {field} "), &format!("give {flag} "));
    }
    text
}

/// The command line's spelling of a request's field: its flag (`train_seeds` is
/// `--train-seeds`, `sets` is `--set`, `methods` is `--method`), or `MAP` for the maps
/// given as arguments.
pub fn flag_of(field: &str) -> String {
    match field {
        "maps" => "MAP".into(),
        "methods" => "--method".into(),
        "sets" => "--set".into(),
        f => format!("--{}", f.replace('_', "-")),
    }
}

/// Parses a method by name (`--method`), listing every name with its summary.
pub fn method_parser() -> impl TypedValueParser<Value = Method> {
    let names = Method::ALL.map(|m| PossibleValue::new(m.name()).help(m.summary()));
    PossibleValuesParser::new(names).map(|s| s.parse::<Method>().expect("a listed method name"))
}

/// Parses one protocol by name (`--protocol` of `eval` and `trace`), listing both.
pub fn protocol_parser() -> impl TypedValueParser<Value = Protocol> {
    let names = Protocol::ALL.map(|p| PossibleValue::new(p.name()).help(p.summary()));
    PossibleValuesParser::new(names).map(|s| s.parse::<Protocol>().expect("a listed protocol name"))
}

/// Parses the `--protocol` option of `compare` and `batch` (one protocol or both),
/// listing every choice.
pub fn protocol_choice_parser() -> impl TypedValueParser<Value = ProtocolChoice> {
    let names = ProtocolChoice::ALL.map(|p| PossibleValue::new(p.name()).help(p.summary()));
    PossibleValuesParser::new(names).map(|s| s.parse::<ProtocolChoice>().expect("a listed protocol choice"))
}

/// Options shared by the commands that drive a trained agent.
#[derive(Debug, Clone, Args)]
pub struct AgentArgs {
    /// Agent file from `unforeseen train`; without it, one is trained first on the
    /// embedded training map (`intersection`) with the default episodes and `--seed`.
    #[arg(long, value_name = "FILE")]
    pub agent: Option<PathBuf>,
    /// Scaled-agent parameter overrides (help text: [`unforeseen_harness::overrides::help`], the keys
    /// derived from the parameter table).
    #[arg(long = "set", value_name = "KEY=VALUE", help = unforeseen_harness::overrides::help())]
    pub set: Vec<String>,
    /// Run seed: the evaluation episodes and, without `--agent`, the training run derive from it.
    #[arg(long, default_value_t = unforeseen_env::seeds::DEFAULT_SEED)]
    pub seed: u64,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
}

impl AgentArgs {
    /// Loads the agent file, or trains one on the embedded training map
    /// (`intersection`) for the default episodes with `--seed` (`export-model`; the other
    /// commands choose their agent in the library's request).
    pub fn bundle(&self) -> anyhow::Result<AgentBundle> {
        if let Some(path) = &self.agent {
            return Ok(unforeseen_harness::training::agent_file::load(path)?);
        }
        let (seed, episodes) = (self.seed, unforeseen_harness::training::DEFAULT_TRAIN_EPISODES);
        let map = unforeseen_harness::maps::load(DEFAULT_TRAIN_MAP)?;
        progress::training(self.quiet, false, 1, episodes, &map.name, seed);
        let bars = progress::Bars::new(self.quiet);
        bars.phase("training", episodes);
        let trained = train_with_progress(&map, &TrainConfig::new(episodes, seed), &bars);
        bars.finish();
        Ok(trained?.0)
    }

    /// The input files among these options (`--agent`), for the output guard.
    pub fn inputs(&self) -> unforeseen_harness::runs::outputs::Outputs {
        let guard = unforeseen_harness::runs::outputs::Outputs::new();
        match &self.agent {
            Some(p) => guard.input("--agent", p),
            None => guard,
        }
    }

    /// The scaled agent's parameters with the `--set` overrides applied.
    pub fn params(&self) -> anyhow::Result<ScaledParams> {
        Ok(params::apply(ScaledParams::default(), &self.set)?)
    }
}

/// Parses an episode count that may be 0 (`check-map --survivability-episodes`, where 0
/// turns the check off): a whole number in 0..=MAX_EPISODES, digits only (`+5` is
/// refused).
pub fn episodes_or_none(s: &str) -> Result<u64, String> {
    if s == "0" { Ok(0) } else { episodes(s) }
}

/// Most worker threads: `--jobs` and `RAYON_NUM_THREADS` beyond it are capped.
pub const MAX_JOBS: usize = unforeseen_harness::limits::MAX_JOBS;

/// Caps `RAYON_NUM_THREADS` (which sizes the thread pools of every command but batch)
/// at [`MAX_JOBS`], with a warning: a huge value spent minutes starting threads.
/// Called before any pool is built; a value that is not a number is left to rayon.
pub fn cap_rayon_threads() {
    let Ok(v) = std::env::var("RAYON_NUM_THREADS") else {
        return;
    };
    if let Ok(n) = v.trim().parse::<usize>()
        && n > MAX_JOBS
    {
        errln!("warning: RAYON_NUM_THREADS={n} is more than {MAX_JOBS} worker threads; using {MAX_JOBS}");
        let _ = rayon::ThreadPoolBuilder::new().num_threads(MAX_JOBS).build_global();
    }
}

/// Parses `--timeout-as`.
pub fn timeout_as(s: &str) -> Result<unforeseen_harness::training::TimeoutAs, String> {
    s.parse()
}

/// Parses an episode count (`--episodes`, `--train-episodes`): a whole number in 1..=MAX_EPISODES.
pub fn episodes(s: &str) -> Result<u64, String> {
    if s.is_empty() || !s.bytes().all(|b| b.is_ascii_digit()) {
        return Err(format!(
            "'{s}' is not a whole number of episodes (digits only, e.g. 100)"
        ));
    }
    match s.parse::<u64>() {
        Ok(n) if (1..=MAX_EPISODES).contains(&n) => Ok(n),
        Ok(0) => Err("must be at least 1 (0 episodes would measure nothing)".into()),
        Ok(_) => Err(format!(
            "at most {MAX_EPISODES} per run (split larger runs with --shard or several --seed values)"
        )),
        Err(_) => Err(format!("'{s}' is not a whole number of episodes")),
    }
}

/// Parses an episode index (`trace --episode`): digits only (no sign, no `+5`), at most
/// MAX_EPISODES.
pub fn episode_index(s: &str) -> Result<u64, String> {
    match s.parse::<u64>() {
        Ok(n) if s.bytes().all(|b| b.is_ascii_digit()) && n <= MAX_EPISODES => Ok(n),
        _ => Err(format!(
            "'{s}' is not an episode number: digits only, 0 (the first) to {MAX_EPISODES}"
        )),
    }
}

/// Warns on stderr (whatever `--quiet` says) that this run replaces the file `path` an
/// earlier run wrote.
pub fn warn_replacing_file(path: &std::path::Path) {
    if path.is_file() {
        errln!(
            "warning: replacing {} from an earlier run (--out FILE writes elsewhere)",
            path.display()
        );
    }
}

/// Warns on stderr (whatever `--quiet` says) that this run replaces the files `names` in
/// `dir` that an earlier run wrote; results are replaced, never merged.
pub fn warn_replacing(dir: &std::path::Path, names: &[&str]) {
    let existing: Vec<&str> = names.iter().copied().filter(|n| dir.join(n).is_file()).collect();
    if !existing.is_empty() {
        errln!(
            "warning: replacing {} in {} from an earlier run (--out DIR writes them elsewhere)",
            existing.join(", "),
            dir.display()
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use unforeseen_harness::runs::compare::CompareRequest;
    use unforeseen_harness::runs::evaluate::EvalRequest;
    use unforeseen_harness::runs::learn::LearnRequest;
    use unforeseen_harness::runs::trace::TraceRequest;

    fn command(args: &[&str]) -> Command {
        Cli::parse_from(args).command.expect("a command")
    }

    /// The flags' defaults are the requests' (batch and search check theirs beside their
    /// arguments), and `cargo run` with no command runs compare's defaults.
    #[test]
    fn the_flags_defaults_are_the_requests() {
        let Command::Compare(compare) = command(&["unforeseen", "compare"]) else {
            panic!("not compare")
        };
        assert_eq!(compare.request(), CompareRequest::default());
        assert_eq!(compare::CompareArgs::default().request(), CompareRequest::default());
        let Command::Eval(eval) = command(&["unforeseen", "eval"]) else {
            panic!("not eval")
        };
        assert_eq!(eval.request(), EvalRequest::default());
        let Command::Learn(learn) = command(&["unforeseen", "learn"]) else {
            panic!("not learn")
        };
        assert_eq!(learn.request(), LearnRequest::default());
        let Command::Trace(trace) = command(&["unforeseen", "trace"]) else {
            panic!("not trace")
        };
        assert_eq!(trace.request(), TraceRequest::default());
    }
}
