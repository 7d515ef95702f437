//! The search for the unforeseen: the fair scenarios of a space of map variations
//! where a method fails (the paper's subject is what nobody foresaw; safety engineers
//! search for it: adaptive stress testing, falsification).
//!
//! A [`Space`] names which fields of a base map vary and over what (`space.rs`). The
//! search evaluates *candidates*, points of the space laid over the base map, each with
//! K episodes of the two fairness witnesses (brake-on-pedestrian's line is the worst of
//! its careful cruises, [`careful_witness`]) and of the method (for each training seed),
//! in three stages. A fair candidate is a *failure* of the method when at least one of its
//! trained agents (training seeds) succeeds in under 50% of the episodes: each agent is
//! one draw of the method.
//!
//!
//! 1. **Sobol stage** (candidates `0..n1`, `n1 = ceil(budget × sobol_share)`): points of
//!    a scrambled Sobol sequence (`sampler.rs`), uniform on the unit cube, so the share of
//!    its fair candidates the method fails is an unbiased estimate of
//!    P(the method fails | the candidate is fair), reported with a 95% Wilson interval
//!    per training seed, with the share of the space that is fair ([`Fairness`]).
//! 2. **Adaptive stage** (candidates `n1..budget`, in [`SearchConfig::rounds`] rounds):
//!    the cross-entropy method (`adaptive.rs`) fitted to the fair failures found so far.
//! 3. **Minimisation** (`minimise.rs`): each of the best failures (up to
//!    [`SearchConfig::max_failures`], distinct by which parameters they change) is moved
//!    back toward the base map, one parameter at a time, while it still fails fairly.
//!
//! Every candidate's map is a valid map or is rejected with the map loader's reason
//! (counted and reported, never evaluated). Episode seeds derive from (seed, candidate
//! name, method, episode) and every stage's candidates from the seed and the results of
//! earlier stages, so the same seed gives the same candidates and results whatever the
//! number of threads.
//!
//! **Shards** cover the Sobol stage only: `--shard i/n` evaluates the i-th contiguous
//! slice of its candidates (the same contract as `batch`); the shards' `candidates.jsonl`
//! concatenated in order are the Sobol part of a single run's file. The adaptive stage
//! and minimisation depend on all of the first stage's results, so they run once, in a
//! run without `--shard` given the concatenated file with `--resume` (which keeps every
//! complete candidate and evaluates only what is missing). **Resume** refuses a file of
//! another run (its first line is the run's identity), keeps the complete candidates'
//! lines byte for byte and evaluates the rest.
//!
//! A search's request ([`SearchRequest`]) is every choice of its user; its planning
//! ([`SearchRequest::plan`]) is shared by the command line, the Python package and the
//! Ray driver.
//!
//! Outputs ([`Summary`], `output.rs`): `candidates.jsonl`, `failures/NAME.ron`, `summary.json` and
//! `search.svg`.

pub(crate) mod adaptive;
mod candidates;
mod config;
pub(crate) mod fairness;
mod identity;
pub(crate) mod minimise;
pub(crate) mod output;
pub(crate) mod request;
mod resume;
mod runner;
pub(crate) mod sampler;
pub(crate) mod space;
mod wire;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Mutex;
use unforeseen_agent::params::ScaledParams;
use unforeseen_sim::Map;

use crate::episodes::evaluation::{run_agent_episodes, run_scripted_episodes};
use crate::episodes::methods::Method;
use crate::episodes::metrics::Aggregate;
use crate::episodes::protocol::{Protocol, covered};
use crate::episodes::survivability::{at_cruise, careful_witness};
use crate::error::Error;
use crate::progress::{CancelOnly, NoProgress, Progress};
use crate::runs::batch::{ResultLine, Shard, UnitLabel};
use crate::runs::outputs::Guarded;
use crate::training::seed_agents::Agent;

pub use candidates::{
    Candidate, CandidateLine, CarefulCruise, Evaluated, Role, Stage, candidate_name, sobol_candidates,
};
pub use config::{DEFAULT_MAX_FAILURES, DEFAULT_ROUNDS, DEFAULT_SOBOL_SHARE, MAX_BUDGET, SearchConfig};
pub use fairness::{FailureThreshold, Fairness};
pub use identity::SearchIdentity;
pub use output::{MAX_LISTED_REJECTIONS, Summary, read_result_lines};
pub use request::{SearchJob, SearchRequest, SearchSetup};
pub use runner::evaluate_candidate;
pub use space::{Space, Value, map_ron};
pub use wire::{CandidateWire, Evaluator, evaluate_wire, evaluate_wire_with};

use candidates::RawLine;
use resume::{lines_per_candidate, resume_lines};
use runner::Runner;

