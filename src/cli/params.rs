//! `--set KEY=VALUE` overrides of the scaled agent's parameters; the parsing lives in
//! the library ([`crate::overrides`]) because sweeps use it too.

pub use crate::overrides::{apply, help, keys, set_one, set_value};
