//! `unforeseen plot-sweep results.jsonl`: the measured test-time scaling law — success
//! and reward against reasoning compute, one panel pair per swept parameter.

use clap::Args;
use plotters::style::RGBColor;
use std::collections::BTreeMap;
use std::path::PathBuf;

use unforeseen_harness::error::Error;
use unforeseen_harness::reports::figures::{Series, line_panels};
use unforeseen_harness::runs::batch::ResultLine;
use unforeseen_harness::runs::outputs::Own;

/// Arguments of `plot-sweep`.
#[derive(Debug, Clone, Args)]
pub struct PlotSweepArgs {
    /// Results file written by `unforeseen batch --set ...`.
    #[arg(value_name = "RESULTS.jsonl")]
    pub results: PathBuf,
    /// Output SVG.
    #[arg(long, value_name = "FILE", default_value = "sweep.svg")]
    pub out: PathBuf,
    /// Plot a run that is not whole (a shard, a run cut short), saying which units are
    /// missing; without it such a file is refused (exit 2), listing them.
    #[arg(long)]
    pub partial: bool,
    /// Replace --out even when it holds something other than an SVG figure; without it such a
    /// file is refused (exit 2).
    #[arg(long)]
    pub force: bool,
}

/// One series before plotting: key label, colour, points.
type SeriesData = (String, RGBColor, Vec<(f64, f64)>);

/// Reads an x value off a result line.
type XOf = Box<dyn Fn(&unforeseen_harness::runs::batch::ResultLine) -> Option<f64>>;

/// Distinct colours, readable on white (Paul Tol's "bright" and "muted" schemes), in turn.
const COLORS: [RGBColor; 12] = [
    RGBColor(68, 119, 170),
    RGBColor(238, 102, 119),
    RGBColor(34, 136, 51),
    RGBColor(204, 187, 68),
    RGBColor(102, 204, 238),
    RGBColor(170, 51, 119),
    RGBColor(0, 0, 0),
    RGBColor(136, 34, 85),
    RGBColor(17, 119, 51),
    RGBColor(221, 204, 119),
    RGBColor(51, 34, 136),
    RGBColor(187, 187, 187),
];

/// The result lines of `path` for one plot, read against the run its identity names
/// (`runs::merge::read_run`: two runs refused, a partial run refused unless `partial`);
/// says on stderr how many lines were cut (a last line without its newline, not read),
/// how many repeated a unit already read (left out, the first kept) and, with
/// `--partial`, which units are missing.
fn checked_lines(path: &std::path::Path, partial: bool) -> Result<Vec<ResultLine>, Error> {
    let run = unforeseen_harness::runs::merge::read_run(path, partial)?;
    if let Some(n) = run.cut_line {
        errln!(
            "warning: {}: line {n} is cut (no newline at its end: a killed run or a full disk?); left out",
            path.display()
        );
    }
    if run.repeated > 0 {
        errln!(
            "warning: {}: {} line(s) repeat a unit read already (duplicated lines?); each unit is plotted once, from its first line",
            path.display(),
            run.repeated
        );
    }
    if let Some(what) = &run.missing {
        errln!("warning: {}: --partial: {what}", path.display());
    }
    Ok(run.lines)
}

