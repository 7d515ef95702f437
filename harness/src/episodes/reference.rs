//! Scripted reference controllers: they never reason and never learn, so they measure
//! the *scenario*, not an agent (§VI's jaywalk test is only a test if a careful driver
//! can survive it and a careless one cannot).
//!
//! * [`BrakeOnPedestrian`] (`brake-on-pedestrian`): slows down from the first tick a
//!   pedestrian is on the crosswalk while the car has not yet arrived (p = 1 and
//!   d >= 1), otherwise speeds up. It is the careful driver of §VI: a map of the
//!   jaywalk family must let it succeed (it is the witness that the map is survivable).
//!   On a map with the red-light rule (`reward.red_light < 0`) it also stops for red
//!   ([`RedLightStop`]): it slows down while L = 0 in the distance bin before the
//!   crosswalk, and in a crosswalk bin while L = 0 at the lowest speeds (v <= 1), unless
//!   it was in a crosswalk bin on green earlier in the episode: a driver who entered on
//!   green clears the crosswalk and the junction box behind it, and does not stop in
//!   them for a later red.
//! * [`NeverBrake`] (`never-brake`): always speeds up. It is the witness that a map is
//!   dangerous: a car that drives on must be hit.
//!
//! Why a second scripted method rather than reusing Q-learning as the "drives on"
//! witness: `check-map` has no trained agent, so its witness has to be scripted; and a
//! trained Q-table is a weaker witness anyway (whether it brakes depends on its seed
//! and on the light), while the warning is about the map's physics and timing. Making
//! it a [`crate::episodes::methods::Method`] lets `batch` report both witnesses from ordinary
//! units and print the same warnings as `check-map` ([`crate::episodes::survivability`]).
//!
//! Both decode the observation index `s = ((d*n_v + v)*2 + L)*2 + p` (docs/ARCHITECTURE.md §3)
//! with the factor sizes they are built with.

use unforeseen_agent::controller::{Controller, Decision, Dist};
use unforeseen_discretizer::Discretizer;
use unforeseen_sim::{Action, Map};

use crate::error::Error;

/// A one-hot distribution over the three actions at `action` (the policy a scripted
/// controller acts from).
fn one_hot(action: Action) -> Dist {
    let mut policy = [0.0; Action::ALL.len()];
    policy[action.index()] = 1.0;
    Dist::from_slice(&policy)
}

/// A decision of a scripted controller: never reasoned, no surprise.
fn decision(action: Action) -> Decision {
    Decision {
        action: action.index(),
        reasoned: false,
        policy: one_hot(action),
        ..Default::default()
    }
}

/// How [`BrakeOnPedestrian`] stops for red on a map with the red-light rule. It sees only
/// the discrete state, so it cannot tell where in a distance bin the car is: it brakes on
/// L = 0 (amber or red) in the bin before the crosswalk, where braking still stops the
/// car before the crosswalk's near edge (from 9 m/s with the default bins: 13.5 m from at
/// least 30 m), and on L = 0 in a bin that overlaps the crosswalk when it stands or
/// crawls (v <= 1: 0 or 3 m/s with the defaults, so one tick of braking stops it within
/// 1.5 m; it gets there by braking in the bin before, e.g. 42 -> 34.5 -> 30 m). Faster
/// in a crosswalk bin it drives on: there the car is either too close to stop or
/// already on or past the crosswalk, where stopping would leave it standing in the
/// pedestrians' way.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RedLightStop {
    /// The distance bin just before (farther from the goal than) the crosswalk's bins.
    pub approach: Option<usize>,
    /// The distance bins that overlap the crosswalk (`crosswalk_bins` in `episodes/rewards.rs`).
    pub crosswalk: Vec<usize>,
}

impl RedLightStop {
    /// The rule for `map`, if its reward has the red-light term (`reward.red_light < 0`).
    pub fn of(map: &Map, disc: &Discretizer) -> Option<Self> {
        if map.reward.red_light >= 0.0 {
            return None;
        }
        let crosswalk = crate::episodes::rewards::crosswalk_bins(map, disc);
        let last = *crosswalk.last()?;
        let n_d = disc.factor_sizes()[0];
        Some(Self {
            approach: (last + 1 < n_d).then_some(last + 1),
            crosswalk,
        })
    }

    /// Whether the rule says slow down at (d, v, L).
    fn stops(&self, d: usize, v: usize, l: usize) -> bool {
        l == 0 && (self.approach == Some(d) || (v <= 1 && self.crosswalk.contains(&d)))
    }
}

/// Brakes while a pedestrian is on the crosswalk and the car has not arrived, else
/// speeds up (§VI's careful driver); with a [`RedLightStop`], also stops for red.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BrakeOnPedestrian {
    /// Factor sizes `[n_d, n_v, n_L, n_p]` of the joint observation index.
    sizes: [usize; 4],
    /// Stops for red too (maps with the red-light rule).
    red_light: Option<RedLightStop>,
    /// This episode, the car has been in a crosswalk bin on green: it has entered, and
    /// no longer stops for red.
    entered: bool,
}

