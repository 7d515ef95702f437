//! Writing results: atomically (temporary file, then rename), so a killed run never
//! leaves a half-written file behind, and a failed write leaves no temporary file.
//!
//! A set of files ([`all_or_none`]) is committed through a journal: every file is written
//! to a temporary part (`.unforeseen-part-ID-*`), then a journal listing the renames
//! (`.unforeseen-set-ID.json`, one in each folder of the set) is written and synced (the
//! commit), then the parts are renamed into place and the journal removed. A kill before
//! the commit leaves the earlier set and parts that [`recover`] removes; a kill between
//! two renames leaves a journal that [`recover`] completes, so the set becomes the new
//! one. A set may also remove files ([`remove_with_set`]: a file the earlier set had and
//! this one has not), listed in the journal and removed after the renames. The output
//! guard runs [`recover`] in every output folder before a run writes, and any reader
//! may. Every temporary is locked while its writer lives, so [`recover`] tells a live
//! writer's files from a dead one's.
//!
//! A file a run streams while it lasts ([`Streamed`], a search's candidates, an
//! estimate's draws) is not an output: it is a part under its own name that `--resume`
//! reads after a kill, committed (rewritten into the output) with the rest of the set at
//! the end, and removed with it.

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
    recover(dir)?;
    let result = (|| -> std::io::Result<()> {
        let prefix = STAGED.with_borrow(|s| s.as_ref().map(|set| format!("{PART_PREFIX}{}-", set.id)));
        let mut builder = tempfile::Builder::new();
        builder.prefix(prefix.as_deref().unwrap_or(TEMP_PREFIX));
        #[cfg(unix)]
        builder.permissions(new_file_permissions(path));
        let mut tmp = builder.tempfile_in(dir)?;
        let _registered = Registered::new(tmp.path());
        // Held while the writer lives: `recover` leaves a locked temporary alone.
        let _ = tmp.as_file().try_lock();
        tmp.write_all(bytes)?;
        tmp.as_file().sync_all()?;
        let tmp = match STAGED.with_borrow_mut(|staged| match staged {
            Some(set) => {
                set.writes.push((tmp, path.to_path_buf(), _registered));
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

/// A file a run streams line by line while it lasts (module docs): created with its
/// first lines through [`write_atomic`], then appended to, each append flushed, so a kill
/// leaves every finished line for `--resume`. It is a part, not an output: the run
/// commits its content with the rest of its set ([`all_or_none`]) and removes it there
/// ([`remove_with_set`]), so a failure partway (a full disk) leaves the earlier set as it
/// was.
#[derive(Debug)]
pub struct Streamed {
    file: std::fs::File,
    path: PathBuf,
    appends: usize,
}

impl Streamed {
    /// Creates (or replaces) `path` holding `head`, open for appending.
    pub fn create(path: &Path, head: &[u8]) -> Result<Streamed, Error> {
        write_atomic(path, head)?;
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .map_err(|e| Error::io("append to", path, e))?;
        Ok(Streamed {
            file,
            path: path.to_path_buf(),
            appends: 0,
        })
    }

    /// Appends `bytes` (whole lines) and flushes them.
    pub fn append(&mut self, bytes: &[u8]) -> Result<(), Error> {
        let n = self.appends;
        self.appends += 1;
        fault::before_append(n)
            .and_then(|()| self.file.write_all(bytes))
            .and_then(|()| self.file.flush())
            .map_err(|e| Error::io("write", &self.path, e))
    }

    /// Where it is.
    pub fn path(&self) -> &Path {
        &self.path
    }
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

/// Name prefix of a single file's temporary.
const TEMP_PREFIX: &str = ".unforeseen-tmp-";
/// Name prefix of a set's parts (`.unforeseen-part-ID-*`).
const PART_PREFIX: &str = ".unforeseen-part-";
/// Name prefix of a set's journal (`.unforeseen-set-ID.json`).
const JOURNAL_PREFIX: &str = ".unforeseen-set-";

/// The set [`all_or_none`] is writing on a thread: its id, and the writes and removals
/// it holds back until its closure succeeds.
struct Set {
    id: String,
    writes: Vec<Staged>,
    removes: Vec<PathBuf>,
}

std::thread_local! {
    /// The set [`all_or_none`] is writing on this thread.
    static STAGED: std::cell::RefCell<Option<Set>> = const { std::cell::RefCell::new(None) };
}

/// A set's journal: the renames that make it, part to file, then the files it removes
/// (absolute paths).
#[derive(serde::Serialize, serde::Deserialize)]
struct Journal {
    renames: Vec<(PathBuf, PathBuf)>,
    #[serde(default)]
    removes: Vec<PathBuf>,
}

/// A fresh id for a set (process, time and a counter: unique among the writers of a
/// folder, which the lock makes one at a time).
fn set_id() -> String {
    static COUNT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = COUNT.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let t = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_nanos());
    format!("{:x}{:x}{n:x}", std::process::id(), t % (1 << 40))
}

/// The folder a file is written in (`.` for a bare name).
fn folder_of(path: &Path) -> &Path {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    }
}

/// Runs `write` (which writes files with [`write_atomic`] on this thread) so that its
/// files appear together: each is written to a temporary part first, and only when
/// `write` succeeds are they committed (module docs: a journal, then the renames); when
/// it fails (a full disk) every part is removed and the previous files stay as they
/// were, never a mix of old and new outputs.
pub fn all_or_none<T, E: From<Error>>(write: impl FnOnce() -> Result<T, E>) -> Result<T, E> {
    let outer = STAGED.with_borrow_mut(|s| {
        s.replace(Set {
            id: set_id(),
            writes: Vec::new(),
            removes: Vec::new(),
        })
    });
    let result = write();
    let staged = STAGED.with_borrow_mut(|s| std::mem::replace(s, outer));
    let value = result?;
    if let Some(set) = staged {
        commit(set)?;
    }
    Ok(value)
}

/// Removes `path` as part of the set [`all_or_none`] is writing on this thread: after
/// its renames, in the same commit (a kill in between leaves the removal to
/// [`recover`]), and not at all when the set fails. Outside a set, removes it now. A
/// missing file is no error.
pub fn remove_with_set(path: &Path) -> Result<(), Error> {
    let path = std::path::absolute(path).map_err(|e| Error::io("resolve", path, e))?;
    let path = match STAGED.with_borrow_mut(|s| match s {
        Some(set) => {
            set.removes.push(path.clone());
            None
        }
        None => Some(path),
    }) {
        Some(p) => p,
        None => return Ok(()),
    };
    remove_if_there(&path)
}

/// Removes `path`; a missing file is no error.
fn remove_if_there(path: &Path) -> Result<(), Error> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(Error::io("remove", path, e)),
        _ => Ok(()),
    }
}

/// Commits the staged set: the journal in every folder of the set, then the renames and
/// removals, then the journals removed. Holds [`TEMPORARIES`] throughout, so that SIGINT
/// or SIGTERM ([`remove_temporaries`]) waits for the set instead of cutting it.
fn commit(set: Set) -> Result<(), Error> {
    let Set {
        id,
        writes: staged,
        removes,
    } = set;
    if staged.is_empty() && removes.is_empty() {
        return Ok(());
    }
    let absolute = |p: &Path| std::path::absolute(p).map_err(|e| Error::io("resolve", p, e));
    let mut renames = Vec::new();
    for (tmp, path, _) in &staged {
        renames.push((absolute(tmp.path())?, absolute(path)?));
    }
    let mut folders: Vec<PathBuf> = renames
        .iter()
        .map(|(_, p)| p)
        .chain(&removes)
        .map(|p| folder_of(p).to_path_buf())
        .collect();
    folders.sort();
    folders.dedup();
    let journal = Journal { renames, removes };
    let text = serde_json::to_vec(&journal)?;
    let registry = TEMPORARIES.lock().unwrap_or_else(|e| e.into_inner());
    let mut journals = Vec::new();
    for dir in &folders {
        let path = dir.join(format!("{JOURNAL_PREFIX}{id}.json"));
        let written = (|| -> std::io::Result<std::fs::File> {
            let mut f = std::fs::File::create(&path)?;
            let _ = f.try_lock();
            f.write_all(&text)?;
            f.sync_all()?;
            sync_folder(dir);
            Ok(f)
        })();
        match written {
            Ok(f) => journals.push((path, f)),
            Err(e) => {
                // Not committed: no rename was made; the earlier set stays.
                let _ = std::fs::remove_file(&path);
                for (p, _) in &journals {
                    let _ = std::fs::remove_file(p);
                }
                return Err(Error::io("write", &path, e));
            }
        }
    }
    // Committed: from here the parts belong to the journal (a failed rename leaves them
    // for `recover` to complete the set), so dropping them removes nothing. No early
    // return while `registry` is held: a registration's drop takes that lock too.
    let mut registered = Vec::new();
    let mut parts = Vec::new();
    for (tmp, path, reg) in staged {
        parts.push((tmp.into_temp_path(), path));
        registered.push(reg);
    }
    let renamed = parts
        .iter()
        .enumerate()
        .try_for_each(|(done, (part, path))| {
            fault::before_rename(done);
            std::fs::rename(part, path).map_err(|e| Error::io("write", path, e))
        })
        .and_then(|()| journal.removes.iter().try_for_each(|p| remove_if_there(p)));
    if renamed.is_ok() {
        for dir in &folders {
            sync_folder(dir);
        }
        for (p, _) in &journals {
            let _ = std::fs::remove_file(p);
        }
    }
    for (part, _) in parts {
        // Renamed (nothing to remove), or the journal's to complete.
        let _ = part.keep();
    }
    drop(journals);
    drop(registry);
    drop(registered);
    renamed
}

/// Makes the renames in `dir` durable (a folder can be opened and synced on Unix;
/// elsewhere this is best effort).
fn sync_folder(dir: &Path) {
    if let Ok(d) = std::fs::File::open(dir) {
        let _ = d.sync_all();
    }
}

/// Finishes or undoes what a killed writer left in `dir`: completes every set whose
/// journal is there (its remaining parts renamed into place, the set becoming the new
/// one), then removes the temporaries and uncommitted parts no live writer holds. The
/// output guard calls it in every output folder before a run writes.
pub fn recover(dir: &Path) -> Result<(), Error> {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return Ok(());
    };
    let mut names: Vec<String> = entries
        .flatten()
        .filter_map(|e| e.file_name().into_string().ok())
        .filter(|n| n.starts_with(".unforeseen-"))
        .collect();
    names.sort();
    // Only a writer that is gone released its lock.
    let unheld = |p: &Path| std::fs::File::open(p).is_ok_and(|f| f.try_lock().is_ok());
    for name in names.iter().filter(|n| n.starts_with(JOURNAL_PREFIX)) {
        let path = dir.join(name);
        if !unheld(&path) {
            continue;
        }
        let text = std::fs::read(&path).map_err(|e| Error::io("read", &path, e))?;
        if let Ok(journal) = serde_json::from_slice::<Journal>(&text) {
            let mut folders = Vec::new();
            for (part, file) in &journal.renames {
                if part.exists() {
                    std::fs::rename(part, file).map_err(|e| Error::io("write", file, e))?;
                }
                folders.push(folder_of(file).to_path_buf());
            }
            for gone in &journal.removes {
                remove_if_there(gone)?;
                folders.push(folder_of(gone).to_path_buf());
            }
            folders.sort();
            folders.dedup();
            for f in &folders {
                sync_folder(f);
                let _ = std::fs::remove_file(f.join(name));
            }
        }
        let _ = std::fs::remove_file(&path);
    }
    let committed = |n: &str| {
        n.strip_prefix(PART_PREFIX)
            .and_then(|rest| rest.split_once('-'))
            .is_some_and(|(id, _)| dir.join(format!("{JOURNAL_PREFIX}{id}.json")).exists())
    };
    for name in &names {
        let path = dir.join(name);
        let leftover = name.starts_with(TEMP_PREFIX) || (name.starts_with(PART_PREFIX) && !committed(name));
        if leftover && path.is_file() && unheld(&path) {
            let _ = std::fs::remove_file(&path);
        }
    }
    Ok(())
}

/// Faults for the tests of [`all_or_none`] and [`Streamed`], with the `fault-injection`
/// feature (which only the tests enable):
///
/// * a kill between two renames of a set: `UNFORESEEN_KILL_AT_RENAME=N` aborts the
///   process just before the set's rename `N` (0-based), as `kill -9` would: no
///   destructor runs, and the journal and the parts not yet renamed stay on disk;
/// * a full disk: `UNFORESEEN_FULL_DISK_AT_APPEND=N` fails the `N`-th append (0-based)
///   of each [`Streamed`] file with the error a full disk gives (`ENOSPC`).
mod fault {
    /// Fails append `n` when asked (see the module docs).
    #[cfg(feature = "fault-injection")]
    pub fn before_append(n: usize) -> std::io::Result<()> {
        let at = std::env::var("UNFORESEEN_FULL_DISK_AT_APPEND").ok();
        if at.and_then(|v| v.parse::<usize>().ok()) == Some(n) {
            return Err(std::io::Error::new(
                std::io::ErrorKind::StorageFull,
                "No space left on device (injected)",
            ));
        }
        Ok(())
    }

    /// Nothing, without the `fault-injection` feature.
    #[cfg(not(feature = "fault-injection"))]
    pub fn before_append(_n: usize) -> std::io::Result<()> {
        Ok(())
    }

    /// Aborts before rename `done` when asked (see the module docs).
    #[cfg(feature = "fault-injection")]
    pub fn before_rename(done: usize) {
        let at = std::env::var("UNFORESEEN_KILL_AT_RENAME").ok();
        if at.and_then(|v| v.parse::<usize>().ok()) == Some(done) {
            std::process::abort();
        }
    }

    /// Nothing, without the `fault-injection` feature.
    #[cfg(not(feature = "fault-injection"))]
    pub fn before_rename(_done: usize) {}
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
    fn a_set_removes_its_files_only_when_it_commits() {
        let dir = tempfile::tempdir().unwrap();
        let (a, gone) = (dir.path().join("a.csv"), dir.path().join("gone.ron"));
        std::fs::write(&gone, "old").unwrap();
        let failed = all_or_none(|| -> Result<(), Error> {
            write_atomic(&a, b"new")?;
            remove_with_set(&gone)?;
            Err(Error::Interrupted)
        });
        assert!(failed.is_err());
        assert!(gone.is_file() && !a.exists());
        all_or_none(|| -> Result<(), Error> {
            write_atomic(&a, b"new")?;
            remove_with_set(&gone)
        })
        .unwrap();
        assert!(!gone.exists() && a.is_file());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
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