/// Everything a search found, in memory (what [`run`] writes).
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Every candidate of the Sobol and adaptive stages (rejected ones too), in order.
    pub candidates: Vec<Evaluated>,
    /// The minimised failures, best first.
    pub failures: Vec<minimise::Minimised>,
    /// The minimisation steps evaluated.
    pub minimise_steps: Vec<Evaluated>,
}

/// Runs the search into folder `out` (`candidates.jsonl`, `failures/`, `summary.json`,
/// `search.svg`); with `resume`, completes the search a file there holds. Progress: one
/// phase per stage (`search sobol`, `search adaptive N`, `search minimise`). `guard` is
/// the job's output guard, held while the run writes.
///
/// The candidates are streamed to `candidates.jsonl.part` (`output::CANDIDATES_PART`)
/// as they are evaluated, and the set (candidates, failure maps, summary, figure) is
/// committed as one at the end ([`crate::files::all_or_none`]), the part removed with
/// it: a run that fails or is killed partway leaves the earlier search's set as it was,
/// and the part for `--resume`, which reads the part when there is one (the latest run
/// into the folder) and `candidates.jsonl` otherwise.
pub fn run(
    cfg: &SearchConfig<'_>,
    out: &Path,
    resume: bool,
    guard: &Guarded,
    progress: &dyn Progress,
) -> Result<Summary, Error> {
    run_with(cfg, out, resume, guard, progress, None)
}

/// [`run`], with the candidates evaluated by `remote` when given (each stage's
/// candidates in one call, each minimisation try in its own; the stage logic, the files
/// and their order stay here, so the outputs equal [`run`]'s). Minimisation's failures
/// run on `cfg.jobs` threads, each waiting on its own calls.
pub fn run_with(
    cfg: &SearchConfig<'_>,
    out: &Path,
    resume: bool,
    _guard: &Guarded,
    progress: &dyn Progress,
    remote: Option<&dyn Evaluator>,
) -> Result<Summary, Error> {
    cfg.check()?;
    std::fs::create_dir_all(out).map_err(|e| Error::io("create folder", out, e))?;
    let file = out.join(output::CANDIDATES);
    let part = out.join(output::CANDIDATES_PART);
    let read = if part.is_file() { &part } else { &file };
    let kept = if resume {
        resume_lines(cfg, read)?
    } else {
        BTreeMap::new()
    };
    let head: String = std::iter::once(output::identity_line(&cfg.identity()))
        .chain(kept.values().flatten().map(|l| l.raw.clone()))
        .collect();
    let sink = crate::files::Streamed::create(&part, head.as_bytes())?;
    let runner = Runner {
        cfg,
        sink: Mutex::new(sink),
        out: read,
        kept,
        written: Mutex::new(BTreeMap::new()),
        progress,
        remote,
        prefetched: Mutex::new(BTreeMap::new()),
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(cfg.jobs.max(1)).build()?;
    let outcome = pool.install(|| search(&runner))?;
    // Canonical order: by candidate, each candidate's lines in role and seed order.
    let written = runner.written.into_inner().expect("lines lock");
    let text: String = std::iter::once(output::identity_line(&cfg.identity()))
        .chain(written.values().flatten().map(|l| l.raw.clone()))
        .collect();
    // The candidates, failure maps, summary and figure appear together or not at all;
    // the part goes with them.
    crate::files::all_or_none(|| {
        crate::files::write_atomic(&file, text.as_bytes())?;
        let summary = output::write_all(cfg, out, &outcome)?;
        crate::files::remove_with_set(&part)?;
        Ok(summary)
    })
}

/// The stages (see the module doc).
fn search(runner: &Runner<'_, '_>) -> Result<Outcome, Error> {
    let cfg = runner.cfg;
    let space = cfg.space;
    let n1 = cfg.sobol_count();
    let range = cfg.shard.map_or(0..n1, |s| s.range(n1));
    let mut all = runner.stage("search sobol", sobol_candidates(space, cfg.seed, range))?;
    if cfg.shard.is_some() {
        return Ok(Outcome {
            candidates: all,
            failures: Vec::new(),
            minimise_steps: Vec::new(),
        });
    }
    let mut ce = adaptive::CrossEntropy::uniform(space);
    let mut next = n1;
    for (round, size) in cfg.round_sizes().into_iter().enumerate() {
        let scored: Vec<(Vec<f64>, f64)> = all.iter().map(|e| (e.candidate.point.clone(), e.score())).collect();
        ce.refit(&scored);
        let candidates: Vec<Candidate> = ce
            .sample(cfg.seed, round, size)
            .into_iter()
            .enumerate()
            .map(|(k, p)| Candidate::new(space, next + k, Stage::Adaptive { round }, p, None))
            .collect();
        next += size;
        all.extend(runner.stage(&format!("search adaptive {}", round + 1), candidates)?);
    }
    let (failures, steps) = minimise::minimise_all(runner, &all)?;
    Ok(Outcome {
        candidates: all,
        failures,
        minimise_steps: steps,
    })
}
