//! Hyperparameters in checked parameter types (linfa style: plain structs with
//! documented defaults, `check()` returns a typed [`ParamError`] instead of panicking;
//! for the scaled agent, `check()` returns the validated [`CheckedScaledParams`]).
//!
//! Every constructor that takes parameters ([`crate::model::WorldModel::new`],
//! [`crate::scaled_agent::ScaledAgent::new`], [`crate::bayes_rl::BayesRl::new`],
//! [`crate::q_learning::QLearning::new`]) calls `check()` and returns the error.
//! Defaults follow the paper's §VI where it states them. The scaled agent's parameters
//! are declared once per group with their keys and ranges, and read and set by name
//! through [`crate::param_table`].

use crate::error::ParamError;
use crate::param_decl::{Bound, NameRule, Rule, param_enum, param_group, param_groups};
use crate::structure::{Parent, Structure};
use serde::{Deserialize, Serialize};

fn in_half_open01(name: &'static str, x: f64) -> Result<(), ParamError> {
    if x > 0.0 && x <= 1.0 {
        Ok(())
    } else {
        Err(ParamError::new(name, x, "in (0, 1]"))
    }
}
fn in_closed01(name: &'static str, x: f64) -> Result<(), ParamError> {
    if (0.0..=1.0).contains(&x) {
        Ok(())
    } else {
        Err(ParamError::new(name, x, "in [0, 1]"))
    }
}
fn positive(name: &'static str, x: f64) -> Result<(), ParamError> {
    if x > 0.0 && x.is_finite() {
        Ok(())
    } else {
        Err(ParamError::new(name, x, "finite and > 0"))
    }
}
fn non_negative(name: &'static str, x: f64) -> Result<(), ParamError> {
    if x >= 0.0 && x.is_finite() {
        Ok(())
    } else {
        Err(ParamError::new(name, x, "finite and >= 0"))
    }
}
/// `1 <= x <= max`, else `expected` (which states the range and why): counts that size an
/// allocation or a loop, so that no setting asks for more memory or time than a run has.
fn at_most(name: &'static str, x: usize, max: usize, expected: &'static str) -> Result<(), ParamError> {
    if (1..=max).contains(&x) {
        Ok(())
    } else {
        Err(ParamError::new(name, x, expected))
    }
}

/// Largest VMP window, ticks: the perception keeps one belief per tick of the window
/// (1000 x 1024 states x 8 bytes = 8 MB at most); episodes are 40 ticks by default.
pub const MAX_VMP_WINDOW: usize = 1000;
/// Largest iteration cap of the scaling and VMP loops (each runs on every reasoning tick).
pub const MAX_ITERATIONS: usize = 10_000;
/// Largest number of value-iteration sweeps of the Bayesian-RL planner per tick.
pub const MAX_PLANNER_ITERATIONS: usize = 100_000;
/// Largest lookahead depth of the Bayesian-RL planner.
pub const MAX_LOOKAHEAD: usize = 100;

/// Priors of the world model's Dirichlet counts (§II-A world model, §V learning).
///
/// | field | default | range | meaning |
/// |---|---|---|---|
/// | `transition_concentration` | 1.0 | >= 0 | prior count added to every CPT cell (b0) |
/// | `a_concentration` | 1000.0 | > 0 | total prior count of each column of A |
/// | `a_noise` | 0.0 | [0, 1) | mass of each column of A spread uniformly over the other observations (0 = identity A) |
/// | `d` | `None` (uniform) | length = states, sums to 1 | initial state prior D |
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelPriors {
    /// Prior count per CPT cell (b0 >= 0). With 0, a parent configuration never seen is uniform.
    pub transition_concentration: f64,
    /// Total prior count per column of A (> 0).
    pub a_concentration: f64,
    /// Off-diagonal mass of A's columns in [0, 1): 0 gives the identity A (MDP, §VI).
    pub a_noise: f64,
    /// Initial state prior D; `None` means uniform.
    pub d: Option<Vec<f64>>,
}

impl Default for ModelPriors {
    fn default() -> Self {
        Self {
            transition_concentration: 1.0,
            a_concentration: 1000.0,
            a_noise: 0.0,
            d: None,
        }
    }
}

impl ModelPriors {
    /// Validate ranges (table above).
    pub fn check(&self) -> Result<(), ParamError> {
        non_negative("transition_concentration", self.transition_concentration)?;
        positive("a_concentration", self.a_concentration)?;
        if !(0.0..1.0).contains(&self.a_noise) {
            return Err(ParamError::new("a_noise", self.a_noise, "in [0, 1)"));
        }
        if let Some(d) = &self.d {
            let s: f64 = d.iter().sum();
            if d.iter().any(|x| x.is_nan() || *x < 0.0) || (s - 1.0).abs() > 1e-9 {
                return Err(ParamError::new("d", format!("{d:?}"), "non-negative and summing to 1"));
            }
        }
        Ok(())
    }
}

param_enum! {
    /// How the scaled policy is computed (§IV Theorem 1).
    pub enum ScalingMode {
        /// The iterative update of eq. "gradient_descent_equations" with eq. "stopping_criterion".
        #[default]
        Iterative = "iterative",
        /// The closed form of Theorem 1: `π' ∝ π_o ψ^θ`.
        ClosedForm = "closed-form",
    }
}

