//! The surprise gate on the state (§VI "surprise measured from the state space", Fig. 9a-b;
//! docs/ARCHITECTURE.md §4.4): how likely the habit finds the watched factor's value
//! given the factors it depends on, `P(x | parents)`, e.g. `P(p | L, d)`, a pedestrian
//! given light and distance.
//!
//! `S_t = -ln Σ_s q_t(s) P(x(s) | parents(s))`, which for a one-hot belief is
//! `-ln P(x_t | parents_t)`: the paper's Fig. 9a (1.95 -> 0.2 bits) is `-log2` of its
//! Fig. 9b (`P(p=1 | L=1, d=2)`: 0.25 -> 0.9). Unlike the one-step surprise of the joint
//! transition ([`crate::surprise`]), it does not fire on the car's own bin crossings, and
//! it stays high for as long as the unforeseen state lasts (a pedestrian on the crosswalk
//! under a green light), however predictable the pedestrian's persistence has become.
//!
//! The table's counts come from the watched factor's CPT in the world model (its counts
//! summed over every parent that is not a next-time parent, i.e. the occupancy counts of
//! `(parents', x')`), less the CPT's prior. Test-time learning (§V) adds the posteriors'
//! expected counts. Each row keeps a **bounded memory**: its data counts are rescaled to
//! at most `memory` ticks (exponential forgetting), so that 6000 training episodes do not
//! make a never-seen event cost hundreds of episodes to become familiar (measured: with
//! unbounded counts, 50 learning episodes move the jaywalk surprise 12.6 -> 5.3 bits).
//!
//! Beyond the paper, the gate also keeps, per joint state, how often reasoning there
//! endorsed the habit, and offers the surprise in excess of the surprise expected in
//! such states ([`StateGate::excess_surprise`]): once the habit has been shown to do
//! what reasoning would, the ordinary uncertainty of the situation (is a pedestrian
//! there or not?) no longer triggers reasoning; only surprise beyond it does.

use crate::error::AgentError;
use crate::error::ParamError;
use crate::maths::ln;
use crate::model::WorldModel;
use crate::structure::Parent;

/// `P(x | parents)` of one watched factor, with Dirichlet counts of bounded memory.
#[derive(Debug, Clone, PartialEq)]
pub struct StateGate {
    /// The watched factor's conditioning factors (its next-time parents in the world model), in parent order.
    given: Vec<usize>,
    /// Their sizes.
    given_sizes: Vec<usize>,
    /// Number of values of the watched factor.
    size: usize,
    /// Prior count per cell.
    prior: f64,
    /// Largest data mass a row keeps.
    memory: f64,
    /// Data counts `[row * size + value]`.
    data: Vec<f64>,
    /// Per joint state: its row and the watched factor's value.
    row_of: Vec<usize>,
    value_of: Vec<usize>,
    /// Per joint state: `P(x(s) | parents(s))`, refreshed after learning.
    prob: Vec<f64>,
    /// Per joint state: `P(x(s) | parents(s))` as the table stood when the gate was built
    /// (before any test-time learning): what the trained agent's trigger reads.
    trained: Vec<f64>,
    /// Per joint state: how often reasoning has endorsed the habit there (at most `memory`).
    endorsed: Vec<f64>,
    /// Per joint state: the surprise expected there, `min(1, endorsed / memory) · H(row)`.
    expected: Vec<f64>,
}

