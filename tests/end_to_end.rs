//! End to end (§VI): train on the intersection, then meet the jaywalker. On a fixed
//! seed, Q-learning drives on and hits the pedestrian; the scaled agent notices the
//! surprise, reasons, and avoids it.

mod common;

use unforeseen::experiments::{evaluate, trace};
use unforeseen::methods::Method;
use unforeseen::metrics::Aggregate;
use unforeseen_agent::params::ScaledParams;

#[test]
fn scaled_avoids_the_jaywalker_that_q_learning_hits() {
    let bundle = common::bundle();
    let jaywalk = unforeseen::maps::load("jaywalk").unwrap();
    let params = ScaledParams::default();

    let (q, q_ticks) = trace(bundle, &params, Method::QLearning, &jaywalk, 11).unwrap();
    assert!(q.collision, "Q-learning should hit the jaywalker: {q:?}");
    assert!(q_ticks.iter().all(|t| !t.reasoned), "Q-learning never reasons");

    let (s, s_ticks) = trace(bundle, &params, Method::Scaled, &jaywalk, 11).unwrap();
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
    assert!(jay[0].theta.unwrap() > params.epsilon);
    assert!(s.reasoning_ticks < s.ticks, "reasoning is triggered, not constant");
}

#[test]
fn over_a_few_episodes_scaled_beats_q_learning_on_the_jaywalk() {
    let bundle = common::bundle();
    let jaywalk = unforeseen::maps::load("jaywalk").unwrap();
    let params = ScaledParams::default();
    let run = |m: Method| {
        let mut c = m.controller(bundle, &params).unwrap();
        Aggregate::of(&evaluate(&jaywalk, c.as_mut(), m, 10, 5, true).unwrap())
    };
    let q = run(Method::QLearning);
    let s = run(Method::Scaled);
    assert!(q.collision_rate >= 0.8, "Q-learning collisions {q:?}");
    assert!(s.success_rate >= 0.9, "scaled success {s:?}");
    assert!(s.mean_reward > q.mean_reward);
    assert!(s.inference_rate > 0.0 && s.inference_rate < 1.0);
}