impl BrakeOnPedestrian {
    /// A controller for observations of factor sizes `[n_d, n_v, n_L, n_p]` (the order
    /// of the joint index: d, v, L, p). Fails unless there are four factors of at least
    /// the paper's minimal sizes (d has "arrived" and "not arrived", L and p are binary).
    pub fn new(sizes: &[usize]) -> Result<Self, Error> {
        match *sizes {
            [n_d, n_v, 2, 2] if n_d >= 2 && n_v >= 1 => Ok(Self {
                sizes: [n_d, n_v, 2, 2],
                red_light: None,
                entered: false,
            }),
            _ => Err(Error::Agent {
                problem: format!(
                    "brake-on-pedestrian needs the four factors d, v, L, p (L and p binary), got factor sizes {sizes:?}"
                ),
                fix: "use an agent of the intersection's d, v, L, p state space".into(),
            }),
        }
    }

    /// The witness for `map`: [`BrakeOnPedestrian::new`], stopping for red where the map's
    /// reward has the red-light rule ([`RedLightStop::of`], with the map's bins).
    pub fn for_map(sizes: &[usize], map: &Map) -> Result<Self, Error> {
        let mut c = Self::new(sizes)?;
        let disc = Discretizer::new(map)?;
        if disc.factor_sizes() == c.sizes {
            c.red_light = RedLightStop::of(map, &disc);
        }
        Ok(c)
    }

    /// The action for joint observation `obs` before the car has entered on green: slow
    /// down iff p = 1 and d >= 1, or the red-light rule says so; otherwise speed up.
    pub fn action(&self, obs: usize) -> Action {
        let (d, v, l, p) = self.decode(obs);
        let red = !self.entered && self.red_light.as_ref().is_some_and(|r| r.stops(d, v, l));
        if (p == 1 && d >= 1) || red {
            Action::SlowDown
        } else {
            Action::SpeedUp
        }
    }

    /// `(d, v, L, p)` of joint observation `obs`.
    fn decode(&self, obs: usize) -> (usize, usize, usize, usize) {
        let [_, n_v, n_l, n_p] = self.sizes;
        (
            obs / (n_v * n_l * n_p),
            (obs / (n_l * n_p)) % n_v,
            (obs / n_p) % n_l,
            obs % n_p,
        )
    }
}

impl Controller for BrakeOnPedestrian {
    fn name(&self) -> &'static str {
        "brake-on-pedestrian"
    }
    fn begin_episode(&mut self, _seed: u64) {
        self.entered = false;
    }
    /// Scripted; never reasons. Records when the car is in a crosswalk bin on green
    /// (with the red-light rule), after which it no longer stops for red.
    fn act(&mut self, obs: usize) -> Decision {
        let (d, _, l, _) = self.decode(obs);
        if l == 1 && self.red_light.as_ref().is_some_and(|r| r.crosswalk.contains(&d)) {
            self.entered = true;
        }
        decision(self.action(obs))
    }
}

/// Always speeds up, whatever it observes: the car that never brakes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct NeverBrake;

