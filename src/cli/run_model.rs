//! `unforeseen run-model --model FILE.json --env FILE.json`: the surprise-gated agent
//! (`unforeseen_agent::aif::gate`) on a model in pymdp's layout, acting in a world given
//! in the same layout, for a number of episodes; prints the summary as JSON, and with
//! `--out` also writes it to a file through the output guard
//! ([`unforeseen_harness::runs::outputs`]).

use clap::{Args, ValueEnum};
use std::path::{Path, PathBuf};

use unforeseen_agent::aif::agent::Settings;
use unforeseen_agent::aif::gate::{GatedAgent, Habit};
use unforeseen_agent::aif::model::Model;
use unforeseen_agent::aif::process::Process;
use unforeseen_agent::aif::run::{self as gated_run, RunConfig};
use unforeseen_harness::error::Error;
use unforeseen_harness::files::write_json;
use unforeseen_harness::runs::outputs::{Outputs, Own};

/// The habit of the gated agent.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum HabitArg {
    /// The action it planned most often before in the same most likely state.
    Learned,
    /// The first-step marginal of the model's E.
    Prior,
}

/// Arguments of `run-model`.
#[derive(Debug, Clone, Args)]
pub struct RunModelArgs {
    /// The agent's model in pymdp's layout: {"A", "B", "C", "D", "E"?, "pA"?, "pB"?,
    /// "A_dependencies"?, "B_dependencies"?} with A[m][o, s...], B[f][s', s..., u], and
    /// optionally its settings "policy_len", "gamma", "num_iter", "sampling_mode", "preferences".
    #[arg(long, value_name = "FILE.json")]
    pub model: PathBuf,
    /// The world in the same layout ({"A", "B", "D", dependencies}); it may differ from
    /// the model (an unforeseen change) but must have the same shapes.
    #[arg(long, value_name = "FILE.json")]
    pub env: PathBuf,
    /// Episodes.
    #[arg(long, default_value_t = 10)]
    pub episodes: usize,
    /// Ticks per episode.
    #[arg(long, default_value_t = 10)]
    pub steps: usize,
    /// Seed of the world's and the agent's draws.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Surprise threshold ε in bits: plan when the surprise exceeds it (negative: every tick).
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub epsilon: f64,
    /// What the agent does when not surprised.
    #[arg(long, value_enum, default_value_t = HabitArg::Learned)]
    pub habit: HabitArg,
    /// Learn the model's pA/pB after each episode (test-time learning).
    #[arg(long)]
    pub learn: bool,
    /// Also write the summary to this file (JSON).
    #[arg(long, value_name = "FILE.json")]
    pub out: Option<PathBuf>,
    /// Replace --out even when it holds something other than a `run-model` summary;
    /// without it such a file is refused (exit 2).
    #[arg(long)]
    pub force: bool,
}

fn read(path: &Path) -> Result<serde_json::Value, Error> {
    let text = unforeseen_harness::limits::read_model_file(path)?;
    serde_json::from_str(&text).map_err(|e| Error::ModelFile {
        path: path.to_path_buf(),
        problem: format!("invalid JSON: {e}"),
    })
}

/// Runs `run-model`, printing the summary as JSON on stdout (and writing it to `--out`).
pub fn run(args: RunModelArgs) -> anyhow::Result<()> {
    if let Some(out) = &args.out {
        let inputs = Outputs::new().input("--model", &args.model).input("--env", &args.env);
        super::outputs::file("--out", out, Own::ModelRun, args.force, inputs)?;
    }
    let bad = |path: &Path| {
        let path = path.to_path_buf();
        move |e: unforeseen_agent::aif::error::ModelError| Error::ModelFile {
            path: path.clone(),
            problem: e.to_string(),
        }
    };
    let mv = read(&args.model)?;
    let model = Model::from_json(&mv).map_err(bad(&args.model))?;
    let agent = Settings::from_json(&mv)
        .and_then(|s| s.agent(model))
        .map_err(bad(&args.model))?;
    let habit = match args.habit {
        HabitArg::Learned => Habit::Learned,
        HabitArg::Prior => Habit::Prior,
    };
    let mut gated = GatedAgent::new(agent, args.epsilon, habit).map_err(bad(&args.model))?;
    let world = Model::from_json(&read(&args.env)?).map_err(bad(&args.env))?;
    let cfg = RunConfig {
        episodes: args.episodes,
        steps: args.steps,
        seed: args.seed,
        learn: args.learn,
    };
    let summary = gated_run::run(&mut gated, &mut Process::new(world), cfg).map_err(bad(&args.env))?;
    if let Some(out) = &args.out {
        write_json(out, &summary)?;
    }
    outln!("{}", serde_json::to_string_pretty(&summary)?);
    Ok(())
}
