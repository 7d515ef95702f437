//! Golden digests: a few trajectories and decisions, hashed bit for bit, so that no
//! refactoring can change what an agent learns or decides without this test saying so
//! (in the spirit of rapier's snapshot-portability test). A digest covers, per tick, the
//! true and the observed state, the action, whether it reasoned, the surprise, theta, the
//! policy, psi and the reward as exact bits, and the car's position and speed; and the
//! trained agent's tables.
//!
//! When a change is meant to alter behaviour, the new digests are printed by the failing
//! assertion; update them in the same commit and say why in its message.

use std::fmt::Write;
use unforeseen_agent::params::{ActionSelection, CompetenceCheck, CrashPlanning, ScaledParams, TieBreak};
use unforeseen_agent::persist::AgentBundle;
use unforeseen_env::seeds::content_hash;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::episodes::trace;
use unforeseen_harness::episodes::{EpisodeResult, Tick};
use unforeseen_harness::fixtures;
use unforeseen_harness::training::{TimeoutAs, train};

fn bits(x: f64) -> String {
    format!("{:016x}", x.to_bits())
}

fn opt_bits(x: Option<f64>) -> String {
    x.map_or_else(|| "-".into(), bits)
}

fn push_episode(out: &mut String, result: &EpisodeResult, ticks: &[Tick]) {
    for t in ticks {
        let _ = write!(
            out,
            "{} {:?} {:?} {} {} {} {} [",
            t.step,
            t.state,
            t.observed,
            t.action.index(),
            t.reasoned,
            opt_bits(t.surprise),
            opt_bits(t.theta)
        );
        for p in &t.policy {
            out.push_str(&bits(*p));
        }
        out.push_str("] [");
        for p in t.psi.iter().flatten() {
            out.push_str(&bits(*p));
        }
        let _ = writeln!(
            out,
            "] {} {} {} {}",
            bits(t.reward),
            bits(t.snapshot.car_x),
            bits(t.snapshot.car_speed),
            t.snapshot.pedestrians.len()
        );
    }
    let _ = writeln!(
        out,
        "= {} {} {} {} {} {} {}",
        bits(result.ret),
        result.success,
        result.collision,
        result.timeout,
        result.ticks,
        result.reasoning_ticks,
        opt_bits(result.jaywalk_surprise)
    );
}

/// The trained agent's tables (Q-table, world-model counts, Bayesian-RL counts), without
/// its metadata.
fn agent_digest(bundle: &AgentBundle) -> String {
    let mut bundle = bundle.clone();
    bundle.meta.clear();
    // The tables of before: the crash model (docs/ARCHITECTURE.md §4.3) is an addition,
    // whose own values `crosswalk::hazards_by_hand` checks.
    assert!(bundle.world_model.crash_model().is_some());
    bundle.world_model.set_crash_model(None).unwrap();
    content_hash(bundle.to_ron_string().as_bytes())
}

/// Every method's episodes 0..3 on `map` zero-shot, and the scaled agent's episode 5 of a
/// continual run (after learning from episodes 0..5).
fn episodes_digest(bundle: &AgentBundle, map: &unforeseen_sim::Map, params: &ScaledParams) -> String {
    let mut out = String::new();
    let methods = [
        Method::QLearning,
        Method::BayesRl,
        Method::Scaled,
        Method::ScaledNoLearning,
        Method::BrakeOnPedestrian,
        Method::NeverBrake,
    ];
    for method in methods {
        for ep in 0..3 {
            let (result, ticks) = trace(bundle, params, method, map, 7, Protocol::ZeroShot, ep).unwrap();
            let _ = writeln!(out, "{} {ep}", method.name());
            push_episode(&mut out, &result, &ticks);
        }
    }
    let (result, ticks) = trace(bundle, params, Method::Scaled, map, 7, Protocol::Continual, 5).unwrap();
    out.push_str("scaled continual 5\n");
    push_episode(&mut out, &result, &ticks);
    content_hash(out.as_bytes())
}

/// The jaywalk with observation noise, so the noisy observation path is covered too;
/// with the paper's distance edges when `papers`.
fn noisy_jaywalk(papers: bool) -> unforeseen_sim::Map {
    let text = "Map(base: \"jaywalk\", name: \"noisy_jaywalk\", bins: (observation_noise: 0.1))";
    let mut map = unforeseen_sim::Map::from_str_named("noisy_jaywalk.ron", text, &unforeseen_sim::embedded::base)
        .expect("valid map");
    if papers {
        let papers = fixtures::papers_bins("jaywalk").bins;
        map.bins.distance_edges = papers.distance_edges;
        map.bins.speed_edges = papers.speed_edges;
    }
    map
}

/// The paper's agent (docs/ARCHITECTURE.md §4.3, §4.9, §4.11): the scaled agent's default
/// parameters without the competence check (`competence = surprise-only`), with the
/// paper's crash-risk states (`crash_model = states`) and acting on the mode of the policy
/// (`action_selection = mode`) as chosen (`tie_break = chosen`), whose decisions the
/// digests below recorded before any of these was added.
fn papers_agent() -> ScaledParams {
    let mut params = ScaledParams::default();
    params.gate.competence = CompetenceCheck::SurpriseOnly;
    params.planning.crash_model = CrashPlanning::States;
    params.scaling.action_selection = ActionSelection::Mode;
    params.scaling.tie_break = TieBreak::Chosen;
    params
}

