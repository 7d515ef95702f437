//! The maps shipped in `maps/`, compiled into the binary. Bases named in an
//! embedded map (e.g. `base: "jaywalk.ron"`) resolve among these.

use crate::load::{Diagnostic, MapError};
use crate::map::Map;
pub use crate::map_texts::{
    FAR_APPEARANCE, INTERSECTION, JAYWALK, JAYWALK_LATE, LATE_FAST, LONG_PAUSE, NEAR_KERB, SLOW_WALKER, STOP_MIDWAY,
    STUCK_GREEN, TWO_PEDESTRIANS, names, source,
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
    Map::from_str_named(&format!("{stem}.ron"), src, &|base| {
        source(base).map(|s| {
            let b = base.strip_suffix(".ron").unwrap_or(base);
            (format!("{b}.ron"), s.to_string())
        })
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
