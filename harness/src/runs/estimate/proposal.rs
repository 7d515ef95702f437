//! The importance-sampling proposal over the space's unit cube: the uniform cube at
//! first, then a defensive mixture (Hesterberg 1995) `q = α + (1 − α) ∏ f_d`, `α =`
//! [`DEFENSIVE`], of one marginal per parameter (uniform, a normal truncated to [0, 1] for
//! a range, or cell probabilities spread evenly within each cell for a count or a choice,
//! each moved one itself a mixture with [`SPREAD`] of the uniform), refitted by the
//! cross-entropy method (Rubinstein 1999) to the draws with the smallest scores. A refit
//! moves only the marginals whose elite departs from the uniform beyond its noise ([`MOVE_Z`] standard errors, at the elite's effective size); every other
//! parameter stays uniform, so a 17-parameter space whose failures depend on three is
//! fitted in three (a product of 17 refitted marginals makes weights vary in every
//! dimension, noise included). The uniform part keeps every point of the cube in the
//! proposal's support and bounds every weight `1/q` by `1/α`.
//!
//! The estimate pools every stage's draws ([`Mixture`]): a draw's weight is the target's
//! density over the *mixture* of the proposals weighted by their numbers of draws (the
//! balance heuristic of multiple importance sampling, Veach & Guibas 1995; Owen & Zhou
//! 2000), bounded by the total draws over the uniform round's.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};
use statrs::distribution::{Continuous, ContinuousCDF, Normal};

use crate::runs::search::Space;
use unforeseen_env::seeds::episode_seed;

/// The uniform share of a fitted proposal.
pub const DEFENSIVE: f64 = 0.2;
/// Share of the scored draws that form the elite.
pub const ELITE_SHARE: f64 = 0.1;
/// Fewest elite draws (a refit waits until it has them).
pub const MIN_ELITE: usize = 5;
/// Smallest standard deviation of a range's normal, on the unit interval.
pub const MIN_SD: f64 = 0.01;
/// The uniform share within each moved marginal: a parameter the elite moved on noise,
/// or narrower than the failures spread, still draws over its whole range.
pub const SPREAD: f64 = 0.2;
/// Standard errors by which an elite's marginal must depart from the uniform for a refit
/// to move it (its mean, its spread, or a cell's frequency).
pub const MOVE_Z: f64 = 3.0;
/// The fourth central moment of the uniform interval minus its variance squared
/// (`1/80 − 1/144`): `n` times the variance of the variance of `n` uniform points.
const VAR_OF_VAR: f64 = 1.0 / 80.0 - 1.0 / 144.0;

/// One parameter's part of a fitted proposal.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Marginal {
    /// The uniform interval (the target's own marginal: weight 1).
    Uniform,
    /// A normal (mean, standard deviation) truncated to [0, 1], mixed with [`SPREAD`] of
    /// the uniform interval.
    Normal {
        /// Mean, on the unit interval.
        mean: f64,
        /// Standard deviation, on the unit interval.
        sd: f64,
    },
    /// The cells' probabilities (each spread evenly over its cell; a fitted one holds
    /// [`SPREAD`] of the even cells).
    Cells(Vec<f64>),
}

/// The proposal: the uniform cube, or a fitted defensive mixture.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Proposal {
    /// The fitted marginals (none: the uniform cube).
    pub marginals: Option<Vec<Marginal>>,
}

/// A point to refit on: its coordinates, its weight (target over proposal density) and
/// its score (lower is nearer a failure; infinite never counts).
pub type Scored<'a> = (&'a [f64], f64, f64);

impl Proposal {
    /// The uniform cube.
    pub fn uniform() -> Proposal {
        Proposal { marginals: None }
    }

    /// The density at `x` (1 for the uniform cube).
    pub fn density(&self, x: &[f64]) -> f64 {
        let Some(marginals) = &self.marginals else { return 1.0 };
        let product: f64 = marginals.iter().zip(x).map(|(m, &u)| marginal_density(m, u)).product();
        DEFENSIVE + (1.0 - DEFENSIVE) * product
    }

