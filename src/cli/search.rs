//! `unforeseen search`: search a space of map variations for the fair scenarios where a
//! method fails (`unforeseen_harness::runs::search`).

use clap::Args;
use std::path::{Path, PathBuf};

use super::progress::{self, Bars};
use super::train_seeds::TrainSeedArgs;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::runs::batch::{AgentChoice, Shard};
use unforeseen_harness::runs::search::{SearchRequest, Summary};

/// Arguments of `search`.
#[derive(Debug, Clone, Args)]
pub struct SearchArgs {
    /// Base map (file or embedded name) that the space varies.
    #[arg(long, value_name = "MAP", default_value_t = SearchRequest::default().map)]
    pub map: String,
    /// Space file (RON; maps/README.md, "Space files"), e.g. maps/spaces/jaywalk.ron.
    #[arg(long, value_name = "FILE")]
    pub space: PathBuf,
    /// The method searched for failures.
    #[arg(long, default_value_t = SearchRequest::default().method, value_parser = super::method_parser())]
    pub method: Method,
    /// The method's evaluation protocol on each candidate.
    #[arg(long, default_value_t = SearchRequest::default().protocol, value_parser = super::protocol_parser())]
    pub protocol: Protocol,
    /// Candidates of the Sobol and adaptive stages (minimisation tries come on top).
    #[arg(long, default_value_t = SearchRequest::default().budget)]
    pub budget: usize,
    /// Episodes per candidate, for each witness and for the method (per training seed).
    #[arg(long, default_value_t = SearchRequest::default().episodes, value_parser = super::episodes)]
    pub episodes: u64,
    /// Run seed: Sobol scrambling, adaptive draws and every episode derive from it.
    #[arg(long, default_value_t = SearchRequest::default().seed)]
    pub seed: u64,
    /// Share of the budget for the Sobol stage (the unbiased estimate), in (0, 1].
    #[arg(long, default_value_t = SearchRequest::default().sobol_share)]
    pub sobol_share: f64,
    /// Rounds of the adaptive (cross-entropy) stage.
    #[arg(long, default_value_t = SearchRequest::default().rounds)]
    pub rounds: usize,
    /// Failures minimised and written as maps.
    #[arg(long, default_value_t = SearchRequest::default().max_failures)]
    pub max_failures: usize,
    /// Worker threads (results do not depend on it); default: every core.
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Evaluate only shard I of N of the Sobol stage (no adaptive stage, no
    /// minimisation); concatenate the shards' candidates.jsonl and finish with --resume.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Keep the complete candidates in --out/candidates.jsonl (of the same search) and
    /// evaluate only the rest.
    #[arg(long)]
    pub resume: bool,
    /// Output folder: candidates.jsonl, summary.json, search.svg and failures/*.ron.
    /// No input may be inside it.
    #[arg(long, value_name = "DIR", default_value_os_t = SearchRequest::default().out)]
    pub out: PathBuf,
    /// Replace files in --out that a search did not write (a failure map edited by hand,
    /// a file of another program); without it they are refused.
    #[arg(long)]
    pub force: bool,
    /// Training episodes when no --agent is given.
    #[arg(long, default_value_t = SearchRequest::default().train_episodes, value_parser = super::episodes)]
    pub train_episodes: u64,
    /// Agent file from `unforeseen train` (default: train on --train-map).
    #[arg(long, value_name = "FILE")]
    pub agent: Option<PathBuf>,
    /// Training map (file or embedded name) when no --agent is given: the agent (or, with
    /// --train-seeds, each agent) is trained there.
    #[arg(long, value_name = "MAP", default_value_t = SearchRequest::default().train_map, conflicts_with = "agent")]
    pub train_map: String,
    /// Training seeds and the agent cache.
    #[command(flatten)]
    pub seeds: TrainSeedArgs,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
}

impl SearchArgs {
    /// The request these arguments make.
    pub fn request(&self) -> SearchRequest {
        SearchRequest {
            space: self.space.clone(),
            map: self.map.clone(),
            method: self.method,
            protocol: self.protocol,
            budget: self.budget,
            episodes: self.episodes,
            seed: self.seed,
            sobol_share: self.sobol_share,
            rounds: self.rounds,
            max_failures: self.max_failures,
            jobs: self.jobs,
            shard: self.shard,
            resume: self.resume,
            out: self.out.clone(),
            force: self.force,
            agent: self.agent.clone(),
            train_seeds: self.seeds.train_seeds.clone(),
            train_map: self.train_map.clone(),
            train_episodes: self.train_episodes,
            timeout_as: self.seeds.timeout_as,
            cache: self.seeds.cache_dir().map(Path::to_path_buf),
        }
    }
}

/// Runs `search`: the request of the arguments, planned, its agents trained and the
/// search run by the library ([`SearchRequest::plan`]).
pub fn run(args: SearchArgs) -> anyhow::Result<()> {
    let quiet = args.quiet;
    let creates = super::outputs::to_create(&args.out);
    // Every output checked, the folder created and locked, before any work.
    let job = args.request().plan(None)?;
    super::outputs::creating("--out", creates);
    let setup = &job.setup;
    let to_train = setup.to_train();
    if let AgentChoice::Trained { map, .. } = &setup.agents
        && !to_train.is_empty()
    {
        let per_seed = args.seeds.train_seeds.is_some();
        let episodes = args.train_episodes;
        progress::training(quiet, per_seed, to_train.len(), episodes, &map.name, args.seed);
    }
    let agents = setup.agents(&Bars::counting(quiet, "episodes"))?;
    let command = std::iter::once("unforeseen".to_string())
        .chain(std::env::args().skip(1))
        .collect::<Vec<_>>()
        .join(" ");
    let cfg = setup.config(&agents, setup.jobs, command.clone());
    progress::phase(
        quiet,
        format_args!(
            "searching {} ({} parameters over {}) for failures of {} ({}): {} candidates ({} Sobol), {} episodes each, on {} thread(s), into {}",
            setup.space.name,
            setup.space.params.len(),
            setup.space.base.name,
            args.method.name(),
            args.protocol.name(),
            args.budget,
            cfg.sobol_count(),
            args.episodes,
            setup.jobs,
            args.out.display()
        ),
    );
    let summary = job.run(&agents, command, &Bars::new(quiet))?;
    print_summary(&summary, &args);
    Ok(())
}

fn print_summary(s: &Summary, args: &SearchArgs) {
    let c = &s.counts;
    outln!(
        "candidates: {} Sobol, {} adaptive, {} minimisation tries; {} rejected (not valid maps)",
        c.sobol,
        c.adaptive,
        c.minimise,
        c.rejected
    );
    outln!(
        "evaluated {}: {} fair, {} not survivable, {} not dangerous, {} neither; fair failures: {} Sobol, {} adaptive",
        c.evaluated,
        c.fair,
        c.not_survivable,
        c.not_dangerous,
        c.neither,
        c.failing_fair_sobol,
        c.failing_fair_adaptive
    );
    outln!("fair share of the space (Sobol stage): {}", s.fair_share.text());
    for e in &s.failure_probability {
        let who = e
            .train_seed
            .map_or("with the given agent".to_string(), |t| format!("training seed {t}"));
        outln!(
            "P({} fails | fair), {who}: {}",
            args.method.name(),
            e.failure_probability.text()
        );
    }
    if let Some(st) = &s.failure_probability_over_seeds
        && st.n > 1
    {
        let ci = match (st.ci95_low, st.ci95_high) {
            // A probability's interval is cut to [0, 1] (the t interval over three seeds can reach past it).
            (Some(l), Some(h)) => format!(" [{:.1}, {:.1}]", 100.0 * l.max(0.0), 100.0 * h.min(1.0)),
            _ => String::new(),
        };
        outln!(
            "over {} training seeds: mean {:.1}%{ci} (95% Student t), range {:.1}..{:.1}%",
            st.n,
            100.0 * st.mean,
            100.0 * st.min,
            100.0 * st.max
        );
    }
    for f in &s.failures {
        let changed: Vec<String> = f.changed.iter().map(|(n, _, v)| format!("{n}={v}")).collect();
        outln!(
            "failure {}: {} (from candidate {}; changes {})",
            f.name,
            f.file.display(),
            f.found_as,
            if changed.is_empty() {
                "nothing".into()
            } else {
                changed.join(", ")
            }
        );
    }
    outln!(
        "wrote {}/{{candidates.jsonl, summary.json, search.svg, failures/}}",
        args.out.display()
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[test]
    fn the_flags_defaults_are_the_requests() {
        let cli = super::super::Cli::parse_from(["unforeseen", "search", "--space", "s.ron"]);
        let Some(super::super::Command::Search(args)) = cli.command else {
            panic!("not search")
        };
        let expected = SearchRequest {
            space: "s.ron".into(),
            ..SearchRequest::default()
        };
        assert_eq!(args.request(), expected);
    }
}
