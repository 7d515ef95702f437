//! How rare is a failure: the probability that an episode of a method fails on a space of
//! map variations, with an interval that holds (docs/ARCHITECTURE.md §6).
//!
//! **The estimand.** A scenario is a point of the space's unit cube drawn uniformly (each
//! parameter uniform over its range, or over its cells for a count or a choice, as the
//! search's Sobol stage draws it), laid over the base map; points that make no valid map
//! are no scenario (counted, and left out: the distribution is conditioned on a valid
//! map). On it, the method runs `episodes` episodes for each of its agents (training
//! seeds), each episode's own randomness (spawns, walking speeds, light offset) from its
//! seed, which derives from the run seed, the draw's map name and the episode. An
//! episode *fails* when it does not succeed: a collision or a time-out. Estimated:
//!
//! * `p_fail` = P(an episode fails) = `E[y]`, `y` the share of the draw's episodes that
//!   failed (over its agents: an episode of an agent drawn evenly among them);
//! * `p_fail_given_fair` = `E[y·F] / E[F]`, `F` the draw's fairness as the search's
//!   witnesses decide it ([`crate::runs::search::Fairness`]), with the same `episodes`;
//! * `fair_share` = `E[F]`, the fair part of the space.
//!
//! **Estimators** ([`estimators`]), each stopping once the relative half-widths of what
//! it aims at ([`Estimates::reach`]: `mc` both probabilities, `is` P(fails | fair),
//! `is-fails` P(fails)) are at most the target or the budget of draws is spent, checked after
//! each block of draws (blocks of fixed sizes, so the stopping point does not depend on
//! the threads):
//!
//! * **mc**: independent uniform draws; the mean with its Wilson interval, over the valid
//!   draws and over the fair ones (conditionally on their number, the fair draws are
//!   independent draws of the distribution restricted to the fair part).
//! * **is**, **is-fails**: cross-entropy importance sampling. Rounds of draws
//!   ([`rounds`]: a tenth of the budget each, at most [`MAX_ROUNDS`] and half the budget,
//!   fewer once the failures fill the elite), the first uniform, each refitting the proposal ([`proposal`]: a defensive mixture of
//!   the uniform and a product of marginals, of which only those the elite departs in
//!   move) to the elite of the draws so far, each draw weighted as below. A draw's
//!   *score* ([`Draw::score`]) is minus its failed share when it failed; otherwise `is`,
//!   aimed at P(fails | fair), scores a fair draw 0 and an unfair one +∞ (its elite is
//!   every fair draw until the fair failures alone fill it), and `is-fails`, aimed at
//!   P(fails), scores a valid draw by its smallest stopping margin. Then a final
//!   stage from the last proposal. The estimates pool every stage's draws, rounds
//!   included, each weighted by one over the density of the mixture of the stages'
//!   proposals in proportion to their draws ([`proposal::Mixture`], the balance
//!   heuristic): self-normalised, P(fails | fair) the ratio of the weighted fair failures
//!   to the weighted fair draws, with the Wilson interval at the delta method's effective
//!   sample size, the ESS, the largest weight's share and refusals when the weights
//!   degenerate or carry under 5 effective failures ([`estimators::importance`]).
//!
//! What these measured (EXPERIMENTS.md, "How rare is a failure"): at p ≈ 2%
//! (`late_jaywalker.ron`) `is-fails`' intervals covered the value of a Monte Carlo run of
//! twenty times the draws in 19 of 20 runs of 1000 draws, at half of `mc`'s variance; at p ≈ 10⁻³
//! (`late_jaywalker_rare.ron`) it reached ±30% in a median 4.6% of the draws `mc` needs,
//! its estimates leaning low (17% on average); on the jaywalk space, whose fair failures
//! have no structure a product of marginals can fit, `is` is about as precise as `mc` on
//! P(fails | fair), so `mc` is the default.
//!
//! Every draw has its own generator (run seed, stage, index) and its episodes their own
//! seeds, and draws are evaluated in parallel but taken in index order, so the same
//! request gives the same files bit for bit whatever the number of threads.
//!
//! **Resume.** The state of a run is a function of its draws: each draw's point and
//! density (its own stage's proposal's) derive from (run seed, stage, index) and the
//! proposal in force, and the proposals of `is` and `is-fails` are refitted
//! deterministically from the earlier rounds' draws (their mixture weights included,
//! which depend only on the stages' sizes and proposals). So `--resume` (`resume.rs`)
//! reads the draws an earlier run of the same request left (its identity line checked,
//! each line checked as this program writes it), walks the stages as a fresh run does,
//! takes each kept draw where the walk reaches its index (checked against the draw
//! derived there) and evaluates only the missing ones: the files are those of a run never
//! interrupted, byte for byte (the walk refits each round's proposal from the kept draws
//! as the first run did, so the mixture that weighs the draws is the same). Kept draws
//! the walk never reaches (past the block where the stopping rule stops it) are left out.
//!
//! **Shards.** A shard `I/N` evaluates the draws of index `≡ I − 1 (mod N)` of the first
//! stage the draws in its folder do not complete (none, without `--resume`), writes
//! `estimate.jsonl` (every draw it holds) and stops ([`ShardPart`]). The stages are: each
//! cross-entropy round of `is` and `is-fails` whole (its draws come from the proposal the
//! rounds before it fitted, so a round can only be dealt once they are all in); then the
//! estimating stage (`mc`'s uniform draws, the final ones of `is` and `is-fails`) from
//! its first incomplete block to the budget (the stopping rule needs every draw of a
//! block, which no shard has; the draws dealt in turn put each shard's share in the
//! earliest blocks, so little past the stopping point is wasted). The shards' files
//! concatenated (a draw that several files hold, line for line the same, is one draw) are
//! the input of the next step: `--resume --shard I/N` again for the next stage of `is` or
//! `is-fails`, and, once a shard finds every needed draw there, a run without `--shard`
//! with `--resume`, which takes every draw, evaluates none, applies the stopping rule and
//! writes what the unsharded run writes. So `mc` takes one round of shards, `is` and
//! `is-fails` one per round and one for the final stage; concatenation and `--resume` are
//! the merge (`unforeseen merge` joins batch runs' units, whose files have no stages to
//! walk).
//!
//! Outputs ([`output`]): `estimate.jsonl` (the run's identity, then one line per draw)
//! and `summary.json` (the estimates, their intervals and diagnostics, the failure
//! threshold, the stages' mixture for `is` and `is-fails`), written together at the end;
//! the draws stream to `estimate.jsonl.part` while the run lasts.

