//! The methods compared in §VI, and the ablations of docs/ARCHITECTURE.md §5, built from one
//! trained [`AgentBundle`] so every method shares the same training data.

use unforeseen_agent::controller::Controller;
use unforeseen_agent::params::{GateLearning, GateMode, ReasoningMode, ScaledParams};
use unforeseen_agent::persist::AgentBundle;
use unforeseen_agent::scaled_agent::ScaledAgent;
use unforeseen_discretizer::Discretizer;
use unforeseen_sim::Map;

use crate::episodes::metrics::efe_prefix_tree;
use crate::episodes::reference::{BrakeOnPedestrian, NeverBrake};
use crate::error::Error;

/// A method (or ablation) the runner can drive.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// Tabular Q-learning, greedy on its Q-table; never reasons.
    QLearning,
    /// Model-based Bayesian RL on a flat Dirichlet joint-transition posterior; plans every tick.
    BayesRl,
    /// The paper's agent: Q-learning policy as pi_o, surprise-triggered reasoning,
    /// test-time scaling and test-time learning.
    Scaled,
    /// Ablation: Bayesian RL planning on the factored world model instead of the flat one.
    BayesRlFactored,
    /// Ablation: the scaled agent reasoning on every tick.
    ScaledAlways,
    /// Ablation: the scaled agent without test-time learning.
    ScaledNoLearning,
    /// Ablation: the scaled agent gated by the one-step surprise of the joint transition
    /// instead of the surprise on the state.
    ScaledOneStepGate,
    /// Ablation: the scaled agent whose gate learns every tick as familiar, whether or not
    /// reasoning endorses what the habit would do there.
    ScaledGateLearnsAll,
    /// Scripted reference (not a method of the paper): slows down while a pedestrian is
    /// on the crosswalk and the car has not arrived, else speeds up; never reasons,
    /// never learns. Whether it survives a map says whether the map is survivable
    /// ([`crate::episodes::reference::BrakeOnPedestrian`]).
    BrakeOnPedestrian,
    /// Scripted reference: always speeds up. Whether it is hit says whether a map is
    /// dangerous ([`crate::episodes::reference::NeverBrake`]).
    NeverBrake,
}

impl Method {
    /// Every method, in the order listings show them.
    pub const ALL: [Method; 10] = [
        Method::QLearning,
        Method::BayesRl,
        Method::Scaled,
        Method::BayesRlFactored,
        Method::ScaledAlways,
        Method::ScaledNoLearning,
        Method::ScaledOneStepGate,
        Method::ScaledGateLearnsAll,
        Method::BrakeOnPedestrian,
        Method::NeverBrake,
    ];
    /// The three methods of the paper's table.
    pub const PAPER: [Method; 3] = [Method::QLearning, Method::BayesRl, Method::Scaled];
    /// The ablations (docs/ARCHITECTURE.md §5).
    pub const ABLATIONS: [Method; 5] = [
        Method::BayesRlFactored,
        Method::ScaledAlways,
        Method::ScaledNoLearning,
        Method::ScaledOneStepGate,
        Method::ScaledGateLearnsAll,
    ];
    /// The scripted references ([`crate::episodes::BrakeOnPedestrian`], [`crate::episodes::NeverBrake`]): the careful driver and the car
    /// that never brakes. They need no trained agent.
    pub const REFERENCE: [Method; 2] = [Method::BrakeOnPedestrian, Method::NeverBrake];

