//! # unforeseen's Python extension (`unforeseen._unforeseen`)
//!
//! A thin layer over the Rust crates the command line uses: every number a Python caller
//! sees (observations, rewards, events, decisions, evaluation figures) comes from them.
//! The Python package `unforeseen` (python/unforeseen/) wraps these classes into
//! Gymnasium environments; `_unforeseen.pyi` is the interface, class by class.
//!
//! * [`convert`]: Python arguments (counts, seeds, sizes, paths, a job's keyword
//!   arguments) to the library's values, every refusal naming its argument;
//! * [`maps`]: a map by file or embedded name, with keyword overrides as a RON patch
//!   validated by the map loader;
//! * [`env`]: one episode API ([`unforeseen_env::Env`]) per Python object;
//! * [`vector`]: many envs stepped in Rust threads with the GIL released;
//! * [`render`]: the top-down frame (tiny-skia) and the text line;
//! * [`agent`]: training, agent files, every method's controller, evaluation;
//! * [`aif`]: the general active-inference agent on any model in pymdp's layout, behind
//!   the surprise gate (`unforeseen.aif`);
//! * [`results`]: `compare` and `batch`, run as the command line runs them;
//! * [`reports`]: the reports of `compare`, `eval` and `batch` as Python objects: their
//!   files' data, and the command line's printed table as `str()`, Markdown and HTML;
//! * [`wrapper`]: the scaled agent around any habit, and the batch summary of a results file;
//! * [`policy`]: Python policies (and the scaled agent around a Python habit) evaluated by
//!   the library's episode loop, reported as the batch's result lines;
//! * [`units`]: a batch run as units of work for a distributed driver (plan, train a
//!   seed, run a block of units with the GIL released, join the results);
//! * [`errors`]: Rust errors as Python exceptions (`ValueError` for what the user can fix).

mod agent;
mod aif;
mod convert;
mod env;
mod errors;
mod estimate;
mod interrupt;
mod maps;
mod policy;
mod render;
mod reports;
mod requests;
mod runs;
mod search_units;
mod units;
mod vector;
mod wrapper;

use pyo3::prelude::*;

/// Names of the maps embedded in the library (`intersection`, `jaywalk`, ...).
#[pyfunction]
fn embedded_maps() -> Vec<&'static str> {
    unforeseen_sim::embedded::names().to_vec()
}

/// The version of the Rust crates this extension was built from.
#[pyfunction]
fn version() -> &'static str {
    env!("CARGO_PKG_VERSION")
}

/// The extension module.
#[pymodule]
fn _unforeseen(m: &Bound<'_, PyModule>) -> PyResult<()> {
    // NumPy's C API and the numpy crate's shared borrow checking, set up now, at import:
    // the crate sets each up on first use and reports a failure there as a panic. Its
    // set-up runs Python code (`numpy.lib.NumpyVersion`), so a Ctrl-C pending at that
    // moment made a `PanicException` instead of `KeyboardInterrupt` while stepping a
    // vector env. Here the module's name is found first, where a failure (the Ctrl-C
    // itself) is the import's exception; what follows runs no Python code.
    numpy::get_array_module(m.py())?;
    let probe = numpy::PyArray1::<i64>::zeros(m.py(), [0], false);
    drop(numpy::PyArrayMethods::readonly(&probe));
    m.add_function(wrap_pyfunction!(embedded_maps, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    convert::register(m)?;
    env::register(m)?;
    vector::register(m)?;
    agent::register(m)?;
    aif::register(m)?;
    runs::register(m)?;
    reports::register(m)?;
    wrapper::register(m)?;
    policy::register(m)?;
    requests::register(m)?;
    units::register(m)?;
    search_units::register(m)?;
    estimate::register(m)?;
    Ok(())
}
