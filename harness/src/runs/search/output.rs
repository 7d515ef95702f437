//! What a search writes into its folder:
//!
//! * `candidates.jsonl`: the run's identity (`{"search": {...}}`), then one line per
//!   evaluation of every candidate (the two witnesses, then the method per training
//!   seed), in candidate order. Each line is a batch result line ([`ResultLine`]'s
//!   fields, its `scenario` the candidate's map) with the candidate's number, stage,
//!   parameter values, fairness and failure verdict.
//! * `failures/NAME.ron`: each distinct minimised fair failure as a complete map, whose
//!   comments give the parameters it changes, the figures measured on it and the
//!   commands that found it and re-run it (`unforeseen batch` with the same seed and
//!   episodes meets the same pedestrians and reproduces the figures).
//! * `summary.json` ([`Summary`]): the failure probability on the fair part of the space
//!   from the Sobol stage, per training seed with its 95% Wilson interval and over the
//!   seeds with a Student-t interval; the share of the space that is fair; the counts of
//!   candidates by stage and verdict; the rejected points with their reasons; the
//!   failures found.
//! * `search.svg`: the success of the method's worst agent (training seed) over the two
//!   parameters that matter most (the largest |correlation| between a parameter's
//!   coordinate and that success over fair candidates), unfair candidates in grey, failures ringed and the
//!   minimised failures as squares.

use plotters::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

use super::fairness::{FailureThreshold, Fairness};
use super::minimise::Minimised;
use super::space::{Domain, Value, map_ron};
use super::{Evaluated, Outcome, Role, SearchConfig, SearchIdentity, Stage};
use crate::error::Error;
use crate::reports::figures::{plot_err, tick_label, write_svg};
use crate::runs::batch::ResultLine;
use crate::runs::outputs::{Outputs, Own};
use crate::stats::Stat;

/// The candidates file's name.
pub const CANDIDATES: &str = "candidates.jsonl";
/// The candidates a run streams while it lasts, committed into [`CANDIDATES`] with the
/// rest of the set at its end (what `--resume` reads after a kill or a failure).
pub const CANDIDATES_PART: &str = "candidates.jsonl.part";
/// The summary's name.
pub const SUMMARY: &str = "summary.json";
/// The figure's name.
pub const FIGURE: &str = "search.svg";
/// The failure maps' folder.
pub const FAILURES: &str = "failures";
/// Rejected points listed in the summary (all are counted).
pub const MAX_LISTED_REJECTIONS: usize = 20;

/// The output guard of a search into the folder `out` (the front adds the inputs: the
/// space file, the base map, the agent file): every file in it is the search's, the
/// candidates (and their part) are a search's, the summary, the figure and the failure
/// maps (`failures/*.ron`, each a map an earlier search wrote) too. The run replaces
/// them as one set at its end ([`super::run`]).
pub fn outputs(out: &Path) -> Outputs {
    Outputs::new()
        .folder("out", out)
        .file("out", out.join(CANDIDATES), Own::Candidates)
        .file("out", out.join(CANDIDATES_PART), Own::Candidates)
        .file("out", out.join(SUMMARY), Own::SearchSummary)
        .file("out", out.join(FIGURE), Own::Svg)
        .folder_files("out", &out.join(FAILURES), "ron", Own::FailureMap)
}

/// `{"search": identity}` and a newline.
pub fn identity_line(identity: &SearchIdentity) -> String {
    let mut s = serde_json::json!({ "search": identity }).to_string();
    s.push('\n');
    s
}

/// A proportion `k / n` with its 95% Wilson score interval (Wilson 1927).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Proportion {
    /// Successes counted (failures of the method, fair candidates, ...).
    pub k: usize,
    /// Trials.
    pub n: usize,
    /// k / n (None when n = 0).
    pub p: Option<f64>,
    /// Lower end of the 95% interval.
    pub ci95_low: Option<f64>,
    /// Upper end of the 95% interval.
    pub ci95_high: Option<f64>,
}

