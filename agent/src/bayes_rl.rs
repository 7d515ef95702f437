//! The Bayesian-RL baseline (§VI): a Dirichlet posterior over joint transitions (flat,
//! or the factored model as an ablation), a learned mean reward, and planning on every
//! tick on the posterior-mean MDP (value iteration warm-started from the last values,
//! or finite-horizon lookahead). Terminal transitions lead to an absorbing state of value 0.

use crate::controller::{Controller, Decision, Ending, one_hot};
use crate::error::{AgentError, FieldError, ParamError};
use crate::limits::{MAX_ACTIONS, MAX_STATES};
use crate::maths::argmax;
use crate::model::WorldModel;
use crate::params::{BayesModel, BayesRlParams, ModelPriors, Planner};
use crate::stored_values;
use serde::{Deserialize, Serialize};

/// Model-based Bayesian RL. Reading one (serde) checks every stored value (see
/// [`BayesRl::try_from`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "BayesRlRepr")]
pub struct BayesRl {
    n_states: usize,
    n_actions: usize,
    params: BayesRlParams,
    /// Successor counts `[(s * A + a) * N + s']` (non-terminal transitions).
    counts: Vec<f64>,
    /// Terminal-transition counts `[s * A + a]`.
    terminal: Vec<f64>,
    /// Visits `[s * A + a]` (all transitions).
    visits: Vec<f64>,
    /// Reward sums `[s * A + a]`.
    reward_sum: Vec<f64>,
    /// The factored model, if `params.model` is `Factored`.
    factored: Option<WorldModel>,
    #[serde(skip)]
    cache: Option<Cache>,
    #[serde(skip)]
    last: Option<(usize, usize)>,
}

/// The stored fields of a [`BayesRl`], before they are checked.
#[derive(Deserialize)]
#[serde(deny_unknown_fields, rename = "BayesRl")]
struct BayesRlRepr {
    n_states: usize,
    n_actions: usize,
    params: BayesRlParams,
    counts: Vec<f64>,
    terminal: Vec<f64>,
    visits: Vec<f64>,
    reward_sum: Vec<f64>,
    factored: Option<WorldModel>,
}

impl TryFrom<BayesRlRepr> for BayesRl {
    type Error = FieldError;
    /// Sizes in range; parameters valid; `counts` of `n_states * n_actions * n_states`
    /// and `terminal`, `visits`, `reward_sum` of `n_states * n_actions` entries; counts
    /// finite and >= 0, reward sums finite; each pair's visits equal to its terminal
    /// count plus its successor counts (else the posterior-mean rows do not sum to 1 and
    /// planning diverges); a factored model exactly when the parameters ask for one, of
    /// the same sizes.
    fn try_from(r: BayesRlRepr) -> Result<Self, FieldError> {
        stored_values::state_action_sizes(r.n_states, r.n_actions)?;
        r.params.check().map_err(|e| FieldError::from(e).within("params"))?;
        for (name, x) in [
            ("params.prior_concentration", r.params.prior_concentration),
            ("params.reward_prior", r.params.reward_prior),
        ] {
            if !stored_values::bounded(x) {
                return Err(FieldError::new(
                    name,
                    format!("is {x}; must be at most {:e} in size", crate::limits::MAX_VALUE),
                ));
            }
        }
        let (n, na) = (r.n_states, r.n_actions);
        let sa = n * na;
        let why = format!("n_states x n_actions = {n} x {na}");
        stored_values::len("counts", r.counts.len(), sa * n, &format!("{why} x n_states"))?;
        stored_values::len("terminal", r.terminal.len(), sa, &why)?;
        stored_values::len("visits", r.visits.len(), sa, &why)?;
        stored_values::len("reward_sum", r.reward_sum.len(), sa, &why)?;
        stored_values::counts("counts", &r.counts)?;
        stored_values::counts("terminal", &r.terminal)?;
        stored_values::counts("visits", &r.visits)?;
        stored_values::finite("reward_sum", &r.reward_sum)?;
        for i in 0..sa {
            let seen = r.terminal[i] + r.counts[i * n..(i + 1) * n].iter().sum::<f64>();
            if (r.visits[i] - seen).abs() > 1e-9 * r.visits[i].max(1.0) {
                return Err(FieldError::new(
                    format!("visits[{i}]"),
                    format!(
                        "is {}, but state {} action {} has {seen} recorded outcomes (terminal plus successor counts); they must be equal",
                        r.visits[i],
                        i / na,
                        i % na
                    ),
                ));
            }
        }
        match (&r.params.model, &r.factored) {
            (BayesModel::Flat, None) => {}
            (BayesModel::Factored(st), Some(m)) => {
                if st != m.structure() || m.n_actions() != na {
                    return Err(FieldError::new(
                        "factored",
                        "its structure or actions differ from params.model's",
                    ));
                }
                if st.joint_size() != n {
                    return Err(FieldError::new(
                        "params.model",
                        format!(
                            "the factored structure has {} joint states, n_states is {n}",
                            st.joint_size()
                        ),
                    ));
                }
            }
            (BayesModel::Flat, Some(_)) => {
                return Err(FieldError::new("factored", "present, but params.model is Flat"));
            }
            (BayesModel::Factored(_), None) => {
                return Err(FieldError::new("factored", "missing, but params.model is Factored"));
            }
        }
        Ok(BayesRl {
            n_states: n,
            n_actions: na,
            params: r.params,
            counts: r.counts,
            terminal: r.terminal,
            visits: r.visits,
            reward_sum: r.reward_sum,
            factored: r.factored,
            cache: None,
            last: None,
        })
    }
}

