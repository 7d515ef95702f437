//! End to end (§VI): train on the intersection, then meet the jaywalker. On a fixed
//! seed, Q-learning drives on and hits the pedestrian; the scaled agent notices the
//! surprise, reasons, and avoids it.

use unforeseen_harness::fixtures;

use unforeseen_agent::params::ScaledParams;
use unforeseen_agent::persist::AgentBundle;
use unforeseen_harness::episodes::Aggregate;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::episodes::learn;
use unforeseen_harness::episodes::run_controller;
use unforeseen_harness::episodes::trace;
use unforeseen_harness::progress::NoProgress;

#[test]
fn scaled_avoids_the_jaywalker_that_q_learning_hits() {
    let bundle = fixtures::bundle();
    let jaywalk = unforeseen_harness::maps::load("jaywalk").unwrap();
    let params = ScaledParams::default();

    let (q, q_ticks) = trace(bundle, &params, Method::QLearning, &jaywalk, 11, Protocol::ZeroShot, 0).unwrap();
    assert!(q.collision, "Q-learning should hit the jaywalker: {q:?}");
    assert!(q_ticks.iter().all(|t| !t.reasoned), "Q-learning never reasons");

    let (s, s_ticks) = trace(bundle, &params, Method::Scaled, &jaywalk, 11, Protocol::ZeroShot, 0).unwrap();
    assert!(
        !s.collision && s.success,
        "the scaled agent should avoid the jaywalker and arrive: {s:?}"
    );
    // It reasoned while the pedestrian was on the crosswalk on green, and only on some ticks.
    let jay: Vec<_> = s_ticks
        .iter()
        .filter(|t| t.state.p == 1 && t.state.l == 1 && !t.policy.is_empty())
        .collect();
    assert!(!jay.is_empty(), "the jaywalker should be seen");
    assert!(
        jay[0].reasoned,
        "the first jaywalk tick must trigger reasoning: {:?}",
        jay[0]
    );
    assert!(jay[0].theta.unwrap() > params.gate.epsilon);
    // The gate reads the state (§VI): before any test-time learning it stays open on every
    // tick the pedestrian is on the crosswalk under green, and is closed before they appear.
    assert!(
        jay.iter().all(|t| t.reasoned),
        "reasoning lasts while the jaywalker crosses"
    );
    let before: Vec<_> = s_ticks.iter().take_while(|t| t.state.p == 0).collect();
    assert!(
        !before.is_empty() && before.iter().all(|t| !t.reasoned),
        "no reasoning before the event"
    );
    assert!(s.reasoning_ticks < s.ticks, "reasoning is triggered, not constant");
}

/// Fig. 9's shape on the trained model, over continual episodes: the gate's surprise at the
/// event falls, `P(p=1 | L=1, d=2)` and the habit's `P(slow down)` rise, reasoning fades,
/// and learning never costs a crash.
#[test]
fn test_time_learning_makes_the_jaywalk_familiar_without_a_crash() {
    let bundle = fixtures::bundle();
    let jaywalk = unforeseen_harness::maps::load("jaywalk").unwrap();
    let points = learn(bundle, &ScaledParams::default(), &jaywalk, 30, 3, &NoProgress).unwrap();
    let (first, last) = (&points[0], points.last().unwrap());
    assert!(points.iter().all(|p| p.success), "a crash while learning: {points:?}");
    let surprise = |p: &unforeseen_harness::episodes::LearnPoint| p.event_surprise_bits.unwrap();
    assert!(surprise(last) < 0.5 * surprise(first), "surprise {first:?} -> {last:?}");
    assert!(last.p_pedestrian_green_d2.unwrap() > first.p_pedestrian_green_d2.unwrap() + 0.3);
    assert!(last.p_slow_down > first.p_slow_down, "habit {first:?} -> {last:?}");
    assert!(
        last.reasoning_ticks < first.reasoning_ticks,
        "reasoning {first:?} -> {last:?}"
    );
}

#[test]
fn over_a_few_episodes_scaled_beats_q_learning_on_the_jaywalk() {
    let bundle = fixtures::bundle();
    let jaywalk = unforeseen_harness::maps::load("jaywalk").unwrap();
    let params = ScaledParams::default();
    let run = |m: Method| {
        let mut c = m.controller(bundle, &params, &jaywalk).unwrap();
        Aggregate::of(&run_controller(&jaywalk, c.as_mut(), m, 10, 5, &NoProgress).unwrap())
    };
    let q = run(Method::QLearning);
    let s = run(Method::Scaled);
    assert!(q.collision_rate >= 0.8, "Q-learning collisions {q:?}");
    assert!(s.success_rate >= 0.9, "scaled success {s:?}");
    assert!(s.mean_reward > q.mean_reward);
    assert!(s.inference_rate > 0.0 && s.inference_rate < 1.0);
}