impl StateGate {
    /// The gate on factor `name` of `model`, conditioned on that factor's next-time parents,
    /// with counts taken from its CPT and a row memory of `memory` ticks (`inf` = unbounded).
    pub fn from_model(model: &WorldModel, name: &str, memory: f64) -> Result<StateGate, AgentError> {
        if memory.is_nan() || memory <= 0.0 {
            return Err(ParamError::new("gate_memory", memory, "> 0 (inf for unbounded)").into());
        }
        let st = model.structure();
        let factors = st.factors();
        let factor = factors.iter().position(|f| f.name == name).ok_or_else(|| {
            let names: Vec<&str> = factors.iter().map(|f| f.name.as_str()).collect();
            AgentError::Structure(format!(
                "the surprise gate watches factor `{name}`, which is not one of {names:?}"
            ))
        })?;
        let fac = &factors[factor];
        let given: Vec<usize> = fac
            .parents
            .iter()
            .filter_map(|p| if let Parent::Next(g) = p { Some(*g) } else { None })
            .collect();
        let size = fac.size;
        let n_rows: usize = given.iter().map(|g| factors[*g].size).product();
        let row = |vals: &[usize]| given.iter().fold(0, |r, g| r * factors[*g].size + vals[*g]);

        // Sum the CPT's data counts over every parent configuration: mixed radix over the
        // parents (in parent order), then the action if it is a parent.
        let parent_sizes = st.parent_sizes(factor);
        let n_actions = model.n_actions();
        let actions = if fac.action_parent { n_actions } else { 1 };
        let b0 = model.priors().transition_concentration;
        let counts = model.cpt_counts(factor);
        let mut data = vec![0.0; n_rows * size];
        let mut pv = vec![0; parent_sizes.len()];
        let mut vals = vec![0; factors.len()];
        for cfg in 0..parent_sizes.iter().product::<usize>() {
            let mut rest = cfg;
            for k in (0..pv.len()).rev() {
                pv[k] = rest % parent_sizes[k];
                rest /= parent_sizes[k];
            }
            for (p, v) in fac.parents.iter().zip(&pv) {
                if let Parent::Next(g) = p {
                    vals[*g] = *v;
                }
            }
            let r = row(&vals);
            for u in 0..actions {
                let c = st.config_from_parent_values(factor, &pv, Some(u), n_actions) * size;
                for x in 0..size {
                    data[r * size + x] += (counts[c + x] - b0).max(0.0);
                }
            }
        }
        let n = st.joint_size();
        let (mut row_of, mut value_of) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for s in 0..n {
            st.decode_into(s, &mut vals);
            row_of.push(row(&vals));
            value_of.push(vals[factor]);
        }
        let mut gate = StateGate {
            given_sizes: given.iter().map(|g| factors[*g].size).collect(),
            given,
            size,
            prior: b0.max(f64::MIN_POSITIVE),
            memory,
            data,
            row_of,
            value_of,
            prob: vec![0.0; n],
            trained: Vec::new(),
            endorsed: vec![0.0; n],
            expected: vec![0.0; n],
        };
        gate.consolidate();
        gate.trained.clone_from(&gate.prob);
        Ok(gate)
    }

    /// The conditioning factors' indices.
    pub fn given(&self) -> &[usize] {
        &self.given
    }

    /// `Σ_s q(s) P(x(s) | parents(s))`: the probability the habit gives the state under belief `q`.
    pub fn evidence(&self, q: &[f64]) -> f64 {
        expectation(q, &self.prob)
    }

    /// Number of cells `(x | parents)` of the table.
    pub fn n_cells(&self) -> usize {
        self.data.len()
    }

    /// The cell `(x(s) | parents(s))` joint state `s` falls in.
    pub fn cell_of(&self, s: usize) -> usize {
        self.row_of[s] * self.size + self.value_of[s]
    }

    /// The gate's surprise in nats, `-ln Σ_s q(s) P(x(s) | parents(s))` (§VI, Fig. 9a).
    pub fn surprise(&self, q: &[f64]) -> f64 {
        -ln(self.evidence(q))
    }

    /// The surprise the trained agent's gate reads, `-ln Σ_s q(s) P_0(x(s) | parents(s))`
    /// with `P_0` the table as it stood when the gate was built, before any test-time
    /// learning. Where it exceeds the trigger but [`StateGate::surprise`] (or its excess)
    /// no longer does, test-time learning has made the situation familiar: that is the
    /// hand-back [`crate::handback`] checks.
    pub fn trained_surprise(&self, q: &[f64]) -> f64 {
        -ln(expectation(q, &self.trained))
    }

