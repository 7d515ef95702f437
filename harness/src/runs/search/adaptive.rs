//! The adaptive stage: the cross-entropy method (Rubinstein 1999; de Boer et al. 2005,
//! "A tutorial on the cross-entropy method") over the unit cube of the space, aimed at
//! fair failures.
//!
//! The sampling distribution is a product of one distribution per parameter: a normal
//! (mean, standard deviation) truncated to [0, 1] for a range, a categorical over its
//! cells for a count or a choice. It starts uniform and, after each round, is refitted
//! to the *elite* candidates evaluated so far:
//!
//! * a candidate's score is the method's lowest success rate over the training seeds
//!   (its worst agent) when the candidate is fair, and +∞ when it is not (an unfair failure is worth
//!   nothing) or was rejected;
//! * the elite is the best [`ELITE_SHARE`] of the scored candidates (at least
//!   [`MIN_ELITE`]), lowest score first, ties by candidate index;
//! * each parameter's distribution moves a share [`SMOOTHING`] of the way to the
//!   elite's mean and standard deviation (or cell frequencies), with a floor on the
//!   standard deviation ([`MIN_SD`]) and on every cell's probability ([`MIN_CELL`]),
//!   so the search never collapses onto one point and keeps exploring.
//!
//! Every draw comes from a ChaCha8 generator seeded by (run seed, round), and rounds
//! depend only on the results of earlier rounds (which depend only on the seed), so the
//! adaptive candidates are the same whatever the number of threads. Candidates of this
//! stage are not a uniform sample: they do not enter the failure-probability estimate.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::space::{Domain, Space};
use unforeseen_env::seeds::episode_seed;

/// Share of the scored candidates that form the elite.
pub const ELITE_SHARE: f64 = 0.2;
/// Fewest elite candidates.
pub const MIN_ELITE: usize = 5;
/// How far each refit moves the distribution toward the elite's (1 = all the way).
pub const SMOOTHING: f64 = 0.7;
/// Smallest standard deviation of a range's normal, on the unit interval.
pub const MIN_SD: f64 = 0.05;
/// Smallest probability of a cell of a count or a choice.
pub const MIN_CELL: f64 = 0.05;

/// One parameter's sampling distribution.
#[derive(Debug, Clone, PartialEq)]
pub enum Marginal {
    /// A normal (mean, sd) truncated to [0, 1].
    Normal(f64, f64),
    /// Probabilities of the cells.
    Cells(Vec<f64>),
}

/// The cross-entropy method's sampling distribution.
#[derive(Debug, Clone, PartialEq)]
pub struct CrossEntropy {
    /// One marginal per parameter.
    pub marginals: Vec<Marginal>,
}

impl CrossEntropy {
    /// The uniform distribution over the space's unit cube.
    pub fn uniform(space: &Space) -> Self {
        let marginals = space
            .params
            .iter()
            .map(|p| match p.domain {
                Domain::Range(..) => Marginal::Normal(0.5, 1.0),
                _ => {
                    let n = p.cells().unwrap_or(1);
                    Marginal::Cells(vec![1.0 / n as f64; n])
                }
            })
            .collect();
        CrossEntropy { marginals }
    }

    /// Refits to the elite of `scored` (coordinates, score), as the module says.
    pub fn refit(&mut self, scored: &[(Vec<f64>, f64)]) {
        let mut order: Vec<usize> = (0..scored.len()).filter(|&i| scored[i].1.is_finite()).collect();
        if order.is_empty() {
            return; // nothing fair yet: keep exploring as before
        }
        order.sort_by(|&a, &b| scored[a].1.total_cmp(&scored[b].1).then(a.cmp(&b)));
        let n = ((order.len() as f64 * ELITE_SHARE).ceil() as usize)
            .max(MIN_ELITE)
            .min(order.len());
        let elite: Vec<&Vec<f64>> = order[..n].iter().map(|&i| &scored[i].0).collect();
        for (d, m) in self.marginals.iter_mut().enumerate() {
            match m {
                Marginal::Normal(mean, sd) => {
                    let xs: Vec<f64> = elite.iter().map(|u| u[d]).collect();
                    let mu = xs.iter().sum::<f64>() / xs.len() as f64;
                    let var = xs.iter().map(|x| (x - mu).powi(2)).sum::<f64>() / xs.len() as f64;
                    *mean = SMOOTHING * mu + (1.0 - SMOOTHING) * *mean;
                    *sd = (SMOOTHING * var.sqrt() + (1.0 - SMOOTHING) * *sd).max(MIN_SD);
                }
                Marginal::Cells(p) => {
                    let k = p.len();
                    let mut freq = vec![0.0; k];
                    for u in &elite {
                        let c = ((u[d] * k as f64).floor() as usize).min(k - 1);
                        freq[c] += 1.0 / elite.len() as f64;
                    }
                    for (pi, f) in p.iter_mut().zip(freq) {
                        *pi = (SMOOTHING * f + (1.0 - SMOOTHING) * *pi).max(MIN_CELL);
                    }
                    let total: f64 = p.iter().sum();
                    p.iter_mut().for_each(|x| *x /= total);
                }
            }
        }
    }

    /// `count` points of round `round`, drawn from the distribution with run seed `seed`.
    pub fn sample(&self, seed: u64, round: usize, count: usize) -> Vec<Vec<f64>> {
        let mut rng = ChaCha8Rng::seed_from_u64(episode_seed(seed, "search/cross-entropy", round as u64));
        (0..count)
            .map(|_| self.marginals.iter().map(|m| draw(m, &mut rng)).collect())
            .collect()
    }
}

/// One coordinate from a marginal.
fn draw(m: &Marginal, rng: &mut ChaCha8Rng) -> f64 {
    match m {
        Marginal::Normal(mean, sd) => {
            // Truncation by rejection (a few tries), then a uniform draw: with sd >= MIN_SD
            // and the mean in [0, 1], at least 16% of the mass is inside.
            for _ in 0..64 {
                // Box-Muller.
                let (a, b): (f64, f64) = (rng.random_range(f64::EPSILON..1.0), rng.random_range(0.0..1.0));
                let z = (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos();
                let x = mean + sd * z;
                if (0.0..1.0).contains(&x) {
                    return x;
                }
            }
            rng.random_range(0.0..1.0)
        }
        Marginal::Cells(p) => {
            let k = p.len();
            let r: f64 = rng.random_range(0.0..1.0);
            let mut acc = 0.0;
            for (i, pi) in p.iter().enumerate() {
                acc += pi;
                if r < acc {
                    return (i as f64 + 0.5) / k as f64;
                }
            }
            (k as f64 - 0.5) / k as f64
        }
    }
}
