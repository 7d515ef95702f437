//! `unforeseen batch`: run scenario suites (maps, or one deployment stream with
//! `--stream`) headless, with expectations, sweeps, shards, both protocols and
//! training-seed studies.

use clap::Args;
use std::path::PathBuf;

use super::ProtocolChoice;
use super::progress::{self, Bars};
use super::train_seeds::TrainSeedArgs;
use unforeseen_harness::episodes::methods::Method;
use unforeseen_harness::episodes::survivability::{Witness, warnings};
use unforeseen_harness::maps;
use unforeseen_harness::reports::files::write_json;
use unforeseen_harness::reports::tables;
use unforeseen_harness::runs::batch::{
    BatchConfig, DEFAULT_METHODS, ResultLine, SCRIPTED_ONLY, Scenario, ScenarioKind, Shard, SummaryRow,
    agent_file_identity, checked_sweep, load_scenarios, load_stream_scenario, run_plan, stream_learning, summarize,
    summary_path, trained_agents_identity,
};
use unforeseen_harness::runs::merge::summary_document;
use unforeseen_harness::runs::outputs::Outputs;
use unforeseen_harness::training::seed_agents::Agent;
use unforeseen_harness::training::{DEFAULT_TRAIN_EPISODES, DEFAULT_TRAIN_MAP};

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
    #[arg(long, default_value_t = 100, value_parser = super::episodes)]
    pub episodes: u64,
    /// Evaluation seed (and, without --agent or --train-seeds, the training seed).
    #[arg(long, default_value_t = 7)]
    pub seed: u64,
    /// Methods to run (repeatable); default: q-learning, bayes-rl, scaled and the
    /// scripted references brake-on-pedestrian and never-brake (so every map reports
    /// whether it is survivable and dangerous).
    #[arg(long = "method", value_parser = super::method_parser())]
    pub methods: Vec<Method>,
    /// Evaluation protocol: zero-shot (every episode starts from the trained agent),
    /// continual (learning carries over between episodes, in order) or both. A method
    /// that does not learn across episodes runs once; its line covers both.
    #[arg(long, value_enum, default_value_t = ProtocolChoice::Both)]
    pub protocol: ProtocolChoice,
    /// Worker threads (results do not depend on it).
    #[arg(long, default_value_t = default_jobs(), value_parser = jobs)]
    pub jobs: usize,
    /// Results file (JSON Lines), one line per unit as soon as it finishes; the summary
    /// over training seeds goes beside it (`results.summary.json`).
    #[arg(long, value_name = "FILE", default_value = "results.jsonl")]
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
    #[arg(long, default_value_t = DEFAULT_TRAIN_EPISODES, value_parser = super::episodes)]
    pub train_episodes: u64,
    /// Agent file from `unforeseen train` (default: train on --train-map).
    #[arg(long, value_name = "FILE")]
    pub agent: Option<PathBuf>,
    /// Training map (file or embedded name) when no --agent is given: the agent (or, with
    /// --train-seeds, each agent) is trained there.
    #[arg(long, value_name = "MAP", default_value = DEFAULT_TRAIN_MAP, conflicts_with = "agent")]
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

fn default_jobs() -> usize {
    std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
}

