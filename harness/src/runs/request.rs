//! Requests read field by field: a job's request ([`EvalRequest`](super::evaluate::EvalRequest),
//! [`CompareRequest`](super::compare::CompareRequest), [`BatchRequest`](super::batch::BatchRequest),
//! [`SearchRequest`](super::search::SearchRequest), [`LearnRequest`](super::learn::LearnRequest),
//! [`TraceRequest`](super::trace::TraceRequest)) from a JSON object, such as Python's
//! keyword arguments, with each field's error naming that field.

use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::{Map, Value};

use crate::error::Error;

/// The request `T` whose fields are `fields`, every other field at its default, read in
/// one pass (serde, with the path of a failing field kept). An unknown field, or a value
/// its field cannot take, is an [`Error::Request`] naming the field (`protocol: unknown
/// variant ...`, `train_seeds: '3..1': the range runs backwards ...`).
pub fn from_fields<T: Serialize + DeserializeOwned + Default>(fields: Map<String, Value>) -> Result<T, Error> {
    let given: Vec<String> = fields.keys().cloned().collect();
    serde_path_to_error::deserialize(Value::Object(fields)).map_err(|e| {
        // Only on the error path: the request's field names, to tell an unknown field.
        let known = known_fields::<T>();
        match given.iter().find(|k| !known.contains(k)) {
            Some(field) => Error::request(
                field.as_str(),
                format!("not a field of this request; its fields are {}", known.join(", ")),
            ),
            None => {
                let field = e.path().iter().next().map(|s| s.to_string()).unwrap_or_default();
                Error::request(field.as_str(), e.into_inner().to_string())
            }
        }
    })
}

/// The field names of request `T` (its defaults' keys), for the error on an unknown one.
fn known_fields<T: Serialize + Default>() -> Vec<String> {
    match serde_json::to_value(T::default()) {
        Ok(Value::Object(o)) => o.keys().cloned().collect(),
        _ => Vec::new(),
    }
}

/// The fields of request `T` with their defaults, as a JSON object (for a front that
/// shows or checks them, e.g. Python's signatures).
pub fn defaults<T: Serialize + Default>() -> Result<Value, Error> {
    Ok(serde_json::to_value(T::default())?)
}
