//! Scripted reference controllers: they never reason and never learn, so they measure
//! the *scenario*, not an agent (§VI's jaywalk test is only a test if a careful driver
//! can survive it and a careless one cannot).
//!
//! * [`BrakeOnPedestrian`] (`brake-on-pedestrian`): slows down from the first tick a
//!   pedestrian is on the crosswalk while the car has not yet arrived (p = 1 and
//!   d >= 1), otherwise speeds up. It is the careful driver of §VI: a map of the
//!   jaywalk family must let it succeed (it is the witness that the map is survivable).
//! * [`NeverBrake`] (`never-brake`): always speeds up. It is the witness that a map is
//!   dangerous: a car that drives on must be hit.
//!
//! Why a second scripted method rather than reusing Q-learning as the "drives on"
//! witness: `check-map` has no trained agent, so its witness has to be scripted; and a
//! trained Q-table is a weaker witness anyway (whether it brakes depends on its seed
//! and on the light), while the warning is about the map's physics and timing. Making
//! it a [`crate::methods::Method`] lets `batch` report both witnesses from ordinary
//! units and print the same warnings as `check-map` ([`crate::survivability`]).
//!
//! Both decode the observation index `s = ((d*n_v + v)*2 + L)*2 + p` (docs/ARCHITECTURE.md §3)
//! with the factor sizes they are built with.

use unforeseen_agent::controller::{Controller, Decision, Dist};
use unforeseen_sim::Action;

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

/// Brakes while a pedestrian is on the crosswalk and the car has not arrived, else
/// speeds up (§VI's careful driver).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BrakeOnPedestrian {
    /// Factor sizes `[n_d, n_v, n_L, n_p]` of the joint observation index.
    sizes: [usize; 4],
}

impl BrakeOnPedestrian {
    /// A controller for observations of factor sizes `[n_d, n_v, n_L, n_p]` (the order
    /// of the joint index: d, v, L, p). Fails unless there are four factors of at least
    /// the paper's minimal sizes (d has "arrived" and "not arrived", L and p are binary).
    pub fn new(sizes: &[usize]) -> Result<Self, Error> {
        match *sizes {
            [n_d, n_v, 2, 2] if n_d >= 2 && n_v >= 1 => Ok(Self {
                sizes: [n_d, n_v, 2, 2],
            }),
            _ => Err(Error::Agent {
                problem: format!(
                    "brake-on-pedestrian needs the four factors d, v, L, p (L and p binary), got factor sizes {sizes:?}"
                ),
                fix: "use an agent of the intersection's d, v, L, p state space".into(),
            }),
        }
    }

    /// The action for joint observation `obs`: slow down iff p = 1 and d >= 1.
    pub fn action(&self, obs: usize) -> Action {
        let [_, n_v, n_l, n_p] = self.sizes;
        let p = obs % n_p;
        let d = obs / (n_v * n_l * n_p);
        if p == 1 && d >= 1 {
            Action::SlowDown
        } else {
            Action::SpeedUp
        }
    }
}

impl Controller for BrakeOnPedestrian {
    fn name(&self) -> &'static str {
        "brake-on-pedestrian"
    }
    fn begin_episode(&mut self, _seed: u64) {}
    /// Scripted; never reasons.
    fn act(&mut self, obs: usize) -> Decision {
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
    use unforeseen_sim::Bins;

    fn disc() -> Discretizer {
        Discretizer::new(&Bins::default()).unwrap()
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
            distance_edges: vec![0.0, 20.0, 40.0, 80.0],
            speed_edges: vec![4.0],
            observation_noise: 0.0,
        };
        let disc = Discretizer::new(&bins).unwrap();
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
