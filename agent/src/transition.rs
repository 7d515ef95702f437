//! The transition model `B[u]` applied factor by factor (§II-A).
//!
//! `B[u][(s', s)] = Π_f p(s'_f | parents_f, u)` is a product of small CPTs, so the
//! prediction `s' = B[u] x` need not touch the dense `N x N` matrix: replace one factor
//! at a time, previous value by next value, summing the previous value out,
//!
//! `x_{k}[.., s'_f, ..] = Σ_{s_f} p(s'_f | parents_f, u) x_{k-1}[.., s_f, ..]`,
//!
//! which costs `N · size_f` multiply-adds per factor instead of `N²` in all (768 instead of
//! 4096 for the paper's `[4, 4, 2, 2]`). This works in place whenever the factors can be
//! ordered so that each one's next-time parents are already replaced and its other
//! previous-time parents are not yet replaced (an *elimination order*); the paper's
//! structure has one (`v, d, L, p`). Structures without one keep the dense `B`.
//!
//! Terminal states (absorbing in the planning model, see `WorldModel::set_terminal_states`)
//! are handled exactly: their mass bypasses the factor steps and stays where it is.
//!
//! Two types: [`FactoredTransition`] applies `B[u]` (the prediction `B[u] x`, above);
//! [`FactoredLogB`] works with `ln B[u]`, a sum of per-factor log-CPT tables, for VMP's
//! messages: the forward message `(ln B[u]) q`, the backward message `(ln B[u])ᵀ q` and
//! the transition term `q_nextᵀ (ln B[u]) q_prev` of `F`, without the dense matrix
//! (used when every entry of `B` is above the log floor, so that it equals the dense
//! floored logarithm up to rounding).

use crate::structure::{Parent, Structure};

/// One factor's replacement step, a sparse `N x N` matrix with `size` entries per row:
/// `dst[i] = Σ_t coef_t[i] · src[base(i) + t * stride]`, where row `i` holds the
/// factor's next value, `t` runs over its previous values and `base(i)` is `i` with the
/// factor's digit set to 0 (§II-A). With the joint index written
/// `i = (hi · size + k) · stride + lo` (`lo < stride`), the rows of one `(hi, k)` form a
/// run of `stride` consecutive indices whose sources, for each `t`, are the run
/// `src[(hi · size + t) · stride + lo]`: each step is a sequence of contiguous
/// multiply-adds over runs, which the compiler vectorises. The coefficients are stored
/// run by run, `[((run · size) + t) · stride + lo]` with `run = i / stride`, so that one
/// block `hi` reads one contiguous tile of `size² · stride` coefficients.
#[derive(Debug, Clone, PartialEq)]
struct Step {
    size: usize,
    /// The factor's stride in the joint index.
    stride: usize,
    /// Offset of this step's coefficients in each action's coefficient vector (laid out
    /// run by run, see above).
    offset: usize,
}

/// `B[u]` as per-factor steps (see the module docs). Build with
/// [`FactoredTransition::new`]; apply with [`FactoredTransition::apply`].
#[derive(Debug, Clone, PartialEq)]
pub struct FactoredTransition {
    n: usize,
    steps: Vec<Step>,
    /// Per action: the coefficients of every step, `N * size` per step (see [`Step`]).
    coef: Vec<Vec<f64>>,
    terminal: Vec<usize>,
}

/// An elimination order of `structure` (see the module docs), or `None` if it has none.
pub fn elimination_order(structure: &Structure) -> Option<Vec<usize>> {
    let factors = structure.factors();
    let n = factors.len();
    // `before[f]`: the factors that must be replaced before f.
    let mut before: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (f, fac) in factors.iter().enumerate() {
        for p in &fac.parents {
            match *p {
                Parent::Next(g) => before[f].push(g),
                Parent::Prev(g) if g != f => before[g].push(f),
                Parent::Prev(_) => {}
            }
        }
    }
    let mut order = Vec::with_capacity(n);
    let mut done = vec![false; n];
    while order.len() < n {
        // Lowest-index ready factor first, so the order is deterministic.
        let next = (0..n).find(|&f| !done[f] && before[f].iter().all(|&g| done[g]))?;
        done[next] = true;
        order.push(next);
    }
    Some(order)
}

