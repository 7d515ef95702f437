//! Serializable agent state (RON) with a format version. Derived state (the
//! materialised `B`, planner caches) is not stored and is rebuilt on load.

use crate::bayes_rl::BayesRl;
use crate::error::PersistError;
use crate::model::WorldModel;
use crate::q_learning::QLearning;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The format version this build writes and reads.
pub const FORMAT_VERSION: u32 = 1;

/// Everything training produces.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AgentBundle {
    /// Must equal [`FORMAT_VERSION`].
    pub format_version: u32,
    /// The trained Q-table (base policy).
    pub q_learning: QLearning,
    /// The trained world model.
    pub world_model: WorldModel,
    /// The trained Bayesian-RL posterior.
    pub bayes_rl: BayesRl,
    /// Bayesian RL given the factored world model instead of the flat one (ablation,
    /// docs/ARCHITECTURE.md §5), trained on the same episodes; absent in older files.
    #[serde(default)]
    pub bayes_rl_factored: Option<BayesRl>,
    /// Free-form metadata (map name, seed, episodes...).
    pub meta: BTreeMap<String, String>,
}

#[derive(Deserialize)]
#[serde(rename = "AgentBundle")]
struct VersionProbe {
    format_version: u32,
}

fn corrupt(e: ron::error::SpannedError) -> PersistError {
    PersistError::Corrupt {
        message: format!("{}:{}: {}", e.span.start.line, e.span.start.col, e.code),
    }
}

impl AgentBundle {
    /// A bundle at the current format version.
    pub fn new(
        q_learning: QLearning,
        world_model: WorldModel,
        bayes_rl: BayesRl,
        meta: BTreeMap<String, String>,
    ) -> Self {
        AgentBundle {
            format_version: FORMAT_VERSION,
            q_learning,
            world_model,
            bayes_rl,
            bayes_rl_factored: None,
            meta,
        }
    }

    /// Pretty RON.
    pub fn to_ron_string(&self) -> String {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default()).unwrap_or_else(|e| format!("/* {e} */"))
    }

    /// Parse RON: a different `format_version` is [`PersistError::VersionMismatch`], anything
    /// else invalid is [`PersistError::Corrupt`] with `line:col`.
    pub fn from_ron_str(s: &str) -> Result<AgentBundle, PersistError> {
        let probe: VersionProbe = ron::from_str(s).map_err(corrupt)?;
        if probe.format_version != FORMAT_VERSION {
            return Err(PersistError::VersionMismatch {
                found: probe.format_version,
                expected: FORMAT_VERSION,
            });
        }
        ron::from_str(s).map_err(corrupt)
    }
}