pub mod estimators;
pub mod output;
pub mod proposal;
pub mod request;
mod resume;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::Error;
use crate::files::Streamed;
use crate::progress::Progress;
use crate::runs::batch::Shard;
use crate::runs::outputs::Guarded;
use crate::runs::search::{
    Candidate, CandidateLine, CandidateWire, Evaluator, Fairness, Role, SearchConfig, Stage, Value, evaluate_candidate,
};

pub use estimators::Estimate;
pub use output::{EstimateIdentity, Summary};

pub use proposal::Proposal;
pub use request::{EstimateJob, EstimateRequest, EstimateSetup, Estimator};

/// Most rounds of the cross-entropy stage of `is` and `is-fails` (the first from the
/// uniform cube); the rounds stop earlier once the failures fill the elite
/// ([`proposal::failure_level_reached`]), and take at most half the budget.
pub const MAX_ROUNDS: usize = 5;
/// Fewest draws of one block (one cross-entropy round, one check of the stopping rule).
pub const MIN_BLOCK: usize = 50;
/// Most draws one estimate may have.
pub const MAX_BUDGET: usize = 1_000_000;

/// Which stage made a draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DrawStage {
    /// A uniform draw of `mc`.
    Uniform,
    /// Round `round` of the cross-entropy stage of `is` or `is-fails`.
    Round {
        /// 0-based round.
        round: usize,
    },
    /// The final stage of `is` or `is-fails`.
    Final,
}

impl DrawStage {
    /// The name of its draws' generator stream.
    fn stream(self) -> String {
        match self {
            DrawStage::Uniform => "estimate/uniform".into(),
            DrawStage::Round { round } => format!("estimate/round-{round}"),
            DrawStage::Final => "estimate/final".into(),
        }
    }
}

/// One evaluated draw: a line of `estimate.jsonl`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Draw {
    /// Its number (also its map's, `SPACE_cNNNN`, from which its episodes' seeds derive).
    pub draw: usize,
    /// The stage that made it.
    pub stage: DrawStage,
    /// Its coordinates in the unit cube.
    pub point: Vec<f64>,
    /// Its parameter values.
    pub values: Vec<(String, Value)>,
    /// The proposal's density at the point (1 for a uniform draw); its weight is `1/density`.
    pub density: f64,
    /// Why the point is no valid map, when it is not (then nothing ran).
    pub rejected: Option<String>,
    /// What the witnesses say (none when rejected).
    pub fairness: Option<Fairness>,
    /// Episodes of the method, over its agents.
    pub episodes: u64,
    /// Those that failed (a collision or a time-out).
    pub failed: u64,
    /// The smallest clearance car–pedestrian over the method's episodes, m.
    pub min_clearance_m: Option<f64>,
    /// The smallest time-to-collision over them, s.
    pub min_ttc_s: Option<f64>,
    /// The smallest stopping margin over them, m (absent from draws written before it
    /// was kept).
    #[serde(default)]
    pub min_stop_margin_m: Option<f64>,
    /// The smallest clearance car–vehicle over them, m (absent as the stopping margin).
    #[serde(default)]
    pub min_vehicle_clearance_m: Option<f64>,
    /// The smallest post-encroachment time car–pedestrian over them, s (absent as the
    /// vehicle clearance).
    #[serde(default)]
    pub min_pet_s: Option<f64>,
}

