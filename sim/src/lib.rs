//! # unforeseen-sim: a Rapier 2D signalized intersection built from map files
//!
//! A straight road runs along +x from the car's start to a destination. On the
//! way there is a crosswalk with a traffic light (a cycle of green, amber and
//! red phases). The car is a dynamic rigid body; the three actions of the
//! paper ([`Action`]: maintain, speed up, slow down) act on it through
//! longitudinal velocity control (Rapier integrates it and finds contacts). Pedestrians are kinematic bodies with sensor colliders
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
//! light), [`world`] (car, pedestrians, stepping), [`embedded`] (the shipped
//! maps), and the loader with its diagnostics ([`MapError`], [`Diagnostic`]).

pub mod embedded;
pub mod light;
mod load;
pub mod map;
mod map_texts;
mod validate;
pub mod world;

pub use light::{LightPhase, light_at};
pub use load::{Diagnostic, EMBEDDED_PREFIX, MAX_BASE_DEPTH, MAX_FILE_BYTES, MAX_NESTING, MapError};
pub use map::{
    Bins, Crosswalk, CrosswalkBins, DistanceEdges, Episode, Expectation, Light, LightCondition, Map, Offset, Pause,
    Phase, Reward, Road, Side, SpawnRule, Trigger, Vehicle,
};
pub use validate::{
    DECISION_DT, MAX_EPISODE_PLANNING, MAX_EPISODE_SUBSTEPS, MAX_JOINT_STATES, MAX_LIST, MAX_METRES, MAX_PEDESTRIANS,
    MAX_SPAWN_RULES, MAX_STEPS, MAX_SUBSTEPS, PHYSICS_HZ,
};
pub use world::{Action, PedestrianSnapshot, Snapshot, StepOutcome, World};
