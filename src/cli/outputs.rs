//! Output paths checked before any work: an output that is one of the command's inputs
//! (the same file, after resolving links) is refused, naming both flags; an output file
//! that exists and is not a regular file (a device, a folder, a pipe), an output folder
//! that exists and is not a folder, and a place where nothing can be created (a
//! read-only folder, `/proc`) are refused before training or evaluating anything.
//! Folders that do not exist yet are created by the writers; the command says so.

use std::path::{Path, PathBuf};

use unforeseen_harness::error::Error;

/// The same file: both exist and resolve (links followed) to one path.
fn same_file(a: &Path, b: &Path) -> bool {
    match (std::fs::canonicalize(a), std::fs::canonicalize(b)) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}

/// Refuses the output `out` (given as `out_flag`) when it is one of `inputs` (flag and
/// path): writing it would destroy that input.
pub fn not_an_input(out_flag: &str, out: &Path, inputs: &[(&str, &Path)]) -> Result<(), Error> {
    for (flag, input) in inputs {
        if same_file(out, input) {
            return Err(Error::flag(
                format!("{out_flag} {}", out.display()),
                format!(
                    "is the file given as {flag} ({}); writing it would destroy that input: give {out_flag} another path",
                    input.display()
                ),
            ));
        }
    }
    Ok(())
}

/// The nearest folder of `path` that exists (`path`'s parent, or its parent, ...), and
/// the folders that would be created below it.
fn existing_ancestor(dir: &Path) -> (PathBuf, Vec<PathBuf>) {
    let mut missing = Vec::new();
    let mut cur = if dir.as_os_str().is_empty() {
        PathBuf::from(".")
    } else {
        dir.to_path_buf()
    };
    loop {
        if std::fs::symlink_metadata(&cur).is_ok() {
            return (cur, missing);
        }
        missing.push(cur.clone());
        match cur.parent() {
            Some(p) if !p.as_os_str().is_empty() => cur = p.to_path_buf(),
            _ => return (PathBuf::from("."), missing),
        }
    }
}

/// Checks that files can be created in `dir` (made if missing, as the writers will):
/// its nearest existing folder must be a folder we can create a file in.
fn creatable_in(flag: &str, shown: &Path, dir: &Path) -> Result<(), Error> {
    let (base, missing) = existing_ancestor(dir);
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
    if let Some(top) = missing.last() {
        errln!(
            "note: {flag}: creating the folder {} (it does not exist yet)",
            top.display()
        );
    }
    Ok(())
}

/// Checks an output file before any work: it is a regular file or does not exist yet,
/// and its folder can hold files.
pub fn file(flag: &str, path: &Path) -> Result<(), Error> {
    if let Ok(meta) = std::fs::metadata(path)
        && !meta.is_file()
    {
        return Err(Error::NotRegularFile {
            path: path.to_path_buf(),
        });
    }
    let parent = path.parent().unwrap_or(Path::new(""));
    creatable_in(flag, path, parent)
}

/// Checks an output folder before any work: a folder or not there yet, and one that
/// can hold files.
pub fn dir(flag: &str, dir: &Path) -> Result<(), Error> {
    if let Ok(meta) = std::fs::metadata(dir)
        && !meta.is_dir()
    {
        return Err(Error::flag(
            format!("{flag} {}", dir.display()),
            "exists and is not a folder; give a folder for the outputs",
        ));
    }
    creatable_in(flag, dir, dir)
}
