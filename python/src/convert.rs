//! Python arguments to the library's values, in one place: every count, seed, size, path
//! and request field a Python caller gives is read here, so that each refusal names its
//! argument (and, for a number, its range) the same way whatever the function.
//!
//! * whole numbers ([`whole`], [`seed`], [`episodes`]): a Python `int` or any integer
//!   with `__index__` (NumPy's); never a bool, a float (even `3.0`, NaN or inf) or text;
//!   out of range (negative, zero where a count starts at one, past the bound) is
//!   `FIELD VALUE: expected a whole number in LO..=HI`, the library's bounds
//!   ([`unforeseen_harness::limits`]);
//! * paths and names ([`path`], [`text`]): text or an `os.PathLike`, not empty, no
//!   control characters;
//! * a job's request ([`request`]): its keyword arguments, each converted as above by its
//!   field's kind ([`FIELDS`]), then the library's request type built from them
//!   ([`unforeseen_harness::runs::request::from_fields`], which names the field of any
//!   other refusal).

use std::ops::RangeInclusive;
use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::{PyBool, PyBytes, PyDict, PyFloat, PyInt, PyString};
use serde_json::Value;
use unforeseen_harness::limits::{MAX_EPISODES, MAX_JOBS};

use crate::errors;

/// Every seed (world, training, evaluation, key): any `u64`.
pub const SEEDS: RangeInclusive<u64> = 0..=u64::MAX;

/// An episode count of one run ([`unforeseen_harness::limits::check_episodes`]'s bound).
pub const EPISODES: RangeInclusive<u64> = 1..=MAX_EPISODES;

/// Most characters of a refused value's text in a message.
const SHOWN: usize = 40;

/// Most items of one list in a request field (a run takes at most 1,000 training seeds
/// and 10,000 parameter sets).
const MAX_ITEMS: usize = 100_000;

/// `v` as Python shows it (`repr`), cut to [`SHOWN`] characters.
fn shown(v: &Bound<'_, PyAny>) -> String {
    let text = v.repr().map(|r| r.to_string()).unwrap_or_else(|_| "?".into());
    if text.chars().count() > SHOWN {
        format!("{}...", text.chars().take(SHOWN).collect::<String>())
    } else {
        text
    }
}

/// The refusal of `v` for `field`, a whole number in `range`.
fn not_whole(field: &str, v: &Bound<'_, PyAny>, range: &RangeInclusive<u64>) -> PyErr {
    errors::value(format!(
        "{field} {}: expected a whole number in {}..={}",
        shown(v),
        range.start(),
        range.end()
    ))
}

/// `v` as an integer if it is one (a Python or NumPy integer, not a bool), else `None`;
/// an integer past `i128` is `Err` with its text.
fn integer(v: &Bound<'_, PyAny>) -> PyResult<Option<Result<i128, ()>>> {
    if v.is_instance_of::<PyBool>() || v.is_instance_of::<PyFloat>() || v.is_instance_of::<PyString>() {
        return Ok(None);
    }
    if !v.is_instance_of::<PyInt>() && !v.hasattr("__index__")? {
        return Ok(None);
    }
    // NumPy's bool has `__index__` in some versions: a bool still.
    if v.get_type().name()?.to_string().starts_with("bool") {
        return Ok(None);
    }
    let Ok(index) = v.py().import("operator")?.call_method1("index", (v,)) else {
        return Ok(None);
    };
    Ok(Some(index.extract::<i128>().map_err(|_| ())))
}

/// `v` as a whole number in `range`, or a `ValueError` naming `field` and the range.
pub fn whole(field: &str, v: &Bound<'_, PyAny>, range: RangeInclusive<u64>) -> PyResult<u64> {
    match integer(v)? {
        Some(Ok(n)) => u64::try_from(n)
            .ok()
            .filter(|n| range.contains(n))
            .ok_or_else(|| not_whole(field, v, &range)),
        _ => Err(not_whole(field, v, &range)),
    }
}

/// [`whole`] as a `usize` (sizes: envs, threads, slots).
pub fn size(field: &str, v: &Bound<'_, PyAny>, range: RangeInclusive<usize>) -> PyResult<usize> {
    let (lo, hi) = (*range.start() as u64, *range.end() as u64);
    whole(field, v, lo..=hi).map(|n| n as usize)
}

/// A seed (any `u64`), naming `field`.
pub fn seed(field: &str, v: &Bound<'_, PyAny>) -> PyResult<u64> {
    whole(field, v, SEEDS)
}

/// An episode count of one run, naming `field`.
pub fn episodes(field: &str, v: &Bound<'_, PyAny>) -> PyResult<u64> {
    whole(field, v, EPISODES)
}