param_enum! {
    /// How the action is drawn from the policy acted upon (docs/ARCHITECTURE.md §4.9).
    /// By name also `sample=true|false` (see [`crate::param_table::ALIASES`]).
    pub enum ActionSelection {
        /// The mode over the outcomes the model tells apart (beyond the paper; default in
        /// evaluation): on a reasoning tick each action's probability is pooled with that of
        /// every action whose predicted next state overlaps its own,
        /// `π̃(u) = Σ_w (1 - TV(B[u] q_t, B[w] q_t)) π'(w)`, and the agent acts on the mode of
        /// `π̃` (ties: lowest index), so that two actions the model cannot tell apart
        /// (maintain and speed up in the top speed bin, maintain and slow down at a
        /// standstill) do not split the mass of one choice between them. Feed-forward ticks
        /// act on the mode of `π_o`, as [`ActionSelection::Mode`] does.
        #[default]
        OutcomeMode = "outcome-mode" | "false" | "no" | "0",
        /// The mode of the policy acted upon (ties: lowest index): the paper's rule (ablation).
        Mode = "mode",
        /// Sample with the agent's seeded ChaCha8 RNG.
        Sample = "sample" | "true" | "yes" | "1",
    }
}

param_enum! {
    /// What the agent does with the actions its world model cannot tell apart from the one it
    /// chose (docs/ARCHITECTURE.md §4.9).
    pub enum TieBreak {
        /// Beyond the paper (default): on every tick, among the chosen action and the actions
        /// whose predicted next state `B[u] q_t` lies within `tie_tolerance` of its own (total
        /// variation), the agent takes the one least likely to crash when held for
        /// `handback_horizon` ticks (the hand-back's crash risk, [`crate::handback`]); the
        /// chosen action keeps the tick where none is less likely. Where the model cannot tell
        /// "speed up" from "maintain" (the top speed bin), the crash model still can: the
        /// faster car covers more ground in a tick where a pedestrian may be.
        #[default]
        Safest = "safest",
        /// Act on the chosen action (the paper's; ablation).
        Chosen = "chosen",
    }
}

param_enum! {
    /// When reasoning (VMP + planning + scaling) runs (§II footnote, §IV; ablation).
    pub enum ReasoningMode {
        /// Only when θ_t > ε (the paper's method).
        #[default]
        Triggered = "triggered",
        /// On every tick (ablation "scaled with reasoning on every tick").
        Always = "always",
    }
}

param_enum! {
    /// What the reasoning trigger measures (§II, §VI; docs/ARCHITECTURE.md §4.4).
    pub enum GateMode {
        /// Surprise on the state: `-ln P(x_t | parents_t)` of the watched factor (the paper's
        /// "surprise measured from the state space", Fig. 9a-b), see [`crate::gate`].
        #[default]
        State = "state",
        /// Ablation: the one-step surprise of the joint transition, `-ln Σ_s A[o_t,s] ŝ_t[s]`
        /// (Lemma 1), which also fires on the car's own bin crossings.
        OneStep = "one-step",
    }
}

param_enum! {
    /// How the gate's table learns a situation as familiar (§V applied to the gate;
    /// docs/ARCHITECTURE.md §4.4). Beyond the paper, whose rule is only `θ <= ε`.
    pub enum GateLearning {
        /// A reasoning tick counts in the gate's table with weight `π'(a_o) / max_u π'(u)`,
        /// where `a_o` is the habit's action after this episode's update of `ν`: a situation
        /// becomes familiar (and control returns to the habit) only as far as the planner
        /// endorses what the habit would do there. Feed-forward ticks count fully.
        #[default]
        Endorsed = "endorsed",
        /// Ablation: every tick counts fully (the situation becomes familiar whatever the habit does).
        Every = "every",
    }
}

param_enum! {
    /// What the trigger subtracts from the gate's surprise before `θ = 1 - exp(-Ω S)`
    /// ([`crate::gate::StateGate::excess_surprise`]). Beyond the paper, whose trigger reads `S`.
    pub enum GateBaseline {
        /// The surprise expected in the state, `c(s) H(row)`, where `c(s)` grows with the
        /// reasoning ticks in that state that endorsed the habit (full after `gate_memory`):
        /// the uncertainty of a situation stops triggering reasoning once the habit has
        /// been shown to act there as reasoning would. Zero for a never-endorsed state.
        #[default]
        Endorsed = "endorsed",
        /// As `endorsed`, with every state's endorsement first audited when the agent is
        /// built: the planner, from a certain belief in that state, endorses the habit's
        /// action by `ψ(a_o) / max_u ψ(u)` ([`crate::scaled_agent::ScaledAgent::audit_habit`]).
        /// So the ordinary uncertainty of a familiar situation (a pedestrian or a cross car
        /// in the car's path on half of the red ticks) does not trigger reasoning from the
        /// first episode on where the habit already does what reasoning would.
        Audited = "audited",
        /// As `endorsed`, with every state's endorsement first set by how much the habit
        /// was trained there: `c(s) = min(1, n(row(s)) / gate_memory)` for the row's data
        /// counts ([`crate::gate::StateGate::foresee`]). The uncertainty the training data
        /// showed (a cross car in the car's path on half of the red ticks) is expected; the
        /// surprise beyond it, and any surprise in a row training never filled, triggers.
        Foreseen = "foreseen",
        /// Ablation (the paper's trigger): nothing; `θ` reads the surprise itself.
        None = "none",
    }
}

