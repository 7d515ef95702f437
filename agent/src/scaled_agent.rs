//! The paper's agent (§II–§V): Q-learning's policy as the habitual `π_o`, surprise-
//! triggered reasoning (VMP perception, EFE planning, test-time scaling), and
//! test-time learning at the end of each episode.
//!
//! Feed-forward ticks (`θ_t <= ε`) are cheap: `q_t` by one exact Bayes step and the
//! action from `π_o(·|q_t)`; no VMP and no planning (§II footnote). Reasoning ticks:
//! VMP over the window -> `q_t`, EFE tree -> `ψ`, scaling `π_o(·|q_t)` -> `π'`, act.
//!
//! The trigger reads the surprise on the state ([`crate::gate`], §VI) by default, and
//! the one-step joint surprise ([`crate::surprise`]) as an ablation; by default it reads
//! the surprise in excess of what is expected in states where reasoning has endorsed the
//! habit ([`GateBaseline::Endorsed`], beyond the paper). `Decision::surprise` is always
//! the surprise itself, `Decision::theta` what the trigger compared with `ε`. Planning always
//! predicts with the full transition model, which keeps the pedestrian's persistence.

use crate::competence::Competence;
use crate::controller::{Controller, Decision, Dist, Ending};
use crate::error::AgentError;
use crate::gate::StateGate;
use crate::habit::{Habit, PolicyHabit, TableHabit};
use crate::handback::HandBack;
use crate::learning;
use crate::maths::argmax;
use crate::model::WorldModel;
use crate::params::{
    ActionSelection, CheckedScaledParams, CompetenceCheck, CompetenceRollout, CrashPlanning, GateBaseline,
    GateLearning, GateMode, HandBackRule, ReasoningMode, RootStep, ScaledParams, ScalingMode, TieBreak,
};
use crate::perception::{VmpWorkspace, vmp};
use crate::planning::{EfeTree, q_s_into};
use crate::q_learning::QLearning;
use crate::scaling::{scale_closed_form, scale_iterative};
use crate::surprise::{bayes_step, predict_into, surprise, theta};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// What the last reasoning tick computed (buffers reused between ticks).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ReasoningTrace {
    /// Free energy at the end of VMP (nats).
    pub free_energy: f64,
    /// VMP sweeps.
    pub vmp_iters: u32,
    /// `G(π)` per policy (lexicographic).
    pub g: Vec<f64>,
    /// `q(π)`.
    pub q_pi: Vec<f64>,
    /// `ψ(u)`.
    pub psi: Vec<f64>,
    /// `Q_S(u) = -(1/γ) ln ψ(u)`.
    pub q_s: Vec<f64>,
    /// `π_o(·|q_t)`.
    pub pi_o: Vec<f64>,
    /// `π'`.
    pub pi_scaled: Vec<f64>,
    /// `KL[π_o || ψ]`.
    pub kl_initial: f64,
    /// `KL[π' || ψ]`.
    pub kl_final: f64,
}

/// The scaled active-inference agent (docs/ARCHITECTURE.md §4, §5), with habit `H`
/// ([`crate::habit`]): the paper's Q-table habit by default, or an external policy.
#[derive(Debug, Clone)]
pub struct ScaledAgent<H: Habit = TableHabit> {
    model: WorldModel,
    params: CheckedScaledParams,
    n_states: usize,
    n_actions: usize,
    /// The habit `π_o` (§V-C).
    habit: H,
    /// The surprise gate on the state (`None` with [`GateMode::OneStep`]).
    gate: Option<StateGate>,
    /// The crash-risk check of hand-backs that learning made ([`crate::handback`]).
    handback: HandBack,
    /// The competence check of the habit where the gate leaves it in charge
    /// ([`crate::competence`]).
    competence: Competence,
    /// Whether test-time learning has changed the agent (an episode was learned from).
    learned: bool,
    rng: ChaCha8Rng,
    tree: EfeTree,
    vmp_ws: VmpWorkspace,
    s_hat: Vec<f64>,
    q_cur: Vec<f64>,
    pi: Vec<f64>,
    window_q: Vec<Vec<f64>>,
    window_obs: Vec<usize>,
    /// Episode history.
    hist_obs: Vec<usize>,
    hist_act: Vec<usize>,
    hist_q: Vec<f64>,
    /// The policy acted upon each tick (`π'` on reasoning ticks), `[t * n_actions + u]`.
    hist_pi: Vec<f64>,
    hist_surprise: Vec<f64>,
    hist_reasoned: Vec<bool>,
    /// Whether each tick reasoned because the hand-back check refused the habit.
    hist_refused: Vec<bool>,
    /// Whether each tick reasoned because the competence check found the habit's action
    /// wanting.
    hist_checked: Vec<bool>,
    /// Whether each tick's trigger fired only because of test-time learning and the habit
    /// acted, the check finding it safe.
    hist_declined: Vec<bool>,
    /// The competence check's scratch: one action per state, the held action's policy or
    /// the habit's.
    held_policy: Vec<usize>,
    /// The habit's policy in one state (`competence_rollout = feedback`).
    state_pi: Vec<f64>,
    /// This tick's `B[u] q_t` per action, `[u * n + s]` ([`ScaledAgent::predict_all`]), for
    /// [`ActionSelection::OutcomeMode`] and [`TieBreak::Safest`].
    next_pred: Vec<f64>,
    pred_scratch: Vec<f64>,
    final_obs: Option<usize>,
    /// One-hot index of the last posterior, if it was one-hot.
    prev_one_hot: Option<usize>,
    last: ReasoningTrace,
}

