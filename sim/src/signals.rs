//! One signal controller for every approach (docs/ARCHITECTURE.md §2): the car's
//! signal (`light.cycle`, the paper's light), the cross street's (`junction.cross`),
//! a pedestrian head per crosswalk, and the dark state of an outage
//! (`junction.outages`).
//!
//! Heads on the road (the car's and oncoming traffic's) show `light.cycle`; the cross
//! street's heads show `junction.cross`; a crosswalk across the road shows *walk* while
//! the road's heads show red, one across the cross street while the cross street's
//! show red. During an outage every head is dark and the cycle runs on underneath.
//! Without a junction the controller is the paper's light: `Controller::reading` is
//! [`light_at`] of the map's light, bit for bit.

use crate::light::light_at;
use crate::map::{Arm, CrossCycle, DarkReading, Light, LightPhase, Map, Offset, Outage, Phase, Trigger};

/// What a vehicle head shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Aspect {
    /// Lit, in this phase.
    Lit(LightPhase),
    /// Dark (an outage).
    Dark,
}

impl Aspect {
    /// The phase shown, `None` when dark.
    pub fn phase(self) -> Option<LightPhase> {
        match self {
            Aspect::Lit(p) => Some(p),
            Aspect::Dark => None,
        }
    }
}

/// What a pedestrian head shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Walk {
    /// Pedestrians may cross.
    Walk,
    /// Pedestrians may not start crossing.
    DontWalk,
    /// Dark (an outage).
    Dark,
}

/// Every head of the junction at one moment.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SignalState {
    /// The heads on the road: the car's and oncoming traffic's.
    pub road: Aspect,
    /// The cross street's heads (`Lit(Red)` on a map without a junction: it has none).
    pub cross: Aspect,
    /// Pedestrian heads of the crosswalks across the road (West, East).
    pub walk_road: Walk,
    /// Pedestrian heads of the crosswalks across the cross street (South, North).
    pub walk_cross: Walk,
}

impl SignalState {
    /// The pedestrian head of the crosswalk on `arm`.
    pub fn walk(&self, arm: Arm) -> Walk {
        if arm.on_road() { self.walk_road } else { self.walk_cross }
    }

    /// Whether the heads are dark.
    pub fn dark(&self) -> bool {
        self.road == Aspect::Dark
    }
}

/// What an outage's trigger may look at: the time, the phase the car's signal is
/// in (lit or not), and the car.
#[derive(Debug, Clone, Copy)]
pub(crate) struct TriggerView {
    /// Episode time, s.
    pub t: f64,
    /// The car's signal's phase in the cycle (shown unless dark).
    pub phase: LightPhase,
    /// Metres from the car's front to the crosswalk's near edge.
    pub to_cross: f64,
    /// The car's speed, m/s.
    pub speed: f64,
}

impl TriggerView {
    /// Whether `trigger` holds now: `RedStarts` / `GreenStarts` while the phase is red /
    /// green, the others as for a pedestrian spawn rule.
    pub fn holds(&self, trigger: Trigger) -> bool {
        let (t, to_cross, speed) = (self.t, self.to_cross, self.speed);
        match trigger {
            Trigger::RedStarts => self.phase == LightPhase::Red,
            Trigger::GreenStarts => self.phase == LightPhase::Green,
            Trigger::AtTime(at) => t + 1e-9 >= at,
            Trigger::CarWithin { min, max } => to_cross >= min && to_cross <= max,
            Trigger::CarArrivesWithin(secs) => to_cross > 0.0 && speed > 1e-3 && to_cross <= secs * speed,
        }
    }
}

/// The controller of one episode: the cycles, the offset, and the outages started.
#[derive(Debug, Clone)]
pub(crate) struct Controller {
    light: Light,
    offset: f64,
    /// The cross street's cycle and where it starts relative to the car's, or `None`
    /// without a junction.
    cross: Option<(Light, f64)>,
    outages: Vec<(Outage, Option<f64>)>,
    dark_reads_as: DarkReading,
}

