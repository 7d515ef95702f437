//! Reading back the file a `--resume` continues: a search's candidates
//! ([`crate::runs::search`]) or an estimate's draws ([`crate::runs::estimate`]). Both are
//! JSON Lines whose first line is the run's identity, `{"KEY": {...}}`, followed by the
//! run's lines; the identity line may come again further down (shard files
//! concatenated), and every copy must be this run's. A last line without its newline
//! (cut by a kill or a full disk) is left out: what it held is made again.

use serde::Serialize;
use serde::de::DeserializeOwned;
use std::path::Path;

use crate::error::Error;

/// What to do about a file `--resume` refuses (the end of its errors).
pub const START_OVER: &str = "give another --out, or leave out --resume to start it over";

/// A line read back: its number in the file (1-based), its text (with its newline) and
/// its value.
#[derive(Debug, Clone)]
pub struct ReadLine<L> {
    /// Its number in the file, 1-based.
    pub line: usize,
    /// Its text, newline included.
    pub raw: String,
    /// Its value.
    pub parsed: L,
}

/// One phrase per field of `file` (the file's identity) that differs from `run` (this
/// run's): `seed: the file has 5, this run 6`.
pub fn differences<T: Serialize>(file: &T, run: &T) -> Vec<String> {
    let a = serde_json::to_value(file).unwrap_or_default();
    let b = serde_json::to_value(run).unwrap_or_default();
    let mut out = Vec::new();
    if let (Some(a), Some(b)) = (a.as_object(), b.as_object()) {
        for (k, va) in a {
            if *va != b[k] {
                out.push(format!("{k}: the file has {va}, this run {}", b[k]));
            }
        }
    }
    out
}

/// The complete lines of `path` after its identity lines, for `--resume` of the run
/// whose identity is `identity` (the `KEY` of `{"KEY": ...}` is `key`, e.g. `search`;
/// `line_kind` names a line for the errors, e.g. `a candidate line`). No file: no lines.
///
/// Refuses ([`Error::Results`] naming the file and the line, and saying what to do) a
/// line that is not text, an identity line of another run (saying what differs) or not
/// an identity at all, a file that does not start with an identity line, and a line
/// that is not a `line_kind`.
pub fn read_lines<I, L>(path: &Path, key: &str, identity: &I, line_kind: &str) -> Result<Vec<ReadLine<L>>, Error>
where
    I: Serialize + DeserializeOwned + PartialEq,
    L: DeserializeOwned,
{
    let bad = |problem: String| Error::Results {
        path: path.to_path_buf(),
        problem,
    };
    let bytes = match std::fs::read(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(Error::io("read", path, e)),
        Ok(b) => b,
    };
    let head = format!("{{\"{key}\":");
    let mut lines = Vec::new();
    let mut seen_identity = false;
    for (i, raw) in bytes.split_inclusive(|&b| b == b'\n').enumerate() {
        let line = i + 1;
        if !raw.ends_with(b"\n") {
            break; // cut by a kill: what it held is made again
        }
        let raw = std::str::from_utf8(raw).map_err(|_| bad(format!("line {line}: not text; {START_OVER}")))?;
        if raw.starts_with(&head) {
            let found = serde_json::from_str::<serde_json::Map<String, serde_json::Value>>(raw.trim_end())
                .map_err(|e| e.to_string())
                .and_then(|mut m| match (m.remove(key), m.is_empty()) {
                    (Some(v), true) => serde_json::from_value::<I>(v).map_err(|e| e.to_string()),
                    _ => Err(format!("fields other than {key:?}")),
                })
                .map_err(|e| {
                    bad(format!(
                        "line {line}: not {key} identity ({e}); {START_OVER}",
                        key = a(key)
                    ))
                })?;
            if found != *identity {
                return Err(bad(format!(
                    "--resume: line {line} was written by another {key} ({}); {START_OVER}",
                    differences(&found, identity).join("; ")
                )));
            }
            seen_identity = true;
            continue;
        }
        if !seen_identity {
            return Err(bad(format!(
                "--resume: the file does not start with {key} identity line; {START_OVER}",
                key = a(key)
            )));
        }
        let parsed: L = serde_json::from_str(raw.trim_end())
            .map_err(|e| bad(format!("line {line}: not {line_kind} ({e}); {START_OVER}")))?;
        lines.push(ReadLine {
            line,
            raw: raw.to_string(),
            parsed,
        });
    }
    Ok(lines)
}

/// `a search`, `an estimate`.
fn a(word: &str) -> String {
    let article = if word.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    };
    format!("{article} {word}")
}