impl ScaledAgent<TableHabit> {
    /// Build the agent from a trained world model and Q-table: `ν = ν0 σ(Q[s,·]/T)` (docs/ARCHITECTURE.md §4.8).
    /// Checks `params` ([`ScaledParams::check`]) and builds the agent with
    /// [`ScaledAgent::with_checked`].
    pub fn new(model: WorldModel, q: &QLearning, params: ScaledParams) -> Result<ScaledAgent, AgentError> {
        ScaledAgent::with_checked(model, q, params.check()?)
    }

    /// Build the agent from checked parameters; first checks their factor names against
    /// the model ([`CheckedScaledParams::check_factors`]).
    pub fn with_checked(
        model: WorldModel,
        q: &QLearning,
        params: CheckedScaledParams,
    ) -> Result<ScaledAgent, AgentError> {
        let habit = TableHabit::from_q(
            q.table(),
            q.n_actions(),
            params.learning.nu0,
            params.learning.nu_temperature,
        );
        if q.n_states() != model.n_states() {
            return Err(AgentError::SizeMismatch {
                what: "Q-table states vs world-model states".into(),
                expected: model.n_states(),
                found: q.n_states(),
            });
        }
        if q.n_actions() != model.n_actions() {
            return Err(AgentError::SizeMismatch {
                what: "Q-table actions vs world-model actions".into(),
                expected: model.n_actions(),
                found: q.n_actions(),
            });
        }
        ScaledAgent::with_habit(model, habit, params)
    }

    /// Policy counts `ν`, `[s * n_actions + u]` (§V-C).
    pub fn nu(&self) -> &[f64] {
        self.habit.nu()
    }
    /// `π_o(·|s)` (Dirichlet mean of `ν`, §V-C).
    pub fn pi_o(&self, s: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.n_actions];
        self.habit.pi_o_state(0, s, &mut out);
        out
    }
}

impl ScaledAgent<PolicyHabit> {
    /// Decides on `obs` with the external policy's probabilities `probs` at this tick's
    /// observation as the habit's (the scaled agent as a test-time safety layer around any
    /// policy, [`crate::habit`]). Refuses probabilities of the wrong length, negative, not
    /// finite or not summing to 1.
    pub fn act_with(&mut self, obs: usize, probs: &[f64]) -> Result<Decision, AgentError> {
        // The habit keeps one entry per tick of the episode: a tick decided without
        // probabilities (Controller::act) is filled with uniform ones first.
        while self.habit.ticks() < self.hist_obs.len() {
            let uniform = vec![1.0 / self.n_actions as f64; self.n_actions];
            self.habit.push(&uniform)?;
        }
        self.habit.push(probs)?;
        Ok(self.act(obs))
    }
}

impl<H: Habit> ScaledAgent<H> {
    /// Build the agent around `habit` from checked parameters; first checks their factor
    /// names against the model ([`CheckedScaledParams::check_factors`]) and the habit's
    /// sizes against the model's.
    pub fn with_habit(
        mut model: WorldModel,
        habit: H,
        params: CheckedScaledParams,
    ) -> Result<ScaledAgent<H>, AgentError> {
        params.check_factors(model.structure())?;
        let pooling = (!params.planning.persistence_ignores.is_empty()).then_some((
            params.gate.gate_factor.as_str(),
            params.planning.persistence_ignores.as_str(),
        ));
        model.set_persistence_pooling(pooling)?;
        model.plan_with_crash_model(params.planning.crash_model == CrashPlanning::Hazard);
        let n = model.n_states();
        let na = model.n_actions();
        if crate::limits::policies(na, params.planning.horizon).is_none() {
            return Err(crate::error::ParamError::new(
                "horizon",
                params.planning.horizon,
                "such that n_actions ^ horizon <= 65536 (limits::MAX_POLICIES)",
            )
            .into());
        }
        if habit.n_states() != n {
            return Err(AgentError::SizeMismatch {
                what: "habit states vs world-model states".into(),
                expected: n,
                found: habit.n_states(),
            });
        }
        if habit.n_actions() != na {
            return Err(AgentError::SizeMismatch {
                what: "habit actions vs world-model actions".into(),
                expected: na,
                found: habit.n_actions(),
            });
        }
        let gate = match params.gate.mode {
            GateMode::State => Some(StateGate::from_model(
                &model,
                &params.gate.gate_factor,
                params.gate.gate_memory,
            )?),
            GateMode::OneStep => None,
        };
        let n_obs = model.generative().n_obs();
        let handback = HandBack::new(&model);
        let mut agent = ScaledAgent {
            tree: EfeTree::new(n, n_obs, na, params.planning.horizon),
            window_q: vec![vec![0.0; n]; params.perception.vmp_window],
            window_obs: Vec::with_capacity(params.perception.vmp_window),
            rng: ChaCha8Rng::seed_from_u64(0),
            vmp_ws: VmpWorkspace::default(),
            s_hat: vec![0.0; n],
            q_cur: vec![0.0; n],
            pi: vec![0.0; na],
            hist_obs: Vec::with_capacity(256),
            hist_act: Vec::with_capacity(256),
            hist_q: Vec::with_capacity(256 * n),
            hist_pi: Vec::with_capacity(256 * na),
            hist_surprise: Vec::with_capacity(256),
            hist_reasoned: Vec::with_capacity(256),
            hist_refused: Vec::with_capacity(256),
            hist_checked: Vec::with_capacity(256),
            hist_declined: Vec::with_capacity(256),
            held_policy: vec![0; n],
            state_pi: vec![0.0; na],
            next_pred: vec![0.0; n * na],
            pred_scratch: Vec::new(),
            final_obs: None,
            prev_one_hot: None,
            last: ReasoningTrace::default(),
            model,
            params,
            n_states: n,
            n_actions: na,
            habit,
            gate,
            handback,
            competence: Competence::new(n, n_obs, na),
            learned: false,
        };
        match agent.params.gate.gate_baseline {
            GateBaseline::Audited => agent.audit_habit(),
            GateBaseline::Foreseen => {
                if let Some(gate) = &mut agent.gate {
                    gate.foresee();
                    gate.consolidate();
                }
            }
            GateBaseline::Endorsed | GateBaseline::None => {}
        }
        Ok(agent)
    }

