//! `unforeseen estimate`: how rare a method's failures are on a space of map variations,
//! P(an episode fails) and P(fails | fair) with their intervals
//! (`unforeseen_harness::runs::estimate`).

use clap::Args;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use std::path::{Path, PathBuf};

use super::progress::{self, Bars};
use super::train_seeds::TrainSeedArgs;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::runs::batch::{AgentChoice, Shard};
use unforeseen_harness::runs::estimate::{DrawStage, EstimateRequest, Estimator, Report, ShardPart, Summary};

/// Arguments of `estimate`.
#[derive(Debug, Clone, Args)]
pub struct EstimateArgs {
    /// Base map (file or embedded name) that the space varies.
    #[arg(long, value_name = "MAP", default_value_t = EstimateRequest::default().map)]
    pub map: String,
    /// Space file (RON; maps/README.md, "Space files"), e.g. maps/spaces/jaywalk.ron.
    #[arg(long, value_name = "FILE")]
    pub space: PathBuf,
    /// The method whose failures are counted.
    #[arg(long, default_value_t = EstimateRequest::default().method, value_parser = super::method_parser())]
    pub method: Method,
    /// The method's evaluation protocol on each draw.
    #[arg(long, default_value_t = EstimateRequest::default().protocol, value_parser = super::protocol_parser())]
    pub protocol: Protocol,
    /// The estimator.
    #[arg(long, default_value_t = EstimateRequest::default().estimator, value_parser = estimator_parser())]
    pub estimator: Estimator,
    /// Stop once the relative half-width of what the estimator aims at is at most this, in
    /// (0, 1): both probabilities' for mc, P(fails | fair)'s for is, P(fails)'s for is-fails.
    #[arg(long, value_name = "R", default_value_t = EstimateRequest::default().target_rel_error)]
    pub target_rel_error: f64,
    /// Most draws (points of the space evaluated); mc needs 50 at least, is and is-fails 200.
    #[arg(long, value_name = "N", default_value_t = EstimateRequest::default().budget)]
    pub budget: usize,
    /// Episodes per draw, for each witness and for the method (per training seed).
    #[arg(long, default_value_t = EstimateRequest::default().episodes, value_parser = super::episodes)]
    pub episodes: u64,
    /// Run seed: every draw and episode derive from it.
    #[arg(long, default_value_t = EstimateRequest::default().seed)]
    pub seed: u64,
    /// Worker threads (results do not depend on it); default: every core.
    #[arg(long)]
    pub jobs: Option<usize>,
    /// Evaluate only shard I of N of the next stage (the draws I-1 mod N of the first stage
    /// --out does not complete: mc's draws, or the next round or final draws of is and is-fails); write
    /// estimate.jsonl, no summary. Concatenate the shards' estimate.jsonl and finish with
    /// --resume (for is and is-fails, one --resume --shard round per stage).
    #[arg(long, value_name = "I/N")]
    pub shard: Option<Shard>,
    /// Keep the draws of the same request in --out (estimate.jsonl.part, left by an
    /// interrupted run, else estimate.jsonl) and evaluate only the rest.
    #[arg(long)]
    pub resume: bool,
    /// Output folder: estimate.jsonl and summary.json. No input may be inside it.
    #[arg(long, value_name = "DIR", default_value_os_t = EstimateRequest::default().out)]
    pub out: PathBuf,
    /// Replace files in --out that an estimate did not write; without it they are refused.
    #[arg(long)]
    pub force: bool,
    /// Training episodes when no --agent is given.
    #[arg(long, default_value_t = EstimateRequest::default().train_episodes, value_parser = super::episodes)]
    pub train_episodes: u64,
    /// Agent file from `unforeseen train` (default: train on --train-map).
    #[arg(long, value_name = "FILE")]
    pub agent: Option<PathBuf>,
    /// Training map (file or embedded name) when no --agent is given: the agent (or, with
    /// --train-seeds, each agent) is trained there.
    #[arg(long, value_name = "MAP", default_value_t = EstimateRequest::default().train_map, conflicts_with = "agent")]
    pub train_map: String,
    /// Training seeds and the agent cache.
    #[command(flatten)]
    pub seeds: TrainSeedArgs,
    /// No progress bars.
    #[arg(long, short)]
    pub quiet: bool,
}