param_enum! {
    /// When control goes back to the habit on a tick whose `θ <= ε` ([`crate::handback`];
    /// docs/ARCHITECTURE.md §4.10). Beyond the paper, whose rule is `θ <= ε` alone.
    pub enum HandBackRule {
        /// Where test-time learning changed the trigger's verdict, learning may only take
        /// reasoning away, and only where the habit is safe. A hand-back that learning made
        /// (the trained agent's trigger would still fire) is made only if the habit, rolled
        /// forward `handback_horizon` ticks through the learned model, enters a crash-risk
        /// state at most `handback_risk` more likely than the safest action; otherwise the
        /// agent reasons. A reasoning tick that learning alone made (the trained trigger would
        /// hand back, the learned one fires: learning that pedestrians are common makes an
        /// empty road read as surprising) is declined: the habit acts, as the trained agent's
        /// would. So the agent reasons only where its trained trigger fires.
        #[default]
        DeclineLearned = "decline-learned",
        /// Option: the crash-risk check decides both ways. Hand-backs as `DeclineLearned`; a
        /// reasoning tick that learning alone made is taken where the check finds the habit at
        /// risk (e.g. about to run a red light into a crosswalk where pedestrians cross on red),
        /// otherwise declined. There the planner acts on what it knows and the habit has not
        /// learnt (a traffic rule: on the rule-aware maps/red_light/ it saves cars of two of
        /// 20 agents), at the cost of reasoning on an empty road (EXPERIMENTS.md, "The safe
        /// hand-back").
        RiskChecked = "risk-checked",
        /// Ablation: only hand-backs that learning made are checked; every tick the learned
        /// trigger fires on reasons.
        HandBackChecked = "hand-back-checked",
        /// Ablation (the paper's rule): `θ <= ε` hands back, whatever the habit does.
        Theta = "theta",
    }
}

param_enum! {
    /// Whether the world model checks the habit where the surprise gate leaves it in charge
    /// ([`crate::competence`]; docs/ARCHITECTURE.md §4.11). Beyond the paper, whose agent
    /// trusts the habit wherever nothing surprises it.
    pub enum CompetenceCheck {
        /// The habit acts only where holding its action for `competence_horizon` ticks is
        /// predicted (expected free energy, Prop. 1) at most `competence_regret` nats worse than
        /// holding the best action, or where the best action is the riskier (by more than
        /// `handback_risk`); otherwise the agent reasons.
        #[default]
        Regret = "regret",
        /// Ablation (the paper's agent): reasoning only where the gate finds surprise.
        SurpriseOnly = "surprise-only",
    }
}

param_enum! {
    /// How the competence check ([`crate::competence`]) rolls the habit out.
    pub enum CompetenceRollout {
        /// Holding its action for `competence_horizon` ticks, as every other action.
        #[default]
        Held = "held",
        /// The better of holding its action and following it: its action now, then in each
        /// predicted state the action it takes there (a habit that stops at a red line is
        /// judged stopping there, not driving through it).
        Feedback = "feedback",
    }
}

param_enum! {
    /// Which model the EFE tree's first step from `q_t` goes through
    /// ([`crate::planning::EfeTree::evaluate`]).
    pub enum RootStep {
        /// The learned `B`: the car observes `q_t` while the episode goes on, so from a
        /// crash-risk state braking out of it counts; later steps absorb.
        #[default]
        Learned = "learned",
        /// Ablation: the planning model's, where episode-ending states are absorbing from
        /// the root on, so every action from a crash-risk state ends alike.
        Absorbing = "absorbing",
    }
}

param_enum! {
    /// How the planner models a crash at the crosswalk.
    pub enum CrashPlanning {
        /// The paper's model (the ablation): every state with a pedestrian on the crosswalk
        /// while the car moves in the crosswalk's distance bin is a crash, absorbing, whatever
        /// the car does, so braking there earns nothing and a dash to the goal looks best.
        States = "states",
        /// Beyond the paper, the default: a tick in the crosswalk's bin with a pedestrian on
        /// the crosswalk ends in a crash with a probability that grows with the distance the
        /// car covers under the action, and a crashed episode forfeits the goal
        /// ([`crate::model::CrashModel`]); braking there earns what it saves. Where the car is
        /// already on the crosswalk when a pedestrian steps on, stopping can be what gets it
        /// hit (EXPERIMENTS.md, "The crosswalk's distance bins and the crash model"). Agents
        /// without a crash model plan as `states`.
        #[default]
        Hazard = "hazard",
    }
}

