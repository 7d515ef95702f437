//! One episode and the methods that drive it: the runner, the compared methods and the
//! scripted references, the evaluation protocols, the metrics of the paper's table, the
//! per-state preferences, the survivability check, the evaluation of a method on a map,
//! one traced episode, the test-time learning curves and the recording of reasoning ticks.

pub(crate) mod evaluation;
pub(crate) mod learning_curves;
pub(crate) mod methods;
pub(crate) mod metrics;
pub(crate) mod protocol;
pub(crate) mod reference;
pub(crate) mod rewards;
pub(crate) mod runner;
pub mod survivability;
pub(crate) mod tick_recording;
pub(crate) mod trace;

pub use evaluation::{
    EvalReport, MakeController, MakeControllerMut, MethodRow, eval_seeds, eval_seeds_named, evaluate_map, method_row,
    run_agent_episodes, run_controller, run_episodes_in_order, run_episodes_with, run_scripted_episodes,
};
pub use learning_curves::{LearnPoint, learn};
pub use methods::{Method, PaperFigures, UnknownMethod, check_compatible, scaled_agent};
pub use metrics::{Aggregate, efe_prefix_tree};
pub use protocol::{Protocol, ProtocolChoice, UnknownProtocol};
pub use reference::{BrakeOnPedestrian, NeverBrake, RedLightStop};
pub use rewards::{crash_model, entered_bins, red_light_cost, state_rewards};
pub use runner::{EpisodeResult, EpisodeSeeds, Tick, run_episode};
pub use tick_recording::{RecordedEpisode, Recording, ReplayOutcome, TickTimes, TimeSummary, jaywalk_family, record};
pub use trace::trace;