impl Proportion {
    /// `k` of `n`, with the Wilson interval at z = 1.96.
    pub fn wilson(k: usize, n: usize) -> Self {
        if n == 0 {
            return Proportion {
                k,
                n,
                p: None,
                ci95_low: None,
                ci95_high: None,
            };
        }
        let z = 1.959_963_984_540_054_f64;
        let (nf, p) = (n as f64, k as f64 / n as f64);
        let denom = 1.0 + z * z / nf;
        let centre = (p + z * z / (2.0 * nf)) / denom;
        let half = z * (p * (1.0 - p) / nf + z * z / (4.0 * nf * nf)).sqrt() / denom;
        Proportion {
            k,
            n,
            p: Some(p),
            ci95_low: Some((centre - half).max(0.0)),
            ci95_high: Some((centre + half).min(1.0)),
        }
    }

    /// `p [low, high]` in percent.
    pub fn text(&self) -> String {
        match (self.p, self.ci95_low, self.ci95_high) {
            (Some(p), Some(l), Some(h)) => format!(
                "{:.1}% [{:.1}, {:.1}] ({} of {})",
                100.0 * p,
                100.0 * l,
                100.0 * h,
                self.k,
                self.n
            ),
            _ => "n/a (none counted)".into(),
        }
    }
}

/// The failure probability of one training seed's agent.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeedEstimate {
    /// The training seed.
    pub train_seed: Option<u64>,
    /// Fair Sobol candidates the agent fails, of all fair Sobol candidates.
    pub failure_probability: Proportion,
}

/// Candidates counted by stage and verdict.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Counts {
    /// Sobol-stage candidates (of this shard, with a shard).
    pub sobol: usize,
    /// Adaptive-stage candidates.
    pub adaptive: usize,
    /// Minimisation tries.
    pub minimise: usize,
    /// Points that are not valid maps (all stages).
    pub rejected: usize,
    /// Evaluated candidates of the Sobol and adaptive stages.
    pub evaluated: usize,
    /// Of those: fair.
    pub fair: usize,
    /// Of those: not survivable (brake-on-pedestrian under 99%).
    pub not_survivable: usize,
    /// Of those: not dangerous (never-brake over 20%).
    pub not_dangerous: usize,
    /// Of those: neither survivable nor dangerous.
    pub neither: usize,
    /// Fair candidates the method fails (some training seed's success under 50%), Sobol stage.
    pub failing_fair_sobol: usize,
    /// The same, adaptive stage.
    pub failing_fair_adaptive: usize,
}

/// A point that is not a valid map.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RejectedPoint {
    /// Candidate number.
    pub candidate: usize,
    /// Its values.
    pub values: Vec<(String, Value)>,
    /// Why.
    pub reason: String,
}

/// One minimised failure, as reported.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FailureReport {
    /// Its map's name (the file is `failures/NAME.ron`).
    pub name: String,
    /// The file written.
    pub file: PathBuf,
    /// The candidate the search found failing.
    pub found_as: usize,
    /// The candidate of the minimised scenario.
    pub candidate: usize,
    /// Parameters it changes from the base: (name, base value, value).
    pub changed: Vec<(String, Option<Value>, Value)>,
    /// brake-on-pedestrian's success on it.
    pub brake_on_pedestrian_success: f64,
    /// never-brake's success on it.
    pub never_brake_success: f64,
    /// The method's success per training seed.
    pub method_success: Vec<(Option<u64>, f64)>,
    /// Minimisation tries, and how many were kept.
    pub tries: usize,
    /// Tries kept (each still failing).
    pub kept: usize,
}

