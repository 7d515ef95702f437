//! The Rapier world built from a map: the car (a dynamic body under longitudinal
//! velocity control, `dynamics: Ideal`, or driven by forces, `dynamics: Forces`),
//! pedestrians (kinematic bodies with sensor colliders), the road surface, the traffic
//! light, spawn rules, and the episode's end.

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rapier2d::prelude::*;

use crate::draw::uniform;
use crate::dynamics::{Drivetrain, Pedal};
use crate::light::{LightPhase, light_at};
use crate::map::{Dynamics, LightCondition, Map, Offset, Pause, Side, SurfacePatch, Trigger};
use crate::margins::{Margins, Measure};
use crate::signals::{Aspect, Controller, SignalState, TriggerView};
use crate::traffic::{Body, Traffic, VehicleSnapshot};

/// The three longitudinal actions of the paper.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Action {
    /// Hold the current speed (under `Forces`: a cruise controller, within the forces
    /// available).
    Maintain = 0,
    /// Accelerate at `vehicle.max_accel` (under `Forces`: full drive force) up to
    /// `vehicle.max_speed`.
    SpeedUp = 1,
    /// Brake at `vehicle.max_brake` (under `Forces`: demand `vehicle.brake_force`), never
    /// below 0 m/s.
    SlowDown = 2,
}

impl Action {
    /// All actions, in index order.
    pub const ALL: [Action; 3] = [Action::Maintain, Action::SpeedUp, Action::SlowDown];

    /// The action with this index (0 maintain, 1 speed up, 2 slow down).
    pub fn from_index(i: usize) -> Option<Action> {
        Action::ALL.get(i).copied()
    }

    /// This action's index.
    pub fn index(self) -> usize {
        self as usize
    }
}

impl std::fmt::Display for Action {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Action::Maintain => "maintain",
            Action::SpeedUp => "speed up",
            Action::SlowDown => "slow down",
        })
    }
}

/// One pedestrian as seen by an observer.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PedestrianSnapshot {
    /// Position, m.
    pub x: f64,
    /// Position, m (the car's lane is at negative y).
    pub y: f64,
    /// Velocity, m/s.
    pub vx: f64,
    /// Velocity, m/s.
    pub vy: f64,
    /// Whether the centre is within the road part of the crosswalk (kerb to kerb).
    pub on_crosswalk: bool,
}

/// Everything an observer (the discretizer) may look at after a tick.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// Decision ticks done.
    pub step: u32,
    /// Simulated time, s.
    pub time: f64,
    /// x of the car's front bumper, m.
    pub car_x: f64,
    /// Speed along +x, m/s (>= 0).
    pub car_speed: f64,
    /// `road.goal_x - car_x`, m; <= 0 once arrived.
    pub distance_to_goal: f64,
    /// The car's signal as its agent reads it (its L factor): the phase its head shows,
    /// or while dark the map's `junction.dark_reads_as`.
    pub light: LightPhase,
    /// Seconds until the car's signal changes (0 while dark: no head counts down).
    pub light_time_left: f64,
    /// Every head of the junction now (without a junction: the car's light, and a
    /// cross street that is always red).
    pub signals: SignalState,
    /// The other vehicles now.
    pub vehicles: Vec<VehicleSnapshot>,
    /// Whether a vehicle is in the car's path: in its lane ahead of it within 3 s at
    /// the car's speed plus 3 s at the speed it closes on it (10 m at least), or standing
    /// (below 1 m/s) in its lane with its rear before the far side of the junction box
    /// while the car has not reached the box (the box is blocked), or an oncoming car
    /// signalling a left turn that comes on (faster than 1 m/s) within 30 m of its turn
    /// while the car has not passed the box, or on a route that crosses the car's (cross
    /// traffic, an oncoming left-turner) in the box past its stop line, or before its
    /// line (a turner: its turn) too fast to stop there at twice its comfortable braking
    /// (about to run its red, or to turn without yielding). Always false on a map
    /// without traffic.
    pub vehicle_in_path: bool,
    /// Pedestrians currently in the world (spawned and not yet gone).
    pub pedestrians: Vec<PedestrianSnapshot>,
    /// The surface patches on the road now (`road.surface`'s, once appeared), in the
    /// map's order.
    pub surface: Vec<SurfacePatch>,
}