    /// Audits the habit in every state (`gate_baseline = audited`): in each state `s`, from
    /// a certain belief there, plans (Prop. 1) and scales the habit's policy by the trained
    /// trigger's `θ(s)` (Theorem 1), as a reasoning tick there would, and records in the
    /// gate how far that policy endorses the habit's action, as if `memory` reasoning ticks
    /// in `s` had ([`StateGate::set_endorsed`]). One planning per state.
    pub fn audit_habit(&mut self) {
        let Some(gate) = &self.gate else { return };
        let n = self.n_states;
        let mut q = vec![0.0; n];
        let trained: Vec<f64> = (0..n)
            .map(|s| {
                q.fill(0.0);
                q[s] = 1.0;
                gate.trained_surprise(&q)
            })
            .collect();
        let mut endorsed = Vec::with_capacity(n);
        for (s, surprise) in trained.into_iter().enumerate() {
            q.fill(0.0);
            q[s] = 1.0;
            let th = theta(surprise, self.params.gate.omega);
            let root = match self.params.planning.root_step {
                RootStep::Learned => self.model.generative(),
                RootStep::Absorbing => self.model.planning_generative(),
            };
            self.tree
                .evaluate(self.model.planning_generative(), root, &q, self.params.planning.gamma);
            self.habit.pi_o_belief(0, &q, &mut self.pi);
            let habit = argmax(&self.pi);
            self.scale(th);
            endorsed.push(endorsement(&self.pi, habit));
        }
        if let Some(gate) = &mut self.gate {
            for (s, e) in endorsed.into_iter().enumerate() {
                gate.set_endorsed(s, e);
            }
            gate.consolidate();
        }
        self.tree.invalidate();
        self.last = ReasoningTrace::default();
    }

    /// Whether the trained agent's trigger would reason under belief `q_t`
    /// ([`StateGate::trained_surprise`]): a tick that now hands back although this holds is a
    /// hand-back test-time learning made. With the one-step gate, which keeps no trained
    /// table, every tick after the first learned episode counts as one.
    fn trained_trigger_fires(&self) -> Option<f64> {
        let th0 = match &self.gate {
            Some(gate) => theta(gate.trained_surprise(&self.q_cur), self.params.gate.omega),
            None if self.learned => 1.0,
            None => 0.0,
        };
        (th0 > self.params.gate.epsilon).then_some(th0)
    }

    /// The crash-risk check of the habit ([`crate::handback`]), with the habit's policy in
    /// `self.pi`: whether holding the habit's action for `handback_horizon` ticks is
    /// predicted, under the learned model, to enter a crash-risk state more likely, by more
    /// than `handback_risk`, than holding the safest action would.
    fn habit_at_risk(&mut self) -> bool {
        let own = self.held_crash_risk(argmax(&self.pi));
        let safest = (0..self.n_actions)
            .map(|u| self.held_crash_risk(u))
            .fold(f64::INFINITY, f64::min);
        own - safest > self.params.gate.handback_risk
    }

    /// The hand-back's crash risk ([`crate::handback`]) of holding `u` for
    /// `handback_horizon` ticks from belief `q_t`.
    fn held_crash_risk(&mut self, u: usize) -> f64 {
        let root = match self.params.planning.root_step {
            RootStep::Learned => self.model.generative(),
            RootStep::Absorbing => self.model.planning_generative(),
        };
        let plan = self.model.planning_generative();
        self.held_policy.fill(u);
        let horizon = self.params.gate.handback_horizon;
        self.handback
            .crash_risk(root, plan, &self.q_cur, u, &self.held_policy, horizon)
    }

