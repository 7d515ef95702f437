//! The library's typed error: every public function of this crate returns
//! `Result<_, Error>`. Some variants are input the user can fix by changing it (an agent
//! file, a map, a flag, a results file), and say what is wrong and how to fix it; the
//! others are failures of the machine or of a component (a file that cannot be written,
//! an episode the env refused, a learner that cannot be built). [`Error::is_user_input`]
//! tells them apart, and [`in_chain`] over a chain of causes; only the fronts
//! (the command line, the Python package) turn an error into a message and an exit code
//! or an exception. The errors of other crates keep their own types and messages inside
//! it (map errors, [`unforeseen_env::EnvError`], [`unforeseen_agent::error::AgentError`], ...).

use std::path::PathBuf;

/// Why a function of this crate failed.
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
    /// A value out of its allowed range, named by its field (`episodes`,
    /// `train_episodes`, ...); a front adds its own spelling of the field (a flag, a
    /// keyword argument) where it needs one.
    #[error("{field} {value}: expected {expected}")]
    OutOfRange {
        /// The field, e.g. `episodes`.
        field: String,
        /// The value given.
        value: String,
        /// What is allowed, e.g. `1..=1000000`.
        expected: String,
    },
    /// A parameter override, named by its setting (`epsilon=2`), whichever front it came
    /// from: the command line spells it as its flag (`--set epsilon=2`), Python as the
    /// keyword argument it was.
    #[error("{setting}: {problem}")]
    Override {
        /// The setting as given, `key=value` (or `key` where the key is unknown).
        setting: String,
        /// What is wrong and what is allowed.
        problem: String,
    },
    /// A field of a job's request ([`crate::runs::batch::BatchRequest`],
    /// [`crate::runs::search::SearchRequest`]) that cannot be used, named by the field
    /// (`train_seeds`, `protocol`, `sets`, ...) and, where it helps, the value given; a
    /// front spells the field its own way (the command line as its flag).
    #[error("{field}{}: {problem}", value.as_ref().map(|v| format!(" {v}")).unwrap_or_default())]
    Request {
        /// The request's field, e.g. `train_seeds`.
        field: String,
        /// The value given, as the user wrote it, when the problem is one value.
        value: Option<String>,
        /// What is wrong and what is allowed.
        problem: String,
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
    /// No map of that name or path, or a map that does not validate.
    #[error(transparent)]
    Map(#[from] unforeseen_sim::embedded::LookupError),
    /// A map file that does not validate (every diagnostic).
    #[error(transparent)]
    MapFile(#[from] unforeseen_sim::MapError),
    /// A deployment stream file that cannot be used (its place and what to change).
    #[error(transparent)]
    Stream(#[from] StreamError),
    /// A file or folder could not be read, written, created or listed.
    #[error("cannot {action} {}", path.display())]
    Io {
        /// What was attempted: `read`, `write`, `create folder`, `list`, `append to`.
        action: &'static str,
        /// The file or folder.
        path: PathBuf,
        /// What the system said.
        #[source]
        source: std::io::Error,
    },
    /// The env could not be built or stepped.
    #[error(transparent)]
    Env(#[from] unforeseen_env::EnvError),
    /// An episode could not run (the controller chose an action the env refused).
    #[error(transparent)]
    Episode(#[from] EpisodeError),
    /// A learner or an agent could not be built from its parameters and sizes.
    #[error(transparent)]
    Learner(#[from] unforeseen_agent::error::AgentError),
    /// A map's bins cannot make a discretizer.
    #[error(transparent)]
    Bins(#[from] unforeseen_discretizer::DiscretizerError),
    /// A value could not be written as JSON.
    #[error(transparent)]
    Json(#[from] serde_json::Error),
    /// A figure could not be drawn.
    #[error("{message}")]
    Plot {
        /// What the plotting library said.
        message: String,
    },
    /// The worker threads could not be started.
    #[error(transparent)]
    Threads(#[from] rayon::ThreadPoolBuildError),
    /// A batch unit names a training seed none of the agents given has.
    #[error("no agent with training seed {train_seed:?} was given")]
    MissingAgent {
        /// The unit's training seed.
        train_seed: Option<u64>,
    },
    /// A method that needs a trained agent was asked to run as a scripted reference.
    #[error("{method} is not a scripted method")]
    NotScripted {
        /// The method's name.
        method: String,
    },
    /// The caller asked the run to stop ([`crate::progress::Progress::cancelled`]).
    #[error("interrupted")]
    Interrupted,
}

impl Error {
    /// Whether the error is input the user can fix (an agent file, a map, a flag, a
    /// results file, an output path), rather than a failure of the machine or of a
    /// component. An [`Error::Io`] is not; what it wraps is only an I/O error.
    pub fn is_user_input(&self) -> bool {
        match self {
            Error::AgentFile { .. }
            | Error::Agent { .. }
            | Error::Flag { .. }
            | Error::Override { .. }
            | Error::Request { .. }
            | Error::OutOfRange { .. }
            | Error::Results { .. }
            | Error::NotRegularFile { .. }
            | Error::DuplicateScenario { .. }
            | Error::ModelFile { .. }
            | Error::MapsFailed { .. }
            | Error::Map(_)
            | Error::MapFile(_)
            | Error::Stream(_) => true,
            Error::Io { .. }
            | Error::Env(_)
            | Error::Episode(_)
            | Error::Learner(_)
            | Error::Bins(_)
            | Error::Json(_)
            | Error::Plot { .. }
            | Error::Threads(_)
            | Error::MissingAgent { .. }
            | Error::NotScripted { .. }
            | Error::Interrupted => false,
        }
    }

    /// An [`Error::Io`]: `action` (`read`, `write`, ...) on `path` failed with `source`.
    pub fn io(action: &'static str, path: impl Into<PathBuf>, source: std::io::Error) -> Self {
        Error::Io {
            action,
            path: path.into(),
            source,
        }
    }

    /// The message with every cause after it, `outer: inner: ...` (as the command line
    /// prints errors).
    pub fn full_message(&self) -> String {
        let mut text = self.to_string();
        let mut cause = std::error::Error::source(self);
        while let Some(e) = cause {
            text.push_str(": ");
            text.push_str(&e.to_string());
            cause = e.source();
        }
        text
    }

    /// An [`Error::Request`] about `field`, with no value quoted.
    pub fn request(field: impl Into<String>, problem: impl Into<String>) -> Self {
        Error::Request {
            field: field.into(),
            value: None,
            problem: problem.into(),
        }
    }

    /// A [`Error::Flag`].
    pub fn flag(flag: impl Into<String>, problem: impl Into<String>) -> Self {
        Error::Flag {
            flag: flag.into(),
            problem: problem.into(),
        }
    }
}

/// Whether `err` or anything in its chain of causes is input the user can fix: an
/// [`Error`] for which [`Error::is_user_input`] holds, a map that cannot be found or
/// loaded ([`unforeseen_sim::embedded::LookupError`], [`unforeseen_sim::MapError`]) or a bad
/// deployment stream ([`StreamError`]). The command line exits with 2 for these and the
/// Python package raises `ValueError`; anything else is a failure of the machine or of a
/// component.
pub fn in_chain(err: &(dyn std::error::Error + 'static)) -> bool {
    let mut cause = Some(err);
    while let Some(e) = cause {
        let bad_input = e.downcast_ref::<Error>().is_some_and(Error::is_user_input)
            || e.is::<unforeseen_sim::embedded::LookupError>()
            || e.is::<StreamError>()
            || e.is::<unforeseen_sim::MapError>();
        if bad_input {
            return true;
        }
        cause = e.source();
    }
    false
}

/// Why an episode could not run: the controller chose an action that is not one of the
/// three (a bug in the controller, or a policy given from outside).
#[derive(Debug, thiserror::Error)]
#[error("{controller}: {source}")]
pub struct EpisodeError {
    /// The controller's name.
    pub controller: String,
    /// What the env refused.
    #[source]
    pub source: unforeseen_env::EnvError,
}

/// A stream file that cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum StreamError {
    /// Unreadable, too large or not UTF-8.
    #[error("{file}: {message}")]
    Read {
        /// The stream file.
        file: String,
        /// What went wrong.
        message: String,
    },
    /// Not valid RON for a stream.
    #[error(
        "{file}:{line}:{column}: {message} (a stream is Stream(maps: [(map: \"FILE\", weight: W), ...], order: Weighted | Sequence))"
    )]
    Syntax {
        /// The stream file.
        file: String,
        /// Line, from 1.
        line: usize,
        /// Column, from 1.
        column: usize,
        /// What the parser said.
        message: String,
    },
    /// A field with a value that cannot be used.
    #[error("{file}: {field}: {message}")]
    Invalid {
        /// The stream file.
        file: String,
        /// The field, e.g. `maps[1].weight`.
        field: String,
        /// What is wrong and how to fix it.
        message: String,
    },
    /// A map of the stream could not be loaded.
    #[error("{file}: maps[{index}] (a map file relative to the stream file's folder, or an embedded map's name)")]
    Map {
        /// The stream file.
        file: String,
        /// The entry.
        index: usize,
        /// Why the map could not be loaded.
        #[source]
        source: unforeseen_sim::embedded::LookupError,
    },
}