/// [`seed`] for each item of `v` (a sequence), each named `field[i]`.
pub fn seeds(field: &str, v: &Bound<'_, PyAny>) -> PyResult<Vec<u64>> {
    items(field, v)?
        .iter()
        .enumerate()
        .map(|(i, s)| seed(&format!("{field}[{i}]"), s))
        .collect()
}

/// [`path`] for each item of `v` (a sequence), each named `field[i]`.
pub fn paths(field: &str, v: &Bound<'_, PyAny>) -> PyResult<Vec<PathBuf>> {
    items(field, v)?
        .iter()
        .enumerate()
        .map(|(i, p)| path(&format!("{field}[{i}]"), p))
        .collect()
}

/// The items of `v`, a sequence (not text), naming `field`.
fn items<'py>(field: &str, v: &Bound<'py, PyAny>) -> PyResult<Vec<Bound<'py, PyAny>>> {
    if v.is_instance_of::<PyString>() || v.is_instance_of::<PyBytes>() || v.is_instance_of::<PyDict>() {
        return Err(errors::value(format!("{field} {}: expected a sequence", shown(v))));
    }
    let Ok(iter) = v.try_iter() else {
        return Err(errors::value(format!("{field} {}: expected a sequence", shown(v))));
    };
    let mut out = Vec::new();
    for item in iter {
        if out.len() >= MAX_ITEMS {
            return Err(errors::value(format!("{field}: more than {MAX_ITEMS} items")));
        }
        out.push(item?);
    }
    Ok(out)
}

/// `v` as text (a `str`, not empty, without control characters), naming `field`.
pub fn text(field: &str, v: &Bound<'_, PyAny>) -> PyResult<String> {
    let Ok(s) = v.cast::<PyString>() else {
        return Err(errors::value(format!("{field} {}: expected text", shown(v))));
    };
    checked_text(field, s.to_str()?.to_string(), "empty text; give a value")
}

/// `v` as a path (text or an `os.PathLike`, not empty, without control characters),
/// naming `field`.
pub fn path(field: &str, v: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    path_text(field, v).map(PathBuf::from)
}

/// [`path`] as text.
fn path_text(field: &str, v: &Bound<'_, PyAny>) -> PyResult<String> {
    let os = v.py().import("os")?;
    let Ok(p) = os.call_method1("fspath", (v,)) else {
        return Err(errors::value(format!(
            "{field} {}: expected a path (text or a pathlib.Path)",
            shown(v)
        )));
    };
    let Ok(s) = p.cast::<PyString>() else {
        return Err(errors::value(format!("{field} {}: expected a path as text", shown(v))));
    };
    checked_text(
        field,
        s.to_str()?.to_string(),
        "an empty path; give a file or folder name",
    )
}

fn checked_text(field: &str, s: String, empty: &str) -> PyResult<String> {
    if s.is_empty() {
        return Err(errors::value(format!("{field}: {empty}")));
    }
    if s.chars().any(char::is_control) {
        return Err(errors::value(format!(
            "{field} {s:?}: has a control character (a newline, a tab, ...); give it without"
        )));
    }
    Ok(s)
}

/// How a request field is read from Python.
#[derive(Clone, Copy)]
enum Kind {
    /// A whole number in the range.
    Whole(u64, u64),
    /// A path (text or `os.PathLike`).
    Path,
    /// Several paths (or one).
    Paths,
    /// Several names (methods, `--set` texts).
    Texts,
    /// Training seeds: a sequence of seeds, or text like `1..4`.
    Seeds,
    /// Text (a method's, a protocol's name, a shard).
    Text,
    /// A bool.
    Bool,
    /// A number (a share).
    Number,
}

/// The most draws or candidates of any job (the estimate's or the search's; the job's own
/// bound is the library's check).
const MAX_BUDGET: usize = {
    use unforeseen_harness::runs::{estimate, search};
    if estimate::MAX_BUDGET > search::MAX_BUDGET {
        estimate::MAX_BUDGET
    } else {
        search::MAX_BUDGET
    }
};

/// Every field of every job's request and its kind, the bounds those of the library.
const FIELDS: &[(&str, Kind)] = &[
    ("episodes", Kind::Whole(1, MAX_EPISODES)),
    ("train_episodes", Kind::Whole(1, MAX_EPISODES)),
    ("seed", Kind::Whole(0, u64::MAX)),
    ("jobs", Kind::Whole(1, MAX_JOBS as u64)),
    ("budget", Kind::Whole(1, MAX_BUDGET as u64)),
    ("rounds", Kind::Whole(0, u64::MAX)),
    ("max_failures", Kind::Whole(0, u64::MAX)),
    ("maps", Kind::Paths),
    ("stream", Kind::Path),
    ("space", Kind::Path),
    ("out", Kind::Path),
    ("cache", Kind::Path),
    ("agent", Kind::Path),
    ("map", Kind::Path),
    ("train_map", Kind::Path),
    ("test_map", Kind::Path),
    ("methods", Kind::Texts),
    ("sets", Kind::Texts),
    ("train_seeds", Kind::Seeds),
    ("method", Kind::Text),
    ("protocol", Kind::Text),
    ("shard", Kind::Text),
    ("timeout_as", Kind::Text),
    ("estimator", Kind::Text),
    ("resume", Kind::Bool),
    ("force", Kind::Bool),
    ("ablations", Kind::Bool),
    ("sobol_share", Kind::Number),
    ("target_rel_error", Kind::Number),
];