/// `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Format version.
    pub schema: u32,
    /// The run.
    pub run: SearchIdentity,
    /// The shard run (`i/n`), if any: then only the Sobol slice was evaluated.
    pub shard: Option<String>,
    /// The space's file.
    pub space_file: String,
    /// When an agent fails a candidate and a candidate is fair.
    pub failure_threshold: FailureThreshold,
    /// Counts.
    pub counts: Counts,
    /// Share of evaluated Sobol candidates that are fair (the fair part of the space).
    pub fair_share: Proportion,
    /// P(the method fails | fair), per training seed, from the Sobol stage.
    pub failure_probability: Vec<SeedEstimate>,
    /// The per-seed failure probabilities over the training seeds: mean, Student-t
    /// 95% interval, range (None without fair candidates).
    pub failure_probability_over_seeds: Option<Stat>,
    /// P(at least one training seed's agent fails | fair), Sobol stage (the candidates
    /// the search counts as failures, [`Evaluated::fails_fairly`]).
    pub failure_probability_any_seed: Proportion,
    /// The two parameters the figure shows.
    pub figure_parameters: Vec<String>,
    /// The minimised failures, best first.
    pub failures: Vec<FailureReport>,
    /// Rejected points (at most [`MAX_LISTED_REJECTIONS`]; `counts.rejected` has them all).
    pub rejected: Vec<RejectedPoint>,
}

/// Writes `failures/`, `summary.json` and `search.svg` for `outcome` (within the run's
/// set, [`crate::files::all_or_none`]); returns the summary.
pub(super) fn write_all(cfg: &SearchConfig<'_>, out: &Path, outcome: &Outcome) -> Result<Summary, Error> {
    let space = cfg.space;
    let dir = out.join(FAILURES);
    std::fs::create_dir_all(&dir).map_err(|e| Error::io("create folder", &dir, e))?;
    let mut failures = Vec::new();
    for m in &outcome.failures {
        failures.push(write_failure(cfg, &dir, m)?);
    }
    // The folder holds this run's failures only: an earlier search's other maps (which
    // the guard, [`outputs`], checked are failure maps) go with the set.
    let earlier = std::fs::read_dir(&dir).map_err(|e| Error::io("read folder", &dir, e))?;
    for path in earlier.flatten().map(|e| e.path()) {
        if path.extension().is_some_and(|x| x == "ron") && !failures.iter().any(|f| f.file == path) {
            crate::files::remove_with_set(&path)?;
        }
    }
    let sobol: Vec<&Evaluated> = outcome
        .candidates
        .iter()
        .filter(|e| e.candidate.stage == Stage::Sobol)
        .collect();
    let fair_sobol: Vec<&&Evaluated> = sobol
        .iter()
        .filter(|e| e.fairness().is_some_and(Fairness::is_fair))
        .collect();
    let evaluated_sobol = sobol.iter().filter(|e| e.fairness().is_some()).count();
    let per_seed: Vec<SeedEstimate> = cfg
        .train_seeds
        .iter()
        .enumerate()
        .map(|(i, &s)| {
            let k = fair_sobol
                .iter()
                .filter(|e| e.method_success().get(i).is_some_and(|&x| super::fairness::fails(x)))
                .count();
            SeedEstimate {
                train_seed: s,
                failure_probability: Proportion::wilson(k, fair_sobol.len()),
            }
        })
        .collect();
    let ps: Vec<f64> = per_seed.iter().filter_map(|s| s.failure_probability.p).collect();
    let mut counts = Counts::default();
    let all_evaluated = outcome.candidates.iter().chain(&outcome.minimise_steps);
    counts.rejected = all_evaluated.filter(|e| e.candidate.map.is_err()).count();
    for e in &outcome.candidates {
        match e.candidate.stage {
            Stage::Sobol => counts.sobol += 1,
            Stage::Adaptive { .. } => counts.adaptive += 1,
            Stage::Minimise { .. } => {}
        }
        let Some(f) = e.fairness() else { continue };
        counts.evaluated += 1;
        match f {
            Fairness::Fair => counts.fair += 1,
            Fairness::NotSurvivable => counts.not_survivable += 1,
            Fairness::NotDangerous => counts.not_dangerous += 1,
            Fairness::Neither => counts.neither += 1,
        }
        if e.fails_fairly() {
            match e.candidate.stage {
                Stage::Sobol => counts.failing_fair_sobol += 1,
                _ => counts.failing_fair_adaptive += 1,
            }
        }
    }
    counts.minimise = outcome.minimise_steps.len();
    let rejected: Vec<RejectedPoint> = outcome
        .candidates
        .iter()
        .chain(&outcome.minimise_steps)
        .filter_map(|e| {
            e.candidate.map.as_ref().err().map(|reason| RejectedPoint {
                candidate: e.candidate.index,
                values: e.candidate.named_values(space),
                reason: reason.clone(),
            })
        })
        .take(MAX_LISTED_REJECTIONS)
        .collect();
    let figure_parameters = draw(cfg, &out.join(FIGURE), outcome)?;
    let summary = Summary {
        schema: 1,
        run: cfg.identity(),
        shard: cfg.shard.map(|s| format!("{}/{}", s.index, s.count)),
        space_file: space.source.clone(),
        failure_threshold: FailureThreshold::search(cfg.episodes),
        counts,
        fair_share: Proportion::wilson(fair_sobol.len(), evaluated_sobol),
        failure_probability_any_seed: Proportion::wilson(
            fair_sobol.iter().filter(|e| e.fails_fairly()).count(),
            fair_sobol.len(),
        ),
        failure_probability_over_seeds: (!ps.is_empty()).then(|| Stat::of(&ps)),
        failure_probability: per_seed,
        figure_parameters,
        failures,
        rejected,
    };
    crate::files::write_json(&out.join(SUMMARY), &summary)?;
    Ok(summary)
}

