//! Finding a map: a file path, or the name of a map embedded in the binary
//! (`intersection`, `jaywalk`, ...), so the default run needs no files at all.

use std::path::Path;
use unforeseen_sim::{Map, MapError, embedded};

/// Why a map could not be had.
#[derive(Debug, thiserror::Error)]
pub enum MapLookupError {
    /// Neither a readable file nor an embedded map of that name.
    #[error(
        "{arg}: no such map file, and no embedded map of that name (embedded maps: {names}); pass a path to a .ron map file"
    )]
    NotFound {
        /// What the user passed.
        arg: String,
        /// The embedded names, comma separated.
        names: String,
    },
    /// The file or embedded map did not validate (its diagnostics, printed once).
    #[error(transparent)]
    Invalid(#[from] MapError),
}

/// Loads `arg` as a map file if such a path exists, else as an embedded map name
/// (with or without `.ron`).
pub fn load(arg: &str) -> Result<Map, MapLookupError> {
    let path = Path::new(arg);
    if path.exists() {
        return Ok(Map::load(path)?);
    }
    let name = arg.strip_suffix(".ron").unwrap_or(arg);
    if embedded::names().contains(&name) {
        return Ok(embedded::load(name)?);
    }
    Err(MapLookupError::NotFound {
        arg: arg.to_string(),
        names: embedded::names().join(", "),
    })
}