impl Draw {
    /// The share of its episodes that failed (0 when none ran).
    pub fn failed_share(&self) -> f64 {
        if self.episodes == 0 {
            0.0
        } else {
            self.failed as f64 / self.episodes as f64
        }
    }

    /// Whether it is a valid map (evaluated).
    pub fn valid(&self) -> bool {
        self.fairness.is_some()
    }

    /// Whether the witnesses found it fair.
    pub fn fair(&self) -> bool {
        self.fairness.is_some_and(Fairness::is_fair)
    }

    /// Its importance weight, `1/density` (the target is uniform on the cube).
    pub fn weight(&self) -> f64 {
        1.0 / self.density
    }

    /// The cross-entropy stage's score, lower nearer a failure: +∞ when rejected; minus
    /// the failed share when an episode failed. Otherwise, aiming at P(fails) (`is-fails`,
    /// `fair_only` false), the smallest stopping margin (+∞ when the car was never on a
    /// collision course): it falls as the car comes nearer a course it can no longer stop
    /// short of, where the clearance and the post-encroachment time are also small when
    /// the car yields close to a pedestrian and waits (EXPERIMENTS.md, "How rare is a
    /// failure"); aiming at P(fails | fair) (`is`, `fair_only`), +∞ when unfair and 0
    /// when fair, so that the elite is every fair draw until the fair failures alone fill
    /// it (the levels "fair", then "fair and failed": on the jaywalk space the fair draws
    /// that came closest did not lie where the fair failures lie, EXPERIMENTS.md, "How
    /// rare is a failure").
    pub fn score(&self, fair_only: bool) -> f64 {
        if !self.valid() || (fair_only && !self.fair()) {
            f64::INFINITY
        } else if self.failed > 0 {
            -self.failed_share()
        } else if fair_only {
            0.0
        } else {
            self.min_stop_margin_m.unwrap_or(f64::INFINITY)
        }
    }
}

/// The three estimates of a set of draws.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimates {
    /// P(an episode fails).
    pub p_fail: Estimate,
    /// P(an episode fails | the scenario is fair).
    pub p_fail_given_fair: Estimate,
    /// The fair part of the space.
    pub fair_share: Estimate,
}

impl Estimates {
    /// `mc`'s estimates of uniform draws, or those of `is` and `is-fails` of every stage's
    /// draws, each weighted by one over the density of `mixture`, the stages' proposals
    /// pooled ([`proposal::Mixture`]).
    pub fn of(estimator: Estimator, draws: &[Draw], mixture: &proposal::Mixture) -> Estimates {
        let valid: Vec<&Draw> = draws.iter().filter(|d| d.valid()).collect();
        let fair: Vec<&Draw> = valid.iter().copied().filter(|d| d.fair()).collect();
        match estimator {
            Estimator::Mc => {
                let share = |set: &[&Draw]| set.iter().map(|d| d.failed_share()).collect::<Vec<_>>();
                Estimates {
                    p_fail: estimators::monte_carlo(&share(&valid)),
                    p_fail_given_fair: estimators::monte_carlo(&share(&fair)),
                    fair_share: estimators::monte_carlo(
                        &valid.iter().map(|d| f64::from(u8::from(d.fair()))).collect::<Vec<_>>(),
                    ),
                }
            }
            Estimator::Is | Estimator::IsFails => {
                let weight = |d: &Draw| mixture.weight(&d.point);
                let weighted = |set: &[&Draw]| set.iter().map(|d| (weight(d), d.failed_share())).collect::<Vec<_>>();
                Estimates {
                    p_fail: estimators::importance(&weighted(&valid)),
                    p_fail_given_fair: estimators::importance(&weighted(&fair)),
                    fair_share: estimators::importance(
                        &valid
                            .iter()
                            .map(|d| (weight(d), f64::from(u8::from(d.fair()))))
                            .collect::<Vec<_>>(),
                    ),
                }
            }
        }
    }

    /// Whether the probabilities `estimator` aims at reach the relative half-width
    /// `target`: both for `mc`, P(fails | fair) for `is`, P(fails) for `is-fails`.
    pub fn reach(&self, estimator: Estimator, target: f64) -> bool {
        match estimator {
            Estimator::Mc => self.p_fail.reaches(target) && self.p_fail_given_fair.reaches(target),
            Estimator::Is => self.p_fail_given_fair.reaches(target),
            Estimator::IsFails => self.p_fail.reaches(target),
        }
    }
}