impl Controller {
    /// The controller of `map` with the car's cycle at `offset` s at time 0.
    pub fn new(map: &Map, offset: f64) -> Controller {
        let (cross, outages, dark_reads_as) = match &map.junction {
            None => (None, Vec::new(), DarkReading::Red),
            Some(j) => {
                let cross = match &j.cross {
                    CrossCycle::Cycle(c) => (
                        Light {
                            cycle: c.clone(),
                            offset: Offset::Fixed(0.0),
                        },
                        0.0,
                    ),
                    CrossCycle::Derived { amber, all_red } => derived_cross(&map.light.cycle, *amber, *all_red),
                };
                (
                    Some(cross),
                    // A scheduled outage starts at its time exactly (seen by the snapshot
                    // taken then); the others when a sub-step first sees their trigger.
                    (j.outages.iter())
                        .map(|o| match o.start {
                            Trigger::AtTime(at) => (*o, Some(at)),
                            _ => (*o, None),
                        })
                        .collect(),
                    j.dark_reads_as,
                )
            }
        };
        Controller {
            light: map.light.clone(),
            offset,
            cross,
            outages,
            dark_reads_as,
        }
    }

    /// The car's signal's phase in the cycle at `t` and the seconds left in it (shown
    /// unless dark).
    pub fn cycle_phase(&self, t: f64) -> (LightPhase, f64) {
        light_at(&self.light, self.offset, t)
    }

    /// Start the outages whose trigger holds (each once).
    pub fn fire(&mut self, view: &TriggerView) {
        for (o, started) in &mut self.outages {
            if started.is_none() && view.holds(o.start) {
                *started = Some(view.t);
            }
        }
    }

    /// Whether an outage darkens the heads at `t`.
    pub fn dark(&self, t: f64) -> bool {
        self.outages
            .iter()
            .any(|(o, started)| started.is_some_and(|s| t >= s && t < s + o.duration))
    }

    /// Every head at `t`.
    pub fn state(&self, t: f64) -> SignalState {
        if self.dark(t) {
            return SignalState {
                road: Aspect::Dark,
                cross: Aspect::Dark,
                walk_road: Walk::Dark,
                walk_cross: Walk::Dark,
            };
        }
        let road = self.cycle_phase(t).0;
        let cross = match &self.cross {
            Some((c, shift)) => light_at(c, self.offset - shift, t).0,
            None => LightPhase::Red,
        };
        let walk = |p: LightPhase| {
            if p == LightPhase::Red {
                Walk::Walk
            } else {
                Walk::DontWalk
            }
        };
        SignalState {
            road: Aspect::Lit(road),
            cross: Aspect::Lit(cross),
            walk_road: walk(road),
            walk_cross: walk(cross),
        }
    }

    /// What the car's agent reads (its L factor) at `t`, with the seconds until it
    /// changes: the car's head, or while dark the map's `dark_reads_as` with 0 s (no
    /// head counts down).
    pub fn reading(&self, t: f64) -> (LightPhase, f64) {
        if self.dark(t) {
            let p = match self.dark_reads_as {
                DarkReading::Red => LightPhase::Red,
                DarkReading::Green => LightPhase::Green,
            };
            return (p, 0.0);
        }
        self.cycle_phase(t)
    }
}

