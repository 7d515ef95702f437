//! The command line's integration tests, one module per subject, in one test binary (one
//! link instead of one per file keeps `cargo test` builds short): what runs the built
//! binary, and what checks the fronts against each other. Modules share one small trained
//! agent (`unforeseen_harness::fixtures::bundle`); the harness's own end-to-end tests are
//! in `harness/tests/it`.

mod batch;
mod cli;
mod common;
mod compare_determinism;
mod corrupt_agent_files;
mod doc_paths;
mod estimate;
mod guard;
mod merge;
mod newcomer;
mod outputs;
mod overrides;
mod readme;
mod red_light;
mod reference;
mod replay;
mod robustness;
mod search;
mod stream;
mod stream_memory;
mod train_seeds;
mod writers;