    /// The surprise in excess of what is expected where the habit has proven itself:
    /// `max(0, S - Σ_s q(s) c(s) H(row(s)))`, with `H(row)` the entropy of the state's row
    /// of the table (the surprise one expects there on average) and `c(s)` in [0, 1] the
    /// share of `memory` reasoning ticks in state `s` that endorsed the habit
    /// ([`StateGate::endorse`]). Where reasoning never endorsed the habit, it is `S`.
    ///
    /// Beyond the paper, whose trigger reads `S` itself: a row that is genuinely uncertain
    /// (a pedestrian at the crosswalk on green in half of the episodes) keeps `S` above
    /// the trigger for either outcome, so without this the agent reasons there forever,
    /// although its habit already does what reasoning would (EXPERIMENTS.md).
    pub fn excess_surprise(&self, q: &[f64], surprise: f64) -> f64 {
        (surprise - expectation(q, &self.expected)).max(0.0)
    }

    /// Records that on a reasoning tick in state `s`, reasoning's policy endorsed the
    /// habit's action by `endorsement` in [0, 1] (1: the habit's action is reasoning's
    /// choice). Takes effect at [`StateGate::consolidate`].
    pub fn endorse(&mut self, s: usize, endorsement: f64) {
        if let Some(e) = self.endorsed.get_mut(s) {
            *e = (*e + endorsement.clamp(0.0, 1.0)).min(self.memory);
        }
    }

    /// Sets state `s`'s endorsement as if `memory` reasoning ticks there had each endorsed
    /// the habit by `endorsement` in [0, 1] (the audit of a trained habit). Takes effect at
    /// [`StateGate::consolidate`]. With an unbounded memory no endorsement is ever full, and
    /// this does nothing.
    pub fn set_endorsed(&mut self, s: usize, endorsement: f64) {
        if let Some(e) = self.endorsed.get_mut(s)
            && self.memory.is_finite()
        {
            *e = endorsement.clamp(0.0, 1.0) * self.memory;
        }
    }

    /// Counts every state's row as endorsed by the data the habit was trained on
    /// (`gate_baseline = foreseen`): `c(s) = min(1, n(row(s)) / memory)`, with `n(row)` the
    /// row's data counts, where `c(s)` is not already higher. A row the training visited
    /// often then expects its own uncertainty (its entropy) from the first tick on; a row it
    /// never saw keeps the paper's trigger. Takes effect at [`StateGate::consolidate`].
    pub fn foresee(&mut self) {
        for s in 0..self.endorsed.len() {
            let row = self.row_of[s];
            let mass: f64 = self.data[row * self.size..(row + 1) * self.size].iter().sum();
            let e = &mut self.endorsed[s];
            *e = e.max(mass.min(self.memory));
        }
    }

    /// `P(x = value | given = given_values)` (given values in the order of [`StateGate::given`]),
    /// e.g. the paper's `P(p=1 | L=1, d=2)` (Fig. 9b). NaN when out of range.
    pub fn probability(&self, value: usize, given_values: &[usize]) -> f64 {
        if value >= self.size || given_values.len() != self.given.len() {
            return f64::NAN;
        }
        let mut r = 0;
        for (size, v) in self.given_sizes.iter().zip(given_values) {
            if v >= size {
                return f64::NAN;
            }
            r = r * size + v;
        }
        self.cell(r, value)
    }

    /// Adds the expected counts of one tick's posterior `q`, times `lr` (§V, applied to the
    /// gate's table). Call [`StateGate::consolidate`] at the end of the episode.
    pub fn learn(&mut self, q: &[f64], lr: f64) {
        for (s, w) in q.iter().enumerate() {
            if *w != 0.0 {
                self.data[self.row_of[s] * self.size + self.value_of[s]] += lr * w;
            }
        }
    }

