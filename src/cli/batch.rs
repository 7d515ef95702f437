//! `unforeseen batch`: run scenario suites (maps, or one deployment stream with
//! `--stream`) headless, with expectations, sweeps, shards, both protocols and
//! training-seed studies.

use clap::Args;
use std::path::{Path, PathBuf};

use super::progress::{self, Bars};
use super::train_seeds::TrainSeedArgs;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::ProtocolChoice;
use unforeseen_harness::runs::batch::batch_summary;
use unforeseen_harness::runs::batch::{AgentChoice, BatchRequest, ScenarioKind, Shard, SummaryRow, stream_learning};

/// Arguments of `batch`.
#[derive(Debug, Clone, Args)]
pub struct BatchArgs {
    /// Map files or folders of maps (every *.ron); default: the embedded maps.
    #[arg(value_name = "MAP|DIR")]
    pub maps: Vec<PathBuf>,
    /// A deployment stream (a RON file listing maps with weights or a sequence; see
    /// `harness/src/runs/stream.rs` and `maps/streams/`) as the one scenario, instead of maps: each
    /// unit runs `--episodes` episodes over the stream's maps, and its line and the
    /// summary report per map within the stream.
    #[arg(long, value_name = "FILE", conflicts_with = "maps")]
    pub stream: Option<PathBuf>,
    /// Episodes per (scenario, method, parameter set, protocol, training seed).
    #[arg(long, default_value_t = BatchRequest::default().episodes, value_parser = super::episodes)]
    pub episodes: u64,
    /// Evaluation seed (and, without --agent or --train-seeds, the training seed).
    #[arg(long, default_value_t = BatchRequest::default().seed)]
    pub seed: u64,
    /// Methods to run (repeatable); default: q-learning, bayes-rl, scaled and the
    /// scripted references brake-on-pedestrian and never-brake (so every map reports
    /// whether it is survivable and dangerous).
    #[arg(long = "method", value_parser = super::method_parser())]
    pub methods: Vec<Method>,
    /// Evaluation protocol: zero-shot (every episode starts from the trained agent),
    /// continual (learning carries over between episodes, in order) or both. A method
    /// that does not learn across episodes runs once; its line covers both.
    #[arg(long, default_value_t = BatchRequest::default().protocol, value_parser = super::protocol_choice_parser())]
    pub protocol: ProtocolChoice,
    /// Worker threads (results do not depend on it); default: every core.
    #[arg(long, value_parser = jobs)]
    pub jobs: Option<usize>,
    /// Results file (JSON Lines), one line per unit as soon as it finishes; the summary
    /// over training seeds goes beside it (`results.summary.json`).
    #[arg(long, value_name = "FILE", default_value_os_t = BatchRequest::default().out)]
    pub out: PathBuf,
    /// Keep the complete lines already in --out and run only the missing units. The file
    /// must have been written by the same run (same program, agents, maps, methods,
    /// parameter sets, protocols, training seeds, episodes and seed; the shard may
    /// differ): otherwise it is refused, saying what differs.
    #[arg(long)]
    pub resume: bool,
    /// Replace --out even when it holds something other than a batch's results (a file
    /// whose first line is not `{"run": ...}`); without it such a file is refused.
    #[arg(long)]
    pub force: bool,
    /// Run only shard I of N (1-based) of the canonical unit order.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Sweep: `--set KEY=V1,V2,...` (repeatable; cross product). Keys as for `--set` elsewhere.
    #[arg(long = "set", value_name = "KEY=V1,V2")]
    pub sweep: Vec<String>,
    /// Training episodes when no --agent is given.
    #[arg(long, default_value_t = BatchRequest::default().train_episodes, value_parser = super::episodes)]
    pub train_episodes: u64,
    /// Agent file from `unforeseen train` (default: train on --train-map).
    #[arg(long, value_name = "FILE")]
    pub agent: Option<PathBuf>,
    /// Training map (file or embedded name) when no --agent is given: the agent (or, with
    /// --train-seeds, each agent) is trained there.
    #[arg(long, value_name = "MAP", default_value_t = BatchRequest::default().train_map, conflicts_with = "agent")]
    pub train_map: String,
    /// Training seeds and the agent cache.
    #[command(flatten)]
    pub seeds: TrainSeedArgs,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Parses `--jobs`: 1 to 256 worker threads.
fn jobs(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=super::MAX_JOBS).contains(&n) => Ok(n),
        _ => Err(format!("'{s}': expected a number of worker threads from 1 to 256")),
    }
}

impl BatchArgs {
    /// The request these arguments make.
    pub fn request(&self) -> BatchRequest {
        BatchRequest {
            maps: self.maps.clone(),
            stream: self.stream.clone(),
            methods: self.methods.clone(),
            protocol: self.protocol,
            sets: self.sweep.clone(),
            episodes: self.episodes,
            seed: self.seed,
            jobs: self.jobs,
            out: self.out.clone(),
            resume: self.resume,
            force: self.force,
            shard: self.shard,
            agent: self.agent.clone(),
            train_seeds: self.seeds.train_seeds.clone(),
            train_map: self.train_map.clone(),
            train_episodes: self.train_episodes,
            timeout_as: self.seeds.timeout_as,
            cache: self.seeds.cache_dir().map(Path::to_path_buf),
        }
    }
}