    /// Draw `index` of the stream `stream` of run seed `seed`, with `dims` coordinates:
    /// its own generator, so that draws do not depend on each other's order.
    pub fn draw(&self, seed: u64, stream: &str, index: usize, dims: usize) -> Vec<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(episode_seed(seed, stream, index as u64));
        let fitted = self
            .marginals
            .as_ref()
            .filter(|_| rng.random_range(0.0..1.0) >= DEFENSIVE);
        match fitted {
            None => (0..dims).map(|_| rng.random_range(0.0..1.0)).collect(),
            Some(ms) => ms.iter().map(|m| marginal_draw(m, &mut rng)).collect(),
        }
    }

    /// The cross-entropy refit to the elite of `scored`: the [`ELITE_SHARE`] of the draws
    /// with a finite score (at least [`MIN_ELITE`]; fewer: no refit), lowest first, ties
    /// by order, and every failure (a negative score) when there are more (the multilevel
    /// method's level: the elite's threshold is the larger of the quantile and the
    /// failure level); every draw scoring the threshold joins. A parameter's marginal
    /// moves only when the elite's weighted marginal departs from the uniform by more than
    /// [`MOVE_Z`] standard errors at the elite's effective size (Kish's): its mean, its
    /// variance (smaller only) or a cell's frequency; it is then the elite's weighted mean
    /// and standard deviation, floored at [`MIN_SD`] (or its cell frequencies), mixed
    /// with [`SPREAD`] of the uniform, without smoothing toward the marginal before: a
    /// failure region that fills 1% of a parameter's range is reached within the rounds,
    /// where smoothing held the proposal wide (EXPERIMENTS.md, "How rare is a failure").
    /// Any other marginal is the uniform.
    pub fn refit(&self, space: &Space, scored: &[Scored<'_>]) -> Proposal {
        let mut order: Vec<usize> = (0..scored.len()).filter(|&i| scored[i].2.is_finite()).collect();
        if order.len() < MIN_ELITE {
            return self.clone();
        }
        order.sort_by(|&a, &b| scored[a].2.total_cmp(&scored[b].2).then(a.cmp(&b)));
        let failures = order.iter().filter(|&&i| scored[i].2 < 0.0).count();
        let n = quantile_size(order.len()).max(failures).min(order.len());
        // Every draw at the threshold joins (the elite is {score ≤ γ}).
        let threshold = scored[order[n - 1]].2;
        let n = order.iter().take_while(|&&i| scored[i].2 <= threshold).count();
        let elite: Vec<(&[f64], f64)> = order[..n].iter().map(|&i| (scored[i].0, scored[i].1)).collect();
        let total: f64 = elite.iter().map(|e| e.1).sum();
        let n_eff = total * total / elite.iter().map(|e| e.1 * e.1).sum::<f64>();
        let marginals: Vec<Marginal> = (0..space.params.len())
            .map(|d| match space.params[d].cells() {
                None => {
                    let mu = elite.iter().map(|(x, w)| w * x[d]).sum::<f64>() / total;
                    let var = elite.iter().map(|(x, w)| w * (x[d] - mu).powi(2)).sum::<f64>() / total;
                    let z_mean = (mu - 0.5) / (1.0 / 12.0 / n_eff).sqrt();
                    let z_var = (var - 1.0 / 12.0) / (VAR_OF_VAR / n_eff).sqrt();
                    if z_mean.abs() <= MOVE_Z && z_var >= -MOVE_Z {
                        return Marginal::Uniform;
                    }
                    Marginal::Normal {
                        mean: mu,
                        sd: var.sqrt().max(MIN_SD),
                    }
                }
                Some(k) => {
                    let even = 1.0 / k as f64;
                    let mut freq = vec![0.0; k];
                    for (x, w) in &elite {
                        freq[cell(x[d], k)] += w / total;
                    }
                    let noise = MOVE_Z * (even * (1.0 - even) / n_eff).sqrt();
                    if freq.iter().all(|f| (f - even).abs() <= noise) {
                        return Marginal::Cells(vec![even; k]);
                    }
                    Marginal::Cells(freq.into_iter().map(|f| SPREAD * even + (1.0 - SPREAD) * f).collect())
                }
            })
            .collect();
        let moved = marginals.iter().any(|m| match m {
            Marginal::Uniform => false,
            Marginal::Normal { .. } => true,
            Marginal::Cells(p) => p.iter().any(|&x| x != 1.0 / p.len() as f64),
        });
        Proposal {
            marginals: moved.then_some(marginals),
        }
    }
}