impl FactoredTransition {
    /// Build from the structure, the CPT means (`means[f]` laid out
    /// `[config * size + child]`, each row summing to 1) and the number of actions, with
    /// no absorbing states (see [`FactoredTransition::with_terminal`]). `None` if the structure has no elimination order, if it is a
    /// single factor (then the steps are the dense matrix itself), or if joint indices
    /// do not fit in 32 bits.
    pub fn new(structure: &Structure, means: &[Vec<f64>], n_actions: usize) -> Option<Self> {
        let factors = structure.factors();
        if factors.len() < 2 || structure.joint_size() > u32::MAX as usize {
            return None;
        }
        let order = elimination_order(structure)?;
        let n = structure.joint_size();
        let nf = factors.len();
        let mut steps = Vec::with_capacity(nf);
        let mut coef = vec![Vec::new(); n_actions];
        let (mut vals, mut prev, mut next) = (vec![0usize; nf], vec![0usize; nf], vec![0usize; nf]);
        for (k, &f) in order.iter().enumerate() {
            let size = factors[f].size;
            let replaced = &order[..k];
            let offset = coef[0].len();
            let stride = structure.encode(&unit(nf, f));
            for c in coef.iter_mut() {
                c.resize(offset + n * size, 0.0);
            }
            for i in 0..n {
                // Row i: factors replaced so far (and f) hold next values, the rest previous ones.
                structure.decode_into(i, &mut vals);
                for g in 0..nf {
                    if replaced.contains(&g) || g == f {
                        next[g] = vals[g];
                    } else {
                        prev[g] = vals[g];
                    }
                }
                // The run layout of `Step` is the mixed-radix joint index's.
                vals[f] = 0;
                debug_assert_eq!(structure.encode(&vals), i - (i / stride % size) * stride);
                for b in 0..size {
                    prev[f] = b;
                    for (u, c) in coef.iter_mut().enumerate() {
                        let cfg = structure.config_index(f, &prev, &next, u, n_actions);
                        c[offset + ((i / stride) * size + b) * stride + i % stride] = means[f][cfg * size + next[f]];
                    }
                }
            }
            steps.push(Step { size, stride, offset });
        }
        Some(FactoredTransition {
            n,
            steps,
            coef,
            terminal: Vec::new(),
        })
    }

    /// The same transition with `terminal` as its absorbing states (the planning model).
    pub fn with_terminal(&self, terminal: &[usize]) -> Self {
        FactoredTransition {
            terminal: terminal.to_vec(),
            ..self.clone()
        }
    }

    /// Multiply-adds of one [`FactoredTransition::apply`] (`N · Σ_f size_f`).
    pub fn cost(&self) -> usize {
        self.steps.iter().map(|s| self.n * s.size).sum()
    }

    /// The dense `B[u]` (column `s` is `B[u] e_s`), for materialising the joint matrices.
    pub fn dense(&self, u: usize) -> nalgebra::DMatrix<f64> {
        let mut m = nalgebra::DMatrix::zeros(self.n, self.n);
        let (mut e, mut scratch) = (vec![0.0; self.n], Vec::new());
        for (s, mut col) in m.column_iter_mut().enumerate() {
            e[s] = 1.0;
            self.apply(u, &e, col.as_mut_slice(), &mut scratch);
            e[s] = 0.0;
        }
        m
    }

    /// `out = B[u] x`. `scratch` is resized to `N`.
    pub fn apply(&self, u: usize, x: &[f64], out: &mut [f64], scratch: &mut Vec<f64>) {
        let n = self.n;
        scratch.resize(n, 0.0);
        // Ping-pong between `out` and `scratch`, starting where the last step lands in `out`.
        let odd = self.steps.len() % 2 == 1;
        {
            let first: &mut [f64] = if odd { scratch.as_mut_slice() } else { &mut *out };
            first.copy_from_slice(x);
            for &t in &self.terminal {
                first[t] = 0.0;
            }
        }
        let coef = &self.coef[u];
        for (k, st) in self.steps.iter().enumerate() {
            let (src, dst): (&[f64], &mut [f64]) = if (k % 2 == 0) == odd {
                (scratch.as_slice(), &mut *out)
            } else {
                (&*out, scratch.as_mut_slice())
            };
            let c = &coef[st.offset..st.offset + n * st.size];
            match (st.size, st.stride) {
                (2, 1) => runs_kw::<2, 1>(c, src, dst),
                (2, 2) => runs_kw::<2, 2>(c, src, dst),
                (2, 4) => runs_kw::<2, 4>(c, src, dst),
                (2, 8) => runs_kw::<2, 8>(c, src, dst),
                (4, 4) => runs_kw::<4, 4>(c, src, dst),
                (4, 8) => runs_kw::<4, 8>(c, src, dst),
                (4, 16) => runs_kw::<4, 16>(c, src, dst),
                (2, w) => runs::<2>(c, w, src, dst),
                (3, w) => runs::<3>(c, w, src, dst),
                (4, w) => runs::<4>(c, w, src, dst),
                (k, w) => runs_dyn(k, c, w, src, dst),
            }
        }
        for &t in &self.terminal {
            out[t] += x[t];
        }
    }
}

