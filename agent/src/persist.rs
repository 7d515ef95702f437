//! Serializable agent state (RON) with a format version. Derived state (the
//! materialised `B`, planner caches) is not stored and is rebuilt on load.
//!
//! Reading a bundle checks everything before anything is computed from it: unknown
//! fields are refused, every learner checks its stored values as it is read (shapes,
//! finite values, counts >= 0, `C` normalised, parameters in range, sizes within
//! [`crate::limits`]), then the learners must agree on states and actions. A failure
//! names the field from the top of the file, e.g. `world_model.a_counts[3,2]`.

use crate::bayes_rl::BayesRl;
use crate::error::{FieldError, PersistError};
use crate::model::WorldModel;
use crate::q_learning::QLearning;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// The format version this build writes and reads.
pub const FORMAT_VERSION: u32 = 1;

/// Largest agent file read, bytes: an agent at [`crate::limits::MAX_STATES`] states
/// writes about 150 MB of text.
pub const MAX_FILE_BYTES: usize = 512 << 20;

/// Everything training produces.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
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

    /// Parse RON: a different `format_version` is [`PersistError::VersionMismatch`]; a
    /// value of the wrong shape or out of range is [`PersistError::Invalid`] naming the
    /// field; anything else invalid (syntax, types, unknown fields) is
    /// [`PersistError::Corrupt`] with `line:col` and, when known, the field.
    pub fn from_ron_str(s: &str) -> Result<AgentBundle, PersistError> {
        if s.len() > MAX_FILE_BYTES {
            return Err(PersistError::TooLarge {
                bytes: s.len(),
                limit: MAX_FILE_BYTES,
            });
        }
        let probe: VersionProbe = ron::from_str(s).map_err(corrupt)?;
        if probe.format_version != FORMAT_VERSION {
            return Err(PersistError::VersionMismatch {
                found: probe.format_version,
                expected: FORMAT_VERSION,
            });
        }
        let mut de = ron::Deserializer::from_str(s).map_err(corrupt)?;
        let bundle: AgentBundle = match serde_path_to_error::deserialize(&mut de) {
            Ok(b) => b,
            Err(e) => {
                let path = e.path().to_string();
                let path = if path == "." { String::new() } else { path };
                let inner = e.into_inner();
                // A learner's own check: "field: message", joined to the outer path.
                if let ron::Error::Message(m) = &inner
                    && let Some(field) = split_field(m)
                {
                    return Err(PersistError::Invalid(field.within(&path)));
                }
                let spanned = de.span_error(inner);
                let at = if path.is_empty() {
                    String::new()
                } else {
                    format!("{path}: ")
                };
                return Err(PersistError::Corrupt {
                    message: format!(
                        "{}:{}: {at}{}",
                        spanned.span.start.line, spanned.span.start.col, spanned.code
                    ),
                });
            }
        };
        de.end().map_err(|e| corrupt(de.span_error(e)))?;
        bundle.check().map_err(PersistError::Invalid)?;
        Ok(bundle)
    }

    /// The learners agree on the state space and the actions.
    fn check(&self) -> Result<(), FieldError> {
        let n = self.world_model.n_states();
        let na = self.world_model.n_actions();
        let mut learners = vec![
            ("q_learning", self.q_learning.n_states(), self.q_learning.n_actions()),
            ("bayes_rl", self.bayes_rl.n_states(), self.bayes_rl.n_actions()),
        ];
        if let Some(b) = &self.bayes_rl_factored {
            learners.push(("bayes_rl_factored", b.n_states(), b.n_actions()));
        }
        for (name, ns, nas) in learners {
            if ns != n {
                return Err(FieldError::new(
                    format!("{name}.n_states"),
                    format!(
                        "is {ns}, but the world model has {n} joint states; all learners of an agent share one state space"
                    ),
                ));
            }
            if nas != na {
                return Err(FieldError::new(
                    format!("{name}.n_actions"),
                    format!("is {nas}, but the world model has {na} actions"),
                ));
            }
        }
        Ok(())
    }
}

/// A learner's check failure as serde carries it, `path: message` (see
/// [`FieldError`]'s `Display`), back into a [`FieldError`]; `None` for other messages.
fn split_field(m: &str) -> Option<FieldError> {
    let (path, message) = m.split_once(": ")?;
    let first = path.chars().next()?;
    let ok = (first.is_ascii_alphabetic() || first == '_')
        && path.chars().all(|c| c.is_ascii_alphanumeric() || "_.[],".contains(c));
    ok.then(|| FieldError::new(path, message))
}
