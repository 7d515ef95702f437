//! Progress of long runs, through the [`Progress`] trait: the library announces a phase
//! (a name and a number of steps), advances it, finishes it, and passes on the lines it
//! has for the user (what it is doing, one finished item, a warning). It draws and prints
//! nothing itself; [`NoProgress`] ignores everything, and the command line draws bars or
//! prints lines.
//!
//! Functions that run a whole phase (training several agents, a study, a batch, learning
//! curves) announce it and finish it; the building blocks they share
//! ([`crate::training::train_with_progress`], [`crate::episodes::evaluation::run_agent_episodes`] and
//! its siblings) only advance, so several of them running in parallel share one phase.

use crate::error::Error;

/// What a line for the user is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Message {
    /// What the run is doing now, e.g. `evaluating q-learning, scaled on ...` or
    /// `evaluated scaled`.
    Status,
    /// One finished item of the phase, e.g. `agent seed 3: loaded ...`.
    Item,
    /// Something the user should know whether or not they asked for progress, e.g. a
    /// cache entry that could not be used.
    Warning,
}

/// Receives the progress of a run. Shared between the worker threads of a phase.
pub trait Progress: Sync {
    /// A phase of `total` steps starts, labelled `name` (e.g. `training`, `evaluating`).
    fn phase(&self, name: &str, total: u64);
    /// `n` more steps of the current phase are done.
    fn advance(&self, n: u64);
    /// The current phase is over.
    fn finish(&self);
    /// A line for the user.
    fn message(&self, kind: Message, line: &str);
    /// Whether the caller asks the run to stop (the Python package: a pending Ctrl-C).
    /// Runs ask at every step ([`step`]) and then return [`Error::Interrupted`]; by
    /// default, never.
    fn cancelled(&self) -> bool {
        false
    }
}

/// Passes on only whether the caller asks `0` to stop: the progress of a run's inner
/// steps (a unit's episodes) when only its outer steps are shown.
pub struct CancelOnly<'a>(pub &'a dyn Progress);

impl Progress for CancelOnly<'_> {
    fn phase(&self, _name: &str, _total: u64) {}
    fn advance(&self, _n: u64) {}
    fn finish(&self) {}
    fn message(&self, _kind: Message, _line: &str) {}
    fn cancelled(&self) -> bool {
        self.0.cancelled()
    }
}

/// One more step of the current phase of `progress` is done; [`Error::Interrupted`]
/// when the caller asks the run to stop.
pub fn step<P: Progress + ?Sized>(progress: &P) -> Result<(), Error> {
    progress.advance(1);
    if progress.cancelled() {
        Err(Error::Interrupted)
    } else {
        Ok(())
    }
}

/// Ignores all progress.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn phase(&self, _name: &str, _total: u64) {}
    fn advance(&self, _n: u64) {}
    fn finish(&self) {}
    fn message(&self, _kind: Message, _line: &str) {}
}
