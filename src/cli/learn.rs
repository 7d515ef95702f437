//! `unforeseen learn`: test-time learning curves over repeated encounters (paper Fig. 9),
//! on one map or over a deployment stream (`--stream`, [`unforeseen_harness::runs::stream::learn_stream`]).

use clap::Args;
use plotters::style::{BLUE, RED, RGBColor};
use std::path::PathBuf;

use super::{AgentArgs, warn_replacing};
use unforeseen_harness::episodes::experiments::{LearnPoint, learn};
use unforeseen_harness::maps;
use unforeseen_harness::reports::figures::{Series, line_panels};
use unforeseen_harness::reports::files::{Csv, num, write_json};
use unforeseen_harness::reports::tables::Grid;
use unforeseen_harness::runs::outputs::Outputs;
use unforeseen_harness::runs::stream::{Stream, learn_stream};

/// Arguments of `learn`.
#[derive(Debug, Clone, Args)]
pub struct LearnArgs {
    /// Map with the unforeseen scenario (file or embedded name).
    #[arg(long, default_value = "jaywalk")]
    pub map: String,
    /// Episodes of test-time learning.
    #[arg(long, default_value_t = 50, value_parser = super::episodes)]
    pub episodes: u64,
    /// Output folder for learn.csv, learn.json and learn.svg (files from an earlier run
    /// there are replaced, with a warning).
    #[arg(long, value_name = "DIR", default_value = "out/learn")]
    pub out: PathBuf,
    /// A deployment stream (a RON file listing maps with weights or a sequence; see
    /// `harness/src/runs/stream.rs` and `maps/streams/`): learn across its maps instead of `--map`;
    /// learn.csv's `map` column says which map each episode ran on, and the summary
    /// gives the figures per map.
    #[arg(long, value_name = "FILE", conflicts_with = "map")]
    pub stream: Option<PathBuf>,
    /// Trained agent, parameter overrides, seed and progress.
    #[command(flatten)]
    pub agent: AgentArgs,
}

/// What `learn` learns on.
enum Subject {
    /// One map (`--map`).
    Map(Box<unforeseen_sim::Map>),
    /// A deployment stream (`--stream`).
    Stream(Stream),
}

