//! One episode and the methods that drive it: the runner, the compared methods and the
//! scripted references, the evaluation protocols, the metrics of the paper's table, the
//! per-state preferences, the survivability check, the evaluation of a method on a map,
//! one traced episode, the test-time learning curves and the recording of reasoning ticks.

pub mod evaluation;
pub mod learning_curves;
pub mod methods;
pub mod metrics;
pub mod protocol;
pub mod reference;
pub mod rewards;
pub mod runner;
pub mod survivability;
pub mod tick_recording;
pub mod trace;