/// Writes one minimised failure as `failures/NAME.ron`.
fn write_failure(cfg: &SearchConfig<'_>, dir: &Path, m: &Minimised) -> Result<FailureReport, Error> {
    let space = cfg.space;
    let e = &m.result;
    let Ok(map) = &e.candidate.map else {
        unreachable!("a minimised failure was evaluated, so its map is valid")
    };
    let mut map = map.clone();
    map.description = format!(
        "found by unforeseen search: a fair failure of {} ({})",
        cfg.method.name(),
        cfg.protocol.name()
    );
    map.expect = vec![
        unforeseen_sim::Expectation {
            method: "BrakeOnPedestrian".into(),
            min_success: Some(0.99),
            max_success: None,
            min_reward: None,
            max_reward: None,
            max_collision: None,
            max_inference_rate: None,
            max_red_light: None,
            max_timeout: None,
            protocol: None,
        },
        unforeseen_sim::Expectation {
            method: "NeverBrake".into(),
            min_success: None,
            max_success: Some(0.2),
            min_reward: None,
            max_reward: None,
            max_collision: None,
            max_inference_rate: None,
            max_red_light: None,
            max_timeout: None,
            protocol: None,
        },
    ];
    let changed: Vec<(String, Option<Value>, Value)> = m
        .changed
        .iter()
        .map(|&i| {
            (
                space.params[i].name.clone(),
                space.params[i].base.clone(),
                e.candidate.values[i].clone(),
            )
        })
        .collect();
    let method_success: Vec<(Option<u64>, f64)> = e
        .lines
        .iter()
        .filter(|l| l.role == Role::Method)
        .map(|l| (l.result.train_seed, l.result.success_rate))
        .collect();
    let brake = e.witness(Role::SurvivableWitness).unwrap_or(f64::NAN);
    let never = e.witness(Role::DangerousWitness).unwrap_or(f64::NAN);
    let path = dir.join(format!("{}.ron", map.name));
    let mut text = String::new();
    // One comment line each: a control character (a newline in a path of the command)
    // is escaped, so it cannot end the comment.
    let c = |text: &mut String, line: String| {
        text.push_str("// ");
        for ch in line.chars() {
            if ch.is_control() {
                text.extend(ch.escape_default());
            } else {
                text.push(ch);
            }
        }
        text.push('\n');
    };
    c(
        &mut text,
        format!(
            "{}: a fair failure of {} ({}) found by `unforeseen search`.",
            map.name,
            cfg.method.name(),
            cfg.protocol.name()
        ),
    );
    c(
        &mut text,
        format!(
            "Space {} over the base map {}; found as candidate {}, minimised toward the base in {} tries ({} kept).",
            space.source, space.base.name, m.of, m.tries, m.kept
        ),
    );
    c(
        &mut text,
        "Parameters changed from the base (value, base value):".into(),
    );
    for (name, base, v) in &changed {
        let base = base.as_ref().map_or("none".into(), ToString::to_string);
        c(&mut text, format!("  {name} = {v} (base {base})"));
    }
    c(
        &mut text,
        format!(
            "Measured over {} episodes (seed {}): brake-on-pedestrian succeeds in {:.0}%, never-brake in {:.0}%, {} in:",
            cfg.episodes,
            cfg.seed,
            100.0 * brake,
            100.0 * never,
            cfg.method.name()
        ),
    );
    for (s, x) in &method_success {
        let seed = s.map_or("agent file".into(), |s| format!("training seed {s}"));
        c(&mut text, format!("  {seed}: {:.0}%", 100.0 * x));
    }
    c(&mut text, format!("Found by: {}", cfg.command));
    let agents = match cfg.train_seeds {
        [Some(_), ..] if cfg.train_seeds.len() > 1 || cfg.agents.len() > 1 => {
            let seeds: Vec<String> = cfg.train_seeds.iter().flatten().map(u64::to_string).collect();
            format!(" --train-seeds {}", seeds.join(","))
        }
        _ if cfg.method.is_scripted() => String::new(),
        _ => " --agent AGENT".into(),
    };
    c(
        &mut text,
        format!(
            "Re-run: unforeseen batch {} --method {} --method brake-on-pedestrian --method never-brake --protocol {} --episodes {} --seed {}{agents}",
            path.display(),
            cfg.method.name(),
            cfg.protocol.name(),
            cfg.episodes,
            cfg.seed
        ),
    );
    let body = map_ron(&map).map_err(|e| Error::Plot {
        message: format!("cannot write the map {}: {e}", map.name),
    })?;
    text.push_str(&body);
    text.push('\n');
    crate::files::write_atomic(&path, text.as_bytes())?;
    Ok(FailureReport {
        name: map.name.clone(),
        file: path,
        found_as: m.of,
        candidate: e.candidate.index,
        changed,
        brake_on_pedestrian_success: brake,
        never_brake_success: never,
        method_success,
        tries: m.tries,
        kept: m.kept,
    })
}