param_groups! {
    /// Hyperparameters of the paper's agent ([`crate::scaled_agent::ScaledAgent`]), grouped by the
    /// paper's concepts. Every parameter has a key (the name in the table below; the
    /// dotted `group.key` is accepted too) by which it is read and set
    /// ([`ScaledParams::get`], [`ScaledParams::set_str`], [`ScaledParams::set`],
    /// [`crate::param_table`]). Each group's fields are declared once, with their key,
    /// default and range (`param_group!` below): the struct, its serde names, the table's
    /// setter and getter and the range checks all come from that declaration, so a field
    /// added to a group is settable by name with no other edit.
    ///
    /// | group | key | default | range | paper |
    /// |---|---|---|---|---|
    /// | `gate` | `omega` Ω | 0.425 | finite and > 0 | §IV θ = 1 - exp(-Ω S), §VI |
    /// | `gate` | `epsilon` ε | 0.2 | [0, 1) | §II reasoning trigger θ > ε, §VI |
    /// | `gate` | `gate` | `state` | `state`, `one-step` | §VI surprise on the state, or the one-step joint surprise (ablation) ([`GateMode`]) |
    /// | `gate` | `gate_factor` | `"p"` | a factor's name | the factor the state gate watches, given its next-time parents |
    /// | `gate` | `gate_memory` | 20.0 | > 0 (`inf` allowed) | ticks of data a row of the gate's table keeps (§V learning, bounded) |
    /// | `gate` | `gate_learning` | `endorsed` | `endorsed`, `every` | reasoning ticks count in the gate's table as far as the planner endorses the habit ([`GateLearning`]) |
    /// | `gate` | `gate_baseline` | `endorsed` | `endorsed`, `audited`, `foreseen`, `none` | the trigger reads the surprise in excess of what is expected where reasoning endorsed the habit (beyond the paper; `audited` also audits every state's endorsement when the agent is built; `foreseen` starts it from the row's training data; `none` is the paper's trigger) ([`GateBaseline`]) |
    /// | `gate` | `handback` | `decline-learned` | `decline-learned`, `risk-checked`, `hand-back-checked`, `theta` | where test-time learning changed the trigger's verdict: a hand-back learning made goes to the habit only if the world model's crash-risk check passes, a reasoning tick learning alone made is declined (beyond the paper; `risk-checked` takes such a tick where the check finds the habit at risk, `hand-back-checked` takes every one, `theta` is the rule `θ <= ε` alone) ([`HandBackRule`]) |
    /// | `gate` | `handback_risk` ρ | 0.08 | [0, 1) | the largest excess of the habit's predicted crash risk (entering a crash-risk state within `handback_horizon` ticks, following the habit) over the safest first action's at which control goes back to it |
    /// | `gate` | `handback_horizon` | 3 | 1..=8 | ticks the habit is rolled forward through the learned model by the hand-back check |
    /// | `gate` | `competence` | `regret` | `regret`, `surprise-only` | where the gate leaves the habit in charge, the world model scores holding its action against holding the best one, and the agent reasons where it is worse by more than `competence_regret` (beyond the paper; `surprise-only` is the paper's agent) ([`CompetenceCheck`]) |
    /// | `gate` | `competence_regret` | 10.0 | finite and >= 0 | nats of expected free energy by which holding the habit's action may be worse than holding the best action before the agent reasons |
    /// | `gate` | `competence_horizon` | 8 | 1..=40 | ticks each action is held by the competence check |
    /// | `gate` | `competence_rollout` | `held` | `held`, `feedback` | how the competence check rolls the habit out: holding its action, or the better of holding it and following the habit's action in each predicted state (beyond the paper) ([`CompetenceRollout`]) |
    /// | `gate` | `competence_commit` | 2 | 1..=40 | ticks `feedback` holds the habit's action before following it: the car is committed to what it does now for that long |
    /// | `perception` | `vmp_window` W | 4 | 1..=1000 | VMP window (ticks), §III |
    /// | `perception` | `vmp_kappa` κ | 1.0 | (0, 1] | VMP step in logit coordinates (eq. "iterative") |
    /// | `perception` | `vmp_tol` | 1e-6 | finite and > 0 | VMP convergence threshold on max \|Δ q\| |
    /// | `perception` | `vmp_max_iters` | 32 | 1..=10000 | VMP iteration cap |
    /// | `planning` | `gamma` γ | 0.5 | finite and > 0 | Cor. 1 q(π) = σ(-γG), §VI |
    /// | `planning` | `horizon` H | 3 | 1..=8 | policy length (n_actions^H policies, Prop. 1) |
    /// | `planning` | `root_step` | `learned` | `learned`, `absorbing` | the EFE tree's first step uses the learned `B`, later steps the absorbing planning model ([`RootStep`]; `absorbing` absorbs from the root on) |
    /// | `planning` | `crash_model` | `hazard` | `hazard`, `states` | a crash as a transition whose probability grows with the distance the car covers, forfeiting the goal (beyond the paper), or the paper's absorbing crash-risk states ([`CrashPlanning`]) |
    /// | `planning` | `persistence_ignores` | `"d+L"` | next-time parents' names joined by `+`, or `""` (also written `none`) | the watched factor's persistence (rows where it was present) is pooled over these parents in the model `B` is built from ([`crate::model::WorldModel::set_persistence_pooling`]; beyond the paper, `""` is the paper's CPT) |
    /// | `scaling` | `varsigma` ς | 0.05 | finite and >= 0 | eq. "stopping_criterion", §VI |
    /// | `scaling` | `kappa_pi` | 1.0 | (0, 1] | scaling step size: 1 is the paper's step (eq. "gradient_descent_equations": one step lands on ψ); smaller steps stop part-way |
    /// | `scaling` | `max_scaling_iters` | 50 | 1..=10000 | cap of the scaling loop |
    /// | `scaling` | `scaling_mode` | `iterative` | `iterative`, `closed-form` | Theorem 1 iterative / closed form ([`ScalingMode`]) |
    /// | `scaling` | `action_selection` | `outcome-mode` | `outcome-mode`, `mode`, `sample` | act on the mode over the outcomes the model tells apart, on the policy's mode (the paper's, ablation) or sample it ([`ActionSelection`]) |
    /// | `scaling` | `tie_break` | `safest` | `safest`, `chosen` | among the actions whose predicted next state is within `tie_tolerance` of the chosen one's, take the one least likely to crash within `handback_horizon` ticks (beyond the paper), or the chosen one (the paper's, ablation) ([`TieBreak`]) |
    /// | `scaling` | `tie_tolerance` | 0.05 | [0, 1) | the total variation between two actions' predicted next states below which the model cannot tell them apart |
    /// | `scaling` | `reasoning` | `triggered` | `triggered`, `always` | reason when θ > ε, or on every tick (ablation) ([`ReasoningMode`]) |
    /// | `learning` | `learning` | true | true, false | test-time learning §V at episode end |
    /// | `learning` | `learning_rate` | 1.0 | finite and >= 0 | multiplies the expected counts added in §V |
    /// | `learning` | `nu0` ν0 | 10.0 | finite and > 0 | prior strength of ν = ν0 σ(Q/T) (docs/ARCHITECTURE.md §4.8) |
    /// | `learning` | `nu_temperature` T | 1.0 | finite and > 0 | temperature of ν's softmax over Q |
    /// | `learning` | `habit_memory` | 20.0 | > 0 (`inf` allowed) | counts of reasoning a state of the habit keeps beyond its prior: each state's counts are rescaled to at most this many at the end of an episode (beyond the paper; [`crate::habit::Habit::bound_memory`]) |
    ///
    /// Where each range is enforced: numbers, enum values and the spelling of `gate_factor`
    /// and `persistence_ignores` (names without spaces, `+` between names, no name twice)
    /// when set by name and by [`ScaledParams::check`]; that the watched factor is not
    /// among the pooled ones by `check`; that they name factors of the model (the watched factor, and
    /// next-time parents of it) only where a model is known, by
    /// [`CheckedScaledParams::check_factors`], which [`crate::scaled_agent::ScaledAgent::new`] calls.
    pub struct ScaledParams {
        /// The reasoning trigger (§II, §IV, §VI).
        gate: GateParams,
        /// VMP perception (§III).
        perception: PerceptionParams,
        /// EFE planning (§IV, Prop. 1, Cor. 1).
        planning: PlanningParams,
        /// Test-time policy scaling and action selection (§IV, Theorem 1).
        scaling: ScalingParams,
        /// Test-time learning (§V).
        learning: LearningParams,
    }
}

