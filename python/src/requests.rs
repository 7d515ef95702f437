//! The requests of the library's jobs from Python's keyword arguments, and the fields
//! each job's Python function takes with their defaults ([`request_defaults`]).

use pyo3::prelude::*;
use serde_json::Value;
use unforeseen_harness::runs::batch::BatchRequest;

use crate::errors;

/// The request of a job (`BatchRequest`, `SearchRequest`) from the JSON text of its
/// fields (Python's keyword arguments); errors name the field
/// ([`unforeseen_harness::runs::request::from_fields`]).
pub(crate) fn request<T>(fields: &str) -> PyResult<T>
where
    T: serde::Serialize + serde::de::DeserializeOwned + Default,
{
    let fields: serde_json::Map<String, Value> =
        serde_json::from_str(fields).map_err(|e| errors::value(format!("request: not a JSON object ({e})")))?;
    unforeseen_harness::runs::request::from_fields(fields).map_err(errors::to_py)
}

/// The fields of the request of `job` (`batch`, `search`, `compare` or `eval`) with
/// their defaults, as JSON text: what the Python functions of that job take.
#[pyfunction]
fn request_defaults(job: &str) -> PyResult<String> {
    use unforeseen_harness::runs::request::defaults;
    let defaults = match job {
        "batch" => defaults::<BatchRequest>(),
        "search" => defaults::<unforeseen_harness::runs::search::SearchRequest>(),
        "compare" => defaults::<unforeseen_harness::runs::compare::CompareRequest>(),
        "eval" => defaults::<unforeseen_harness::runs::evaluate::EvalRequest>(),
        "estimate" => defaults::<unforeseen_harness::runs::estimate::EstimateRequest>(),
        other => {
            return Err(errors::value(format!(
                "job: no request named '{other}'; the jobs are batch, search, compare, eval, estimate"
            )));
        }
    };
    Ok(defaults.map_err(errors::to_py)?.to_string())
}

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(request_defaults, m)?)?;
    Ok(())
}
