//! `--set KEY=VALUE` overrides of the scaled agent's parameters; the parsing lives in
//! the library ([`unforeseen_harness::overrides`]) because sweeps use it too.

pub use unforeseen_harness::overrides::{apply, help, keys, set_one, set_value};
