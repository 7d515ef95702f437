//! Maps from Python: a file or embedded name ([`unforeseen_sim::embedded::find`], the command
//! line's lookup) with keyword overrides (`max_steps=60`, `lane_width=3.0`,
//! `episode__max_steps=60`). Each override is a typed value ([`FieldValue`]) laid over the
//! loaded map by the simulator ([`Map::with_overrides`]), which converts it to its field's
//! type and validates the result as a map file, so a bad value fails with the loader's
//! diagnostics (the field, a hint; the line and column of RON text given as a string).

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use unforeseen_sim::{FieldValue, Map};

use crate::errors;

/// Loads `arg` (a map file or an embedded name) and applies `overrides`.
pub fn load(arg: &str, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Map> {
    let map = unforeseen_sim::embedded::find(arg).map_err(errors::to_py)?;
    unforeseen_harness::maps::check_agent_settings(&map, arg).map_err(errors::to_py)?;
    match overrides {
        Some(o) if !o.is_empty() => {
            let sections = Map::override_fields();
            let mut fields = Vec::new();
            for (k, v) in o.iter() {
                let key: String = k.extract()?;
                let (section, field, whole) = locate(&key, &sections)?;
                let value = if whole {
                    whole_value(&key, &section, &field, &v)?
                } else {
                    field_value(&key, &v, 0)?
                };
                fields.push((section, field, value));
            }
            map.with_overrides(&format!("{arg} (overrides)"), &fields)
                .map_err(errors::to_py)
        }
        _ => Ok(map),
    }
}

/// A section of a map: its name and its fields, each with whether it is a whole number
/// ([`Map::override_fields`]).
type Section = (&'static str, Vec<(&'static str, bool)>);

/// The override `v` of the whole-number field `section.field` (given as `key`): a Python
/// or NumPy integer; a bool, a float (NaN and inf too) or text is refused.
fn whole_value(key: &str, section: &str, field: &str, v: &Bound<'_, PyAny>) -> PyResult<FieldValue> {
    let refuse = |shown: String| {
        errors::value(format!(
            "map override {key}: {shown} is not a whole number; {section}.{field} is a whole number: give an int (e.g. {key}=60)"
        ))
    };
    if v.is_instance_of::<PyBool>() || v.is_instance_of::<PyFloat>() || v.is_instance_of::<PyString>() {
        return Err(refuse(v.repr()?.to_string()));
    }
    if !v.is_instance_of::<PyInt>() && !v.hasattr("__index__")? {
        return Err(refuse(v.repr()?.to_string()));
    }
    Ok(FieldValue::Int(v.extract::<i128>().map_err(|_| {
        refuse(v.repr().map(|r| r.to_string()).unwrap_or_default())
    })?))
}

/// `key` as `(section, field)`: `section__field`, or a field name that only one
/// section has.
fn locate(key: &str, sections: &[Section]) -> PyResult<(String, String, bool)> {
    let known = || {
        sections
            .iter()
            .flat_map(|(s, fs)| fs.iter().map(move |(f, _)| format!("{s}__{f}")))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let whole = |s: &str, f: &str| {
        sections
            .iter()
            .filter(|(sec, _)| *sec == s)
            .flat_map(|(_, fs)| fs.iter())
            .find(|(x, _)| *x == f)
            .map(|(_, whole)| *whole)
    };
    if let Some((s, f)) = key.split_once("__") {
        if let Some(w) = whole(s, f) {
            return Ok((s.to_string(), f.to_string(), w));
        }
        return Err(errors::value(format!(
            "map override {key}: no such field; known: {}",
            known()
        )));
    }
    let mut owners: Vec<&str> = sections
        .iter()
        .filter(|(_, fs)| fs.iter().any(|(x, _)| *x == key))
        .map(|(s, _)| *s)
        .collect();
    // A name an optional section shares with one every map has means the latter's.
    let always: Vec<&str> = (owners.iter().copied())
        .filter(|s| !Map::OPTIONAL_OVERRIDE_SECTIONS.contains(s))
        .collect();
    if owners.len() > 1 && always.len() == 1 {
        owners = always;
    }
    match owners[..] {
        [s] => Ok((s.to_string(), key.to_string(), whole(s, key).unwrap_or(false))),
        [] => Err(errors::value(format!(
            "map override {key}: no such field; known: {}",
            known()
        ))),
        _ => Err(errors::value(format!(
            "map override {key}: several sections have it ({}); write it as section__{key}",
            owners.join(", ")
        ))),
    }
}

/// Deepest nesting of lists in an override value (a map field nests a few levels at
/// most; a list that contains itself, or one nested thousands deep, is refused rather
/// than exhausting the stack).
const MAX_DEPTH: usize = 8;

/// Most items of one list in an override value (a map's longest lists hold a few dozen).
const MAX_ITEMS: usize = 10_000;

/// A Python value as a typed value: bool, int (a Python or NumPy integer), float, a list
/// or tuple of them nested at most [`MAX_DEPTH`] deep, or a string taken as RON text as
/// written (e.g. `offset="Random"`). `depth` is the nesting of `v`; errors name `key`.
fn field_value(key: &str, v: &Bound<'_, PyAny>, depth: usize) -> PyResult<FieldValue> {
    if v.is_instance_of::<PyBool>() {
        Ok(FieldValue::Bool(v.extract::<bool>()?))
    } else if v.is_instance_of::<PyFloat>() {
        Ok(FieldValue::Float(v.extract::<f64>()?))
    } else if v.is_instance_of::<PyInt>() || v.hasattr("__index__")? {
        Ok(FieldValue::Int(v.extract::<i128>()?))
    } else if v.is_instance_of::<PyString>() {
        Ok(FieldValue::Text(v.extract::<String>()?))
    } else if v.is_instance_of::<PyList>() || v.is_instance_of::<PyTuple>() {
        if depth >= MAX_DEPTH {
            return Err(errors::value(format!(
                "map override {key}: lists nested more than {MAX_DEPTH} deep (or a list that contains itself); give the field's value"
            )));
        }
        if v.len()? > MAX_ITEMS {
            return Err(errors::value(format!(
                "map override {key}: a list of {} items; at most {MAX_ITEMS}",
                v.len()?
            )));
        }
        let items = v
            .try_iter()?
            .map(|x| field_value(key, &x?, depth + 1))
            .collect::<PyResult<Vec<_>>>()?;
        Ok(FieldValue::List(items))
    } else {
        Err(errors::value(format!(
            "map override {key}: value {v}: expected a bool, a number, a list of numbers or RON text"
        )))
    }
}