/// `ln B[u]` as a sum of per-factor terms, for perception's messages and `F`
/// (§III eq. "message passing"; docs/ARCHITECTURE.md §4.5):
///
/// `ln B[u][s', s] = Σ_f ln p(s'_f | parents_f, u) = Σ_f T_f[u][x_f(s), y_f(s')]`,
///
/// where `x_f(s)` indexes the previous-time parents of factor `f` and `y_f(s')` its own
/// next value with its next-time parents. So a message through `ln B` never needs the
/// dense `N x N` matrix: with `q` summed into its marginal over `x_f` (or `y_f`), a
/// factor's part is a small table product, broadcast back over the joint index. The
/// model uses it only when every entry of the dense `B` is at least the log floor
/// `1e-16` (docs/ARCHITECTURE.md §4.1), so that `ln(max(B, 1e-16)) = ln B` and the
/// factored sum is the dense floored logarithm up to rounding.
#[derive(Debug, Clone, PartialEq)]
pub struct FactoredLogB {
    n: usize,
    n_actions: usize,
    terms: Vec<LogTerm>,
}

/// Most values of `x_f` or `y_f` a [`FactoredLogB`] term may have: indices are `u8`, so
/// that reading the scratch arrays (of this length) needs no bounds checks.
const LOG_TERM_MAX: usize = 256;

/// Scratch of [`FactoredLogB`]'s messages: a factor's marginal of `q` and its partial
/// message. Keep one per agent (in the VMP workspace).
#[derive(Debug, Clone)]
pub struct LogBScratch {
    a: [f64; LOG_TERM_MAX],
    b: [f64; LOG_TERM_MAX],
}

impl Default for LogBScratch {
    fn default() -> Self {
        LogBScratch {
            a: [0.0; LOG_TERM_MAX],
            b: [0.0; LOG_TERM_MAX],
        }
    }
}

/// One factor's term of [`FactoredLogB`].
#[derive(Debug, Clone, PartialEq)]
struct LogTerm {
    /// `x_f(s)` for every joint state `s` (previous-time parents, mixed radix).
    x_of: Vec<u8>,
    /// `y_f(s')` for every joint state `s'` (own value, then next-time parents).
    y_of: Vec<u8>,
    nx: usize,
    ny: usize,
    /// Per action, `ln p` laid out `[x * ny + y]`.
    table: Vec<Vec<f64>>,
}

impl FactoredLogB {
    /// Build from the structure and the CPT means (as [`FactoredTransition::new`]). `None`
    /// for a single factor, or when a factor's parents take more than 256 joint values.
    pub fn new(structure: &Structure, means: &[Vec<f64>], n_actions: usize) -> Option<Self> {
        let factors = structure.factors();
        let nf = factors.len();
        let n = structure.joint_size();
        if nf < 2 || n > u32::MAX as usize {
            return None;
        }
        let mut vals = vec![0usize; nf];
        let mut terms = Vec::with_capacity(nf);
        for (f, fac) in factors.iter().enumerate() {
            let prev_parents: Vec<usize> = fac
                .parents
                .iter()
                .filter_map(|p| match *p {
                    Parent::Prev(j) => Some(j),
                    Parent::Next(_) => None,
                })
                .collect();
            let mut next_vars = vec![f];
            next_vars.extend(fac.parents.iter().filter_map(|p| match *p {
                Parent::Next(j) => Some(j),
                Parent::Prev(_) => None,
            }));
            let radix = |vars: &[usize], vals: &[usize]| vars.iter().fold(0, |acc, &j| acc * factors[j].size + vals[j]);
            let nx: usize = prev_parents.iter().map(|&j| factors[j].size).product();
            let ny: usize = next_vars.iter().map(|&j| factors[j].size).product();
            if nx > LOG_TERM_MAX || ny > LOG_TERM_MAX {
                return None;
            }
            let (mut x_of, mut y_of) = (Vec::with_capacity(n), Vec::with_capacity(n));
            // A representative joint state for every x and every y.
            let (mut rep_x, mut rep_y) = (vec![usize::MAX; nx], vec![usize::MAX; ny]);
            for s in 0..n {
                structure.decode_into(s, &mut vals);
                let (x, y) = (radix(&prev_parents, &vals), radix(&next_vars, &vals));
                x_of.push(x as u8);
                y_of.push(y as u8);
                if rep_x[x] == usize::MAX {
                    rep_x[x] = s;
                }
                if rep_y[y] == usize::MAX {
                    rep_y[y] = s;
                }
            }
            let size = fac.size;
            let table = (0..n_actions)
                .map(|u| {
                    let mut t = vec![0.0; nx * ny];
                    for (x, &sx) in rep_x.iter().enumerate() {
                        let prev = structure.decode(sx);
                        for (y, &sy) in rep_y.iter().enumerate() {
                            let next = structure.decode(sy);
                            let cfg = structure.config_index(f, &prev, &next, u, n_actions);
                            t[x * ny + y] = means[f][cfg * size + next[f]].ln();
                        }
                    }
                    t
                })
                .collect();
            terms.push(LogTerm {
                x_of,
                y_of,
                nx,
                ny,
                table,
            });
        }
        Some(FactoredLogB { n, n_actions, terms })
    }

