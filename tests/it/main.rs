//! The root crate's integration tests, one module per subject, in one test binary (one
//! link instead of one per file keeps `cargo test` builds short). Modules share one
//! small trained agent (`common::bundle`).

mod batch;
mod cli;
mod common;
mod compare_determinism;
mod corrupt_agent_files;
mod crosswalk;
mod doc_paths;
mod end_to_end;
mod figures;
mod fuzz;
mod golden;
mod guard;
mod merge;
mod newcomer;
mod outputs;
mod overrides;
mod protocols;
mod readme;
mod red_light;
mod reference;
mod replay;
mod robustness;
mod safety;
mod search;
mod stream;
mod stream_memory;
mod svg_text;
mod train_seeds;