/// The agent's digest and its episodes' on the intersection, the jaywalk and the noisy
/// jaywalk, all with the paper's distance edges, under [`papers_agent`].
fn digests(bundle: &AgentBundle) -> [String; 4] {
    papers_digests(bundle, &papers_agent())
}

/// [`digests`] with the scaled agent's parameters `params`.
fn papers_digests(bundle: &AgentBundle, params: &ScaledParams) -> [String; 4] {
    [
        agent_digest(bundle),
        episodes_digest(bundle, &fixtures::papers_bins("intersection"), params),
        episodes_digest(bundle, &fixtures::papers_bins("jaywalk"), params),
        episodes_digest(bundle, &noisy_jaywalk(true), params),
    ]
}

/// The hand-back rule before the safe hand-back (`handback = theta`, the ablation) decides
/// exactly as the code before it did: the digests recorded on that code.
#[test]
fn the_theta_handback_ablation_reproduces_the_decisions_of_before() {
    let mut params = papers_agent();
    params.set_str("handback", "theta").unwrap();
    assert_eq!(
        papers_digests(fixtures::papers_bundle(), &params),
        GOLDEN_THETA_HANDBACK
    );
}

/// Training with time-outs taken as terminal states reproduces the agent, and every
/// decision, of the code before the episode API (`Env`): the digests below were
/// recorded on that code.
#[test]
fn timeouts_as_terminal_reproduce_the_agents_and_decisions_of_before() {
    let mut cfg = fixtures::small_config(7);
    cfg.timeout_as = TimeoutAs::Termination;
    let (bundle, _) = train(&fixtures::papers_bins("intersection"), &cfg).unwrap();
    assert_eq!(digests(&bundle), GOLDEN_TIMEOUT_AS_TERMINATION);
}

/// The default training (time-outs truncate: the learners bootstrap through them). None of
/// this agent's training episodes times out, so it is the agent of before too (the two
/// settings differ where episodes time out: `timeouts_truncate_and_learners_bootstrap`);
/// with the paper's edges and as the paper's agent it decides as before.
#[test]
fn trained_agent_and_decisions_are_unchanged() {
    let (_, log) = train(&fixtures::papers_bins("intersection"), &fixtures::small_config(7)).unwrap();
    assert_eq!(log.timeouts, 0);
    assert_eq!(digests(fixtures::papers_bundle()), GOLDEN);
}

/// Planning with the crash model (`crash_model = hazard`, docs/ARCHITECTURE.md §4.3) on
/// the paper's edges, without the competence check: the same agent tables; the episodes
/// change where the planner reasons (digests recorded when the option was added).
#[test]
fn the_crash_model_decisions_are_recorded() {
    let mut params = papers_agent();
    params.planning.crash_model = CrashPlanning::Hazard;
    assert_eq!(papers_digests(fixtures::papers_bundle(), &params), GOLDEN_CRASH_MODEL);
}

/// The competence check (docs/ARCHITECTURE.md §4.11) with the paper's edges and crash
/// states: the same agent tables; the episodes change where the check sends a tick to
/// reasoning (digests recorded when the check was added).
#[test]
fn the_competence_check_decisions_are_recorded() {
    let mut params = papers_agent();
    params.gate.competence = CompetenceCheck::Regret;
    assert_eq!(papers_digests(fixtures::papers_bundle(), &params), GOLDEN_COMPETENCE);
}

/// The default agent's digests on the default maps with the scaled agent's parameters
/// `params`.
fn default_digests(params: &ScaledParams) -> [String; 4] {
    let bundle = fixtures::bundle();
    [
        agent_digest(bundle),
        episodes_digest(bundle, &unforeseen_harness::maps::load("intersection").unwrap(), params),
        episodes_digest(bundle, &unforeseen_harness::maps::load("jaywalk").unwrap(), params),
        episodes_digest(bundle, &noisy_jaywalk(false), params),
    ]
}

/// The default agent on the default maps: distance edges anchored at the crosswalk's near
/// edge, the first speed edge at 0.5 m/s, the crash model, the competence check and the
/// mode over the outcomes the model tells apart, and the safest of the actions the model
/// cannot tell from the chosen one (digests recorded when that tie-break became the
/// default; the agent's tables are those of the speed edge at 1.5 m/s: no training car
/// drives between 0.5 and 1.5 m/s).
#[test]
fn the_default_agent_decisions_are_recorded() {
    assert_eq!(default_digests(&ScaledParams::default()), GOLDEN_DEFAULT);
}

/// The default agent acting on the chosen action (`tie_break = chosen`, the ablation)
/// decides exactly as the default did before the tie-break: the digests recorded when
/// the mode over outcomes became the default.
#[test]
fn the_chosen_action_ablation_reproduces_the_default_of_before() {
    let mut params = ScaledParams::default();
    params.scaling.tie_break = TieBreak::Chosen;
    assert_eq!(default_digests(&params), GOLDEN_DEFAULT_CHOSEN);
}