    /// The hand-back check: on a tick that would hand control to the habit (whose policy is
    /// in `self.pi`), `Some(θ_0)` (the trained trigger's `θ`) when the hand-back is one that
    /// learning made and the habit is at risk ([`ScaledAgent::habit_at_risk`]).
    fn refuse_handback(&mut self) -> Option<f64> {
        if self.params.gate.handback == HandBackRule::Theta {
            return None;
        }
        let th0 = self.trained_trigger_fires()?;
        self.habit_at_risk().then_some(th0)
    }

    /// The competence check ([`crate::competence`]), with the habit's policy in `self.pi`
    /// and the gate's `θ` `th`: `Some(θ_c)` when holding the habit's action for
    /// `competence_horizon` ticks is predicted to be worse than holding the best action by
    /// more than `competence_regret` nats, and the best held action is not predicted to
    /// crash more often than the habit's by more than `handback_risk` (the check trades no
    /// safety for progress); the reasoning tick then scales with
    /// `θ_c = max(θ, 1 - exp(-Ω regret))`, the regret read as the trigger reads surprise.
    fn habit_wanting(&mut self, th: f64) -> Option<f64> {
        if self.params.gate.competence == CompetenceCheck::SurpriseOnly {
            return None;
        }
        let root = match self.params.planning.root_step {
            RootStep::Learned => self.model.generative(),
            RootStep::Absorbing => self.model.planning_generative(),
        };
        let plan = self.model.planning_generative();
        let obs_certain = self.q_cur.iter().position(|&x| x == 1.0);
        let habit = argmax(&self.pi);
        let horizon = self.params.gate.competence_horizon;
        let regret = self
            .competence
            .regret(plan, root, &self.q_cur, obs_certain, habit, horizon);
        if regret <= self.params.gate.competence_regret {
            return None;
        }
        let regret = match self.params.gate.competence_rollout {
            CompetenceRollout::Held => regret,
            CompetenceRollout::Feedback => {
                // The habit judged as it drives: its action now, then its own action in
                // each state it is predicted to reach.
                let t = self.hist_obs.len();
                for s in 0..self.held_policy.len() {
                    self.habit.pi_o_state(t, s, &mut self.state_pi);
                    self.held_policy[s] = argmax(&self.state_pi);
                }
                let commit = self.params.gate.competence_commit;
                let followed = self.competence.followed_efe(
                    plan,
                    root,
                    &self.q_cur,
                    (habit, &self.held_policy),
                    (commit, horizon),
                );
                let best = self.competence.held().iter().copied().fold(f64::INFINITY, f64::min);
                let regret = regret.min(followed - best);
                if regret <= self.params.gate.competence_regret {
                    return None;
                }
                regret
            }
        };
        // Never for a riskier action: where holding the preferred action is predicted to
        // crash more often than holding the habit's, by more than ρ within the hand-back's
        // horizon (crash_risk, as the hand-back checks), the habit keeps the tick.
        let held = self.competence.held();
        let best = (0..self.n_actions).fold(habit, |b, u| if held[u] < held[b] { u } else { b });
        let safer = self.held_crash_risk(best) - self.held_crash_risk(habit) <= self.params.gate.handback_risk;
        safer.then(|| th.max(theta(regret, self.params.gate.omega)))
    }

    /// The check of a reasoning tick that learning made: on a tick whose learned trigger
    /// fires, `true` when the trained agent's trigger would have handed back and the habit
    /// is not at risk ([`HandBackRule::RiskChecked`]) or whatever the risk
    /// ([`HandBackRule::DeclineLearned`]), so the habit acts. Leaves the habit's policy in
    /// `self.pi` when it returns `true`.
    fn decline_trigger(&mut self, obs: usize) -> bool {
        let checked = match self.params.gate.handback {
            HandBackRule::RiskChecked => true,
            HandBackRule::DeclineLearned => false,
            HandBackRule::HandBackChecked | HandBackRule::Theta => return false,
        };
        if !self.learned || self.trained_trigger_fires().is_some() {
            return false;
        }
        self.habit_policy(obs);
        !checked || !self.habit_at_risk()
    }

    /// The habit's policy `π_o` for this tick into `self.pi`.
    fn habit_policy(&mut self, obs: usize) {
        let t = self.hist_obs.len();
        if self.model.generative().a_identity {
            self.habit.pi_o_state(t, obs, &mut self.pi);
        } else {
            self.habit.pi_o_belief(t, &self.q_cur, &mut self.pi);
        }
    }

