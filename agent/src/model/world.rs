//! The agent's world model `W` (§II-A eq. "world model"; Dirichlet parameters §V):
//! factor CPTs with Dirichlet counts, the joint `B[u]` materialised from them, the
//! observation model `A` with Dirichlet counts, preferences `C` and the state prior `D`.

use crate::error::{AgentError, FieldError, ParamError};
use crate::limits::{MAX_ACTIONS, MAX_STATES};
use crate::maths::{LN_FLOOR, log_softmax};
use crate::params::ModelPriors;
use crate::structure::Structure;
use crate::transition::{FactoredLogB, FactoredTransition};
use nalgebra::DMatrix;
use serde::{Deserialize, Serialize};

use super::crash::check_crash;
use super::pooling::Pooling;
use super::stored::{WorldModelRepr, check_repr};
use super::{CrashModel, GenerativeModel, TransitionCost};

/// The agent's world model (§II-A, §V): Dirichlet-count CPTs per factor, `A` counts,
/// `C`, `D`, and the materialised joint [`GenerativeModel`] (derived, not serialised).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "WorldModelRepr", into = "WorldModelRepr")]
pub struct WorldModel {
    pub(super) structure: Structure,
    pub(super) n_actions: usize,
    pub(super) priors: ModelPriors,
    /// Per factor: counts laid out `[config * size + child]`, priors included.
    pub(super) cpt: Vec<Vec<f64>>,
    pub(super) a_counts: DMatrix<f64>,
    /// Counts behind `D` (prior mass 1 spread per `ModelPriors::d`).
    pub(super) d_counts: Vec<f64>,
    /// Episode-ending states, absorbing in the planning model.
    pub(super) terminal: Vec<usize>,
    /// The crash model of the map the agent was trained on, if it has one.
    pub(super) crash: Option<CrashModel>,
    /// Whether planning uses [`WorldModel::crash_model`] (not serialised; set by the agent).
    pub(super) plan_crash: bool,
    /// Persistence pooling of one factor (not serialised; set by the agent that uses it).
    pub(super) pooling: Option<Pooling>,
    pub(super) gm: GenerativeModel,
    /// The generative model used for planning: `gm` with every terminal state absorbing.
    pub(super) gm_plan: GenerativeModel,
}

impl From<WorldModel> for WorldModelRepr {
    fn from(w: WorldModel) -> Self {
        WorldModelRepr {
            structure: w.structure,
            n_actions: w.n_actions,
            priors: w.priors,
            cpt: w.cpt,
            a_counts: w.a_counts,
            c: w.gm.c,
            d_counts: w.d_counts,
            terminal: w.terminal,
            transition_cost: w.gm.transition_cost,
            crash: w.crash,
        }
    }
}

impl TryFrom<WorldModelRepr> for WorldModel {
    type Error = FieldError;
    fn try_from(r: WorldModelRepr) -> Result<Self, FieldError> {
        check_repr(&r)?;
        let mut gm = GenerativeModel::new(DMatrix::zeros(0, 0), vec![], r.c, vec![]);
        gm.transition_cost = r.transition_cost;
        let mut w = WorldModel {
            gm,
            gm_plan: GenerativeModel::new(DMatrix::zeros(0, 0), vec![], vec![], vec![]),
            terminal: r.terminal,
            crash: r.crash,
            plan_crash: false,
            pooling: None,
            d_counts: r.d_counts,
            structure: r.structure,
            n_actions: r.n_actions,
            priors: r.priors,
            cpt: r.cpt,
            a_counts: r.a_counts,
        };
        w.materialize();
        Ok(w)
    }
}

