//! Other vehicles (docs/ARCHITECTURE.md §2): spawned by rules in the pedestrians' style
//! ([`TrafficRule`]: trigger, light condition, probability, delay, speed range) on a
//! route through the junction, each a Rapier body with a sensor collider, driven by the
//! intelligent driver model (IDM; Treiber, Hennecke and Helbing, "Congested traffic
//! states in empirical observations and microscopic simulations", Phys. Rev. E 62,
//! 1805, 2000):
//!
//! ```text
//! a = A [1 − (v / v0)^4 − (s* / s)²],   s* = s0 + max(0, v T + v Δv / (2 √(A b)))
//! ```
//!
//! with `s` the gap to what is ahead in the vehicle's lane (another vehicle, the car,
//! or its stop line while its signal says stop, taken as a standing obstacle `s0`
//! beyond the line so that it stops with its front on the line) and `Δv` the speed at
//! which it closes that gap. A vehicle's own state (distance along its route and speed)
//! is integrated in f64 with the ballistic update (a vehicle that would reverse within
//! a sub-step stops where its speed reaches 0); its body is kinematic and follows that
//! state, so contacts never push it (a crash ends the episode before any could). No
//! vehicle decelerates harder than the tyres allow on the road's surface
//! (`min(MAX_DECEL, μ g)` with `road.friction`: a hard stop asked for beyond it slides
//! at μ g, as the car's locked wheels do under `dynamics: Forces`). The rest of the
//! force-driven model of the car (drive force and power, brake lag, drag) is not used
//! here: IDM is itself an acceleration model whose comfortable values stay inside the
//! drive train's limits, and what the kinematic model leaves out is measured in
//! `tests::the_brake_lag_left_out` (the stop-position difference a lag would make).

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rapier2d::prelude::*;

use crate::draw::uniform;
use crate::dynamics::GRAVITY;
use crate::junction::{Approach, Layout};
use crate::map::{Behaviour, LightCondition, LightPhase, Map, Route, TrafficRule, Trigger};
use crate::routes::Path;
use crate::signals::{Aspect, SignalState, TriggerView};

impl Route {
    /// The approach it comes in on.
    pub fn approach(self) -> Approach {
        match self {
            Route::Lead => Approach::FromWest,
            Route::Oncoming | Route::OncomingLeft => Approach::FromEast,
            Route::FromSouth => Approach::FromSouth,
            Route::FromNorth => Approach::FromNorth,
        }
    }
}

/// The hardest any vehicle brakes, m/s² (about 0.9 g, the limit of a dry road).
pub const MAX_DECEL: f64 = 9.0;
/// Seconds a careful driver stands at the stop line of a dark signal before going.
pub const ALL_WAY_STOP_WAIT: f64 = 1.0;
/// At a dark signal a vehicle counts as standing at its line below this speed, m/s ...
const STOPPED_SPEED: f64 = 0.5;
/// ... within this many metres of it, m (IDM's approach to a stop line ends in a long
/// crawl: from 9 m/s it takes about 4 s more to go from 0.5 to 0.05 m/s).
const STOPPED_GAP: f64 = 1.5;
/// A careful left-turner waits at the box while the car would reach the box within this
/// many seconds at its speed (or is in it), s.
pub const YIELD_GAP: f64 = 4.0;
/// A vehicle in the car's lane is in its path within this many seconds at the car's
/// speed plus as many at the speed it closes on it, s (the car's stopping distance from its top speed, 9 m/s at 3 m/s², with a
/// 1 s decision tick is 22.5 m: 2.5 s) ...
const HEADWAY_SEEN: f64 = 3.0;
/// ... or within this many metres, m.
const NEAR_SEEN: f64 = 10.0;
/// A crossing vehicle before its line that would need more than this many times its
/// comfortable deceleration to stop there is seen as entering the box.
const WILL_ENTER_BRAKING: f64 = 2.0;
/// A vehicle in the car's lane slower than this, m/s, with its rear before the far side
/// of the junction box, blocks the box: while the car has not reached the box, it is in
/// the car's path however far ahead (a careful driver does not enter a crosswalk or a box
/// it cannot leave).
const BLOCKING_SPEED: f64 = 1.0;
/// A vehicle whose front is this far past its stop line has entered the junction, whatever
/// its signal shows (one held at its line stops within millimetres of it), m.
const OVERRUN: f64 = 0.5;
/// An oncoming car signalling a left turn (route `OncomingLeft`) that comes on faster than
/// [`BLOCKING_SPEED`] within this many metres of its turn, while the car has not passed
/// the box, is in the car's path: a careful driver slows for a turning car that shows no
/// sign of yielding, before it turns, m.
const TURN_SEEN: f64 = 30.0;
/// Lateral margin within which something counts as in a vehicle's lane, m (each side).
const LANE_MARGIN: f64 = 0.3;
/// How far ahead a vehicle looks, m.
const LOOKAHEAD: f64 = 150.0;
/// Metres past the conflict area where a vehicle leaves the world.
const EXIT_AFTER: f64 = 60.0;