/// Everything an estimate found, in memory (what [`EstimateJob::run`] writes).
#[derive(Debug, Clone)]
pub struct Outcome {
    /// Every draw, in order.
    pub draws: Vec<Draw>,
    /// The estimates.
    pub estimates: Estimates,
    /// The proposal of the final stage (the uniform cube for `mc`).
    pub proposal: Proposal,
    /// Every stage's proposal with its number of draws, whose mixture weighs the draws of
    /// `is` and `is-fails` (none for `mc`).
    pub mixture: Option<proposal::Mixture>,
    /// Whether the target was reached (else the budget was spent).
    pub reached: bool,
    /// The estimates after each block of the estimating stage, as the stopping rule saw them.
    pub checkpoints: Vec<Checkpoint>,
}

/// The two probabilities' estimates after one block of the estimating stage (the
/// estimate against evaluations: EXPERIMENTS.md, "How rare is a failure").
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// Draws evaluated so far (the cross-entropy rounds' included).
    pub evaluations: usize,
    /// P(an episode fails) over the draws so far (`mc`'s; every stage's for `is` and
    /// `is-fails`).
    pub p_fail: Estimate,
    /// P(fails | fair) over them.
    pub p_fail_given_fair: Estimate,
}

/// The size of a cross-entropy round of `is` and `is-fails` with `budget` draws, and the
/// most rounds: a tenth of the budget (at least [`MIN_BLOCK`]), at most [`MAX_ROUNDS`]
/// rounds and half the budget.
pub fn rounds(budget: usize) -> (usize, usize) {
    let round = (budget / 10).max(MIN_BLOCK);
    (round, MAX_ROUNDS.min(budget / 2 / round).max(1))
}

/// The blocks of the estimating stage (`mc`'s uniform draws, the final ones of `is` and
/// `is-fails`): its `draws` in blocks of a twentieth of the `budget`, each at least
/// [`MIN_BLOCK`] (`budget` at least [`Estimator::min_budget`]).
pub fn blocks(draws: usize, budget: usize) -> Vec<usize> {
    let n = (draws / (budget / 20).max(MIN_BLOCK)).max(1);
    (0..n).map(|k| draws * (k + 1) / n - draws * k / n).collect()
}

/// What a run ended with.
#[derive(Debug, Clone)]
enum Ended {
    /// The estimate, finished.
    Finished(Box<Outcome>),
    /// A shard's part of a stage, and the draws it evaluated.
    Shard(ShardPart, Vec<Draw>),
}

/// What a shard (`--shard I/N`) evaluated: its share of the first stage that its file
/// (with `--resume`, the draws read back) does not complete, the draws of index
/// `≡ I − 1 (mod N)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ShardPart {
    /// The shard.
    pub shard: Shard,
    /// The stage it took its share of: a cross-entropy round whole, or the estimating
    /// stage (`mc`'s uniform draws, the final ones of `is` and `is-fails`) from its first block
    /// incomplete to the budget. None when the file holds every draw the estimate
    /// needs: a run without `--shard` finishes it with `--resume`.
    pub stage: Option<DrawStage>,
    /// Its share of that stage.
    pub share: usize,
    /// Of its share, the draws evaluated now (the rest were in the file).
    pub evaluated: usize,
    /// The draws its file holds.
    pub draws: usize,
}

/// What a run wrote: the estimate's summary, or a shard's part.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum Report {
    /// The estimate, finished: `summary.json`.
    Estimate(Box<Summary>),
    /// A shard's part: only `estimate.jsonl` was written.
    Shard(ShardPart),
}

/// One run of an estimate: its configuration, the draws of an earlier run of the same
/// request read back (`--resume`, [`resume`]: each is checked against the draw the run
/// derives at its index when it is taken), the part its fresh draws are appended to as
/// they come, its shard, its progress and the evaluator of its draws when not here.
struct Run<'a, 'b> {
    cfg: &'a SearchConfig<'b>,
    kept: BTreeMap<usize, resume::Kept>,
    /// The file the kept draws were read from, for errors.
    read: PathBuf,
    /// The part, created with `head` (the identity and the kept draws) at the first
    /// fresh draw: a run that evaluates nothing, or refuses a kept draw before, leaves the
    /// folder's files as they were.
    part: PathBuf,
    head: String,
    sink: Mutex<Option<Streamed>>,
    shard: Option<Shard>,
    progress: &'a dyn Progress,
    remote: Option<&'a dyn Evaluator>,
}