impl WorldModel {
    /// A world model with prior counts only (§II-A): CPT cells get
    /// `transition_concentration`, `A` is identity or noisy per [`ModelPriors`], `C` is
    /// uniform (set it with [`WorldModel::set_preferences`]), `D` from the priors.
    pub fn new(structure: Structure, n_actions: usize, priors: &ModelPriors) -> Result<WorldModel, AgentError> {
        priors.check()?;
        if !(1..=MAX_ACTIONS).contains(&n_actions) {
            return Err(ParamError::new("n_actions", n_actions, "in 1..=16 (see limits::MAX_ACTIONS)").into());
        }
        let n = structure.joint_size();
        if n > MAX_STATES {
            return Err(AgentError::Structure(format!(
                "{n} joint states; at most {MAX_STATES} (see limits::MAX_STATES)"
            )));
        }
        let cpt = (0..structure.factors().len())
            .map(|f| {
                vec![priors.transition_concentration; structure.n_configs(f, n_actions) * structure.factors()[f].size]
            })
            .collect();
        let mut a_counts = DMatrix::from_element(n, n, 0.0);
        for s in 0..n {
            for o in 0..n {
                a_counts[(o, s)] = if n == 1 {
                    priors.a_concentration
                } else if o == s {
                    priors.a_concentration * (1.0 - priors.a_noise)
                } else {
                    priors.a_concentration * priors.a_noise / (n - 1) as f64
                };
            }
        }
        let d = match &priors.d {
            Some(d) if d.len() == n => d.clone(),
            Some(d) => {
                return Err(AgentError::SizeMismatch {
                    what: "D".into(),
                    expected: n,
                    found: d.len(),
                });
            }
            None => vec![1.0 / n as f64; n],
        };
        let c = vec![-(n as f64).ln(); n];
        let mut w = WorldModel {
            gm: GenerativeModel::new(DMatrix::zeros(0, 0), vec![], c, vec![]),
            gm_plan: GenerativeModel::new(DMatrix::zeros(0, 0), vec![], vec![], vec![]),
            terminal: Vec::new(),
            crash: None,
            plan_crash: false,
            pooling: None,
            d_counts: d,
            structure,
            n_actions,
            priors: priors.clone(),
            cpt,
            a_counts,
        };
        w.materialize();
        Ok(w)
    }

    /// The factor structure.
    pub fn structure(&self) -> &Structure {
        &self.structure
    }
    /// Number of actions.
    pub fn n_actions(&self) -> usize {
        self.n_actions
    }
    /// Number of joint states.
    pub fn n_states(&self) -> usize {
        self.structure.joint_size()
    }
    /// The priors the model was built with.
    pub fn priors(&self) -> &ModelPriors {
        &self.priors
    }
    /// The materialised matrices.
    pub fn generative(&self) -> &GenerativeModel {
        &self.gm
    }

    /// Fully observed training (§V with one-hot posteriors): add one count to the
    /// CPT cell of every factor for the transition `s --a--> s_next`. Call
    /// [`WorldModel::materialize`] afterwards. Out-of-range indices are ignored.
    pub fn observe_transition(&mut self, s: usize, a: usize, s_next: usize) {
        let n = self.n_states();
        if s >= n || s_next >= n || a >= self.n_actions {
            return;
        }
        let prev = self.structure.decode(s);
        let next = self.structure.decode(s_next);
        for f in 0..self.cpt.len() {
            let size = self.structure.factors()[f].size;
            let cfg = self.structure.config_index(f, &prev, &next, a, self.n_actions);
            self.cpt[f][cfg * size + next[f]] += 1.0;
        }
    }

    /// The joint `B[u]` of the current counts, bit for bit the matrices
    /// [`WorldModel::materialize`] would put in `generative().b`, without building the rest
    /// of the generative model (logarithms, `A`, the planning copy): for a caller that
    /// needs only the transition means (Bayesian RL on the factored model).
    pub fn transition_matrices(&self) -> Vec<DMatrix<f64>> {
        let means = self.cpt_means();
        match FactoredTransition::new(&self.structure, &means, self.n_actions) {
            Some(ft) => (0..self.n_actions).map(|u| ft.dense(u)).collect(),
            None => self.dense_b(&means),
        }
    }