/// The default agent acting on the mode of the policy as chosen (`action_selection =
/// mode`, `tie_break = chosen`, the ablations) decides exactly as the default did before
/// the mode over outcomes: the digests recorded when the speed edge at 0.5 m/s became the
/// default.
#[test]
fn the_policy_mode_ablation_reproduces_the_default_of_before() {
    let mut params = ScaledParams::default();
    params.scaling.action_selection = ActionSelection::Mode;
    params.scaling.tie_break = TieBreak::Chosen;
    assert_eq!(default_digests(&params), GOLDEN_DEFAULT_POLICY_MODE);
}

/// On a map whose episodes often time out (the tiny map: 12 ticks), the two settings
/// train different agents: a truncation is not terminal, so Bayesian RL records the
/// transition it was instead of an absorbing one, and Q-learning bootstraps through it.
/// Every episode ends in exactly one transition: a terminal one unless it timed out and
/// time-outs truncate.
#[test]
fn timeouts_truncate_and_learners_bootstrap() {
    let map = fixtures::tiny_map();
    let mut cfg = fixtures::small_config(3);
    cfg.episodes = 60;
    let (truncating, log) = train(&map, &cfg).unwrap();
    cfg.timeout_as = TimeoutAs::Termination;
    let (terminating, log_t) = train(&map, &cfg).unwrap();
    assert!(
        log.timeouts > 0 && log_t.timeouts > 0,
        "the tiny map's episodes time out"
    );
    let terminal = |b: &AgentBundle| b.bayes_rl.terminal_counts().iter().sum::<f64>();
    assert_eq!(terminal(&truncating), (cfg.episodes - log.timeouts) as f64);
    assert_eq!(terminal(&terminating), cfg.episodes as f64);
    assert_ne!(truncating.q_learning, terminating.q_learning);
}

/// Digests of [`timeouts_as_terminal_reproduce_the_agents_and_decisions_of_before`]: the
/// agent and the zero-shot episodes as recorded on the code before the episode API; the
/// continual episodes of the intersection and the noisy jaywalk re-recorded when test-time
/// learning of `A` started keeping its structural zeros (agent/src/learning.rs `update_a`).
const GOLDEN_TIMEOUT_AS_TERMINATION: [&str; 4] = [
    "10356990b4c98627",
    "06f2fc67eefe1e0a",
    "fd86969ccbedd97b",
    "42645404ec0bad2e",
];

/// Digests of [`trained_agent_and_decisions_are_unchanged`].
const GOLDEN: [&str; 4] = GOLDEN_TIMEOUT_AS_TERMINATION;

/// Digests of [`the_crash_model_decisions_are_recorded`].
const GOLDEN_CRASH_MODEL: [&str; 4] = [
    "10356990b4c98627",
    "a82992ccf57b2219",
    "edd28553a6b36eb0",
    "69af290d4e23083f",
];

/// Digests of [`the_competence_check_decisions_are_recorded`].
/// The jaywalk's episodes are those of before; the intersection's change.
const GOLDEN_COMPETENCE: [&str; 4] = [
    "10356990b4c98627",
    "31a9127450a408ad",
    "fd86969ccbedd97b",
    "42645404ec0bad2e",
];

/// Digests of [`the_default_agent_decisions_are_recorded`].
const GOLDEN_DEFAULT: [&str; 4] = [
    "9be644aee445c8c1",
    "77b3c08e3a53320d",
    "8abc2112411a7bf0",
    "ac5c9162c63e333c",
];

/// Digests of [`the_chosen_action_ablation_reproduces_the_default_of_before`]: those of the
/// default agent before the tie-break ([`GOLDEN_DEFAULT`] until then).
const GOLDEN_DEFAULT_CHOSEN: [&str; 4] = [
    "9be644aee445c8c1",
    "2e6b2cd9a66dc19a",
    "e7b071d234a24639",
    "27c78f87316b00c7",
];

/// Digests of [`the_policy_mode_ablation_reproduces_the_default_of_before`]: those of the
/// default agent before the mode over outcomes ([`GOLDEN_DEFAULT`] until then).
const GOLDEN_DEFAULT_POLICY_MODE: [&str; 4] = [
    "9be644aee445c8c1",
    "2e6b2cd9a66dc19a",
    "9c7508c681ca9542",
    "9f97ef27381e1941",
];

/// Digests of [`the_theta_handback_ablation_reproduces_the_decisions_of_before`]: those of
/// the code before the safe hand-back (the default's, [`GOLDEN`], until then), with the
/// continual episodes re-recorded as [`GOLDEN_TIMEOUT_AS_TERMINATION`]'s.
const GOLDEN_THETA_HANDBACK: [&str; 4] = [
    "10356990b4c98627",
    "06f2fc67eefe1e0a",
    "fd86969ccbedd97b",
    "42645404ec0bad2e",
];
