//! The crosswalk in the agent's states and plans (docs/ARCHITECTURE.md §3, §4.3): the
//! crash model's hazards worked by hand, and what the planner does in the crosswalk's
//! distance bin with a pedestrian on the crosswalk, under the crash model and the paper's
//! crash-risk states.

use unforeseen_agent::params::{CrashPlanning, ScaledParams};
use unforeseen_discretizer::{Discretizer, State};
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::crash_model;
use unforeseen_harness::fixtures::bundle;

/// Hazards of the default map by hand: speed bins [0, 0.5), [0.5, 4.5), [4.5, 7.5),
/// [7.5, 9] have middles 0.25, 2.5, 6, 8.25 m/s; one tick at top speed covers 9 m.
#[test]
fn hazards_by_hand() {
    let map = unforeseen_harness::maps::load("intersection").unwrap();
    let disc = Discretizer::new(&map).unwrap();
    let crash = crash_model(&map, &disc, 1.0);
    let s = |d, v, p| disc.encode(State { d, v, l: 1, p });
    let (maintain, speed_up, slow_down) = (0, 1, 2);
    let cases = [
        // (d, v, action) -> metres covered in the tick
        ((1, 3, maintain), 8.25),
        ((1, 3, speed_up), (8.25 + 9.0) / 2.0),
        ((1, 3, slow_down), (8.25 + 5.25) / 2.0),
        ((1, 2, slow_down), (6.0 + 3.0) / 2.0),
        ((1, 1, slow_down), 2.5 * 2.5 / 6.0), // stops within the tick
        ((1, 0, slow_down), 0.25 * 0.25 / 6.0),
        ((1, 0, maintain), 0.25),
        ((1, 0, speed_up), (0.25 + 3.25) / 2.0),
    ];
    for ((d, v, u), metres) in cases {
        let got = crash.hazard[u][s(d, v, 1)];
        assert!((got - metres / 9.0).abs() < 1e-12, "d {d} v {v} u {u}: {got}");
    }
    // No pedestrian, or not in the crosswalk's bin: no hazard.
    for u in 0..3 {
        assert_eq!(crash.hazard[u][s(1, 3, 0)], 0.0);
        assert_eq!(crash.hazard[u][s(2, 3, 1)], 0.0);
    }
    // A crashed episode is worth the crash and the forfeited goal: -25 - 50 nats below a
    // state without reward.
    assert!((crash.crashed - crash.neutral + 75.0).abs() < 1e-9);
}

/// In the crosswalk's bin at 4.5-7.5 m/s with a pedestrian on the crosswalk, the paper's
/// crash-risk states make every action a crash but speeding up a chance of arriving, so
/// the planner dashes; with the crash model it brakes.
#[test]
fn the_crash_model_brakes_where_the_crash_states_dash() {
    let map = unforeseen_harness::maps::load("intersection").unwrap();
    let disc = Discretizer::new(&map).unwrap();
    let o = disc.encode(State { d: 1, v: 2, l: 1, p: 1 });
    let act = |crash_model| {
        let mut params = ScaledParams::default();
        params.planning.crash_model = crash_model;
        let mut agent = Method::ScaledAlways.controller(bundle(), &params, &map).unwrap();
        agent.act(o)
    };
    let hazard = act(CrashPlanning::Hazard);
    let states = act(CrashPlanning::States);
    let psi = |d: &unforeseen_agent::controller::Decision| d.psi.as_ref().unwrap().to_vec();
    assert_eq!(
        hazard.action,
        2,
        "slow down under the crash model: psi {:?}",
        psi(&hazard)
    );
    assert_eq!(
        states.action,
        1,
        "speed up under the crash states: psi {:?}",
        psi(&states)
    );
}
