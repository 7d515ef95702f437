//! placeholder
pub mod controller;
pub mod error;
pub mod learning;
pub mod q_learning;
pub mod maths;
pub mod model;
pub mod params;
pub mod perception;
pub mod planning;
pub mod scaling;
pub mod structure;
pub mod surprise;