impl Controller for NeverBrake {
    fn name(&self) -> &'static str {
        "never-brake"
    }
    fn begin_episode(&mut self, _seed: u64) {}
    /// Scripted; never reasons.
    fn act(&mut self, _obs: usize) -> Decision {
        decision(Action::SpeedUp)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use unforeseen_discretizer::{Discretizer, State};
    use unforeseen_sim::{Bins, DistanceEdges, Map};

    fn disc() -> Discretizer {
        Discretizer::new(&Map::default()).unwrap()
    }

    fn brake() -> BrakeOnPedestrian {
        BrakeOnPedestrian::new(&disc().factor_sizes()).unwrap()
    }

    fn act(c: &mut dyn Controller, d: usize, v: usize, l: usize, p: usize) -> Action {
        let decision = c.act(disc().encode(State { d, v, l, p }));
        assert!(!decision.reasoned);
        assert_eq!(decision.policy.iter().sum::<f64>(), 1.0);
        assert_eq!(decision.policy[decision.action], 1.0);
        Action::from_index(decision.action).unwrap()
    }

    #[test]
    fn brakes_for_a_pedestrian_before_arriving_whatever_the_light_and_speed() {
        let mut c = brake();
        for d in 1..4 {
            for v in 0..4 {
                for l in 0..2 {
                    assert_eq!(act(&mut c, d, v, l, 1), Action::SlowDown, "d {d} v {v} L {l}");
                    assert_eq!(act(&mut c, d, v, l, 0), Action::SpeedUp, "d {d} v {v} L {l}");
                }
            }
        }
    }

    #[test]
    fn hand_picked_states() {
        let mut c = brake();
        // The jaywalker appears on green at d = 2, car at 9 m/s: brake.
        assert_eq!(act(&mut c, 2, 3, 1, 1), Action::SlowDown);
        // Far away (d = 3), someone on the crosswalk on red: brake too.
        assert_eq!(act(&mut c, 3, 2, 0, 1), Action::SlowDown);
        // Standing, the crosswalk still occupied: keep standing (slow down never reverses).
        assert_eq!(act(&mut c, 2, 0, 1, 1), Action::SlowDown);
        // The crosswalk is clear again: go, even on red (it ignores the light).
        assert_eq!(act(&mut c, 2, 0, 1, 0), Action::SpeedUp);
        assert_eq!(act(&mut c, 1, 1, 0, 0), Action::SpeedUp);
        // Arrived (d = 0): never brakes.
        assert_eq!(act(&mut c, 0, 3, 1, 1), Action::SpeedUp);
        assert_eq!(act(&mut c, 0, 0, 0, 0), Action::SpeedUp);
    }

    #[test]
    fn decodes_other_bin_counts() {
        // Five distance bins and two speed bins: s = ((d*2 + v)*2 + L)*2 + p.
        let bins = Bins {
            distance_edges: DistanceEdges::Goal(vec![0.0, 20.0, 40.0, 80.0]),
            speed_edges: vec![4.0],
            observation_noise: 0.0,
        };
        let disc = Discretizer::new(&Map { bins, ..Map::default() }).unwrap();
        let c = BrakeOnPedestrian::new(&disc.factor_sizes()).unwrap();
        for s in 0..disc.n_states() {
            let st = disc.decode(s);
            let want = if st.p == 1 && st.d >= 1 {
                Action::SlowDown
            } else {
                Action::SpeedUp
            };
            assert_eq!(c.action(s), want, "{st:?}");
        }
    }

    #[test]
    fn stops_for_red_only_where_the_map_has_the_rule() {
        let mut map = unforeseen_sim::embedded::load("intersection").unwrap();
        map.reward.red_light = 0.0;
        let sizes = disc().factor_sizes();
        let plain = BrakeOnPedestrian::for_map(&sizes, &map).unwrap();
        assert_eq!(plain, brake(), "no rule: the witness of before");
        map.reward.red_light = -10.0;
        let mut c = BrakeOnPedestrian::for_map(&sizes, &map).unwrap();
        assert_eq!(
            c.red_light,
            Some(RedLightStop {
                approach: Some(2),
                crosswalk: vec![1]
            })
        );
        for s in 0..disc().n_states() {
            let st = disc().decode(s);
            let red = st.l == 0 && (st.d == 2 || (st.d == 1 && st.v <= 1));
            let want = if (st.p == 1 && st.d >= 1) || red {
                Action::SlowDown
            } else {
                Action::SpeedUp
            };
            c.begin_episode(0);
            assert_eq!(act(&mut c, st.d, st.v, st.l, st.p), want, "{st:?}");
        }
        c.begin_episode(0);
        // The light turns amber or red at d = 2 at full speed: brake.
        assert_eq!(act(&mut c, 2, 3, 0, 0), Action::SlowDown);
        // Standing or crawling before the crosswalk (d = 1) on red: stop; on green: go.
        assert_eq!(act(&mut c, 1, 0, 0, 0), Action::SlowDown);
        assert_eq!(act(&mut c, 1, 1, 0, 0), Action::SlowDown);
        assert_eq!(act(&mut c, 1, 0, 1, 0), Action::SpeedUp);
        // Moving in the crosswalk bin on red: too close to stop, drive on.
        assert_eq!(act(&mut c, 1, 2, 0, 0), Action::SpeedUp);
        // Far away (d = 3) on red: not yet.
        assert_eq!(act(&mut c, 3, 3, 0, 0), Action::SpeedUp);
    }

    #[test]
    fn once_in_the_crosswalk_bin_on_green_it_clears_instead_of_stopping_for_red() {
        let map = unforeseen_sim::embedded::load("intersection").unwrap();
        let mut map = map;
        map.reward.red_light = -10.0;
        let mut c = BrakeOnPedestrian::for_map(&disc().factor_sizes(), &map).unwrap();
        c.begin_episode(0);
        // Stopped in the crosswalk bin for an obstacle on green, then the obstacle goes.
        assert_eq!(act(&mut c, 1, 2, 1, 1), Action::SlowDown);
        assert_eq!(act(&mut c, 1, 0, 1, 0), Action::SpeedUp);
        // Amber at a crawl: it drives on (before entering on green it would stop here).
        assert_eq!(act(&mut c, 1, 1, 0, 0), Action::SpeedUp);
        assert_eq!(act(&mut c, 1, 0, 0, 0), Action::SpeedUp);
        // An obstacle still stops it.
        assert_eq!(act(&mut c, 1, 1, 0, 1), Action::SlowDown);
        // A new episode forgets.
        c.begin_episode(1);
        assert_eq!(act(&mut c, 1, 1, 0, 0), Action::SlowDown);
    }

    #[test]
    fn rejects_structures_it_cannot_decode() {
        assert!(BrakeOnPedestrian::new(&[64]).is_err());
        assert!(BrakeOnPedestrian::new(&[4, 4, 3, 2]).is_err());
        assert!(BrakeOnPedestrian::new(&[1, 4, 2, 2]).is_err());
    }

    #[test]
    fn never_brake_always_speeds_up() {
        let mut c = NeverBrake;
        for s in 0..disc().n_states() {
            let st = disc().decode(s);
            assert_eq!(act(&mut c, st.d, st.v, st.l, st.p), Action::SpeedUp);
        }
    }
}
