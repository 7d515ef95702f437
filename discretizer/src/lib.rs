//! Continuous world snapshot -> the paper's discrete state (§VI; docs/ARCHITECTURE.md §3).
//!
//! The paper's state space is four factors:
//!
//! | factor | values | meaning |
//! |---|---|---|
//! | `d` | `0..=n_d-1` | distance-to-destination bin (0 = arrived, 1 = the crosswalk zone, highest = far) |
//! | `v` | `0..=n_v-1` | speed bin |
//! | `L` | `0, 1` | traffic light: 0 red (amber counts as red), 1 green |
//! | `p` | `0, 1` | an obstacle is in the car's path: a pedestrian on the crosswalk, or a vehicle in its lane ahead up to the junction box's far edge or crossing in the box (`Snapshot::obstacle_in_path`; on a map without traffic, the paper's pedestrian on the crosswalk) |
//!
//! with joint index `s = ((d * n_v + v) * 2 + L) * 2 + p` (64 states for the default
//! 4 x 4 x 2 x 2). Bin edges come from the map ([`unforeseen_sim::Bins`]), so a finer
//! state space is a map change, not a code change.
//!
//! The paper's `d = 1` is the intersection. By default the distance edges are anchored
//! to the crosswalk ([`distance_edges`]), so that `d` means the same on every map: `d = 1`
//! from the crosswalk's near edge to the goal (a car observed there has entered the
//! crosswalk), `d = 2` the approach in which the car can still stop, `d = 3` beyond. On
//! the training intersection these are `[0, 26, 60]`, the paper's `[0, 30, 60]` with its
//! first edge moved 4 m to the crosswalk; a map that moves the crosswalk moves them with
//! it. A map can give the paper's edges as a list (`distance_edges: [0.0, 30.0, 60.0]`).
//!
//! ```
//! use unforeseen_discretizer::Discretizer;
//! let mut map = unforeseen_sim::Map::default();
//! let disc = Discretizer::new(&map).unwrap();
//! assert_eq!(disc.distance_edges(), [0.0, 26.0, 60.0]);
//! assert_eq!(disc.factor_sizes(), [4, 4, 2, 2]);
//! assert_eq!(disc.distance_bin(45.0), 2);
//! assert_eq!(disc.speed_bin(9.0), 3);
//! map.crosswalk.x = 81.0; // near edge 11 m before the goal
//! assert_eq!(Discretizer::new(&map).unwrap().distance_edges(), [0.0, 11.0, 45.0]);
//! ```

use rand::{Rng, RngExt};
use unforeseen_sim::{DistanceEdges, LightPhase, Map, Snapshot};

/// One discrete state of the paper's §VI state space, factor by factor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
pub struct State {
    /// Distance-to-destination bin (0 = arrived).
    pub d: usize,
    /// Speed bin (0 = standing).
    pub v: usize,
    /// Light: 0 red or amber, 1 green.
    pub l: usize,
    /// Pedestrian on the crosswalk: 0 no, 1 yes.
    pub p: usize,
}

/// Why a discretizer could not be built from a map's bins.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum DiscretizerError {
    /// Bin edges must be finite and strictly increasing.
    #[error("bins.{field}: edges must be finite and strictly increasing, got {edges:?}")]
    BadEdges {
        /// `distance_edges` or `speed_edges`.
        field: &'static str,
        /// The offending edges.
        edges: Vec<f64>,
    },
    /// The observation-noise probability must lie in [0, 1).
    #[error("bins.observation_noise: must be in [0, 1), got {0}")]
    BadNoise(f64),
}

/// The distance edges of a map, m to the goal, strictly increasing.
///
/// A list in the map is used as written. `Crosswalk(lead, approach)` gives three edges
/// anchored to the crosswalk's near edge, `n` m before the goal:
///
/// ```text
/// e1 = n + lead                                       d = 1: the crosswalk zone, (0, e1]
/// e2 = e1 + max(approach, v_max·Δt + v_max² / (2 b))  d = 2: the approach, (e1, e2]
///                                                     d = 3: beyond e2
/// ```
///
/// where `v_max` is the car's top speed, `b` its braking and `Δt` a decision tick: the
/// approach is never shorter than the distance in which a car at top speed, braking one
/// tick after it sees a pedestrian, comes to a stop. Under `dynamics: Forces` the
/// `v_max² / (2 b)` term is the force model's stopping distance on the road's default
/// friction (dead time, lag phase, then friction-limited deceleration:
/// `unforeseen_sim::dynamics::stopping_distance`). On the training intersection
/// (`n = 26`, 9 m/s, 3 m/s², 1 s: 22.5 m) the default `Crosswalk(lead: 0.0, approach:
/// 34.0)` gives `[0, 26, 60]`, and `Crosswalk(lead: 4.0, approach: 30.0)` the paper's
/// `[0, 30, 60]`.
pub fn distance_edges(map: &Map) -> Vec<f64> {
    match &map.bins.distance_edges {
        DistanceEdges::Goal(edges) => edges.clone(),
        DistanceEdges::Crosswalk(c) => {
            let near = map.crosswalk_distance_to_goal().0;
            let v = &map.vehicle;
            let stopping = v.max_speed * map.episode.decision_dt
                + unforeseen_sim::dynamics::stopping_distance(v, v.max_speed, map.road.friction);
            let e1 = near + c.lead;
            vec![0.0, e1, e1 + c.approach.max(stopping)]
        }
    }
}

/// Maps [`Snapshot`]s to discrete states using a map's bin edges (docs/ARCHITECTURE.md §3).
#[derive(Debug, Clone, PartialEq)]
pub struct Discretizer {
    distance_edges: Vec<f64>,
    speed_edges: Vec<f64>,
    noise: f64,
}

