//! `unforeseen eval`: one method of a trained agent on a map.

use clap::Args;
use std::path::PathBuf;

use super::progress::{self, Bars};
use super::{AgentArgs, warn_replacing};
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::progress::Progress;
use unforeseen_harness::runs::evaluate::{EVAL_FILE, EvalRequest, EvalScene};

/// Arguments of `eval`.
#[derive(Debug, Clone, Args)]
pub struct EvalArgs {
    /// Map to evaluate on (file or embedded name).
    #[arg(long, default_value_t = EvalRequest::default().map)]
    pub map: String,
    /// Method to evaluate (the scripted `brake-on-pedestrian` and `never-brake` need
    /// no agent: `--agent` is then ignored and nothing is trained).
    #[arg(long, default_value_t = EvalRequest::default().method, value_parser = super::method_parser())]
    pub method: Method,
    /// Episodes.
    #[arg(long, default_value_t = EvalRequest::default().episodes, value_parser = super::episodes)]
    pub episodes: u64,
    /// Evaluation protocol: zero-shot (default; every episode starts from the trained
    /// agent, as in the paper's table) or continual (learning carries over between
    /// episodes, in order).
    #[arg(long, default_value_t = EvalRequest::default().protocol, value_parser = super::protocol_parser())]
    pub protocol: Protocol,
    /// Output folder for eval.json (an eval.json from an earlier run there is replaced,
    /// with a warning).
    #[arg(long, value_name = "DIR", default_value_os_t = EvalRequest::default().out.unwrap_or_default())]
    pub out: PathBuf,
    /// A deployment stream (a RON file listing maps with weights or a sequence; see
    /// `harness/src/runs/stream.rs` and `maps/streams/`): run the episodes over its maps instead of
    /// `--map`, and report per map within the stream.
    #[arg(long, value_name = "FILE", conflicts_with = "map")]
    pub stream: Option<PathBuf>,
    /// Replace an output that holds something other than what this command writes there
    /// (a map, an agent file, another command's results); without it such a file is
    /// refused (exit 2).
    #[arg(long)]
    pub force: bool,
    /// Trained agent, parameter overrides, seed and progress.
    #[command(flatten)]
    pub agent: AgentArgs,
}

impl EvalArgs {
    /// The library's request of these arguments ([`EvalRequest`]).
    pub fn request(&self) -> EvalRequest {
        EvalRequest {
            force: self.force,
            map: self.map.clone(),
            stream: self.stream.clone(),
            method: self.method,
            episodes: self.episodes,
            protocol: self.protocol,
            sets: self.agent.set.clone(),
            seed: self.agent.seed,
            out: Some(self.out.clone()),
            agent: self.agent.agent.clone(),
        }
    }
}

/// Runs `eval`: the request of the arguments, planned, its agent trained or loaded and
/// the episodes run by the library ([`EvalRequest::plan`]), then the line printed and
/// eval.json written.
pub fn run(args: EvalArgs) -> anyhow::Result<()> {
    let quiet = args.agent.quiet;
    let creates = super::outputs::to_create(&args.out);
    let job = args.request().plan(None)?;
    super::outputs::creating("--out", creates);
    progress::training_one(quiet, &job.agent, args.agent.seed);
    let bundle = job.agent(&Bars::counting(quiet, "episodes"))?;
    let (m, p, n) = (args.method, args.protocol, args.episodes);
    let what = match &job.scene {
        EvalScene::Map(map) => format!("evaluating {m} on '{}' ({p}, {n} episodes)", map.name),
        EvalScene::Stream(stream, _) => format!(
            "evaluating {m} on stream '{}' ({} maps, {p}, {n} episodes)",
            stream.name,
            stream.maps.len()
        ),
    };
    progress::phase(quiet, &what);
    let bars = Bars::new(quiet);
    let outcome = job.run(bundle.as_ref(), &bars)?;
    bars.finish();
    outln!("{}", outcome.table());
    let dir = &args.out;
    warn_replacing(dir, &[EVAL_FILE]);
    progress::phase(quiet, format_args!("writing {}", dir.join(EVAL_FILE).display()));
    job.write(&outcome)?;
    outln!("wrote {}/{EVAL_FILE}", dir.display());
    Ok(())
}
