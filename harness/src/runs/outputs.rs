//! The output guard every command and the Python package call before any work: a run
//! states its inputs ([`Outputs::input`]; a stream's maps with [`Outputs::stream`]) and
//! its outputs (files, [`Outputs::file`], and folders whose every file is the run's,
//! [`Outputs::folder`]), then [`Outputs::check`]:
//!
//! * refuses an output that is one of the inputs (the same file after resolving links;
//!   for a folder, any input inside it), naming both;
//! * refuses an output file that exists and is not a regular file, an output folder that
//!   exists and is not a folder, and a place where nothing can be created;
//! * refuses, unless `force`, an output that holds something other than what this kind
//!   of run writes ([`Own`]), recognised by its content ([`Held`]): a map, an agent
//!   file, another command's results, notes;
//! * takes an advisory lock (`OUT.lock` beside a results file, `OUT/.lock` in a folder)
//!   that refuses a second writer until the [`Guarded`] is dropped;
//! * once the run's own checks have passed ([`Guarded::clear_at_end`]), removes the
//!   outputs of the set that the run rewrites at its end (the summary beside a results
//!   file that is streamed in place), so the set on disk is never one run's file beside
//!   another run's; a refusal before that changes no file. (A search and an estimate
//!   stream to a part and replace their whole set at the end: they remove nothing
//!   before.)
//!
//! Names that become file names (a space's name, a map's name in a search's outputs)
//! are checked by [`file_name`].

use std::path::{Path, PathBuf};

use crate::error::Error;
use crate::runs::file_kinds::Held;

/// Longest name that becomes part of a file name (bytes): file systems take 255, and
/// the name gets a suffix (`_c0046.ron`).
pub const MAX_NAME_BYTES: usize = 128;

/// Checks a name that becomes (part of) a file name: not empty, at most
/// [`MAX_NAME_BYTES`], no path separator, no `..`, no control character. The error names
/// `field` (e.g. `name` of a space file).
pub fn file_name(field: &str, name: &str) -> Result<(), String> {
    let problem = if name.is_empty() {
        "is empty".to_string()
    } else if name.len() > MAX_NAME_BYTES {
        format!("is {} bytes long; at most {MAX_NAME_BYTES}", name.len())
    } else if name.contains(['/', '\\']) {
        "holds a path separator ('/' or '\\')".to_string()
    } else if name.contains("..") {
        "holds '..'".to_string()
    } else if name.chars().any(char::is_control) {
        "holds a control character (a newline, a tab, ...)".to_string()
    } else {
        return Ok(());
    };
    Err(format!(
        "{field} {name:?} {problem}: it becomes a file name; use letters, digits, '_' and '-'"
    ))
}

/// Where the summary of results file `out` goes: `results.jsonl` -> `results.summary.json`.
pub fn summary_path(out: &Path) -> PathBuf {
    out.with_extension("summary.json")
}

/// What a run writes into an output, so that a file holding something else (recognised
/// by its content: [`Held`]) is refused, unless `force`, instead of being replaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Own {
    /// Anything: only inputs and non-files are refused.
    Any,
    /// A batch results file (JSON Lines): a run identity first (`{"run": ...}`), or
    /// result lines (Python's `evaluate`).
    Results,
    /// Result lines without a run identity (what Python's `evaluate` writes).
    ResultLines,
    /// A search's candidates file: its first line is `{"search": ...}`.
    Candidates,
    /// The summary beside a batch's results file.
    BatchSummary,
    /// A search's `summary.json`.
    SearchSummary,
    /// An estimate's draws file: its first line is `{"estimate": ...}`.
    Estimates,
    /// An estimate's `summary.json`.
    EstimateSummary,
    /// `eval.json`.
    Evaluation,
    /// `compare.json`.
    Comparison,
    /// `learn.json`.
    LearningCurves,
    /// A planning model in the `inspect` layout (`export-model`).
    Model,
    /// The summary of `run-model`.
    ModelRun,
    /// An agent file (`train`, Python's `Agent.save`).
    Agent,
    /// A CSV table whose first line is a header of names.
    Csv,
    /// An SVG figure.
    Svg,
    /// An HTML page (`trace --html`).
    Html,
    /// A failure map a search wrote (its first line says so).
    FailureMap,
}