    /// The world model.
    pub fn model(&self) -> &WorldModel {
        &self.model
    }
    /// Parameters.
    pub fn params(&self) -> &ScaledParams {
        &self.params
    }
    /// The habit `π_o` (§V-C).
    pub fn habit(&self) -> &H {
        &self.habit
    }
    /// The surprise gate on the state, if the agent uses one (§VI, Fig. 9a-b).
    pub fn gate(&self) -> Option<&StateGate> {
        self.gate.as_ref()
    }
    /// Surprise (nats) of every tick of the current (or last) episode (what the trigger read).
    pub fn last_surprise_history(&self) -> &[f64] {
        &self.hist_surprise
    }
    /// Whether each tick of the current (or last) episode reasoned because the hand-back
    /// check refused to hand the state to the habit ([`crate::handback`]).
    pub fn refused_history(&self) -> &[bool] {
        &self.hist_refused
    }
    /// Whether each tick of the current (or last) episode reasoned because the competence
    /// check found the habit's action wanting ([`crate::competence`]).
    pub fn checked_history(&self) -> &[bool] {
        &self.hist_checked
    }
    /// Whether each tick of the current (or last) episode went to the habit although the
    /// learned trigger fired, because only test-time learning made it fire and the check
    /// found the habit safe ([`HandBackRule::RiskChecked`]), or always
    /// ([`HandBackRule::DeclineLearned`]).
    pub fn declined_history(&self) -> &[bool] {
        &self.hist_declined
    }
    /// What the last reasoning tick computed.
    pub fn last_reasoning(&self) -> &ReasoningTrace {
        &self.last
    }

    /// `B[u] q_t` under the learned `B` for every action, into `self.next_pred`.
    fn predict_all(&mut self) {
        let gm = self.model.generative();
        let (n, na) = (self.n_states, self.n_actions);
        self.next_pred.resize(n * na, 0.0);
        for u in 0..na {
            gm.transition_into(
                u,
                &self.q_cur,
                &mut self.next_pred[u * n..(u + 1) * n],
                &mut self.pred_scratch,
            );
        }
    }

    /// [`ActionSelection::OutcomeMode`] on a reasoning tick: the mode of
    /// `π̃(u) = Σ_w (1 - TV(B[u] q_t, B[w] q_t)) π'(w)` under the learned `B` (this tick's
    /// predictions, [`ScaledAgent::predict_all`]), the policy pooled over actions whose
    /// predicted next states overlap.
    fn outcome_mode(&self, dist: &[f64]) -> usize {
        argmax(&pooled_over_outcomes(&self.next_pred, self.n_states, dist))
    }

    /// [`TieBreak::Safest`]: among `chosen` and the actions whose predicted next states
    /// (this tick's, [`ScaledAgent::predict_all`]) lie within `tie_tolerance` of its own,
    /// the one least likely to crash when held for `handback_horizon` ticks (the
    /// hand-back's crash risk, [`crate::handback`]); `chosen` where none is less likely.
    fn break_tie(&mut self, chosen: usize) -> usize {
        let (n, tol) = (self.n_states, self.params.scaling.tie_tolerance);
        let mut best: Option<(usize, f64)> = None;
        for w in (0..self.n_actions).filter(|&w| w != chosen) {
            if total_variation(&self.next_pred, n, chosen, w) > tol {
                continue;
            }
            let so_far = match best {
                Some(b) => b,
                None => (chosen, self.held_crash_risk(chosen)),
            };
            let risk = self.held_crash_risk(w);
            best = Some(if risk < so_far.1 { (w, risk) } else { so_far });
        }
        best.map_or(chosen, |(a, _)| a)
    }

    fn select(&mut self, dist: &[f64]) -> usize {
        match self.params.scaling.action_selection {
            ActionSelection::OutcomeMode | ActionSelection::Mode => argmax(dist),
            ActionSelection::Sample => {
                let r: f64 = self.rng.random();
                let mut acc = 0.0;
                for (i, p) in dist.iter().enumerate() {
                    acc += p;
                    if r < acc {
                        return i;
                    }
                }
                argmax(dist)
            }
        }
    }

