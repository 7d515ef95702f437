//! The reports of `compare`, `eval` and `batch` as Python objects: each holds its
//! report's serde data (what compare.json, eval.json, or the results file's lines and
//! the summary hold) and the document the command line prints
//! ([`unforeseen_harness::reports::Document`]). `str()` is the command line's table,
//! `_repr_markdown_` / `_repr_html_` the same table for notebooks, `to_dict()` and
//! `result["key"]` the data, `to_records()` the table's rows as flat dicts and
//! `to_pandas()` those rows as a DataFrame (where pandas is installed).

use pyo3::exceptions::{PyImportError, PyKeyError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyList, PyString};
use serde_json::{Map, Value};
use unforeseen_harness::reports::Document;
use unforeseen_harness::runs::batch::{ResultLine, summarize};
use unforeseen_harness::runs::batch::{batch_summary, expectation_failures};
use unforeseen_harness::runs::compare::CompareReport;
use unforeseen_harness::runs::compare::compare_table;
use unforeseen_harness::runs::evaluate::EvalOutcome;

use crate::errors;

/// JSON data as the Python value `json.loads` would give (objects as dicts, arrays as
/// lists, null as None).
pub fn to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => {
            if let Some(i) = n.as_i64() {
                i.into_pyobject(py)?.into_any()
            } else if let Some(u) = n.as_u64() {
                u.into_pyobject(py)?.into_any()
            } else {
                n.as_f64().unwrap_or(f64::NAN).into_pyobject(py)?.into_any()
            }
        }
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(items) => {
            let list = PyList::empty(py);
            for item in items {
                list.append(to_py(py, item)?)?;
            }
            list.into_any()
        }
        Value::Object(fields) => {
            let dict = PyDict::new(py);
            for (k, item) in fields {
                dict.set_item(k, to_py(py, item)?)?;
            }
            dict.into_any()
        }
    })
}

/// A row as one flat object: a nested object's fields are named `outer_inner`, and a
/// summarized figure's mean keeps the figure's own name (`success_rate`,
/// `success_rate_ci95_low`, ..., as compare.csv names them).
fn flatten(prefix: &str, v: &Value, out: &mut Map<String, Value>) {
    match v {
        Value::Object(fields) => {
            for (k, item) in fields {
                let name = match (prefix.is_empty(), k.as_str()) {
                    (true, _) => k.clone(),
                    (false, "mean") => prefix.to_string(),
                    (false, _) => format!("{prefix}_{k}"),
                };
                flatten(&name, item, out);
            }
        }
        _ => {
            out.insert(prefix.to_string(), v.clone());
        }
    }
}

/// What every report object holds: the data, the printed document and the table's rows.
struct Report {
    data: Value,
    doc: Document,
    rows: Vec<Value>,
}

impl Report {
    fn item<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
        match self.data.get(key) {
            Some(v) => to_py(py, v),
            None => Err(PyKeyError::new_err(key.to_string())),
        }
    }

    fn keys(&self) -> Vec<String> {
        self.data
            .as_object()
            .map(|o| o.keys().cloned().collect())
            .unwrap_or_default()
    }

    fn records<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let flat: Vec<Value> = self
            .rows
            .iter()
            .map(|r| {
                let mut out = Map::new();
                flatten("", r, &mut out);
                Value::Object(out)
            })
            .collect();
        to_py(py, &Value::Array(flat))
    }

    fn pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pandas = py.import("pandas").map_err(|e| {
            if e.is_instance_of::<PyImportError>(py) {
                PyImportError::new_err(
                    "to_pandas() needs pandas, which is not installed: pip install 'unforeseen[pandas]' (or pandas)",
                )
            } else {
                e
            }
        })?;
        pandas.getattr("DataFrame")?.call1((self.records(py)?,))
    }
}

/// A report class: the data by key and as a dict, the printed table as `str()` and
/// `repr()`, Markdown and HTML for notebooks, the rows as records and a DataFrame; then
/// the class's own getters.
macro_rules! report_class {
    ($(#[$doc:meta])* $name:ident, $py_name:literal, { $($getters:tt)* }) => {
        $(#[$doc])*
        #[pyclass(name = $py_name, module = "unforeseen._unforeseen", frozen)]
        pub struct $name {
            report: Report,
        }

        #[pymethods]
        impl $name {
            /// The table the command line prints.
            fn __str__(&self) -> String {
                self.report.doc.to_string()
            }

            /// The table the command line prints.
            fn __repr__(&self) -> String {
                self.report.doc.to_string()
            }

            /// The table as Markdown (a notebook's rich display).
            fn _repr_markdown_(&self) -> String {
                self.report.doc.markdown()
            }

            /// The table as an HTML fragment (a notebook's rich display).
            fn _repr_html_(&self) -> String {
                self.report.doc.html()
            }

            /// The data under `key` (as `to_dict()[key]`); `KeyError` if there is none.
            fn __getitem__<'py>(&self, py: Python<'py>, key: &str) -> PyResult<Bound<'py, PyAny>> {
                self.report.item(py, key)
            }

            /// Whether the data has `key`.
            fn __contains__(&self, key: &str) -> bool {
                self.report.data.get(key).is_some()
            }

            /// The data's keys, sorted.
            fn keys(&self) -> Vec<String> {
                self.report.keys()
            }

            /// The data under `key`, or `default`.
            #[pyo3(signature = (key, default = None))]
            fn get<'py>(
                &self,
                py: Python<'py>,
                key: &str,
                default: Option<Bound<'py, PyAny>>,
            ) -> PyResult<Bound<'py, PyAny>> {
                match self.report.data.get(key) {
                    Some(v) => to_py(py, v),
                    None => Ok(default.unwrap_or_else(|| py.None().into_bound(py))),
                }
            }

            /// The whole data as a new dict (as `json.load` of the file would give it).
            fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                to_py(py, &self.report.data)
            }

            /// The table's rows as flat dicts: nested fields as `outer_inner`, a
            /// summarized figure's mean under the figure's name.
            fn to_records<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                self.report.records(py)
            }

            /// The rows of `to_records()` as a pandas DataFrame; `ImportError` naming
            /// the `pandas` extra where pandas is not installed.
            fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
                self.report.pandas(py)
            }

            $($getters)*
        }
    };
}