impl Run<'_, '_> {
    /// The draws `range` of `stage` from `proposal`, in index order: those kept, checked,
    /// and the rest that `only` deals (all when none) evaluated, one phase of `progress`:
    /// here in parallel (taken in index order), or by `remote` in one call (the draws'
    /// valid maps as the search's candidates, [`CandidateWire`]; the lines it returns
    /// checked as the search checks them). Either way the same draws, each appended to
    /// the part as it comes.
    fn block(
        &self,
        proposal: &Proposal,
        stage: DrawStage,
        range: Range<usize>,
        only: Option<Shard>,
    ) -> Result<Vec<Draw>, Error> {
        let cfg = self.cfg;
        let dims = cfg.space.params.len();
        let stream = stage.stream();
        let mut kept = Vec::new();
        let mut fresh = Vec::new();
        for i in range {
            let taken = self.kept.get(&i);
            if taken.is_none() && !only.is_none_or(|s| s.deals(i)) {
                continue;
            }
            let point = proposal.draw(cfg.seed, &stream, i, dims);
            let density = proposal.density(&point);
            let candidate = Candidate::new(cfg.space, i, Stage::Sobol, point, None);
            match taken {
                Some(k) => kept.push(k.check(cfg, stage, &candidate, density, &self.read)?),
                None => fresh.push((candidate, density)),
            }
        }
        let name = match stage {
            DrawStage::Uniform => "estimate: uniform draws".to_string(),
            DrawStage::Round { round } => format!("estimate: cross-entropy round {}", round + 1),
            DrawStage::Final => "estimate: weighted draws".to_string(),
        };
        self.progress.phase(&name, fresh.len() as u64);
        let done = match self.remote {
            None => fresh
                .into_par_iter()
                .map(|(candidate, density)| {
                    let lines = match &candidate.map {
                        Ok(map) => {
                            let values = candidate.named_values(cfg.space);
                            Some(evaluate_candidate(cfg, &candidate, map, values, self.progress)?)
                        }
                        Err(_) => None,
                    };
                    let draw = Draw::of(cfg, stage, &candidate, density, lines.as_deref());
                    self.append(std::slice::from_ref(&draw))?;
                    crate::progress::step(self.progress)?;
                    Ok(draw)
                })
                .collect::<Result<Vec<_>, Error>>(),
            Some(remote) => evaluate_remotely(cfg, stage, &fresh, self.progress, remote)
                .and_then(|draws| self.append(&draws).map(|()| draws)),
        };
        self.progress.finish();
        let mut draws = done?;
        draws.extend(kept);
        draws.sort_by_key(|d| d.draw);
        Ok(draws)
    }

    /// Appends fresh draws to the part.
    fn append(&self, draws: &[Draw]) -> Result<(), Error> {
        if draws.is_empty() {
            return Ok(());
        }
        let text = draws.iter().map(output::draw_line).collect::<Result<String, Error>>()?;
        let mut sink = self.sink.lock().expect("part lock");
        if sink.is_none() {
            *sink = Some(Streamed::create(&self.part, self.head.as_bytes())?);
        }
        sink.as_mut().expect("created above").append(text.as_bytes())
    }

    /// The shard's part when the run has one and the draws `needed` are not all in the
    /// file: its share of `rest` (the stage from `needed` on) evaluated.
    fn shard_part(
        &self,
        proposal: &Proposal,
        stage: DrawStage,
        needed: Range<usize>,
        rest: Range<usize>,
    ) -> Result<Option<Ended>, Error> {
        let Some(shard) = self.shard else { return Ok(None) };
        if needed.clone().all(|i| self.kept.contains_key(&i)) {
            return Ok(None);
        }
        let share = rest.clone().filter(|&i| shard.deals(i)).count();
        let drawn = self.block(proposal, stage, rest, Some(shard))?;
        let fresh: Vec<Draw> = drawn.into_iter().filter(|d| !self.kept.contains_key(&d.draw)).collect();
        let part = ShardPart {
            shard,
            stage: Some(stage),
            share,
            evaluated: fresh.len(),
            draws: self.kept.len() + fresh.len(),
        };
        Ok(Some(Ended::Shard(part, fresh)))
    }
}

/// The draws `drawn` evaluated by `remote` in one call.
fn evaluate_remotely(
    cfg: &SearchConfig<'_>,
    stage: DrawStage,
    drawn: &[(Candidate, f64)],
    progress: &dyn Progress,
    remote: &dyn Evaluator,
) -> Result<Vec<Draw>, Error> {
    if progress.cancelled() {
        return Err(Error::Interrupted);
    }
    let valid: Vec<&Candidate> = drawn.iter().map(|(c, _)| c).filter(|c| c.map.is_ok()).collect();
    let wires: Vec<CandidateWire> = valid.iter().map(|c| CandidateWire::of(c)).collect();
    let got = if wires.is_empty() {
        Vec::new()
    } else {
        remote.evaluate(&wires)?
    };
    let bad = |problem: String| Error::Results {
        path: cfg.space.source.clone().into(),
        problem: format!("the evaluator of the estimate's draws: {problem}"),
    };
    if got.len() != valid.len() {
        return Err(bad(format!("{} draws' lines returned for {}", got.len(), valid.len())));
    }
    let need = 2 + cfg.train_seeds.len();
    let mut lines = got.into_iter();
    drawn
        .iter()
        .map(|(candidate, density)| {
            let parsed = match &candidate.map {
                Err(_) => None,
                Ok(_) => {
                    let raws = lines.next().expect("as many lines as valid draws (checked)");
                    if raws.len() != need {
                        return Err(bad(format!(
                            "draw {}: {} lines, expected {need}",
                            candidate.index,
                            raws.len()
                        )));
                    }
                    let parsed = raws
                        .iter()
                        .map(|raw| serde_json::from_str::<CandidateLine>(raw.trim_end()))
                        .collect::<Result<Vec<_>, _>>()
                        .map_err(|e| bad(format!("draw {}: a bad line ({e})", candidate.index)))?;
                    if parsed.iter().any(|l| l.candidate != candidate.index) {
                        return Err(bad(format!("draw {}: another draw's line", candidate.index)));
                    }
                    Some(parsed)
                }
            };
            crate::progress::step(progress)?;
            Ok(Draw::of(cfg, stage, candidate, *density, parsed.as_deref()))
        })
        .collect()
}