/// Runs `batch`; fails (exit 1) when any expectation fails on the mean over seeds.
pub fn run_cli(args: BatchArgs) -> anyhow::Result<()> {
    let scenarios = match &args.stream {
        Some(file) => vec![load_stream_scenario(file)?],
        None => load_scenarios(&args.maps)?,
    };
    let summary = summary_path(&args.out);
    // One run at a time per results file: a second one would interleave its lines with
    // this run's and lose them. The lock is released when the run ends.
    let _guard = guard(&args, &scenarios)?;
    let methods = if args.methods.is_empty() {
        DEFAULT_METHODS.to_vec()
    } else {
        args.methods.clone()
    };
    let params = checked_sweep(&args.sweep)?;
    let protocols = args.protocol.protocols();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(args.jobs.max(1)).build()?;
    // Without --train-seeds, the one agent (loaded, or trained now) and what determines
    // it; with them, what determines the agents, trained once the plan says which the
    // units still to run need. Scripted methods only, with neither: no agent at all.
    let scripted_only = methods.iter().all(|m| m.is_scripted());
    let (single, axis, agents_identity) = match &args.seeds.train_seeds {
        None if scripted_only && args.agent.is_none() => (None, vec![None], SCRIPTED_ONLY.to_string()),
        None => {
            let bundle = pool.install(|| {
                super::load_or_train(
                    args.agent.as_deref(),
                    &args.train_map,
                    args.train_episodes,
                    args.seed,
                    args.quiet,
                )
            })?;
            let identity = match &args.agent {
                Some(_) => agent_file_identity(&bundle),
                None => {
                    trained_agents_identity(&maps::load(&args.train_map)?, &[Some(args.seed)], args.train_episodes)?
                }
            };
            let agent = Agent::from_bundle(bundle);
            let axis = vec![agent.train_seed];
            (Some(agent), axis, identity)
        }
        Some(seeds) => {
            let axis: Vec<Option<u64>> = seeds.0.iter().map(|&s| Some(s)).collect();
            let identity = trained_agents_identity(&maps::load(&args.train_map)?, &axis, args.train_episodes)?;
            (None, axis, identity)
        }
    };
    let planning = BatchConfig {
        agents: &[],
        train_seeds: &axis,
        scenarios: &scenarios,
        methods: &methods,
        params: &params,
        protocols: &protocols,
        episodes: args.episodes,
        seed: args.seed,
        jobs: args.jobs,
        shard: args.shard,
        agents_identity,
    };
    let plan = planning.plan(&args.out, args.resume)?;
    let to_train = plan.train_seeds_to_run();
    let agents = match single {
        Some(agent) => vec![agent],
        None if to_train.is_empty() => Vec::new(),
        None => pool.install(|| {
            args.seeds
                .train(&to_train, &args.train_map, args.train_episodes, args.quiet)
        })?,
    };
    let states = agents.iter().map(|a| a.bundle.bayes_rl.n_states()).max().unwrap_or(0);
    let cfg = BatchConfig {
        agents: &agents,
        jobs: memory_bound_jobs(args.jobs, states),
        ..planning
    };
    let what = match &scenarios[0].kind {
        ScenarioKind::Stream(stream) if scenarios.len() == 1 => {
            format!("the stream '{}' ({} maps)", stream.name, stream.maps.len())
        }
        _ => format!("{} scenario(s)", scenarios.len()),
    };
    let seeds = if scripted_only && cfg.agents.is_empty() {
        "no agent (scripted methods only)".to_string()
    } else {
        format!("{} agent(s)", axis.len())
    };
    progress::phase(
        args.quiet,
        format_args!(
            "running {what} x {} method(s) x {} parameter set(s) x {} protocol(s) x {seeds} on {} thread(s), {} episodes each, into {}",
            methods.len(),
            params.len(),
            protocols.len(),
            cfg.jobs,
            args.episodes,
            args.out.display()
        ),
    );
    let total = plan.units.len();
    if plan.shard.is_empty() {
        errln!(
            "note: shard {}/{} has no units (the run has {total}); writing a results file with none",
            args.shard.map_or(1, |s| s.index),
            args.shard.map_or(1, |s| s.count),
        );
    } else if plan.todo().is_empty() {
        errln!(
            "note: --resume: every unit of this run is in {} already",
            args.out.display()
        );
    }
    let lines = run_plan(&cfg, &plan, &args.out, &Bars::new(args.quiet))?;
    let rows = summarize(&lines);
    print_summary(&rows);
    for warning in survivability_warnings(&scenarios, &lines) {
        errln!("{warning}");
    }
    let checked: usize = rows.iter().map(|r| r.checks.len()).sum();
    let failures = tables::expectation_failures(&rows);
    let shard = args.shard.map(|s| format!("{}/{}", s.index, s.count));
    write_json(
        &summary,
        &summary_document(&args.out, shard.as_deref(), &plan.identity, &rows),
    )?;
    outln!(
        "wrote {} ({} lines) and {}; {} expectation(s) checked on the mean over training seeds, {} failed",
        args.out.display(),
        lines.len(),
        summary.display(),
        checked,
        failures.len()
    );
    if !failures.is_empty() {
        for f in &failures {
            errln!("expectation failed: {f}");
        }
        anyhow::bail!("{} expectation(s) failed", failures.len());
    }
    Ok(())
}

