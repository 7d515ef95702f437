//! `unforeseen learn`: test-time learning curves over repeated encounters (paper Fig. 9),
//! on one map or over a deployment stream (`--stream`): the arguments mapped to the
//! library's request ([`LearnRequest`]), which plans, runs and writes; the figures printed here.

use clap::Args;
use std::path::PathBuf;

use super::progress::{self, Bars};
use super::{AgentArgs, warn_replacing};
use unforeseen_harness::reports::Grid;
use unforeseen_harness::runs::learn::{LEARN_FILES, LearnReport, LearnRequest, MapLearning};

/// Arguments of `learn`.
#[derive(Debug, Clone, Args)]
pub struct LearnArgs {
    /// Map with the unforeseen scenario (file or embedded name).
    #[arg(long, default_value_t = LearnRequest::default().map)]
    pub map: String,
    /// Episodes of test-time learning.
    #[arg(long, default_value_t = LearnRequest::default().episodes, value_parser = super::episodes)]
    pub episodes: u64,
    /// Output folder for learn.csv, learn.json and learn.svg (files from an earlier run
    /// there are replaced, with a warning).
    #[arg(long, value_name = "DIR", default_value_os_t = LearnRequest::default().out.unwrap_or_default())]
    pub out: PathBuf,
    /// A deployment stream (a RON file listing maps with weights or a sequence; see
    /// `harness/src/runs/stream.rs` and `maps/streams/`): learn across its maps instead of `--map`;
    /// learn.csv's `map` column says which map each episode ran on, and the summary
    /// gives the figures per map.
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

impl LearnArgs {
    /// The library's request of these arguments ([`LearnRequest`]).
    pub fn request(&self) -> LearnRequest {
        LearnRequest {
            force: self.force,
            map: self.map.clone(),
            stream: self.stream.clone(),
            episodes: self.episodes,
            sets: self.agent.set.clone(),
            seed: self.agent.seed,
            out: Some(self.out.clone()),
            agent: self.agent.agent.clone(),
        }
    }
}

/// Runs `learn`: the request of the arguments, planned, its agent trained or loaded and
/// the episodes run by the library ([`LearnRequest::plan`]), then the figures printed
/// and learn.csv, learn.json and learn.svg written.
pub fn run(args: LearnArgs) -> anyhow::Result<()> {
    let quiet = args.agent.quiet;
    let creates = super::outputs::to_create(&args.out);
    let job = args.request().plan(None)?;
    super::outputs::creating("--out", creates);
    progress::training_one(quiet, &job.agent, args.agent.seed);
    let bundle = job.agent(&Bars::counting(quiet, "episodes"))?;
    let on = job.on();
    progress::phase(
        quiet,
        format_args!("test-time learning on {on} over {} episodes (continual)", args.episodes),
    );
    let bars = Bars::new(quiet);
    let report = job.run(&bundle, &bars)?;
    match &report.stream {
        Some(stream) => print_per_map(stream, &report),
        None => print_curve(&on, &report),
    }
    let dir = &args.out;
    warn_replacing(dir, &LEARN_FILES);
    progress::phase(quiet, format_args!("writing {}", dir.display()));
    job.write(&report)?;
    outln!("wrote {}/{}", dir.display(), LEARN_FILES.join(", "));
    Ok(())
}

/// A map's curve: its first and last episode beside the paper's Fig. 9, and its successes.
fn print_curve(on: &str, report: &LearnReport) {
    let Some(MapLearning {
        first,
        last,
        episodes,
        successes,
        ..
    }) = report.per_map.first()
    else {
        return;
    };
    let shown = |x: Option<f64>, unit: &str| x.map(|b| format!("{b:.2}{unit}")).unwrap_or_else(|| "n/a".into());
    outln!(
        "test-time learning on {on} over {} episodes, continual protocol (paper's Fig. 9 in parentheses):",
        report.points.len()
    );
    outln!(
        "  surprise at the event           {} -> {}   (1.95 -> ~0.2 bits)",
        shown(first.event_surprise_bits, " bits"),
        shown(last.event_surprise_bits, " bits")
    );
    outln!(
        "  P(p=1 | L=1, d=2)               {} -> {}   (0.25 -> 0.9)",
        shown(first.p_pedestrian_green_d2, ""),
        shown(last.p_pedestrian_green_d2, "")
    );
    outln!(
        "  pi_o(slow down | event state)   {:.2} -> {:.2}   (0.3 -> 0.92)",
        first.p_slow_down,
        last.p_slow_down
    );
    outln!(
        "  planner's P(p'=1 | p=1, L'=1, d'=2)  {:.2} -> {:.2}",
        first.p_stay_green_d2,
        last.p_stay_green_d2
    );
    outln!(
        "  reasoning ticks per episode     {} -> {}",
        first.reasoning_ticks,
        last.reasoning_ticks
    );
    outln!("  successes                       {successes}/{episodes}");
}

/// A stream's curve per map, in the stream's order ([`LearnReport::per_map`]): its
/// episodes and successes, and the first and last of its episodes' surprise at the event,
/// `pi_o(slow down | event state)` and reasoning ticks.
fn print_per_map(stream: &str, report: &LearnReport) {
    outln!(
        "test-time learning over the stream '{stream}' ({} episodes, continual protocol), per map (its first -> last episode):",
        report.points.len()
    );
    let mut grid = vec![
        [
            "map",
            "episodes",
            "successes",
            "surprise at the event (bits)",
            "P(slow down | event)",
            "reasoning ticks",
        ]
        .map(String::from)
        .to_vec(),
    ];
    let shown = |x: Option<f64>| x.map(|b| format!("{b:.2}")).unwrap_or_else(|| "n/a".into());
    for m in &report.per_map {
        let (first, last) = (&m.first, &m.last);
        grid.push(vec![
            m.map.clone(),
            m.episodes.to_string(),
            format!("{}/{}", m.successes, m.episodes),
            format!(
                "{} -> {}",
                shown(first.event_surprise_bits),
                shown(last.event_surprise_bits)
            ),
            format!("{:.2} -> {:.2}", first.p_slow_down, last.p_slow_down),
            format!("{} -> {}", first.reasoning_ticks, last.reasoning_ticks),
        ]);
    }
    outln!(
        "{}",
        Grid {
            header_rows: 1,
            rows: grid
        }
    );
}