impl Snapshot {
    /// Whether any pedestrian is on the road part of the crosswalk.
    pub fn pedestrian_on_crosswalk(&self) -> bool {
        self.pedestrians.iter().any(|p| p.on_crosswalk)
    }

    /// Whether an obstacle is in the car's path: a pedestrian on the crosswalk or a
    /// vehicle in its path ([`Snapshot::vehicle_in_path`]). What the agent's `p` reads
    /// (issue 45); the paper's "pedestrian on the crosswalk" on a map without traffic.
    pub fn obstacle_in_path(&self) -> bool {
        self.vehicle_in_path || self.pedestrian_on_crosswalk()
    }
}

/// What one decision tick did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOutcome {
    /// Decision ticks done (after this one).
    pub step: u32,
    /// The car touched a pedestrian or another vehicle (their colliders intersect after
    /// a sub-step).
    pub collision: bool,
    /// The car's front reached the destination (and there was no collision).
    pub goal: bool,
    /// The step limit was reached without goal or collision.
    pub timeout: bool,
    /// Metres the car's front advanced during this tick.
    pub progress: f64,
    /// The car's front crossed the crosswalk's near edge during this tick, in a sub-step
    /// whose light (at the sub-step's start, as the spawn rules see it) was `Red` (amber
    /// and a dark signal are not a violation). Reported whatever the map's `reward.red_light`.
    pub red_light: bool,
}

impl StepOutcome {
    /// Whether the episode is over.
    pub fn done(&self) -> bool {
        self.collision || self.goal || self.timeout
    }
}

/// A pedestrian walking across the crosswalk.
struct Pedestrian {
    body: RigidBodyHandle,
    collider: ColliderHandle,
    x: f64,
    y0: f64,
    /// +1 walking towards +y, -1 towards -y.
    dir: f64,
    speed: f64,
    walked: f64,
    length: f64,
    pause: Option<Pause>,
    pause_left: f64,
    moving: bool,
}

/// A pedestrian decided by a rule, waiting for its start time.
struct Pending {
    /// Sub-step at which it starts walking; earlier than now means it is
    /// placed part-way across.
    at_substep: i64,
    rule: usize,
    side_far: bool,
    speed: f64,
    x_offset: f64,
}

/// The simulated intersection. Drive it with [`World::step`].
///
/// ```
/// use unforeseen_sim::{embedded, Action, World};
/// let map = embedded::load("intersection").unwrap();
/// let mut world = World::from_map(&map, 7);
/// while !world.is_done() {
///     let out = world.step(Action::SpeedUp);
///     assert!(out.progress >= 0.0);
/// }
/// assert!(world.snapshot().distance_to_goal <= 0.0 || world.snapshot().step == map.episode.max_steps);
/// ```
pub struct World {
    map: Map,
    phys: PhysicsWorld,
    car: RigidBodyHandle,
    car_collider: ColliderHandle,
    rng: ChaCha8Rng,
    light_offset: f64,
    substeps: u32,
    substep: u64,
    step: u32,
    fired: Vec<bool>,
    pending: Vec<Pending>,
    peds: Vec<Pedestrian>,
    /// The car's signal's phase shown at the last sub-step (`None`: dark).
    prev_phase: Option<LightPhase>,
    /// The signal controller of every approach.
    signals: Controller,
    /// The other vehicles.
    traffic: Traffic,
    terminal: Option<StepOutcome>,
    /// The drive train and brakes under `dynamics: Forces`.
    drivetrain: Option<Drivetrain>,
    /// Which of `road.surface` lie on the road now (a triggered patch appears later).
    surface_on: Vec<bool>,
    /// The episode's margins so far, when measured ([`World::measure_margins`]).
    margins: Option<Measure>,
}