    /// Perception, planning and scaling on a reasoning tick (§III–§IV). Leaves `q_t` in
    /// `self.q_cur` and `π'` in `self.pi`; returns scaling iterations.
    fn reason(&mut self, obs: usize, th: f64) -> u32 {
        let gm = self.model.generative();
        let n = self.n_states;
        let t = self.hist_obs.len();
        let w = self.params.perception.vmp_window.min(t + 1);
        let first = t + 1 - w;
        // Prior of the first window slot.
        if first == 0 {
            self.s_hat.copy_from_slice(&gm.d);
        } else {
            let q_before = &self.hist_q[(first - 1) * n..first * n];
            predict_into(gm, Some((q_before, self.hist_act[first - 1])), &mut self.s_hat);
        }
        self.window_obs.clear();
        self.window_obs.extend_from_slice(&self.hist_obs[first..t]);
        self.window_obs.push(obs);
        for k in 0..w - 1 {
            self.window_q[k].copy_from_slice(&self.hist_q[(first + k) * n..(first + k + 1) * n]);
        }
        self.window_q[w - 1].copy_from_slice(&self.q_cur);
        let out = vmp(
            gm,
            &self.s_hat,
            &self.window_obs,
            &self.hist_act[first..t],
            &mut self.window_q[..w],
            self.params.perception.vmp_kappa,
            self.params.perception.vmp_tol,
            self.params.perception.vmp_max_iters,
            &mut self.vmp_ws,
            None,
        );
        for k in 0..w - 1 {
            self.hist_q[(first + k) * n..(first + k + 1) * n].copy_from_slice(&self.window_q[k]);
        }
        self.q_cur.copy_from_slice(&self.window_q[w - 1]);
        // Planning (§IV). The first step goes through the learned B, the later ones
        // through the planning model's (episode-ending states absorbing): the car is
        // observed while the episode goes on, so braking out of a crash-risk state counts
        // (module docs of `planning`).
        // The models change only at the end of an episode (`begin_episode` invalidates
        // the tree), so the tree may reuse the previous tick's subtrees.
        let root = match self.params.planning.root_step {
            RootStep::Learned => self.model.generative(),
            RootStep::Absorbing => self.model.planning_generative(),
        };
        self.tree.evaluate_reusing(
            self.model.planning_generative(),
            root,
            &self.q_cur,
            self.params.planning.gamma,
        );
        self.habit.pi_o_belief(t, &self.q_cur, &mut self.pi);
        let tr = &mut self.last;
        tr.free_energy = out.free_energy;
        tr.vmp_iters = out.iterations;
        tr.g.clone_from(&self.tree.g);
        tr.q_pi.clone_from(&self.tree.q_pi);
        tr.psi.clone_from(&self.tree.psi);
        tr.q_s.resize(self.n_actions, 0.0);
        q_s_into(&self.tree.psi, self.params.planning.gamma, &mut tr.q_s);
        tr.pi_o.clone_from(&self.pi);
        self.scale(th)
    }

    /// Scales the habit's policy in `self.pi` toward the planner's `ψ` of the last
    /// evaluation by `θ` (Theorem 1) into `self.pi` (and the trace); returns the iterations.
    fn scale(&mut self, th: f64) -> u32 {
        let tr = &mut self.last;
        tr.pi_scaled.resize(self.n_actions, 0.0);
        let iters = match self.params.scaling.scaling_mode {
            ScalingMode::Iterative => {
                let o = scale_iterative(
                    &self.pi,
                    &self.tree.psi,
                    th,
                    self.params.scaling.kappa_pi,
                    self.params.scaling.varsigma,
                    self.params.scaling.max_scaling_iters,
                    &mut tr.pi_scaled,
                    None,
                );
                tr.kl_initial = o.kl_initial;
                tr.kl_final = o.kl_final;
                o.iterations
            }
            ScalingMode::ClosedForm => {
                scale_closed_form(&self.pi, &self.tree.psi, th, &mut tr.pi_scaled);
                tr.kl_initial = crate::maths::kl(&self.pi, &self.tree.psi);
                tr.kl_final = crate::maths::kl(&tr.pi_scaled, &self.tree.psi);
                0
            }
        };
        self.pi.copy_from_slice(&tr.pi_scaled);
        iters
    }
}

