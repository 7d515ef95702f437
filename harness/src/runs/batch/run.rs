//! Running a batch: one unit ([`run_unit`]) and a whole plan, in parallel, streaming
//! each finished unit to the results file as one JSON line.

use rayon::prelude::*;
use std::io::Write;
use std::path::Path;
use std::sync::Mutex;

use crate::episodes::evaluation::{run_agent_episodes, run_scripted_episodes};
use crate::episodes::metrics::Aggregate;
use crate::episodes::runner::EpisodeResult;
use crate::error::Error;
use crate::progress::{CancelOnly, NoProgress, Progress};
use crate::runs::stream::{evaluate_stream, per_map};

use super::expectations::check_expectations;
use super::plan::{BatchConfig, Plan};
use super::result_line::{MapFigures, ResultLine, UnitLabel};
use super::results_file::KeptLine;
use super::scenario::ScenarioKind;
use super::units::Unit;

/// Runs one unit: `episodes` episodes of its method on its scenario with its agent,
/// under its protocol. A map: [`run_agent_episodes`] (zero-shot episodes in parallel, each
/// from a fresh controller; continual ones in order on one controller). A stream:
/// [`evaluate_stream`] (the same, over the stream's maps), and the line adds the figures
/// per map within the stream ([`per_map`]).
pub fn run_unit(cfg: &BatchConfig<'_>, unit: &Unit) -> Result<ResultLine, Error> {
    run_unit_with(cfg, unit, &NoProgress)
}

/// [`run_unit`], stopping between episodes ([`Error::Interrupted`]) when `cancel` asks.
/// A scripted method's unit runs without an agent when the run has none for its
/// training seed (a run of scripted methods only trains none: [`Plan::train_seeds_to_run`](super::Plan::train_seeds_to_run)).
pub fn run_unit_with(cfg: &BatchConfig<'_>, unit: &Unit, cancel: &dyn Progress) -> Result<ResultLine, Error> {
    let scenario = &cfg.scenarios[unit.scenario];
    let agent = cfg.agents.iter().find(|a| a.train_seed == unit.train_seed);
    if agent.is_none() && !unit.method.is_scripted() {
        return Err(Error::MissingAgent {
            train_seed: unit.train_seed,
        });
    }
    let bundle = agent.map(|a| &a.bundle);
    // A stream's maps agree on their agent settings ([`Stream::load`](crate::runs::stream::Stream::load)).
    let params = match &scenario.kind {
        ScenarioKind::Map(map) => unit.params.on_map(map)?,
        ScenarioKind::Stream(stream) => unit.params.on_map(&stream.maps[0].0)?,
    };
    let tree = unit.method.reasoning_tree(&params);
    let (agg, per_map_figures) = match &scenario.kind {
        ScenarioKind::Map(map) => {
            let results = match bundle {
                Some(bundle) => run_agent_episodes(
                    unit.protocol,
                    map,
                    bundle,
                    &params,
                    unit.method,
                    cfg.episodes,
                    cfg.seed,
                    &CancelOnly(cancel),
                )?,
                None => run_scripted_episodes(map, unit.method, cfg.episodes, cfg.seed, &CancelOnly(cancel))?,
            };
            (Aggregate::of(&results), Vec::new())
        }
        ScenarioKind::Stream(stream) => {
            let episodes = evaluate_stream(
                stream,
                bundle,
                &params,
                unit.method,
                unit.protocol,
                cfg.episodes,
                cfg.seed,
                &CancelOnly(cancel),
            )?;
            let results: Vec<EpisodeResult> = episodes.iter().map(|e| e.result.clone()).collect();
            let figures = per_map(stream, &episodes)
                .into_iter()
                .map(|row| MapFigures::new(row.map, &row.aggregate, tree))
                .collect();
            (Aggregate::of(&results), figures)
        }
    };
    // A map's expectations describe the methods at their default parameters on that map
    // alone: the other points of a sweep, and streams, are reported, not gated.
    let checks = match scenario.map() {
        Some(map) if unit.params.0.is_empty() => check_expectations(map, unit.method, &unit.covers, &agg),
        _ => Vec::new(),
    };
    let label = UnitLabel {
        unit: unit.index,
        scenario: scenario.name().to_string(),
        source: scenario.source.clone(),
        method: unit.method.name().into(),
        param_set: unit.params.label(),
        params: unit.params.0.clone(),
        protocol: unit.protocol,
        covers: unit.covers.clone(),
        train_seed: unit.train_seed,
        train_episodes: agent.and_then(|a| a.train_episodes),
        seed: cfg.seed,
    };
    Ok(ResultLine::new(label, &agg, tree, checks, per_map_figures))
}