    /// The name used on the command line and in result files.
    pub fn name(self) -> &'static str {
        match self {
            Method::QLearning => "q-learning",
            Method::BayesRl => "bayes-rl",
            Method::Scaled => "scaled",
            Method::BayesRlFactored => "bayes-rl-factored",
            Method::ScaledAlways => "scaled-always",
            Method::ScaledNoLearning => "scaled-no-learning",
            Method::ScaledOneStepGate => "scaled-one-step-gate",
            Method::ScaledGateLearnsAll => "scaled-gate-learns-all",
            Method::BrakeOnPedestrian => "brake-on-pedestrian",
            Method::NeverBrake => "never-brake",
        }
    }

    /// The name map files give the method in an expectation (`method: Scaled`):
    /// the variant's name.
    pub fn map_name(self) -> &'static str {
        match self {
            Method::QLearning => "QLearning",
            Method::BayesRl => "BayesRl",
            Method::Scaled => "Scaled",
            Method::BayesRlFactored => "BayesRlFactored",
            Method::ScaledAlways => "ScaledAlways",
            Method::ScaledNoLearning => "ScaledNoLearning",
            Method::ScaledOneStepGate => "ScaledOneStepGate",
            Method::ScaledGateLearnsAll => "ScaledGateLearnsAll",
            Method::BrakeOnPedestrian => "BrakeOnPedestrian",
            Method::NeverBrake => "NeverBrake",
        }
    }

    /// The method a map file names ([`Method::map_name`]), if any.
    pub fn from_map_name(name: &str) -> Option<Method> {
        Method::all().iter().copied().find(|m| m.map_name() == name)
    }

    /// Every method, in declaration order.
    pub fn all() -> &'static [Method] {
        &Method::ALL
    }

    /// One line saying what the method is (for listings such as `--help`).
    pub fn summary(self) -> &'static str {
        match self {
            Method::QLearning => "Tabular Q-learning, greedy on its Q-table; never reasons",
            Method::BayesRl => {
                "Model-based Bayesian RL on a flat Dirichlet joint-transition posterior; plans every tick"
            }
            Method::Scaled => {
                "The paper's agent: Q-learning policy as pi_o, surprise-triggered reasoning, test-time scaling and test-time learning"
            }
            Method::BayesRlFactored => {
                "Ablation: Bayesian RL planning on the factored world model instead of the flat one"
            }
            Method::ScaledAlways => "Ablation: the scaled agent reasoning on every tick",
            Method::ScaledNoLearning => "Ablation: the scaled agent without test-time learning",
            Method::ScaledOneStepGate => {
                "Ablation: the scaled agent gated by the one-step surprise of the joint transition instead of the surprise on the state"
            }
            Method::ScaledGateLearnsAll => {
                "Ablation: the scaled agent whose gate learns every tick as familiar, whether or not reasoning endorses what the habit would do there"
            }
            Method::BrakeOnPedestrian => {
                "Scripted reference (not a method of the paper): slows down while a pedestrian is on the crosswalk and the car has not arrived, else speeds up; never reasons, never learns. Whether it survives a map says whether the map is survivable"
            }
            Method::NeverBrake => {
                "Scripted reference: always speeds up. Whether it is hit says whether a map is dangerous"
            }
        }
    }

    /// The paper's reported figures for this method (§VI, Fig. 8), where it reports them.
    pub fn paper(self) -> Option<PaperFigures> {
        match self {
            Method::QLearning => Some(PaperFigures {
                train_reward: 78.0,
                test_reward: -21.8,
                success_rate: 0.03,
                inference_rate: 0.0,
            }),
            Method::BayesRl => Some(PaperFigures {
                train_reward: 72.7,
                test_reward: -18.2,
                success_rate: 0.05,
                inference_rate: 1.0,
            }),
            Method::Scaled => Some(PaperFigures {
                train_reward: 78.0,
                test_reward: 22.9,
                success_rate: 1.0,
                inference_rate: 0.633,
            }),
            _ => None,
        }
    }

    /// Whether the method is the scaled agent or one of its ablations (plans by EFE, §IV).
    pub fn is_scaled(self) -> bool {
        matches!(
            self,
            Method::Scaled
                | Method::ScaledAlways
                | Method::ScaledNoLearning
                | Method::ScaledOneStepGate
                | Method::ScaledGateLearnsAll
        )
    }

    /// The expected-free-energy mat-vecs one reasoning tick of the method costs: the
    /// planning tree ([`efe_prefix_tree`]) of a method that plans by EFE, 0 for any other.
    pub fn reasoning_tree(self, params: &ScaledParams) -> usize {
        if self.is_scaled() { efe_prefix_tree(params) } else { 0 }
    }

    /// Whether the method carries state from one episode to the next (test-time
    /// learning), so its episodes must run in order.
    pub fn learns_across_episodes(self, params: &ScaledParams) -> bool {
        match self {
            Method::Scaled | Method::ScaledAlways | Method::ScaledOneStepGate | Method::ScaledGateLearnsAll => {
                params.learning.enabled
            }
            Method::ScaledNoLearning | Method::QLearning => false,
            Method::BrakeOnPedestrian | Method::NeverBrake => false,
            Method::BayesRl | Method::BayesRlFactored => true,
        }
    }

    /// Whether the method is scripted ([`Method::REFERENCE`]): it needs no trained agent.
    pub fn is_scripted(self) -> bool {
        Method::REFERENCE.contains(&self)
    }

    /// A fresh scripted controller for episodes on `map`, for observations of factor
    /// sizes `sizes` (`[n_d, n_v, n_L, n_p]`), or `None` for a method that needs a
    /// trained agent: `brake-on-pedestrian` also stops for red where the map's reward
    /// has the red-light rule ([`BrakeOnPedestrian::for_map`]). [`Method::controller`]
    /// builds its scripted methods here, with the sizes of the bundle's world model;
    /// callers without an agent (`check-map`, `eval` without `--agent`, Python's
    /// `scripted_controller`) pass the map discretizer's sizes. The map is required, so
    /// no front can build the witness without the map's rule.
    pub fn scripted_controller(self, sizes: &[usize], map: &Map) -> Result<Option<Box<dyn Controller>>, Error> {
        Ok(match self {
            Method::BrakeOnPedestrian => Some(Box::new(BrakeOnPedestrian::for_map(sizes, map)?)),
            Method::NeverBrake => Some(Box::new(NeverBrake)),
            _ => None,
        })
    }

    /// Builds a fresh controller of this method from the trained bundle for episodes on
    /// `map` (the scripted references take only the factor sizes of its world model, and
    /// the witness follows the map's red-light rule: [`Method::scripted_controller`]).
    pub fn controller(
        self,
        bundle: &AgentBundle,
        params: &ScaledParams,
        map: &Map,
    ) -> Result<Box<dyn Controller>, Error> {
        let scaled = |params: ScaledParams| -> Result<Box<dyn Controller>, Error> {
            Ok(Box::new(scaled_agent(bundle, params)?))
        };
        // An ablation: the given parameters with one changed.
        let ablation = |change: fn(&mut ScaledParams)| {
            let mut p = params.clone();
            change(&mut p);
            scaled(p)
        };
        Ok(match self {
            Method::QLearning => Box::new(bundle.q_learning.clone()),
            Method::BayesRl => Box::new(bundle.bayes_rl.clone()),
            Method::BayesRlFactored => Box::new(bundle.bayes_rl_factored.clone().ok_or_else(|| Error::Agent {
                problem: "this agent file has no factored Bayesian-RL model".into(),
                fix: "retrain it with `unforeseen train`".into(),
            })?),
            Method::Scaled => scaled(params.clone())?,
            Method::ScaledAlways => ablation(|p| p.scaling.reasoning = ReasoningMode::Always)?,
            Method::ScaledNoLearning => ablation(|p| p.learning.enabled = false)?,
            Method::ScaledOneStepGate => ablation(|p| p.gate.mode = GateMode::OneStep)?,
            Method::ScaledGateLearnsAll => ablation(|p| p.gate.gate_learning = GateLearning::Every)?,
            Method::BrakeOnPedestrian | Method::NeverBrake => {
                let sizes = bundle.world_model.structure().sizes();
                self.scripted_controller(&sizes, map)?
                    .expect("scripted_controller builds every scripted method")
            }
        })
    }
}

