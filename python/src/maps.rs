//! Maps from Python: a file or embedded name ([`unforeseen_sim::embedded::find`], the command
//! line's lookup) with keyword overrides (`max_steps=60`, `lane_width=3.0`,
//! `episode__max_steps=60`). Overrides become a RON patch laid over the loaded map
//! (`base:` the map itself) and go through the map loader, so a bad value fails with the
//! loader's diagnostics (file, line and column or field, and a hint) like a map file.

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use unforeseen_sim::Map;

use crate::errors;

/// The base name the patch refers to.
const BASE: &str = "<the map being overridden>";

/// Loads `arg` (a map file or an embedded name) and applies `overrides`.
pub fn load(arg: &str, overrides: Option<&Bound<'_, PyDict>>) -> PyResult<Map> {
    let map = unforeseen_sim::embedded::find(arg).map_err(errors::to_py)?;
    match overrides {
        Some(o) if !o.is_empty() => {
            let sections = sections();
            let mut fields = Vec::new();
            for (k, v) in o.iter() {
                let key: String = k.extract()?;
                let (section, field, whole) = locate(&key, &sections)?;
                let value = if whole {
                    whole_value(&key, &section, &field, &v)?
                } else {
                    ron_value(&key, &v, 0)?
                };
                fields.push((section, field, value));
            }
            patch(&map, arg, &fields)
        }
        _ => Ok(map),
    }
}

/// A section of a map: its name and its fields, each with whether it is a whole number.
type Section = (String, Vec<(String, bool)>);

/// The sections of a map and their fields, from the map's own serialization (so new
/// fields need no change here); a field whose default serializes as an integer is a
/// whole number, so an override of another type is refused by name rather than parsed.
fn sections() -> Vec<Section> {
    let value = serde_json::to_value(Map::default()).unwrap_or_default();
    let mut out = Vec::new();
    if let Some(top) = value.as_object() {
        for (section, v) in top {
            if let Some(fields) = v.as_object() {
                let fields = fields
                    .iter()
                    .map(|(f, d)| (f.clone(), d.as_number().is_some_and(|n| n.is_u64() || n.is_i64())))
                    .collect();
                out.push((section.clone(), fields));
            }
        }
    }
    out
}

/// The override `v` of the whole-number field `section.field` (given as `key`) as RON
/// text: a Python or NumPy integer; a bool, a float (NaN and inf too) or text is refused.
fn whole_value(key: &str, section: &str, field: &str, v: &Bound<'_, PyAny>) -> PyResult<String> {
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
    Ok(v.extract::<i128>()
        .map_err(|_| refuse(v.repr().map(|r| r.to_string()).unwrap_or_default()))?
        .to_string())
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
            .filter(|(sec, _)| sec == s)
            .flat_map(|(_, fs)| fs.iter())
            .find(|(x, _)| x == f)
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
    let owners: Vec<&String> = sections
        .iter()
        .filter(|(_, fs)| fs.iter().any(|(x, _)| x == key))
        .map(|(s, _)| s)
        .collect();
    match owners[..] {
        [s] => Ok((s.clone(), key.to_string(), whole(s, key).unwrap_or(false))),
        [] => Err(errors::value(format!(
            "map override {key}: no such field; known: {}",
            known()
        ))),
        _ => Err(errors::value(format!(
            "map override {key}: several sections have it ({}); write it as section__{key}",
            owners.iter().map(|s| s.as_str()).collect::<Vec<_>>().join(", ")
        ))),
    }
}

/// Deepest nesting of lists in an override value (a map field nests a few levels at
/// most; a list that contains itself, or one nested thousands deep, is refused rather
/// than exhausting the stack).
const MAX_DEPTH: usize = 8;

/// Most items of one list in an override value (a map's longest lists hold a few dozen).
const MAX_ITEMS: usize = 10_000;

/// A Python value as RON text: bool, int (a Python or NumPy integer), float, a list or
/// tuple of them nested at most [`MAX_DEPTH`] deep, or a string taken as RON text as
/// written (e.g. `offset="Random"`). `depth` is the nesting of `v`; errors name `key`.
fn ron_value(key: &str, v: &Bound<'_, PyAny>, depth: usize) -> PyResult<String> {
    if v.is_instance_of::<PyBool>() {
        Ok(if v.extract::<bool>()? { "true" } else { "false" }.into())
    } else if v.is_instance_of::<PyFloat>() {
        Ok(format!("{:?}", v.extract::<f64>()?))
    } else if v.is_instance_of::<PyInt>() || v.hasattr("__index__")? {
        Ok(v.extract::<i128>()?.to_string())
    } else if v.is_instance_of::<PyString>() {
        v.extract::<String>()
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
            .map(|x| ron_value(key, &x?, depth + 1))
            .collect::<PyResult<Vec<_>>>()?;
        Ok(format!("[{}]", items.join(", ")))
    } else {
        Err(errors::value(format!(
            "map override {key}: value {v}: expected a bool, a number, a list of numbers or RON text"
        )))
    }
}

/// Lays `fields` (section, field, RON value) over `map` and validates the result with
/// the loader.
fn patch(map: &Map, arg: &str, fields: &[(String, String, String)]) -> PyResult<Map> {
    let mut by_section: Vec<(String, Vec<String>)> = Vec::new();
    for (s, f, value) in fields {
        let line = format!("{f}: {value}");
        match by_section.iter_mut().find(|(x, _)| x == s) {
            Some((_, lines)) => lines.push(line),
            None => by_section.push((s.clone(), vec![line])),
        }
    }
    let quote = |s: &str| ron::to_string(s).unwrap_or_else(|_| format!("{s:?}"));
    let mut text = format!(
        "(\n    base: {},\n    name: {},\n    description: {},\n",
        quote(BASE),
        quote(&map.name),
        quote(&map.description)
    );
    for (section, lines) in &by_section {
        text.push_str(&format!("    {section}: (\n"));
        for line in lines {
            text.push_str(&format!("        {line},\n"));
        }
        text.push_str("    ),\n");
    }
    text.push_str(")\n");
    let mut restated = map.clone();
    restated.base = None;
    let base = ron::to_string(&restated).map_err(|e| errors::value(format!("{arg}: cannot restate the map: {e}")))?;
    let origin = format!("{arg} (overrides)");
    Map::from_str_named(&origin, &text, &|b| {
        (b == BASE).then(|| (arg.to_string(), base.clone()))
    })
    .map_err(errors::to_py)
}
