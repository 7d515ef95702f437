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

/// Rows of `out` computed together by [`axpy_columns`] and [`dot_columns`], held in
/// registers while the columns stream past.
const BLOCK: usize = 8;

/// `out = M x` for `M` stored column-major with `rows` rows (`m[j * rows + r]`), skipping
/// the zero entries of `x`: every `out[r]` starts at `+0.0` and adds `x_j M[r, j]` in `j`
/// order (exact; cheap for one-hot beliefs). Rows are done [`BLOCK`] at a time, so the
/// partial sums stay in registers.
pub fn axpy_columns(m: &[f64], rows: usize, x: &[f64], out: &mut [f64]) {
    let out = &mut out[..rows];
    let full = rows - rows % BLOCK;
    for r0 in (0..full).step_by(BLOCK) {
        let mut acc = [0.0f64; BLOCK];
        for (col, xj) in m.chunks_exact(rows).zip(x) {
            if *xj != 0.0 {
                let col: &[f64; BLOCK] = col[r0..r0 + BLOCK].try_into().expect("block");
                for l in 0..BLOCK {
                    acc[l] += xj * col[l];
                }
            }
        }
        out[r0..r0 + BLOCK].copy_from_slice(&acc);
    }
    for r in full..rows {
        let mut acc = 0.0;
        for (col, xj) in m.chunks_exact(rows).zip(x) {
            if *xj != 0.0 {
                acc += xj * col[r];
            }
        }
        out[r] = acc;
    }
}

/// `acc[s] = Σ_i m_t[i * n + s] x[i]` (`m_t` is `Mᵀ` stored column-major, so `acc[s]` is
/// column `s` of `M` dotted with `x`): each sum runs term by term in `i` order from the
/// first term, bit for bit the serial `Σ` (which starts from `-0.0`, and `-0.0 + y = y`),
/// but [`BLOCK`] sums advance together in registers instead of one dependent chain after
/// another.
pub fn dot_columns(m_t: &[f64], n: usize, x: &[f64], acc: &mut [f64]) {
    let acc = &mut acc[..n];
    let full = n - n % BLOCK;
    for s0 in (0..full).step_by(BLOCK) {
        let mut rows = m_t.chunks_exact(n).zip(x);
        let mut a = [0.0f64; BLOCK];
        if let Some((row, x0)) = rows.next() {
            let row: &[f64; BLOCK] = row[s0..s0 + BLOCK].try_into().expect("block");
            for l in 0..BLOCK {
                a[l] = row[l] * x0;
            }
        }
        for (row, xi) in rows {
            let row: &[f64; BLOCK] = row[s0..s0 + BLOCK].try_into().expect("block");
            for l in 0..BLOCK {
                a[l] += row[l] * xi;
            }
        }
        acc[s0..s0 + BLOCK].copy_from_slice(&a);
    }
    for s in full..n {
        let mut rows = m_t.chunks_exact(n).zip(x);
        let mut a = rows.next().map_or(0.0, |(row, x0)| row[s] * x0);
        for (row, xi) in rows {
            a += row[s] * xi;
        }
        acc[s] = a;
    }
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

    /// The blocked products equal the plain loops bit for bit (same terms, same order).
    #[test]
    fn blocked_products_equal_plain_loops_bit_for_bit() {
        for n in [1usize, 5, 8, 13, 64] {
            let m: Vec<f64> = (0..n * n).map(|i| ((i * 7919) % 1000) as f64 / 997.0 - 0.3).collect();
            let mut x: Vec<f64> = (0..n).map(|i| ((i * 104_729) % 100) as f64 / 99.0).collect();
            x[n / 2] = 0.0;
            let mut got = vec![0.0; n];
            axpy_columns(&m, n, &x, &mut got);
            for (r, g) in got.iter().enumerate() {
                let mut want = 0.0;
                for (j, xj) in x.iter().enumerate() {
                    if *xj != 0.0 {
                        want += xj * m[j * n + r];
                    }
                }
                assert_eq!(g.to_bits(), want.to_bits());
            }
            dot_columns(&m, n, &x, &mut got);
            for (s, g) in got.iter().enumerate() {
                let want: f64 = (0..n).map(|i| m[i * n + s] * x[i]).sum();
                assert_eq!(g.to_bits(), want.to_bits());
            }
        }
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