impl Draw {
    /// The draw of `candidate` (from `stage`, at the proposal's `density`) from its lines
    /// as a search evaluates a candidate ([`evaluate_candidate`]: the witnesses, then the
    /// method per training seed); `None` when it is no valid map.
    fn of(
        cfg: &SearchConfig<'_>,
        stage: DrawStage,
        candidate: &Candidate,
        density: f64,
        lines: Option<&[CandidateLine]>,
    ) -> Draw {
        let mut draw = Draw {
            draw: candidate.index,
            stage,
            point: candidate.point.clone(),
            values: candidate.named_values(cfg.space),
            density,
            rejected: candidate.map.as_ref().err().cloned(),
            fairness: None,
            episodes: 0,
            failed: 0,
            min_clearance_m: None,
            min_ttc_s: None,
            min_stop_margin_m: None,
            min_vehicle_clearance_m: None,
            min_pet_s: None,
        };
        let Some(lines) = lines else { return draw };
        draw.fairness = lines.first().map(|l| l.fairness);
        for l in lines.iter().filter(|l| l.role == Role::Method) {
            let r = &l.result;
            draw.episodes += r.episodes;
            draw.failed += (r.episodes as f64 * (1.0 - r.success_rate)).round() as u64;
            let m = &r.margins;
            for (least, x) in [
                (&mut draw.min_clearance_m, m.min_clearance_m),
                (&mut draw.min_ttc_s, m.min_ttc_s),
                (&mut draw.min_stop_margin_m, m.min_stop_margin_m),
                (&mut draw.min_vehicle_clearance_m, m.min_vehicle_clearance_m),
                (&mut draw.min_pet_s, m.min_pet_s),
            ] {
                *least = match (*least, x) {
                    (Some(a), Some(b)) => Some(a.min(b)),
                    (a, b) => a.or(b),
                };
            }
        }
        draw
    }
}

/// Runs the estimate `r` on the search configuration `cfg` (its space, method, agents,
/// episodes and seed; its budget and stages unused) into `r.out`, on `cfg.jobs` threads,
/// each block's draws evaluated here or by `remote` (a distributed driver's), the same
/// draws either way; with `r.resume`, from the draws an earlier run of the same request
/// left there, and with `r.shard`, only the shard's part of the next stage. `guard` is
/// the job's output guard, held while the run writes.
///
/// The fresh draws are streamed to `estimate.jsonl.part` ([`output::DRAWS_PART`]) as
/// they are evaluated (after the identity and the draws kept; the part is made at the
/// first fresh draw), and the set is committed as one at the end
/// ([`crate::files::all_or_none`]), the part removed with it: a run that fails or is
/// killed partway leaves the earlier set as it was, and the part for `--resume`, which
/// reads the part when there is one (the latest run into the folder) and
/// `estimate.jsonl` otherwise.
pub(crate) fn run(
    cfg: &SearchConfig<'_>,
    r: &EstimateRequest,
    _guard: &Guarded,
    progress: &dyn Progress,
    remote: Option<&dyn Evaluator>,
) -> Result<Report, Error> {
    let out = Path::new(&r.out);
    std::fs::create_dir_all(out).map_err(|e| Error::io("create folder", out, e))?;
    let (file, part) = (out.join(output::DRAWS), out.join(output::DRAWS_PART));
    let read = if part.is_file() { part.clone() } else { file };
    let identity = output::identity(cfg, r);
    let kept = if r.resume {
        resume::kept_draws(cfg, r, &identity, &read)?
    } else {
        BTreeMap::new()
    };
    let head = std::iter::once(Ok(output::identity_line(&identity)))
        .chain(kept.values().map(|k| output::draw_line(&k.draw)))
        .collect::<Result<String, Error>>()?;
    let run = Run {
        cfg,
        kept,
        read,
        part,
        head,
        sink: Mutex::new(None),
        shard: r.shard,
        progress,
        remote,
    };
    match estimate(&run, r.estimator, r.budget, r.target_rel_error)? {
        Ended::Finished(outcome) => crate::files::all_or_none(|| output::write_all(cfg, r, out, &outcome))
            .map(|s| Report::Estimate(Box::new(s))),
        Ended::Shard(shard_part, fresh) => {
            let mut draws: BTreeMap<usize, Draw> = run.kept.into_iter().map(|(i, k)| (i, k.draw)).collect();
            draws.extend(fresh.into_iter().map(|d| (d.draw, d)));
            let draws: Vec<Draw> = draws.into_values().collect();
            crate::files::all_or_none(|| output::write_shard(cfg, r, out, &draws))?;
            Ok(Report::Shard(shard_part))
        }
    }
}

