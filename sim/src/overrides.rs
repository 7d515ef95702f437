//! Typed overrides of a loaded map: a front that takes map fields as values (Python's
//! `make_env("jaywalk", max_steps=60, lane_width=3.0)`) lays them over the map with
//! [`Map::with_overrides`], field by field, with no map text written or parsed: each
//! value is converted to its field's type (the conversions a map file's values get), and
//! the result is validated as a map file is, its errors naming the field.

use serde::de::DeserializeOwned;

use crate::load::{Diagnostic, MapError};
use crate::map::{Bins, Convert, Crosswalk, Episode, Junction, Light, Map, Reward, Road, Vehicle};

/// A value given for one map field.
#[derive(Debug, Clone, PartialEq)]
pub enum FieldValue {
    /// `true` or `false`.
    Bool(bool),
    /// A whole number.
    Int(i128),
    /// A number.
    Float(f64),
    /// RON as a map file writes the field's value (an enum such as `Random`, or a
    /// structure): the one kind of value that is parsed.
    Text(String),
    /// A list of values.
    List(Vec<FieldValue>),
}

impl FieldValue {
    /// The value as the RON crate's typed value (no text).
    fn to_ron(&self) -> Result<ron::Value, String> {
        Ok(match self {
            FieldValue::Bool(b) => ron::Value::Bool(*b),
            FieldValue::Int(i) => ron::Value::Number(match (i64::try_from(*i), u64::try_from(*i)) {
                (Ok(v), _) => ron::Number::from(v),
                (_, Ok(v)) => ron::Number::from(v),
                _ => ron::Number::from(*i),
            }),
            FieldValue::Float(x) => ron::Value::Number(ron::Number::from(*x)),
            FieldValue::Text(_) => return Err("RON text inside a list: give the whole list as RON text".into()),
            FieldValue::List(items) => ron::Value::Seq(items.iter().map(FieldValue::to_ron).collect::<Result<_, _>>()?),
        })
    }
}

/// `value` as a `T`, or the problem with the field `path` of the map `origin` (with the
/// line and column in RON text, when the value is text, checked as a map file's text is).
fn typed<T: DeserializeOwned>(origin: &str, path: &str, value: &FieldValue) -> Result<T, Diagnostic> {
    match value {
        FieldValue::Text(text) => {
            crate::load::check_text(origin, text)?;
            crate::load::ron_options()
                .from_str::<T>(text)
                .map_err(|e| crate::load::spanned(origin, path, &e))
        }
        other => other
            .to_ron()
            .and_then(|v| T::deserialize(v).map_err(|e| e.to_string()))
            .map_err(|message| Diagnostic::new(origin, path, message, None)),
    }
}

/// A value for the field `path` of the map `origin`.
struct At<'a> {
    origin: &'a str,
    path: &'a str,
    value: &'a FieldValue,
}

impl Convert for At<'_> {
    type Error = Diagnostic;

    fn to<T: DeserializeOwned>(&self) -> Result<T, Diagnostic> {
        typed(self.origin, self.path, self.value)
    }

    /// It takes `1` and not `1.5`.
    fn whole<T: DeserializeOwned>() -> bool {
        typed::<T>("", "", &FieldValue::Int(1)).is_ok() && typed::<T>("", "", &FieldValue::Float(1.5)).is_err()
    }
}

impl Map {
    /// The sections of [`Map::override_fields`] that a map may leave out. A bare field
    /// name that such a section shares with a section every map has (`lane_width`:
    /// `road` and `junction`) names the latter's field; the optional section's is written
    /// with its section (`junction__lane_width` in Python).
    pub const OPTIONAL_OVERRIDE_SECTIONS: &[&str] = &["junction"];