    /// Rebuild the joint `B[u][(s',s)] = Π_f p(s'_f | parents_f, u)` from CPT posterior
    /// means, and `A` from its counts (§II-A; re-run after learning, §V).
    pub fn materialize(&mut self) {
        let means = self.cpt_means();
        let factored = FactoredTransition::new(&self.structure, &means, self.n_actions);
        let b: Vec<DMatrix<f64>> = match &factored {
            // Factor by factor: N columns of N · Σ size_f multiply-adds each.
            Some(ft) => (0..self.n_actions).map(|u| ft.dense(u)).collect(),
            None => self.dense_b(&means),
        };
        let mut a = self.a_counts.clone();
        for mut col in a.column_iter_mut() {
            let z: f64 = col.sum();
            if z > 0.0 {
                col /= z;
            }
        }
        let c = std::mem::take(&mut self.gm.c);
        let rule = self.gm.transition_cost.take();
        let mut d = self.d_counts.clone();
        crate::maths::normalize_in_place(&mut d);
        // Planning with the crash hazard: its states are neither absorbing nor crashes.
        let crash = self.crash.as_ref().filter(|_| self.plan_crash);
        let hazard_states = crash.map(CrashModel::hazard_states).unwrap_or_default();
        let absorbing: Vec<usize> = self
            .terminal
            .iter()
            .copied()
            .filter(|s| !hazard_states.contains(s))
            .collect();
        let mut b_plan = b.clone();
        for m in &mut b_plan {
            for &s in &absorbing {
                m.column_mut(s).fill(0.0);
                m[(s, s)] = 1.0;
            }
        }
        let mut c_plan = c.clone();
        if let Some(cm) = crash {
            hazard_states.iter().for_each(|&s| c_plan[s] = cm.neutral);
        }
        self.gm_plan = GenerativeModel::new(a.clone(), b_plan, c_plan, d.clone());
        self.gm_plan.transition_cost.clone_from(&rule);
        self.gm_plan.crash = crash.cloned();
        self.gm_plan.factored = factored.as_ref().map(|ft| ft.with_terminal(&absorbing));
        // Perception's messages through ln B factor by factor, when no entry of B is under
        // the log floor (then the per-factor sum is the floored ln B up to rounding).
        let log_factored = if b.iter().all(|m| m.iter().all(|p| *p >= LN_FLOOR)) {
            FactoredLogB::new(&self.structure, &means, self.n_actions)
        } else {
            None
        };
        self.gm = GenerativeModel::new(a, b, c, d);
        self.gm.transition_cost = rule;
        self.gm.factored = factored;
        self.gm.log_factored = log_factored;
    }

    /// Posterior means of each CPT, laid out like the counts (rows pooled where
    /// [`WorldModel::set_persistence_pooling`] says so).
    fn cpt_means(&self) -> Vec<Vec<f64>> {
        (0..self.structure.factors().len())
            .map(|f| {
                let size = self.structure.factors()[f].size;
                let mut m = match &self.pooling {
                    Some(pool) if pool.factor == f => {
                        pool.pooled(&self.cpt[f], size, self.priors.transition_concentration)
                    }
                    _ => self.cpt[f].clone(),
                };
                for row in m.chunks_mut(size) {
                    crate::maths::normalize_in_place(row);
                }
                m
            })
            .collect()
    }

    /// Pool the persistence of factor `factor` over its next-time parents `over` (by
    /// name; several joined by `+`, e.g. `"d+L"`): in every CPT row where the factor's own previous value is not 0 (it was
    /// present), the data counts of the rows that differ only in `over` are summed and
    /// shared, so that those rows predict alike; rows with previous value 0 (appearance)
    /// keep their own counts. The counts themselves are unchanged (the state gate and
    /// agent files read them as learned); only the probabilities `B` is built from are.
    ///
    /// This is a context-specific independence the paper's CPT `p' | p, L', d'` does not
    /// have: a pedestrian who is on the crosswalk stays or leaves whatever the car's
    /// distance and whatever the light. Without `d`, one episode in which a pedestrian
    /// left just as the car reached the crosswalk teaches the planner that driving on
    /// makes pedestrians leave (measured on `late_fast`, EXPERIMENTS.md). Without `L`,
    /// a pedestrian on the crosswalk under green, never seen in training, keeps the
    /// prior's even odds of leaving every tick, so the planner bets on them vanishing
    /// (measured on `slow_walker`, EXPERIMENTS.md). `None` restores the paper's CPT.
    pub fn set_persistence_pooling(&mut self, pooling: Option<(&str, &str)>) -> Result<(), AgentError> {
        self.pooling = match pooling {
            None => None,
            Some((factor, over)) => Some(Pooling::new(&self.structure, self.n_actions, factor, over)?),
        };
        self.materialize();
        Ok(())
    }

    /// The joint `B[u][(s', s)] = Π_f p(s'_f | parents_f, u)` computed entry by entry,
    /// straight from the definition (§II-A). [`WorldModel::materialize`] builds `B`
    /// factor by factor when it can; this is the slow oracle the tests compare it with.
    pub fn b_by_definition(&self) -> Vec<DMatrix<f64>> {
        self.dense_b(&self.cpt_means())
    }