impl World {
    /// Build the world for one episode. All randomness (light offset, spawn
    /// draws) comes from `seed`. The map should be valid (as returned by the
    /// loaders); invalid numbers are not checked here again.
    pub fn from_map(map: &Map, seed: u64) -> World {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let cycle = map.light.cycle_length();
        let light_offset = match map.light.offset {
            Offset::Fixed(o) => o,
            Offset::Random => rng.random_range(0.0..1.0) * cycle,
        };
        let mut phys = PhysicsWorld::new();
        phys.gravity = Vector::ZERO;
        phys.integration_parameters.dt = (1.0 / map.episode.physics_hz) as Real;
        // What the scene does not need: no CCD (a 4.5 m car at 60 Hz would
        // tunnel only above ~290 m/s), and no position-stabilisation
        // passes (they correct penetrations of solid contacts and joints; the scene has
        // neither: pedestrians are sensors), and one solver iteration instead of 4: the
        // car is the only dynamic body and has no contact or joint to solve, so more
        // iterations only split the same free motion into smaller integration sub-steps.
        // One iteration saves 19% of the training's instructions (BENCHMARKS.md); it
        // moves positions in their last bits, which decides the distance bin where the
        // car stops exactly on a bin edge (EXPERIMENTS.md, slow_walker).
        phys.integration_parameters.max_ccd_substeps = 0;
        phys.integration_parameters.num_internal_stabilization_iterations = 0;
        phys.integration_parameters.num_solver_iterations = 1;

        let v = &map.vehicle;
        let body = RigidBodyBuilder::dynamic()
            .translation(Vector::new(
                (v.start_x - v.length / 2.0) as Real,
                map.road.car_lane_y() as Real,
            ))
            .linvel(Vector::new(v.start_speed as Real, 0.0))
            .linear_damping(v.damping as Real)
            .angular_damping(0.0)
            // The car stays in its lane and pointed along +x.
            .enabled_translations(true, false)
            .lock_rotations()
            .can_sleep(false);
        let collider = ColliderBuilder::cuboid((v.length / 2.0) as Real, (v.width / 2.0) as Real)
            .mass(v.mass as Real)
            .friction(0.0);
        let (car, car_collider) = phys.insert(body, collider);
        let prev_phase = Some(light_at(&map.light, light_offset, 0.0).0);
        let drivetrain = (v.dynamics == Dynamics::Forces)
            .then(|| Drivetrain::new(v, map.road.air_density, 1.0 / map.episode.physics_hz));
        World {
            map: map.clone(),
            phys,
            car,
            car_collider,
            rng,
            light_offset,
            substeps: map.episode.substeps(),
            substep: 0,
            step: 0,
            fired: vec![false; map.pedestrians.len()],
            pending: Vec::new(),
            peds: Vec::new(),
            prev_phase,
            signals: Controller::new(map, light_offset),
            traffic: Traffic::new(map, seed),
            terminal: None,
            drivetrain,
            surface_on: map.road.surface.iter().map(|p| p.trigger.is_none()).collect(),
            margins: None,
        }
    }

    /// Measures the episode's margins after every sub-step from now on
    /// ([`crate::margins`]); they change nothing in the episode.
    pub fn measure_margins(&mut self) {
        self.margins.get_or_insert_with(Measure::default);
    }

    /// The episode's smallest margins so far (none unless [`World::measure_margins`]).
    pub fn margins(&self) -> Option<Margins> {
        self.margins.as_ref().map(Measure::margins)
    }

    /// The surface patches on the road now, in the map's order (a later one lies over
    /// an earlier one).
    pub fn surface(&self) -> impl Iterator<Item = &SurfacePatch> {
        self.map
            .road
            .surface
            .iter()
            .zip(&self.surface_on)
            .filter(|(_, on)| **on)
            .map(|(p, _)| p)
    }

    /// The road's friction coefficient at `x`: the last patch on the road there, else
    /// `road.friction`.
    pub fn friction_at(&self, x: f64) -> f64 {
        self.surface()
            .filter(|p| p.from <= x && x <= p.to)
            .last()
            .map_or(self.map.road.friction, |p| p.friction)
    }

    /// The friction the car's tyres have: the mean of its two axles' road (each carries
    /// half the weight), the axles a sixth of the body's length in from either end.
    fn car_friction(&self) -> f64 {
        let (front, length) = (self.car_front(), self.map.vehicle.length);
        (self.friction_at(front - length / 6.0) + self.friction_at(front - length * 5.0 / 6.0)) / 2.0
    }

    /// The map this world was built from.
    pub fn map(&self) -> &Map {
        &self.map
    }

    /// Whether the episode has ended (goal, collision or time-out).
    pub fn is_done(&self) -> bool {
        self.terminal.is_some()
    }

    /// The light's cycle offset used in this episode, s.
    pub fn light_offset(&self) -> f64 {
        self.light_offset
    }

