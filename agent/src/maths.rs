//! Numerical primitives shared by every module (docs/ARCHITECTURE.md §4.1).
//!
//! Natural logarithms throughout; `ln x` is computed as `ln(max(x, 1e-16))` so
//! that zero probabilities give a large finite penalty instead of `-inf`;
//! softmax is max-subtracted.

/// Floor applied before every logarithm (docs/ARCHITECTURE.md §4.1): `ln x = ln(max(x, LN_FLOOR))`.
pub const LN_FLOOR: f64 = 1e-16;

/// Floored natural logarithm, `ln(max(x, 1e-16))` (docs/ARCHITECTURE.md §4.1).
#[inline]
pub fn ln(x: f64) -> f64 {
    x.max(LN_FLOOR).ln()
}

/// In-place softmax `σ(x)_i = exp(x_i - max x) / Σ_j exp(x_j - max x)`
/// (the normalisation σ of §III eq. "iterative" and §IV eq. "gradient_descent_equations").
pub fn softmax_in_place(x: &mut [f64]) {
    let m = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    if !m.is_finite() {
        let n = x.len() as f64;
        x.iter_mut().for_each(|v| *v = 1.0 / n);
        return;
    }
    let mut z = 0.0;
    for v in x.iter_mut() {
        *v = (*v - m).exp();
        z += *v;
    }
    for v in x.iter_mut() {
        *v /= z;
    }
}

/// `Σ_{i<n} f(i)` with four interleaved accumulators, so that consecutive additions do
/// not wait on each other (a plain `sum` is one serial chain of adds). The order is
/// fixed, so the result is deterministic; it may differ from a serial sum in the last bits.
#[inline]
pub fn lane_sum(n: usize, f: impl Fn(usize) -> f64) -> f64 {
    let mut acc = [0.0f64; 4];
    let n4 = n - n % 4;
    for i in (0..n4).step_by(4) {
        acc[0] += f(i);
        acc[1] += f(i + 1);
        acc[2] += f(i + 2);
        acc[3] += f(i + 3);
    }
    for i in n4..n {
        acc[i - n4] += f(i);
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3])
}

/// Softmax of a slice into a new vector (see [`softmax_in_place`]).
pub fn softmax(x: &[f64]) -> Vec<f64> {
    let mut v = x.to_vec();
    softmax_in_place(&mut v);
    v
}

/// `log_softmax(x)_i = x_i - ln Σ_j exp(x_j)`, computed stably. Used for the
/// preferences `C = ln c = log_softmax(R / τ_c)` (§IV "EFE_0"; docs/ARCHITECTURE.md §4.3).
pub fn log_softmax(x: &[f64]) -> Vec<f64> {
    let m = x.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let lse = m + x.iter().map(|v| (v - m).exp()).sum::<f64>().ln();
    x.iter().map(|v| v - lse).collect()
}

/// Kullback–Leibler divergence `KL[p || q] = Σ p_i (ln p_i - ln q_i)` with floored logs;
/// terms with `p_i = 0` contribute 0 (§IV, eq. "stopping_criterion").
pub fn kl(p: &[f64], q: &[f64]) -> f64 {
    p.iter()
        .zip(q)
        .filter(|(pi, _)| **pi > 0.0)
        .map(|(pi, qi)| pi * (ln(*pi) - ln(*qi)))
        .sum()
}

/// Shannon entropy `H[p] = -Σ p_i ln p_i` in nats (zero terms contribute 0); Prop. 1 ambiguity.
pub fn entropy(p: &[f64]) -> f64 {
    -p.iter().filter(|x| **x > 0.0).map(|x| x * ln(*x)).sum::<f64>()
}

/// Normalise a non-negative vector to sum to 1 in place; a zero vector becomes uniform.
/// Returns the sum before normalisation.
pub fn normalize_in_place(x: &mut [f64]) -> f64 {
    let z: f64 = x.iter().sum();
    if z > 0.0 && z.is_finite() {
        x.iter_mut().for_each(|v| *v /= z);
    } else {
        let n = x.len() as f64;
        x.iter_mut().for_each(|v| *v = 1.0 / n);
    }
    z
}

/// Index of the largest entry, ties broken by the lowest index (deterministic mode).
pub fn argmax(x: &[f64]) -> usize {
    let mut best = 0;
    for (i, v) in x.iter().enumerate() {
        if *v > x[best] {
            best = i;
        }
    }
    best
}

/// Nats to bits (reporting only: nats inside, bits when reported; docs/ARCHITECTURE.md §4.1).
pub fn nats_to_bits(x: f64) -> f64 {
    x / std::f64::consts::LN_2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn softmax_and_log_softmax_agree() {
        let x = [1.0, 2.0, -3.0];
        let s = softmax(&x);
        let l = log_softmax(&x);
        for (a, b) in s.iter().zip(&l) {
            assert!((a.ln() - b).abs() < 1e-12);
        }
        assert!((s.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn kl_and_entropy_basics() {
        assert!(kl(&[0.5, 0.5], &[0.5, 0.5]).abs() < 1e-15);
        assert!((entropy(&[0.5, 0.5]) - 2f64.ln()).abs() < 1e-15);
        assert_eq!(argmax(&[1.0, 3.0, 3.0]), 1);
        assert!((ln(0.0) - (1e-16f64).ln()).abs() < 1e-12);
    }

    #[test]
    fn lane_sum_adds_every_term_once() {
        for n in 0..11 {
            // Powers of two: every partial sum is exact, so any order gives the same value.
            let got = lane_sum(n, |i| (1u64 << i) as f64);
            assert_eq!(got, ((1u64 << n) - 1) as f64, "n = {n}");
        }
    }
}
