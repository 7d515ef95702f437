//! Writing results: atomically (temporary file, then rename), so a killed run never
//! leaves a half-written file behind, and a failed write leaves no temporary file.

use std::collections::BTreeSet;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::error::Error;

/// The temporary files of writes under way, for [`remove_temporaries`].
static TEMPORARIES: Mutex<BTreeSet<PathBuf>> = Mutex::new(BTreeSet::new());

/// Removes the temporary files of the writes under way (the command line calls it on
/// SIGINT/SIGTERM, which end the process without dropping them); later writes fail.
pub fn remove_temporaries() {
    let set = TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner());
    for p in set.iter() {
        let _ = std::fs::remove_file(p);
    }
    // Keep the lock: a writer that would create a temporary now waits until the exit.
    std::mem::forget(set);
}

/// A temporary file registered in [`TEMPORARIES`] while it lives.
struct Registered(PathBuf);

impl Registered {
    fn new(path: &Path) -> Self {
        TEMPORARIES
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .insert(path.to_path_buf());
        Registered(path.to_path_buf())
    }
}

impl Drop for Registered {
    fn drop(&mut self) {
        TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner()).remove(&self.0);
    }
}

/// Writes `bytes` to `path` through a temporary file in the same folder
/// ([`tempfile::NamedTempFile`], removed if anything fails, a panic included) and a
/// rename, then syncs the folder so the rename itself is durable.
/// Refuses a `path` that exists and is not a regular file (a device such as `/dev/full`,
/// a folder, a pipe): the rename would replace it.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    if let Ok(meta) = std::fs::metadata(path)
        && !meta.is_file()
    {
        return Err(Error::NotRegularFile {
            path: path.to_path_buf(),
        });
    }
    let dir = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    std::fs::create_dir_all(dir).map_err(|e| Error::io("create folder", dir, e))?;
    let result = (|| -> std::io::Result<()> {
        let mut builder = tempfile::Builder::new();
        #[cfg(unix)]
        builder.permissions(new_file_permissions(path));
        let mut tmp = builder.tempfile_in(dir)?;
        let _registered = Registered::new(tmp.path());
        tmp.write_all(bytes)?;
        tmp.as_file().sync_all()?;
        let tmp = match STAGED.with_borrow_mut(|staged| match staged {
            Some(list) => {
                list.push((tmp, path.to_path_buf(), _registered));
                None
            }
            None => Some((tmp, _registered)),
        }) {
            Some(t) => t,
            None => return Ok(()), // renamed by `all_or_none`
        };
        tmp.0.persist(path).map_err(|e| e.error)?;
        // Make the rename durable (a folder can be opened and synced on Unix; elsewhere
        // this is best effort).
        if let Ok(d) = std::fs::File::open(dir) {
            let _ = d.sync_all();
        }
        Ok(())
    })();
    result.map_err(|e| Error::io("write", path, e))
}

/// The permissions the written file gets: those of the file it replaces, else what a new
/// file gets under the usual umask (`rw-r--r--`), not the temporary file's private
/// `rw-------`.
#[cfg(unix)]
fn new_file_permissions(path: &Path) -> std::fs::Permissions {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(path).map_or_else(|_| std::fs::Permissions::from_mode(0o644), |m| m.permissions())
}

/// A staged write: the temporary file, where it goes, its registration.
type Staged = (tempfile::NamedTempFile, PathBuf, Registered);

std::thread_local! {
    /// The writes [`all_or_none`] holds back on this thread until its closure succeeds.
    static STAGED: std::cell::RefCell<Option<Vec<Staged>>> = const { std::cell::RefCell::new(None) };
}

/// Runs `write` (which writes files with [`write_atomic`] on this thread) so that its
/// files appear together: each is written to a temporary file first, and only when
/// `write` succeeds are they all renamed into place; when it fails (a full disk) every
/// temporary is removed and the previous files stay as they were, never a mix of old and
/// new outputs.
pub fn all_or_none<T, E: From<Error>>(write: impl FnOnce() -> Result<T, E>) -> Result<T, E> {
    let outer = STAGED.with_borrow_mut(|s| s.replace(Vec::new()));
    let result = write();
    let staged = STAGED
        .with_borrow_mut(|s| std::mem::replace(s, outer))
        .unwrap_or_default();
    let value = result?;
    for (tmp, path, _registered) in staged {
        tmp.persist(&path).map_err(|e| Error::io("write", &path, e.error))?;
        let dir = match path.parent() {
            Some(p) if !p.as_os_str().is_empty() => p,
            _ => Path::new("."),
        };
        if let Ok(d) = std::fs::File::open(dir) {
            let _ = d.sync_all();
        }
    }
    Ok(value)
}