    fn time_at(&self, substep: u64) -> f64 {
        substep as f64 / self.map.episode.physics_hz
    }

    fn car_front(&self) -> f64 {
        self.phys.bodies[self.car].translation().x as f64 + self.map.vehicle.length / 2.0
    }

    fn car_speed(&self) -> f64 {
        (self.phys.bodies[self.car].linvel().x as f64).max(0.0)
    }

    /// Advance one decision tick (`episode.decision_dt` seconds in
    /// `decision_dt × physics_hz` sub-steps) with `action` held throughout.
    /// Stepping a finished world changes nothing and returns the terminal outcome again.
    pub fn step(&mut self, action: Action) -> StepOutcome {
        if let Some(t) = self.terminal {
            return t;
        }
        let start_x = self.car_front();
        let mut collision = false;
        let mut goal = false;
        let mut red_light = false;
        let near_x = self.map.crosswalk_near_x();
        let v0 = self.car_speed();
        for k in 1..=self.substeps {
            let t = self.time_at(self.substep);
            let view = self.trigger_view(t);
            self.signals.fire(&view);
            self.spawn_due();
            self.lay_surface();
            self.move_pedestrians();
            if !self.traffic.is_empty() {
                self.move_traffic(t, &view);
            }
            self.control_car(action, v0, k);
            let before = self.car_front();
            self.phys.step();
            self.substep += 1;
            self.after_substep();
            self.measure();
            if before < near_x && self.car_front() >= near_x {
                red_light |= self.signals.state(t).road == Aspect::Lit(LightPhase::Red);
            }
            if self.car_touches_pedestrian() || self.traffic.hits(&self.phys, self.car_collider) {
                collision = true;
                break;
            }
            if self.car_front() >= self.map.road.goal_x {
                goal = true;
                break;
            }
        }
        self.step += 1;
        let timeout = !collision && !goal && self.step >= self.map.episode.max_steps;
        let out = StepOutcome {
            step: self.step,
            collision,
            goal,
            timeout,
            progress: self.car_front() - start_x,
            red_light,
        };
        if out.done() {
            self.terminal = Some(out);
        }
        out
    }

    /// What triggers may look at, at the start of the sub-step at time `t`.
    fn trigger_view(&self, t: f64) -> TriggerView {
        TriggerView {
            t,
            phase: self.signals.cycle_phase(t).0,
            to_cross: self.map.crosswalk_near_x() - self.car_front(),
            speed: self.car_speed(),
        }
    }

    /// Spawn the vehicles due and drive every vehicle one sub-step from time `t`.
    fn move_traffic(&mut self, t: f64, view: &TriggerView) {
        let signals = self.signals.state(t);
        let h = 1.0 / self.map.episode.physics_hz;
        let front = self.car_front();
        self.traffic
            .spawn_due(&mut self.phys, self.substep, h, view, signals.road.phase(), front);
        let car = self.car_body();
        self.traffic.drive(&mut self.phys, h, &signals, car);
    }

    /// The car's box and velocity, as the other vehicles see it.
    fn car_body(&self) -> Body {
        let (v, front) = (&self.map.vehicle, self.car_front());
        let lane = self.map.road.car_lane_y();
        Body {
            x: (front - v.length, front),
            y: (lane - v.width / 2.0, lane + v.width / 2.0),
            vel: (self.car_speed(), 0.0),
        }
    }

    /// Whether the car's collider overlaps a pedestrian's on the current poses: the
    /// test Rapier's narrow phase runs on a sensor pair (parry's `intersection_test`),
    /// run after every sub-step, so a collision is reported on the sub-step the shapes
    /// first overlap. (Rapier's own sensor events arrive one sub-step late with four
    /// solver iterations and two with one, as measured on the scene of the test
    /// `collision_is_reported_when_the_shapes_touch`.)
    fn car_touches_pedestrian(&self) -> bool {
        let car = &self.phys.colliders[self.car_collider];
        self.peds.iter().any(|p| {
            let ped = &self.phys.colliders[p.collider];
            rapier2d::parry::query::intersection_test(car.position(), car.shape(), ped.position(), ped.shape())
                .is_ok_and(|hit| hit.intersecting)
        })
    }