#[derive(Debug, Clone, PartialEq)]
struct Cache {
    /// Posterior-mean transition to non-terminal successors `[(s * A + a) * N + s']`.
    p: Vec<f64>,
    r: Vec<f64>,
    v: Vec<f64>,
    qv: Vec<f64>,
    dirty: bool,
}

impl BayesRl {
    /// A posterior with prior counts only.
    pub fn new(n_states: usize, n_actions: usize, params: BayesRlParams) -> Result<BayesRl, AgentError> {
        params.check()?;
        if !(1..=MAX_STATES).contains(&n_states) {
            return Err(ParamError::new("n_states", n_states, "in 1..=1024 (see limits::MAX_STATES)").into());
        }
        if !(1..=MAX_ACTIONS).contains(&n_actions) {
            return Err(ParamError::new("n_actions", n_actions, "in 1..=16 (see limits::MAX_ACTIONS)").into());
        }
        let factored = match &params.model {
            BayesModel::Flat => None,
            BayesModel::Factored(st) => {
                if st.joint_size() != n_states {
                    return Err(AgentError::SizeMismatch {
                        what: "factored structure joint size".into(),
                        expected: n_states,
                        found: st.joint_size(),
                    });
                }
                let priors = ModelPriors {
                    transition_concentration: params.prior_concentration,
                    ..Default::default()
                };
                Some(WorldModel::new(st.clone(), n_actions, &priors)?)
            }
        };
        let sa = n_states * n_actions;
        Ok(BayesRl {
            n_states,
            n_actions,
            counts: vec![0.0; sa * n_states],
            terminal: vec![0.0; sa],
            visits: vec![0.0; sa],
            reward_sum: vec![0.0; sa],
            factored,
            params,
            cache: None,
            last: None,
        })
    }

    /// Parameters.
    pub fn params(&self) -> &BayesRlParams {
        &self.params
    }
    /// Number of states.
    pub fn n_states(&self) -> usize {
        self.n_states
    }
    /// Number of actions.
    pub fn n_actions(&self) -> usize {
        self.n_actions
    }

    /// Counts of transitions into the terminal (absorbing) state, `[s * A + a]`.
    pub fn terminal_counts(&self) -> &[f64] {
        &self.terminal
    }

    /// Update the Dirichlet counts and the running mean reward with one transition.
    /// A transition into a terminal state (`terminal`: goal or collision) goes to the
    /// absorbing state (value 0); a time-out is not terminal and is recorded as the
    /// transition to `s_next` it was.
    pub fn observe_transition(&mut self, s: usize, a: usize, r: f64, s_next: usize, terminal: bool) {
        let (n, na) = (self.n_states, self.n_actions);
        if s >= n || a >= na || s_next >= n {
            return;
        }
        let i = s * na + a;
        self.visits[i] += 1.0;
        self.reward_sum[i] += r;
        if terminal {
            self.terminal[i] += 1.0;
        } else {
            self.counts[i * n + s_next] += 1.0;
            if let Some(m) = self.factored.as_mut() {
                m.observe_transition(s, a, s_next);
            }
        }
        if let Some(c) = self.cache.as_mut() {
            c.dirty = true;
        }
    }

    /// Posterior-mean reward of `(s, a)` (the prior mean if unvisited).
    pub fn mean_reward(&self, s: usize, a: usize) -> f64 {
        let i = s * self.n_actions + a;
        if self.visits[i] > 0.0 {
            self.reward_sum[i] / self.visits[i]
        } else {
            self.params.reward_prior
        }
    }