param_group! {
    /// The reasoning trigger's parameters (table of [`ScaledParams`]).
    pub struct GateParams {
        /// Ω, saturation of the normalised surprise.
        omega: f64 = 0.425 => "omega" in Bound::Positive,
        /// ε, reasoning threshold on θ.
        epsilon: f64 = 0.2 => "epsilon" in Bound::BelowOne,
        /// What the reasoning trigger measures (key `gate`).
        mode: GateMode = GateMode::State => "gate",
        /// Name of the factor the state gate watches (given its next-time parents).
        gate_factor: String = "p".into() => "gate_factor" in NameRule::Factor,
        /// Data counts each row of the state gate's table keeps (bounded memory; `inf`
        /// is written as the string `"inf"`).
        #[serde(with = "f64_or_inf")]
        gate_memory: f64 = 20.0 => "gate_memory" in Bound::PositiveOrInf,
        /// How the gate's table learns a situation as familiar.
        gate_learning: GateLearning = GateLearning::Endorsed => "gate_learning",
        /// What the trigger subtracts from the gate's surprise.
        gate_baseline: GateBaseline = GateBaseline::Endorsed => "gate_baseline",
        /// When control goes back to the habit.
        handback: HandBackRule = HandBackRule::DeclineLearned => "handback",
        /// ρ: the largest excess of the habit's predicted crash risk over the safest first
        /// action's at which control goes back to it.
        handback_risk: f64 = 0.08 => "handback_risk" in Bound::BelowOne,
        /// Ticks of the hand-back check's rollout of the habit.
        handback_horizon: usize = 3 => "handback_horizon" in count(
            MAX_HORIZON,
            "in 1..=8 (the hand-back check rolls the habit forward on the ticks it checks)",
        ),
        /// Whether the world model checks the habit's action on the ticks the gate leaves to it.
        competence: CompetenceCheck = CompetenceCheck::Regret => "competence",
        /// The largest regret (nats) of holding the habit's action at which it acts.
        competence_regret: f64 = 10.0 => "competence_regret" in Bound::NonNegative,
        /// Ticks each action is held by the competence check.
        competence_horizon: usize = 8 => "competence_horizon" in count(
            MAX_COMPETENCE_HORIZON,
            "in 1..=40 (the competence check holds each action this many ticks where the habit acts)",
        ),
        /// How the competence check rolls the habit out.
        competence_rollout: CompetenceRollout = CompetenceRollout::Held => "competence_rollout",
        /// Ticks the habit's action is held before `competence_rollout = feedback` follows it.
        competence_commit: usize = 2 => "competence_commit" in count(
            MAX_COMPETENCE_HORIZON,
            "in 1..=40 (ticks the competence check holds the habit's action before following it)",
        ),
    }
}

