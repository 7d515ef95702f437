//! `unforeseen trace`: one episode step by step (paper Figs. 6-7).

use clap::Args;
use std::path::PathBuf;

use super::{AgentArgs, warn_replacing};
use unforeseen_harness::episodes::experiments::trace;
use unforeseen_harness::episodes::methods::Method;
use unforeseen_harness::episodes::protocol::Protocol;
use unforeseen_harness::maps;
use unforeseen_harness::reports::figures::{filmstrip, theta_trace};
use unforeseen_harness::reports::files::{Csv, num, write_atomic};
use unforeseen_harness::reports::replay_page::replay_html;

/// Arguments of `trace`.
#[derive(Debug, Clone, Args)]
pub struct TraceArgs {
    /// Map (file or embedded name).
    #[arg(long, default_value = "jaywalk")]
    pub map: String,
    /// Method to trace.
    #[arg(long, default_value_t = Method::Scaled, value_parser = super::method_parser())]
    pub method: Method,
    /// Output folder for trace.csv, theta.svg and filmstrip.svg (files from an earlier
    /// run there are replaced, with a warning).
    #[arg(long, value_name = "DIR", default_value = "out/trace")]
    pub out: PathBuf,
    /// Also write the episode as one self-contained HTML page (no network) that plays
    /// the car, the pedestrians and the light beside theta and the actions, with a
    /// slider to scrub, e.g. `--html out/trace/replay.html`.
    #[arg(long, value_name = "FILE")]
    pub html: Option<PathBuf>,
    /// Evaluation episode to trace (0 = the first). Under `--protocol continual` the agent
    /// first runs and learns from episodes 0..N, as a continual evaluation does.
    #[arg(long, default_value_t = 0, value_parser = clap::value_parser!(u64).range(0..=1_000_000))]
    pub episode: u64,
    /// Evaluation protocol of the traced episode: zero-shot (from the trained state) or
    /// continual (after learning from the episodes before it).
    #[arg(long, default_value_t = Protocol::ZeroShot, value_parser = super::protocol_parser())]
    pub protocol: Protocol,
    /// Trained agent, parameter overrides, seed and progress.
    #[command(flatten)]
    pub agent: AgentArgs,
}

fn mode(reasoned: bool) -> &'static str {
    if reasoned { "reasoning" } else { "feed-forward" }
}

/// Runs `trace`.
pub fn run(args: TraceArgs) -> anyhow::Result<()> {
    if let Some(html) = &args.html {
        super::outputs::file("--html", html, args.agent.inputs().input("--map", &args.map))?;
    }
    args.agent.check_out_dir(
        &args.out,
        &["trace.csv", "theta.svg", "filmstrip.svg"],
        &[&args.map],
        None,
    )?;
    let map = maps::load(&args.map)?;
    let params = args.agent.params()?;
    let bundle = args.agent.bundle()?;
    let (result, ticks) = trace(
        &bundle,
        &params,
        args.method,
        &map,
        args.agent.seed,
        args.protocol,
        args.episode,
    )?;
    let bits = |x: Option<f64>| x.map(|s| s / std::f64::consts::LN_2);
    let opt = |x: Option<f64>, d| x.map(|v| num(v, d)).unwrap_or_else(|| "-".into());
    outln!(
        "{} on '{}', seed {}, episode {} ({})",
        args.method,
        map.name,
        args.agent.seed,
        args.episode,
        args.protocol
    );
    let dist = |x: &[f64]| x.iter().map(|p| format!("{p:.2}")).collect::<Vec<_>>().join("/");
    outln!(
        "{:>4} {:>2} {:>2} {:>2} {:>2}  {:<10} {:<12} {:>8} {:>7} {:>8}  {:<14} {:<14}",
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
        "psi"
    );
    let mut csv = Csv::new(&[
        "step",
        "d",
        "v",
        "L",
        "p",
        "action",
        "mode",
        "surprise_bits",
        "theta",
        "reward",
        "policy",
        "psi",
        "car_x",
        "car_speed",
        "light",
    ]);
    let decided = &ticks[..ticks.len().saturating_sub(1)];
    for t in decided {
        let s = t.state;
        outln!(
            "{:>4} {:>2} {:>2} {:>2} {:>2}  {:<10} {:<12} {:>8} {:>7} {:>8.2}  {:<14} {:<14}",
            t.step,
            s.d,
            s.v,
            s.l,
            s.p,
            t.action.to_string(),
            mode(t.reasoned),
            opt(bits(t.surprise), 3),
            opt(t.theta, 3),
            t.reward,
            dist(&t.policy),
            t.psi.as_deref().map(dist).unwrap_or_else(|| "-".into()),
        );
        csv.row(vec![
            t.step.to_string(),
            s.d.to_string(),
            s.v.to_string(),
            s.l.to_string(),
            s.p.to_string(),
            t.action.to_string(),
            mode(t.reasoned).into(),
            opt(bits(t.surprise), 6),
            opt(t.theta, 6),
            num(t.reward, 4),
            t.policy.iter().map(|p| num(*p, 6)).collect::<Vec<_>>().join(" "),
            t.psi
                .as_deref()
                .map(|x| x.iter().map(|p| num(*p, 6)).collect::<Vec<_>>().join(" "))
                .unwrap_or_default(),
            num(t.snapshot.car_x, 3),
            num(t.snapshot.car_speed, 3),
            format!("{:?}", t.snapshot.light),
        ]);
    }
    let outcome = if result.success {
        "reached the destination"
    } else if result.collision {
        "hit a pedestrian"
    } else {
        "ran out of time"
    };
    outln!(
        "{outcome} after {} ticks, return {:.2}, reasoned on {} ticks",
        result.ticks,
        result.ret,
        result.reasoning_ticks
    );
    let dir = &args.out;
    warn_replacing(dir, &["trace.csv", "theta.svg", "filmstrip.svg"]);
    super::progress::phase(args.agent.quiet, format_args!("writing {}", dir.display()));
    csv.write(&dir.join("trace.csv"))?;
    let points: Vec<_> = decided
        .iter()
        .map(|t| (t.step, t.theta, t.reasoned, t.action.to_string()))
        .collect();
    theta_trace(
        &dir.join("theta.svg"),
        &format!("{} on {}: normalized surprise", args.method, map.name),
        &points,
        params.gate.epsilon,
    )?;
    filmstrip(
        &dir.join("filmstrip.svg"),
        &format!(
            "{} on {}, seed {}: {outcome} after {} ticks (from above, one strip per decision tick)",
            args.method, map.name, args.agent.seed, result.ticks
        ),
        &map,
        &ticks,
    )?;
    outln!("wrote {}/trace.csv, theta.svg, filmstrip.svg", dir.display());
    if let Some(html) = &args.html {
        let title = format!("{} on {}, seed {}", args.method, map.name, args.agent.seed);
        let outcome = format!(
            "{} {outcome} after {} ticks, return {:.2}, reasoned on {} ticks",
            args.method, result.ticks, result.ret, result.reasoning_ticks
        );
        let page = replay_html(&title, &outcome, &map, &ticks, params.gate.epsilon)?;
        write_atomic(html, page.as_bytes())?;
        outln!("wrote {} (open it in a browser)", html.display());
    }
    Ok(())
}
