//! # unforeseen
//!
//! Active inference as the test-time scaling law for physical AI agents, on a real
//! physics engine. This crate wires the pieces of the paper's §VI experiment:
//!
//! ```text
//! map.ron -> env::Env { sim::World --snapshot--> discretizer } --observation--> agent --action--> Env::step
//!                        \--reward terms, events (collision, goal, time-out)--> runner (metrics)
//! ```
//!
//! One episode steps in one place, [`unforeseen_env::Env`]; this crate's runner, training
//! and references are loops over it.
//!
//! * [`maps`] finds a map by path or by embedded name;
//! * [`rewards`] turns a map's reward section into the agent's per-state preferences
//!   (the C vector of §IV) and its planning model's episode-ending states (the per-tick
//!   reward is the env's [`unforeseen_env::RewardTerms`]);
//! * [`training`] learns Q-learning, the world model and Bayesian RL on the same episodes;
//! * [`runner`] drives one episode of any [`unforeseen_agent::controller::Controller`] in an
//!   [`unforeseen_env::Env`];
//! * [`methods`] builds the three compared methods (§VI), their ablations and the
//!   scripted references of [`reference`](mod@reference);
//! * [`survivability`] checks with those references that a scenario is survivable and
//!   dangerous;
//! * [`metrics`] aggregates episodes into the paper's table;
//! * [`protocol`] names the zero-shot and continual evaluation protocols;
//! * [`experiments`] runs evaluations under a protocol, `trace` and `learn`;
//! * [`agents`] trains one agent per training seed, in parallel, with an on-disk cache;
//! * [`study`] runs `compare` over agents and protocols and summarizes over seeds with
//!   [`stats`] (mean, 95% Student-t interval, range, worst seed);
//! * [`report`] writes JSON/CSV atomically, [`plots`] draws SVG figures and [`replay`]
//!   writes an episode as a self-contained HTML page that plays it;
//! * [`tick_replay`] records the scaled agent's reasoning ticks in episodes and replays
//!   them (the benches' in-loop reasoning tick);
//! * [`batch`] plans and runs scenario suites and sweeps headless, in parallel and in
//!   shards, and [`merge`] joins shard files produced anywhere into one run's file;
//! * [`search`] searches a space of map variations for the fair scenarios where a
//!   method fails (Sobol stage, cross-entropy stage, minimisation);
//! * [`error`] is the library's typed error, which every public function returns;
//! * [`progress`] is how long runs report progress ([`progress::Progress`]); the library
//!   itself prints nothing;
//! * [`cli`] is the command line (arguments, progress bars), and alone prints and
//!   decides messages and exit codes.
//!
//! `docs/ARCHITECTURE.md` in the repository describes the layout, the data flow and the
//! equations, with the paper's sections.

pub mod agent_file;
pub mod agents;
pub mod batch;
pub mod cli;
pub mod error;
pub mod experiments;
pub mod maps;
pub mod merge;
pub mod methods;
pub mod metrics;
pub mod overrides;
pub mod plots;
pub mod progress;
pub mod protocol;
pub mod reference;
pub mod replay;
pub mod report;
pub mod rewards;
pub mod runner;
pub mod search;
pub mod seeds;
pub mod stats;
pub mod stream;
pub mod study;
pub mod survivability;
pub mod tick_replay;
pub mod training;
