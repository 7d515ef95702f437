//! placeholder
pub mod error;
pub mod maths;
pub mod model;
pub mod params;
pub mod structure;
