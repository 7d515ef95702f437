//! The two estimators of a probability from evaluated draws, each with its 95% interval
//! (module doc of [`super`]): plain Monte Carlo with the Wilson score interval, and
//! self-normalised importance sampling with the Wilson interval at the delta method's
//! effective sample size (Korn & Graubard 1998), its diagnostics and its refusals.

use serde::{Deserialize, Serialize};

/// The normal quantile of a two-sided 95% interval.
pub const Z95: f64 = 1.959_963_984_540_054;
/// Fewest effective draws (Kish's `(Σw)² / Σw²`) an importance-sampling estimate reports with.
pub const MIN_ESS: f64 = 30.0;
/// Largest share of the weights one draw may hold in an importance-sampling estimate.
pub const MAX_WEIGHT_SHARE: f64 = 0.1;
/// Fewest effective failures (`(Σwy)² / Σ(wy)²`) an importance-sampling estimate reports
/// with: below it the normal interval is not to be trusted.
pub const MIN_EFFECTIVE_FAILURES: f64 = 5.0;

/// One estimated probability, with its interval and how it was made.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The estimate (none when refused or nothing counted).
    pub p: Option<f64>,
    /// Lower end of the 95% interval.
    pub ci95_low: Option<f64>,
    /// Upper end of the 95% interval.
    pub ci95_high: Option<f64>,
    /// Half the interval's width over the estimate (none when the estimate is 0 or none).
    pub rel_half_width: Option<f64>,
    /// Draws the estimate is over (those in the set it conditions on).
    pub draws: usize,
    /// The interval's kind.
    pub interval: String,
    /// Kish's effective sample size of the weights (importance sampling only).
    pub ess: Option<f64>,
    /// The largest weight's share of the weights (importance sampling only).
    pub largest_weight_share: Option<f64>,
    /// Effective number of failures, `(Σwy)² / Σ(wy)²` (importance sampling only).
    pub effective_failures: Option<f64>,
    /// Why no number is reported, when none is.
    pub refused: Option<String>,
}

impl Estimate {
    fn with(p: f64, low: f64, high: f64, draws: usize, interval: &str) -> Estimate {
        let (low, high) = (low.max(0.0), high.min(1.0));
        Estimate {
            p: Some(p),
            ci95_low: Some(low),
            ci95_high: Some(high),
            rel_half_width: (p > 0.0).then(|| (high - low) / 2.0 / p),
            draws,
            interval: interval.into(),
            ess: None,
            largest_weight_share: None,
            effective_failures: None,
            refused: None,
        }
    }

    fn refused(draws: usize, interval: &str, why: String) -> Estimate {
        Estimate {
            p: None,
            ci95_low: None,
            ci95_high: None,
            rel_half_width: None,
            draws,
            interval: interval.into(),
            ess: None,
            largest_weight_share: None,
            effective_failures: None,
            refused: Some(why),
        }
    }

    /// Whether its relative half-width is at most `target`.
    pub fn reaches(&self, target: f64) -> bool {
        self.rel_half_width.is_some_and(|r| r <= target)
    }

    /// `p [low, high] (±r%, n draws)`, or why there is none.
    pub fn text(&self) -> String {
        match (self.p, self.ci95_low, self.ci95_high, &self.refused) {
            (Some(p), Some(l), Some(h), _) => format!(
                "{p:.3e} [{l:.3e}, {h:.3e}] ({}, {} draws)",
                self.rel_half_width
                    .map_or("relative half-width n/a".into(), |r| format!("±{:.0}%", 100.0 * r)),
                self.draws
            ),
            (_, _, _, Some(why)) => format!("no estimate: {why}"),
            _ => "no estimate".into(),
        }
    }
}

/// The Monte Carlo estimate of `E[y]` from `ys` (each in [0, 1], drawn independently from
/// the distribution), with the 95% Wilson score interval (Wilson 1927) at `n = ys.len()`.
/// For a 0/1 `y` it is the binomial Wilson interval; for a share of failed episodes in
/// [0, 1] with mean `p` the variance is at most `p(1 − p)`, so the interval is the Wilson
/// interval of the worst case (conservative).
pub fn monte_carlo(ys: &[f64]) -> Estimate {
    const KIND: &str = "Wilson score, 95% (plain Monte Carlo)";
    let n = ys.len();
    if n == 0 {
        return Estimate::refused(0, KIND, "no draw in the set".into());
    }
    let p = ys.iter().sum::<f64>() / n as f64;
    let (low, high) = wilson(p, n as f64);
    Estimate::with(p, low, high, n, KIND)
}