impl Own {
    /// The kinds of file this output may replace (besides an empty file).
    fn accepts(self) -> &'static [Held] {
        match self {
            Own::Any => &[],
            Own::Results => &[Held::BatchRun, Held::ResultLines],
            Own::ResultLines => &[Held::ResultLines],
            Own::Candidates => &[Held::Candidates],
            Own::BatchSummary => &[Held::BatchSummary],
            Own::SearchSummary => &[Held::SearchSummary],
            Own::Estimates => &[Held::Estimates],
            Own::EstimateSummary => &[Held::EstimateSummary],
            Own::Evaluation => &[Held::Evaluation],
            Own::Comparison => &[Held::Comparison],
            Own::LearningCurves => &[Held::LearningCurves],
            Own::Model => &[Held::Model],
            Own::ModelRun => &[Held::ModelRun],
            Own::Agent => &[Held::Agent],
            Own::Csv => &[Held::Csv],
            Own::Svg => &[Held::Svg],
            Own::Html => &[Held::Html],
            Own::FailureMap => &[Held::FailureMap],
        }
    }

    /// What it is, for the error.
    fn what(self) -> &'static str {
        self.accepts().first().map_or("a file", |h| h.describe())
    }

    /// What the file at `path` (which exists) holds when that is not what this run
    /// writes; `None` when the run may replace it (an empty file, or one of its kind).
    fn foreign(self, path: &Path) -> Option<Held> {
        if self == Own::Any {
            return None;
        }
        let held = Held::of(path);
        (held != Held::Empty && !self.accepts().contains(&held)).then_some(held)
    }
}

/// An output file of a run.
#[derive(Debug, Clone)]
struct OutFile {
    flag: String,
    path: PathBuf,
    own: Own,
    /// Written at the end of the run: removed when the guard is taken.
    at_end: bool,
}

/// The inputs and outputs of one run, checked together by [`Outputs::check`].
#[derive(Debug, Clone, Default)]
pub struct Outputs {
    inputs: Vec<(String, PathBuf)>,
    files: Vec<OutFile>,
    /// Output folders (flag, path, whether every file inside is the run's).
    folders: Vec<(String, PathBuf, bool)>,
    /// Files inside a folder the run replaces as a set ([`Outputs::folder_files`]).
    folder_files: Vec<OutFile>,
    /// Where the lock goes (the first output's).
    lock: Option<(String, PathBuf)>,
}

/// A guarded run: holds the lock until dropped.
#[derive(Debug)]
pub struct Guarded {
    _lock: std::fs::File,
    /// Folders that did not exist and were created (for a front to mention).
    pub created: Vec<PathBuf>,
    /// The outputs written at the end of the run ([`Guarded::clear_at_end`]).
    at_end: Vec<PathBuf>,
}

impl Outputs {
    /// No inputs or outputs yet.
    pub fn new() -> Outputs {
        Outputs::default()
    }

    /// An input given as `flag` (a file; a name that is no file, such as an embedded
    /// map, is ignored).
    pub fn input(mut self, flag: &str, path: impl AsRef<Path>) -> Outputs {
        self.inputs.push((flag.to_string(), path.as_ref().to_path_buf()));
        self
    }

    /// A stream file given as `flag` and the map files it lists (`maps`, by position in
    /// its `maps`; `None` for an embedded map).
    pub fn stream(mut self, flag: &str, file: &Path, maps: &[Option<PathBuf>]) -> Outputs {
        self.inputs.push((flag.to_string(), file.to_path_buf()));
        for (i, f) in maps.iter().enumerate() {
            if let Some(f) = f {
                self.inputs
                    .push((format!("{flag} {} (its maps[{i}])", file.display()), f.clone()));
            }
        }
        self
    }