/// Runs `estimator` with `budget` draws and the target relative half-width `target`
/// (see the module doc), taking the draws `run` kept; with a shard, stops at the first
/// stage the kept draws do not complete, with the shard's part of it.
fn estimate(run: &Run<'_, '_>, estimator: Estimator, budget: usize, target: f64) -> Result<Ended, Error> {
    let cfg = run.cfg;
    let pool = rayon::ThreadPoolBuilder::new().num_threads(cfg.jobs.max(1)).build()?;
    pool.install(|| {
        let (size, most) = rounds(budget);
        let most = if estimator.weighted() { most } else { 0 };
        let mut draws: Vec<Draw> = Vec::new();
        let mut proposal = Proposal::uniform();
        let mut mixture = proposal::Mixture::default();
        for round in 0..most {
            let stage = DrawStage::Round { round };
            let range = draws.len()..draws.len() + size;
            if let Some(part) = run.shard_part(&proposal, stage, range.clone(), range.clone())? {
                return Ok(part);
            }
            draws.extend(run.block(&proposal, stage, range, None)?);
            check_fair_mass(&draws)?;
            mixture.add(size, &proposal);
            let scored: Vec<proposal::Scored<'_>> = draws
                .iter()
                .map(|d| {
                    let score = d.score(estimator == Estimator::Is);
                    (d.point.as_slice(), mixture.weight(&d.point), score)
                })
                .collect();
            proposal = proposal.refit(cfg.space, &scored);
            if proposal::failure_level_reached(&scored) {
                break;
            }
        }
        let stage = match estimator {
            Estimator::Mc => DrawStage::Uniform,
            Estimator::Is | Estimator::IsFails => DrawStage::Final,
        };
        let mut estimates = Estimates::of(estimator, &[], &mixture);
        let mut reached = false;
        let mut checkpoints = Vec::new();
        for size in blocks(budget - draws.len(), budget) {
            let range = draws.len()..draws.len() + size;
            if let Some(part) = run.shard_part(&proposal, stage, range.clone(), range.start..budget)? {
                return Ok(part);
            }
            draws.extend(run.block(&proposal, stage, range, None)?);
            check_fair_mass(&draws)?;
            mixture.add(size, &proposal);
            estimates = Estimates::of(estimator, &draws, &mixture);
            checkpoints.push(Checkpoint {
                evaluations: draws.len(),
                p_fail: estimates.p_fail.clone(),
                p_fail_given_fair: estimates.p_fail_given_fair.clone(),
            });
            if estimates.reach(estimator, target) {
                reached = true;
                break;
            }
        }
        if let Some(shard) = run.shard {
            let part = ShardPart {
                shard,
                stage: None,
                share: 0,
                evaluated: 0,
                draws: run.kept.len(),
            };
            return Ok(Ended::Shard(part, Vec::new()));
        }
        Ok(Ended::Finished(Box::new(Outcome {
            draws,
            estimates,
            proposal,
            mixture: estimator.weighted().then_some(mixture),
            reached,
            checkpoints,
        })))
    })
}