param_group! {
    /// VMP perception's parameters (table of [`ScaledParams`]).
    pub struct PerceptionParams {
        /// VMP window W.
        vmp_window: usize = 4 => "vmp_window" in count(
            MAX_VMP_WINDOW,
            "in 1..=1000 (the perception keeps a belief per tick of the window)",
        ),
        /// VMP step size κ.
        vmp_kappa: f64 = 1.0 => "vmp_kappa" in Bound::HalfOpenUnit,
        /// VMP tolerance.
        vmp_tol: f64 = 1e-6 => "vmp_tol" in Bound::Positive,
        /// VMP iteration cap.
        vmp_max_iters: u32 = 32 => "vmp_max_iters" in count(
            MAX_ITERATIONS,
            "in 1..=10000 (VMP runs on every reasoning tick)",
        ),
    }
}

param_group! {
    /// EFE planning's parameters (table of [`ScaledParams`]).
    pub struct PlanningParams {
        /// γ, policy precision.
        gamma: f64 = 0.5 => "gamma" in Bound::Positive,
        /// Planning horizon H.
        horizon: usize = 3 => "horizon" in count(
            MAX_HORIZON,
            "in 1..=8 (the planner evaluates n_actions^H policies on every reasoning tick)",
        ),
        /// The model of the EFE tree's first step.
        root_step: RootStep = RootStep::Learned => "root_step",
        /// How a crash at the crosswalk is modelled.
        crash_model: CrashPlanning = CrashPlanning::Hazard => "crash_model",
        /// The next-time parents the watched factor's persistence does not depend on, joined
        /// by `+` (`""`: none; `"none"` is read as `""`).
        #[serde(deserialize_with = "factor_list")]
        persistence_ignores: String = "d+L".into() => "persistence_ignores" in NameRule::FactorList,
    }
}

param_group! {
    /// Policy scaling's parameters (table of [`ScaledParams`]).
    pub struct ScalingParams {
        /// ς, stopping tolerance.
        varsigma: f64 = 0.05 => "varsigma" in Bound::NonNegative,
        /// Scaling step size in (0, 1].
        kappa_pi: f64 = 1.0 => "kappa_pi" in Bound::HalfOpenUnit,
        /// Maximum scaling iterations.
        max_scaling_iters: u32 = 50 => "max_scaling_iters" in count(
            MAX_ITERATIONS,
            "in 1..=10000 (the scaling loop runs on every reasoning tick)",
        ),
        /// Iterative or closed-form scaling.
        scaling_mode: ScalingMode = ScalingMode::Iterative => "scaling_mode",
        /// Mode over outcomes, mode or sample.
        action_selection: ActionSelection = ActionSelection::OutcomeMode => "action_selection",
        /// What happens to the actions the model cannot tell from the chosen one.
        tie_break: TieBreak = TieBreak::Safest => "tie_break",
        /// Total variation below which two actions' predicted next states are the same.
        tie_tolerance: f64 = 0.05 => "tie_tolerance" in Bound::BelowOne,
        /// Triggered or always.
        reasoning: ReasoningMode = ReasoningMode::Triggered => "reasoning",
    }
}

param_group! {
    /// Test-time learning's parameters (table of [`ScaledParams`]).
    pub struct LearningParams {
        /// Test-time learning on/off (key `learning`).
        enabled: bool = true => "learning",
        /// Test-time learning rate.
        learning_rate: f64 = 1.0 => "learning_rate" in Bound::NonNegative,
        /// ν0, prior strength of the policy counts.
        nu0: f64 = 10.0 => "nu0" in Bound::Positive,
        /// T, temperature of the Q softmax that initialises ν.
        nu_temperature: f64 = 1.0 => "nu_temperature" in Bound::Positive,
        /// Counts of reasoning each state of the habit keeps beyond its prior (bounded memory;
        /// `inf`, written as the string `"inf"`, is unbounded).
        #[serde(with = "f64_or_inf")]
        habit_memory: f64 = 20.0 => "habit_memory" in Bound::PositiveOrInf,
    }
}

/// A count's range: `1..=max`, stated as `expected` (the range and why).
const fn count(max: usize, expected: &'static str) -> Bound {
    Bound::Count { max, expected }
}

/// `gate_memory` and `habit_memory`: a number, or `"inf"` (JSON has no infinity).
mod f64_or_inf {
    use serde::{Deserialize, Deserializer, Serializer, de::Error};

    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            s.serialize_f64(*x)
        } else {
            s.serialize_str(&x.to_string())
        }
    }

    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Repr {
        Number(f64),
        Text(String),
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        match Repr::deserialize(d)? {
            Repr::Number(x) => Ok(x),
            Repr::Text(t) => t
                .trim()
                .parse()
                .map_err(|_| D::Error::custom(format!("'{t}' is not a number (or inf)"))),
        }
    }
}

/// `persistence_ignores`: `"none"` is read as `""` (no pooling).
fn factor_list<'de, D: serde::Deserializer<'de>>(d: D) -> Result<String, D::Error> {
    Ok(NameRule::FactorList.normal(String::deserialize(d)?))
}