/// `trace --episode N --protocol continual` shows the episode a continual evaluation meets
/// at index N: the same outcome, return and reasoning as `evaluate`'s N-th episode.
#[test]
fn a_traced_continual_episode_is_the_one_a_continual_run_meets() {
    let bundle = fixtures::bundle();
    let map = unforeseen_harness::maps::load("stop_midway").unwrap();
    let params = ScaledParams::default();
    let mut agent = Method::Scaled.controller(bundle, &params, &map).unwrap();
    let run = run_controller(&map, agent.as_mut(), Method::Scaled, 4, 3, &NoProgress).unwrap();
    let (traced, ticks) = trace(bundle, &params, Method::Scaled, &map, 3, Protocol::Continual, 3).unwrap();
    let last = &run[3];
    assert_eq!(
        (traced.ret, traced.success, traced.ticks, traced.reasoning_ticks),
        (last.ret, last.success, last.ticks, last.reasoning_ticks)
    );
    assert_eq!(ticks.iter().filter(|t| t.reasoned).count() as u32, last.reasoning_ticks);
}

/// Where the event is genuinely uncertain (on jaywalk_late the car meets the crosswalk on
/// green about as often with a pedestrian as without), the paper's trigger keeps firing
/// on either outcome; with the endorsed baseline (the default) reasoning fades once the
/// habit does what reasoning chose, and learning causes no crash.
#[test]
fn reasoning_fades_with_learning_where_the_event_is_uncertain() {
    let bundle = fixtures::bundle();
    let map = unforeseen_harness::maps::load("jaywalk_late").unwrap();
    let reasoning = |params: &ScaledParams| {
        let points = learn(bundle, params, &map, 30, 3, &NoProgress).unwrap();
        assert!(points.iter().all(|p| p.success), "a crash while learning: {points:?}");
        let ticks = |ps: &[unforeseen_harness::episodes::LearnPoint]| ps.iter().map(|p| p.reasoning_ticks).sum::<u32>();
        (ticks(&points[..5]), ticks(&points[25..]))
    };
    let (first, last) = reasoning(&ScaledParams::default());
    assert!(last < first, "reasoning ticks, first 5 episodes {first}, last 5 {last}");
    let mut paper = ScaledParams::default();
    paper.gate.gate_baseline = unforeseen_agent::params::GateBaseline::None;
    let (_, last_paper) = reasoning(&paper);
    assert!(
        last < last_paper,
        "last 5 episodes: {last} reasoning ticks, paper's trigger {last_paper}"
    );
}

/// A pedestrian who walks slowly keeps the crosswalk under green for 6-8 ticks. The car
/// can stop in time, and the scaled agent does, in every episode, with the crash model
/// (the default) and with the paper's crash states. With the paper's states and the
/// paper's distance edges (`d = 1` from 4 m before the crosswalk) it is the tree's first
/// step that matters (EXPERIMENTS.md, item 6): the braking car enters the crash-risk
/// state (d = 1, still moving) and, with the planning model absorbing from the root on
/// (`root_step=absorbing`), every action from there ends alike; that planner loses
/// episodes here, which shows the test sees the difference. (With the crash model no
/// state is a crash, and with the default edges the braking car stops before `d = 1`, so
/// the root step does not matter there.)
#[test]
fn scaled_waits_for_the_slow_walker() {
    let success = |bundle: &AgentBundle, map: &unforeseen_sim::Map, params: &ScaledParams| {
        let mut agent = Method::Scaled.controller(bundle, params, map).unwrap();
        Aggregate::of(&run_controller(map, agent.as_mut(), Method::Scaled, 10, 7, &NoProgress).unwrap()).success_rate
    };
    let map = unforeseen_harness::maps::load("slow_walker").unwrap();
    let mut states = ScaledParams::default();
    states.planning.crash_model = unforeseen_agent::params::CrashPlanning::States;
    assert_eq!(success(fixtures::bundle(), &map, &ScaledParams::default()), 1.0);
    assert_eq!(success(fixtures::bundle(), &map, &states), 1.0);
    let (papers, papers_map) = (fixtures::papers_bundle(), fixtures::papers_bins("slow_walker"));
    assert_eq!(success(papers, &papers_map, &states), 1.0);
    let mut absorbing = states;
    absorbing.planning.root_step = unforeseen_agent::params::RootStep::Absorbing;
    assert!(
        success(papers, &papers_map, &absorbing) < 1.0,
        "the absorbing root should lose a slow-walker episode"
    );
}