impl<H: Habit> Controller for ScaledAgent<H> {
    fn name(&self) -> &'static str {
        "scaled"
    }

    fn begin_episode(&mut self, seed: u64) {
        self.rng = ChaCha8Rng::seed_from_u64(seed);
        self.hist_obs.clear();
        self.hist_act.clear();
        self.hist_q.clear();
        self.hist_pi.clear();
        self.hist_surprise.clear();
        self.hist_reasoned.clear();
        self.hist_refused.clear();
        self.hist_checked.clear();
        self.hist_declined.clear();
        self.final_obs = None;
        self.prev_one_hot = None;
        self.tree.invalidate();
        self.habit.begin_episode();
    }

    fn act(&mut self, obs: usize) -> Decision {
        let n = self.n_states;
        let obs = obs.min(self.model.generative().n_obs() - 1);
        let t = self.hist_obs.len();
        // Prediction ŝ_t = B[a_{t-1}] q_{t-1} (one-hot q: a column copy).
        {
            let gm = self.model.generative();
            if t == 0 {
                self.s_hat.copy_from_slice(&gm.d);
            } else if let Some(j) = self.prev_one_hot {
                let u = self.hist_act[t - 1];
                self.s_hat.copy_from_slice(&gm.b[u].as_slice()[j * n..(j + 1) * n]);
            } else {
                let u = self.hist_act[t - 1];
                predict_into(gm, Some((&self.hist_q[(t - 1) * n..t * n], u)), &mut self.s_hat);
            }
        }
        let gm = self.model.generative();
        bayes_step(gm, obs, &self.s_hat, &mut self.q_cur);
        // The surprise (reported) and what the trigger reads (the excess over the surprise
        // expected where reasoning endorsed the habit, with `GateBaseline::Endorsed`).
        let (s, trigger) = match &self.gate {
            Some(gate) => {
                let s = gate.surprise(&self.q_cur);
                match self.params.gate.gate_baseline {
                    GateBaseline::Endorsed | GateBaseline::Audited | GateBaseline::Foreseen => {
                        (s, gate.excess_surprise(&self.q_cur, s))
                    }
                    GateBaseline::None => (s, s),
                }
            }
            None => {
                let s = surprise(gm, obs, &self.s_hat);
                (s, s)
            }
        };
        let th = theta(trigger, self.params.gate.omega);
        let always = self.params.scaling.reasoning == ReasoningMode::Always;
        let mut reasoned = always || th > self.params.gate.epsilon;
        // A reasoning tick that only learning made, where the habit is safe: the habit acts.
        let declined = reasoned && !always && self.decline_trigger(obs);
        reasoned &= !declined;
        let mut refused = false;
        let mut checked = false;
        let mut scaling_iters = 0;
        if reasoned {
            scaling_iters = self.reason(obs, th);
        } else {
            if !declined {
                self.habit_policy(obs);
            }
            // The safe hand-back: reason instead where the habit is predicted to crash,
            // scaling with the trained trigger's θ (the surprise learning removed).
            if let Some(th0) = self.refuse_handback() {
                (reasoned, refused) = (true, true);
                scaling_iters = self.reason(obs, th0);
            } else if let Some(thc) = self.habit_wanting(th) {
                // The competence check: reason where holding the habit's action is
                // predicted to be worse than the best action by more than the bound.
                (reasoned, checked) = (true, true);
                scaling_iters = self.reason(obs, thc);
            }
        }
        let pi = std::mem::take(&mut self.pi);
        // On a reasoning tick, the mode over the outcomes the model tells apart (default);
        // on every tick, the safest of the actions the model cannot tell from the chosen
        // one (default). Both read this tick's predictions, made once.
        let outcome_mode = reasoned && self.params.scaling.action_selection == ActionSelection::OutcomeMode;
        let safest = self.params.scaling.tie_break == TieBreak::Safest;
        if outcome_mode || safest {
            self.predict_all();
        }
        let action = if outcome_mode {
            self.outcome_mode(&pi)
        } else {
            self.select(&pi)
        };
        self.pi = pi;
        let action = if safest { self.break_tie(action) } else { action };
        self.prev_one_hot = if self.q_cur[obs] == 1.0 { Some(obs) } else { None };
        self.hist_obs.push(obs);
        self.hist_act.push(action);
        self.hist_q.extend_from_slice(&self.q_cur);
        self.hist_pi.extend_from_slice(&self.pi);
        self.hist_surprise.push(s);
        self.hist_reasoned.push(reasoned);
        self.hist_refused.push(refused);
        self.hist_checked.push(checked);
        self.hist_declined.push(declined);
        Decision {
            action,
            reasoned,
            surprise: Some(s),
            theta: Some(th),
            policy: Dist::from_slice(&self.pi),
            psi: reasoned.then(|| Dist::from_slice(&self.tree.psi)),
            scaling_iters,
        }
    }

    fn observe(&mut self, _reward: f64, next_obs: usize, ending: Ending) {
        if ending.is_over() {
            self.final_obs = Some(next_obs);
        }
    }

    /// Test-time learning (§V): A, factor CPTs, the gate's table and ν from the episode's
    /// posteriors. `ν` consolidates the actions reasoning took (§V-C: "the policy π_o needs
    /// to consolidate the actions sampled from its scaled version π'"), `ν[s,a_τ] += lr q_τ[s]`
    /// on reasoning ticks only: feed-forward ticks do not reinforce the habit's own choices;
    /// then each habit state keeps at most `habit_memory` of those counts
    /// ([`Habit::bound_memory`]).
    /// The gate's table then learns the episode's states; with [`GateLearning::Endorsed`],
    /// each situation of the table (a cell `(x | parents)`) counts with the smallest
    /// endorsement, over this episode's reasoning ticks in it, of the updated habit's action
    /// by reasoning's policy: a situation becomes familiar only as far as the habit now does
    /// what reasoning chose in every state of it the episode met. Each reasoning tick's
    /// endorsement is also recorded for its state ([`crate::gate::StateGate::endorse`]),
    /// which is what [`GateBaseline::Endorsed`] subtracts the expected surprise by.
    fn end_episode(&mut self) {
        if !self.params.learning.enabled || self.hist_obs.is_empty() {
            return;
        }
        let n = self.n_states;
        let lr = self.params.learning.learning_rate;
        let na = self.n_actions;
        let steps = self.hist_obs.len();
        let mut taken = vec![0.0; na];
        for k in 0..steps {
            let q = &self.hist_q[k * n..(k + 1) * n];
            learning::update_a(self.model.a_counts_mut(), self.hist_obs[k], q, lr);
            if self.hist_reasoned[k] {
                taken.fill(0.0);
                taken[self.hist_act[k]] = 1.0;
                self.habit.learn(q, &taken, lr);
            }
            if k > 0 {
                let qp = &self.hist_q[(k - 1) * n..k * n];
                learning::update_cpts(&mut self.model, qp, self.hist_act[k - 1], q, lr);
            }
        }
        self.habit.bound_memory(self.params.learning.habit_memory);
        if let Some(gate) = &mut self.gate {
            // Each tick is attributed to its most likely state and that state's cell.
            let mut weight = vec![1.0; gate.n_cells()];
            let mut habit = vec![0.0; na];
            for k in (0..steps).filter(|&k| self.hist_reasoned[k]) {
                let q = &self.hist_q[k * n..(k + 1) * n];
                self.habit.pi_o_belief(k, q, &mut habit);
                let e = endorsement(&self.hist_pi[k * na..(k + 1) * na], argmax(&habit));
                let s = argmax(q);
                if self.params.gate.gate_learning == GateLearning::Endorsed {
                    let cell = gate.cell_of(s);
                    weight[cell] = f64::min(weight[cell], e);
                }
                gate.endorse(s, e);
            }
            for k in 0..steps {
                let q = &self.hist_q[k * n..(k + 1) * n];
                gate.learn(q, lr * weight[gate.cell_of(argmax(q))]);
            }
        }
        if let Some(o) = self.final_obs.filter(|o| *o < self.model.generative().n_obs()) {
            let gm = self.model.generative();
            let qp = self.hist_q[(steps - 1) * n..steps * n].to_vec();
            let u = self.hist_act[steps - 1];
            let mut pred = vec![0.0; n];
            predict_into(gm, Some((&qp, u)), &mut pred);
            let mut qf = vec![0.0; n];
            bayes_step(gm, o, &pred, &mut qf);
            learning::update_a(self.model.a_counts_mut(), o, &qf, lr);
            learning::update_cpts(&mut self.model, &qp, u, &qf, lr);
            if let Some(gate) = &mut self.gate {
                gate.learn(&qf, lr);
            }
        }
        if let Some(gate) = &mut self.gate {
            gate.consolidate();
        }
        self.model.materialize();
        self.competence.invalidate();
        self.learned = true;
    }
}

