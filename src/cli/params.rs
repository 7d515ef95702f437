//! `--set KEY=VALUE` overrides of the scaled agent's parameters; the parsing lives in
//! the library ([`crate::overrides`]) because sweeps use it too.

pub use crate::overrides::{KEYS, apply, set_one};
