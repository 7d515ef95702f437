//! `unforeseen eval`: one method of a trained agent on a map.

use clap::Args;
use std::path::PathBuf;

use super::progress::{self, Bars};
use super::{AgentArgs, warn_replacing};
use unforeseen_harness::episodes::experiments::evaluate_map;
use unforeseen_harness::episodes::methods::Method;
use unforeseen_harness::episodes::protocol::Protocol;
use unforeseen_harness::maps;
use unforeseen_harness::progress::Progress;
use unforeseen_harness::reports::files::write_json;
use unforeseen_harness::reports::tables;

/// Arguments of `eval`.
#[derive(Debug, Clone, Args)]
pub struct EvalArgs {
    /// Map to evaluate on (file or embedded name).
    #[arg(long, default_value = "jaywalk")]
    pub map: String,
    /// Method to evaluate (the scripted `brake-on-pedestrian` and `never-brake` need
    /// no agent: `--agent` is then ignored and nothing is trained).
    #[arg(long, default_value_t = Method::Scaled, value_parser = super::method_parser())]
    pub method: Method,
    /// Episodes.
    #[arg(long, default_value_t = 100, value_parser = super::episodes)]
    pub episodes: u64,
    /// Evaluation protocol: zero-shot (default; every episode starts from the trained
    /// agent, as in the paper's table) or continual (learning carries over between
    /// episodes, in order).
    #[arg(long, default_value_t = Protocol::ZeroShot, value_parser = super::protocol_parser())]
    pub protocol: Protocol,
    /// Output folder for eval.json (an eval.json from an earlier run there is replaced,
    /// with a warning).
    #[arg(long, value_name = "DIR", default_value = "out/eval")]
    pub out: PathBuf,
    /// A deployment stream (a RON file listing maps with weights or a sequence; see
    /// `harness/src/runs/stream.rs` and `maps/streams/`): run the episodes over its maps instead of
    /// `--map`, and report per map within the stream.
    #[arg(long, value_name = "FILE", conflicts_with = "map")]
    pub stream: Option<PathBuf>,
    /// Trained agent, parameter overrides, seed and progress.
    #[command(flatten)]
    pub agent: AgentArgs,
}

/// Runs `eval`.
pub fn run(args: EvalArgs) -> anyhow::Result<()> {
    if let Some(file) = &args.stream {
        return run_stream(&args, file);
    }
    args.agent
        .check_out_dir(&args.out, &["eval.json"], &[&args.map], None)?;
    let map = maps::load(&args.map)?;
    let params = args.agent.params()?;
    let bars = Bars::new(args.agent.quiet);
    let label = format!("{} {}", args.method, map.name);
    let evaluating = format!(
        "evaluating {} on '{}' ({}, {} episodes)",
        args.method, map.name, args.protocol, args.episodes
    );
    // The scripted references need no agent: they decode the map's own observations.
    let bundle = if args.method.is_scripted() {
        None
    } else {
        Some(args.agent.bundle()?)
    };
    progress::phase(args.agent.quiet, &evaluating);
    bars.phase(&label, args.episodes);
    let report = evaluate_map(
        &map,
        args.method,
        args.protocol,
        bundle.as_ref(),
        &params,
        args.episodes,
        args.agent.seed,
        &bars,
    )?;
    bars.finish();
    outln!("{}", tables::eval(&report));
    let dir = &args.out;
    warn_replacing(dir, &["eval.json"]);
    progress::phase(
        args.agent.quiet,
        format_args!("writing {}", dir.join("eval.json").display()),
    );
    write_json(&dir.join("eval.json"), &report.document()?)?;
    outln!("wrote {}/eval.json", dir.display());
    Ok(())
}

/// `eval --stream FILE`: the episodes over the stream's maps, one row per map.
fn run_stream(args: &EvalArgs, file: &std::path::Path) -> anyhow::Result<()> {
    use unforeseen_harness::runs::stream::{Stream, StreamEvalReport, evaluate_stream};
    let stream = Stream::load(file)?;
    let inputs = unforeseen_harness::runs::outputs::Outputs::new().stream("--stream", file, &stream);
    args.agent.check_out_dir(&args.out, &["eval.json"], &[], Some(inputs))?;
    let params = args.agent.params()?;
    let bundle = if args.method.is_scripted() {
        None
    } else {
        Some(args.agent.bundle()?)
    };
    let bars = Bars::new(args.agent.quiet);
    progress::phase(
        args.agent.quiet,
        format_args!(
            "evaluating {} on stream '{}' ({} maps, {}, {} episodes)",
            args.method,
            stream.name,
            stream.maps.len(),
            args.protocol,
            args.episodes
        ),
    );
    bars.phase(&format!("{} {}", args.method, stream.name), args.episodes);
    let episodes = evaluate_stream(
        &stream,
        bundle.as_ref(),
        &params,
        args.method,
        args.protocol,
        args.episodes,
        args.agent.seed,
        &bars,
    )?;
    bars.finish();
    let report = StreamEvalReport::new(
        &stream,
        file,
        args.method,
        args.protocol,
        &params,
        args.agent.seed,
        bundle.as_ref(),
        episodes,
    );
    outln!("{}", tables::eval_stream(&report));
    let dir = &args.out;
    warn_replacing(dir, &["eval.json"]);
    write_json(&dir.join("eval.json"), &report.document()?)?;
    outln!("wrote {}/eval.json", dir.display());
    Ok(())
}