/// IDM's acceleration at speed `v` with desired speed `v0`, gap `gap` (m, > 0) to what
/// is ahead, closing at `dv` m/s, for a driver with maximum acceleration `a`,
/// comfortable deceleration `b`, headway `t` and minimum gap `s0`. `gap = ∞`: free road.
pub fn idm(v: f64, v0: f64, gap: f64, dv: f64, (a, b, t, s0): (f64, f64, f64, f64)) -> f64 {
    let free = 1.0 - (v / v0).powi(4);
    if gap.is_infinite() {
        return a * free;
    }
    let desired = s0 + (v * t + v * dv / (2.0 * (a * b).sqrt())).max(0.0);
    a * (free - (desired / gap.max(1e-3)).powi(2))
}

/// One vehicle as seen by an observer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VehicleSnapshot {
    /// Centre, m.
    pub x: f64,
    /// Centre, m.
    pub y: f64,
    /// Heading, rad (0 along +x).
    pub heading: f64,
    /// Speed along its heading, m/s (>= 0).
    pub speed: f64,
    /// Body length, m.
    pub length: f64,
    /// Body width, m.
    pub width: f64,
    /// Its route.
    pub route: Route,
    /// Its front's distance past its stop line, m (negative before it).
    pub past_stop_line: f64,
    /// Whether it is in the car's path (the rule of
    /// [`crate::world::Snapshot::vehicle_in_path`], which holds when any vehicle's does).
    pub in_path: bool,
}

/// A lead car's hard stop, in stages.
#[derive(Debug, Clone, Copy, PartialEq)]
enum HardStop {
    Waiting,
    Braking,
    Holding(f64),
    Done,
}

struct Other {
    body: RigidBodyHandle,
    collider: ColliderHandle,
    rule: usize,
    approach: Approach,
    /// Its path (s = 0 at the stop line).
    path: Path,
    /// Distance of the front past the stop line, m.
    s: f64,
    v: f64,
    v0: f64,
    end: f64,
    age: f64,
    /// Seconds since it stalled (`Stalls`), once it has.
    stalled: Option<f64>,
    hard: HardStop,
    /// Seconds stood at a dark stop line, and whether it may go.
    waited: f64,
    cleared: bool,
    /// Whether its front crossed its stop line with its signal letting it go, or ran
    /// [`OVERRUN`] past it: from then on the signal no longer stops it (a vehicle held at
    /// its line that creeps a few mm past it in a sub-step is still held).
    entered: bool,
    /// Whether it began its turn with the way clear (a careful left-turner is held at
    /// the box until then, as at a stop line).
    turning: bool,
}

impl Other {
    /// Its front's point and its heading.
    fn front(&self) -> ((f64, f64), (f64, f64)) {
        self.path.pose(self.s)
    }
}

