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
//! **Estimators** ([`estimators`]), each stopping once both probabilities' relative
//! half-widths are at most the target or the budget of draws is spent, checked after
//! each block of draws (blocks of fixed sizes, so the stopping point does not depend on
//! the threads):
//!
//! * **mc**: independent uniform draws; the mean with its Wilson interval, over the valid
//!   draws and over the fair ones (conditionally on their number, the fair draws are
//!   independent draws of the distribution restricted to the fair part).
//! * **is**, **is-fails**: cross-entropy importance sampling. [`ROUNDS`] rounds of draws,
//!   the first uniform, each refitting the proposal ([`proposal`]: a defensive mixture of
//!   the uniform and a product of marginals, of which only those the elite departs in
//!   move) to the elite of the draws so far, each draw weighted as below. A draw's
//!   *score* ([`Draw::score`]) is minus its failed share when it failed; otherwise `is`,
//!   aimed at P(fails | fair), scores a fair draw 0 and an unfair one +∞ (its elite is
//!   every fair draw until the fair failures alone fill it), and `is-fails`, aimed at
//!   P(fails), scores a valid draw by its smallest clearance car–pedestrian. Then a final
//!   stage from the last proposal. The estimates pool every stage's draws, rounds
//!   included, each weighted by one over the density of the mixture of the stages'
//!   proposals in proportion to their draws ([`proposal::Mixture`], the balance
//!   heuristic): self-normalised, P(fails | fair) the ratio of the weighted fair failures
//!   to the weighted fair draws, with the Wilson interval at the delta method's effective
//!   sample size, the ESS, the largest weight's share and refusals when the weights
//!   degenerate or carry under 5 effective failures ([`estimators::importance`]).
//!
//! What these measured (EXPERIMENTS.md, "How rare is a failure"): on the jaywalk space,
//! whose fair failures have no structure a product of marginals can fit, `is` is about
//! as precise as `mc` at equal draws on P(fails | fair) (its intervals covered the
//! reference in 17 of 20 repetitions of 2000 draws, one refused), so `mc` is the default.
//!
//! Every draw has its own generator (run seed, stage, index) and its episodes their own
//! seeds, and draws are evaluated in parallel but taken in index order, so the same
//! request gives the same files bit for bit whatever the number of threads.
//!
//! Outputs ([`output`]): `estimate.jsonl` (the run's identity, then one line per draw)
//! and `summary.json` (the estimates, their intervals and diagnostics, the failure
//! threshold), written together at the end.

pub mod estimators;
pub mod output;
pub mod proposal;
pub mod request;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::Error;
use crate::progress::Progress;
use crate::runs::search::{
    Candidate, CandidateLine, CandidateWire, Evaluator, Fairness, Role, SearchConfig, Stage, Value, evaluate_candidate,
};

pub use estimators::Estimate;
pub use output::{EstimateIdentity, Summary};

pub use proposal::Proposal;
pub use request::{EstimateJob, EstimateRequest, EstimateSetup, Estimator};

/// Rounds of the cross-entropy stage of `is` (the first from the uniform cube).
pub const ROUNDS: usize = 3;
/// Fewest draws of one block (one round of `is`, one check of the stopping rule).
pub const MIN_BLOCK: usize = 50;
/// Most draws one estimate may have.
pub const MAX_BUDGET: usize = 1_000_000;

/// Which stage made a draw.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum DrawStage {
    /// A uniform draw of `mc`.
    Uniform,
    /// Round `round` of the cross-entropy stage of `is`.
    Round {
        /// 0-based round.
        round: usize,
    },
    /// The final, weighted stage of `is`.
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
    /// `fair_only` false), the smallest clearance car–pedestrian (+∞ without a
    /// pedestrian); aiming at P(fails | fair) (`is`, `fair_only`), +∞ when unfair and 0
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
            self.min_clearance_m.unwrap_or(f64::INFINITY)
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
    /// `mc`'s estimates of uniform draws, or `is`'s of every stage's draws, each weighted
    /// by one over the density of `mixture`, the stages' proposals pooled ([`proposal::Mixture`]).
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

    /// Whether both probabilities reach the relative half-width `target`.
    pub fn reach(&self, target: f64) -> bool {
        self.p_fail.reaches(target) && self.p_fail_given_fair.reaches(target)
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
    /// Every stage's proposal with its number of draws, whose mixture weighs `is`'s draws
    /// (none for `mc`).
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
    /// P(an episode fails) over the estimating stage's draws so far.
    pub p_fail: Estimate,
    /// P(fails | fair) over them.
    pub p_fail_given_fair: Estimate,
}

/// The sizes of the stages of `estimator` with `budget` draws: for `mc` its blocks;
/// for `is` the cross-entropy rounds, then the final stage's blocks. Every block has
/// at least [`MIN_BLOCK`] draws (`budget` at least [`Estimator::min_budget`]).
pub fn blocks(estimator: Estimator, budget: usize) -> (Vec<usize>, Vec<usize>) {
    let split = |total: usize, size: usize| {
        let n = (total / size).max(1);
        (0..n).map(|k| total * (k + 1) / n - total * k / n).collect::<Vec<_>>()
    };
    let block = (budget / 20).max(MIN_BLOCK);
    match estimator {
        Estimator::Mc => (Vec::new(), split(budget, block)),
        Estimator::Is | Estimator::IsFails => {
            let round = (budget / 10).max(MIN_BLOCK);
            let rest = budget - ROUNDS * round;
            (vec![round; ROUNDS], split(rest, block.min(rest)))
        }
    }
}

