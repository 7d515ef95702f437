//! Rust errors as Python exceptions. What the command line reports with exit code 2 (a
//! bad map, agent file, parameter, ...; [`unforeseen::cli::exit_code`]) and what the env
//! refuses as bad input (an action out of range, a configuration value) raise
//! `ValueError` with the message the command line prints (after its `error: `);
//! anything else raises `RuntimeError`.

use pyo3::PyErr;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use unforeseen_env::EnvError;

/// Whether `err` is bad input: exit code 2 on the command line, or an env input error.
fn is_user_error(err: &anyhow::Error) -> bool {
    unforeseen::cli::exit_code(err) == 2
        || err.chain().any(|e| {
            matches!(
                e.downcast_ref::<EnvError>(),
                Some(EnvError::BadAction { .. } | EnvError::Config { .. } | EnvError::Bins { .. })
            )
        })
}

/// The Python exception of `err`, with the message the command line prints.
pub fn to_py(err: anyhow::Error) -> PyErr {
    let message = format!("{err:#}");
    if is_user_error(&err) {
        PyValueError::new_err(message)
    } else {
        PyRuntimeError::new_err(message)
    }
}

/// [`to_py`] for any error type the command line knows.
pub fn py<E: Into<anyhow::Error>>(err: E) -> PyErr {
    to_py(err.into())
}

/// A `ValueError` with `message`.
pub fn value(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}