/// A body of `length` m whose front is at `front` heading `u`: its centre and rotation.
fn centre_of(front: (f64, f64), u: (f64, f64), length: f64) -> (Vector, Real) {
    let c = (front.0 - u.0 * length / 2.0, front.1 - u.1 * length / 2.0);
    (Vector::new(c.0 as Real, c.1 as Real), u.1.atan2(u.0) as Real)
}

struct PendingCar {
    at_substep: i64,
    rule: usize,
    v0: f64,
}

/// An axis-aligned box with its velocity: something a vehicle may find in its lane.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Body {
    pub x: (f64, f64),
    pub y: (f64, f64),
    pub vel: (f64, f64),
}

/// The other vehicles of one episode.
pub(crate) struct Traffic {
    rules: Vec<TrafficRule>,
    layout: Layout,
    others: Vec<Other>,
    fired: Vec<bool>,
    pending: Vec<PendingCar>,
    prev_phase: Option<LightPhase>,
    rng: ChaCha8Rng,
    goal_x: f64,
    /// The tyres' limit on the road's default surface, μ g, m/s²: no vehicle brakes harder.
    grip: f64,
}

impl Traffic {
    /// The traffic of `map`; its draws come from `seed` on a stream of their own (so a
    /// map's pedestrians draw the same with or without traffic).
    pub fn new(map: &Map, seed: u64) -> Traffic {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        rng.set_stream(1);
        Traffic {
            rules: map.traffic.clone(),
            layout: Layout::new(map),
            others: Vec::new(),
            fired: vec![false; map.traffic.len()],
            pending: Vec::new(),
            prev_phase: None,
            rng,
            goal_x: map.road.goal_x,
            grip: map.road.friction * GRAVITY,
        }
    }

    /// Whether there is nothing to do (no rules).
    pub fn is_empty(&self) -> bool {
        self.rules.is_empty()
    }

    /// Fire the rules whose trigger holds (`shown`: the car's signal's phase, `None`
    /// while dark) and place the vehicles whose delay has elapsed; `car_front` is the
    /// car's front x.
    pub fn spawn_due(
        &mut self,
        phys: &mut PhysicsWorld,
        substep: u64,
        h: f64,
        view: &TriggerView,
        shown: Option<LightPhase>,
        car_front: f64,
    ) {
        for i in 0..self.rules.len() {
            let rule = &self.rules[i];
            let fires = match rule.trigger {
                Trigger::RedStarts | Trigger::GreenStarts => {
                    let want = if rule.trigger == Trigger::RedStarts {
                        LightPhase::Red
                    } else {
                        LightPhase::Green
                    };
                    shown == Some(want) && self.prev_phase != Some(want)
                }
                other => !self.fired[i] && view.holds(other),
            };
            let light_ok = match rule.light {
                LightCondition::Any => true,
                LightCondition::Green => shown.is_some_and(LightPhase::is_green),
                LightCondition::Red => shown.is_some_and(|p| !p.is_green()),
            };
            if !(fires && light_ok) {
                continue;
            }
            self.fired[i] = true;
            if self.rng.random_range(0.0..1.0) >= rule.probability {
                continue;
            }
            let (speed, delay) = (rule.speed, rule.delay);
            let v0 = uniform(&mut self.rng, speed);
            let delay = uniform(&mut self.rng, delay);
            self.pending.push(PendingCar {
                at_substep: substep as i64 + (delay / h).round() as i64,
                rule: i,
                v0,
            });
        }
        self.prev_phase = shown;
        let mut k = 0;
        while k < self.pending.len() {
            if self.pending[k].at_substep <= substep as i64 {
                let p = self.pending.remove(k);
                self.place(phys, p, car_front);
            } else {
                k += 1;
            }
        }
    }