    /// `B[u][(s', s)] = Π_f means_f[...]` entry by entry (structures without an
    /// elimination order, e.g. the flat joint model).
    fn dense_b(&self, means: &[Vec<f64>]) -> Vec<DMatrix<f64>> {
        let n = self.n_states();
        let nf = self.structure.factors().len();
        let decoded: Vec<Vec<usize>> = (0..n).map(|s| self.structure.decode(s)).collect();
        let mut b = Vec::with_capacity(self.n_actions);
        for u in 0..self.n_actions {
            let mut m = DMatrix::zeros(n, n);
            for (s, prev) in decoded.iter().enumerate() {
                for (s2, next) in decoded.iter().enumerate() {
                    let mut p = 1.0;
                    for f in 0..nf {
                        let size = self.structure.factors()[f].size;
                        let cfg = self.structure.config_index(f, prev, next, u, self.n_actions);
                        p *= means[f][cfg * size + next[f]];
                        if p == 0.0 {
                            break;
                        }
                    }
                    m[(s2, s)] = p;
                }
            }
            b.push(m);
        }
        b
    }

    /// Declares the episode-ending states (arrival, and the crash-risk states the agent
    /// must not enter): in the model used for planning they are absorbing, so the
    /// expected free energy of a policy that ends the episode counts that end for the
    /// rest of the horizon instead of imagining the drive going on (§IV, EFE_0).
    /// Perception and surprise keep the learned transitions. Re-materializes.
    pub fn set_terminal_states(&mut self, states: &[usize]) -> Result<(), AgentError> {
        let n = self.n_states();
        if let Some(&s) = states.iter().find(|&&s| s >= n) {
            return Err(AgentError::OutOfRange {
                what: "terminal state",
                index: s,
                size: n,
            });
        }
        self.terminal = states.to_vec();
        self.materialize();
        Ok(())
    }

    /// The episode-ending states (see [`WorldModel::set_terminal_states`]).
    pub fn terminal_states(&self) -> &[usize] {
        &self.terminal
    }

    /// The generative model used for planning: as [`WorldModel::generative`], with the
    /// terminal states absorbing.
    pub fn planning_generative(&self) -> &GenerativeModel {
        &self.gm_plan
    }

    /// `B[u]` (n_states x n_states, column-stochastic; entry `(s', s)`).
    pub fn b(&self, u: usize) -> &DMatrix<f64> {
        &self.gm.b[u]
    }
    /// `A` (entry `(o, s)`).
    pub fn a(&self) -> &DMatrix<f64> {
        &self.gm.a
    }
    /// Dirichlet counts of `A` (§V "Updating the World Model: Observation Model").
    pub fn a_counts(&self) -> &DMatrix<f64> {
        &self.a_counts
    }
    /// Mutable Dirichlet counts of `A` (call [`WorldModel::materialize`] afterwards).
    pub fn a_counts_mut(&mut self) -> &mut DMatrix<f64> {
        &mut self.a_counts
    }
    /// CPT counts of factor `f`, laid out `[config * size + child]`.
    pub fn cpt_counts(&self, f: usize) -> &[f64] {
        &self.cpt[f]
    }
    /// Mutable CPT counts of factor `f` (call [`WorldModel::materialize`] afterwards).
    pub fn cpt_counts_mut(&mut self, f: usize) -> &mut [f64] {
        &mut self.cpt[f]
    }
    /// Log preferences `C`.
    pub fn c(&self) -> &[f64] {
        &self.gm.c
    }
    /// State prior `D`.
    pub fn d(&self) -> &[f64] {
        &self.gm.d
    }

    /// Set `C = log_softmax(R / τ_c)` from per-observation rewards (docs/ARCHITECTURE.md §4.3).
    pub fn set_preferences(&mut self, rewards: &[f64], tau_c: f64) -> Result<(), AgentError> {
        if rewards.len() != self.gm.n_obs() {
            return Err(AgentError::SizeMismatch {
                what: "rewards".into(),
                expected: self.gm.n_obs(),
                found: rewards.len(),
            });
        }
        if !(tau_c > 0.0 && tau_c.is_finite()) {
            return Err(ParamError::new("tau_c", tau_c, "finite and > 0").into());
        }
        let scaled: Vec<f64> = rewards.iter().map(|r| r / tau_c).collect();
        self.gm.c = log_softmax(&scaled);
        self.materialize();
        Ok(())
    }

    /// Set (or clear) the crash model of the map the agent is trained on ([`CrashModel`];
    /// docs/ARCHITECTURE.md §4.3). Planning uses it only after
    /// [`WorldModel::plan_with_crash_model`]. Re-materializes.
    pub fn set_crash_model(&mut self, crash: Option<CrashModel>) -> Result<(), AgentError> {
        if let Some(c) = &crash {
            check_crash(c, self.n_states(), self.n_actions)?;
        }
        self.crash = crash;
        self.materialize();
        Ok(())
    }

