//! Agent files: a trained [`AgentBundle`] as RON, written atomically; a missing,
//! corrupt or incompatible file is a clear error naming the file and the fix.

use std::path::Path;
use unforeseen_agent::persist::AgentBundle;

use crate::cli::BadInput;
use crate::report::write_atomic;

/// Saves `bundle` to `path` (temporary file + rename).
pub fn save(path: &Path, bundle: &AgentBundle) -> anyhow::Result<()> {
    let text = bundle.to_ron_string();
    write_atomic(path, text.as_bytes())
}

/// Loads an agent file; every failure is a [`BadInput`] naming the file.
pub fn load(path: &Path) -> anyhow::Result<AgentBundle> {
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        return Err(BadInput(format!(
            "{}: not a regular file; an agent file is written by `unforeseen train --out FILE`",
            path.display()
        ))
        .into());
    }
    let text = std::fs::read(path).map_err(|e| {
        BadInput(format!(
            "{}: cannot read the agent file ({e}); create one with `unforeseen train --out {}`",
            path.display(),
            path.display()
        ))
    })?;
    let text = String::from_utf8(text).map_err(|_| {
        BadInput(format!(
            "{}: not an agent file (not UTF-8 text); create one with `unforeseen train`",
            path.display()
        ))
    })?;
    AgentBundle::from_ron_str(&text).map_err(|e| {
        BadInput(format!(
            "{}: {e}; retrain with `unforeseen train --out {}`",
            path.display(),
            path.display()
        ))
        .into()
    })
}

/// Checks that an agent trained on `agent_states` states can drive a map whose bins
/// give `map_states` states.
pub fn check_compatible(bundle: &AgentBundle, map_name: &str, map_states: usize) -> anyhow::Result<()> {
    let agent_states = bundle.q_learning.n_states();
    if agent_states != map_states {
        return Err(BadInput(format!(
            "the agent was trained on {agent_states} discrete states but map '{map_name}' has {map_states}; \
             its bins differ from the training map's: train an agent on a map with the same bins"
        ))
        .into());
    }
    Ok(())
}
