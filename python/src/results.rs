//! `compare` and `batch` from Python (see the functions), returning the JSON data the
//! command line writes.

use pyo3::prelude::*;

/// Registers the functions.
pub fn register(_m: &Bound<'_, PyModule>) -> PyResult<()> {
    Ok(())
}