    /// Number of actions.
    pub fn n_actions(&self) -> usize {
        self.n_actions
    }

    /// `out[s'] = Σ_s ln B[u][s', s] q[s]` (the forward message).
    pub fn forward(&self, u: usize, q: &[f64], out: &mut [f64], sc: &mut LogBScratch) {
        let out = &mut out[..self.n];
        out.fill(0.0);
        let (mx, w) = (&mut sc.a, &mut sc.b);
        for t in &self.terms {
            mx[..t.nx].fill(0.0);
            for (x, qs) in t.x_of.iter().zip(&q[..self.n]) {
                mx[*x as usize] += qs;
            }
            // w[y] = Σ_x mx[x] T[x, y].
            w[..t.ny].fill(0.0);
            for (row, m) in t.table[u].chunks_exact(t.ny).zip(&mx[..t.nx]) {
                for (wy, ty) in w[..t.ny].iter_mut().zip(row) {
                    *wy += m * ty;
                }
            }
            for (o, y) in out.iter_mut().zip(&t.y_of) {
                *o += w[*y as usize];
            }
        }
    }

    /// `out[s] = Σ_{s'} q[s'] ln B[u][s', s]` (the backward message, `(ln B[u])ᵀ q`).
    pub fn backward(&self, u: usize, q: &[f64], out: &mut [f64], sc: &mut LogBScratch) {
        let out = &mut out[..self.n];
        out.fill(0.0);
        let (r, my) = (&mut sc.a, &mut sc.b);
        for t in &self.terms {
            my[..t.ny].fill(0.0);
            for (y, qs) in t.y_of.iter().zip(&q[..self.n]) {
                my[*y as usize] += qs;
            }
            // r[x] = Σ_y T[x, y] my[y].
            for (rx, row) in r[..t.nx].iter_mut().zip(t.table[u].chunks_exact(t.ny)) {
                *rx = row.iter().zip(&my[..t.ny]).map(|(a, b)| a * b).sum();
            }
            for (o, x) in out.iter_mut().zip(&t.x_of) {
                *o += r[*x as usize];
            }
        }
    }

    /// `q_nextᵀ (ln B[u]) q_prev` (the transition term of `F`, Definition "VFE").
    pub fn quadratic(&self, u: usize, q_next: &[f64], q_prev: &[f64], sc: &mut LogBScratch) -> f64 {
        let mut total = 0.0;
        let (mx, my) = (&mut sc.a, &mut sc.b);
        for t in &self.terms {
            mx[..t.nx].fill(0.0);
            my[..t.ny].fill(0.0);
            for ((x, y), (a, b)) in t
                .x_of
                .iter()
                .zip(&t.y_of)
                .zip(q_prev[..self.n].iter().zip(&q_next[..self.n]))
            {
                mx[*x as usize] += a;
                my[*y as usize] += b;
            }
            for (row, m) in t.table[u].chunks_exact(t.ny).zip(&mx[..t.nx]) {
                total += m * row.iter().zip(&my[..t.ny]).map(|(a, b)| a * b).sum::<f64>();
            }
        }
        total
    }
}