fn to_line(r: &ResultLine) -> String {
    let mut s = serde_json::to_string(r).expect("result lines serialize");
    s.push('\n');
    s
}

/// Plans the batch ([`BatchConfig::plan`]) and runs it ([`run_plan`]).
pub fn run(cfg: &BatchConfig<'_>, out: &Path, resume: bool, progress: &dyn Progress) -> Result<Vec<ResultLine>, Error> {
    run_plan(cfg, &cfg.plan(out, resume)?, out, progress)
}

/// Runs a planned batch, streaming each finished unit to `out` after the run's identity
/// and the lines the plan keeps, then rewrites `out` in canonical order (kept lines byte
/// for byte). Returns all lines of the file in canonical order. One phase of `progress`
/// (`batch units`, one step per unit).
pub fn run_plan(
    cfg: &BatchConfig<'_>,
    plan: &Plan,
    out: &Path,
    progress: &dyn Progress,
) -> Result<Vec<ResultLine>, Error> {
    run_plan_then(cfg, plan, out, progress, |_| Ok(()))
}

/// [`run_plan`], with the files `then` writes from the lines (a summary) written as one
/// set with the rewritten `out` ([`crate::files::all_or_none`]).
pub fn run_plan_then(
    cfg: &BatchConfig<'_>,
    plan: &Plan,
    out: &Path,
    progress: &dyn Progress,
    then: impl FnOnce(&[ResultLine]) -> Result<(), Error>,
) -> Result<Vec<ResultLine>, Error> {
    let identity = &plan.identity;
    let todo = plan.todo();

    // The identity and the kept lines, then the new lines as they finish.
    let head: String = std::iter::once(identity.to_line())
        .chain(plan.kept.iter().map(|l| l.raw.clone()))
        .collect();
    crate::files::write_atomic(out, head.as_bytes())?;
    let file = std::fs::OpenOptions::new()
        .append(true)
        .open(out)
        .map_err(|e| Error::io("append to", out, e))?;
    let sink = Mutex::new(file);
    progress.phase("batch units", todo.len() as u64);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(cfg.jobs.max(1)).build()?;
    let fresh: Vec<KeptLine> = pool.install(|| {
        todo.par_iter()
            .map(|u| {
                let line = run_unit_with(cfg, u, progress)?;
                let raw = to_line(&line);
                let mut f = sink.lock().expect("result file lock");
                f.write_all(raw.as_bytes())
                    .and_then(|()| f.flush())
                    .map_err(|e| Error::io("write", out, e))?;
                crate::progress::step(progress)?;
                Ok(KeptLine {
                    line: 0,
                    raw,
                    parsed: line,
                })
            })
            .collect::<Result<Vec<_>, Error>>()
    })?;
    progress.finish();
    let mut lines: Vec<KeptLine> = plan.kept.iter().cloned().chain(fresh).collect();
    lines.sort_by_key(|l| l.parsed.unit);
    let text: String = std::iter::once(identity.to_line())
        .chain(lines.iter().map(|l| l.raw.clone()))
        .collect();
    let lines: Vec<ResultLine> = lines.into_iter().map(|l| l.parsed).collect();
    crate::files::all_or_none(|| {
        crate::files::write_atomic(out, text.as_bytes())?;
        then(&lines)
    })?;
    Ok(lines)
}