/// Whether the failures of `scored` fill the elite's quantile ([`ELITE_SHARE`] of the
/// draws with a finite score, at least [`MIN_ELITE`]): the multilevel method's threshold
/// has reached the failure level, so a refit fits the failures alone and a further round
/// would only add draws to the same fit.
pub fn failure_level_reached(scored: &[Scored<'_>]) -> bool {
    let finite = scored.iter().filter(|s| s.2.is_finite()).count();
    let failures = scored.iter().filter(|s| s.2 < 0.0).count();
    finite >= MIN_ELITE && failures >= quantile_size(finite)
}

/// The elite's quantile among `finite` scored draws: [`ELITE_SHARE`] of them, at least
/// [`MIN_ELITE`].
fn quantile_size(finite: usize) -> usize {
    ((finite as f64 * ELITE_SHARE).ceil() as usize).max(MIN_ELITE)
}

/// The proposals of an estimate's stages, each with its number of draws: the pooled draws
/// are a stratified sample of their mixture `Σ n_k q_k / Σ n_k`, and each draw's weight
/// is the target's density (1) over the mixture's.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Mixture {
    /// Each proposal and its number of draws.
    pub parts: Vec<(usize, Proposal)>,
}

impl Mixture {
    /// Adds `n` draws of `q` (to its part when `q` is the last part's proposal).
    pub fn add(&mut self, n: usize, q: &Proposal) {
        match self.parts.last_mut() {
            Some((m, last)) if last == q => *m += n,
            _ => self.parts.push((n, q.clone())),
        }
    }

    /// The mixture's density at `x` (1 with no part).
    pub fn density(&self, x: &[f64]) -> f64 {
        let total: usize = self.parts.iter().map(|p| p.0).sum();
        if total == 0 {
            return 1.0;
        }
        self.parts.iter().map(|(n, q)| *n as f64 * q.density(x)).sum::<f64>() / total as f64
    }

    /// The weight of a draw at `x`: one over the mixture's density.
    pub fn weight(&self, x: &[f64]) -> f64 {
        1.0 / self.density(x)
    }
}

/// The cell of coordinate `u` among `k`.
fn cell(u: f64, k: usize) -> usize {
    ((u * k as f64).floor().max(0.0) as usize).min(k - 1)
}

/// The truncated normal of (mean, sd), and its mass in [0, 1].
fn truncated(mean: f64, sd: f64) -> (Normal, f64, f64) {
    let n = Normal::new(mean, sd).expect("a finite mean and sd >= MIN_SD");
    let (lo, hi) = (n.cdf(0.0), n.cdf(1.0));
    (n, lo, hi - lo)
}

fn marginal_density(m: &Marginal, u: f64) -> f64 {
    match m {
        Marginal::Uniform => 1.0,
        Marginal::Normal { mean, sd } => {
            let (n, _, mass) = truncated(*mean, *sd);
            SPREAD + (1.0 - SPREAD) * n.pdf(u) / mass
        }
        Marginal::Cells(p) => p[cell(u, p.len())] * p.len() as f64,
    }
}

