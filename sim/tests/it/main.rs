//! The simulation's integration tests, one module per subject, in one test binary (one
//! link instead of one per file keeps `cargo test` builds short).

mod bad_maps;
mod common;
mod determinism;
mod junction;
mod margins;
mod red_light;
mod scenarios;
mod traffic_behaviours;
mod triggers;
mod vehicle_forces;
mod vehicle_kinematics;