/// Evaluates the draws `range` of `stage` from `proposal`, one phase of `progress`: here
/// in parallel (taken in index order), or by `remote` in one call (the draws' valid maps
/// as the search's candidates, [`CandidateWire`]; the lines it returns checked as the
/// search checks them). Either way the same draws.
fn evaluate_block(
    cfg: &SearchConfig<'_>,
    proposal: &Proposal,
    stage: DrawStage,
    range: std::ops::Range<usize>,
    progress: &dyn Progress,
    remote: Option<&dyn Evaluator>,
) -> Result<Vec<Draw>, Error> {
    let dims = cfg.space.params.len();
    let name = match stage {
        DrawStage::Uniform => "estimate mc".to_string(),
        DrawStage::Round { round } => format!("estimate is round {}", round + 1),
        DrawStage::Final => "estimate is final".to_string(),
    };
    progress.phase(&name, range.len() as u64);
    let stream = stage.stream();
    let drawn: Vec<(Candidate, f64)> = range
        .map(|i| {
            let point = proposal.draw(cfg.seed, &stream, i, dims);
            let density = proposal.density(&point);
            (Candidate::new(cfg.space, i, Stage::Sobol, point, None), density)
        })
        .collect();
    let done = match remote {
        None => drawn
            .into_par_iter()
            .map(|(candidate, density)| {
                let lines = match &candidate.map {
                    Ok(map) => {
                        let values = candidate.named_values(cfg.space);
                        Some(evaluate_candidate(cfg, &candidate, map, values, progress)?)
                    }
                    Err(_) => None,
                };
                crate::progress::step(progress)?;
                Ok(Draw::of(cfg, stage, &candidate, density, lines.as_deref()))
            })
            .collect::<Result<Vec<_>, Error>>(),
        Some(remote) => evaluate_remotely(cfg, stage, &drawn, progress, remote),
    };
    progress.finish();
    done
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
        };
        let Some(lines) = lines else { return draw };
        draw.fairness = lines.first().map(|l| l.fairness);
        for l in lines.iter().filter(|l| l.role == Role::Method) {
            let r = &l.result;
            draw.episodes += r.episodes;
            draw.failed += (r.episodes as f64 * (1.0 - r.success_rate)).round() as u64;
            let least = |a: Option<f64>, b: Option<f64>| match (a, b) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
            draw.min_clearance_m = least(draw.min_clearance_m, r.min_clearance_m);
            draw.min_ttc_s = least(draw.min_ttc_s, r.min_ttc_s);
        }
        draw
    }
}

/// Runs `estimator` on the search configuration `cfg` (its space, method, agents,
/// episodes and seed; its budget and stages unused) with `budget` draws and the target
/// relative half-width `target`, on `cfg.jobs` threads, each block's draws evaluated
/// here or by `remote` (a distributed driver's), the same draws either way.
pub fn estimate(
    cfg: &SearchConfig<'_>,
    estimator: Estimator,
    budget: usize,
    target: f64,
    progress: &dyn Progress,
    remote: Option<&dyn Evaluator>,
) -> Result<Outcome, Error> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(cfg.jobs.max(1)).build()?;
    pool.install(|| {
        let (rounds, finals) = blocks(estimator, budget);
        let mut draws: Vec<Draw> = Vec::new();
        let mut proposal = Proposal::uniform();
        let mut mixture = proposal::Mixture::default();
        for (round, size) in rounds.into_iter().enumerate() {
            let next = draws.len();
            draws.extend(evaluate_block(
                cfg,
                &proposal,
                DrawStage::Round { round },
                next..next + size,
                progress,
                remote,
            )?);
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
        }
        let stage = match estimator {
            Estimator::Mc => DrawStage::Uniform,
            Estimator::Is | Estimator::IsFails => DrawStage::Final,
        };
        let mut estimates = Estimates::of(estimator, &[], &mixture);
        let mut reached = false;
        let mut checkpoints = Vec::new();
        for size in finals {
            let next = draws.len();
            draws.extend(evaluate_block(
                cfg,
                &proposal,
                stage,
                next..next + size,
                progress,
                remote,
            )?);
            check_fair_mass(&draws)?;
            mixture.add(size, &proposal);
            estimates = Estimates::of(estimator, &draws, &mixture);
            checkpoints.push(Checkpoint {
                evaluations: draws.len(),
                p_fail: estimates.p_fail.clone(),
                p_fail_given_fair: estimates.p_fail_given_fair.clone(),
            });
            if estimates.reach(target) {
                reached = true;
                break;
            }
        }
        Ok(Outcome {
            draws,
            estimates,
            proposal,
            mixture: estimator.weighted().then_some(mixture),
            reached,
            checkpoints,
        })
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
            let run = |jobs| {
                let cfg = s.search.config(&[], jobs, String::new());
                estimate(&cfg, estimator, estimator.min_budget(), 0.01, &NoProgress, None).unwrap()
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

    #[test]
    fn the_stages_split_the_budget() {
        assert_eq!(blocks(Estimator::Mc, 1000), (Vec::new(), vec![50; 20]));
        let (rounds, finals) = blocks(Estimator::Is, 1000);
        assert_eq!(rounds, vec![100; 3]);
        assert_eq!(finals.iter().sum::<usize>(), 700);
        assert!(finals.iter().all(|&b| b >= MIN_BLOCK));
        assert_eq!(blocks(Estimator::Is, 200), (vec![50; 3], vec![50]));
    }
}
