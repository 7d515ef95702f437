//! # unforeseen-harness
//!
//! The experiment harness of *Active Inference as the Test-Time Scaling Law for
//! Physical AI Agents*, on a real physics engine: the library that the command line
//! (the `unforeseen` binary) and the Python package (`python/`) share. It wires the
//! pieces of the paper's §VI experiment:
//!
//! ```text
//! map.ron -> env::Env { sim::World --snapshot--> discretizer } --observation--> agent --action--> Env::step
//!                        \--reward terms, events (collision, goal, time-out)--> runner (metrics)
//! ```
//!
//! One episode steps in one place, [`unforeseen_env::Env`]; this crate's runner, training
//! and references are loops over it. Its parts, one folder each:
//!
//! * [`episodes`]: one episode and the methods that drive it — the runner
//!   ([`run_episode`](episodes::run_episode)), the compared [`Method`](episodes::Method)s
//!   with their ablations and the scripted references
//!   ([`BrakeOnPedestrian`](episodes::BrakeOnPedestrian), [`NeverBrake`](episodes::NeverBrake)),
//!   the evaluation [`Protocol`](episodes::Protocol)s, the metrics of the paper's table
//!   ([`Aggregate`](episodes::Aggregate)), the per-state rewards (the C vector of §IV,
//!   [`state_rewards`](episodes::state_rewards)), the
//!   [`survivability`](episodes::survivability) check of a scenario, the evaluation of a
//!   method on a map under a protocol ([`evaluate_map`](episodes::evaluate_map)), a controller run in order ([`run_controller`](episodes::run_controller)), one traced episode
//!   ([`trace`](episodes::trace)), the test-time learning curves ([`learn`](episodes::learn))
//!   and the recording of reasoning ticks for the benches ([`record`](episodes::record));
//! * [`training`]: the training loop (Q-learning, the world model and Bayesian RL on the
//!   same episodes), one agent per training seed in parallel with an on-disk cache
//!   ([`train_agents`](training::train_agents)) and the [`agent_file`](training::agent_file);
//! * [`runs`]: what runs many episodes — [`batch`](runs::batch) (scenario suites and
//!   sweeps, in parallel and in shards), deployment [`stream`](runs::stream)s, the
//!   [`compare`](runs::compare) study (the paper's table over agents and protocols),
//!   test-time [`learn`](runs::learn)ing curves, an episode's [`trace`](runs::trace),
//!   [`merge`](runs::merge) of shard files and the [`search`](runs::search) for fair
//!   failing scenarios; each job is asked for by one typed request
//!   ([`EvalRequest`](runs::evaluate::EvalRequest), [`CompareRequest`](runs::compare::CompareRequest),
//!   [`BatchRequest`](runs::batch::BatchRequest), [`SearchRequest`](runs::search::SearchRequest),
//!   [`LearnRequest`](runs::learn::LearnRequest), [`TraceRequest`](runs::trace::TraceRequest)),
//!   the same value from every front, whose planning owns defaults, checks, agents, the
//!   output guard and identity, and whose job writes its files;
//! * [`reports`]: what the jobs render with: SVG [`figures`](reports::figures), the HTML
//!   replay page of an episode ([`replay_html`](reports::replay_html)) and printed
//!   documents ([`Document`](reports::Document)).
//!
//! **One face per part.** Each part's `mod.rs` is its face: the files inside a part are
//! `pub(crate)`, and what other crates use is re-exported there, so every public item has
//! one path (`episodes::Method`, `runs::batch::BatchRequest`). The exceptions are modules
//! whose names are the namespace of what they hold (`training::agent_file::load`,
//! `episodes::survivability::check`, `reports::figures`, and each job of [`runs`]).
//!
//! Shared by all of them: [`files`] are written atomically, [`maps`] finds a map by path or by embedded name,
//! [`overrides`] applies `KEY=VALUE` parameter overrides, [`limits`] bounds what one
//! run may ask for (seeds derive in [`unforeseen_env::seeds`]),
//! [`stats`] summarizes over seeds (mean, 95% Student-t interval, range, worst seed),
//! [`error`] is the typed error every public function returns (and tells
//! which are input the user can fix), and [`progress`] is how
//! long runs report progress ([`progress::Progress`]). The library prints nothing; its
//! fronts (the command line, the Python package) choose messages and exit codes.
//!
//! `docs/ARCHITECTURE.md` in the repository describes the layout, the data flow and the
//! equations, with the paper's sections.

pub mod episodes;
pub mod error;
pub mod files;
#[cfg(feature = "fixtures")]
pub mod fixtures;
pub mod limits;
pub mod maps;
pub mod overrides;
pub mod progress;
pub mod reports;
pub mod runs;
pub mod stats;
pub mod training;