fn marginal_draw(m: &Marginal, rng: &mut ChaCha8Rng) -> f64 {
    let u: f64 = rng.random_range(0.0..1.0);
    let x = match m {
        Marginal::Uniform => u,
        // The uniform share, else the inverse CDF within [0, 1].
        Marginal::Normal { mean, sd } => {
            let v: f64 = rng.random_range(0.0..1.0);
            if u < SPREAD {
                v
            } else {
                let (n, lo, mass) = truncated(*mean, *sd);
                n.inverse_cdf(lo + v * mass)
            }
        }
        Marginal::Cells(p) => {
            let k = p.len();
            let mut acc = 0.0;
            let c = p
                .iter()
                .position(|pi| {
                    acc += pi;
                    u < acc
                })
                .unwrap_or(k - 1);
            (c as f64 + rng.random_range(0.0..1.0)) / k as f64
        }
    };
    x.clamp(0.0, 1.0 - f64::EPSILON)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The density integrates to 1 over the cube and the draws follow it.
    #[test]
    fn a_fitted_proposal_is_a_density_its_draws_follow() {
        let q = Proposal {
            marginals: Some(vec![
                Marginal::Normal { mean: 0.8, sd: 0.1 },
                Marginal::Cells(vec![0.1, 0.2, 0.7]),
            ]),
        };
        let grid = 300;
        let mut integral = 0.0;
        for i in 0..grid {
            for j in 0..grid {
                let x = [(i as f64 + 0.5) / grid as f64, (j as f64 + 0.5) / grid as f64];
                integral += q.density(&x) / (grid * grid) as f64;
            }
        }
        assert!((integral - 1.0).abs() < 1e-3, "integral {integral}");
        let draws: Vec<Vec<f64>> = (0..4000).map(|i| q.draw(7, "test", i, 2)).collect();
        let in_last_cell = draws.iter().filter(|x| x[1] >= 2.0 / 3.0).count() as f64 / 4000.0;
        // 0.2/3 + 0.8 × 0.7.
        assert!((in_last_cell - (0.2 / 3.0 + 0.56)).abs() < 0.03, "{in_last_cell}");
        // Importance weights 1/q of draws from q average to 1 (the cube's volume).
        let mean_weight = draws.iter().map(|x| 1.0 / q.density(x)).sum::<f64>() / 4000.0;
        assert!((mean_weight - 1.0).abs() < 0.05, "{mean_weight}");
        assert_eq!(q.draw(7, "test", 3, 2), draws[3]);
    }

    fn space(params: &str) -> Space {
        let base = crate::maps::load("jaywalk").unwrap();
        let text = format!("Space(name: \"t\", params: [{params}])");
        Space::parse("test", &text, &base).unwrap()
    }

    /// Two ranges and a choice of two.
    fn three() -> Space {
        space(
            r#"(field: "pedestrians[0].trigger.value", range: (2.5, 6.5)),
               (field: "vehicle.max_brake", range: (2.0, 5.0)),
               (field: "pedestrians[0].side", choose: ["Near", "Far"])"#,
        )
    }

    /// By hand: a mixture of 1 uniform draw and 3 of a proposal whose one marginal is a
    /// normal (0.5, 0.1) truncated to [0, 1]: its mass in [0, 1] is Φ(5) − Φ(−5) ≈ 1, so at
    /// 0.5 its density is 1/(0.1 √(2π)) = 3.98942, the marginal's 0.2 + 0.8 × 3.98942 =
    /// 3.39154, the proposal's 0.2 + 0.8 × 3.39154 = 2.91323, and the mixture's (1 × 1 + 3
    /// × 2.91323)/4 = 2.43492.
    #[test]
    fn the_mixture_density_is_the_draw_weighted_sum_by_hand() {
        let q = Proposal {
            marginals: Some(vec![Marginal::Normal { mean: 0.5, sd: 0.1 }]),
        };
        assert!((q.density(&[0.5]) - 2.913_23).abs() < 1e-5, "{}", q.density(&[0.5]));
        let mut m = Mixture::default();
        m.add(1, &Proposal::uniform());
        m.add(2, &q);
        m.add(1, &q);
        assert_eq!(m.parts.len(), 2, "the same proposal's draws are one part");
        assert!((m.density(&[0.5]) - 2.434_92).abs() < 1e-5, "{}", m.density(&[0.5]));
        assert!((m.weight(&[0.5]) - 1.0 / 2.434_92).abs() < 1e-5);
        // Truncation: the normal (0.9, 0.2) keeps Φ(0.5) − Φ(−4.5) = 0.691459 of its mass,
        // so at 0.9 its density is 1.994711/0.691459 = 2.884786.
        let t = Proposal {
            marginals: Some(vec![Marginal::Normal { mean: 0.9, sd: 0.2 }]),
        };
        assert!(
            (t.density(&[0.9]) - (0.2 + 0.8 * (0.2 + 0.8 * 2.884_786))).abs() < 1e-5,
            "{}",
            t.density(&[0.9])
        );
        // A uniform marginal is the cube's own: the density stays 1.
        let u = Proposal {
            marginals: Some(vec![Marginal::Uniform, Marginal::Cells(vec![0.5, 0.5])]),
        };
        assert_eq!(u.density(&[0.3, 0.7]), 1.0);
        assert_eq!(Mixture::default().density(&[0.3]), 1.0);
    }

    /// Parameters the elite does not depend on stay uniform; one it depends on moves.
    #[test]
    fn a_refit_moves_only_the_marginals_the_elite_departs_in() {
        let space = three();
        // 400 draws of a uniform grid-like sequence; a failure wherever trigger < 0.1.
        let points: Vec<Vec<f64>> = (0..400)
            .map(|i| {
                let q = Proposal::uniform();
                q.draw(3, "refit", i, 3)
            })
            .collect();
        let scored: Vec<Scored<'_>> = points
            .iter()
            .map(|x| (x.as_slice(), 1.0, if x[0] < 0.1 { -1.0 } else { 1.0 + x[0] }))
            .collect();
        let q = Proposal::uniform().refit(&space, &scored);
        let ms = q.marginals.expect("the trigger moved");
        match ms[0] {
            Marginal::Normal { mean, .. } => assert!(mean < 0.2, "{mean}"),
            ref m => panic!("{m:?}"),
        }
        assert_eq!(ms[1], Marginal::Uniform);
        assert_eq!(ms[2], Marginal::Cells(vec![0.5, 0.5]));
        // Scores that depend on nothing: no marginal moves, the proposal stays the cube.
        let flat: Vec<Scored<'_>> = points
            .iter()
            .enumerate()
            .map(|(i, x)| (x.as_slice(), 1.0, ((i * 7919) % 400) as f64))
            .collect();
        assert_eq!(Proposal::uniform().refit(&space, &flat), Proposal::uniform());
    }

    /// The elite is every failure when they outnumber the quantile, and every draw tied
    /// at the threshold: with 30 failures among 100 (over 10%) the refit fits the 30.
    #[test]
    fn the_elite_is_every_failure_and_every_tie() {
        let space = three();
        let points: Vec<Vec<f64>> = (0..100).map(|i| vec![(i as f64 + 0.5) / 100.0, 0.5, 0.25]).collect();
        let failing: Vec<Scored<'_>> = points
            .iter()
            .map(|x| (x.as_slice(), 1.0, if x[0] < 0.3 { -1.0 } else { 1.0 }))
            .collect();
        let q = Proposal::uniform().refit(&space, &failing);
        // The 30 failures' mean is 0.15 and their sd 0.3/√12 (less the grid's 1/100):
        // the marginal is theirs.
        match q.marginals.unwrap()[0] {
            Marginal::Normal { mean, sd } => {
                let grid_sd = ((30.0f64 * 30.0 - 1.0) / 12.0).sqrt() / 100.0;
                assert!((mean - 0.15).abs() < 1e-9 && (sd - grid_sd).abs() < 1e-9, "{mean} {sd}");
            }
            ref m => panic!("{m:?}"),
        }
        // No failure, 60 draws tied at 0 (the fair ones, for `is`): all 60 are the elite.
        let tied: Vec<Scored<'_>> = points
            .iter()
            .map(|x| (x.as_slice(), 1.0, if x[0] >= 0.4 { 0.0 } else { f64::INFINITY }))
            .collect();
        match Proposal::uniform().refit(&space, &tied).marginals.unwrap()[0] {
            Marginal::Normal { mean, .. } => assert!((mean - 0.7).abs() < 1e-9, "{mean}"),
            ref m => panic!("{m:?}"),
        }
    }

    #[test]
    fn the_failure_level_is_reached_when_the_failures_fill_the_quantile() {
        let points: Vec<Vec<f64>> = (0..100).map(|i| vec![i as f64 / 100.0]).collect();
        let scored = |failures: usize, finite: usize| -> Vec<Scored<'_>> {
            points
                .iter()
                .enumerate()
                .map(|(i, x)| {
                    let score = if i < failures {
                        -1.0
                    } else if i < finite {
                        1.0
                    } else {
                        f64::INFINITY
                    };
                    (x.as_slice(), 1.0, score)
                })
                .collect()
        };
        // 100 finite scores: the quantile is 10 draws.
        assert!(!failure_level_reached(&scored(9, 100)));
        assert!(failure_level_reached(&scored(10, 100)));
        // 30 finite scores: 3 draws, but at least MIN_ELITE.
        assert!(!failure_level_reached(&scored(MIN_ELITE - 1, 30)));
        assert!(failure_level_reached(&scored(MIN_ELITE, 30)));
        // Fewer finite scores than MIN_ELITE: no refit, no level.
        assert!(!failure_level_reached(&scored(MIN_ELITE - 1, MIN_ELITE - 1)));
    }

    proptest::proptest! {
        /// Under any fitted proposal, the weights of its own draws average to 1 (the
        /// cube's volume), and so do the mixture weights of draws from the mixture.
        #[test]
        fn weights_average_to_one_under_the_proposal(
            mean in 0.0f64..1.0,
            sd in MIN_SD..0.5,
            p0 in 0.05f64..0.95,
            seed in 0u64..1000,
        ) {
            let q = Proposal {
                marginals: Some(vec![Marginal::Normal { mean, sd }, Marginal::Cells(vec![p0, 1.0 - p0]), Marginal::Uniform]),
            };
            let n = 4000;
            let own = (0..n).map(|i| 1.0 / q.density(&q.draw(seed, "p", i, 3))).sum::<f64>() / n as f64;
            proptest::prop_assert!((own - 1.0).abs() < 0.08, "{}", own);
            let mut m = Mixture::default();
            m.add(n / 4, &Proposal::uniform());
            m.add(3 * n / 4, &q);
            let pooled = (0..n / 4)
                .map(|i| Proposal::uniform().draw(seed, "u", i, 3))
                .chain((0..3 * n / 4).map(|i| q.draw(seed, "q", i, 3)))
                .map(|x| m.weight(&x))
                .sum::<f64>()
                / n as f64;
            proptest::prop_assert!((pooled - 1.0).abs() < 0.05, "{}", pooled);
        }
    }
}