    /// The crash model, if the agent was trained with one.
    pub fn crash_model(&self) -> Option<&CrashModel> {
        self.crash.as_ref()
    }

    /// Plan with the crash model (`true`, where the model has one) or with the paper's
    /// crash-risk states (`false`, the default). Re-materializes when it changes.
    pub fn plan_with_crash_model(&mut self, on: bool) {
        if self.plan_crash != on {
            self.plan_crash = on;
            self.materialize();
        }
    }

    /// Set (or, with `None`, clear) the preference over transitions planning adds to `G`
    /// ([`TransitionCost`]; docs/ARCHITECTURE.md §4.3). Both masks need `n_states`
    /// entries and the cost must be finite.
    pub fn set_transition_cost(&mut self, cost: Option<TransitionCost>) -> Result<(), AgentError> {
        if let Some(t) = &cost {
            for (what, len) in [
                ("transition cost from", t.from.len()),
                ("transition cost to", t.to.len()),
            ] {
                if len != self.n_states() {
                    return Err(AgentError::SizeMismatch {
                        what: what.into(),
                        expected: self.n_states(),
                        found: len,
                    });
                }
            }
            if !t.cost.is_finite() {
                return Err(ParamError::new("transition cost", t.cost, "finite").into());
            }
        }
        self.gm.transition_cost.clone_from(&cost);
        self.gm_plan.transition_cost = cost;
        Ok(())
    }

    /// Set the initial state prior `D` (must have `n_states` non-negative entries summing to 1);
    /// the Dirichlet counts behind `D` keep their total mass.
    pub fn set_d(&mut self, d: &[f64]) -> Result<(), AgentError> {
        if d.len() != self.n_states() {
            return Err(AgentError::SizeMismatch {
                what: "D".into(),
                expected: self.n_states(),
                found: d.len(),
            });
        }
        if d.iter().any(|x| x.is_nan() || *x < 0.0) || (d.iter().sum::<f64>() - 1.0).abs() > 1e-9 {
            return Err(ParamError::new("d", format!("{d:?}"), "non-negative and summing to 1").into());
        }
        let mass = self.d_counts.iter().sum::<f64>().max(1.0);
        self.d_counts = d.iter().map(|x| x * mass).collect();
        self.gm.d = d.to_vec();
        Ok(())
    }

    /// Count `s` as an initial state (D's Dirichlet counts, §V applied to `D`); takes
    /// effect at the next [`WorldModel::materialize`]. Out-of-range `s` is ignored.
    pub fn observe_initial(&mut self, s: usize) {
        if let Some(c) = self.d_counts.get_mut(s) {
            *c += 1.0;
        }
    }

