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

/// `ln 2` split so that `k · LN2_HI` is exact for `|k| < 2^11`: `LN2_HI` holds the
/// leading 32 bits of `ln 2`, `LN2_LO = ln 2 - LN2_HI` the rest.
const LN2_HI: f64 = f64::from_bits(0x3FE6_2E42_FEE0_0000);
const LN2_LO: f64 = 1.9082149292705877e-10;
/// `2^52 + 1023`: subtracting it from the float whose bits are `0x433 << 52 | e` gives
/// the unbiased exponent `e - 1023` exactly (no integer-to-float conversion needed, so
/// the compiler keeps the loop in SSE2 registers).
const EXP_MAGIC: f64 = 4_503_599_627_370_496.0 + 1023.0;

/// Natural logarithm of a positive normal `x` by a series (no table): builds the table
/// of [`ln_fast`] at compile time, and is its reference in the tests.
///
/// `x = 2^k m` with `m` in `[√2/2, √2)`; with `f = m - 1` and `s = f / (2 + f)`,
/// `ln m = 2 atanh s = 2s + 2s (s²/3 + s⁴/5 + … + s¹⁸/19)` (the Taylor series of
/// `atanh`, `|s| <= 0.1716`, truncated where the next term is below 1e-17 of the result),
/// written `f - s (f - 2 s² Q(s²))` since `2s = f - s f`; `k ln 2` is added in two parts.
/// Max error against `std`'s `ln` ~1 ulp of `max(|ln x|, 1)`.
const fn ln_series(x: f64) -> f64 {
    let bits = x.to_bits();
    let mut k = f64::from_bits((bits >> 52) | 0x4330_0000_0000_0000) - EXP_MAGIC;
    let mut m = f64::from_bits((bits & 0x000F_FFFF_FFFF_FFFF) | 0x3FF0_0000_0000_0000);
    if m > std::f64::consts::SQRT_2 {
        m *= 0.5;
        k += 1.0;
    }
    let f = m - 1.0;
    let s = f / (2.0 + f);
    let z = s * s;
    let q = 1.0 / 3.0
        + z * (1.0 / 5.0
            + z * (1.0 / 7.0
                + z * (1.0 / 9.0
                    + z * (1.0 / 11.0 + z * (1.0 / 13.0 + z * (1.0 / 15.0 + z * (1.0 / 17.0 + z * (1.0 / 19.0))))))));
    let ln_m = f - s * (f - 2.0 * z * q);
    k * LN2_HI + (k * LN2_LO + ln_m)
}

/// The table of [`ln_fast`] has an entry per `1/128` of the mantissa, ends included.
const LN_TABLE_STEPS: usize = 128;

/// Per point `c_i = 1 + i/128` (`i = 0..=128`): `[1/c_i rounded, -ln(that), 0]`,
/// computed at compile time by [`ln_series`]. Entry 0 is `[1, 0, 0]`, so that `ln 1 = 0`
/// exactly; the last (`c = 2`) is `[1/2, 0, 1]`: the mantissa is halved and the exponent
/// raised by one, so that `ln x` just below 1 is `ln(1 + r)` with an exact `r`.
const LN_TABLE: [[f64; 3]; LN_TABLE_STEPS + 1] = {
    let mut t = [[0.0; 3]; LN_TABLE_STEPS + 1];
    let mut i = 0;
    while i < LN_TABLE_STEPS {
        let inv = 1.0 / (1.0 + i as f64 / LN_TABLE_STEPS as f64);
        t[i] = [inv, -ln_series(inv), 0.0];
        i += 1;
    }
    t[LN_TABLE_STEPS] = [0.5, 0.0, 1.0];
    t
};

