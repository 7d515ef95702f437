//! The world model `W` (§II-A eq. "world model"; Dirichlet parameters §V), one concept
//! per file:
//!
//! - [`WorldModel`] (`world.rs`): factor CPTs with Dirichlet counts, the joint `B[u]`
//!   materialised from them, the observation model `A` with Dirichlet counts,
//!   preferences `C` and the state prior `D`;
//! - [`GenerativeModel`] and [`TransitionCost`] (`generative.rs`): the plain matrices
//!   perception and planning read, and the preference over transitions beside `C`;
//! - [`CrashModel`] (`crash.rs`): the crosswalk's crash hazard (beyond the paper);
//! - `pooling.rs`: persistence pooling ([`WorldModel::set_persistence_pooling`]);
//! - `stored.rs`: the world model as agent files store it, and the checks of a loaded one.

mod crash;
mod generative;
mod pooling;
mod stored;
mod world;

pub use crash::CrashModel;
pub use generative::{GenerativeModel, TransitionCost};
pub use world::WorldModel;