    /// An output file given as `flag`, streamed or rewritten by the run (it is kept
    /// until the run replaces it: `--resume` reads it).
    pub fn file(mut self, flag: &str, path: impl AsRef<Path>, own: Own) -> Outputs {
        let path = path.as_ref().to_path_buf();
        if self.lock.is_none() {
            let mut name = path.as_os_str().to_owned();
            name.push(".lock");
            self.lock = Some((flag.to_string(), PathBuf::from(name)));
        }
        self.files.push(OutFile {
            flag: flag.to_string(),
            path,
            own,
            at_end: false,
        });
        self
    }

    /// A batch results file given as `flag` and the summary beside it (written at the
    /// end of the run): what `batch`, `merge` and Python's `batch` and `evaluate` write.
    pub fn results(flag: &str, out: &Path) -> Outputs {
        Outputs::new().file(flag, out, Own::Results).file_at_end(
            &format!("{flag} (its summary)"),
            summary_path(out),
            Own::BatchSummary,
        )
    }

    /// An output file written at the end of the run (a summary beside a results file):
    /// removed once the guard is taken, so it never describes another run.
    pub fn file_at_end(mut self, flag: &str, path: impl AsRef<Path>, own: Own) -> Outputs {
        self.files.push(OutFile {
            flag: flag.to_string(),
            path: path.as_ref().to_path_buf(),
            own,
            at_end: true,
        });
        self
    }

    /// An output folder given as `flag`: no input may be inside it; the lock goes in it.
    pub fn folder(mut self, flag: &str, dir: impl AsRef<Path>) -> Outputs {
        let dir = dir.as_ref().to_path_buf();
        if self.lock.is_none() {
            self.lock = Some((flag.to_string(), dir.join(".lock")));
        }
        self.folders.push((flag.to_string(), dir, true));
        self
    }

    /// A folder given as `flag` that the run's output files go in (made if missing);
    /// the run leaves its other files alone.
    pub fn place(mut self, flag: &str, dir: impl AsRef<Path>) -> Outputs {
        self.folders.push((flag.to_string(), dir.as_ref().to_path_buf(), false));
        self
    }

    /// The output folder `dir` given as `flag` ([`Outputs::place`]) and the files `names`
    /// the run writes in it (a job's fixed set: eval.json, compare's four files, ...),
    /// each holding what `kinds` says, in the same order.
    pub fn files_in(self, flag: &str, dir: &Path, names: &[&str], kinds: &[Own]) -> Outputs {
        debug_assert_eq!(names.len(), kinds.len());
        names
            .iter()
            .zip(kinds)
            .fold(self.place(flag, dir), |g, (n, own)| g.file(flag, dir.join(n), *own))
    }

    /// The files with extension `ext` in the output folder `dir` (a search's
    /// `failures/*.ron`): each must be [`Own`] `own` (unless `force`); the run replaces
    /// them as a set at its end.
    pub fn folder_files(mut self, flag: &str, dir: &Path, ext: &str, own: Own) -> Outputs {
        self.folders.push((flag.to_string(), dir.to_path_buf(), true));
        if let Ok(entries) = std::fs::read_dir(dir) {
            let mut paths: Vec<PathBuf> = entries
                .flatten()
                .map(|e| e.path())
                .filter(|p| p.extension().is_some_and(|x| x == ext))
                .collect();
            paths.sort();
            for path in paths {
                self.folder_files.push(OutFile {
                    flag: flag.to_string(),
                    path,
                    own,
                    at_end: false,
                });
            }
        }
        self
    }