/// Natural logarithm of a positive normal `x`, branch-free, so that loops over slices
/// vectorise (docs/ARCHITECTURE.md §4.1; used through [`ln_into`] and [`risk_sum`]).
///
/// `x = 2^k m`, `m` in `[1, 2)`; the top 8 bits of `m`, rounded to 7, pick the nearest
/// `c = 1 + i/128 ≈ 1/inv` from a 129-entry table, `r = m · inv - 1` (`|r| <= 2^-8`), and
/// `ln x = k ln 2 - ln inv + ln(1 + r)` (for `c = 2`: `(k + 1) ln 2 + ln(1 + r)`, with
/// `r = m/2 - 1`) with `ln(1 + r)` by its Taylor series to `r^6/6`
/// (the next term is below 3e-18). Plain IEEE operations and a constant table (no FMA,
/// no run-time dispatch): every x86-64 machine computes the same bits, scalar or
/// vectorised. Max error ~2 ulp of `max(|ln x|, 1)`, against `std`'s `ln` (test
/// `fast_ln_matches_std`) and against musl's `log` through the `libm` crate, a
/// reference independent of the platform (tests `fast_ln_matches_libm_*`). Not for zero, subnormal, negative or non-finite `x`:
/// callers floor first.
#[inline(always)]
pub fn ln_fast(x: f64) -> f64 {
    let bits = x.to_bits();
    let k = f64::from_bits((bits >> 52) | 0x4330_0000_0000_0000) - EXP_MAGIC;
    let m = f64::from_bits((bits & 0x000F_FFFF_FFFF_FFFF) | 0x3FF0_0000_0000_0000);
    let [inv, ln_c, k_add] = LN_TABLE[((((bits >> 44) & 0xFF) + 1) >> 1) as usize];
    let k = k + k_add;
    let r = m * inv - 1.0;
    let p = r * r * (-0.5 + r * (1.0 / 3.0 + r * (-0.25 + r * (0.2 - r * (1.0 / 6.0)))));
    k * LN2_HI + (ln_c + (k * LN2_LO + (r + p)))
}

/// `out[i] = ln(max(x[i], 1e-16))` with [`ln_fast`] (docs/ARCHITECTURE.md §4.1); the
/// loop vectorises.
pub fn ln_into(x: &[f64], out: &mut [f64]) {
    for (o, v) in out[..x.len()].iter_mut().zip(x) {
        *o = ln_fast(v.max(LN_FLOOR));
    }
}

/// `Σ_i p_i (ln p_i - c_i)` with the floored [`ln_fast`], summed in four lanes in [`lane_sum`]'s order; zero
/// entries add exactly 0. The risk of one step of the EFE (Prop. 1, `KL[A s || c]`).
pub fn risk_sum(p: &[f64], c: &[f64]) -> f64 {
    const CHUNK: usize = 64;
    let c = &c[..p.len()];
    let mut buf = [0.0f64; CHUNK];
    let mut acc = [0.0f64; 4];
    // The logarithms of a chunk first (a loop that vectorises), then its terms, added
    // to four lanes by index modulo 4 as `lane_sum` does.
    for (pc, cc) in p.chunks(CHUNK).zip(c.chunks(CHUNK)) {
        ln_into(pc, &mut buf);
        // CHUNK is a multiple of 4, so entry i of the chunk goes to lane i % 4.
        let full = pc.len() - pc.len() % 4;
        for ((p4, l4), c4) in pc[..full]
            .chunks_exact(4)
            .zip(buf[..full].chunks_exact(4))
            .zip(cc[..full].chunks_exact(4))
        {
            for l in 0..4 {
                acc[l] += p4[l] * (l4[l] - c4[l]);
            }
        }
        for (l, ((pi, li), ci)) in pc[full..].iter().zip(&buf[full..]).zip(&cc[full..]).enumerate() {
            acc[l] += pi * (li - ci);
        }
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3])
}

/// Rows of `out` computed together by [`axpy_columns`] and [`dot_columns`], held in
/// registers while the columns stream past.
const BLOCK: usize = 8;

