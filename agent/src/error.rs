//! Typed errors of the agent crate (`thiserror` in libraries; no panics on bad input).

use thiserror::Error;

/// A hyperparameter outside its documented range (see the tables in [`crate::params`]).
#[derive(Debug, Clone, PartialEq, Error)]
#[error("parameter `{name}` = {value} is invalid: must be {expected}")]
pub struct ParamError {
    /// Field name, e.g. `"omega"`.
    pub name: &'static str,
    /// The rejected value, formatted.
    pub value: String,
    /// The valid range, in words, e.g. `"> 0"`.
    pub expected: &'static str,
}

impl ParamError {
    pub(crate) fn new(name: &'static str, value: impl ToString, expected: &'static str) -> Self {
        Self {
            name,
            value: value.to_string(),
            expected,
        }
    }
}

/// Errors building or using a world model or an agent.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum AgentError {
    /// A hyperparameter is out of range.
    #[error(transparent)]
    Param(#[from] ParamError),
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
    /// The file is not a valid bundle; the message names `line:col`.
    #[error("corrupt agent bundle: {message}")]
    Corrupt {
        /// Parser message including `line:col`.
        message: String,
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
}