/// Runs `learn`.
pub fn run(args: LearnArgs) -> anyhow::Result<()> {
    const OUTPUTS: [&str; 3] = ["learn.csv", "learn.json", "learn.svg"];
    // What the agent learns on: one map, or a stream of them.
    let subject = match &args.stream {
        Some(file) => {
            let stream = Stream::load(file)?;
            let inputs = Outputs::new().stream("--stream", file, &stream);
            args.agent.check_out_dir(&args.out, &OUTPUTS, &[], Some(inputs))?;
            Subject::Stream(stream)
        }
        None => {
            args.agent.check_out_dir(&args.out, &OUTPUTS, &[&args.map], None)?;
            Subject::Map(Box::new(maps::load(&args.map)?))
        }
    };
    let params = args.agent.params()?;
    let bundle = args.agent.bundle()?;
    let on = match &subject {
        Subject::Map(map) => format!("'{}'", map.name),
        Subject::Stream(stream) => format!("the stream '{}' ({} maps)", stream.name, stream.maps.len()),
    };
    super::progress::phase(
        args.agent.quiet,
        format_args!("test-time learning on {on} over {} episodes (continual)", args.episodes),
    );
    let bars = super::progress::Bars::new(args.agent.quiet);
    let (episodes, seed) = (args.episodes, args.agent.seed);
    let points = match &subject {
        Subject::Map(map) => learn(&bundle, &params, map, episodes, seed, &bars)?,
        Subject::Stream(stream) => learn_stream(stream, &bundle, &params, episodes, seed, &bars)?,
    };
    let mut csv = Csv::new(&[
        "episode",
        "map",
        "event_surprise_bits",
        "p_pedestrian_green_d2",
        "p_stay_green_d2",
        "p_slow_down",
        "reasoning_ticks",
        "inference_rate",
        "success",
        "reward",
    ]);
    let opt = |x: Option<f64>, d| x.map(|v| num(v, d)).unwrap_or_default();
    for p in &points {
        csv.row(vec![
            p.episode.to_string(),
            p.map.clone(),
            opt(p.event_surprise_bits, 4),
            opt(p.p_pedestrian_green_d2, 5),
            num(p.p_stay_green_d2, 5),
            num(p.p_slow_down, 5),
            p.reasoning_ticks.to_string(),
            num(p.inference_rate, 4),
            p.success.to_string(),
            num(p.reward, 3),
        ]);
    }
    if let Subject::Stream(stream) = &subject {
        print_per_map(stream, &points);
    } else if let (Some(first), Some(last)) = (points.first(), points.last()) {
        let shown = |x: Option<f64>, unit: &str| x.map(|b| format!("{b:.2}{unit}")).unwrap_or_else(|| "n/a".into());
        outln!(
            "test-time learning on {on} over {} episodes, continual protocol (paper's Fig. 9 in parentheses):",
            points.len()
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
        outln!(
            "  successes                       {}/{}",
            points.iter().filter(|p| p.success).count(),
            points.len()
        );
    }
    let dir = &args.out;
    warn_replacing(dir, &OUTPUTS);
    super::progress::phase(args.agent.quiet, format_args!("writing {}", dir.display()));
    // All three or none: a failed write (a full disk) leaves the previous run's set.
    unforeseen_harness::reports::files::all_or_none(|| -> anyhow::Result<()> {
        csv.write(&dir.join("learn.csv"))?;
        write_json(&dir.join("learn.json"), &points)?;
        let x = |f: &dyn Fn(&LearnPoint) -> Option<f64>| -> Vec<(f64, f64)> {
            points
                .iter()
                .filter_map(|p| f(p).map(|y| (p.episode as f64, y)))
                .collect()
        };
        line_panels(
            &dir.join("learn.svg"),
            "episode of test-time learning",
            &[
                (
                    "(a) surprise at the event (bits)",
                    vec![Series {
                        label: "gate's surprise at the first pedestrian on green",
                        points: x(&|p| p.event_surprise_bits),
                        color: RED,
                    }],
                ),
                (
                    "(b) pedestrian on green at d = 2",
                    vec![
                        Series {
                            label: "gate: P(p=1 | L=1, d=2)",
                            points: x(&|p| p.p_pedestrian_green_d2),
                            color: BLUE,
                        },
                        Series {
                            label: "planner: P(p'=1 | p=1, L'=1, d'=2)",
                            points: x(&|p| Some(p.p_stay_green_d2)),
                            color: RGBColor(0, 150, 0),
                        },
                    ],
                ),
                (
                    "(c) policy: pi_o(slow down | event state)",
                    vec![Series {
                        label: "P(slow down)",
                        points: x(&|p| Some(p.p_slow_down)),
                        color: BLUE,
                    }],
                ),
            ],
        )?;
        Ok(())
    })?;
    outln!("wrote {}/learn.csv, learn.json, learn.svg", dir.display());
    Ok(())
}

/// The figures of a stream's learning curve per map, in the stream's order: its
/// episodes and successes, and the first and last of its episodes' surprise at the event,
/// `pi_o(slow down | event state)` and reasoning ticks.
fn print_per_map(stream: &Stream, points: &[LearnPoint]) {
    outln!(
        "test-time learning over the stream '{}' ({} episodes, continual protocol), per map (its first -> last episode):",
        stream.name,
        points.len()
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
    for (map, _) in &stream.maps {
        let on: Vec<&LearnPoint> = points.iter().filter(|p| p.map == map.name).collect();
        let (Some(first), Some(last)) = (on.first(), on.last()) else {
            continue;
        };
        grid.push(vec![
            map.name.clone(),
            on.len().to_string(),
            format!("{}/{}", on.iter().filter(|p| p.success).count(), on.len()),
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