report_class!(
    /// `compare`'s report: compare.json's data, printed as the command line's tables (one
    /// per protocol). Rows: one per (protocol, method), summarized over the agents.
    CompareResult,
    "CompareResult",
    {
        /// One table per protocol, each with its `methods` rows.
        #[getter]
        fn tables<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
            self.report.item(py, "tables")
        }

        /// The protocols, in table order.
        #[getter]
        fn protocols<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
            self.report.item(py, "protocols")
        }

        /// The training map's name.
        #[getter]
        fn train_map<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
            self.report.item(py, "train_map")
        }

        /// The test map's name.
        #[getter]
        fn test_map<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
            self.report.item(py, "test_map")
        }
    }
);

impl CompareResult {
    /// The Python object of a compare report.
    pub fn new(report: &CompareReport) -> PyResult<Self> {
        let data = serde_json::to_value(report).map_err(errors::to_py)?;
        let rows = report
            .tables
            .iter()
            .flat_map(|t| &t.methods)
            .map(|m| {
                let mut row = serde_json::to_value(m)?;
                if let Some(o) = row.as_object_mut() {
                    o.remove("per_seed");
                    o.remove("reward");
                }
                Ok(row)
            })
            .collect::<Result<_, serde_json::Error>>()
            .map_err(errors::to_py)?;
        Ok(CompareResult {
            report: Report {
                data,
                doc: compare_table(report),
                rows,
            },
        })
    }
}

report_class!(
    /// `eval`'s report: eval.json's data, printed as the command line's line. Rows: one
    /// per episode.
    EvalResult,
    "EvalResult",
    {
        /// The figures over every episode.
        #[getter]
        fn aggregate<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
            self.report.item(py, "aggregate")
        }

        /// Every episode, in order.
        #[getter]
        fn episodes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
            self.report.item(py, "episodes")
        }
    }
);

impl EvalResult {
    /// The Python object of an eval report (of a map or of a stream).
    pub fn new(report: &EvalOutcome) -> PyResult<Self> {
        let data = report.document().map_err(errors::to_py)?;
        let rows = data
            .get("episodes")
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default();
        Ok(EvalResult {
            report: Report {
                data,
                doc: report.table(),
                rows,
            },
        })
    }
}

report_class!(
    /// `batch`'s report: the results file's lines (`lines`), the summary over training
    /// seeds (`summary`) and the expectations checked and failed on its mean (`checked`,
    /// `failures`), printed as the command line's summary table. Rows: one
    /// per summary row.
    BatchResult,
    "BatchResult",
    {
        /// The result lines, one per unit (the results file after its `run` line).
        #[getter]
        fn lines<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
            self.report.item(py, "lines")
        }

        /// The summary's rows over training seeds (results.summary.json's rows).
        #[getter]
        fn summary<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
            self.report.item(py, "summary")
        }

        /// The expectations checked on the mean over training seeds.
        #[getter]
        fn checked<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
            self.report.item(py, "checked")
        }

        /// One message per expectation failed on the mean over training seeds, in
        /// `unforeseen batch`'s words (the command exits 1 on any).
        #[getter]
        fn failures<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
            self.report.item(py, "failures")
        }
    }
);

impl BatchResult {
    /// The Python object of a batch's result lines, summarized as the command line does.
    pub fn new(lines: &[ResultLine]) -> PyResult<Self> {
        let summary = summarize(lines);
        let rows = serde_json::to_value(&summary).map_err(errors::to_py)?;
        let mut data = Map::new();
        data.insert("lines".into(), serde_json::to_value(lines).map_err(errors::to_py)?);
        data.insert("summary".into(), rows.clone());
        let checked: usize = summary.iter().map(|r| r.checks.len()).sum();
        data.insert("checked".into(), checked.into());
        data.insert("failures".into(), expectation_failures(&summary).into());
        let data = Value::Object(data);
        Ok(BatchResult {
            report: Report {
                doc: batch_summary(&summary),
                rows: rows.as_array().cloned().unwrap_or_default(),
                data,
            },
        })
    }
}

/// Registers the classes.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<CompareResult>()?;
    m.add_class::<EvalResult>()?;
    m.add_class::<BatchResult>()?;
    Ok(())
}
