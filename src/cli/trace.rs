//! `unforeseen trace`: one episode step by step (paper Figs. 6-7): the arguments mapped
//! to the library's request ([`TraceRequest`]), which plans, runs and writes; the table
//! printed here.

use clap::Args;
use std::path::{Path, PathBuf};

use super::progress::{self, Bars};
use super::{AgentArgs, warn_replacing};
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::files::num;
use unforeseen_harness::reports::nearest_in_path;
use unforeseen_harness::runs::trace::{TRACE_FILES, TraceReport, TraceRequest, mode, shows_street, surprise_bits};
use unforeseen_sim::Map;

/// Arguments of `trace`.
#[derive(Debug, Clone, Args)]
pub struct TraceArgs {
    /// Map (file or embedded name).
    #[arg(long, default_value_t = TraceRequest::default().map)]
    pub map: String,
    /// Method to trace.
    #[arg(long, default_value_t = TraceRequest::default().method, value_parser = super::method_parser())]
    pub method: Method,
    /// Output folder for trace.csv, theta.svg and filmstrip.svg (files from an earlier
    /// run there are replaced, with a warning).
    #[arg(long, value_name = "DIR", default_value_os_t = TraceRequest::default().out.unwrap_or_default())]
    pub out: PathBuf,
    /// Also write the episode as one self-contained HTML page (no network) that plays
    /// the car, the pedestrians and the light beside theta and the actions, with a
    /// slider to scrub, e.g. `--html out/trace/replay.html`.
    #[arg(long, value_name = "FILE")]
    pub html: Option<PathBuf>,
    /// Evaluation episode to trace (0 = the first). Under `--protocol continual` the agent
    /// first runs and learns from episodes 0..N, as a continual evaluation does.
    #[arg(long, default_value_t = TraceRequest::default().episode, value_parser = super::episode_index)]
    pub episode: u64,
    /// Evaluation protocol of the traced episode: zero-shot (from the trained state) or
    /// continual (after learning from the episodes before it).
    #[arg(long, default_value_t = TraceRequest::default().protocol, value_parser = super::protocol_parser())]
    pub protocol: Protocol,
    /// Replace an output that holds something other than what this command writes there
    /// (a map, an agent file, another command's results); without it such a file is
    /// refused (exit 2).
    #[arg(long)]
    pub force: bool,
    /// Trained agent, parameter overrides, seed and progress.
    #[command(flatten)]
    pub agent: AgentArgs,
}

impl TraceArgs {
    /// The library's request of these arguments ([`TraceRequest`]).
    pub fn request(&self) -> TraceRequest {
        TraceRequest {
            force: self.force,
            map: self.map.clone(),
            method: self.method,
            episode: self.episode,
            protocol: self.protocol,
            sets: self.agent.set.clone(),
            seed: self.agent.seed,
            out: Some(self.out.clone()),
            html: self.html.clone(),
            agent: self.agent.agent.clone(),
        }
    }
}

/// Runs `trace`: the request of the arguments, planned, its agent trained or loaded and
/// the episode run by the library ([`TraceRequest::plan`]), then the table printed and
/// the files written.
pub fn run(args: TraceArgs) -> anyhow::Result<()> {
    let quiet = args.agent.quiet;
    let creates_html = args
        .html
        .as_deref()
        .and_then(|html| super::outputs::to_create(html.parent().unwrap_or(Path::new(""))));
    let creates = super::outputs::to_create(&args.out);
    let job = args.request().plan(None)?;
    super::outputs::creating("--html", creates_html);
    super::outputs::creating("--out", creates);
    progress::training_one(quiet, &job.agent, args.agent.seed);
    let bundle = job.agent(&Bars::counting(quiet, "episodes"))?;
    let report = job.run(&bundle)?;
    outln!(
        "{} on '{}', seed {}, episode {} ({})",
        args.method,
        job.map.name,
        args.agent.seed,
        args.episode,
        args.protocol
    );
    print_ticks(&job.map, &report);
    outln!("{}", report.summary());
    let dir = &args.out;
    warn_replacing(dir, &TRACE_FILES);
    progress::phase(quiet, format_args!("writing {}", dir.display()));
    job.write(&report)?;
    outln!("wrote {}/{}", dir.display(), TRACE_FILES.join(", "));
    if let Some(html) = &args.html {
        outln!("wrote {} (open it in a browser)", html.display());
    }
    Ok(())
}

/// The decision ticks as a table: the state, the action and how it was chosen, the
/// surprise and theta, the reward, the policy and psi; on a map with a junction or
/// traffic ([`shows_street`]) also the vehicles and the nearest in the car's path
/// (`3/1 12.4m@9.0` is three vehicles, one in its path, 12.4 m from the car's front at
/// 9.0 m/s).
fn print_ticks(map: &Map, report: &TraceReport) {
    let opt = |x: Option<f64>, d| x.map(|v| num(v, d)).unwrap_or_else(|| "-".into());
    let dist = |x: &[f64]| x.iter().map(|p| format!("{p:.2}")).collect::<Vec<_>>().join("/");
    let street = shows_street(map);
    outln!(
        "{:>4} {:>2} {:>2} {:>2} {:>2}  {:<10} {:<12} {:>8} {:>7} {:>8}  {:<14} {:<14}{}",
        "step",
        "d",
        "v",
        "L",
        "p",
        "action",
        "mode",
        "S(bits)",
        "theta",
        "reward",
        "policy",
        "psi",
        if street { "  vehicles (in path, nearest)" } else { "" }
    );
    for t in report.decided() {
        let s = t.state;
        let vehicles = if street {
            let snap = &t.snapshot;
            let seen = snap.vehicles.iter().filter(|v| v.in_path).count();
            let nearest =
                nearest_in_path(map, snap).map_or_else(String::new, |(v, gap)| format!(" {gap:.1}m@{:.1}", v.speed));
            format!("  {}/{seen}{nearest}", snap.vehicles.len())
        } else {
            String::new()
        };
        outln!(
            "{:>4} {:>2} {:>2} {:>2} {:>2}  {:<10} {:<12} {:>8} {:>7} {:>8.2}  {:<14} {:<14}{}",
            t.step,
            s.d,
            s.v,
            s.l,
            s.p,
            t.action.to_string(),
            mode(t.reasoned),
            opt(surprise_bits(t), 3),
            opt(t.theta, 3),
            t.reward,
            dist(&t.policy),
            t.psi.as_deref().map(dist).unwrap_or_else(|| "-".into()),
            vehicles,
        );
    }
}
