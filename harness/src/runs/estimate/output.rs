//! What an estimate writes into its folder, together at the end of the run:
//!
//! * `estimate.jsonl`: the run's identity (`{"estimate": {...}}`), then one line per draw
//!   ([`Draw`]) in order: its stage, point, parameter values, proposal density, fairness,
//!   the method's episodes and failures, and their smallest margins;
//! * `summary.json` ([`Summary`]): the estimand and the failure threshold, the three
//!   estimates with their intervals and diagnostics, the evaluations, whether the target
//!   was reached, the final proposal, for `is` and `is-fails` every stage's proposal with
//!   its draws (`mixture`, which weighs the draws), and the estimates after each block
//!   (`checkpoints`).
//!
//! While it runs, the draws go to `estimate.jsonl.part` as they come (what `--resume`
//! reads after a kill), removed with the commit of the set. A shard writes
//! `estimate.jsonl` alone (the draws it holds, in order) and removes the summary.

use serde::{Deserialize, Serialize};
use std::path::Path;

use super::{Checkpoint, Draw, EstimateRequest, Estimates, Estimator, Outcome, Proposal};
use crate::episodes::Protocol;
use crate::error::Error;
use crate::runs::outputs::{Outputs, Own};
use crate::runs::search::{FailureThreshold, SearchConfig};

/// The draws file's name.
pub const DRAWS: &str = "estimate.jsonl";
/// The draws a run streams while it lasts, committed into [`DRAWS`] with the rest of
/// the set at its end.
pub const DRAWS_PART: &str = "estimate.jsonl.part";
/// The summary's name.
pub const SUMMARY: &str = "summary.json";

/// The output guard of an estimate into the folder `out` (the front adds the inputs):
/// the draws (and their part) are an estimate's, the summary too. The run replaces them
/// as one set at its end.
pub fn outputs(out: &Path) -> Outputs {
    Outputs::new()
        .folder("out", out)
        .file("out", out.join(DRAWS), Own::Estimates)
        .file("out", out.join(DRAWS_PART), Own::Estimates)
        .file("out", out.join(SUMMARY), Own::EstimateSummary)
}

/// What determines an estimate's results (the first line of `estimate.jsonl`); the shard
/// is not part of it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EstimateIdentity {
    /// Program version and code fingerprint.
    pub program: String,
    /// The space: name and a hash of its file.
    pub space: (String, String),
    /// The base map: name and a hash of its contents.
    pub base: (String, String),
    /// The method.
    pub method: String,
    /// The agents.
    pub agents: String,
    /// Training seeds.
    pub train_seeds: Vec<Option<u64>>,
    /// Protocol.
    pub protocol: Protocol,
    /// The estimator.
    pub estimator: Estimator,
    /// The target relative half-width.
    pub target_rel_error: f64,
    /// Most draws.
    pub budget: usize,
    /// Episodes per draw, for each witness and for the method (per training seed).
    pub episodes: u64,
    /// Seed.
    pub seed: u64,
}

/// `summary.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// Format version.
    pub schema: u32,
    /// The run.
    pub run: EstimateIdentity,
    /// The space's file.
    pub space_file: String,
    /// What is estimated.
    pub estimand: String,
    /// When an episode fails and a scenario is fair.
    pub failure_threshold: FailureThreshold,
    /// The estimates.
    pub estimates: Estimates,
    /// Draws evaluated (points of the space, the cross-entropy rounds' included).
    pub evaluations: usize,
    /// Of them, those that were no valid map.
    pub rejected: usize,
    /// Draws the estimates are over: all (`is` and `is-fails` pool every stage's,
    /// [`super::proposal::Mixture`]).
    pub estimate_draws: usize,
    /// Episodes of the method run, over all draws (the witnesses' come on top).
    pub method_episodes: u64,
    /// Whether what the estimator aims at reached the target (else the budget was spent).
    pub target_reached: bool,
    /// The proposal of the last stage (the uniform cube for `mc`).
    pub proposal: Proposal,
    /// `is`, `is-fails`: every stage's proposal with its number of draws; a draw's weight
    /// is one over their mixture's density at its point (absent for `mc`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub mixture: Option<super::proposal::Mixture>,
    /// The estimates after each block of the estimating stage.
    pub checkpoints: Vec<Checkpoint>,
}