/// `v` as the JSON value of a request field of kind `kind` (None as null).
fn field_value(field: &str, kind: Kind, v: &Bound<'_, PyAny>) -> PyResult<Value> {
    if v.is_none() {
        return Ok(Value::Null);
    }
    Ok(match kind {
        Kind::Whole(lo, hi) => Value::from(whole(field, v, lo..=hi)?),
        Kind::Path => Value::from(path_text(field, v)?),
        Kind::Text => Value::from(text(field, v)?),
        Kind::Paths if v.is_instance_of::<PyString>() || v.hasattr("__fspath__")? => {
            Value::Array(vec![Value::from(path_text(field, v)?)])
        }
        Kind::Paths => Value::Array(
            items(field, v)?
                .iter()
                .enumerate()
                .map(|(i, p)| path_text(&format!("{field}[{i}]"), p).map(Value::from))
                .collect::<PyResult<_>>()?,
        ),
        Kind::Texts => Value::Array(
            items(field, v)?
                .iter()
                .enumerate()
                .map(|(i, t)| text(&format!("{field}[{i}]"), t).map(Value::from))
                .collect::<PyResult<_>>()?,
        ),
        Kind::Seeds if v.is_instance_of::<PyString>() => Value::from(text(field, v)?),
        Kind::Seeds if integer(v)?.is_some() || !v.hasattr("__iter__")? => {
            return Err(errors::value(format!(
                "{field} {}: expected training seeds: a sequence such as range(1, 5), or text like '1..4'",
                shown(v)
            )));
        }
        Kind::Seeds => Value::from(seeds(field, v)?),
        Kind::Bool => match v.cast::<PyBool>() {
            Ok(b) => Value::Bool(b.is_true()),
            Err(_) => return Err(errors::value(format!("{field} {}: expected True or False", shown(v)))),
        },
        Kind::Number => {
            let x = if v.is_instance_of::<PyBool>() || v.is_instance_of::<PyString>() {
                None
            } else {
                v.extract::<f64>().ok().filter(|x| x.is_finite())
            };
            match x.and_then(serde_json::Number::from_f64) {
                Some(n) => Value::Number(n),
                None => return Err(errors::value(format!("{field} {}: expected a finite number", shown(v)))),
            }
        }
    })
}

/// The request `T` of a job from its keyword arguments `fields` (the others at their
/// defaults): each converted by its field's kind ([`FIELDS`]), then the request built by
/// the library, which names the field of any other refusal.
pub fn request<T>(fields: &Bound<'_, PyDict>) -> PyResult<T>
where
    T: serde::Serialize + serde::de::DeserializeOwned + Default,
{
    let mut values = serde_json::Map::new();
    for (k, v) in fields.iter() {
        let field: String = k.extract()?;
        let value = match FIELDS.iter().find(|(name, _)| *name == field) {
            Some((_, kind)) => field_value(&field, *kind, &v)?,
            // Not a field of any request: the library lists the request's fields.
            None => Value::Null,
        };
        values.insert(field, value);
    }
    unforeseen_harness::runs::request::from_fields(values).map_err(errors::to_py)
}

/// Converts `value` as the argument `field` of kind `kind` (`"seed"`, `"episodes"`,
/// `"seeds"`, `"path"`, `"text"`), raising the `ValueError` the functions of this
/// extension raise for it: for the Python functions of the package that take such
/// arguments themselves. Returns the converted value.
#[pyfunction]
fn argument<'py>(py: Python<'py>, field: &str, kind: &str, value: &Bound<'py, PyAny>) -> PyResult<Bound<'py, PyAny>> {
    Ok(match kind {
        "seed" => seed(field, value)?.into_pyobject(py)?.into_any(),
        "episodes" => episodes(field, value)?.into_pyobject(py)?.into_any(),
        "seeds" => seeds(field, value)?.into_pyobject(py)?.into_any(),
        "path" => path_text(field, value)?.into_pyobject(py)?.into_any(),
        "text" => text(field, value)?.into_pyobject(py)?.into_any(),
        other => {
            return Err(errors::value(format!(
                "kind: no argument kind '{other}'; the kinds are seed, episodes, seeds, path, text"
            )));
        }
    })
}

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(argument, m)?)?;
    Ok(())
}