/// Parses `--estimator`, listing each with its summary.
fn estimator_parser() -> impl TypedValueParser<Value = Estimator> {
    let names = Estimator::ALL.map(|e| PossibleValue::new(e.name()).help(e.summary()));
    PossibleValuesParser::new(names).map(|s| s.parse::<Estimator>().expect("a listed estimator"))
}

impl EstimateArgs {
    /// The request these arguments make.
    pub fn request(&self) -> EstimateRequest {
        EstimateRequest {
            space: self.space.clone(),
            map: self.map.clone(),
            method: self.method,
            protocol: self.protocol,
            estimator: self.estimator,
            target_rel_error: self.target_rel_error,
            budget: self.budget,
            episodes: self.episodes,
            seed: self.seed,
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

/// Runs `estimate`: the request of the arguments, planned, its agents trained and the
/// estimate run by the library ([`EstimateRequest::plan`]).
pub fn run(args: EstimateArgs) -> anyhow::Result<()> {
    let quiet = args.quiet;
    let creates = super::outputs::to_create(&args.out);
    let job = args.request().plan()?;
    super::outputs::creating("--out", creates);
    let setup = &job.setup.search;
    let to_train = setup.to_train();
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
    let agents = setup.agents(&Bars::counting(quiet, "episodes"))?;
    progress::phase(
        quiet,
        format_args!(
            "estimating P({} fails) on {} ({} parameters over {}) by {}: at most {} draws, {} episodes each, to ±{:.0}%, on {} thread(s), into {}",
            args.method.name(),
            setup.space.name,
            setup.space.params.len(),
            setup.space.base.name,
            args.estimator,
            args.budget,
            args.episodes,
            100.0 * args.target_rel_error,
            setup.jobs,
            args.out.display()
        ),
    );
    match job.run(&agents, &Bars::new(quiet))? {
        Report::Estimate(summary) => print_summary(&summary, &args),
        Report::Shard(part) => print_shard(&part, &args),
    }
    Ok(())
}

fn print_shard(p: &ShardPart, args: &EstimateArgs) {
    let out = args.out.display();
    match p.stage {
        None => outln!(
            "shard {}: {out}/estimate.jsonl holds every draw the estimate needs ({}); finish it with --resume, without --shard",
            String::from(p.shard),
            p.draws
        ),
        Some(stage) => {
            let stage = match stage {
                DrawStage::Uniform => "the uniform draws".to_string(),
                DrawStage::Round { round } => format!("cross-entropy round {}", round + 1),
                DrawStage::Final => "the final draws".to_string(),
            };
            outln!(
                "shard {} of {stage}: {} draws evaluated, {} were in the file; {out}/estimate.jsonl holds {} draws",
                String::from(p.shard),
                p.evaluated,
                p.share - p.evaluated,
                p.draws
            );
            outln!(
                "next: concatenate the shards' estimate.jsonl into one --out and run with --resume (for is and is-fails before the final draws: --resume --shard I/N again on it)"
            );
        }
    }
}

fn print_summary(s: &Summary, args: &EstimateArgs) {
    let e = &s.estimates;
    let method = args.method.name();
    outln!(
        "{} draws evaluated ({} rejected, not valid maps), {} in the estimate; {} episodes of {method}; target ±{:.0}% {}",
        s.evaluations,
        s.rejected,
        s.estimate_draws,
        s.method_episodes,
        100.0 * args.target_rel_error,
        if s.target_reached {
            "reached"
        } else {
            "not reached (budget spent)"
        }
    );
    outln!("P({method} fails):        {}", e.p_fail.text());
    outln!("P({method} fails | fair): {}", e.p_fail_given_fair.text());
    outln!("fair share of the space: {}", e.fair_share.text());
    if let Some(ess) = e.p_fail.ess {
        outln!(
            "weights: ESS {ess:.0} of {} draws, largest weight {:.1}% of the total",
            e.p_fail.draws,
            100.0 * e.p_fail.largest_weight_share.unwrap_or(0.0)
        );
    }
    outln!("interval: {}", e.p_fail.interval);
    outln!("wrote {}/{{estimate.jsonl, summary.json}}", args.out.display());
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[test]
    fn the_flags_defaults_are_the_requests() {
        let cli = super::super::Cli::parse_from(["unforeseen", "estimate", "--space", "s.ron"]);
        let Some(super::super::Command::Estimate(args)) = cli.command else {
            panic!("not estimate")
        };
        let expected = EstimateRequest {
            space: "s.ron".into(),
            ..EstimateRequest::default()
        };
        assert_eq!(args.request(), expected);
    }
}