    /// Applies the bounded memory (rows rescaled to at most `memory` data counts) and
    /// refreshes the per-state probabilities and expected surprises.
    pub fn consolidate(&mut self) {
        for row in self.data.chunks_mut(self.size) {
            let total: f64 = row.iter().sum();
            if total > self.memory {
                let k = self.memory / total;
                row.iter_mut().for_each(|c| *c *= k);
            }
        }
        for s in 0..self.prob.len() {
            let row = self.row_of[s];
            self.prob[s] = self.cell(row, self.value_of[s]);
            let entropy: f64 = (0..self.size)
                .map(|x| self.cell(row, x))
                .map(|p| if p > 0.0 { -p * ln(p) } else { 0.0 })
                .sum();
            self.expected[s] = entropy * (self.endorsed[s] / self.memory).min(1.0);
        }
    }

    fn cell(&self, row: usize, value: usize) -> f64 {
        let r = &self.data[row * self.size..(row + 1) * self.size];
        (self.prior + r[value]) / (self.size as f64 * self.prior + r.iter().sum::<f64>())
    }
}

/// `Σ_s q(s) x(s)` over the states the belief `q` gives weight to.
fn expectation(q: &[f64], x: &[f64]) -> f64 {
    q.iter().zip(x).filter(|(w, _)| **w != 0.0).map(|(w, v)| w * v).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ModelPriors;
    use crate::structure::Structure;

    fn model() -> WorldModel {
        let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
        WorldModel::new(st, 3, &ModelPriors::default()).unwrap()
    }

    /// A belief certain of joint state `s` (of the paper's 64).
    fn one_hot(s: usize) -> Vec<f64> {
        let mut q = vec![0.0; 64];
        q[s] = 1.0;
        q
    }

    #[test]
    fn hand_worked_counts_and_memory() {
        let mut w = model();
        let st = w.structure().clone();
        // 8 ticks ending at (d=2, L=1, p=0), 2 ending at (d=2, L=1, p=1), from various p.
        for k in 0..10 {
            let p_next = usize::from(k >= 8);
            w.observe_transition(st.encode(&[3, 2, 1, k % 2]), k % 3, st.encode(&[2, 2, 1, p_next]));
        }
        let unbounded = StateGate::from_model(&w, "p", f64::INFINITY).unwrap();
        assert_eq!(unbounded.given(), &[2, 0]);
        // (1 + 2) / (2 + 10), by hand.
        assert!((unbounded.probability(1, &[1, 2]) - 3.0 / 12.0).abs() < 1e-12);
        // An unvisited row is uniform.
        assert!((unbounded.probability(1, &[0, 3]) - 0.5).abs() < 1e-12);
        // Memory 5: data 8:2 rescaled to 4:1 -> (1 + 1) / (2 + 5).
        let mut bounded = StateGate::from_model(&w, "p", 5.0).unwrap();
        assert!((bounded.probability(1, &[1, 2]) - 2.0 / 7.0).abs() < 1e-12);
        // Learning three ticks at p = 1: 4:4 -> rescaled 2.5:2.5 -> (1 + 2.5) / 7 = 0.5.
        let q = one_hot(st.encode(&[2, 0, 1, 1]));
        for _ in 0..3 {
            bounded.learn(&q, 1.0);
        }
        bounded.consolidate();
        assert!((bounded.probability(1, &[1, 2]) - 0.5).abs() < 1e-12);
        assert!((bounded.surprise(&q) - 2f64.ln()).abs() < 1e-12);
        // The trained table is what the gate was built with: learning leaves it, (1 + 1) / 7.
        assert!((bounded.trained_surprise(&q) - (7.0f64 / 2.0).ln()).abs() < 1e-12);
    }

    #[test]
    fn probabilities_sum_to_one_and_unknown_factor_is_an_error() {
        let mut w = model();
        let st = w.structure().clone();
        w.observe_transition(st.encode(&[3, 2, 0, 0]), 1, st.encode(&[2, 2, 0, 1]));
        let g = StateGate::from_model(&w, "p", 20.0).unwrap();
        for l in 0..2 {
            for d in 0..4 {
                let total = g.probability(0, &[l, d]) + g.probability(1, &[l, d]);
                assert!((total - 1.0).abs() < 1e-12);
            }
        }
        assert!(StateGate::from_model(&w, "pedestrian", 20.0).is_err());
        assert!(StateGate::from_model(&w, "p", 0.0).is_err());
    }

    #[test]
    fn an_audited_endorsement_counts_as_a_full_memory_of_reasoning_ticks() {
        let mut w = model();
        let st = w.structure().clone();
        // Row (L=1, d=2) at P = 1/2 (H = ln 2), as in `excess_surprise_by_hand`.
        for k in 0..10 {
            w.observe_transition(st.encode(&[3, 2, 1, 0]), 1, st.encode(&[2, 2, 1, usize::from(k < 5)]));
        }
        let (s_fast, s_slow) = (st.encode(&[2, 3, 1, 1]), st.encode(&[2, 0, 1, 1]));
        let ln2 = 2f64.ln();
        let mut g = StateGate::from_model(&w, "p", 20.0).unwrap();
        g.set_endorsed(s_slow, 1.0);
        g.set_endorsed(s_fast, 0.25);
        g.consolidate();
        // Fully endorsed: the row's whole entropy is expected, nothing is in excess.
        assert!(g.excess_surprise(&one_hot(s_slow), ln2).abs() < 1e-12);
        // A quarter: a quarter of it.
        assert!((g.excess_surprise(&one_hot(s_fast), ln2) - 0.75 * ln2).abs() < 1e-12);
        // Setting replaces (an audit is not added to): 0.5 after 1 is half.
        g.set_endorsed(s_slow, 0.5);
        g.consolidate();
        assert!((g.excess_surprise(&one_hot(s_slow), ln2) - 0.5 * ln2).abs() < 1e-12);
        // With an unbounded memory nothing is ever fully endorsed: no effect.
        let mut unbounded = StateGate::from_model(&w, "p", f64::INFINITY).unwrap();
        unbounded.set_endorsed(s_slow, 1.0);
        unbounded.consolidate();
        assert!((unbounded.excess_surprise(&one_hot(s_slow), ln2) - ln2).abs() < 1e-12);
    }

    #[test]
    fn a_foreseen_row_expects_its_entropy_in_proportion_to_its_training_data() {
        let mut w = model();
        let st = w.structure().clone();
        // Row (L=1, d=2): 10 ticks at P = 1/2 (H = ln 2); row (L=0, d=2): 4 ticks at 1/2.
        for k in 0..10 {
            w.observe_transition(st.encode(&[3, 2, 1, 0]), 1, st.encode(&[2, 2, 1, usize::from(k < 5)]));
        }
        for k in 0..4 {
            w.observe_transition(st.encode(&[3, 2, 0, 0]), 1, st.encode(&[2, 2, 0, usize::from(k < 2)]));
        }
        let ln2 = 2f64.ln();
        let (full, part, unseen) = (
            st.encode(&[2, 0, 1, 1]),
            st.encode(&[2, 0, 0, 1]),
            st.encode(&[0, 0, 1, 1]),
        );
        // Memory 10: the first row's 10 ticks fill it, the second's 4 fill 0.4 of it, an
        // unvisited row (d=0 under green) has no data and keeps the whole surprise.
        let mut g = StateGate::from_model(&w, "p", 10.0).unwrap();
        g.foresee();
        g.consolidate();
        assert!(g.excess_surprise(&one_hot(full), ln2).abs() < 1e-12);
        assert!((g.excess_surprise(&one_hot(part), ln2) - 0.6 * ln2).abs() < 1e-12);
        assert!((g.excess_surprise(&one_hot(unseen), ln2) - ln2).abs() < 1e-12);
        // A state already endorsed further keeps its endorsement.
        let mut g = StateGate::from_model(&w, "p", 10.0).unwrap();
        g.set_endorsed(part, 1.0);
        g.foresee();
        g.consolidate();
        assert!(g.excess_surprise(&one_hot(part), ln2).abs() < 1e-12);
    }

    #[test]
    fn excess_surprise_by_hand() {
        let mut w = model();
        let st = w.structure().clone();
        // Row (L=1, d=2): 5 ticks with a pedestrian and 5 without, so P = 1/2 and H = ln 2.
        for k in 0..10 {
            w.observe_transition(st.encode(&[3, 2, 1, 0]), 1, st.encode(&[2, 2, 1, usize::from(k < 5)]));
        }
        let mut g = StateGate::from_model(&w, "p", 20.0).unwrap();
        let (s_fast, s_slow) = (st.encode(&[2, 3, 1, 1]), st.encode(&[2, 0, 1, 1]));
        let ln2 = 2f64.ln();
        let (q_fast, q_slow) = (one_hot(s_fast), one_hot(s_slow));
        assert!((g.surprise(&q_slow) - ln2).abs() < 1e-12);
        // Never endorsed: the excess is the surprise itself.
        assert!((g.excess_surprise(&q_slow, ln2) - ln2).abs() < 1e-12);
        // Ten full endorsements at v = 0 out of a memory of 20: half the entropy is expected there.
        for _ in 0..10 {
            g.endorse(s_slow, 1.0);
        }
        g.consolidate();
        assert!((g.excess_surprise(&q_slow, ln2) - 0.5 * ln2).abs() < 1e-12);
        // The same row at v = 3, where reasoning never endorsed the habit, stays fully surprising.
        assert!((g.excess_surprise(&q_fast, ln2) - ln2).abs() < 1e-12);
        // Partial endorsements count in part; the count saturates at the memory.
        for _ in 0..40 {
            g.endorse(s_slow, 0.5);
        }
        g.consolidate();
        assert!(g.excess_surprise(&q_slow, ln2).abs() < 1e-12);
        // A spread belief mixes the two states' expectations.
        let mut q = vec![0.0; 64];
        q[s_slow] = 0.5;
        q[s_fast] = 0.5;
        assert!((g.excess_surprise(&q, ln2) - 0.5 * ln2).abs() < 1e-12);
    }
}

