//! `unforeseen compare`: the paper's table (§VI, Fig. 8) beside the paper's values, one
//! table per protocol (zero-shot first, then continual), over one agent or over several
//! independently trained agents (`--train-seeds`).

use clap::Args;
use std::path::{Path, PathBuf};

use super::progress::{self, Bars};
use super::train_seeds::TrainSeedArgs;
use super::{AgentArgs, warn_replacing};
use unforeseen_harness::episodes::ProtocolChoice;
use unforeseen_harness::runs::batch::AgentChoice;
use unforeseen_harness::runs::compare::compare_table;
use unforeseen_harness::runs::compare::{COMPARE_FILES, CompareRequest};

/// Arguments of `compare`.
#[derive(Debug, Clone, Args)]
pub struct CompareArgs {
    /// Training map (file or embedded name).
    #[arg(long, default_value_t = CompareRequest::default().train_map)]
    pub train_map: String,
    /// Test map with the unforeseen scenario (file or embedded name).
    #[arg(long, default_value_t = CompareRequest::default().test_map)]
    pub test_map: String,
    /// Training episodes when no --agent is given.
    #[arg(long, default_value_t = CompareRequest::default().train_episodes, value_parser = super::episodes)]
    pub train_episodes: u64,
    /// Evaluation episodes per method, map and agent.
    #[arg(long, default_value_t = CompareRequest::default().episodes, value_parser = super::episodes)]
    pub episodes: u64,
    /// Also run the ablations (bayes-rl-factored, scaled-always, scaled-no-learning).
    #[arg(long)]
    pub ablations: bool,
    /// Evaluation protocol: zero-shot (every test episode starts from the trained agent,
    /// the paper's table), continual (learning carries over between test episodes, in
    /// order) or both (zero-shot table first).
    #[arg(long, default_value_t = CompareRequest::default().protocol, value_parser = super::protocol_choice_parser())]
    pub protocol: ProtocolChoice,
    /// Output folder for compare.json, compare.csv, compare_seeds.csv and compare.svg
    /// (files from an earlier run there are replaced, with a warning).
    #[arg(long, value_name = "DIR", default_value_os_t = CompareRequest::default().out.unwrap_or_default())]
    pub out: PathBuf,
    /// Training seeds and the agent cache.
    #[command(flatten)]
    pub seeds: TrainSeedArgs,
    /// Replace an output that holds something other than what this command writes there
    /// (a map, an agent file, another command's results); without it such a file is
    /// refused (exit 2).
    #[arg(long)]
    pub force: bool,
    /// Trained agent, parameter overrides, seed and progress.
    #[command(flatten)]
    pub agent: AgentArgs,
}

impl Default for CompareArgs {
    /// The flags' defaults: `unforeseen compare` with no arguments (what `cargo run`
    /// runs), so that no default is spelled twice.
    fn default() -> Self {
        #[derive(clap::Parser)]
        struct Flags {
            #[command(flatten)]
            args: CompareArgs,
        }
        <Flags as clap::Parser>::parse_from(["unforeseen"]).args
    }
}

impl CompareArgs {
    /// The library's request of these arguments ([`CompareRequest`]).
    pub fn request(&self) -> CompareRequest {
        CompareRequest {
            force: self.force,
            train_map: self.train_map.clone(),
            test_map: self.test_map.clone(),
            train_episodes: self.train_episodes,
            episodes: self.episodes,
            ablations: self.ablations,
            protocol: self.protocol,
            sets: self.agent.set.clone(),
            seed: self.agent.seed,
            out: Some(self.out.clone()),
            agent: self.agent.agent.clone(),
            train_seeds: self.seeds.train_seeds.clone(),
            timeout_as: self.seeds.timeout_as,
            cache: self.seeds.cache_dir().map(Path::to_path_buf),
        }
    }
}

/// Runs `compare`: the request of the arguments, planned, its agents trained or loaded
/// and the study run by the library ([`CompareRequest::plan`]), then the tables printed
/// and the files written.
pub fn run(args: CompareArgs) -> anyhow::Result<()> {
    let quiet = args.agent.quiet;
    let creates = super::outputs::to_create(&args.out);
    let job = args.request().plan(Vec::new())?;
    super::outputs::creating("--out", creates);
    if let AgentChoice::Trained { map, seeds, .. } = &job.agents {
        let per_seed = args.seeds.train_seeds.is_some();
        progress::training(
            quiet,
            per_seed,
            seeds.len(),
            args.train_episodes,
            &map.name,
            args.agent.seed,
        );
    }
    let agents = job.agents(&Bars::counting(quiet, "episodes"))?;
    let report = job.run(&agents, &Bars::new(quiet))?;
    outln!("{}", compare_table(&report));
    let dir = &args.out;
    warn_replacing(dir, &COMPARE_FILES);
    progress::phase(quiet, format_args!("writing {}", dir.display()));
    job.write(&report)?;
    outln!("wrote {}/{}", dir.display(), COMPARE_FILES.join(", "));
    Ok(())
}
