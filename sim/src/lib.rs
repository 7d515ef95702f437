//! # unforeseen-sim: a Rapier 2D signalized intersection built from map files
//!
//! A straight road runs along +x from the car's start to a destination. On the
//! way there is a crosswalk with a traffic light (a cycle of green, amber and
//! red phases). The car is a dynamic rigid body; the three actions of the
//! paper ([`Action`]: maintain, speed up, slow down) act on it through
//! longitudinal velocity control (`dynamics: Ideal`, the paper's) or through forces
//! (`dynamics: Forces`: engine, brakes with lag, rolling resistance, drag, and the
//! friction of the road surface, [`dynamics`]); Rapier integrates and finds contacts. Pedestrians are kinematic bodies with sensor colliders
//! that cross the crosswalk when the map's spawn rules say so. A collision is the
//! car's collider intersecting a pedestrian's (parry's intersection test, the one
//! Rapier's narrow phase runs on sensors) after any physics sub-step.
//!
//! Everything about a scenario is in a [`Map`] (RON; see `maps/README.md`):
//!
//! ```
//! use unforeseen_sim::{embedded, Action, World};
//! let map = embedded::load("jaywalk").unwrap();
//! let mut world = World::from_map(&map, 42);
//! let out = world.step(Action::SpeedUp);
//! let snap = world.snapshot();
//! assert_eq!(out.step, 1);
//! assert!(snap.car_speed > 5.9 && snap.car_speed < 6.1);
//! ```
//!
//! Determinism: the same map, seed and actions give bit-identical snapshots.
//!
//! Modules: [`map`] (the map's fields and defaults), [`light`] (the traffic
//! light), [`dynamics`] (the force-driven vehicle model), [`world`] (car, pedestrians,
//! surface, stepping), [`embedded`] (the shipped
//! maps), and the loader with its diagnostics ([`MapError`], [`Diagnostic`]).

mod draw;
pub mod dynamics;
pub mod embedded;
pub mod junction;
pub mod light;
mod load;
mod locate;
pub mod map;
mod map_texts;
pub mod margins;
mod overrides;
mod routes;
pub mod signals;
pub mod traffic;
mod validate;
pub mod world;

pub use junction::{Approach, Layout};
pub use light::{LightPhase, light_at};
pub use load::{Diagnostic, EMBEDDED_PREFIX, MAX_BASE_DEPTH, MAX_FILE_BYTES, MAX_NESTING, MapError};
pub use map::{
    Arm, Behaviour, Bins, CrossCycle, Crosswalk, CrosswalkBins, DarkReading, DistanceEdges, Dynamics, Episode,
    Expectation, Junction, Light, LightCondition, Map, Offset, Outage, Pause, Phase, Reward, Road, Route, Side,
    SpawnRule, SurfacePatch, TrafficRule, Trigger, Vehicle,
};
pub use margins::Margins;
pub use overrides::FieldValue;
pub use signals::{Aspect, SignalState, Walk};
pub use traffic::VehicleSnapshot;
pub use validate::{
    DECISION_DT, MAX_EPISODE_PLANNING, MAX_EPISODE_SUBSTEPS, MAX_JOINT_STATES, MAX_LIST, MAX_METRES, MAX_PEDESTRIANS,
    MAX_SPAWN_RULES, MAX_STEPS, MAX_SUBSTEPS, PHYSICS_HZ,
};
pub use world::{Action, PedestrianSnapshot, Snapshot, StepOutcome, World};