/// The self-normalised importance-sampling estimate `μ̂ = Σ wᵢyᵢ / Σ wᵢ` of `E_p[y]` from
/// `(wᵢ, yᵢ)` (weights `p/q` of draws from the proposal `q`, `yᵢ` in [0, 1]). Its variance
/// is the delta method's, `V = Σ wᵢ²(yᵢ − μ̂)² / (Σ wᵢ)²` (Owen 2013, *Monte Carlo theory,
/// methods and examples*, §9.2); the interval is the Wilson score interval at the
/// effective sample size `n* = μ̂(1 − μ̂)/V`, the plain draws that would give the same
/// variance (Korn & Graubard 1998, *Survey Methodology* 24: intervals for proportions
/// with a small expected number of positives under weighting). With equal weights `n*` is
/// the number of draws and the interval is [`monte_carlo`]'s; unlike the normal interval
/// `μ̂ ± 1.96 √V`, it is skewed upward as a proportion's with few failures is. Refused,
/// with the reason, when the weights degenerate: an ESS under [`MIN_ESS`], a weight
/// holding over [`MAX_WEIGHT_SHARE`] of the total, or fewer than
/// [`MIN_EFFECTIVE_FAILURES`] effective failures (none at all included).
pub fn importance(samples: &[(f64, f64)]) -> Estimate {
    const KIND: &str = "self-normalised importance sampling, Wilson 95% at the delta method's effective sample size";
    let n = samples.len();
    let sum_w: f64 = samples.iter().map(|s| s.0).sum();
    if n == 0 || sum_w <= 0.0 {
        return Estimate::refused(n, KIND, "no draw in the set".into());
    }
    let sum_w2: f64 = samples.iter().map(|s| s.0 * s.0).sum();
    let sum_wy: f64 = samples.iter().map(|s| s.0 * s.1).sum();
    let sum_wy2: f64 = samples.iter().map(|s| (s.0 * s.1).powi(2)).sum();
    let ess = sum_w * sum_w / sum_w2;
    let largest = samples.iter().map(|s| s.0).fold(0.0, f64::max) / sum_w;
    let failures = if sum_wy2 > 0.0 { sum_wy * sum_wy / sum_wy2 } else { 0.0 };
    let diagnose = |mut e: Estimate| {
        e.ess = Some(ess);
        e.largest_weight_share = Some(largest);
        e.effective_failures = Some(failures);
        e
    };
    let refusal = if ess < MIN_ESS {
        Some(format!(
            "the weights degenerate: effective sample size {ess:.1} < {MIN_ESS}"
        ))
    } else if largest > MAX_WEIGHT_SHARE {
        Some(format!(
            "the weights degenerate: one draw holds {:.0}% of the weight (> {:.0}%)",
            100.0 * largest,
            100.0 * MAX_WEIGHT_SHARE
        ))
    } else if failures < MIN_EFFECTIVE_FAILURES {
        Some(format!(
            "{failures:.1} effective failures among {n} draws (< {MIN_EFFECTIVE_FAILURES}): too few for the interval; \
             give a larger budget, or use mc for a bound"
        ))
    } else {
        None
    };
    if let Some(why) = refusal {
        return diagnose(Estimate::refused(n, KIND, why));
    }
    let mu = sum_wy / sum_w;
    let var = samples.iter().map(|s| (s.0 * (s.1 - mu)).powi(2)).sum::<f64>() / (sum_w * sum_w);
    let n_star = if var > 0.0 { mu * (1.0 - mu) / var } else { ess };
    let (low, high) = wilson(mu, n_star);
    diagnose(Estimate::with(mu, low, high, n, KIND))
}

