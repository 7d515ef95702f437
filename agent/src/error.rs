//! Typed errors of the agent crate (`thiserror` in libraries; no panics on bad input).

use std::borrow::Cow;
use thiserror::Error;

/// A hyperparameter outside its documented range (see the tables in [`crate::params`]).
#[derive(Debug, Clone, PartialEq, Error)]
#[error("parameter `{name}` = {value} is invalid: must be {expected}")]
pub struct ParamError {
    /// Field name, e.g. `"omega"`.
    pub name: &'static str,
    /// The rejected value, formatted.
    pub value: String,
    /// The valid range, in words, e.g. `"> 0"` (for a factor name, the model's names).
    pub expected: Cow<'static, str>,
}

impl ParamError {
    pub(crate) fn new(name: &'static str, value: impl ToString, expected: impl Into<Cow<'static, str>>) -> Self {
        Self {
            name,
            value: value.to_string(),
            expected: expected.into(),
        }
    }
}

/// What to say of the unknown parameter `key`: the nearest of `known` when it is a typo
/// away (two edits at most, as the map loader suggests a field), then every key.
fn suggestion(key: &str, known: &[&'static str]) -> String {
    let near = known
        .iter()
        .map(|k| (strsim::levenshtein(key, k), *k))
        .min_by_key(|(d, _)| *d)
        .filter(|(d, _)| *d <= 2);
    let all = format!("known: {}", known.join(", "));
    match near {
        Some((_, k)) => format!("did you mean `{k}`? ({all})"),
        None => all,
    }
}

/// A parameter of [`crate::params::ScaledParams`] set by name
/// ([`crate::param_table`]) with an unknown key or a value it does not admit.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum SetError {
    /// No parameter has this key.
    #[error("unknown parameter `{key}`; {}", suggestion(key, known))]
    UnknownKey {
        /// The key as given.
        key: String,
        /// Every key ([`crate::param_table::key_names`]).
        known: Vec<&'static str>,
    },
    /// The value does not fit the parameter: `problem` states what is allowed (an enum's
    /// values, a number's range and why).
    #[error("parameter `{key}` = {value} is invalid: {problem}")]
    BadValue {
        /// The key as given.
        key: String,
        /// The value as given.
        value: String,
        /// What is wrong and what is allowed.
        problem: String,
    },
}

/// A stored value of the wrong shape or out of range, found when reading a persisted
/// learner (see [`crate::persist`]). `path` names the field inside the learner, e.g.
/// `table[17]` or `a_counts[3,2]`; the loader prefixes the learner's own path
/// (`q_learning.table[17]`).
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{path}: {message}")]
pub struct FieldError {
    /// Field path, e.g. `cpt[2][5]`.
    pub path: String,
    /// What is wrong, e.g. `must be a finite count >= 0, found NaN`.
    pub message: String,
}

impl FieldError {
    pub(crate) fn new(path: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            path: path.into(),
            message: message.into(),
        }
    }

    /// The same error one level down: `prefix.path` (or `prefix[i]` paths as given).
    pub fn within(mut self, prefix: &str) -> Self {
        if !prefix.is_empty() {
            self.path = if self.path.is_empty() {
                prefix.to_string()
            } else if self.path.starts_with('[') {
                format!("{prefix}{}", self.path)
            } else {
                format!("{prefix}.{}", self.path)
            };
        }
        self
    }
}

impl From<ParamError> for FieldError {
    fn from(e: ParamError) -> Self {
        FieldError::new(e.name, format!("is {}; must be {}", e.value, e.expected))
    }
}

/// Errors building or using a world model or an agent.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AgentError {
    /// A hyperparameter is out of range.
    #[error(transparent)]
    Param(#[from] ParamError),
    /// A stored value is of the wrong shape or out of range (a damaged agent file).
    #[error(transparent)]
    Field(#[from] FieldError),
    /// The factor structure is invalid (bad parent index, cycle, zero size...).
    #[error("invalid structure: {0}")]
    Structure(String),
    /// Sizes of two inputs disagree (e.g. Q-table states vs model states).
    #[error("size mismatch: {what}: expected {expected}, found {found}")]
    SizeMismatch {
        /// What was compared.
        what: String,
        /// Expected size.
        expected: usize,
        /// Found size.
        found: usize,
    },
    /// An index (state, action, observation) is out of range.
    #[error("{what} index {index} out of range (size {size})")]
    OutOfRange {
        /// What was indexed.
        what: &'static str,
        /// The index.
        index: usize,
        /// The size of the indexed set.
        size: usize,
    },
    /// A habit's probabilities or prior strength are unusable (§V-C, [`crate::habit`]).
    #[error("invalid habit: {0}")]
    InvalidHabit(String),
}

/// Errors loading a persisted [`crate::persist::AgentBundle`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum PersistError {
    /// The file was written by another format version.
    #[error("agent bundle format version {found} is not supported (expected {expected})")]
    VersionMismatch {
        /// Version found in the file.
        found: u32,
        /// Version this build reads.
        expected: u32,
    },
    /// The file is not a valid bundle (syntax, types, unknown fields); the message names
    /// `line:col` and, when known, the field.
    #[error("corrupt agent bundle: {message}")]
    Corrupt {
        /// Parser message including `line:col`.
        message: String,
    },
    /// The file parses but a value is of the wrong shape or out of range; `path` names
    /// the field from the top of the bundle, e.g. `world_model.a_counts[3,2]`.
    #[error("invalid agent bundle: {0}")]
    Invalid(FieldError),
    /// The file is larger than any agent this build can write.
    #[error("{bytes} bytes is larger than any agent file (at most {limit} bytes)")]
    TooLarge {
        /// Size of the input.
        bytes: usize,
        /// [`crate::persist::MAX_FILE_BYTES`].
        limit: usize,
    },
}

/// Errors of `unforeseen inspect` (bad model JSON); messages name the offending field.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum InspectError {
    /// The JSON does not parse or lacks a field.
    #[error("invalid model JSON: {0}")]
    Json(String),
    /// A field has an invalid value; the message names the field, e.g. `B[1] column 0 ...`.
    #[error("{0}")]
    Invalid(String),
    /// A model in pymdp's general layout was refused ([`crate::aif::error::ModelError`]).
    #[error("{0}")]
    Model(#[from] crate::aif::error::ModelError),
}
