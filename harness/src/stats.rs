//! Summaries over independently trained agents (training seeds): the mean with a 95%
//! confidence interval from Student's t distribution with n - 1 degrees of freedom,
//! plus the smallest and largest value, as every figure over training seeds is
//! reported (docs/ARCHITECTURE.md §5).

use serde::{Deserialize, Serialize};

/// Degrees of freedom beyond which [`t_975`] uses this many: `statrs`' inverse CDF
/// loses accuracy past about 10^5 (1.95985 instead of 1.95997 at 10^6), while the
/// quantile at 10^4 is within 2.4e-4 above every quantile beyond it (the normal
/// quantile 1.959964 is their limit), so intervals err on the wide side by at most that.
pub const T_MAX_DF: usize = 10_000;

/// t_{0.975, df}: the half-width multiplier of a two-sided 95% interval, the 0.975
/// quantile of Student's t with `df` degrees of freedom (`statrs`' inverse CDF; at most
/// [`T_MAX_DF`] degrees of freedom). `df` must be at least 1.
pub fn t_975(df: usize) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    assert!(df >= 1, "Student's t needs at least one degree of freedom");
    StudentsT::new(0.0, 1.0, df.min(T_MAX_DF) as f64)
        .expect("a standard t with at least one degree of freedom")
        .inverse_cdf(0.975)
}

/// A figure over training seeds: its mean, a 95% interval for that mean, and its range.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Stat {
    /// Number of values (agents).
    pub n: usize,
    /// Mean of the values.
    pub mean: f64,
    /// Lower end of the 95% interval for the mean (None with fewer than 2 values).
    pub ci95_low: Option<f64>,
    /// Upper end of the 95% interval for the mean (None with fewer than 2 values).
    pub ci95_high: Option<f64>,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

impl Stat {
    /// Summarizes `values`: mean ± t_{0.975, n-1} s / sqrt(n), with s the sample standard
    /// deviation. One value has no interval; no values give NaN figures.
    pub fn of(values: &[f64]) -> Self {
        let n = values.len();
        let mean = values.iter().sum::<f64>() / n as f64;
        let (min, max) = values.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
        // Equal values: exactly that value and a zero-width interval (no rounding).
        let (mean, half) = if n > 1 && min == max {
            (min, Some(0.0))
        } else {
            (mean, half_width(values, mean))
        };
        Self {
            n,
            mean,
            ci95_low: half.map(|h| mean - h),
            ci95_high: half.map(|h| mean + h),
            min: if n == 0 { f64::NAN } else { min },
            max: if n == 0 { f64::NAN } else { max },
        }
    }

    /// Half the width of the 95% interval (None with fewer than 2 values).
    pub fn half_width(&self) -> Option<f64> {
        Some((self.ci95_high? - self.ci95_low?) / 2.0)
    }
}

/// The worst of a group of per-seed rows, each given as `(success rate, reward)`: the
/// lowest success, ties broken by the lowest reward, then by the first. The one rule of
/// "worst seed" in every summary over training seeds (the batch summary and `compare`'s
/// table). None for no rows.
pub fn worst_of(rows: impl IntoIterator<Item = (f64, f64)>) -> Option<usize> {
    let mut worst: Option<(usize, (f64, f64))> = None;
    for (i, (success, reward)) in rows.into_iter().enumerate() {
        let worse = match worst {
            None => true,
            Some((_, (s, r))) => success < s || (success == s && reward < r),
        };
        if worse {
            worst = Some((i, (success, reward)));
        }
    }
    worst.map(|(i, _)| i)
}