#[cfg(test)]
mod properties {
    use super::*;
    use crate::params::ModelPriors;
    use crate::structure::Structure;
    use proptest::prelude::*;

    proptest! {
        /// 0 <= excess surprise <= surprise, for any counts, endorsements and beliefs.
        #[test]
        fn excess_is_between_zero_and_the_surprise(
            ticks in proptest::collection::vec((0usize..64, 0usize..3, 0usize..64), 0..40),
            endorse in proptest::collection::vec((0usize..64, 0.0f64..1.0), 0..40),
            belief in proptest::collection::vec(0.0f64..1.0, 64),
        ) {
            let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
            let mut w = WorldModel::new(st, 3, &ModelPriors::default()).unwrap();
            for (s, u, s2) in ticks {
                w.observe_transition(s, u, s2);
            }
            let mut g = StateGate::from_model(&w, "p", 20.0).unwrap();
            for (s, e) in endorse {
                g.endorse(s, e);
            }
            g.consolidate();
            let z: f64 = belief.iter().sum();
            prop_assume!(z > 0.0);
            let q: Vec<f64> = belief.iter().map(|b| b / z).collect();
            let s = g.surprise(&q);
            let x = g.excess_surprise(&q, s);
            prop_assert!(s >= 0.0);
            prop_assert!((0.0..=s + 1e-12).contains(&x), "excess {} surprise {}", x, s);
        }
    }
}
