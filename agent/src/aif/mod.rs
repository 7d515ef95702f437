//! Bring your own model: discrete active inference on any generative model in pymdp's
//! layout (pymdp 1.0.4): several state factors with `B_dependencies`, one control factor
//! per state factor, several modalities with `A_dependencies`, `C` static or
//! time-indexed, `D`, `E`, Dirichlet `pA`, `pB`.
//!
//! Each algorithm is pymdp's, checked against its outputs on its own environments
//! (`agent/tests/it/aif_pymdp.rs`, data from `scripts/pymdp_envs_reference.py`):
//! [`infer`] (fpi), [`policies`], [`efe`] (G and q_π), [`action`], [`learning`]; [`agent`]
//! drives them. [`gate`] puts the paper's surprise gate in front of any such agent, and
//! [`run`] runs it in a [`process`] (a world in the same layout). [`driving`] writes the
//! driving agent's planning model in this layout, its planner's `G` exactly. Where the paper's agent differs it is named: `C` as `ln softmax`
//! ([`efe::Preferences::LnSoftmax`]), VMP over a window ([`crate::perception`]).
//!
//! ```
//! use unforeseen_agent::aif::{agent::{Agent, AgentParams}, model::{Model, ModelParts}, tensor::Tensor};
//! // One factor of 2 states, observed exactly; action 0 stays, action 1 switches.
//! let a = Tensor { shape: vec![2, 2], data: vec![1.0, 0.0, 0.0, 1.0] };
//! let b = Tensor { shape: vec![2, 2, 2], data: vec![1.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0] };
//! let c = Tensor { shape: vec![2], data: vec![0.0, 2.0] };
//! let model = Model::new(ModelParts { A: vec![a], B: vec![b], C: Some(vec![c]), ..Default::default() }).unwrap();
//! let agent = Agent::new(model, AgentParams::default(), None).unwrap();
//! let qs = agent.infer_states(&[0], &agent.initial_prior()).unwrap();
//! let post = agent.infer_policies(&qs);
//! let mut rng = rand::rng();
//! assert_eq!(agent.sample_action(&post.q_pi, &mut rng), vec![1]); // switch to the preferred state
//! ```

pub mod action;
pub mod agent;
pub mod driving;
pub mod efe;
pub mod error;
pub mod gate;
pub mod infer;
pub mod inspect;
pub mod learning;
pub mod model;
pub mod policies;
pub mod process;
pub mod run;
pub mod tensor;
pub mod validate;
