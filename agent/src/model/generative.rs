//! The generative model the agent perceives and plans with (§II-A): the plain matrices
//! `A`, `B`, `C`, `D`, their logarithms and the ambiguity `H_A` (Prop. 1), and the
//! preference over transitions beside `C` (docs/ARCHITECTURE.md §4.3).

use crate::maths::ln;
use crate::transition::{FactoredLogB, FactoredTransition};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::CrashModel;

/// The plain matrices of a generative model (what perception and planning read):
/// `A[o,s] = p(o|s)`, `B[u][(s',s)] = p(s'|s,u)`, `C = ln c` (normalised log
/// preferences), `D = p(s_1)`, plus the derived `ln A`, `ln B` and the ambiguity
/// `H_A[s] = -Σ_o A[o,s] ln A[o,s]` (Prop. 1).
#[derive(Debug, Clone, PartialEq)]
pub struct GenerativeModel {
    /// Observation model `A` (n_obs x n_states, column-stochastic).
    pub a: DMatrix<f64>,
    /// Elementwise floored `ln A`.
    pub ln_a: DMatrix<f64>,
    /// Ambiguity per state, `H_A[s]`.
    pub h_a: Vec<f64>,
    /// Whether `A` is exactly the identity (enables one-hot fast paths).
    pub a_identity: bool,
    /// Transition matrices `B[u]` (n_states x n_states, column-stochastic).
    pub b: Vec<DMatrix<f64>>,
    /// Elementwise floored `ln B[u]`.
    pub ln_b: Vec<DMatrix<f64>>,
    /// `(ln B[u])^T`, i.e. `ln B[u]` row by row: VMP's backward messages and `F` read
    /// `ln B` a row at a time, which this layout makes contiguous.
    pub ln_b_t: Vec<DMatrix<f64>>,
    /// Log preferences over observations, `C = ln c` (a normalised log distribution).
    pub c: Vec<f64>,
    /// A preference over transitions, beside `C` (docs/ARCHITECTURE.md §4.3): planning adds
    /// its expected cost to every step's `G`.
    pub transition_cost: Option<TransitionCost>,
    /// The crash hazard planning uses in place of absorbing crash-risk states
    /// ([`CrashModel`]; only on the planning model, and only when the agent plans with it).
    pub crash: Option<CrashModel>,
    /// Initial state prior `D`.
    pub d: Vec<f64>,
    /// The same `B[u]` as per-factor steps (§II-A), when the model came from a factored
    /// world model whose structure allows it; planning uses it for dense beliefs.
    pub factored: Option<FactoredTransition>,
    /// `ln B[u]` as per-factor terms (perception's messages and `F`), when the model came
    /// from a factored world model and every entry of `B` is at least the log floor, so
    /// that the factored sum is `ln B` up to rounding (see [`FactoredLogB`]).
    pub log_factored: Option<FactoredLogB>,
}

/// A cost in nats for moving from one set of states to another in one step (a
/// preference over transitions that no state preference can express, such as entering
/// the crosswalk on red: docs/ARCHITECTURE.md §4.3).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TransitionCost {
    /// The states a costly step starts from, per state.
    pub from: Vec<bool>,
    /// The states a costly step ends in, per state.
    pub to: Vec<bool>,
    /// The cost, in nats of `G` (added to the expected free energy, so positive is avoided).
    pub cost: f64,
}

impl GenerativeModel {
    /// Build from `A`, `B`, `C` (already normalised log preferences) and `D`, computing
    /// the derived quantities. Shapes are the caller's responsibility (see `inspect`).
    pub fn new(a: DMatrix<f64>, b: Vec<DMatrix<f64>>, c: Vec<f64>, d: Vec<f64>) -> Self {
        let ln_a = a.map(ln);
        let h_a = (0..a.ncols())
            .map(|s| -(0..a.nrows()).map(|o| a[(o, s)] * ln_a[(o, s)]).sum::<f64>())
            .collect();
        let a_identity = a.is_square() && a == DMatrix::identity(a.nrows(), a.ncols());
        let ln_b: Vec<DMatrix<f64>> = b.iter().map(|m| m.map(ln)).collect();
        let ln_b_t = ln_b.iter().map(|m| m.transpose()).collect();
        GenerativeModel {
            a,
            ln_a,
            h_a,
            a_identity,
            b,
            ln_b,
            ln_b_t,
            c,
            transition_cost: None,
            crash: None,
            d,
            factored: None,
            log_factored: None,
        }
    }

    /// The expected cost of one step `u` from belief `s` under [`Self::transition_cost`]
    /// (0 without one): `cost · Σ_{s'} to[s'] (B[u] (from ⊙ s))[s']`. `masked` and
    /// `next` are scratch of `n_states`.
    pub fn transition_cost_of(
        &self,
        u: usize,
        s: &[f64],
        masked: &mut [f64],
        next: &mut [f64],
        scratch: &mut Vec<f64>,
    ) -> f64 {
        let Some(t) = &self.transition_cost else {
            return 0.0;
        };
        for ((m, x), f) in masked.iter_mut().zip(s).zip(&t.from) {
            *m = if *f { *x } else { 0.0 };
        }
        if masked.iter().all(|m| *m == 0.0) {
            return 0.0;
        }
        self.transition_into(u, masked, next, scratch);
        t.cost
            * next
                .iter()
                .zip(&t.to)
                .filter(|(_, to)| **to)
                .map(|(p, _)| p)
                .sum::<f64>()
    }

    /// `out = B[u] x` (§II): the factor-by-factor product when it is cheaper than the
    /// dense columns of `x`'s non-zero entries, else those columns. `scratch` is reused.
    pub fn transition_into(&self, u: usize, x: &[f64], out: &mut [f64], scratch: &mut Vec<f64>) {
        let n = self.n_states();
        match &self.factored {
            Some(ft) if x.iter().filter(|v| **v != 0.0).count() * n > ft.cost() => ft.apply(u, x, out, scratch),
            _ => crate::maths::axpy_columns(self.b[u].as_slice(), n, x, out),
        }
    }

    /// Number of hidden states.
    pub fn n_states(&self) -> usize {
        self.a.ncols()
    }
    /// Number of observations.
    pub fn n_obs(&self) -> usize {
        self.a.nrows()
    }
    /// Number of actions.
    pub fn n_actions(&self) -> usize {
        self.b.len()
    }
}