/// Largest planning horizon: the EFE tree evaluates `n_actions^H` policies per reasoning tick.
pub const MAX_HORIZON: usize = 8;
/// Largest horizon of the competence check: `n_actions × H_c` predictions per checked tick,
/// the length of a default episode.
pub const MAX_COMPETENCE_HORIZON: usize = 40;

impl ScaledParams {
    /// Every violation of the declared ranges (numbers, counts, the factor names'
    /// spelling), group by group in declaration order, then of the rules between fields.
    pub(crate) fn problems(&self) -> Vec<ParamError> {
        let mut out = self.field_problems();
        out.extend(self.cross_problem().filter(|e| !out.iter().any(|o| o.name == e.name)));
        out
    }

    /// The rule between fields: `persistence_ignores` does not name the watched factor
    /// (`gate_factor`). The error names `persistence_ignores`.
    pub(crate) fn cross_problem(&self) -> Option<ParamError> {
        let (factor, ignores) = (&self.gate.gate_factor, &self.planning.persistence_ignores);
        (!ignores.is_empty() && ignores.split('+').any(|n| n == factor)).then(|| {
            ParamError::new(
                "persistence_ignores",
                format!("{ignores:?}"),
                NameRule::FactorList.range().unwrap_or(""),
            )
        })
    }

    /// Validate ranges (table above) without consuming the parameters.
    pub fn check_ref(&self) -> Result<(), ParamError> {
        match self.problems().into_iter().next() {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Validate ranges (table above) and return the checked parameters the agent is built from.
    pub fn check(self) -> Result<CheckedScaledParams, ParamError> {
        self.check_ref()?;
        Ok(CheckedScaledParams(self))
    }
}

/// [`ScaledParams`] whose ranges have been checked ([`ScaledParams::check`]); read them
/// through `Deref`. Whether the factor names fit a model is checked by
/// [`CheckedScaledParams::check_factors`].
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(transparent)]
pub struct CheckedScaledParams(ScaledParams);

impl std::ops::Deref for CheckedScaledParams {
    type Target = ScaledParams;
    fn deref(&self) -> &ScaledParams {
        &self.0
    }
}

impl TryFrom<ScaledParams> for CheckedScaledParams {
    type Error = ParamError;
    fn try_from(p: ScaledParams) -> Result<Self, ParamError> {
        p.check()
    }
}

impl CheckedScaledParams {
    /// The parameters.
    pub fn into_inner(self) -> ScaledParams {
        self.0
    }

    /// Checks the factor names against a model's structure: `gate_factor` names a
    /// factor (when the state gate or the pooling uses it) and every name of
    /// `persistence_ignores` is a next-time parent of it. The error names the key and
    /// the names allowed.
    pub fn check_factors(&self, structure: &Structure) -> Result<(), ParamError> {
        let factors = structure.factors();
        let (name, ignores) = (&self.gate.gate_factor, &self.planning.persistence_ignores);
        if self.gate.mode != GateMode::State && ignores.is_empty() {
            return Ok(());
        }
        let Some(f) = factors.iter().position(|f| &f.name == name) else {
            let names: Vec<&str> = factors.iter().map(|f| f.name.as_str()).collect();
            return Err(ParamError::new(
                "gate_factor",
                format!("{name:?}"),
                format!("one of the model's factors: {}", names.join(", ")),
            ));
        };
        if ignores.is_empty() {
            return Ok(());
        }
        let parents: Vec<&str> = factors[f]
            .parents
            .iter()
            .filter_map(|p| match p {
                Parent::Next(g) => Some(factors[*g].name.as_str()),
                Parent::Prev(_) => None,
            })
            .collect();
        if ignores.split('+').any(|n| !parents.contains(&n)) {
            return Err(ParamError::new(
                "persistence_ignores",
                format!("{ignores:?}"),
                format!(
                    "next-time parents of `{name}` joined by `+` (of: {}), or \"\" / none",
                    parents.join(", ")
                ),
            ));
        }
        Ok(())
    }
}

/// Hyperparameters of tabular Q-learning (§VI base policy).
///
/// | field | default | range | meaning |
/// |---|---|---|---|
/// | `alpha` | 0.1 | (0, 1] | learning rate |
/// | `discount` | 0.95 | [0, 1] | discount factor |
/// | `epsilon` | 1.0 | [0, 1] | initial exploration rate of ε-greedy |
/// | `epsilon_decay` | 0.999 | (0, 1] | multiplicative decay per [`crate::q_learning::QLearning::decay_epsilon`] call |
/// | `epsilon_min` | 0.05 | [0, epsilon] | floor of the decayed exploration rate |
/// | `bias_action` | `Some(1)` ("speed up") | < n_actions | action whose initial Q gets `bias` (§VI velocity preference) |
/// | `bias` | 1.0 | finite | initial Q of `bias_action` (others start at 0) |
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct QParams {
    /// Learning rate α.
    pub alpha: f64,
    /// Discount factor.
    pub discount: f64,
    /// Initial ε of ε-greedy.
    pub epsilon: f64,
    /// Multiplicative ε decay.
    pub epsilon_decay: f64,
    /// Minimum ε.
    pub epsilon_min: f64,
    /// Action favoured at initialisation.
    pub bias_action: Option<usize>,
    /// Initial Q value of `bias_action`.
    pub bias: f64,
}

impl Default for QParams {
    fn default() -> Self {
        Self {
            alpha: 0.1,
            discount: 0.95,
            epsilon: 1.0,
            epsilon_decay: 0.999,
            epsilon_min: 0.05,
            bias_action: Some(1),
            bias: 1.0,
        }
    }
}

impl QParams {
    /// Validate ranges (table above; `bias_action` is checked against `n_actions` by
    /// [`crate::q_learning::QLearning::new`]).
    pub fn check(&self) -> Result<(), ParamError> {
        in_half_open01("alpha", self.alpha)?;
        in_closed01("discount", self.discount)?;
        in_closed01("epsilon", self.epsilon)?;
        in_half_open01("epsilon_decay", self.epsilon_decay)?;
        if !(0.0..=self.epsilon).contains(&self.epsilon_min) {
            return Err(ParamError::new("epsilon_min", self.epsilon_min, "in [0, epsilon]"));
        }
        if !self.bias.is_finite() {
            return Err(ParamError::new("bias", self.bias, "finite"));
        }
        Ok(())
    }
}

/// Planner of the Bayesian-RL baseline (§VI).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Planner {
    /// Value iteration on the posterior-mean MDP, warm-started from the previous values.
    ValueIteration {
        /// Maximum sweeps per tick.
        iterations: u32,
        /// Stop when the largest value change is below this.
        tol: f64,
    },
    /// Finite-horizon lookahead (backward induction over `horizon` steps).
    Lookahead {
        /// Depth.
        horizon: usize,
    },
}

