//! # unforeseen-agent
//!
//! The math of "Active Inference as the Test-Time Scaling Law for Physical AI Agents"
//! (no physics, no maps): a factored world model with Dirichlet counts, surprise and the
//! reasoning trigger, VMP perception, EFE planning, test-time policy scaling, test-time
//! learning, and the two baselines (tabular Q-learning, Bayesian RL). All three methods
//! implement [`controller::Controller`].
//!
//! Module map (named after the paper): [`maths`], [`params`] (declared with [`param_decl`]; [`param_table`], the scaled agent's parameters by name), [`structure`], [`model`] (the world model, one concept per file), [`transition`] (factored `B`),
//! [`surprise`] (§II), [`gate`] (§VI surprise on the state), [`handback`] (the safe hand-back, beyond the paper), [`competence`] (the competence check of the habit, beyond the paper), [`perception`] (§III), [`planning`] (§IV, Prop. 1, Cor. 1),
//! [`scaling`] (§IV, Theorem 1), [`learning`] (§V), [`q_learning`], [`bayes_rl`],
//! [`habit`] (`π_o` as an interface), [`scaled_agent`] (the paper's agent), [`controller`], [`persist`], [`inspect`], [`error`], [`limits`]; [`aif`]: any discrete model in pymdp's layout, with pymdp's algorithms and the paper's gate.
//!
//! ```
//! use unforeseen_agent::{controller::Controller, model::WorldModel, params::*,
//!     q_learning::QLearning, scaled_agent::ScaledAgent, structure::Structure};
//! let st = Structure::paper_default([4, 4, 2, 2]).unwrap();
//! let mut w = WorldModel::new(st.clone(), 3, &ModelPriors::default()).unwrap();
//! w.observe_transition(st.encode(&[3, 1, 1, 0]), 0, st.encode(&[2, 1, 1, 0]));
//! w.materialize();
//! let q = QLearning::new(64, 3, QParams::default()).unwrap();
//! let mut agent = ScaledAgent::new(w, &q, ScaledParams::default()).unwrap();
//! agent.begin_episode(1);
//! let d = agent.act(st.encode(&[3, 1, 1, 0]));
//! assert!(d.action < 3);
//! ```
pub mod aif;
pub mod bayes_rl;
pub mod competence;
pub mod controller;
pub mod error;
#[cfg(test)]
mod factored_checks;
pub mod gate;
pub mod habit;
pub mod handback;
pub mod inspect;
pub mod learning;
pub mod limits;
pub mod maths;
pub mod model;
pub mod param_decl;
pub mod param_table;
pub mod params;
pub mod perception;
pub mod persist;
pub mod planning;
pub mod q_learning;
pub mod scaled_agent;
pub mod scaling;
mod stored_values;
pub mod structure;
pub mod surprise;
pub mod transition;