/// Serializes `value` as pretty JSON to `path`, atomically.
pub fn write_json<T: serde::Serialize>(path: &Path, value: &T) -> Result<(), Error> {
    let mut text = serde_json::to_string_pretty(value)?;
    text.push('\n');
    write_atomic(path, text.as_bytes())
}

/// A CSV table: a header and rows of already formatted cells.
#[derive(Debug, Default, Clone)]
pub struct Csv {
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Csv {
    /// A table with the given column names.
    pub fn new(header: &[&str]) -> Self {
        Self {
            header: header.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        }
    }

    /// Appends a row (cells containing commas, quotes or line breaks are quoted in the text).
    pub fn row(&mut self, cells: Vec<String>) {
        debug_assert_eq!(cells.len(), self.header.len());
        self.rows.push(cells);
    }

    /// The table as CSV text (the `csv` crate's writer: a cell is quoted when it holds
    /// a comma, a quote or a line break; lines end in `\n`).
    pub fn to_text(&self) -> String {
        let mut w = csv::WriterBuilder::new().flexible(true).from_writer(Vec::new());
        for line in std::iter::once(&self.header).chain(&self.rows) {
            w.write_record(line).expect("writing CSV to memory cannot fail");
        }
        let bytes = w.into_inner().expect("writing CSV to memory cannot fail");
        String::from_utf8(bytes).expect("CSV of UTF-8 cells is UTF-8")
    }

    /// Writes the table to `path`, atomically.
    pub fn write(&self, path: &Path) -> Result<(), Error> {
        write_atomic(path, self.to_text().as_bytes())
    }
}

/// Formats a float for tables and CSV with `digits` decimals.
pub fn num(x: f64, digits: usize) -> String {
    format!("{x:.digits$}")
}

#[cfg(test)]
mod tests {
    #[cfg(unix)]
    #[test]
    fn written_files_are_readable_like_new_files_and_keep_a_replaced_files_mode() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.json");
        super::write_atomic(&path, b"1").unwrap();
        let mode = |p: &std::path::Path| std::fs::metadata(p).unwrap().permissions().mode() & 0o777;
        assert_eq!(mode(&path), 0o644);
        std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o640)).unwrap();
        super::write_atomic(&path, b"2").unwrap();
        assert_eq!(mode(&path), 0o640);
        assert_eq!(std::fs::read(&path).unwrap(), b"2");
    }

    use super::*;

    #[test]
    fn atomic_write_replaces_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("sub").join("a.json");
        write_json(&path, &serde_json::json!({"x": 1})).unwrap();
        write_json(&path, &serde_json::json!({"x": 2})).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.contains("\"x\": 2"));
        let names: Vec<_> = std::fs::read_dir(path.parent().unwrap())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names.len(), 1, "{names:?}");
    }

    #[test]
    fn csv_quotes_cells_that_need_it() {
        let mut csv = Csv::new(&["a", "b"]);
        csv.row(vec!["1".into(), "x,y".into()]);
        csv.row(vec!["say \"hi\"".into(), "two\nlines".into()]);
        csv.row(vec!["".into(), "-0.5000".into()]);
        assert_eq!(
            csv.to_text(),
            "a,b\n1,\"x,y\"\n\"say \"\"hi\"\"\",\"two\nlines\"\n,-0.5000\n"
        );
    }

    #[test]
    fn all_or_none_leaves_the_previous_set_when_one_write_fails() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        std::fs::write(&a, "old").unwrap();
        let bad = dir.path().join("taken");
        std::fs::create_dir(&bad).unwrap();
        let result = all_or_none(|| -> Result<(), Error> {
            write_atomic(&a, b"new")?;
            write_atomic(&bad, b"x")
        });
        assert!(result.is_err());
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "old");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
        all_or_none(|| write_atomic(&a, b"new")).unwrap();
        assert_eq!(std::fs::read_to_string(&a).unwrap(), "new");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }

    #[test]
    fn a_refused_write_leaves_nothing_behind() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("out.csv");
        std::fs::create_dir(&target).unwrap();
        assert!(write_atomic(&target, b"x").is_err());
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left, ["out.csv"], "{left:?}");
    }
}