    /// Checks everything (module docs) before any work, without touching the disk.
    pub fn check(&self, force: bool) -> Result<(), Error> {
        for (flag, dir, owned) in &self.folders {
            if let Ok(meta) = std::fs::metadata(dir)
                && !meta.is_dir()
            {
                return Err(Error::flag(
                    format!("{flag} {}", dir.display()),
                    "exists and is not a folder; give a folder for the outputs (or move that file away)",
                ));
            }
            creatable_in(flag, dir, dir)?;
            let inside = std::fs::canonicalize(dir).ok().filter(|_| *owned);
            for (in_flag, input) in &self.inputs {
                if let (Some(d), Ok(i)) = (&inside, std::fs::canonicalize(input))
                    && i.starts_with(d)
                {
                    return Err(Error::flag(
                        format!("{flag} {}", dir.display()),
                        format!(
                            "holds the file given as {in_flag} ({}); the run replaces what is in this folder: copy that input elsewhere, or give {flag} another folder",
                            input.display()
                        ),
                    ));
                }
            }
        }
        for f in self.files.iter().chain(&self.folder_files) {
            if let Ok(meta) = std::fs::metadata(&f.path)
                && !meta.is_file()
            {
                return Err(Error::flag(
                    format!("{} {}", f.flag, f.path.display()),
                    "exists and is not a regular file (a folder, a device, a pipe); give a file path",
                ));
            }
            creatable_in(&f.flag, &f.path, f.path.parent().unwrap_or(Path::new("")))?;
            for (in_flag, input) in &self.inputs {
                if same_file(&f.path, input) {
                    return Err(Error::flag(
                        format!("{} {}", f.flag, f.path.display()),
                        format!(
                            "is the file given as {in_flag} ({}); writing it would destroy that input: give {} another path",
                            input.display(),
                            f.flag
                        ),
                    ));
                }
            }
            if !force
                && f.path.is_file()
                && let Some(held) = f.own.foreign(&f.path)
            {
                return Err(Error::flag(
                    format!("{} {}", f.flag, f.path.display()),
                    format!(
                        "exists and holds {}, not {}; give another path, or add --force (force=True) to replace it",
                        held.describe(),
                        f.own.what()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// [`Outputs::check`], then creates the missing folders and takes the lock (refusing
    /// a second writer). The outputs written at the end of the run stay until
    /// [`Guarded::clear_at_end`]: a check of the run that refuses after the guard
    /// (`--resume` of another run) leaves every file as it was.
    pub fn guard(&self, force: bool) -> Result<Guarded, Error> {
        self.check(force)?;
        let mut created = Vec::new();
        for (_, dir, _) in &self.folders {
            if !dir.exists() {
                created.push(dir.clone());
            }
        }
        let lock = match &self.lock {
            Some((flag, path)) => lock(flag, path)?,
            None => return Err(Error::flag("outputs", "a run with no output: nothing to guard")),
        };
        for (_, dir, _) in &self.folders {
            std::fs::create_dir_all(dir).map_err(|e| Error::io("create folder", dir, e))?;
        }
        // What a killed writer left: its committed set completed, its temporaries removed.
        let parents = self.files.iter().filter_map(|f| f.path.parent());
        for dir in self.folders.iter().map(|(_, d, _)| d.as_path()).chain(parents) {
            crate::files::recover(if dir.as_os_str().is_empty() {
                Path::new(".")
            } else {
                dir
            })?;
        }
        let at_end = self
            .files
            .iter()
            .chain(&self.folder_files)
            .filter(|f| f.at_end)
            .map(|f| f.path.clone())
            .collect();
        Ok(Guarded {
            _lock: lock,
            created,
            at_end,
        })
    }
}

impl Guarded {
    /// Removes the outputs the run writes at its end (the summary beside a results
    /// file), so that the set on disk never mixes
    /// this run's streamed file with an earlier run's summary. Called once every check
    /// of the run has passed, just before it writes.
    pub fn clear_at_end(&self) -> Result<(), Error> {
        for path in &self.at_end {
            match std::fs::remove_file(path) {
                Err(e) if e.kind() != std::io::ErrorKind::NotFound => return Err(Error::io("remove", path, e)),
                _ => {}
            }
        }
        Ok(())
    }
}

/// Checks the agent cache folder `dir` (given as `cache`) before any training, as an
/// output of the run: a folder, or a path where one can be made; not a file (exit 2, or
/// `ValueError` in Python).
pub fn check_cache(dir: &Path) -> Result<(), Error> {
    Outputs::new().place("cache", dir).check(false)
}

/// The same file: both exist and resolve (links followed) to one path.
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// The nearest folder of `dir` that exists (`dir`, or its parent, ...).
fn existing_ancestor(dir: &Path) -> PathBuf {
    let mut cur = if dir.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        dir.to_path_buf()
    };
    loop {
        if std::fs::symlink_metadata(&cur).is_ok() {
            return cur;
        }
        match cur.parent() {
            Some(p) if !p.as_os_str().is_empty() => cur = p.to_path_buf(),
            _ => return PathBuf::from("."),
        }
    }
}

/// The topmost folder of `dir` that does not exist yet (and that a run writing into
/// `dir` creates), if any: for a front to mention it.
pub fn missing_folder(dir: &Path) -> Option<PathBuf> {
    let base = existing_ancestor(dir);
    let mut cur = dir;
    let mut top = None;
    while cur != base && !cur.as_os_str().is_empty() {
        top = Some(cur.to_path_buf());
        cur = cur.parent()?;
    }
    top
}

/// Checks that files can be created in `dir` (made if missing): its nearest existing
/// folder must be a folder a file can be created in.
fn creatable_in(flag: &str, shown: &Path, dir: &Path) -> Result<(), Error> {
    let base = existing_ancestor(dir);
    let bad = |problem: String| Error::flag(format!("{flag} {}", shown.display()), problem);
    if !base.is_dir() {
        return Err(bad(format!(
            "{} is not a folder; give {flag} a path in a folder",
            base.display()
        )));
    }
    if let Err(e) = tempfile::tempfile_in(&base) {
        return Err(bad(format!(
            "cannot create files in {} ({e}); give {flag} a path in a writable folder",
            base.display()
        )));
    }
    Ok(())
}

/// Takes an advisory lock on `path` (created if missing, left in place), or refuses
/// while another run holds it. The lock is released when the file is closed.
fn lock(flag: &str, path: &Path) -> Result<std::fs::File, Error> {
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| Error::io("create folder", dir, e))?;
    }
    let file = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(path)
        .map_err(|e| Error::io("open the lock file", path, e))?;
    match file.try_lock() {
        Ok(()) => Ok(file),
        Err(std::fs::TryLockError::WouldBlock) => Err(Error::flag(
            flag,
            format!(
                "another run is writing these outputs now (it holds {}); wait for it to finish, or give {flag} another path",
                path.display()
            ),
        )),
        Err(std::fs::TryLockError::Error(e)) => Err(Error::io("lock", path, e)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_that_become_file_names_are_checked() {
        assert!(file_name("name", "jaywalk_space").is_ok());
        for bad in ["../../escaped", "/tmp/x/absname", "a\nb", "", "a\\b", &"x".repeat(300)] {
            let e = file_name("name", bad).expect_err(bad);
            assert!(e.starts_with("name "), "{e}");
        }
    }

    #[test]
    fn an_input_is_not_an_output_and_a_foreign_file_needs_force() {
        let d = tempfile::tempdir().unwrap();
        let map = d.path().join("m.ron");
        std::fs::write(&map, "Map()").unwrap();
        let same = Outputs::new().input("MAP", &map).file("--out", &map, Own::Results);
        assert!(same.check(true).unwrap_err().to_string().contains("would destroy"));
        let foreign = Outputs::new().file("--out", &map, Own::Results);
        assert!(foreign.check(false).unwrap_err().to_string().contains("--force"));
        assert!(foreign.check(true).is_ok());
        let inside = Outputs::new().input("--map", &map).folder("--out", d.path());
        assert!(inside.check(true).unwrap_err().to_string().contains("holds the file"));
    }

    #[test]
    fn a_second_writer_is_refused() {
        let d = tempfile::tempdir().unwrap();
        let out = Outputs::new().file("--out", d.path().join("r.jsonl"), Own::Results);
        let first = out.guard(false).unwrap();
        assert!(out.guard(false).unwrap_err().to_string().contains("another run"));
        drop(first);
        assert!(out.guard(false).is_ok());
    }
}
