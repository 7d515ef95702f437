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
//! * [`episodes`]: one episode and the methods that drive it — the [`runner`](episodes::runner),
//!   the compared [`methods`](episodes::methods) with their ablations and the scripted
//!   [`reference`](episodes::reference)s, the evaluation [`protocol`](episodes::protocol)s,
//!   the [`metrics`](episodes::metrics) of the paper's table, the per-state
//!   [`rewards`](episodes::rewards) (the C vector of §IV), the
//!   [`survivability`](episodes::survivability) check of a scenario, the
//!   [`evaluation`](episodes::evaluation) of a method on a map under a protocol, one
//!   [`trace`](episodes::trace)d episode, the test-time [`learning_curves`](episodes::learning_curves)
//!   and the [`tick_recording`](episodes::tick_recording) of reasoning ticks for the
//!   benches;
//! * [`training`]: the training loop (Q-learning, the world model and Bayesian RL on the
//!   same episodes), [`seed_agents`](training::seed_agents) (one agent per training
//!   seed, in parallel, with an on-disk cache) and the [`agent_file`](training::agent_file);
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
//!   [`replay_page`](reports::replay_page) of an episode and printed
//!   [`tables`](reports::tables).
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
pub mod limits;
pub mod maps;
pub mod overrides;
pub mod progress;
pub mod reports;
pub mod runs;
pub mod stats;
pub mod training;
