//! Bin edges as a table of (continuous input -> expected discrete state) cases (§VI; docs/ARCHITECTURE.md §3).

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use unforeseen_discretizer::{Discretizer, State, distance_edges};
use unforeseen_sim::{
    Aspect, Bins, CrosswalkBins, DistanceEdges, LightPhase, Map, PedestrianSnapshot, SignalState, Snapshot, Walk,
};

/// The training intersection with the paper's bins as fixed edges and `noise`.
fn paper_bins(noise: f64) -> Map {
    with_bins(Bins {
        distance_edges: DistanceEdges::Goal(vec![0.0, 30.0, 60.0]),
        speed_edges: vec![1.5, 4.5, 7.5],
        observation_noise: noise,
    })
}

fn with_bins(bins: Bins) -> Map {
    Map { bins, ..Map::default() }
}

fn snapshot(distance: f64, speed: f64, light: LightPhase, peds_on: &[bool]) -> Snapshot {
    Snapshot {
        step: 0,
        time: 0.0,
        car_x: 90.0 - distance,
        car_speed: speed,
        surface: Vec::new(),
        distance_to_goal: distance,
        light,
        light_time_left: 1.0,
        signals: SignalState {
            road: Aspect::Lit(light),
            cross: Aspect::Lit(LightPhase::Red),
            walk_road: if light == LightPhase::Red {
                Walk::Walk
            } else {
                Walk::DontWalk
            },
            walk_cross: Walk::Walk,
        },
        vehicles: Vec::new(),
        vehicle_in_path: false,
        pedestrians: peds_on
            .iter()
            .map(|&on| PedestrianSnapshot {
                x: 66.0,
                y: 0.0,
                vx: 0.0,
                vy: 1.2,
                on_crosswalk: on,
            })
            .collect(),
    }
}