/// t_{0.975, n-1} s / sqrt(n) for the values around their `mean`, or None when n < 2.
fn half_width(values: &[f64], mean: f64) -> Option<f64> {
    let n = values.len();
    if n < 2 {
        return None;
    }
    let ss: f64 = values.iter().map(|v| (v - mean).powi(2)).sum();
    let sd = (ss / (n - 1) as f64).sqrt();
    Some(t_975(n - 1) * sd / (n as f64).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn the_worst_row_is_the_lowest_success_then_the_lowest_reward_then_the_first() {
        assert_eq!(worst_of([]), None);
        assert_eq!(worst_of([(1.0, 5.0), (0.5, 9.0), (0.5, 3.0), (0.5, 3.0)]), Some(2));
        assert_eq!(worst_of([(0.2, 1.0), (0.2, 1.0)]), Some(0));
    }

    #[test]
    fn two_values_by_hand() {
        // Values 1 and 3: mean 2, s = sqrt(((1-2)^2 + (3-2)^2) / 1) = sqrt(2),
        // s / sqrt(2) = 1, so the half-width is t_{0.975, 1} = 12.706204736.
        let s = Stat::of(&[1.0, 3.0]);
        assert_eq!((s.n, s.mean, s.min, s.max), (2, 2.0, 1.0, 3.0));
        assert!(close(s.ci95_low.unwrap(), 2.0 - 12.706_204_736, 1e-9));
        assert!(close(s.ci95_high.unwrap(), 2.0 + 12.706_204_736, 1e-9));
    }

    #[test]
    fn ten_values_by_hand() {
        // 1..=10: mean 5.5, sum of squares 82.5, s^2 = 82.5 / 9 = 9.1666..., s / sqrt(10)
        // = 0.957427107756338, times t_{0.975, 9} = 2.262157163 gives 2.1658506.
        let values: Vec<f64> = (1..=10).map(f64::from).collect();
        let s = Stat::of(&values);
        assert_eq!(s.mean, 5.5);
        let half = 2.262_157_163 * 0.957_427_107_756_338;
        assert!(close(s.half_width().unwrap(), half, 1e-9), "{s:?}");
        assert!(close(s.half_width().unwrap(), 2.165_850_6, 1e-6));
        assert!(close(s.ci95_low.unwrap(), 5.5 - half, 1e-9));
        assert_eq!((s.min, s.max), (1.0, 10.0));
    }

    #[test]
    fn one_value_has_no_interval_and_none_gives_nan() {
        let s = Stat::of(&[4.0]);
        assert_eq!(
            (s.mean, s.min, s.max, s.ci95_low, s.ci95_high),
            (4.0, 4.0, 4.0, None, None)
        );
        assert!(Stat::of(&[]).mean.is_nan());
    }

    #[test]
    fn t_quantiles_match_printed_tables() {
        // Printed tables to 9 decimals (df 1, 9, 30) and 6 decimals (40, 60, 120), and
        // the normal quantile 1.959964 in the limit.
        for (df, t) in [(1, 12.706_204_736), (9, 2.262_157_163), (30, 2.042_272_456)] {
            assert!(close(t_975(df), t, 1e-9), "df {df}: {}", t_975(df));
        }
        assert!(close(t_975(40), 2.021_075_390, 1e-7));
        assert!(close(t_975(60), 2.000_297_822, 1e-7));
        assert!(close(t_975(120), 1.979_930_405, 1e-7));
        assert!(t_975(31) < t_975(30) && t_975(31) > t_975(32));
        // Past T_MAX_DF, the quantile at T_MAX_DF: above the normal limit, within 2.4e-4.
        let z = 1.959_963_984_540_054;
        for df in [T_MAX_DF, 100_000, 1_000_000, 10_000_000] {
            assert!(t_975(df) > z && t_975(df) < z + 2.4e-4, "df {df}: {}", t_975(df));
        }
        let dfs = [1, 2, 3, 5, 10, 30, 31, 100, 1000, T_MAX_DF, T_MAX_DF + 1];
        assert!(dfs.windows(2).all(|w| t_975(w[0]) >= t_975(w[1])));
    }

    #[test]
    fn t_quantiles_match_the_density_integral() {
        // Oracle independent of statrs: integrate the t density from 0 to t_{0.975, df}
        // by Simpson's rule; the result must be 0.475. Gamma ratios of half-integers by the recursion
        // Gamma(x + 1) = x Gamma(x) from Gamma(1/2) = sqrt(pi) and Gamma(1) = 1.
        fn gamma_half(k: usize) -> f64 {
            // Gamma(k / 2)
            let even = k.is_multiple_of(2);
            let mut g = if even { 1.0 } else { std::f64::consts::PI.sqrt() };
            let mut x = if even { 1.0 } else { 0.5 };
            while x < k as f64 / 2.0 - 1e-9 {
                g *= x;
                x += 1.0;
            }
            g
        }
        for df in [1usize, 2, 5, 9, 17, 30, 31, 45, 100] {
            let v = df as f64;
            let c = gamma_half(df + 1) / gamma_half(df) / (v * std::f64::consts::PI).sqrt();
            let pdf = |t: f64| c * (1.0 + t * t / v).powf(-(v + 1.0) / 2.0);
            let (b, n) = (t_975(df), 20_000);
            let h = b / n as f64;
            let inner: f64 = (1..n)
                .map(|i| if i % 2 == 1 { 4.0 } else { 2.0 } * pdf(i as f64 * h))
                .sum();
            let area = (pdf(0.0) + pdf(b) + inner) * h / 3.0;
            assert!(close(area, 0.475, 1e-8), "df {df}: {area}");
        }
    }

    proptest! {
        #[test]
        fn the_interval_contains_the_mean_and_the_range_too(values in prop::collection::vec(-1e6f64..1e6, 2..40)) {
            let s = Stat::of(&values);
            let (lo, hi) = (s.ci95_low.unwrap(), s.ci95_high.unwrap());
            prop_assert!(lo <= s.mean && s.mean <= hi);
            prop_assert!(s.min <= s.mean + 1e-6 && s.mean <= s.max + 1e-6);
        }

        #[test]
        fn equal_values_give_a_zero_width_interval(v in -1e6f64..1e6, n in 2usize..40) {
            let s = Stat::of(&vec![v; n]);
            prop_assert_eq!(s.mean, v);
            prop_assert_eq!(s.half_width(), Some(0.0));
        }
    }
}
