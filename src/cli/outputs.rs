//! Output paths checked before any work, by the harness's output guard
//! ([`unforeseen_harness::runs::outputs`]), for the commands whose output is one file
//! (an agent file, a model, a figure): replaced when it holds what the command writes,
//! else refused unless `--force`; the folders the writers will create are mentioned on
//! stderr.

use std::path::Path;

use unforeseen_harness::error::Error;
use unforeseen_harness::runs::outputs::{Outputs, Own, missing_folder};

/// Says on stderr which folder a run writing into `dir` creates, if any.
pub fn note_created(flag: &str, dir: &Path) {
    creating(flag, missing_folder(dir));
}

/// The folder a run writing into `dir` would create, found before the run's output guard
/// creates it; [`creating`] says so once the guard has passed.
pub fn to_create(dir: &Path) -> Option<std::path::PathBuf> {
    missing_folder(dir)
}

/// Says on stderr that the run creates the folder `top` for `flag` (from [`to_create`]).
pub fn creating(flag: &str, top: Option<std::path::PathBuf>) {
    if let Some(top) = top {
        errln!(
            "note: {flag}: creating the folder {} (it does not exist yet)",
            top.display()
        );
    }
}

/// Checks the output file `out` (given as `out_flag`) before any work: a regular file or
/// not there yet, in a folder that can hold files, none of the inputs `guard` holds, and
/// (unless `force`) empty or holding what the command writes (`own`).
pub fn file(out_flag: &str, out: &Path, own: Own, force: bool, guard: Outputs) -> Result<(), Error> {
    let guard = guard.file(out_flag, out, own);
    guard.check(force)?;
    note_created(out_flag, out.parent().unwrap_or(Path::new("")));
    Ok(())
}

/// `n` lines, in words: `1 line`, `3 lines`.
pub fn lines(n: usize) -> String {
    if n == 1 { "1 line".into() } else { format!("{n} lines") }
}

/// How many lines the regular file `path` holds (None: no such file, or not a regular
/// file): what a notice of its replacement says.
pub fn line_count(path: &Path) -> Option<usize> {
    use std::io::BufRead;
    let file = std::fs::File::open(path)
        .ok()
        .filter(|f| f.metadata().is_ok_and(|m| m.is_file()))?;
    Some(std::io::BufReader::new(file).split(b'\n').count())
}
