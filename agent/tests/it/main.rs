//! The agent's integration tests, one module per subject, in one test binary (one link
//! instead of one per file keeps `cargo test` builds short).

mod aif_driving;
mod aif_gate;
mod aif_pymdp;
mod bundle_and_controllers;
mod closed_form;
mod hand_worked;
mod planning_root;
mod properties;
mod pymdp_crossval;
mod tie_break;
mod transition_cost;
