//! Rust errors as Python exceptions. What the command line reports with exit code 2 (a
//! bad map, agent file, parameter, ...;
//! [`unforeseen_harness::error::in_chain`]) and what the env
//! refuses as bad input (an action out of range, a configuration value) raise
//! `ValueError` with the message the command line prints (after its `error: `);
//! anything else raises `RuntimeError`.

use pyo3::PyErr;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use unforeseen_env::EnvError;

type DynError = dyn std::error::Error + 'static;

/// Whether `err` is bad input: exit code 2 on the command line, or an env input error.
fn is_user_error(err: &DynError) -> bool {
    if unforeseen_harness::error::in_chain(err) {
        return true;
    }
    let mut cause = Some(err);
    while let Some(e) = cause {
        if matches!(
            e.downcast_ref::<EnvError>(),
            Some(EnvError::BadAction { .. } | EnvError::Config { .. } | EnvError::Bins { .. } | EnvError::Map(_))
        ) {
            return true;
        }
        cause = e.source();
    }
    false
}

/// The message the command line prints: the error and its causes, joined by `: `.
pub fn message(err: &DynError) -> String {
    let mut text = err.to_string();
    let mut cause = err.source();
    while let Some(e) = cause {
        let more = e.to_string();
        // Wrappers that print their cause (`#[error(transparent)]`, "{0}") add nothing.
        if !text.ends_with(&more) {
            text.push_str(": ");
            text.push_str(&more);
        }
        cause = e.source();
    }
    text
}

/// The Python exception of `err`, with the message the command line prints.
pub fn to_py<E: std::error::Error + 'static>(err: E) -> PyErr {
    if is_user_error(&err) {
        PyValueError::new_err(message(&err))
    } else {
        PyRuntimeError::new_err(message(&err))
    }
}

/// A `ValueError` with `message`.
pub fn value(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