/// (distance to goal m, speed m/s, light, pedestrians on the crosswalk) -> (d, v, L, p).
type Case = (f64, f64, LightPhase, &'static [bool], (usize, usize, usize, usize));

#[test]
fn table_of_continuous_inputs_to_states() {
    use LightPhase::*;
    let disc = Discretizer::new(&paper_bins(0.0)).unwrap();
    // (distance to goal m, speed m/s, light, pedestrians on crosswalk) -> (d, v, L, p)
    let cases: &[Case] = &[
        (90.0, 3.0, Green, &[], (3, 1, 1, 0)),       // the start: far, slow, green, nobody
        (60.0001, 0.0, Red, &[false], (3, 0, 0, 0)), // just beyond the 60 m edge; pedestrian on the sidewalk
        (60.0, 1.5, Red, &[true], (2, 1, 0, 1)),     // on an edge: d counts edges strictly below, v edges at or below
        (45.0, 4.4999, Amber, &[], (2, 1, 0, 0)),    // amber is red for the agent
        (30.0, 4.5, Green, &[false, true], (1, 2, 1, 1)),
        (24.0, 7.5, Green, &[true], (1, 3, 1, 1)), // on the crosswalk at full speed: the crash-risk state
        (0.0001, 9.0, Red, &[], (1, 3, 0, 0)),
        (0.0, 9.0, Green, &[], (0, 3, 1, 0)),  // arrived
        (-3.0, 0.0, Green, &[], (0, 0, 1, 0)), // past the destination
    ];
    for &(distance, speed, light, peds, (d, v, l, p)) in cases {
        let got = disc.state(&snapshot(distance, speed, light, peds));
        assert_eq!(
            got,
            State { d, v, l, p },
            "distance {distance} speed {speed} light {light:?} peds {peds:?}"
        );
    }
}

#[test]
fn joint_index_matches_the_paper_layout_and_round_trips() {
    let disc = Discretizer::new(&paper_bins(0.0)).unwrap();
    assert_eq!(disc.n_states(), 64);
    assert_eq!(disc.encode(State { d: 0, v: 0, l: 0, p: 0 }), 0);
    assert_eq!(disc.encode(State { d: 0, v: 0, l: 0, p: 1 }), 1);
    assert_eq!(disc.encode(State { d: 0, v: 0, l: 1, p: 0 }), 2);
    assert_eq!(disc.encode(State { d: 0, v: 1, l: 0, p: 0 }), 4);
    assert_eq!(
        disc.encode(State { d: 2, v: 1, l: 1, p: 1 }),
        ((2 * 4 + 1) * 2 + 1) * 2 + 1
    );
    assert_eq!(disc.encode(State { d: 3, v: 3, l: 1, p: 1 }), 63);
    for s in 0..64 {
        assert_eq!(disc.encode(disc.decode(s)), s);
    }
}

#[test]
fn finer_bins_are_a_map_change() {
    let bins = Bins {
        distance_edges: DistanceEdges::Goal((0..8).map(|i| i as f64 * 10.0).collect()),
        speed_edges: vec![1.0, 2.0],
        observation_noise: 0.0,
    };
    let disc = Discretizer::new(&with_bins(bins)).unwrap();
    assert_eq!(disc.factor_sizes(), [9, 3, 2, 2]);
    assert_eq!(disc.n_states(), 108);
    assert_eq!(disc.distance_bin(75.0), 8);
    assert_eq!(disc.distance_bin(5.0), 1);
    for s in 0..disc.n_states() {
        assert_eq!(disc.encode(disc.decode(s)), s);
    }
}

#[test]
fn bad_edges_and_noise_are_typed_errors() {
    let mut bins = paper_bins(0.0);
    bins.bins.speed_edges = vec![1.0, 1.0];
    assert!(
        Discretizer::new(&bins)
            .unwrap_err()
            .to_string()
            .contains("bins.speed_edges")
    );
    let mut bins = paper_bins(0.0);
    bins.bins.distance_edges = DistanceEdges::Goal(vec![0.0, f64::NAN]);
    assert!(
        Discretizer::new(&bins)
            .unwrap_err()
            .to_string()
            .contains("bins.distance_edges")
    );
    assert!(Discretizer::new(&paper_bins(1.0)).is_err());
    assert!(Discretizer::new(&paper_bins(-0.1)).is_err());
}

#[test]
fn noise_free_observation_is_the_state_and_the_confusion_model_is_stochastic() {
    let clean = Discretizer::new(&paper_bins(0.0)).unwrap();
    let a = clean.likelihood_matrix();
    for o in 0..64 {
        for s in 0..64 {
            assert_eq!(a[o * 64 + s], if o == s { 1.0 } else { 0.0 });
        }
    }
    let noisy = Discretizer::new(&paper_bins(0.1)).unwrap();
    let a = noisy.likelihood_matrix();
    for s in 0..64 {
        let column: f64 = (0..64).map(|o| a[o * 64 + s]).sum();
        assert!((column - 1.0).abs() < 1e-12, "column {s} sums to {column}");
        assert!((a[s * 64 + s] - 0.9f64.powi(4)).abs() < 1e-12);
    }
    // Empirical frequency of a clean observation matches (1 - noise)^4 within 3 sigma.
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let truth = State { d: 2, v: 1, l: 1, p: 1 };
    let n = 20_000;
    let clean_hits = (0..n).filter(|_| noisy.observe(truth, &mut rng) == truth).count() as f64 / n as f64;
    let expect = 0.9f64.powi(4);
    let sigma = (expect * (1.0 - expect) / n as f64).sqrt();
    assert!((clean_hits - expect).abs() < 3.0 * sigma, "{clean_hits} vs {expect}");
}

/// Hand-worked crosswalk-anchored edges: `e1 = near + lead`, `e2 = e1 + max(approach,
/// v_max·Δt + v_max²/(2b))`.
#[test]
fn anchored_edges_follow_the_crosswalk_and_the_car() {
    // The training intersection: near edge 26 m from the goal; stopping 9 + 81/6 = 22.5 m.
    let mut map = Map::default();
    assert_eq!(distance_edges(&map), [0.0, 26.0, 60.0]);
    // The crosswalk at x = 81 (near edge 11 m), top speed 10.6: stopping 10.6 + 18.73 < 34.
    map.crosswalk.x = 81.0;
    map.vehicle.max_speed = 10.6;
    assert_eq!(distance_edges(&map), [0.0, 11.0, 45.0]);
    // 11 m/s braking at 2 m/s²: 11 + 121/4 = 41.25 m of approach.
    map.vehicle.max_speed = 11.0;
    map.vehicle.max_brake = 2.0;
    assert_eq!(distance_edges(&map), [0.0, 11.0, 52.25]);
    // A lead of 4 m and a 30 m approach: the paper's edges [0, 30, 60] on the intersection.
    let mut map = Map::default();
    map.bins.distance_edges = DistanceEdges::Crosswalk(CrosswalkBins {
        lead: 4.0,
        approach: 30.0,
    });
    assert_eq!(distance_edges(&map), [0.0, 30.0, 60.0]);
}

/// Wherever the crosswalk and whatever the car, the crosswalk lies wholly in d = 1 and
/// the approach d = 2 is at least the stopping distance from top speed.
#[test]
fn the_crosswalk_is_always_in_d1_and_the_approach_lets_the_car_stop() {
    let mut map = Map::default();
    for x in [10.0, 30.0, 45.0, 66.0, 82.0, 87.9] {
        for (speed, brake) in [(6.0, 5.0), (9.0, 3.0), (11.0, 1.5), (20.0, 0.5)] {
            map.crosswalk.x = x;
            map.vehicle.max_speed = speed;
            map.vehicle.max_brake = brake;
            let disc = Discretizer::new(&map).unwrap();
            let (near, far) = map.crosswalk_distance_to_goal();
            assert_eq!((disc.distance_bin(near), disc.distance_bin(far)), (1, 1), "x {x}");
            let e = disc.distance_edges();
            assert!(e[2] - e[1] >= speed + speed * speed / (2.0 * brake) - 1e-9);
        }
    }
}
