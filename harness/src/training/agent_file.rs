//! Agent files: a trained [`AgentBundle`] as RON, written atomically. Loading checks the
//! whole file before anything uses it (the agent crate checks every stored value, see
//! [`unforeseen_agent::persist`]; here, that it is an agent of this intersection: three
//! actions and the factors `d, v, L, p`), and every failure is an [`Error::AgentFile`]
//! naming the file, the field when there is one, and the fix.

use std::io::Read;
use std::path::Path;
use unforeseen_agent::error::PersistError;
use unforeseen_agent::persist::{AgentBundle, MAX_FILE_BYTES};
use unforeseen_sim::Action;

use crate::error::Error;
use crate::files::write_atomic;

/// Saves `bundle` to `path` (temporary file + rename).
pub fn save(path: &Path, bundle: &AgentBundle) -> Result<(), Error> {
    let text = bundle.to_ron_string();
    write_atomic(path, text.as_bytes())
}

fn retrain(path: &Path) -> String {
    format!("retrain it with `unforeseen train --out {}`", path.display())
}

fn bad(path: &Path, field: Option<String>, problem: impl Into<String>, fix: String) -> Error {
    Error::AgentFile {
        path: path.to_path_buf(),
        field,
        problem: problem.into(),
        fix,
    }
}

/// Loads and checks an agent file; every failure is an [`Error::AgentFile`].
pub fn load(path: &Path) -> Result<AgentBundle, Error> {
    let create = format!("create one with `unforeseen train --out {}`", path.display());
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        // Never suggest writing an agent over a device, a folder or a pipe.
        let give = "give the agent file `unforeseen train --out FILE` wrote (a regular file)".to_string();
        return Err(bad(path, None, "not a regular file", give));
    }
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(MAX_FILE_BYTES as u64 + 1).read_to_end(&mut bytes))
        .map_err(|e| bad(path, None, format!("cannot read the agent file ({e})"), create.clone()))?;
    if bytes.len() > MAX_FILE_BYTES {
        return Err(bad(
            path,
            None,
            format!("larger than any agent file (at most {} MiB)", MAX_FILE_BYTES >> 20),
            "pass the file `unforeseen train` wrote".into(),
        ));
    }
    let text = String::from_utf8(bytes).map_err(|_| bad(path, None, "not an agent file (not UTF-8 text)", create))?;
    parse(path, &text)
}

/// Parses and checks the text of an agent file; `path` names it in errors.
pub fn parse(path: &Path, text: &str) -> Result<AgentBundle, Error> {
    let bundle = AgentBundle::from_ron_str(text).map_err(|e| match e {
        PersistError::Invalid(f) => bad(
            path,
            Some(f.path),
            f.message,
            format!("the file is damaged or was edited: restore it, or {}", retrain(path)),
        ),
        other => match other_kind(path, text) {
            // Never suggest writing an agent over a file of another kind.
            Some(kind) => bad(
                path,
                None,
                format!("is {kind}, not an agent file"),
                "give the agent file `unforeseen train --out FILE` wrote (e.g. agent.ron)".into(),
            ),
            None => bad(path, None, clipped(&other.to_string()), retrain(path)),
        },
    })?;
    check_intersection(&bundle).map_err(|(field, problem)| bad(path, Some(field), problem, retrain(path)))?;
    Ok(bundle)
}

/// What the file at `path` (text `text`) is when it is not an agent file but a file of
/// another kind a user may give in its place: a map (it loads as one), or JSON (a results
/// file, a summary, a model).
fn other_kind(path: &Path, text: &str) -> Option<&'static str> {
    if text.trim_start().starts_with('{') {
        return Some("a JSON file (results, a summary or a model)");
    }
    (path.is_file() && unforeseen_sim::Map::load(path).is_ok()).then_some("a map file")
}

/// Longest parser message kept in an error (bytes): a parser may quote the text it met,
/// and a garbage file may be one token of hundreds of megabytes.
const MAX_MESSAGE_BYTES: usize = 300;

/// `message`, cut to [`MAX_MESSAGE_BYTES`] (at a character boundary) with `...` after.
fn clipped(message: &str) -> String {
    if message.len() <= MAX_MESSAGE_BYTES {
        return message.to_string();
    }
    let mut end = MAX_MESSAGE_BYTES;
    while !message.is_char_boundary(end) {
        end -= 1;
    }
    format!("{}...", &message[..end])
}

/// The bundle drives this program's car: the sim's actions, and the discretizer's
/// factors `d, v, L, p` with L and p binary.
fn check_intersection(bundle: &AgentBundle) -> Result<(), (String, String)> {
    let na = Action::ALL.len();
    let model = &bundle.world_model;
    if model.n_actions() != na {
        return Err((
            "world_model.n_actions".into(),
            format!("is {}; the car has {na} actions", model.n_actions()),
        ));
    }
    let factors: Vec<(&str, usize)> = model
        .structure()
        .factors()
        .iter()
        .map(|f| (f.name.as_str(), f.size))
        .collect();
    let ok = matches!(
        factors[..],
        [("d", d), ("v", v), ("L", 2), ("p", 2)]
            if d >= 2 && v >= 1
    );
    if !ok {
        return Err((
            "world_model.structure".into(),
            format!(
                "has factors {factors:?}; an agent of the intersection has d, v, L, p (in that order, L and p binary, d at least 2)"
            ),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_garbage_file_is_not_echoed_whole() {
        for garbage in [
            "\"".repeat(1 << 20),
            "x".repeat(1 << 20),
            format!("({}", "a: 1, ".repeat(1 << 18)),
        ] {
            let e = parse(Path::new("agent.ron"), &garbage).unwrap_err().to_string();
            assert!(e.len() < 1000, "{} bytes: {}", e.len(), &e[..200]);
        }
    }

    /// The map validator bounds the bins by the same number of joint states as the agent
    /// crate bounds its learners, so every valid map can be trained on.
    #[test]
    fn maps_and_agents_share_the_state_bound() {
        assert_eq!(unforeseen_sim::MAX_JOINT_STATES, unforeseen_agent::limits::MAX_STATES);
    }
}