/// Bytes of one copy of an agent's learners with `states` joint states (the world model
/// and Bayesian RL keep dense N x N matrices per action: about 370 bytes x N²).
fn learner_bytes(states: usize) -> u64 {
    370 * (states as u64).pow(2)
}

/// The memory the system says is available (`MemAvailable` of /proc/meminfo), if known.
fn available_bytes() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// `jobs`, or fewer when that many workers' copies of the learners (each running episode
/// learns on its own copy of its method's learner) would take more than half the memory
/// available; says so on stderr. Results do not depend on the number of workers.
fn memory_bound_jobs(jobs: usize, states: usize) -> usize {
    let per = learner_bytes(states);
    let Some(available) = available_bytes() else {
        return jobs;
    };
    let fit = ((available / 2) / per.max(1)).max(1) as usize;
    if jobs > fit {
        errln!(
            "warning: --jobs {jobs}: each worker holds its own copy of the agent's learners (about {} MB for {states} states) and {} MB are available; running {fit} worker(s)",
            per >> 20,
            available >> 20
        );
        fit
    } else {
        jobs
    }
}

/// The output guard of `batch` (`--out` and the summary beside it; the inputs `--agent`,
/// the maps, or the stream and its maps): checked before any work and held until the
/// end of the run (a second run into the same `--out` is refused).
fn guard(args: &BatchArgs, scenarios: &[Scenario]) -> anyhow::Result<unforeseen_harness::runs::outputs::Guarded> {
    let mut guard = Outputs::results("--out", &args.out);
    if let Some(agent) = &args.agent {
        guard = guard.input("--agent", agent);
    }
    for s in scenarios {
        guard = match (&s.kind, &args.stream) {
            (ScenarioKind::Stream(stream), Some(file)) => guard.stream("--stream", file, stream),
            _ => guard.input("MAP", &s.source),
        };
    }
    guard.check(args.force || args.resume)?;
    super::outputs::note_created("--out", args.out.parent().unwrap_or(std::path::Path::new("")));
    Ok(guard.guard(args.force || args.resume)?)
}

/// Prints the summary table ([`tables::batch_summary`]), then warns on stderr about each
/// map within a stream that learning makes worse.
pub(super) fn print_summary(rows: &[SummaryRow]) {
    outln!("{}", tables::batch_summary(rows));
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

/// The survivability warnings of `check-map`, from the brake-on-pedestrian and
/// never-brake units that ran (scripted methods ignore parameter sets, protocols and
/// training seeds, so the first line of each is taken), for map scenarios with pedestrian
/// rules.
fn survivability_warnings(scenarios: &[Scenario], lines: &[ResultLine]) -> Vec<String> {
    let witness = |scenario: &str, method: Method| {
        lines
            .iter()
            .find(|l| l.scenario == scenario && l.method == method.name())
            .map(|l| Witness {
                episodes: l.episodes,
                success_rate: l.success_rate,
                collision_rate: l.collision_rate,
                timeout_rate: l.timeout_rate,
                cruise: 1.0,
            })
    };
    scenarios
        .iter()
        .filter_map(|s| s.map().map(|map| (s, map)))
        .filter(|(_, map)| !map.pedestrians.is_empty())
        .flat_map(|(s, map)| {
            let name = &map.name;
            warnings(
                name,
                witness(name, Method::BrakeOnPedestrian).as_ref(),
                witness(name, Method::NeverBrake).as_ref(),
            )
            .into_iter()
            .map(move |w| format!("{}: {w}", s.source))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jobs_are_bounded_by_the_memory_of_the_learners_copies() {
        // 64 states (the embedded maps): 1.5 MB a copy, never a bound.
        assert_eq!(memory_bound_jobs(16, 64), 16);
        // A million states would be 370 TB a copy: one worker, where memory is known.
        if available_bytes().is_some() {
            assert_eq!(memory_bound_jobs(16, 1 << 20), 1);
        }
    }
}