/// One step (see [`Step`]) with `K` previous values and run length `W` (the factor's
/// stride) known at compile time: every block is a fixed-size tile the compiler unrolls
/// and vectorises. `dst[i] = ((0 + c_0 s_0) + c_1 s_1) + ...`, term by term in `t` order.
fn runs_kw<const K: usize, const W: usize>(coef: &[f64], src: &[f64], dst: &mut [f64]) {
    for ((dblk, sblk), cblk) in dst
        .chunks_exact_mut(K * W)
        .zip(src.chunks_exact(K * W))
        .zip(coef.chunks_exact(K * K * W))
    {
        for k in 0..K {
            let mut acc = [0.0f64; W];
            for t in 0..K {
                for l in 0..W {
                    acc[l] += cblk[(k * K + t) * W + l] * sblk[t * W + l];
                }
            }
            dblk[k * W..(k + 1) * W].copy_from_slice(&acc);
        }
    }
}

/// [`runs_kw`] with the run length `w` known at run time only.
fn runs<const K: usize>(coef: &[f64], w: usize, src: &[f64], dst: &mut [f64]) {
    for ((dblk, sblk), cblk) in dst
        .chunks_exact_mut(K * w)
        .zip(src.chunks_exact(K * w))
        .zip(coef.chunks_exact(K * K * w))
    {
        for (k, d) in dblk.chunks_exact_mut(w).enumerate() {
            let c = &cblk[k * K * w..(k + 1) * K * w];
            for ((d, c), s) in d.iter_mut().zip(&c[..w]).zip(&sblk[..w]) {
                *d = 0.0 + c * s;
            }
            for t in 1..K {
                for ((d, c), s) in d.iter_mut().zip(&c[t * w..(t + 1) * w]).zip(&sblk[t * w..(t + 1) * w]) {
                    *d += c * s;
                }
            }
        }
    }
}

/// [`runs`] for any number of previous values `k`: `dst[i] = c_0 s_0 + c_1 s_1 + ...`
/// (the first term alone, as a serial sum from `-0.0` gives it).
fn runs_dyn(k_size: usize, coef: &[f64], w: usize, src: &[f64], dst: &mut [f64]) {
    for ((dblk, sblk), cblk) in dst
        .chunks_exact_mut(k_size * w)
        .zip(src.chunks_exact(k_size * w))
        .zip(coef.chunks_exact(k_size * k_size * w))
    {
        for (k, d) in dblk.chunks_exact_mut(w).enumerate() {
            let c = &cblk[k * k_size * w..(k + 1) * k_size * w];
            for ((d, c), s) in d.iter_mut().zip(&c[..w]).zip(&sblk[..w]) {
                *d = c * s;
            }
            for t in 1..k_size {
                for ((d, c), s) in d.iter_mut().zip(&c[t * w..(t + 1) * w]).zip(&sblk[t * w..(t + 1) * w]) {
                    *d += c * s;
                }
            }
        }
    }
}

