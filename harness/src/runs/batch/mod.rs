//! Headless batch runs of scenario suites: every (scenario, method, parameter set,
//! protocol, training seed) is a unit of work; units run in parallel (rayon) and each
//! finished unit is streamed as one JSON line. Seeds derive from (seed, scenario, method,
//! episode), never from thread order, so results are identical whatever the number of
//! jobs; `--shard i/n` takes a contiguous slice of the canonical unit order, so shards
//! concatenate into the file a single run writes. A method that does not learn across
//! episodes is run once per (scenario, parameter set, seed), and its line covers every
//! protocol asked. Over training seeds, [`summarize`] gives each figure's mean, 95%
//! interval, range and worst seed, and checks the maps' expectations on the mean.
//!
//! A scenario is a map or a deployment stream ([`ScenarioKind`], [`load_stream_scenario`]):
//! a stream's unit runs its episodes over the stream's maps ([`evaluate_stream`](crate::runs::stream::evaluate_stream)) and its
//! line is a line like a map's (the figures over the whole stream) with the figures per
//! map within the stream added ([`ResultLine::per_map`]); the summary follows the stream's
//! row with one row per map, and [`stream_learning`] compares each map's figures under
//! the two protocols.
//!
//! A results file starts with the [`RunIdentity`] of the run that wrote it (program
//! version, agents, map contents, methods, parameter sets, protocols, training seeds,
//! episodes, seed). `--resume` refuses a file of another run, saying what differs, and
//! keeps the lines it reuses byte for byte.
//!
//! [`BatchConfig::plan`] computes once what a run does (its units, its shard of them, its
//! identity and the lines `--resume` keeps) before any agent is needed, so a caller can
//! train only the agents the units still to run use ([`Plan::train_seeds_to_run`]), then
//! [`run_plan`] runs it.
//!
//! A run's request ([`BatchRequest`]) is every choice of its user; its planning
//! ([`BatchRequest::plan`]) gives the [`BatchJob`] that the command line, the Python
//! package and the Ray driver all run.
//!
//! One private file per part: `request.rs`, `scenario.rs`, `sweep.rs`, `units.rs`, `expectations.rs`,
//! `result_line.rs`, `plan.rs`, `identity.rs`, `run.rs`, `results_file.rs`, `summary.rs` and
//! `table.rs`; what callers use is re-exported here, the batch job's one face.

pub(crate) mod expectations;
pub(crate) mod identity;
pub(crate) mod plan;
pub(crate) mod request;
pub(crate) mod result_line;
pub(crate) mod results_file;
pub(crate) mod run;
pub(crate) mod scenario;
pub(crate) mod summary;
pub(crate) mod sweep;
pub(crate) mod table;
pub(crate) mod units;

pub use expectations::{Check, check_expectations};
pub use identity::{RunIdentity, SCRIPTED_ONLY, agent_file_identity, trained_agents_identity};
pub use plan::{BatchConfig, Plan};
pub use request::{AgentChoice, BatchJob, BatchReport, BatchRequest, BatchSetup, Workers, survivability_warnings};
pub use result_line::{MapFigures, ResultLine, UnitKey, UnitLabel};
pub use results_file::{KeptLine, MAX_FIGURE, ResultsFile, read_lines, read_results, resume_lines};
pub use run::{run, run_plan, run_unit, run_unit_with};
pub use scenario::{Scenario, ScenarioKind, load_scenarios, load_stream_scenario};
pub use summary::{StreamLearning, SummaryCheck, SummaryRow, WorstLine, stream_learning, summarize};
pub use sweep::{MAX_PARAM_SETS, ParamSet, checked_sweep, sweep};
pub use table::{batch_summary, expectation_failures};
pub use units::{DEFAULT_METHODS, Shard, Unit, units};