/// Refuses a space none of whose draws so far is fair: P(fail | fair) is not defined
/// where the fair part has no mass.
fn check_fair_mass(draws: &[Draw]) -> Result<(), Error> {
    if draws.iter().any(Draw::fair) {
        return Ok(());
    }
    let valid = draws.iter().filter(|d| d.valid()).count();
    let bound = estimators::monte_carlo(&vec![0.0; valid]).ci95_high.unwrap_or(1.0);
    Err(Error::request(
        "space",
        format!(
            "none of the first {} draws ({valid} valid maps) is fair (the fair share is below {:.1}% at 95%): \
             P(fail | fair) is not defined on a space whose fair part has no mass; choose a space with fair \
             scenarios (`unforeseen search` counts them)",
            draws.len(),
            100.0 * bound
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::episodes::Method;
    use crate::progress::NoProgress;

    fn setup(estimator: Estimator) -> EstimateSetup {
        let space = concat!(env!("CARGO_MANIFEST_DIR"), "/../maps/spaces/jaywalk.ron");
        EstimateRequest {
            space: space.into(),
            method: Method::NeverBrake,
            estimator,
            episodes: 1,
            budget: estimator.min_budget(),
            ..EstimateRequest::default()
        }
        .setup()
        .unwrap()
    }

    #[test]
    fn the_same_request_gives_the_same_draws_and_estimates_whatever_the_threads() {
        for estimator in Estimator::ALL {
            let s = setup(estimator);
            let dir = tempfile::tempdir().unwrap();
            let run = |jobs| {
                let cfg = s.search.config(&[], jobs, String::new());
                let part = dir.path().join(format!("{jobs}.part"));
                let run = Run {
                    cfg: &cfg,
                    kept: BTreeMap::new(),
                    read: part.clone(),
                    part,
                    head: String::new(),
                    sink: Mutex::new(None),
                    shard: None,
                    progress: &NoProgress,
                    remote: None,
                };
                match estimate(&run, estimator, estimator.min_budget(), 0.01).unwrap() {
                    Ended::Finished(outcome) => *outcome,
                    Ended::Shard(..) => unreachable!("no shard"),
                }
            };
            let (one, two) = (run(1), run(2));
            assert_eq!(one.draws, two.draws, "{estimator}");
            assert_eq!(one.estimates, two.estimates, "{estimator}");
            assert_eq!(one.draws.len(), estimator.min_budget());
            // never-brake fails most fair scenarios (it fails at least 80% of a fair
            // scenario's episodes): near 1, or for `is` on its 50 final draws, a refusal.
            let e = &one.estimates.p_fail_given_fair;
            assert!(
                e.p.is_some_and(|p| p > 0.8) || (estimator.weighted() && e.refused.is_some()),
                "{estimator}: {e:#?}"
            );
            // The defensive mixture bounds every weight by 1/α.
            assert!(
                one.draws
                    .iter()
                    .all(|d| d.weight() <= 1.0 / proposal::DEFENSIVE + 1e-12)
            );
        }
    }

    /// Asks the run to stop once `limit` draws are done.
    struct CancelAfter(std::sync::atomic::AtomicU64, u64);

    impl Progress for CancelAfter {
        fn phase(&self, _: &str, _: u64) {}
        fn advance(&self, n: u64) {
            self.0.fetch_add(n, std::sync::atomic::Ordering::SeqCst);
        }
        fn finish(&self) {}
        fn message(&self, _: crate::progress::Message, _: &str) {}
        fn cancelled(&self) -> bool {
            self.0.load(std::sync::atomic::Ordering::SeqCst) >= self.1
        }
    }

    #[test]
    fn a_cancelled_estimate_resumes_to_the_files_of_one_never_cancelled() {
        let dir = tempfile::tempdir().unwrap();
        for estimator in Estimator::ALL {
            let budget = if estimator == Estimator::Mc { 100 } else { 200 };
            let request = |name: &str, resume: bool| EstimateRequest {
                out: dir.path().join(format!("{estimator}-{name}")),
                resume,
                jobs: Some(2),
                budget,
                target_rel_error: 0.01,
                ..setup(estimator).request
            };
            let files = |name: &str| {
                let out = dir.path().join(format!("{estimator}-{name}"));
                [output::DRAWS, output::SUMMARY].map(|f| std::fs::read(out.join(f)).unwrap())
            };
            request("whole", false).plan().unwrap().run(&[], &NoProgress).unwrap();
            // Cancelled in the last block of 50 (for is and is-fails, in its final draws, after
            // the rounds, whose refits the resumed run redoes from the kept draws).
            let cancel = CancelAfter(Default::default(), budget as u64 - 30);
            let e = request("cut", false).plan().unwrap().run(&[], &cancel).err().unwrap();
            assert!(matches!(e, Error::Interrupted), "{e}");
            let out = dir.path().join(format!("{estimator}-cut"));
            assert!(!out.join(output::DRAWS).exists() && !out.join(output::SUMMARY).exists());
            let part = std::fs::read_to_string(out.join(output::DRAWS_PART)).unwrap();
            assert!(part.lines().count() > 1, "{estimator}: the part holds the draws done");
            request("cut", true).plan().unwrap().run(&[], &NoProgress).unwrap();
            assert_eq!(files("cut"), files("whole"), "{estimator}");
            assert!(!out.join(output::DRAWS_PART).exists());
        }
    }

    #[test]
    fn the_stages_split_the_budget() {
        assert_eq!(blocks(1000, 1000), vec![50; 20]);
        assert_eq!(rounds(1000), (100, 5));
        assert_eq!(rounds(2000), (200, 5));
        assert_eq!(rounds(200), (50, 2), "the rounds take at most half of the budget");
        assert_eq!(blocks(100, 200), vec![50; 2]);
        assert_eq!(blocks(700, 1000), vec![50; 14]);
        assert_eq!(blocks(75, 200), vec![75], "one block of the rest when it is under two");
        let finals = blocks(1470, 2000);
        assert_eq!(finals.iter().sum::<usize>(), 1470);
        assert!(finals.iter().all(|&b| b >= MIN_BLOCK));
    }
}