/// Runs `batch`: the request of the arguments, planned, its agents trained and its units
/// run by the library ([`BatchRequest::plan`]); fails (exit 1) when any expectation fails
/// on the mean over seeds.
pub fn run_cli(args: BatchArgs) -> anyhow::Result<()> {
    let quiet = args.quiet;
    let out = &args.out;
    // The folder the run creates for --out, if any, said once the guard has passed.
    let creates = super::outputs::to_create(out.parent().unwrap_or(Path::new("")));
    // An earlier file the run replaces (not one --resume completes), said once the guard passed.
    let replaced = (!args.resume).then(|| super::outputs::line_count(out)).flatten();
    // One run at a time per results file: the job holds the lock until it is dropped.
    let job = args.request().plan(None)?;
    super::outputs::creating("--out", creates);
    if let Some(n) = replaced
        && !quiet
    {
        errln!(
            "note: replacing {} ({}) from an earlier run (--resume completes a run instead; --out FILE writes elsewhere)",
            out.display(),
            super::outputs::lines(n)
        );
    }
    let setup = &job.setup;
    let to_train = job.to_train();
    if let AgentChoice::Trained { map, .. } = &setup.agents
        && !to_train.is_empty()
    {
        let per_seed = args.seeds.train_seeds.is_some();
        progress::training(
            quiet,
            per_seed,
            to_train.len(),
            args.train_episodes,
            &map.name,
            args.seed,
        );
    }
    let agents = job.agents(&Bars::counting(quiet, "episodes"))?;
    let workers = job.workers(&agents);
    if let Some((per, available)) = workers.bounded {
        errln!(
            "warning: --jobs {}: each worker holds its own copy of the agent's learners (about {} MB each) and {} MB are available; running {} worker(s)",
            setup.jobs,
            per >> 20,
            available >> 20,
            workers.jobs
        );
    }
    let scenarios = &setup.scenarios;
    let what = match &scenarios[0].kind {
        ScenarioKind::Stream(stream) if scenarios.len() == 1 => {
            format!("the stream '{}' ({} maps)", stream.name, stream.maps.len())
        }
        _ => format!("{} scenario(s)", scenarios.len()),
    };
    let seeds = if agents.is_empty() && setup.methods.iter().all(|m| m.is_scripted()) {
        "no agent (scripted methods only)".to_string()
    } else {
        format!("{} agent(s)", setup.train_seeds.len())
    };
    progress::phase(
        quiet,
        format_args!(
            "running {what} x {} method(s) x {} parameter set(s) x {} protocol(s) x {seeds} on {} thread(s), {} episodes each, into {}",
            setup.methods.len(),
            setup.params.len(),
            setup.protocols.len(),
            workers.jobs,
            args.episodes,
            out.display()
        ),
    );
    let total = job.plan.units.len();
    if job.plan.shard.is_empty() {
        errln!(
            "note: shard {}/{} has no units (the run has {total}); writing a results file with none",
            args.shard.map_or(1, |s| s.index),
            args.shard.map_or(1, |s| s.count),
        );
    } else if job.plan.todo().is_empty() {
        errln!("note: --resume: every unit of this run is in {} already", out.display());
    }
    let report = job.run(&agents, workers.jobs, &Bars::new(quiet))?;
    print_summary(&report.rows);
    for warning in &report.survivability {
        errln!("{warning}");
    }
    outln!(
        "wrote {} ({}) and {}; {} expectation(s) checked on the mean over training seeds, {} failed",
        out.display(),
        super::outputs::lines(report.lines.len()),
        report.summary.display(),
        report.checked,
        report.failures.len()
    );
    if !report.failures.is_empty() {
        for f in &report.failures {
            errln!("expectation failed: {f}");
        }
        anyhow::bail!("{} expectation(s) failed", report.failures.len());
    }
    Ok(())
}

/// Prints the summary table ([`batch_summary`]), then warns on stderr about each
/// map within a stream that learning makes worse.
pub(super) fn print_summary(rows: &[SummaryRow]) {
    outln!("{}", batch_summary(rows));
    for l in stream_learning(rows).iter().filter(|l| l.worse) {
        errln!(
            "warning: stream '{}': learning makes map '{}' worse for {} [{}]: success {:.1}% continual, {:.1}% zero-shot over its {} episodes",
            l.stream,
            l.map,
            l.method,
            l.param_set,
            100.0 * l.continual_success,
            100.0 * l.zero_shot_success,
            l.episodes
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[test]
    fn the_flags_defaults_are_the_requests() {
        let cli = super::super::Cli::parse_from(["unforeseen", "batch"]);
        let Some(super::super::Command::Batch(args)) = cli.command else {
            panic!("not batch")
        };
        assert_eq!(args.request(), BatchRequest::default());
    }
}
