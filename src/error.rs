//! The library's typed errors. Every variant is something the user can fix by changing
//! an input (an agent file, a map set, a flag, a results file); the library says what is
//! wrong and how to fix it, and only the command line ([`crate::cli`]) turns an error
//! into a message and an exit code. Map errors keep their own types
//! ([`crate::maps::MapLookupError`], [`unforeseen_sim::MapError`]).

use std::path::PathBuf;

/// An input the user can fix.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An agent file cannot be used: missing, not a regular file, not text, too large,
    /// corrupt, from another format version, a value out of range, or not an agent of
    /// this program's intersection.
    #[error("{}: {}{problem}; {fix}", path.display(), field.as_ref().map(|f| format!("{f}: ")).unwrap_or_default())]
    AgentFile {
        /// The file.
        path: PathBuf,
        /// The field, e.g. `world_model.a_counts[3,2]`, when the problem is one value.
        field: Option<String>,
        /// What is wrong.
        problem: String,
        /// How to fix it.
        fix: String,
    },
    /// A trained agent does not fit a map, or lacks what a method needs.
    #[error("{problem}; {fix}")]
    Agent {
        /// What is wrong.
        problem: String,
        /// How to fix it.
        fix: String,
    },
    /// A command-line value: `--set`, `--obs` and the like.
    #[error("{flag}: {problem}")]
    Flag {
        /// The flag as given, e.g. `--set horizon=1,,2`.
        flag: String,
        /// What is wrong and how to write it.
        problem: String,
    },
    /// A results file cannot be read, or `--resume` would mix two runs in it.
    #[error("{}: {problem}", path.display())]
    Results {
        /// The results file.
        path: PathBuf,
        /// What is wrong and what to do.
        problem: String,
    },
    /// An output path exists and is not a regular file (a folder, a device, a pipe):
    /// replacing it would destroy it.
    #[error("{}: exists and is not a regular file; write results to a file path", path.display())]
    NotRegularFile {
        /// The path.
        path: PathBuf,
    },
    /// Two scenarios of one batch have the same name (results are keyed by it).
    #[error(
        "{second}: its map is named '{name}' like {first}; results and --resume tell scenarios apart by name: give one a different `name:` or list each map once"
    )]
    DuplicateScenario {
        /// The shared name.
        name: String,
        /// Where the first came from.
        first: String,
        /// Where the second came from.
        second: String,
    },
    /// A model file for `inspect` cannot be read or is invalid.
    #[error("{}: {problem}", path.display())]
    ModelFile {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// Some of the maps given to `check-map` failed (each was reported already).
    #[error("{failed} of {total} map file(s) failed the check")]
    MapsFailed {
        /// How many failed.
        failed: usize,
        /// How many were checked.
        total: usize,
    },
}

impl Error {
    /// A [`Error::Flag`].
    pub fn flag(flag: impl Into<String>, problem: impl Into<String>) -> Self {
        Error::Flag {
            flag: flag.into(),
            problem: problem.into(),
        }
    }
}