/// The cross street's cycle derived from the car's (`CrossCycle::Derived`), and the
/// time into the car's cycle where it starts. Each maximal run of red in the car's
/// cycle (wrapping around its end) becomes red `all_red`, green, amber `amber`, red
/// `all_red` for the cross street; the rest is red. A run too short for its clearance
/// and amber gets no green (validation refuses such maps).
pub(crate) fn derived_cross(cycle: &[Phase], amber: f64, all_red: f64) -> (Light, f64) {
    let red = |p: &Phase| p.phase == LightPhase::Red;
    // Start the derived cycle at the first phase that is not red, so no run wraps.
    let first = cycle.iter().position(|p| !red(p)).unwrap_or(0);
    let shift: f64 = cycle[..first].iter().map(|p| p.duration).sum();
    let mut out = Vec::new();
    let mut run = 0.0;
    let flush = |out: &mut Vec<Phase>, run: f64| {
        if run <= 0.0 {
            return;
        }
        let green = run - 2.0 * all_red - amber;
        if green <= 0.0 {
            out.push(Phase {
                phase: LightPhase::Red,
                duration: run,
            });
            return;
        }
        for (phase, duration) in [
            (LightPhase::Red, all_red),
            (LightPhase::Green, green),
            (LightPhase::Amber, amber),
            (LightPhase::Red, all_red),
        ] {
            if duration > 0.0 {
                out.push(Phase { phase, duration });
            }
        }
    };
    for p in cycle[first..].iter().chain(&cycle[..first]) {
        if red(p) {
            run += p.duration;
        } else {
            flush(&mut out, run);
            run = 0.0;
            out.push(Phase {
                phase: LightPhase::Red,
                duration: p.duration,
            });
        }
    }
    flush(&mut out, run);
    (
        Light {
            cycle: out,
            offset: Offset::Fixed(0.0),
        },
        shift,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Junction;

    fn phase(phase: LightPhase, duration: f64) -> Phase {
        Phase { phase, duration }
    }

    #[test]
    fn derived_cross_of_the_default_cycle() {
        let (c, shift) = derived_cross(&Light::default().cycle, 2.0, 1.0);
        assert_eq!(shift, 0.0);
        assert_eq!(
            c.cycle,
            vec![
                phase(LightPhase::Red, 12.0),
                phase(LightPhase::Red, 2.0),
                phase(LightPhase::Red, 1.0),
                phase(LightPhase::Green, 6.0),
                phase(LightPhase::Amber, 2.0),
                phase(LightPhase::Red, 1.0),
            ]
        );
        // A red run across the cycle's end is one run.
        let wrap = [
            phase(LightPhase::Red, 4.0),
            phase(LightPhase::Green, 10.0),
            phase(LightPhase::Red, 6.0),
        ];
        let (c, shift) = derived_cross(&wrap, 2.0, 1.0);
        assert_eq!(shift, 4.0);
        assert_eq!(c.cycle[1], phase(LightPhase::Red, 1.0));
        assert_eq!(c.cycle[2], phase(LightPhase::Green, 6.0));
        assert_eq!(c.cycle_length(), 20.0);
    }

    #[test]
    fn road_green_means_cross_red_and_walk_follows_red() {
        let map = Map {
            junction: Some(Junction::default()),
            ..Map::default()
        };
        for offset in [0.0, 3.7, 17.0] {
            let c = Controller::new(&map, offset);
            for k in 0..2400 {
                let s = c.state(k as f64 / 60.0);
                let (Aspect::Lit(road), Aspect::Lit(cross)) = (s.road, s.cross) else {
                    panic!("dark without an outage");
                };
                assert!(road == LightPhase::Red || cross == LightPhase::Red, "{s:?}");
                assert_eq!(s.walk_road == Walk::Walk, road == LightPhase::Red);
                assert_eq!(s.walk_cross == Walk::Walk, cross == LightPhase::Red);
            }
        }
        // The default: cross green from 1 s into the car's red to 3 s before its end.
        let c = Controller::new(&map, 0.0);
        assert_eq!(c.state(14.5).cross, Aspect::Lit(LightPhase::Red));
        assert_eq!(c.state(15.5).cross, Aspect::Lit(LightPhase::Green));
        assert_eq!(c.state(21.5).cross, Aspect::Lit(LightPhase::Amber));
        assert_eq!(c.state(23.5).cross, Aspect::Lit(LightPhase::Red));
    }

    /// Without a junction the reading is the paper's light, bit for bit.
    #[test]
    fn without_a_junction_the_reading_is_the_light() {
        let map = Map::default();
        for offset in [0.0, 5.25, 23.9] {
            let c = Controller::new(&map, offset);
            for k in 0..5000 {
                let t = k as f64 / 60.0;
                let (a, b) = (c.reading(t), light_at(&map.light, offset, t));
                assert_eq!((a.0, a.1.to_bits()), (b.0, b.1.to_bits()));
                assert!(!c.dark(t));
            }
        }
    }

    #[test]
    fn an_outage_darkens_every_head_and_reads_as_chosen() {
        for (reads, want) in [
            (DarkReading::Red, LightPhase::Red),
            (DarkReading::Green, LightPhase::Green),
        ] {
            let map = Map {
                junction: Some(Junction {
                    outages: vec![Outage {
                        start: Trigger::AtTime(5.0),
                        duration: 10.0,
                    }],
                    dark_reads_as: reads,
                    ..Junction::default()
                }),
                ..Map::default()
            };
            let mut c = Controller::new(&map, 0.0);
            let view = |t| TriggerView {
                t,
                phase: LightPhase::Green,
                to_cross: 50.0,
                speed: 5.0,
            };
            c.fire(&view(4.9));
            assert!(!c.dark(4.9));
            c.fire(&view(5.0));
            assert!(c.state(5.0).dark());
            assert_eq!(c.state(14.9).walk(Arm::South), Walk::Dark);
            assert_eq!(c.reading(10.0), (want, 0.0));
            assert!(!c.dark(15.0));
            assert_eq!(c.reading(15.0), light_at(&map.light, 0.0, 15.0));
        }
    }
}