/// Transition model of the Bayesian-RL baseline.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum BayesModel {
    /// Flat Dirichlet posterior over joint transitions (the paper's baseline).
    Flat,
    /// The factored model of [`crate::structure::Structure`] (ablation).
    Factored(crate::structure::Structure),
}

/// Hyperparameters of the Bayesian-RL baseline.
///
/// | field | default | range | meaning |
/// |---|---|---|---|
/// | `prior_concentration` | 0.1 | >= 0 | Dirichlet prior count per successor state |
/// | `discount` | 0.95 | [0, 1) | discount of the planner |
/// | `planner` | ValueIteration{200, 1e-6} | iterations 1..=100000, tol > 0, horizon 1..=100 | |
/// | `model` | Flat | | flat or factored |
/// | `learn_online` | true | | update the posterior from `Controller::observe` at test time |
/// | `reward_prior` | 0.0 | finite | mean reward assumed for unvisited (s, a) |
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BayesRlParams {
    /// Prior concentration.
    pub prior_concentration: f64,
    /// Discount.
    pub discount: f64,
    /// Planner.
    pub planner: Planner,
    /// Transition model.
    pub model: BayesModel,
    /// Online updates at test time.
    pub learn_online: bool,
    /// Reward of unvisited pairs.
    pub reward_prior: f64,
}

impl Default for BayesRlParams {
    fn default() -> Self {
        Self {
            prior_concentration: 0.1,
            discount: 0.95,
            planner: Planner::ValueIteration {
                iterations: 200,
                tol: 1e-6,
            },
            model: BayesModel::Flat,
            learn_online: true,
            reward_prior: 0.0,
        }
    }
}

impl BayesRlParams {
    /// Validate ranges (table above).
    pub fn check(&self) -> Result<(), ParamError> {
        non_negative("prior_concentration", self.prior_concentration)?;
        if !(0.0..1.0).contains(&self.discount) {
            return Err(ParamError::new("discount", self.discount, "in [0, 1)"));
        }
        match self.planner {
            Planner::ValueIteration { iterations, tol } => {
                at_most(
                    "planner.iterations",
                    iterations as usize,
                    MAX_PLANNER_ITERATIONS,
                    "in 1..=100000 (value-iteration sweeps per tick)",
                )?;
                positive("planner.tol", tol)?;
            }
            Planner::Lookahead { horizon } => at_most(
                "planner.horizon",
                horizon,
                MAX_LOOKAHEAD,
                "in 1..=100 (lookahead steps per tick)",
            )?,
        }
        if !self.reward_prior.is_finite() {
            return Err(ParamError::new("reward_prior", self.reward_prior, "finite"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_match_paper() {
        let p = ScaledParams::default().check().unwrap();
        assert_eq!(
            (p.gate.omega, p.gate.epsilon, p.planning.gamma, p.scaling.varsigma),
            (0.425, 0.2, 0.5, 0.05)
        );
        QParams::default().check().unwrap();
        BayesRlParams::default().check().unwrap();
        ModelPriors::default().check().unwrap();
    }

    #[test]
    fn invalid_values_are_typed_errors() {
        let mut p = ScaledParams::default();
        p.gate.omega = -1.0;
        assert_eq!(p.check().unwrap_err().name, "omega");
        let q = QParams {
            alpha: 0.0,
            ..Default::default()
        };
        assert_eq!(q.check().unwrap_err().name, "alpha");
        let b = BayesRlParams {
            discount: 1.0,
            ..Default::default()
        };
        assert_eq!(b.check().unwrap_err().name, "discount");
    }
}
