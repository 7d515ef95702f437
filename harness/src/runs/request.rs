//! Requests read field by field: a job's request ([`EvalRequest`](super::evaluate::EvalRequest),
//! [`CompareRequest`](super::compare::CompareRequest), [`BatchRequest`](super::batch::BatchRequest),
//! [`SearchRequest`](super::search::SearchRequest), [`LearnRequest`](super::learn::LearnRequest),
//! [`TraceRequest`](super::trace::TraceRequest)) from a JSON object, such as Python's
//! keyword arguments, with each field's error naming that field.

use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::{Map, Value};

use crate::error::Error;

/// The request `T` whose fields are `fields`, every other field at its default. An
/// unknown field, or a value its field cannot take, is an [`Error::Request`] naming the
/// field (`protocol: unknown variant ...`, `train_seeds: '3..1': the range runs
/// backwards ...`).
pub fn from_fields<T: Serialize + DeserializeOwned + Default>(fields: Map<String, Value>) -> Result<T, Error> {
    let defaults = serde_json::to_value(T::default())?;
    let known: Vec<&String> = defaults.as_object().map(|o| o.keys().collect()).unwrap_or_default();
    for (field, value) in &fields {
        if !known.contains(&field) {
            return Err(Error::request(
                field.as_str(),
                format!(
                    "not a field of this request; its fields are {}",
                    known.iter().map(|k| k.as_str()).collect::<Vec<_>>().join(", ")
                ),
            ));
        }
        // The field alone (the others at their defaults), so that its error is its own.
        let alone = Map::from_iter([(field.clone(), value.clone())]);
        serde_json::from_value::<T>(Value::Object(alone)).map_err(|e| Error::request(field.as_str(), e.to_string()))?;
    }
    Ok(serde_json::from_value(Value::Object(fields))?)
}

/// The fields of request `T` with their defaults, as a JSON object (for a front that
/// shows or checks them, e.g. Python's signatures).
pub fn defaults<T: Serialize + Default>() -> Result<Value, Error> {
    Ok(serde_json::to_value(T::default())?)
}