    /// The sections of a map that [`Map::with_overrides`] sets and their fields, each
    /// with whether it takes a whole number only.
    pub fn override_fields() -> Vec<(&'static str, Vec<(&'static str, bool)>)> {
        vec![
            ("road", Road::override_fields::<At>()),
            ("crosswalk", Crosswalk::override_fields::<At>()),
            ("light", Light::override_fields::<At>()),
            ("vehicle", Vehicle::override_fields::<At>()),
            ("bins", Bins::override_fields::<At>()),
            ("reward", Reward::override_fields::<At>()),
            ("episode", Episode::override_fields::<At>()),
            ("junction", Junction::override_fields::<At>()),
        ]
    }

    /// This map with `overrides` (section, field, value) laid over it, then validated as
    /// a map file is; `origin` names it in the errors, with the field (`episode.max_steps`)
    /// and, for RON text, the line and column in that text.
    pub fn with_overrides(&self, origin: &str, overrides: &[(String, String, FieldValue)]) -> Result<Map, MapError> {
        let mut map = self.clone();
        let mut problems = Vec::new();
        for (section, field, value) in overrides {
            let path = format!("{section}.{field}");
            let at = &At {
                origin,
                path: &path,
                value,
            };
            let set = match section.as_str() {
                "road" => map.road.set(field, at),
                "crosswalk" => map.crosswalk.set(field, at),
                "light" => map.light.set(field, at),
                "vehicle" => map.vehicle.set(field, at),
                "bins" => map.bins.set(field, at),
                "reward" => map.reward.set(field, at),
                "episode" => map.episode.set(field, at),
                // A junction field gives the map a junction, as `junction: (..)` in a file does.
                "junction" => map.junction.get_or_insert_default().set(field, at),
                _ => None,
            };
            match set {
                Some(Ok(())) => {}
                Some(Err(d)) => problems.push(d),
                None => {
                    let known: Vec<String> = Map::override_fields()
                        .into_iter()
                        .flat_map(|(s, fs)| fs.into_iter().map(move |(f, _)| format!("{s}.{f}")))
                        .collect();
                    problems.push(Diagnostic::new(
                        origin,
                        &path,
                        "no such field",
                        Some(format!("the fields: {}", known.join(", "))),
                    ));
                }
            }
        }
        if problems.is_empty() {
            problems = crate::validate::validate(&map)
                .into_iter()
                .map(|p| Diagnostic::new(origin, &p.path, p.message, p.hint))
                .collect();
        }
        if problems.is_empty() {
            Ok(map)
        } else {
            Err(MapError::new(problems))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn jaywalk() -> Map {
        crate::embedded::find("jaywalk").expect("embedded")
    }

    #[test]
    fn whole_number_fields_are_known_by_their_type() {
        let fields = Map::override_fields();
        let whole = |s: &str, f: &str| {
            fields
                .iter()
                .find(|(x, _)| *x == s)
                .and_then(|(_, fs)| fs.iter().find(|(x, _)| *x == f))
                .map(|(_, w)| *w)
        };
        assert_eq!(whole("episode", "max_steps"), Some(true));
        assert_eq!(whole("road", "lanes"), Some(true));
        assert_eq!(whole("road", "lane_width"), Some(false));
        assert_eq!(whole("light", "offset"), Some(false));
        assert_eq!(whole("road", "no_such_field"), None);
    }

    #[test]
    fn overrides_equal_a_map_file_over_the_same_base() {
        let set = |s: &str, f: &str, v: FieldValue| (s.to_string(), f.to_string(), v);
        let over = jaywalk()
            .with_overrides(
                "jaywalk (overrides)",
                &[
                    set("road", "lane_width", FieldValue::Float(3.2)),
                    set("episode", "max_steps", FieldValue::Int(30)),
                    set(
                        "bins",
                        "speed_edges",
                        FieldValue::List(vec![FieldValue::Float(0.5), FieldValue::Int(3), FieldValue::Float(6.0)]),
                    ),
                    set("light", "offset", FieldValue::Text("Random".into())),
                ],
            )
            .expect("valid overrides");
        let text = "(base: \"jaywalk\", name: \"jaywalk\", road: (lane_width: 3.2), episode: (max_steps: 30),\n\
                    bins: (speed_edges: [0.5, 3, 6.0]), light: (offset: Random))";
        let mut file = Map::from_str_named("over.ron", text, &|b| {
            crate::map_texts::source(b).map(|t| (format!("embedded:{b}"), t.to_string()))
        })
        .expect("valid file");
        file.description = over.description.clone();
        file.base = over.base.clone();
        file.expect_inherited_from = over.expect_inherited_from.clone();
        assert_eq!(over, file);
    }

    #[test]
    fn errors_name_the_map_and_the_field() {
        let one = |s: &str, f: &str, v: FieldValue| {
            jaywalk()
                .with_overrides("jaywalk (overrides)", &[(s.into(), f.into(), v)])
                .expect_err("a bad override")
                .to_string()
        };
        let typed = one("episode", "max_steps", FieldValue::Int(1 << 40));
        assert!(typed.starts_with("jaywalk (overrides): episode.max_steps: "), "{typed}");
        let text = one("light", "offset", FieldValue::Text("Fixed(".into()));
        assert!(text.starts_with("jaywalk (overrides):1:"), "{text}");
        assert!(text.contains("light.offset: "), "{text}");
        let invalid = one("road", "lane_width", FieldValue::Float(f64::NAN));
        assert!(
            invalid.contains("road.lane_width: must be a finite number"),
            "{invalid}"
        );
        let unknown = one("road", "nope", FieldValue::Int(1));
        assert!(unknown.contains("road.nope: no such field"), "{unknown}");
    }
}