    fn place(&mut self, phys: &mut PhysicsWorld, p: PendingCar, car_front: f64) {
        let rule = &self.rules[p.rule];
        let approach = rule.route.approach();
        let Some(origin) = self.layout.stop_point(approach) else {
            return; // a cross route on a map without a junction (refused by validation)
        };
        let mut s = match rule.route {
            Route::Lead => car_front - origin.0 + rule.start,
            _ => -rule.start,
        };
        let mut v = p.v0;
        // Behind the vehicles of its route that occupy the spot, standing.
        let mut queue: Vec<(f64, f64)> = (self.others.iter())
            .filter(|o| o.approach == approach)
            .map(|o| (o.s, o.s - self.rules[o.rule].length))
            .collect();
        queue.sort_by(|a, b| b.0.total_cmp(&a.0));
        for &(front, rear) in &queue {
            if s > rear - rule.min_gap && s - rule.length < front + rule.min_gap {
                s = rear - rule.min_gap;
                v = 0.0;
            }
        }
        // No faster than it can stop at comfortable braking behind the nearest ahead.
        if let Some(room) = (queue.iter())
            .filter(|(_, rear)| *rear >= s)
            .map(|(_, rear)| rear - rule.min_gap - s)
            .reduce(f64::min)
        {
            v = v.min((2.0 * rule.brake * room.max(0.0)).sqrt());
        }
        let dir = approach.direction();
        let path = match (
            rule.route,
            self.layout.junction_box,
            self.layout.stop_point(Approach::FromNorth),
        ) {
            // Into the box at its east edge, round to the southbound lane.
            (Route::OncomingLeft, Some(b), Some((lane_x, _))) => {
                Path::left_turn(origin, dir, origin.0 - b.x1, b.x1 - lane_x)
            }
            _ => Path::straight(origin, dir),
        };
        let end = (self.layout.conflict_span(approach).map(|(_, b)| b))
            .into_iter()
            .chain(path.turn_span().map(|(_, b)| b))
            .chain((rule.route == Route::Lead).then_some(self.goal_x - origin.0))
            .fold(0.0, f64::max)
            + EXIT_AFTER;
        let (centre, angle) = centre_of(path.pose(s).0, dir, rule.length);
        let body = RigidBodyBuilder::kinematic_position_based()
            .translation(centre)
            .rotation(angle);
        let collider = ColliderBuilder::cuboid((rule.length / 2.0) as Real, (rule.width / 2.0) as Real).sensor(true);
        let (body, collider) = phys.insert(body, collider);
        self.others.push(Other {
            body,
            collider,
            rule: p.rule,
            approach,
            path,
            s,
            v,
            v0: p.v0,
            end,
            age: 0.0,
            stalled: None,
            hard: HardStop::Waiting,
            waited: 0.0,
            cleared: false,
            entered: s >= 0.0,
            turning: false,
        });
    }

    /// The box a vehicle occupies, with its velocity.
    fn body_of(&self, o: &Other) -> Body {
        let rule = &self.rules[o.rule];
        let ((fx, fy), (ux, uy)) = o.front();
        let (rx, ry) = (fx - ux * rule.length, fy - uy * rule.length);
        let half = rule.width / 2.0;
        let (nx, ny) = (-uy * half, ux * half);
        Body {
            x: (fx.min(rx) - nx.abs(), fx.max(rx) + nx.abs()),
            y: (fy.min(ry) - ny.abs(), fy.max(ry) + ny.abs()),
            vel: (ux * o.v, uy * o.v),
        }
    }