/// The 95% Wilson score interval of a proportion `p` observed in `n` (not necessarily
/// whole) draws; its ends are exactly 0 at `p = 0` and 1 at `p = 1` (rounding would leave
/// 1e-18).
pub fn wilson(p: f64, n: f64) -> (f64, f64) {
    let z2 = Z95 * Z95;
    let denom = 1.0 + z2 / n;
    let centre = (p + z2 / (2.0 * n)) / denom;
    let half = Z95 * (p * (1.0 - p) / n + z2 / (4.0 * n * n)).sqrt() / denom;
    let low = if p == 0.0 { 0.0 } else { centre - half };
    let high = if p == 1.0 { 1.0 } else { centre + half };
    (low, high)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn monte_carlo_is_the_wilson_interval_by_hand() {
        // 2 of 10: centre (0.2 + 1.92/10) / 1.384 = 0.2832, half 1.96 * sqrt(0.016 + 0.0096) / 1.384 = 0.2266.
        let ys: Vec<f64> = (0..10).map(|i| if i < 2 { 1.0 } else { 0.0 }).collect();
        let e = monte_carlo(&ys);
        assert_eq!(e.p, Some(0.2));
        assert!((e.ci95_low.unwrap() - 0.0567).abs() < 1e-3, "{e:?}");
        assert!((e.ci95_high.unwrap() - 0.5098).abs() < 1e-3, "{e:?}");
        assert!((e.rel_half_width.unwrap() - (0.5098 - 0.0567) / 2.0 / 0.2).abs() < 1e-2);
        // None of 100: the estimate 0 with an upper end near 3.7%, no relative width.
        let e = monte_carlo(&[0.0; 100]);
        assert_eq!((e.p, e.ci95_low, e.rel_half_width), (Some(0.0), Some(0.0), None));
        assert!((e.ci95_high.unwrap() - 0.037).abs() < 1e-3);
        assert!(monte_carlo(&[]).refused.is_some());
    }

    #[test]
    fn importance_sampling_with_equal_weights_is_the_plain_mean() {
        // 20 failures in 100 draws of weight 2: mean 0.2, variance 4·(20·0.64 + 80·0.04)/200² = 0.0016,
        // so n* = 0.2·0.8/0.0016 = 100 draws and the interval is the Wilson interval of 20 in 100.
        let s: Vec<(f64, f64)> = (0..100).map(|i| (2.0, if i < 20 { 1.0 } else { 0.0 })).collect();
        let e = importance(&s);
        assert_eq!(e.p, Some(0.2));
        let mc = monte_carlo(&s.iter().map(|x| x.1).collect::<Vec<_>>());
        assert!(
            (e.ci95_low.unwrap() - mc.ci95_low.unwrap()).abs() < 1e-12,
            "{e:?} {mc:?}"
        );
        assert!(
            (e.ci95_high.unwrap() - mc.ci95_high.unwrap()).abs() < 1e-12,
            "{e:?} {mc:?}"
        );
        assert_eq!(e.ess, Some(100.0));
        assert_eq!(e.largest_weight_share, Some(0.01));
        assert!((e.effective_failures.unwrap() - 20.0).abs() < 1e-9);
    }

    #[test]
    fn degenerate_weights_give_no_number() {
        let mut s: Vec<(f64, f64)> = (0..100).map(|i| (1.0, f64::from(i % 5 == 0))).collect();
        s.push((50.0, 1.0));
        let e = importance(&s);
        assert!(
            e.p.is_none() && e.refused.as_deref().unwrap().contains("degenerate"),
            "{e:?}"
        );
        let none: Vec<(f64, f64)> = (0..100).map(|_| (1.0, 0.0)).collect();
        let e = importance(&none);
        assert!(
            e.p.is_none() && e.refused.as_deref().unwrap().contains("effective failures"),
            "{e:?}"
        );
        let few: Vec<(f64, f64)> = (0..10).map(|_| (1.0, 1.0)).collect();
        assert!(
            importance(&few)
                .refused
                .as_deref()
                .unwrap()
                .contains("effective sample size")
        );
    }

    /// By hand: 10 failures of weight 0.5 and 90 successes of weight 1. Σw = 95, μ̂ = 5/95
    /// = 0.0526316; V = (10 · 0.25 · 0.9473684² + 90 · 0.0526316²)/95² = 2.4930748/9025 =
    /// 2.762410e-4; n* = 0.0526316 · 0.9473684 / 2.762410e-4 = 180.5; the interval is
    /// Wilson's at 180.5 draws: centre (0.0526316 + 3.841459/361)/(1 + 3.841459/180.5) =
    /// 0.0619542, half 1.959964 · √(2.762410e-4 + 3.841459/130321)/1.0212820 = 0.0335554.
    #[test]
    fn importance_sampling_is_wilson_at_the_effective_size_by_hand() {
        let s: Vec<(f64, f64)> = (0..100).map(|i| if i < 10 { (0.5, 1.0) } else { (1.0, 0.0) }).collect();
        let e = importance(&s);
        assert!((e.p.unwrap() - 0.052_631_6).abs() < 1e-7, "{e:?}");
        assert!(
            (e.ci95_low.unwrap() - (0.061_954_2 - 0.033_555_4)).abs() < 1e-6,
            "{e:?}"
        );
        assert!(
            (e.ci95_high.unwrap() - (0.061_954_2 + 0.033_555_4)).abs() < 1e-6,
            "{e:?}"
        );
        // Skewed upward as a proportion's: farther above the estimate than below.
        assert!(e.ci95_high.unwrap() - e.p.unwrap() > e.p.unwrap() - e.ci95_low.unwrap());
        assert_eq!(wilson(0.0, 10.0).0, 0.0);
        assert_eq!(wilson(1.0, 10.0).1, 1.0);
    }
}