impl Discretizer {
    /// Number of light values (red, green).
    pub const LIGHT_VALUES: usize = 2;
    /// Number of pedestrian values (absent, present).
    pub const PEDESTRIAN_VALUES: usize = 2;

    /// Builds a discretizer from a map's bins (its distance edges derived by
    /// [`distance_edges`]), checking the edges.
    pub fn new(map: &Map) -> Result<Self, DiscretizerError> {
        let bins = &map.bins;
        let check = |field, edges: &[f64]| {
            let ok = edges.iter().all(|e| e.is_finite()) && edges.windows(2).all(|w| w[0] < w[1]);
            if ok {
                Ok(edges.to_vec())
            } else {
                Err(DiscretizerError::BadEdges {
                    field,
                    edges: edges.to_vec(),
                })
            }
        };
        let noise = bins.observation_noise;
        if !(0.0..1.0).contains(&noise) {
            return Err(DiscretizerError::BadNoise(noise));
        }
        Ok(Self {
            distance_edges: check("distance_edges", &distance_edges(map))?,
            speed_edges: check("speed_edges", &bins.speed_edges)?,
            noise,
        })
    }

    /// The distance edges in use, m to the goal (`[0, 30, 60]` on the training map).
    pub fn distance_edges(&self) -> &[f64] {
        &self.distance_edges
    }

    /// Factor sizes `[n_d, n_v, 2, 2]`, in the order of the joint index.
    pub fn factor_sizes(&self) -> [usize; 4] {
        [
            self.distance_edges.len() + 1,
            self.speed_edges.len() + 1,
            Self::LIGHT_VALUES,
            Self::PEDESTRIAN_VALUES,
        ]
    }

    /// Number of joint states (64 for the paper's bins).
    pub fn n_states(&self) -> usize {
        self.factor_sizes().iter().product()
    }

    /// Distance bin: the number of edges `e` with `distance_to_goal > e`
    /// (so with edges `[0, 30, 60]`: arrived -> 0, (0, 30] -> 1, (30, 60] -> 2, beyond -> 3).
    pub fn distance_bin(&self, distance_to_goal: f64) -> usize {
        self.distance_edges.iter().filter(|&&e| distance_to_goal > e).count()
    }

    /// Speed bin: the number of edges `e` with `speed >= e`.
    pub fn speed_bin(&self, speed: f64) -> usize {
        self.speed_edges.iter().filter(|&&e| speed >= e).count()
    }

    /// The true discrete state behind a snapshot (§VI).
    pub fn state(&self, snap: &Snapshot) -> State {
        State {
            d: self.distance_bin(snap.distance_to_goal),
            v: self.speed_bin(snap.car_speed),
            l: usize::from(snap.light == LightPhase::Green),
            p: usize::from(snap.obstacle_in_path()),
        }
    }

    /// Joint index `s = ((d * n_v + v) * 2 + L) * 2 + p`.
    pub fn encode(&self, s: State) -> usize {
        let [_, n_v, n_l, n_p] = self.factor_sizes();
        ((s.d * n_v + s.v) * n_l + s.l) * n_p + s.p
    }

    /// Inverse of [`Discretizer::encode`].
    pub fn decode(&self, index: usize) -> State {
        let [_, n_v, n_l, n_p] = self.factor_sizes();
        let p = index % n_p;
        let rest = index / n_p;
        let l = rest % n_l;
        let rest = rest / n_l;
        State {
            d: rest / n_v,
            v: rest % n_v,
            l,
            p,
        }
    }

    /// The observation the agent receives: the true state, or with probability
    /// `observation_noise` per factor a uniformly drawn *other* value of that factor
    /// (a confusion model, so that A is not the identity).
    pub fn observe<R: Rng + ?Sized>(&self, state: State, rng: &mut R) -> State {
        if self.noise == 0.0 {
            return state;
        }
        let sizes = self.factor_sizes();
        let mut values = [state.d, state.v, state.l, state.p];
        for (value, &size) in values.iter_mut().zip(&sizes) {
            if rng.random::<f64>() < self.noise {
                let other = rng.random_range(0..size - 1);
                *value = if other >= *value { other + 1 } else { other };
            }
        }
        State {
            d: values[0],
            v: values[1],
            l: values[2],
            p: values[3],
        }
    }

    /// Probability that a factor of size `size` is observed as `observed` when its
    /// true value is `actual`, under [`Discretizer::observe`]'s confusion model.
    pub fn factor_likelihood(&self, size: usize, observed: usize, actual: usize) -> f64 {
        if observed == actual {
            1.0 - self.noise
        } else {
            self.noise / (size - 1) as f64
        }
    }

    /// The observation model A[o, s] = p(o | s) of the confusion model, as a dense
    /// row-major `n_states x n_states` table (columns sum to 1). Identity when noise is 0.
    pub fn likelihood_matrix(&self) -> Vec<f64> {
        let n = self.n_states();
        let sizes = self.factor_sizes();
        let mut a = vec![0.0; n * n];
        for o in 0..n {
            let so = self.decode(o);
            for s in 0..n {
                let ss = self.decode(s);
                let pairs = [(so.d, ss.d), (so.v, ss.v), (so.l, ss.l), (so.p, ss.p)];
                a[o * n + s] = pairs
                    .iter()
                    .zip(&sizes)
                    .map(|(&(o_f, s_f), &size)| self.factor_likelihood(size, o_f, s_f))
                    .product();
            }
        }
        a
    }
}