/// The paper's agent from a trained bundle; a failure (parameters that do not fit the
/// agent's world model, e.g. `--set gate_factor` naming no factor) is an [`Error::Agent`].
pub fn scaled_agent(bundle: &AgentBundle, params: ScaledParams) -> Result<ScaledAgent, Error> {
    ScaledAgent::new(bundle.world_model.clone(), &bundle.q_learning, params).map_err(|e| Error::Agent {
        problem: format!("cannot build the scaled agent from this agent file: {e}"),
        fix: "check the --set overrides against the agent's world model, or retrain it".into(),
    })
}

impl std::fmt::Display for Method {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A method name that is none of [`Method::ALL`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("'{given}' is not a method; expected one of {}", Method::ALL.map(Method::name).join(", "))]
pub struct UnknownMethod {
    /// The name given.
    pub given: String,
}

impl std::str::FromStr for Method {
    type Err = UnknownMethod;
    /// Parses a method by [`Method::name`].
    fn from_str(s: &str) -> Result<Self, UnknownMethod> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| UnknownMethod { given: s.to_string() })
    }
}

/// Figures the paper reports for a method (§VI).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct PaperFigures {
    /// Mean training reward.
    pub train_reward: f64,
    /// Mean test reward on the jaywalk scenario.
    pub test_reward: f64,
    /// Success rate on the jaywalk scenario.
    pub success_rate: f64,
    /// Inference rate relative to Bayesian RL (which reasons on every tick).
    pub inference_rate: f64,
}

/// Checks that `bundle` can drive `map`: the world model's factor sizes are the ones the
/// map's bins give (the same joint state space, factor by factor).
pub fn check_compatible(bundle: &AgentBundle, map: &Map) -> Result<(), Error> {
    let disc = Discretizer::new(map)?;
    let agent = bundle.world_model.structure().sizes();
    let map_sizes = disc.factor_sizes();
    if agent != map_sizes {
        return Err(Error::Agent {
            problem: format!(
                "the agent was trained on factor sizes {agent:?} (d, v, L, p: {} discrete states) but map '{}' gives {map_sizes:?} ({} states)",
                agent.iter().product::<usize>(),
                map.name,
                disc.n_states()
            ),
            fix: "its bins differ from the training map's: train an agent on a map with the same bins".into(),
        });
    }
    Ok(())
}