    /// Takes in this sub-step's margins of every pedestrian and vehicle
    /// ([`crate::margins`]), when measured: the clearance of the colliders on the current
    /// poses, on a collision course within the episode's remaining time its
    /// time-to-collision and stopping margin, and the tracks of the post-encroachment time.
    fn measure(&mut self) {
        let Some(mut measure) = self.margins.take() else { return };
        let car = &self.phys.colliders[self.car_collider];
        let speed = self.car_speed();
        let stop = crate::dynamics::stopping_distance(&self.map.vehicle, speed, self.car_friction());
        let now = self.time_at(self.substep);
        let episode_end = f64::from(self.map.episode.max_steps) * self.map.episode.decision_dt;
        let horizon = (episode_end - now).max(0.0) as Real;
        let car_velocity = Vector::new(speed as Real, 0.0);
        let (lane, half_width) = (self.map.road.car_lane_y(), self.map.vehicle.width / 2.0);
        measure.car_at(now, self.car_front());
        let peds = self.peds.iter().map(|p| {
            let walking = if p.moving && p.pause_left <= 0.0 {
                p.dir * p.speed
            } else {
                0.0
            };
            (false, p.collider, Vector::new(0.0, walking as Real))
        });
        let vehicles = self.traffic.movers().map(|(c, v)| (true, c, v));
        for (vehicle, handle, velocity) in peds.chain(vehicles) {
            let other = &self.phys.colliders[handle];
            let Ok(clearance) =
                rapier2d::parry::query::distance(car.position(), car.shape(), other.position(), other.shape())
            else {
                continue;
            };
            let options = rapier2d::parry::query::ShapeCastOptions {
                stop_at_penetration: true,
                ..rapier2d::parry::query::ShapeCastOptions::with_max_time_of_impact(horizon)
            };
            let hit = rapier2d::parry::query::cast_shapes(
                car.position(),
                car_velocity,
                car.shape(),
                other.position(),
                velocity,
                other.shape(),
                options,
            );
            let course = hit.ok().flatten().map(|h| {
                let ttc = f64::from(h.time_of_impact);
                (ttc, speed * ttc - stop)
            });
            measure.record(vehicle, f64::from(clearance.distance), course);
            if let Some(ball) = other.shape().as_ball().filter(|_| !vehicle) {
                let at = other.position().translation;
                let gap = ((f64::from(at.y) - lane).abs() - half_width).max(0.0);
                let radius = f64::from(ball.radius);
                measure.pedestrian_at(now, f64::from(at.x), gap, radius, self.map.vehicle.length);
            }
        }
        self.margins = Some(measure);
    }

    /// Velocity control for sub-step `k` (1-based) of a tick that began at
    /// speed `v0`: the body's velocity is set to the speed integrated at
    /// `max_accel` / `max_brake`, clamped to [0, `max_speed`]; Rapier then
    /// integrates the position and detects contacts. Without damping the target
    /// is planned from `v0` (so ticks land exactly on `v0 ± a·dt` and f32
    /// rounding never accumulates); with damping it builds on the body's
    /// current, damped speed.
    ///
    /// Under `Forces` the drive train drives the car instead (`drive_by_forces`,
    /// "maintain" holding `v0`).
    fn control_car(&mut self, action: Action, v0: f64, k: u32) {
        if self.drivetrain.is_some() {
            self.drive_by_forces(action, v0);
            return;
        }
        let v = &self.map.vehicle;
        let h = 1.0 / self.map.episode.physics_hz;
        let body = &mut self.phys.bodies[self.car];
        let rate = match action {
            Action::Maintain => 0.0,
            Action::SpeedUp => v.max_accel,
            Action::SlowDown => -v.max_brake,
        };
        let target = if v.damping == 0.0 {
            v0 + rate * h * k as f64
        } else {
            body.linvel().x as f64 + rate * h
        };
        let target = target.clamp(0.0, v.max_speed);
        body.set_linvel(Vector::new(target as Real, 0.0), true);
    }

    /// `dynamics: Forces`: the drive train's net force for the coming sub-step, on the
    /// friction under the car's axles, replaces the force on the car's body.
    fn drive_by_forces(&mut self, action: Action, v0: f64) {
        let mu = self.car_friction();
        let speed = self.phys.bodies[self.car].linvel().x as f64;
        let pedal = match action {
            Action::SpeedUp => Pedal::Drive,
            Action::SlowDown => Pedal::Brake,
            Action::Maintain => Pedal::Cruise(v0),
        };
        let Some(drivetrain) = self.drivetrain.as_mut() else {
            return;
        };
        let force = drivetrain.force(pedal, speed, mu);
        let body = &mut self.phys.bodies[self.car];
        body.reset_forces(true);
        body.add_force(Vector::new(force as Real, 0.0), true);
    }

