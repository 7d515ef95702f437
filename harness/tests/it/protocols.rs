//! The two evaluation protocols: a method that does not learn across episodes gives the
//! same results zero-shot (fresh controller per episode, in parallel) as continual (one
//! controller, in order), and zero-shot results do not depend on the number of threads.

use unforeseen_harness::fixtures;

use unforeseen_agent::params::ScaledParams;
use unforeseen_harness::episodes::EpisodeResult;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::episodes::{run_agent_episodes, run_controller};
use unforeseen_harness::progress::NoProgress;

/// Results without the wall-clock fields.
fn untimed(results: Vec<EpisodeResult>) -> Vec<EpisodeResult> {
    results
        .into_iter()
        .map(|r| EpisodeResult {
            decide_ns: 0,
            reasoning_ns: 0,
            ..r
        })
        .collect()
}

fn zero_shot(method: Method, threads: usize) -> Vec<EpisodeResult> {
    let jaywalk = unforeseen_harness::maps::load("jaywalk").unwrap();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let params = ScaledParams::default();
    let hidden = NoProgress;
    untimed(pool.install(|| {
        run_agent_episodes(
            Protocol::ZeroShot,
            &jaywalk,
            fixtures::bundle(),
            &params,
            method,
            4,
            5,
            &hidden,
        )
        .unwrap()
    }))
}

#[test]
fn methods_that_do_not_learn_across_episodes_give_the_same_results_under_both_protocols() {
    let jaywalk = unforeseen_harness::maps::load("jaywalk").unwrap();
    let params = ScaledParams::default();
    for method in [Method::QLearning, Method::ScaledNoLearning] {
        assert!(!method.learns_across_episodes(&params));
        // The real continual loop: one controller, episodes in order.
        let mut controller = method.controller(fixtures::bundle(), &params, &jaywalk).unwrap();
        let continual = untimed(run_controller(&jaywalk, controller.as_mut(), method, 4, 5, &NoProgress).unwrap());
        assert_eq!(continual, zero_shot(method, 2), "{method}");
    }
}

#[test]
fn zero_shot_results_do_not_depend_on_the_number_of_threads() {
    for method in [Method::Scaled, Method::BayesRl] {
        assert_eq!(zero_shot(method, 1), zero_shot(method, 2), "{method}");
    }
}