/// Runs `plot-sweep`.
pub fn run(args: PlotSweepArgs) -> anyhow::Result<()> {
    super::outputs::file(
        "--out",
        &args.out,
        Own::Svg,
        args.force,
        unforeseen_harness::runs::outputs::Outputs::new().input("RESULTS.jsonl", &args.results),
    )?;
    let lines = checked_lines(&args.results, args.partial)?;
    if lines.is_empty() {
        return Err(Error::Results {
            path: args.results.clone(),
            problem: format!(
                "no result lines; run `unforeseen batch --set KEY=V1,V2 --out {}` first",
                args.results.display()
            ),
        }
        .into());
    }
    // Swept keys: those taking more than one numeric value.
    let mut values: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for l in &lines {
        for (k, v) in &l.params {
            if let Ok(x) = v.parse::<f64>() {
                values.entry(k.clone()).or_default().push(x);
            }
        }
    }
    let keys: Vec<String> = values
        .into_iter()
        .filter(|(_, v)| v.iter().any(|x| *x != v[0]))
        .map(|(k, _)| k)
        .collect();
    let mut x_axes: Vec<(String, Option<String>, XOf)> = keys
        .iter()
        .map(|k| {
            let key = k.clone();
            let f: XOf = Box::new(move |l| {
                l.params
                    .iter()
                    .find(|(kk, _)| *kk == key)
                    .and_then(|(_, v)| v.parse().ok())
            });
            (k.clone(), Some(k.clone()), f)
        })
        .collect();
    x_axes.push((
        "EFE mat-vecs per tick (reasoning compute)".into(),
        None,
        Box::new(|l| Some(l.efe_matvecs_per_tick)),
    ));
    // Against one swept key, each setting of the other swept keys is its own series (a
    // line through points that differ in another parameter would zigzag).
    let others = |l: &unforeseen_harness::runs::batch::ResultLine, x_key: &Option<String>| -> String {
        let Some(x_key) = x_key else { return String::new() };
        l.params
            .iter()
            .filter(|(k, _)| k != x_key && keys.contains(k))
            .map(|(k, v)| format!("{k}={v}"))
            .collect::<Vec<_>>()
            .join(", ")
    };

    let mut panels: Vec<(String, Vec<SeriesData>)> = Vec::new();
    // One series per (scenario, method, protocol[, other swept parameters]); one point
    // per parameter set, averaged over its training seeds.
    for (name, x_key, x_of) in &x_axes {
        let mut groups: Vec<(String, String, String, String)> = lines
            .iter()
            .map(|l| {
                (
                    l.scenario.clone(),
                    l.method.clone(),
                    l.protocol.to_string(),
                    others(l, x_key),
                )
            })
            .collect();
        groups.sort();
        groups.dedup();
        for (figure, y_of) in [
            (
                "success rate",
                (|l: &unforeseen_harness::runs::batch::ResultLine| l.success_rate) as fn(&_) -> f64,
            ),
            ("mean reward", |l| l.mean_reward),
            ("inference rate", |l| l.inference_rate),
        ] {
            let series = groups
                .iter()
                .map(|(scenario, method, protocol, other)| {
                    let points: Vec<(String, f64, f64)> = lines
                        .iter()
                        .filter(|l| {
                            &l.scenario == scenario
                                && &l.method == method
                                && l.protocol.name() == protocol
                                && &others(l, x_key) == other
                        })
                        .filter_map(|l| x_of(l).map(|x| (l.param_set.clone(), x, y_of(l))))
                        .collect();
                    let label = if other.is_empty() {
                        format!("{scenario} / {method} / {protocol}")
                    } else {
                        format!("{scenario} / {method} / {protocol}, {other}")
                    };
                    (label, mean_by_param_set(points))
                })
                // A method the swept parameter does not affect ran once, unswept: no series.
                .filter(|(_, points)| !points.is_empty())
                .enumerate()
                .map(|(i, (label, points))| (label, COLORS[i % COLORS.len()], points))
                .collect();
            panels.push((format!("{figure} vs {name}"), series));
        }
    }
    let panels: Vec<(&str, Vec<Series<'_>>)> = panels
        .iter()
        .map(|(title, series)| {
            (
                title.as_str(),
                series
                    .iter()
                    .map(|(label, color, points)| Series {
                        label,
                        points: points.clone(),
                        color: *color,
                    })
                    .collect(),
            )
        })
        .collect();
    super::warn_replacing_file(&args.out);
    line_panels(
        &args.out,
        "x as named in the panel title (each point: mean over training seeds)",
        &panels,
    )?;
    outln!(
        "wrote {} ({} panels over {} result lines)",
        args.out.display(),
        panels.len(),
        lines.len()
    );
    Ok(())
}

/// One point per parameter set: x and y averaged over its lines (the training seeds), sorted by x.
fn mean_by_param_set(mut points: Vec<(String, f64, f64)>) -> Vec<(f64, f64)> {
    points.sort_by(|a, b| a.0.cmp(&b.0));
    let mut out: Vec<(String, f64, f64, usize)> = Vec::new();
    for (set, x, y) in points {
        match out.last_mut() {
            Some(last) if last.0 == set => {
                last.1 += x;
                last.2 += y;
                last.3 += 1;
            }
            _ => out.push((set, x, y, 1)),
        }
    }
    let mut out: Vec<(f64, f64)> = out
        .into_iter()
        .map(|(_, x, y, n)| (x / n as f64, y / n as f64))
        .collect();
    out.sort_by(|a, b| a.0.total_cmp(&b.0));
    out
}