    /// Keep the car's speed within [0, max_speed] after f32 integration.
    fn after_substep(&mut self) {
        let max = self.map.vehicle.max_speed as Real;
        let body = &mut self.phys.bodies[self.car];
        let vx = body.linvel().x;
        if vx < 0.0 {
            body.set_linvel(Vector::ZERO, true);
        } else if vx > max {
            body.set_linvel(Vector::new(max, 0.0), true);
        }
        self.traffic.retire(&mut self.phys);
        // Remove pedestrians that reached the far sidewalk.
        let mut i = 0;
        while i < self.peds.len() {
            if self.peds[i].walked >= self.peds[i].length {
                let p = self.peds.swap_remove(i);
                self.phys.remove_body_with_colliders(p.body, true);
            } else {
                i += 1;
            }
        }
    }

    /// Lay the surface patches whose trigger holds at the current sub-step (once laid, a
    /// patch stays): `RedStarts` / `GreenStarts` hold while the light shows that phase,
    /// the others as for a spawn rule.
    fn lay_surface(&mut self) {
        if self.surface_on.iter().all(|on| *on) {
            return;
        }
        let view = self.trigger_view(self.time_at(self.substep));
        for (on, patch) in self.surface_on.iter_mut().zip(&self.map.road.surface) {
            *on = *on || patch.trigger.is_none_or(|t| view.holds(t));
        }
    }

    /// Fire spawn rules whose trigger holds at the current sub-step, and create
    /// pedestrians whose delay has elapsed.
    fn spawn_due(&mut self) {
        let t = self.time_at(self.substep);
        // The phase the car's head shows (`None` while dark: no phase starts, and only
        // `LightCondition::Any` is met).
        let phase = self.signals.state(t).road.phase();
        let front = self.car_front();
        let speed = self.car_speed();
        let near_x = self.map.crosswalk_near_x();
        let to_cross = near_x - front;
        let h = 1.0 / self.map.episode.physics_hz;
        for i in 0..self.map.pedestrians.len() {
            let rule = &self.map.pedestrians[i];
            // A phase-start rule at time 0 inside its phase fires "in the past":
            // the pedestrian is placed where it would be had the world been
            // running (so an episode that starts mid-red can meet one).
            let at_start = self.substep == 0;
            let mut elapsed = 0.0;
            let fires = match rule.trigger {
                Trigger::RedStarts | Trigger::GreenStarts => {
                    let want = if rule.trigger == Trigger::RedStarts {
                        LightPhase::Red
                    } else {
                        LightPhase::Green
                    };
                    if at_start && phase == Some(want) {
                        elapsed = self.phase_elapsed(t);
                        true
                    } else {
                        phase == Some(want) && self.prev_phase != Some(want)
                    }
                }
                Trigger::AtTime(at) => !self.fired[i] && t + 1e-9 >= at,
                Trigger::CarWithin { min, max } => !self.fired[i] && to_cross >= min && to_cross <= max,
                Trigger::CarArrivesWithin(secs) => {
                    !self.fired[i] && to_cross > 0.0 && speed > 1e-3 && to_cross <= secs * speed
                }
            };
            let light_ok = match rule.light {
                LightCondition::Any => true,
                LightCondition::Green => phase.is_some_and(LightPhase::is_green),
                LightCondition::Red => phase.is_some_and(|p| !p.is_green()),
            };
            if !(fires && light_ok) {
                continue;
            }
            self.fired[i] = true;
            let rule = rule.clone();
            if self.rng.random_range(0.0..1.0) >= rule.probability {
                continue;
            }
            let side_far = match rule.side {
                Side::Near => false,
                Side::Far => true,
                Side::Random => self.rng.random_range(0.0..1.0) < 0.5,
            };
            let speed = uniform(&mut self.rng, rule.speed);
            let delay = uniform(&mut self.rng, rule.delay);
            let x_offset = uniform(&mut self.rng, rule.x_offset);
            self.pending.push(Pending {
                at_substep: self.substep as i64 + ((delay - elapsed) / h).round() as i64,
                rule: i,
                side_far,
                speed,
                x_offset,
            });
        }
        self.prev_phase = phase;

        let mut k = 0;
        while k < self.pending.len() {
            if self.pending[k].at_substep <= self.substep as i64 {
                let p = self.pending.remove(k);
                self.spawn(p);
            } else {
                k += 1;
            }
        }
    }

