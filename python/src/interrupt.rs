//! Long calls that Ctrl-C stops: [`interruptible`] runs the library's work on a thread of
//! its own while the calling thread (the one Python delivers signals to) checks for
//! signals every 50 ms. On a signal (SIGINT: `KeyboardInterrupt`) it asks the work to
//! stop ([`Progress::cancelled`]: the library stops at its next episode with
//! `Error::Interrupted`), waits for it (temporary files are removed as the work
//! unwinds) and raises the signal's exception.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use pyo3::prelude::*;
use unforeseen_harness::error::Error;
use unforeseen_harness::progress::{Message, Progress};

use crate::errors;

/// How often the calling thread checks for signals.
const POLL: Duration = Duration::from_millis(50);

/// No progress shown; cancelled once a signal arrived.
#[derive(Default)]
struct Watch {
    stop: AtomicBool,
}

impl Progress for Watch {
    fn phase(&self, _name: &str, _total: u64) {}
    fn advance(&self, _n: u64) {}
    fn finish(&self) {}
    fn message(&self, _kind: Message, _line: &str) {}
    fn cancelled(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }
}

/// Runs `work` (given the progress to pass to the library) with the GIL released,
/// raising the signal's exception (e.g. `KeyboardInterrupt`) within about 50 ms of the
/// work's next step after a signal; otherwise its result, errors as `ValueError` or
/// `RuntimeError` ([`errors::to_py`]).
pub fn interruptible<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&dyn Progress) -> Result<T, Error> + Send,
{
    interruptible_then(py, |_| Ok(()), work)
}

/// [`interruptible`], calling `on_signal` (with the GIL, on the calling thread) once a
/// signal arrived, after asking the work to stop: for work that waits on Python code
/// the library cannot stop (e.g. setting a `threading.Event` a search's evaluator
/// checks). An error of `on_signal` is dropped: the signal's exception is raised.
pub fn interruptible_then<T, F, S>(py: Python<'_>, on_signal: S, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&dyn Progress) -> Result<T, Error> + Send,
    S: FnOnce(Python<'_>) -> PyResult<()>,
{
    let mut on_signal = Some(on_signal);
    let watch = Watch::default();
    let mut raised: Option<PyErr> = None;
    let done = std::thread::scope(|s| {
        let handle = s.spawn(|| work(&watch));
        loop {
            py.detach(|| {
                let mut waited = Duration::ZERO;
                while !handle.is_finished() && waited < POLL {
                    std::thread::sleep(Duration::from_millis(5));
                    waited += Duration::from_millis(5);
                }
            });
            if handle.is_finished() {
                break;
            }
            if raised.is_none()
                && let Err(e) = py.check_signals()
            {
                raised = Some(e);
                watch.stop.store(true, Ordering::Relaxed);
                if let Some(f) = on_signal.take() {
                    let _ = f(py);
                }
            }
        }
        handle.join()
    });
    if let Some(e) = raised {
        return Err(e);
    }
    match done {
        Ok(result) => result.map_err(errors::to_py),
        Err(_) => Err(errors::value("the run stopped on an internal error (a panic)")),
    }
}