    fn rebuild(&mut self) {
        let (n, na) = (self.n_states, self.n_actions);
        let prior = self.params.prior_concentration;
        // The factored model's transition means only (not the active-inference agent's
        // whole generative model, whose logarithms cost four times as much).
        let factored_b = self.factored.as_ref().map(WorldModel::transition_matrices);
        let cache = self.cache.get_or_insert_with(|| Cache {
            p: vec![0.0; n * na * n],
            r: vec![0.0; n * na],
            v: vec![0.0; n],
            qv: vec![0.0; n * na],
            dirty: true,
        });
        for s in 0..n {
            for a in 0..na {
                let i = s * na + a;
                let total = self.visits[i] + prior * n as f64;
                let row = &mut cache.p[i * n..(i + 1) * n];
                if total <= 0.0 {
                    row.iter_mut().for_each(|x| *x = 1.0 / n as f64);
                } else if let Some(b) = &factored_b {
                    let keep = (total - self.terminal[i]) / total;
                    let col = &b[a].as_slice()[s * n..(s + 1) * n];
                    for (x, b) in row.iter_mut().zip(col) {
                        *x = keep * b;
                    }
                } else {
                    for (x, c) in row.iter_mut().zip(&self.counts[i * n..(i + 1) * n]) {
                        *x = (c + prior) / total;
                    }
                }
                cache.r[i] = if self.visits[i] > 0.0 {
                    self.reward_sum[i] / self.visits[i]
                } else {
                    self.params.reward_prior
                };
            }
        }
        cache.dirty = false;
    }

    /// Plan on the posterior-mean MDP (value iteration or lookahead) and return `Q(s, ·)`.
    pub fn plan(&mut self, s: usize) -> &[f64] {
        if self.cache.as_ref().is_none_or(|c| c.dirty) {
            self.rebuild();
        }
        let (n, na) = (self.n_states, self.n_actions);
        let gamma = self.params.discount;
        let planner = self.params.planner.clone();
        let Some(c) = self.cache.as_mut() else {
            unreachable!("cache built above")
        };
        let mut ev = vec![0.0; na];
        let mut sweep = |c: &mut Cache| -> f64 {
            let mut delta: f64 = 0.0;
            for s in 0..n {
                expected_values(&c.p[s * na * n..(s + 1) * na * n], n, &c.v, &mut ev);
                let mut best = f64::NEG_INFINITY;
                for (a, e) in ev.iter().enumerate() {
                    let i = s * na + a;
                    let q = c.r[i] + gamma * e;
                    c.qv[i] = q;
                    best = best.max(q);
                }
                delta = delta.max((best - c.v[s]).abs());
                c.v[s] = best;
            }
            delta
        };
        match planner {
            Planner::ValueIteration { iterations, tol } => {
                for _ in 0..iterations {
                    if sweep(c) < tol {
                        break;
                    }
                }
            }
            Planner::Lookahead { horizon } => {
                c.v.iter_mut().for_each(|v| *v = 0.0);
                for _ in 0..horizon {
                    // Synchronous backward induction: compute from a snapshot of V.
                    let v_old = c.v.clone();
                    for s in 0..n {
                        expected_values(&c.p[s * na * n..(s + 1) * na * n], n, &v_old, &mut ev);
                        let mut best = f64::NEG_INFINITY;
                        for (a, e) in ev.iter().enumerate() {
                            let i = s * na + a;
                            c.qv[i] = c.r[i] + gamma * e;
                            best = best.max(c.qv[i]);
                        }
                        c.v[s] = best;
                    }
                }
            }
        }
        &c.qv[s * na..(s + 1) * na]
    }
}

/// `ev[a] = Σ_{s'} rows[a * n + s'] v[s']` for every action's row of one state: each sum
/// runs in `s'` order exactly as a serial sum would (from `-0.0`), but the actions' sums
/// advance together, so they do not wait on each other.
fn expected_values(rows: &[f64], n: usize, v: &[f64], ev: &mut [f64]) {
    ev.iter_mut().for_each(|e| *e = -0.0);
    if let [e0, e1, e2] = ev {
        let (r0, rest) = rows.split_at(n);
        let (r1, r2) = rest.split_at(n);
        for (((p0, p1), p2), x) in r0.iter().zip(r1).zip(r2).zip(v) {
            *e0 += p0 * x;
            *e1 += p1 * x;
            *e2 += p2 * x;
        }
    } else {
        for (e, row) in ev.iter_mut().zip(rows.chunks_exact(n)) {
            *e = row.iter().zip(v).map(|(p, x)| p * x).sum();
        }
    }
}

impl Controller for BayesRl {
    fn name(&self) -> &'static str {
        "bayes-rl"
    }
    fn begin_episode(&mut self, _seed: u64) {
        self.last = None;
    }
    /// Plans on every tick (inference rate 100%), then acts greedily (ties: lowest index).
    fn act(&mut self, obs: usize) -> Decision {
        let obs = obs.min(self.n_states - 1);
        let action = argmax(self.plan(obs));
        self.last = Some((obs, action));
        Decision {
            action,
            reasoned: true,
            policy: one_hot(self.n_actions, action),
            ..Default::default()
        }
    }
    fn observe(&mut self, reward: f64, next_obs: usize, ending: Ending) {
        if self.params.learn_online
            && let Some((s, a)) = self.last
        {
            self.observe_transition(s, a, reward, next_obs, ending.is_terminal());
        }
    }
}