    fn spawn(&mut self, p: Pending) {
        let rule = &self.map.pedestrians[p.rule];
        let half = self.map.road.half_width();
        let length = 2.0 * (half + rule.start_back);
        let h = 1.0 / self.map.episode.physics_hz;
        let walked = (self.substep as i64 - p.at_substep).max(0) as f64 * h * p.speed;
        if walked >= length {
            return; // it would already have crossed
        }
        let pause = rule.pause.filter(|pa| pa.after > walked);
        let dir = if p.side_far { -1.0 } else { 1.0 };
        let y0 = -dir * (half + rule.start_back);
        let x = self.map.crosswalk.x + p.x_offset;
        let body = RigidBodyBuilder::kinematic_position_based().translation(Vector::new(x as Real, y0 as Real));
        let collider = ColliderBuilder::ball(rule.radius as Real).sensor(true);
        let (body, collider) = self.phys.insert(body, collider);
        self.peds.push(Pedestrian {
            body,
            collider,
            x,
            y0,
            dir,
            speed: p.speed,
            walked,
            length,
            pause,
            pause_left: 0.0,
            moving: true,
        });
    }

    /// Seconds since the current light phase began.
    fn phase_elapsed(&self, t: f64) -> f64 {
        let total = self.map.light.cycle_length();
        let mut pos = (self.light_offset + t).rem_euclid(total);
        for p in &self.map.light.cycle {
            if pos < p.duration {
                return pos;
            }
            pos -= p.duration;
        }
        0.0
    }

    /// Set each pedestrian's kinematic target for the coming sub-step.
    fn move_pedestrians(&mut self) {
        let h = 1.0 / self.map.episode.physics_hz;
        for p in &mut self.peds {
            if p.pause_left > 0.0 {
                p.pause_left -= h;
                p.moving = false;
            } else {
                let mut next = p.walked + p.speed * h;
                if let Some(pa) = p.pause
                    && p.walked < pa.after
                    && next >= pa.after
                {
                    next = pa.after;
                    p.pause_left = pa.duration;
                    p.pause = None;
                }
                p.moving = next > p.walked;
                p.walked = next.min(p.length);
            }
            let target = Vector::new(p.x as Real, (p.y0 + p.dir * p.walked) as Real);
            self.phys.bodies[p.body].set_next_kinematic_translation(target);
        }
    }

    /// The observable state after the last tick.
    pub fn snapshot(&self) -> Snapshot {
        let t = self.time_at(self.substep);
        let (light, left) = self.signals.reading(t);
        let car_x = self.car_front();
        let half = self.map.road.half_width();
        let cw = &self.map.crosswalk;
        let pedestrians = self
            .peds
            .iter()
            .map(|p| {
                let pos = self.phys.bodies[p.body].translation();
                let (x, y) = (pos.x as f64, pos.y as f64);
                let vy = if p.moving && p.pause_left <= 0.0 {
                    p.dir * p.speed
                } else {
                    0.0
                };
                PedestrianSnapshot {
                    x,
                    y,
                    vx: 0.0,
                    vy,
                    on_crosswalk: (x - cw.x).abs() <= cw.width / 2.0 && y.abs() <= half,
                }
            })
            .collect();
        let vehicles = self.traffic.snapshots(&self.phys, self.car_body());
        Snapshot {
            step: self.step,
            time: t,
            car_x,
            car_speed: self.car_speed(),
            distance_to_goal: self.map.road.goal_x - car_x,
            light,
            light_time_left: left,
            pedestrians,
            surface: self.surface().copied().collect(),
            signals: self.signals.state(t),
            vehicle_in_path: vehicles.iter().any(|v| v.in_path),
            vehicles,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runners may drive worlds on several threads (one world per thread).
    #[test]
    fn world_is_send() {
        fn send<T: Send>() {}
        send::<World>();
        send::<Snapshot>();
    }
}