/// The joint-index values with factor `f` at 1 and the others at 0 (gives `f`'s stride).
fn unit(nf: usize, f: usize) -> Vec<usize> {
    let mut v = vec![0; nf];
    v[f] = 1;
    v
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::structure::Factor;
    use proptest::prelude::*;
    use rand::{RngExt, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn paper_structure_has_an_elimination_order() {
        let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
        // v before d (d' <- v'), L and d before p (p' <- L', d').
        assert_eq!(elimination_order(&st), Some(vec![1, 0, 2, 3]));
    }

    #[test]
    fn crossed_previous_parents_have_none() {
        // x' <- (x, y) and y' <- (y, x): each needs the other's previous value.
        let f = |name: &str, parents| Factor {
            name: name.into(),
            size: 2,
            parents,
            action_parent: false,
        };
        let st = Structure::new(vec![
            f("x", vec![Parent::Prev(0), Parent::Prev(1)]),
            f("y", vec![Parent::Prev(1), Parent::Prev(0)]),
        ])
        .unwrap();
        assert_eq!(elimination_order(&st), None);
    }

    /// With a fifth factor (a second pedestrian `p2 <- (p2, L', d')`) there is still an
    /// elimination order (the factored product's equality with the definition is checked
    /// in `factored_checks`).
    #[test]
    fn five_factor_structure_has_an_elimination_order() {
        let st = Structure::new(five_factors()).unwrap();
        assert_eq!(elimination_order(&st), Some(vec![1, 0, 2, 3, 4]));
    }

    /// The paper's four factors plus a second pedestrian `p2 <- (p2, L', d')`.
    pub(crate) fn five_factors() -> Vec<Factor> {
        let mut factors = Structure::paper_default([3, 2, 2, 2]).unwrap().factors().to_vec();
        factors.push(Factor {
            name: "p2".into(),
            size: 3,
            parents: vec![Parent::Prev(4), Parent::Next(2), Parent::Next(0)],
            action_parent: false,
        });
        factors
    }

    /// The row-by-row form of the steps (each row's sum in `t` order, from `0.0` for 2 to 4
    /// previous values and as a serial sum otherwise): what `apply` computed before its
    /// steps became runs. `apply` must give the same bits.
    fn apply_by_rows(
        st: &Structure,
        means: &[Vec<f64>],
        na: usize,
        u: usize,
        x: &[f64],
        terminal: &[usize],
    ) -> Vec<f64> {
        let factors = st.factors();
        let nf = factors.len();
        let n = st.joint_size();
        let order = elimination_order(st).unwrap();
        let mut cur = x.to_vec();
        for &t in terminal {
            cur[t] = 0.0;
        }
        let (mut vals, mut prev, mut next) = (vec![0usize; nf], vec![0usize; nf], vec![0usize; nf]);
        for (k, &f) in order.iter().enumerate() {
            let size = factors[f].size;
            let stride = st.encode(&unit(nf, f));
            let mut dst = vec![0.0; n];
            for (i, d) in dst.iter_mut().enumerate() {
                st.decode_into(i, &mut vals);
                for g in 0..nf {
                    if order[..k].contains(&g) || g == f {
                        next[g] = vals[g];
                    } else {
                        prev[g] = vals[g];
                    }
                }
                vals[f] = 0;
                let base = st.encode(&vals);
                let terms = (0..size).map(|b| {
                    prev[f] = b;
                    means[f][st.config_index(f, &prev, &next, u, na) * size + next[f]] * cur[base + b * stride]
                });
                *d = if (2..=4).contains(&size) {
                    terms.fold(0.0, |acc, t| acc + t)
                } else {
                    terms.collect::<Vec<f64>>().into_iter().sum()
                };
            }
            cur = dst;
        }
        for &t in terminal {
            cur[t] += x[t];
        }
        cur
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        /// `apply` (runs, tiles, const-generic kernels) equals the row-by-row steps bit for
        /// bit, for random sizes (1 to 5 per factor, every kernel), CPTs, beliefs and terminals.
        #[test]
        fn runs_equal_rows_bit_for_bit(
            sizes in prop::array::uniform4(1usize..6),
            seed in 0u64..1000,
            n_terminal in 0usize..4,
        ) {
            let st = Structure::paper_default(sizes).unwrap();
            let n = st.joint_size();
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let means: Vec<Vec<f64>> = st
                .factors()
                .iter()
                .enumerate()
                .map(|(f, fac)| {
                    let rows = st.n_configs(f, 3);
                    let mut m: Vec<f64> = (0..rows * fac.size).map(|_| rng.random::<f64>()).collect();
                    for row in m.chunks_mut(fac.size) {
                        let z: f64 = row.iter().sum();
                        row.iter_mut().for_each(|v| *v /= z);
                    }
                    m
                })
                .collect();
            let terminal: Vec<usize> = (0..n_terminal.min(n)).map(|i| (i * 7 + seed as usize) % n).collect();
            let ft = FactoredTransition::new(&st, &means, 3).unwrap().with_terminal(&terminal);
            let x: Vec<f64> = (0..n).map(|_| rng.random::<f64>()).collect();
            let (mut out, mut scratch) = (vec![0.0; n], Vec::new());
            for u in 0..3 {
                ft.apply(u, &x, &mut out, &mut scratch);
                let want = apply_by_rows(&st, &means, 3, u, &x, &terminal);
                for (a, b) in out.iter().zip(&want) {
                    prop_assert_eq!(a.to_bits(), b.to_bits());
                }
                // `dense` is apply's columns, bit for bit.
                let dense = ft.dense(u);
                let mut e = vec![0.0; n];
                for s in 0..n {
                    e[s] = 1.0;
                    ft.apply(u, &e, &mut out, &mut scratch);
                    e[s] = 0.0;
                    for (a, b) in dense.column(s).iter().zip(&out) {
                        prop_assert_eq!(a.to_bits(), b.to_bits());
                    }
                }
            }
        }

    }
}