    /// Advance every vehicle one sub-step of `h` s under `signals`, with the car occupying
    /// `car`; set their bodies' kinematic targets for the coming physics step.
    pub fn drive(&mut self, phys: &mut PhysicsWorld, h: f64, signals: &SignalState, car: Body) {
        let bodies: Vec<Body> = self.others.iter().map(|o| self.body_of(o)).collect();
        let accels: Vec<f64> = (0..self.others.len())
            .map(|i| self.accel(i, &bodies, car, signals, h))
            .collect();
        for (o, a) in self.others.iter_mut().zip(accels) {
            let v = o.v + a * h;
            if v < 0.0 {
                // Stops within the sub-step, where its speed reaches 0.
                o.s += if a < 0.0 { -o.v * o.v / (2.0 * a) } else { 0.0 };
                o.v = 0.0;
            } else {
                o.s += o.v * h + a * h * h / 2.0;
                o.v = v;
            }
            o.age += h;
            let (front, u) = o.front();
            let (centre, angle) = centre_of(front, u, self.rules[o.rule].length);
            let body = &mut phys.bodies[o.body];
            body.set_next_kinematic_translation(centre);
            body.set_next_kinematic_rotation(Rotation::from_angle(angle));
        }
    }

    /// The acceleration of vehicle `i` for the coming sub-step (its behaviour's state
    /// updated on the way).
    fn accel(&mut self, i: usize, bodies: &[Body], car: Body, signals: &SignalState, h: f64) -> f64 {
        let rule = self.rules[self.others[i].rule];
        let hardest = MAX_DECEL.min(self.grip);
        let o = &mut self.others[i];
        let p = (rule.accel, rule.brake, rule.headway, rule.min_gap);
        let ((fx, fy), (ux, uy)) = o.front();
        let lane = fx * -uy + fy * ux;
        let half = rule.width / 2.0 + LANE_MARGIN;
        let mut a = idm(o.v, o.v0, f64::INFINITY, 0.0, p);
        let sees_car = !matches!(rule.behaviour, Behaviour::RunsRed | Behaviour::DoesNotYield);
        let ahead = bodies
            .iter()
            .enumerate()
            .filter(|(j, _)| *j != i)
            .map(|(_, b)| *b)
            .chain(sees_car.then_some(car));
        for b in ahead {
            let corners = [(b.x.0, b.y.0), (b.x.1, b.y.1), (b.x.0, b.y.1), (b.x.1, b.y.0)];
            let span = |f: &dyn Fn(f64, f64) -> f64| {
                (corners.iter()).fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &(x, y)| {
                    (lo.min(f(x, y)), hi.max(f(x, y)))
                })
            };
            let (a0, a1) = span(&|x, y| (x - fx) * ux + (y - fy) * uy);
            let (l0, l1) = span(&|x, y| x * -uy + y * ux);
            if a1 <= 0.0 || a0 > LOOKAHEAD || l1 < lane - half || l0 > lane + half {
                continue;
            }
            let dv = o.v - (b.vel.0 * ux + b.vel.1 * uy);
            a = a.min(idm(o.v, o.v0, a0.max(1e-3), dv, p));
        }
        let aspect = match o.approach {
            Approach::FromWest | Approach::FromEast => signals.road,
            Approach::FromSouth | Approach::FromNorth => signals.cross,
        };
        // Well past its line it has entered, whatever the signal now shows: it clears the
        // box (one that could not stop for a red before its line does not stop in it).
        o.entered |= o.s >= OVERRUN;
        if !o.entered && rule.behaviour != Behaviour::RunsRed {
            let to_line = -o.s;
            let stop = match aspect {
                Aspect::Lit(LightPhase::Red) => true,
                Aspect::Lit(LightPhase::Amber) => to_line >= o.v * o.v / (2.0 * rule.brake),
                Aspect::Lit(LightPhase::Green) => false,
                Aspect::Dark => {
                    if o.v < STOPPED_SPEED && to_line < STOPPED_GAP {
                        o.waited += h;
                    }
                    o.cleared |= o.waited >= ALL_WAY_STOP_WAIT;
                    !o.cleared
                }
            };
            if stop {
                a = a.min(idm(o.v, o.v0, to_line + rule.min_gap, o.v, p));
            } else {
                o.entered = o.s >= 0.0;
            }
        }
        // A careful left-turner waits at the box while the car comes (held as at a stop
        // line until it turns with the way clear).
        if let (Some((enter, _)), Some(b), Behaviour::Careful) =
            (o.path.turn_span(), self.layout.junction_box, rule.behaviour)
            && !o.turning
        {
            let car_near = car.x.0 < b.x1 && (car.x.1 >= b.x0 || b.x0 - car.x.1 < YIELD_GAP * car.vel.0);
            if car_near {
                a = a.min(idm(o.v, o.v0, enter - o.s + rule.min_gap, o.v, p));
            } else {
                o.turning = o.s >= enter;
            }
        }
        match rule.behaviour {
            Behaviour::Stalls { at, hold } => {
                if o.stalled.is_none() && o.s >= at {
                    o.stalled = Some(0.0);
                }
                if let Some(stood) = o.stalled.as_mut()
                    && *stood < hold
                {
                    *stood += h;
                    a = -hardest;
                }
            }
            Behaviour::BrakesHard { after, decel, hold } => {
                if o.hard == HardStop::Waiting && o.age >= after {
                    o.hard = HardStop::Braking;
                }
                match o.hard {
                    HardStop::Braking if o.v > 0.0 => a = -decel,
                    HardStop::Braking => o.hard = HardStop::Holding(hold),
                    HardStop::Holding(left) if left > 0.0 => {
                        o.hard = HardStop::Holding(left - h);
                        a = a.min(0.0);
                    }
                    HardStop::Holding(_) => o.hard = HardStop::Done,
                    HardStop::Waiting | HardStop::Done => {}
                }
            }
            Behaviour::Careful | Behaviour::RunsRed | Behaviour::DoesNotYield => {}
        }
        a.max(-hardest)
    }

    /// Remove the vehicles past the end of their route.
    pub fn retire(&mut self, phys: &mut PhysicsWorld) {
        let mut i = 0;
        while i < self.others.len() {
            if self.others[i].s >= self.others[i].end {
                let o = self.others.swap_remove(i);
                phys.remove_body_with_colliders(o.body, true);
            } else {
                i += 1;
            }
        }
    }

    /// Every vehicle's collider with its velocity (its speed along its heading), for the
    /// margins ([`crate::margins`]).
    pub fn movers(&self) -> impl Iterator<Item = (ColliderHandle, Vector)> + '_ {
        self.others.iter().map(|o| {
            let (_, u) = o.front();
            (o.collider, Vector::new((u.0 * o.v) as Real, (u.1 * o.v) as Real))
        })
    }

    /// Whether the collider `car` overlaps a vehicle's on the current poses (parry's
    /// intersection test, as for pedestrians).
    pub fn hits(&self, phys: &PhysicsWorld, car: ColliderHandle) -> bool {
        let car = &phys.colliders[car];
        self.others.iter().any(|o| {
            let other = &phys.colliders[o.collider];
            rapier2d::parry::query::intersection_test(car.position(), car.shape(), other.position(), other.shape())
                .is_ok_and(|hit| hit.intersecting)
        })
    }

    /// Whether `o` is in the path of the car occupying `car` (the rule of
    /// [`crate::world::Snapshot::vehicle_in_path`]).
    fn in_path(&self, o: &Other, car: Body) -> bool {
        let zone = self.layout.junction_box.unwrap_or(self.layout.crosswalks[0].1);
        let (y0, y1) = (car.y.0 - LANE_MARGIN, car.y.1 + LANE_MARGIN);
        let rule = &self.rules[o.rule];
        let b = self.body_of(o);
        // Within 3 s at the car's speed, plus 3 s at the speed it closes on it.
        let closing = (car.vel.0 - b.vel.0).max(0.0);
        let near = (HEADWAY_SEEN * (car.vel.0 + closing)).max(NEAR_SEEN);
        let in_lane = b.y.1 > y0 && b.y.0 < y1 && b.x.1 > car.x.1;
        let in_lane_ahead = in_lane && b.x.0 - car.x.1 < near;
        let blocks_box = in_lane && b.vel.0 < BLOCKING_SPEED && b.x.0 < zone.x1 && car.x.1 < zone.x0;
        let crosses = !matches!(rule.route, Route::Lead | Route::Oncoming);
        let in_zone = b.x.1 > zone.x0 && b.x.0 < zone.x1 && b.y.1 > zone.y0 && b.y.0 < zone.y1;
        // Before its line (a turner: its turn), too fast to stop there at twice its
        // comfortable braking: it will enter (what a driver sees of a car about to run
        // its red, or to turn without yielding).
        let hold = o
            .path
            .turn_span()
            .filter(|_| !o.turning)
            .map_or(0.0, |(enter, _)| enter);
        let will_enter = o.s < hold && o.v * o.v > 2.0 * WILL_ENTER_BRAKING * rule.brake * (hold - o.s);
        let turns_ahead = rule.route == Route::OncomingLeft
            && !o.turning
            && o.v > BLOCKING_SPEED
            && hold - o.s < TURN_SEEN
            && car.x.0 < zone.x1;
        in_lane_ahead || blocks_box || turns_ahead || (crosses && ((o.s > 0.0 && in_zone) || will_enter))
    }

    /// The vehicles now, each marked in the path of the car occupying `car` or not.
    pub fn snapshots(&self, phys: &PhysicsWorld, car: Body) -> Vec<VehicleSnapshot> {
        self.others
            .iter()
            .map(|o| {
                let rule = &self.rules[o.rule];
                let b = &phys.bodies[o.body];
                VehicleSnapshot {
                    x: b.translation().x as f64,
                    y: b.translation().y as f64,
                    heading: b.rotation().angle() as f64,
                    speed: o.v,
                    length: rule.length,
                    width: rule.width,
                    route: rule.route,
                    past_stop_line: o.s,
                    in_path: self.in_path(o, car),
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const P: (f64, f64, f64, f64) = (1.5, 2.0, 1.5, 2.0);

    /// What the kinematic model leaves out of a hard stop: the car's brake dead time
    /// (0.1 s) and lag (0.2 s) would let a lead car braking at 7 m/s² from 50 km/h stop
    /// between v·(dead + τ/2) and v·(dead + τ) further on, 2.8 to 4.2 m: the kinematic
    /// lead stops shorter, so the car behind it meets the harder case.
    #[test]
    fn the_brake_lag_left_out() {
        use crate::dynamics::stopping_distance;
        use crate::map::{Dynamics, Vehicle};
        let (v, d) = (13.9, 7.0);
        let car = Vehicle {
            dynamics: Dynamics::Forces,
            brake_force: d * 1500.0,
            mass: 1500.0,
            ..Vehicle::default()
        };
        let kinematic = v * v / (2.0 * d);
        let lagged = stopping_distance(&car, v, 2.0);
        let more = lagged - kinematic;
        let (dead, tau) = (car.brake_dead_time, car.brake_lag);
        assert!(
            more > v * (dead + tau / 2.0) && more < v * (dead + tau),
            "{more} m further"
        );
    }

    #[test]
    fn idm_is_free_road_acceleration_far_from_anything() {
        assert_eq!(idm(0.0, 10.0, f64::INFINITY, 0.0, P), 1.5);
        assert_eq!(idm(10.0, 10.0, f64::INFINITY, 0.0, P), 0.0);
        // At equilibrium standing s0 behind an obstacle it neither moves nor brakes.
        assert_eq!(idm(0.0, 10.0, 2.0, 0.0, P), 0.0);
        // Closing on a standing obstacle it brakes.
        assert!(idm(10.0, 10.0, 20.0, 10.0, P) < -2.0);
    }
}
