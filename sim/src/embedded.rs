//! The maps shipped in `maps/`, compiled into the binary. Bases named in an
//! embedded map (e.g. `base: "jaywalk.ron"`) resolve among these. [`find`] takes what a
//! user gives: a map file's path, or an embedded map's name.

use crate::load::{Diagnostic, MapError};
use crate::map::Map;
pub use crate::map_texts::{
    FAR_APPEARANCE, INTERSECTION, JAYWALK, JAYWALK_LATE, LATE_FAST, LONG_PAUSE, NEAR_KERB, SLOW_WALKER, STOP_MIDWAY,
    STUCK_GREEN, TWO_PEDESTRIANS, names, path, source,
};

/// Load an embedded map by name (`"jaywalk"` or `"jaywalk.ron"`).
pub fn load(name: &str) -> Result<Map, MapError> {
    let Some(src) = source(name) else {
        return Err(MapError::new(vec![Diagnostic {
            file: name.to_string(),
            position: None,
            path: String::new(),
            message: "no embedded map by this name".into(),
            hint: Some(format!("embedded maps: {}", names().join(", "))),
        }]));
    };
    let stem = name.strip_suffix(".ron").unwrap_or(name);
    Map::load_embedded(stem, src)
}

/// An embedded map as a base (`"jaywalk"` or `"jaywalk.ron"`): its origin
/// (`embedded:jaywalk`) and text, the resolver [`Map::from_str_named`] takes for a map
/// whose bases are embedded.
pub fn base(base: &str) -> Option<(String, String)> {
    let name = base.strip_suffix(".ron").unwrap_or(base);
    source(name).map(|t| (format!("{}{name}", crate::EMBEDDED_PREFIX), t.to_string()))
}

/// An embedded map as a base of the embedded map `including` (a name): the base as
/// `including`'s file in `maps/` finds it (`"training.ron"` beside
/// `junction/red_runner.ron` is `junction_training`; `"../intersection.ron"` is
/// `intersection`), else by name as [`base`]. Its origin and text.
pub fn base_in(including: &str, base: &str) -> Option<(String, String)> {
    crate::map_texts::base_of(including, base)
        .map(|(name, t)| (format!("{}{name}", crate::EMBEDDED_PREFIX), t.to_string()))
}

/// Why a map could not be had.
#[derive(Debug, thiserror::Error)]
pub enum LookupError {
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

/// Loads `arg` as a map file if such a path exists, else as an embedded map name (with
/// or without `.ron`).
pub fn find(arg: &str) -> Result<Map, LookupError> {
    let path = std::path::Path::new(arg);
    if path.exists() {
        return Ok(Map::load(path)?);
    }
    let name = arg.strip_suffix(".ron").unwrap_or(arg);
    if names().contains(&name) {
        return Ok(load(name)?);
    }
    Err(LookupError::NotFound {
        arg: arg.to_string(),
        names: names().join(", "),
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_embedded_map_loads() {
        for name in super::names() {
            let m = super::load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert_eq!(&m.name, name);
        }
    }
}