    /// Posterior-mean probability `p(child' = child_value | parents = parent_values, u)`, the
    /// one `B` is built from (pooled rows included)
    /// of factor `factor` (parent values in the factor's parent order; `action` is used
    /// only if the action is a parent). E.g. `P(p'=1 | p, L'=1, d'=2)` (§VI Fig. 9).
    /// Returns NaN for out-of-range arguments.
    pub fn cpt_prob(&self, factor: usize, child_value: usize, parent_values: &[usize], action: Option<usize>) -> f64 {
        let Some(fac) = self.structure.factors().get(factor) else {
            return f64::NAN;
        };
        if child_value >= fac.size
            || parent_values.len() != fac.parents.len()
            || action.is_some_and(|a| a >= self.n_actions)
        {
            return f64::NAN;
        }
        let cfg = self
            .structure
            .config_from_parent_values(factor, parent_values, action, self.n_actions);
        let pooled = match &self.pooling {
            Some(pool) if pool.factor == factor => {
                Some(pool.pooled(&self.cpt[factor], fac.size, self.priors.transition_concentration))
            }
            _ => None,
        };
        let counts = pooled.as_deref().unwrap_or(&self.cpt[factor]);
        let row = &counts[cfg * fac.size..(cfg + 1) * fac.size];
        let z: f64 = row.iter().sum();
        if z > 0.0 {
            row[child_value] / z
        } else {
            1.0 / fac.size as f64
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn b_is_column_stochastic_and_learns() {
        let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
        let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
        for u in 0..3 {
            for s in 0..64 {
                let z: f64 = w.b(u).column(s).sum();
                assert!((z - 1.0).abs() < 1e-12);
            }
        }
        let s = st.encode(&[2, 1, 1, 0]);
        let s2 = st.encode(&[1, 2, 1, 0]);
        for _ in 0..100 {
            w.observe_transition(s, 1, s2);
        }
        w.materialize();
        assert!(w.b(1)[(s2, s)] > 0.8);
        // p' | p=0, L'=1, d'=1: 101 counts on p'=0 out of 102.
        assert!((w.cpt_prob(3, 0, &[0, 1, 1], None) - 101.0 / 102.0).abs() < 1e-12);
        assert_eq!(w.a(), &DMatrix::identity(64, 64));
        assert!(w.generative().a_identity);
    }

    #[test]
    fn persistence_pooling_by_hand() {
        let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
        let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
        // A pedestrian on green stays twice at d' = 2 and leaves once at d' = 1.
        let at = |d, p| st.encode(&[d, 1, 1, p]);
        w.observe_transition(at(2, 1), 0, at(2, 1));
        w.observe_transition(at(2, 1), 0, at(2, 1));
        w.observe_transition(at(2, 1), 0, at(1, 0));
        w.materialize();
        let stay = |w: &WorldModel, l, d| w.cpt_prob(3, 1, &[1, l, d], None);
        // The paper's CPT: each distance learns alone (prior 1 per cell).
        assert!((stay(&w, 1, 2) - 3.0 / 4.0).abs() < 1e-12);
        assert!((stay(&w, 1, 1) - 1.0 / 3.0).abs() < 1e-12);
        assert!((stay(&w, 1, 3) - 0.5).abs() < 1e-12);
        let counts = w.cpt_counts(3).to_vec();
        w.set_persistence_pooling(Some(("p", "d"))).unwrap();
        // Pooled over d': 2 stays and 1 leave, prior once: 3/5 at every distance under green.
        for d in 0..4 {
            assert!((stay(&w, 1, d) - 0.6).abs() < 1e-12, "d = {d}: {}", stay(&w, 1, d));
            // Red and appearance rows keep their own (prior-only) counts.
            assert!((stay(&w, 0, d) - 0.5).abs() < 1e-12);
            assert!((w.cpt_prob(3, 1, &[0, 1, d], None) - 0.5).abs() < 1e-12);
        }
        // B predicts with the pooled probabilities and stays column-stochastic; the
        // counts (what the gate and agent files read) are unchanged.
        let (from, to) = (at(2, 1), st.encode(&[1, 1, 1, 1]));
        let d_prob = w.cpt_prob(0, 1, &[2, 1], None);
        assert!(
            (w.b(0)[(to, from)] - d_prob * w.cpt_prob(1, 1, &[1], Some(0)) * w.cpt_prob(2, 1, &[1], None) * 0.6).abs()
                < 1e-12
        );
        for u in 0..3 {
            for s in 0..64 {
                assert!((w.b(u).column(s).sum() - 1.0).abs() < 1e-12);
            }
        }
        assert_eq!(w.cpt_counts(3), &counts[..]);
        // Pooled over d' and L': a pedestrian on red stays three more times at d' = 3, so
        // every persistence row shares 5 stays and 1 leave: (1 + 5) / (2 + 6) = 3/4 under
        // either light at every distance; appearance rows still keep their own counts.
        let red = |d, p| st.encode(&[d, 1, 0, p]);
        for _ in 0..3 {
            w.observe_transition(red(3, 1), 0, red(3, 1));
        }
        w.set_persistence_pooling(Some(("p", "d+L"))).unwrap();
        for (l, d) in (0..2).flat_map(|l| (0..4).map(move |d| (l, d))) {
            assert!(
                (stay(&w, l, d) - 0.75).abs() < 1e-12,
                "L = {l}, d = {d}: {}",
                stay(&w, l, d)
            );
            assert!((w.cpt_prob(3, 1, &[0, l, d], None) - 0.5).abs() < 1e-12);
        }
        w.set_persistence_pooling(None).unwrap();
        assert!((stay(&w, 1, 1) - 1.0 / 3.0).abs() < 1e-12);
        assert!((stay(&w, 0, 3) - 4.0 / 5.0).abs() < 1e-12);
    }

    #[test]
    fn persistence_pooling_names_are_checked() {
        let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
        let mut w = WorldModel::new(st, 3, &ModelPriors::default()).unwrap();
        for (factor, over) in [
            ("q", "d"),
            ("p", "x"),
            ("p", "p"),
            ("L", "d"),
            ("p", "d+x"),
            ("p", "d+"),
        ] {
            let e = w.set_persistence_pooling(Some((factor, over))).unwrap_err();
            assert!(matches!(e, AgentError::Structure(_)), "{factor}/{over}: {e}");
        }
    }
}