/// Pearson correlation of two equally long series (0 when either is constant).
fn correlation(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    if n < 2.0 {
        return 0.0;
    }
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx).powi(2);
        syy += (b - my).powi(2);
    }
    if sxx <= 0.0 || syy <= 0.0 {
        0.0
    } else {
        sxy / (sxx * syy).sqrt()
    }
}

/// The colour of a success rate: red (0) through amber to green (1).
fn success_colour(s: f64) -> RGBColor {
    let s = s.clamp(0.0, 1.0);
    if s < 0.5 {
        RGBColor(215, (40.0 + 340.0 * s) as u8, 40)
    } else {
        RGBColor((215.0 - 350.0 * (s - 0.5)) as u8, 210, (40.0 + 40.0 * (s - 0.5)) as u8)
    }
}

/// Draws `search.svg`; returns the parameters on its axes.
fn draw(cfg: &SearchConfig<'_>, path: &Path, outcome: &Outcome) -> Result<Vec<String>, Error> {
    let space = cfg.space;
    let evaluated: Vec<&Evaluated> = outcome.candidates.iter().filter(|e| e.fairness().is_some()).collect();
    let fair: Vec<&&Evaluated> = evaluated
        .iter()
        .filter(|e| e.fairness() == Some(Fairness::Fair))
        .collect();
    let success: Vec<f64> = fair.iter().map(|e| e.worst_success().unwrap_or(1.0)).collect();
    let mut strength: Vec<(usize, f64)> = (0..space.params.len())
        .map(|d| {
            let x: Vec<f64> = fair.iter().map(|e| e.candidate.point[d]).collect();
            (d, correlation(&x, &success).abs())
        })
        .collect();
    strength.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    let dims: Vec<usize> = strength.iter().take(2).map(|s| s.0).collect();
    let names: Vec<String> = dims.iter().map(|&d| space.params[d].name.clone()).collect();
    // Position of a candidate on axis d: the value for a range, the cell (jittered by the
    // candidate's number, so points of one cell do not hide each other) otherwise.
    let position =
        |e: &Evaluated, d: usize| -> f64 {
            let p = &space.params[d];
            match (&p.domain, &e.candidate.values[d]) {
                (Domain::Range(..), Value::Num(x)) => *x,
                _ => {
                    let cells = p.cells().unwrap_or(1) as f64;
                    let cell = (p.coordinate(&e.candidate.values[d]) * cells - 0.5).round();
                    let jitter =
                        (unforeseen_env::seeds::episode_seed(0, "search/jitter", (e.candidate.index * 2 + d) as u64)
                            % 1000) as f64
                            / 1000.0;
                    cell + 0.6 * (jitter - 0.5)
                }
            }
        };
    let axis = |d: Option<usize>| -> (f64, f64) {
        match d.map(|d| &space.params[d].domain) {
            Some(Domain::Range(lo, hi)) => {
                let pad = 0.03 * (hi - lo);
                (lo - pad, hi + pad)
            }
            Some(Domain::Count(lo, hi)) => (-0.5, f64::from(hi - lo) + 0.5),
            Some(Domain::Choose(n)) => (-0.5, n.len() as f64 - 0.5),
            None => (-0.05, 1.05),
        }
    };
    let label = |d: usize, x: f64| -> String {
        let p = &space.params[d];
        match &p.domain {
            Domain::Range(..) => tick_label(x),
            Domain::Count(lo, _) => {
                if (x - x.round()).abs() < 1e-6 {
                    format!("{}", x.round() as i64 + i64::from(*lo))
                } else {
                    String::new()
                }
            }
            Domain::Choose(n) => {
                let i = x.round();
                if (x - i).abs() < 1e-6 && i >= 0.0 && (i as usize) < n.len() {
                    n[i as usize].clone()
                } else {
                    String::new()
                }
            }
        }
    };
    let (dx, dy) = (dims.first().copied(), dims.get(1).copied());
    let (x0, x1) = axis(dx);
    let (y0, y1) = axis(dy);
    let minimised: Vec<&Evaluated> = outcome.failures.iter().map(|m| &m.result).collect();
    let title = format!(
        "{} ({}) on {}: success of the worst agent, fair candidates",
        cfg.method.name(),
        cfg.protocol.name(),
        space.name
    );
    // Room for the longest name of a chosen parameter on the y axis beside its title
    // (about 7 px a character at the mesh's font).
    let y_names = match dy.map(|d| &space.params[d].domain) {
        Some(Domain::Choose(n)) => n.iter().map(String::len).max().unwrap_or(0),
        _ => 0,
    };
    let y_area = 64.max(30 + 7 * y_names as u32);
    write_svg(path, (900, 620), |root| {
        let (plot, key) = root.split_horizontally(660);
        let mut chart = ChartBuilder::on(&plot)
            .caption(title.as_str(), ("sans-serif", 17))
            .margin(12)
            .x_label_area_size(44)
            .y_label_area_size(y_area)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(plot_err)?;
        let x_desc = dx.map_or("".to_string(), |d| space.params[d].name.clone());
        let y_desc = dy.map_or("worst agent's success".to_string(), |d| space.params[d].name.clone());
        let fx = |x: &f64| dx.map_or(tick_label(*x), |d| label(d, *x));
        let fy = |y: &f64| dy.map_or(tick_label(*y), |d| label(d, *y));
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .x_labels(12)
            .y_labels(12)
            .light_line_style(RGBColor(238, 238, 238))
            .x_label_formatter(&fx)
            .y_label_formatter(&fy)
            .draw()
            .map_err(plot_err)?;
        let at = |e: &Evaluated| -> (f64, f64) {
            let x = dx.map_or(0.5, |d| position(e, d));
            let y = match dy {
                Some(d) => position(e, d),
                None => e.worst_success().unwrap_or(0.0),
            };
            (x, y)
        };
        let grey = RGBColor(185, 185, 185);
        chart
            .draw_series(
                evaluated
                    .iter()
                    .filter(|e| e.fairness() != Some(Fairness::Fair))
                    .map(|e| Cross::new(at(e), 3, grey.stroke_width(1))),
            )
            .map_err(plot_err)?;
        chart
            .draw_series(fair.iter().map(|e| {
                let s = e.worst_success().unwrap_or(1.0);
                Circle::new(at(e), 4, success_colour(s).filled())
            }))
            .map_err(plot_err)?;
        chart
            .draw_series(
                fair.iter()
                    .filter(|e| e.fails_fairly())
                    .map(|e| Circle::new(at(e), 7, BLACK.stroke_width(1))),
            )
            .map_err(plot_err)?;
        chart
            .draw_series(minimised.iter().map(|e| {
                let (x, y) = at(e);
                EmptyElement::at((x, y)) + Rectangle::new([(-7, -7), (7, 7)], BLACK.stroke_width(2))
            }))
            .map_err(plot_err)?;
        // The key, beside the chart.
        enum Mark {
            Dot(RGBColor),
            Ring,
            Square,
            Cross,
            None,
        }
        let lines: Vec<(Mark, String)> = vec![
            (Mark::Dot(success_colour(0.0)), "fair, worst agent's success 0%".into()),
            (Mark::Dot(success_colour(0.5)), "fair, worst agent's success 50%".into()),
            (
                Mark::Dot(success_colour(1.0)),
                "fair, worst agent's success 100%".into(),
            ),
            (Mark::Ring, "fair failure (success < 50%)".into()),
            (Mark::Square, "minimised failure".into()),
            (Mark::Cross, "unfair (not survivable".into()),
            (Mark::None, "or not dangerous)".into()),
            (Mark::None, String::new()),
            (Mark::None, format!("{} candidates evaluated,", evaluated.len())),
            (
                Mark::None,
                format!("{} fair; {} episodes each", fair.len(), cfg.episodes),
            ),
        ];
        for (i, (mark, text)) in lines.iter().enumerate() {
            let y = 60 + 20 * i as i32;
            match mark {
                Mark::Dot(c) => key.draw(&Circle::new((14, y), 5, c.filled())),
                Mark::Ring => key.draw(&Circle::new((14, y), 7, BLACK.stroke_width(1))),
                Mark::Square => key.draw(&Rectangle::new([(7, y - 7), (21, y + 7)], BLACK.stroke_width(2))),
                Mark::Cross => key.draw(&Cross::new((14, y), 3, grey.stroke_width(1))),
                Mark::None => Ok(()),
            }
            .map_err(plot_err)?;
            key.draw(&Text::new(text.clone(), (28, y - 7), ("sans-serif", 13)))
                .map_err(plot_err)?;
        }
        Ok(())
    })?;
    Ok(names)
}

/// The batch result lines of `candidates.jsonl` (every line after the identity).
pub fn read_result_lines(path: &Path) -> Result<Vec<ResultLine>, Error> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io("read", path, e))?;
    text.lines()
        .filter(|l| !l.starts_with("{\"search\":"))
        .map(|l| Ok(serde_json::from_str::<ResultLine>(l)?))
        .collect()
}
