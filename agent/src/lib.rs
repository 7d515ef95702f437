//! placeholder
pub mod bayes_rl;
pub mod controller;
pub mod error;
pub mod inspect;
pub mod learning;
pub mod maths;
pub mod model;
pub mod params;
pub mod perception;
pub mod persist;
pub mod planning;
pub mod q_learning;
pub mod scaled;
pub mod scaling;
pub mod structure;
pub mod surprise;