/// The run's identity (the first line of `estimate.jsonl`).
pub fn identity(cfg: &SearchConfig<'_>, r: &EstimateRequest) -> EstimateIdentity {
    let search = cfg.identity();
    EstimateIdentity {
        program: search.program,
        space: search.space,
        base: search.base,
        method: search.method,
        agents: search.agents,
        train_seeds: search.train_seeds,
        protocol: search.protocol,
        estimator: r.estimator,
        target_rel_error: r.target_rel_error,
        budget: r.budget,
        episodes: r.episodes,
        seed: r.seed,
    }
}

/// `{"estimate": identity}` and a newline.
pub fn identity_line(run: &EstimateIdentity) -> String {
    let mut s = serde_json::json!({ "estimate": run }).to_string();
    s.push('\n');
    s
}

/// The line of a draw, newline included.
pub(super) fn draw_line(d: &Draw) -> Result<String, Error> {
    let mut s = serde_json::to_string(d)?;
    s.push('\n');
    Ok(s)
}

/// Writes `estimate.jsonl`: the identity, then `draws`.
fn write_draws(run: &EstimateIdentity, out: &Path, draws: &[Draw]) -> Result<(), Error> {
    let text = std::iter::once(Ok(identity_line(run)))
        .chain(draws.iter().map(draw_line))
        .collect::<Result<String, Error>>()?;
    crate::files::write_atomic(&out.join(DRAWS), text.as_bytes())
}

/// Writes a shard's `estimate.jsonl` (the draws it holds) and removes the summary and
/// the part (in the caller's all-or-none set).
pub(super) fn write_shard(
    cfg: &SearchConfig<'_>,
    r: &EstimateRequest,
    out: &Path,
    draws: &[Draw],
) -> Result<(), Error> {
    write_draws(&identity(cfg, r), out, draws)?;
    crate::files::remove_with_set(&out.join(SUMMARY))?;
    crate::files::remove_with_set(&out.join(DRAWS_PART))
}

/// Writes `estimate.jsonl` and `summary.json` for `outcome` and removes the part (in the
/// caller's all-or-none set); returns the summary.
pub(super) fn write_all(
    cfg: &SearchConfig<'_>,
    r: &EstimateRequest,
    out: &Path,
    outcome: &Outcome,
) -> Result<Summary, Error> {
    let run = identity(cfg, r);
    write_draws(&run, out, &outcome.draws)?;
    let summary = Summary {
        schema: 1,
        run,
        space_file: cfg.space.source.clone(),
        estimand: format!(
            "P(an episode of {} fails) with the scenario drawn uniformly from the space's unit cube (conditioned on a \
             valid map) and each episode's randomness from its seed; P(fails | fair) = P(fails and fair) / P(fair); \
             the method's agents (training seeds) weigh evenly",
            cfg.method.name()
        ),
        failure_threshold: FailureThreshold::episode(r.episodes),
        estimates: outcome.estimates.clone(),
        evaluations: outcome.draws.len(),
        rejected: outcome.draws.iter().filter(|d| d.rejected.is_some()).count(),
        estimate_draws: outcome.draws.len(),
        method_episodes: outcome.draws.iter().map(|d| d.episodes).sum(),
        target_reached: outcome.reached,
        proposal: outcome.proposal.clone(),
        mixture: outcome.mixture.clone(),
        checkpoints: outcome.checkpoints.clone(),
    };
    crate::files::write_json(&out.join(SUMMARY), &summary)?;
    crate::files::remove_with_set(&out.join(DRAWS_PART))?;
    Ok(summary)
}
