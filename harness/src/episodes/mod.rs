//! One episode and the methods that drive it: the runner, the compared methods and the
//! scripted references, the evaluation protocols, the metrics of the paper's table, the
//! per-state preferences, the survivability check, the experiments built on them, and
//! the recording of reasoning ticks.

pub mod experiments;
pub mod methods;
pub mod metrics;
pub mod protocol;
pub mod reference;
pub mod rewards;
pub mod runner;
pub mod survivability;
pub mod tick_recording;