/// How far the policy reasoning chose endorses action `a`: `π'(a) / max_u π'(u)`, 1 when
/// `a` is (one of) reasoning's most likely actions.
fn endorsement(pi_scaled: &[f64], a: usize) -> f64 {
    let best = pi_scaled.iter().copied().fold(0.0, f64::max);
    if best > 0.0 { pi_scaled[a] / best } else { 0.0 }
}

/// The policy `dist` pooled over the actions' predicted next states `pred`
/// (`[u * n + s]`, each a distribution): `π̃(u) = Σ_w (1 - TV(pred_u, pred_w)) dist(w)`
/// ([`ActionSelection::OutcomeMode`]). Actions with disjoint predictions keep their own
/// probability; actions with the same prediction share the sum of theirs.
fn pooled_over_outcomes(pred: &[f64], n: usize, dist: &[f64]) -> Vec<f64> {
    (0..dist.len())
        .map(|u| {
            (0..dist.len())
                .map(|w| (1.0 - total_variation(pred, n, u, w)).max(0.0) * dist[w])
                .sum()
        })
        .collect()
}

/// The total variation between the predicted next states of actions `u` and `w` in `pred`
/// (`[u * n + s]`): half the L1 distance, in [0, 1].
fn total_variation(pred: &[f64], n: usize, u: usize, w: usize) -> f64 {
    let of = |a: usize| &pred[a * n..(a + 1) * n];
    of(u).iter().zip(of(w)).map(|(x, y)| (x - y).abs()).sum::<f64>() / 2.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pooling_over_outcomes_by_hand() {
        // Maintain and speed up predict the same next state (the top speed bin), slow down
        // another: "keep going" (0.26 + 0.26) outweighs "slow down" (0.48).
        let pred = [0.0, 1.0, 0.0, 1.0, 1.0, 0.0];
        let pooled = pooled_over_outcomes(&pred, 2, &[0.26, 0.26, 0.48]);
        assert!((pooled[0] - 0.52).abs() < 1e-12 && (pooled[1] - 0.52).abs() < 1e-12);
        assert!((pooled[2] - 0.48).abs() < 1e-12);
        assert_eq!(argmax(&pooled), 0);
        // Disjoint predictions: the policy itself, so its mode.
        let pred = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        assert_eq!(
            pooled_over_outcomes(&pred, 3, &[0.26, 0.26, 0.48]),
            vec![0.26, 0.26, 0.48]
        );
        // Half-overlapping predictions share half.
        let pred = [0.5, 0.5, 0.0, 1.0];
        let pooled = pooled_over_outcomes(&pred, 2, &[0.4, 0.6]);
        assert!((pooled[0] - 0.7).abs() < 1e-12 && (pooled[1] - 0.8).abs() < 1e-12);
    }

    #[test]
    fn endorsement_by_hand() {
        // The planner's favourite (or a tie with it) is fully endorsed; others in proportion.
        assert_eq!(endorsement(&[0.25, 0.25, 0.5], 2), 1.0);
        assert_eq!(endorsement(&[0.47, 0.06, 0.47], 0), 1.0);
        assert_eq!(endorsement(&[0.25, 0.25, 0.5], 1), 0.5);
        assert_eq!(endorsement(&[0.0, 0.0, 0.0], 1), 0.0);
    }
}