/// `out = M x` for `M` stored column-major with `rows` rows (`m[j * rows + r]`), skipping
/// the zero entries of `x`: every `out[r]` starts at `+0.0` and adds `x_j M[r, j]` in `j`
/// order (exact; cheap for one-hot beliefs). Rows are done `BLOCK` (8) at a time, so the
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
/// but `BLOCK` sums advance together in registers instead of one dependent chain after
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

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

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

    /// Maximum error of the table `ln` (and of the series that builds its table) against
    /// `std` over the range the agent uses, `[1e-16, 1]` (probabilities, floored), and
    /// beyond up to 1e6. Errors are measured in units of `f64::EPSILON` relative to
    /// `max(|std|, 1)` (absolute near `ln 1 = 0`).
    #[test]
    fn fast_ln_matches_std() {
        let n = 200_000;
        let xs: Vec<f64> = (0..=n)
            .map(|i| 10f64.powf(-16.0 + 22.0 * i as f64 / n as f64))
            .collect();
        let mut got = vec![0.0; xs.len()];
        ln_into(&xs, &mut got);
        let mut worst: f64 = 0.0;
        for (x, g) in xs.iter().zip(&got) {
            let want = x.ln();
            worst = worst.max((g - want).abs() / want.abs().max(1.0) / f64::EPSILON);
        }
        eprintln!("ln: worst {worst} eps");
        assert!(worst <= 2.0, "ln: {worst} eps");
        let worst = xs
            .iter()
            .map(|x| (ln_series(*x) - x.ln()).abs() / x.ln().abs().max(1.0) / f64::EPSILON)
            .fold(0.0, f64::max);
        eprintln!("ln_series: worst {worst} eps");
        assert!(worst <= 1.5, "ln_series: {worst} eps");
        // The floor, zero and values just around 1.
        ln_into(&[0.0, 1e-300, 1.0, 1.0 - 1e-12, 1.0 + 1e-12], &mut got);
        assert_eq!(got[0], LN_FLOOR.ln());
        assert_eq!(got[1], LN_FLOOR.ln());
        assert_eq!(got[2], 0.0);
        assert!((got[3] - (1.0f64 - 1e-12).ln()).abs() < 1e-27);
        assert!((got[4] - (1.0f64 + 1e-12).ln()).abs() < 1e-27);
    }

    /// `|got - want|` in units of `EPSILON · max(|want|, 1)`: the error measure of the
    /// bounds in the docs of [`ln_fast`] and [`ln_series`].
    fn ulps(got: f64, want: f64) -> f64 {
        (got - want).abs() / want.abs().max(1.0) / f64::EPSILON
    }

    /// Inputs where a table-and-polynomial logarithm is most likely to slip: every
    /// power of two of the normal range (`r = 0`, the exponent alone) and its
    /// neighbours, both sides of every table point `1 + i/128` in several binades,
    /// values within a few ulp and within 1e-k of 1, the log floor 1e-16 and around it,
    /// and the largest values.
    fn edge_inputs() -> Vec<f64> {
        let mut xs = Vec::new();
        let next = |x: f64, by: i64| f64::from_bits((x.to_bits() as i64 + by) as u64);
        for e in -1022..=1023 {
            let p = 2f64.powi(e);
            xs.extend([p, next(p, 1), next(p, 2)]);
            if e > -1022 {
                xs.extend([next(p, -1), next(p, -2)]);
            }
        }
        for scale in [2f64.powi(-60), 0.5, 1.0, 2.0, 1024.0, 2f64.powi(700)] {
            for i in 0..=128 {
                let c = (1.0 + f64::from(i) / 128.0) * scale;
                xs.extend([
                    c,
                    next(c, -1),
                    next(c, 1),
                    c * (1.0 - 1.0 / 512.0),
                    c * (1.0 + 1.0 / 512.0),
                ]);
            }
        }
        for k in 1..=64 {
            xs.extend([next(1.0, k), next(1.0, -k)]);
        }
        for k in 1..=15 {
            let d = 10f64.powi(-k);
            xs.extend([1.0 + d, 1.0 - d]);
        }
        xs.extend([LN_FLOOR, next(LN_FLOOR, 1), next(LN_FLOOR, -1), 1e-15, 1e-17]);
        xs.extend([1e300, 1e308, f64::MAX, next(f64::MAX, -1), f64::MIN_POSITIVE]);
        xs.extend([std::f64::consts::E, 10.0, 0.1, 0.3, 0.7, 1.5, 3.0]);
        xs
    }

    /// `ln_fast` (and the series that builds its table) within the documented bounds of
    /// musl's `log` (the `libm` crate: not the platform's `std`), on the edge inputs and
    /// on 400,000 points spread log-uniformly over the whole normal range.
    #[test]
    fn fast_ln_matches_libm_on_edges_and_the_whole_range() {
        let mut xs = edge_inputs();
        let n = 400_000;
        xs.extend((0..=n).map(|i| 2f64.powf(-1022.0 + 2045.0 * f64::from(i) / f64::from(n))));
        assert!(xs.iter().all(|x| x.is_normal() && *x > 0.0));
        let mut got = vec![0.0; xs.len()];
        // Through the vectorised loop as the agent uses it (inputs at or above the
        // floor are unchanged by it), and one by one for those below the floor.
        ln_into(&xs, &mut got);
        let (mut worst, mut worst_series): (f64, f64) = (0.0, 0.0);
        for (x, g) in xs.iter().zip(&got) {
            let want = libm::log(*x);
            let g = if *x >= LN_FLOOR { *g } else { ln_fast(*x) };
            worst = worst.max(ulps(g, want));
            assert!(ulps(g, want) <= 2.0, "ln_fast({x:e}) = {g:e}, libm {want:e}");
            worst_series = worst_series.max(ulps(ln_series(*x), want));
        }
        eprintln!("ln_fast: worst {worst} eps; ln_series: worst {worst_series} eps (vs libm)");
        assert!(worst_series <= 1.5, "ln_series: {worst_series} eps");
        // Exactly 0 at 1, and exactly the floor's logarithm below the floor.
        assert_eq!(ln_fast(1.0), 0.0);
        let mut floored = [0.0; 2];
        ln_into(&[1e-300, 0.0], &mut floored);
        assert_eq!(floored, [ln_fast(LN_FLOOR); 2]);
        assert!(ulps(floored[0], libm::log(LN_FLOOR)) <= 2.0);
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(2000))]
        /// Any positive normal double (every exponent and mantissa equally likely):
        /// `ln_fast` within 2 ulp of `max(|ln x|, 1)` of musl's `log`.
        #[test]
        fn fast_ln_matches_libm_on_any_normal(exponent in 1u64..2047, mantissa in 0u64..(1u64 << 52)) {
            let x = f64::from_bits((exponent << 52) | mantissa);
            let (got, want) = (ln_fast(x), libm::log(x));
            prop_assert!(ulps(got, want) <= 2.0, "ln_fast({x:e}) = {got:e}, libm {want:e}");
        }
    }

    /// The risk with the table `ln` agrees with the `std` form to rounding, for lengths
    /// that are and are not multiples of the lanes and of the chunk.
    #[test]
    fn risk_sum_matches_the_std_form() {
        for n in [1usize, 3, 4, 7, 64, 130] {
            let x: Vec<f64> = (0..n).map(|i| ((i * 37) % 11) as f64 - 40.0 * (i % 3) as f64).collect();
            let mut a = x.clone();
            softmax_in_place(&mut a);
            let c: Vec<f64> = (0..n).map(|i| -(i as f64) * 0.3).collect();
            let want: f64 = a.iter().zip(&c).map(|(p, ci)| p * (ln(*p) - ci)).sum();
            assert!((risk_sum(&a, &c) - want).abs() < 1e-14, "{n}");
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
