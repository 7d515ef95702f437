//! Reading map files: syntax, unknown fields, types, base maps, then semantic
//! validation. Bad input never panics: every problem becomes a [`Diagnostic`]
//! naming the file and either `line:column` or the field path, and a
//! [`MapError`] carries all of them.

use std::cell::Cell;
use std::fmt;
use std::path::Path;

use serde::Deserialize;
use serde::de::{self, Deserializer, Visitor};

use crate::map::{
    BinsPatch, CrosswalkPatch, EpisodePatch, Expectation, JunctionPatch, LightPatch, Map, MapPatch, Outage, Pause,
    Phase, RewardPatch, RoadPatch, SpawnRule, SurfacePatch, TrafficRule, VehiclePatch,
};
use crate::{locate, validate};

/// Largest map file accepted, bytes.
pub const MAX_FILE_BYTES: usize = 1 << 20;
/// Deepest nesting of brackets accepted.
pub const MAX_NESTING: usize = 32;
/// Longest chain of base maps accepted.
pub const MAX_BASE_DEPTH: usize = 16;

/// One problem found in a map file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Diagnostic {
    /// The file (or embedded map name) the problem is in.
    pub file: String,
    /// 1-based line and column: of a syntax or type error, or of the field a semantic
    /// problem is about when the file writes it (not when it is inherited or a default).
    pub position: Option<(usize, usize)>,
    /// Field path such as `road.lane_width` or `pedestrians[0].speed`; empty when not about a field.
    pub path: String,
    /// What is wrong.
    pub message: String,
    /// How to fix it, when there is something useful to say.
    pub hint: Option<String>,
}

impl Diagnostic {
    pub(crate) fn new(file: &str, path: &str, message: impl Into<String>, hint: Option<String>) -> Self {
        Diagnostic {
            file: file.to_string(),
            position: None,
            path: path.to_string(),
            message: message.into(),
            hint,
        }
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.position {
            Some((line, col)) => write!(f, "{}:{line}:{col}: ", self.file)?,
            None => write!(f, "{}: ", self.file)?,
        }
        if !self.path.is_empty() {
            write!(f, "{}: ", self.path)?;
        }
        f.write_str(&self.message)?;
        if let Some(h) = &self.hint {
            write!(f, " (hint: {h})")?;
        }
        Ok(())
    }
}

/// Every problem found while loading one map. `Display` prints one diagnostic per line.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MapError {
    diagnostics: Vec<Diagnostic>,
}

impl MapError {
    /// An error of the given diagnostics (at least one), e.g. for checks a harness makes
    /// on a loaded map (the names in its expectations).
    pub fn new(diagnostics: Vec<Diagnostic>) -> Self {
        debug_assert!(!diagnostics.is_empty());
        MapError { diagnostics }
    }

    fn one(d: Diagnostic) -> Self {
        MapError::new(vec![d])
    }

    /// All diagnostics, in the order found.
    pub fn diagnostics(&self) -> &[Diagnostic] {
        &self.diagnostics
    }
}

impl fmt::Display for MapError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, d) in self.diagnostics.iter().enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{d}")?;
        }
        Ok(())
    }
}

impl std::error::Error for MapError {}

/// How an embedded map's origin starts, in diagnostics and in results' sources
/// (`embedded:jaywalk`).
pub const EMBEDDED_PREFIX: &str = "embedded:";

/// A base map found by a resolver.
pub(crate) struct Resolved {
    /// Name used in diagnostics.
    pub origin: String,
    /// Identity used to detect cycles (e.g. a canonical path).
    pub key: String,
    /// The text, or what went wrong reading it.
    pub text: Result<String, Diagnostic>,
}

/// Finds base maps: `(including map's origin, base as written) -> Resolved`.
pub(crate) type Resolver<'a> = dyn Fn(&str, &str) -> Option<Resolved> + 'a;

impl Map {
    /// Load a map file. A `base` is resolved against the including map's folder (as
    /// written, then with `.ron` added), then among the embedded maps by name (`"jaywalk"`
    /// or `"jaywalk.ron"`); an embedded map's own bases are embedded maps.
    pub fn load(path: &Path) -> Result<Map, MapError> {
        let origin = path.display().to_string();
        let text = read_text(path, &origin).map_err(MapError::one)?;
        let key = canonical_key(path);
        let resolve = |including: &str, base: &str| -> Option<Resolved> {
            if !including.starts_with(EMBEDDED_PREFIX) {
                let dir = Path::new(including).parent().map(Path::to_path_buf).unwrap_or_default();
                let candidates = [dir.join(base), dir.join(format!("{base}.ron"))];
                // A regular file, or else a `.ron` path that exists but is not one (a
                // folder, a pipe, a device): read_text then says "not a regular file",
                // as for the same path given directly, rather than "not found".
                let found = (candidates.iter().find(|p| p.is_file())).or_else(|| {
                    candidates
                        .iter()
                        .find(|p| p.extension().is_some_and(|x| x == "ron") && std::fs::metadata(p).is_ok())
                });
                if let Some(p) = found {
                    let origin = p.display().to_string();
                    return Some(Resolved {
                        text: read_text(p, &origin),
                        origin,
                        key: canonical_key(p),
                    });
                }
            }
            embedded_base(including, base)
        };
        load_top(&origin, &key, &text, &resolve)
    }

    /// Load the embedded map `name` (its text `src`): its bases are embedded maps, found
    /// as its file in `maps/` would find them ([`crate::map_texts::base_of`]).
    /// Its origin in diagnostics is `name.ron`.
    pub(crate) fn load_embedded(name: &str, src: &str) -> Result<Map, MapError> {
        let origin = format!("{name}.ron");
        let top = format!("{EMBEDDED_PREFIX}{name}");
        let resolve =
            |including: &str, base: &str| embedded_base(if including == origin { &top } else { including }, base);
        load_top(&origin, &origin, src, &resolve)
    }

    /// Parse map text. `origin` names it in diagnostics (and gives the default
    /// name); `bases` maps a base as written (e.g. `"intersection.ron"`) to
    /// `(origin, text)`, or `None` if there is no such map; the bases of an embedded base
    /// (origin `embedded:...`) are embedded maps, as [`Map::load`] finds them.
    pub fn from_str_named(
        origin: &str,
        src: &str,
        bases: &dyn Fn(&str) -> Option<(String, String)>,
    ) -> Result<Map, MapError> {
        let resolve = |including: &str, base: &str| -> Option<Resolved> {
            if including.starts_with(EMBEDDED_PREFIX) {
                return embedded_base(including, base);
            }
            bases(base).map(|(origin, text)| Resolved {
                key: origin.clone(),
                text: check_text(&origin, &text).map(|()| text),
                origin,
            })
        };
        load_top(origin, origin, src, &resolve)
    }
}

/// The embedded map a base names: relative to the including map's file in `maps/` when
/// that map is embedded, else by name.
fn embedded_base(including: &str, base: &str) -> Option<Resolved> {
    let including = including.strip_prefix(EMBEDDED_PREFIX).unwrap_or("");
    crate::map_texts::base_of(including, base).map(|(name, text)| {
        let origin = format!("{EMBEDDED_PREFIX}{name}");
        Resolved {
            text: check_text(&origin, text).map(|()| text.to_string()),
            key: origin.clone(),
            origin,
        }
    })
}

fn canonical_key(p: &Path) -> String {
    std::fs::canonicalize(p)
        .unwrap_or_else(|_| p.to_path_buf())
        .display()
        .to_string()
}

/// Read a file as text, refusing huge and binary files without reading them whole.
fn read_text(path: &Path, origin: &str) -> Result<String, Diagnostic> {
    use std::io::Read;
    // A named pipe or a device would block or never end: only regular files are maps.
    if std::fs::metadata(path).is_ok_and(|m| !m.is_file()) {
        return Err(Diagnostic::new(
            origin,
            "",
            "not a regular file".to_string(),
            Some("a map is a RON text file".into()),
        ));
    }
    let file = std::fs::File::open(path)
        .map_err(|e| Diagnostic::new(origin, "", format!("cannot read the file: {e}"), None))?;
    let mut bytes = Vec::new();
    file.take(MAX_FILE_BYTES as u64 + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| Diagnostic::new(origin, "", format!("cannot read the file: {e}"), None))?;
    if bytes.len() > MAX_FILE_BYTES {
        return Err(too_large(origin));
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        Diagnostic::new(
            origin,
            "",
            format!(
                "not a text file: invalid UTF-8 at byte {}",
                e.utf8_error().valid_up_to()
            ),
            Some("a map is a RON text file".into()),
        )
    })?;
    check_text(origin, &text)?;
    Ok(text)
}

fn too_large(origin: &str) -> Diagnostic {
    Diagnostic::new(
        origin,
        "",
        format!("file is too large (more than {MAX_FILE_BYTES} bytes)"),
        Some("a map is a few kilobytes of RON; is this the right file?".into()),
    )
}

/// Checks that need no parsing: size, emptiness, binary content, nesting depth.
pub(crate) fn check_text(origin: &str, text: &str) -> Result<(), Diagnostic> {
    if text.len() > MAX_FILE_BYTES {
        return Err(too_large(origin));
    }
    if let Some(i) = text
        .bytes()
        .position(|b| b == 0 || (b < 0x20 && !matches!(b, b'\n' | b'\r' | b'\t')))
    {
        return Err(Diagnostic::new(
            origin,
            "",
            format!("not a text file: control byte at offset {i}"),
            Some("a map is a RON text file".into()),
        ));
    }
    if strip_comments(text).trim().is_empty() {
        return Err(Diagnostic::new(
            origin,
            "",
            "the file is empty",
            Some("a map is at least `Map()` (all defaults) or `Map(base: \"intersection.ron\")`".into()),
        ));
    }
    if let Some((line, col)) = too_deep(text) {
        return Err(Diagnostic {
            position: Some((line, col)),
            ..Diagnostic::new(
                origin,
                "",
                format!("nested more than {MAX_NESTING} levels deep"),
                Some("maps need only a few levels of brackets".into()),
            )
        });
    }
    Ok(())
}

/// Remove `//` and `/* */` comments (approximately: enough to tell whether anything is left).
fn strip_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars().peekable();
    let mut in_str = false;
    while let Some(c) = chars.next() {
        if in_str {
            out.push(c);
            if c == '\\' {
                if let Some(n) = chars.next() {
                    out.push(n);
                }
            } else if c == '"' {
                in_str = false;
            }
            continue;
        }
        match (c, chars.peek()) {
            ('"', _) => {
                in_str = true;
                out.push(c);
            }
            ('/', Some('/')) => {
                for n in chars.by_ref() {
                    if n == '\n' {
                        out.push('\n');
                        break;
                    }
                }
            }
            ('/', Some('*')) => {
                chars.next();
                let mut prev = ' ';
                for n in chars.by_ref() {
                    if prev == '*' && n == '/' {
                        break;
                    }
                    prev = n;
                }
                out.push(' ');
            }
            _ => out.push(c),
        }
    }
    out
}

/// Position of the first bracket nested deeper than [`MAX_NESTING`] (outside strings).
fn too_deep(text: &str) -> Option<(usize, usize)> {
    let (mut depth, mut line, mut col) = (0usize, 1usize, 0usize);
    let mut in_str = false;
    let mut escaped = false;
    for c in text.chars() {
        col += 1;
        if c == '\n' {
            line += 1;
            col = 0;
        }
        if in_str {
            if escaped {
                escaped = false;
            } else if c == '\\' {
                escaped = true;
            } else if c == '"' {
                in_str = false;
            }
            continue;
        }
        match c {
            '"' => in_str = true,
            '(' | '[' | '{' => {
                depth += 1;
                if depth > MAX_NESTING {
                    return Some((line, col));
                }
            }
            ')' | ']' | '}' => depth = depth.saturating_sub(1),
            _ => {}
        }
    }
    None
}

pub(crate) fn ron_options() -> ron::Options {
    // Implicit `Some`: `base: "intersection.ron"` and `min_success: 0.9` need no `Some(..)`.
    ron::Options::default()
        .with_recursion_limit(MAX_NESTING * 2)
        .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME)
}

pub(crate) fn spanned(origin: &str, path: &str, e: &ron::error::SpannedError) -> Diagnostic {
    let hint = match &e.code {
        ron::Error::Eof => Some("the file ends early: is it truncated or missing a `)`?".into()),
        ron::Error::ExceededRecursionLimit => Some("maps need only a few levels of brackets".into()),
        _ => None,
    };
    Diagnostic {
        position: Some((e.span.start.line, e.span.start.col)),
        ..Diagnostic::new(origin, path, e.code.to_string(), hint)
    }
}

fn load_top(origin: &str, key: &str, src: &str, resolve: &Resolver) -> Result<Map, MapError> {
    let mut chain = vec![key.to_string()];
    let map = build(origin, src, resolve, &mut chain)?;
    let problems = validate::validate(&map);
    if problems.is_empty() {
        Ok(map)
    } else {
        Err(MapError::new(
            problems
                .into_iter()
                .map(|p| Diagnostic {
                    position: locate::field(src, &p.path),
                    ..Diagnostic::new(origin, &p.path, p.message, p.hint)
                })
                .collect(),
        ))
    }
}

/// Default map name: the file name without folders and `.ron`.
fn stem(origin: &str) -> String {
    let name = origin.rsplit(['/', '\\']).next().unwrap_or(origin);
    name.strip_suffix(".ron").unwrap_or(name).to_string()
}

fn build(origin: &str, src: &str, resolve: &Resolver, chain: &mut Vec<String>) -> Result<Map, MapError> {
    check_text(origin, src).map_err(MapError::one)?;
    let patch = parse_patch(origin, src)?;
    let base = match &patch.base {
        None => Map::default(),
        Some(base_name) => {
            let including = chain.last().cloned().unwrap_or_default();
            let Some(found) = resolve(origin, base_name) else {
                return Err(MapError::one(Diagnostic::new(
                    origin,
                    "base",
                    format!("base map {base_name:?} not found"),
                    Some(format!(
                        "a base is a file name relative to this map's folder, e.g. \"intersection.ron\", or an embedded map ({})",
                        crate::map_texts::names().join(", ")
                    )),
                )));
            };
            if found.key == including {
                return Err(MapError::one(Diagnostic::new(
                    origin,
                    "base",
                    format!("the map names itself ({base_name:?}) as its base"),
                    Some("a base must be a different map".into()),
                )));
            }
            if chain.contains(&found.key) {
                let mut names: Vec<String> = chain.iter().map(|k| stem(k)).collect();
                names.push(stem(&found.key));
                return Err(MapError::one(Diagnostic::new(
                    origin,
                    "base",
                    format!("base maps include each other: {}", names.join(" -> ")),
                    Some("remove the cycle of `base` fields".into()),
                )));
            }
            // `chain` holds the top map and the bases read so far: this base would be
            // the chain.len()-th; MAX_BASE_DEPTH of them are accepted.
            if chain.len() > MAX_BASE_DEPTH {
                return Err(MapError::one(Diagnostic::new(
                    origin,
                    "base",
                    format!("more than {MAX_BASE_DEPTH} levels of base maps"),
                    None,
                )));
            }
            let text = found.text.map_err(MapError::one)?;
            chain.push(found.key.clone());
            let base = build(&found.origin, &text, resolve, chain);
            chain.pop();
            base?
        }
    };
    Ok(patch.apply(base, &stem(origin)))
}

/// Typed parse; only when it fails, the unknown-field scan over the untyped value, so
/// that every unknown field is reported, not only the first one serde stops at (a valid
/// file is parsed once).
fn parse_patch(origin: &str, src: &str) -> Result<MapPatch, MapError> {
    let opts = ron_options();
    let typed = || -> Result<MapPatch, Diagnostic> {
        let mut de = ron::Deserializer::from_str_with_options(src, &opts).map_err(|e| spanned(origin, "", &e))?;
        let patch: MapPatch = serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let path = e.path().to_string();
            let path = if path == "." { String::new() } else { path };
            let err = de.span_error(e.into_inner());
            spanned(origin, &path, &err)
        })?;
        de.end().map_err(|e| spanned(origin, "", &de.span_error(e)))?;
        Ok(patch)
    };
    typed().map_err(|first| {
        let mut unknown = Vec::new();
        if let Ok(value) = opts.from_str::<ron::Value>(src) {
            if is_agent_file(&value) {
                return MapError::one(Diagnostic::new(
                    origin,
                    "",
                    "is an agent file, not a map (it has the `format_version` and `world_model` that `unforeseen train` writes)",
                    Some(
                        "give a map file (e.g. maps/jaywalk.ron) or an embedded map's name; an agent file goes after --agent"
                            .into(),
                    ),
                ));
            }
            walk(&value, Kind::Map, "", origin, &mut unknown);
        }
        if unknown.is_empty() {
            MapError::one(first)
        } else {
            MapError::new(unknown)
        }
    })
}

/// Whether `value`, a file's top level, is an agent file (its `format_version` and
/// `world_model`) rather than a map: said as such, not as a map's unknown fields.
fn is_agent_file(value: &ron::Value) -> bool {
    let ron::Value::Map(fields) = value else {
        return false;
    };
    ["format_version", "world_model"]
        .iter()
        .all(|k| fields.get(&ron::Value::String((*k).to_string())).is_some())
}

// ---------------------------------------------------------------------------
// Unknown-field scan over the untyped value, so that every unknown field is
// reported, not only the first one serde stops at. Field lists come from the
// serde derives themselves (see `field_names`), so they cannot drift.

#[derive(Clone, Copy)]
enum Kind {
    Map,
    Road,
    Surface,
    Crosswalk,
    Light,
    Phase,
    Vehicle,
    Rule,
    Pause,
    Bins,
    Reward,
    Episode,
    Expect,
    Junction,
    Outage,
    Traffic,
    Leaf,
}

fn fields_of(kind: Kind) -> &'static [&'static str] {
    match kind {
        Kind::Map => field_names::<MapPatch>(),
        Kind::Road => field_names::<RoadPatch>(),
        Kind::Surface => field_names::<SurfacePatch>(),
        Kind::Crosswalk => field_names::<CrosswalkPatch>(),
        Kind::Light => field_names::<LightPatch>(),
        Kind::Phase => field_names::<Phase>(),
        Kind::Vehicle => field_names::<VehiclePatch>(),
        Kind::Rule => field_names::<SpawnRule>(),
        Kind::Pause => field_names::<Pause>(),
        Kind::Bins => field_names::<BinsPatch>(),
        Kind::Reward => field_names::<RewardPatch>(),
        Kind::Episode => field_names::<EpisodePatch>(),
        Kind::Expect => field_names::<Expectation>(),
        Kind::Junction => field_names::<JunctionPatch>(),
        Kind::Outage => field_names::<Outage>(),
        Kind::Traffic => field_names::<TrafficRule>(),
        Kind::Leaf => &[],
    }
}

fn child(kind: Kind, field: &str) -> Kind {
    match (kind, field) {
        (Kind::Map, "road") => Kind::Road,
        (Kind::Road, "surface") => Kind::Surface,
        (Kind::Map, "crosswalk") => Kind::Crosswalk,
        (Kind::Map, "light") => Kind::Light,
        (Kind::Map, "vehicle") => Kind::Vehicle,
        (Kind::Map, "pedestrians") => Kind::Rule,
        (Kind::Map, "bins") => Kind::Bins,
        (Kind::Map, "reward") => Kind::Reward,
        (Kind::Map, "episode") => Kind::Episode,
        (Kind::Map, "expect") => Kind::Expect,
        (Kind::Light, "cycle") => Kind::Phase,
        (Kind::Rule, "pause") => Kind::Pause,
        (Kind::Map, "junction") => Kind::Junction,
        (Kind::Junction, "outages") => Kind::Outage,
        (Kind::Map, "traffic") => Kind::Traffic,
        _ => Kind::Leaf,
    }
}

fn walk(v: &ron::Value, kind: Kind, path: &str, origin: &str, out: &mut Vec<Diagnostic>) {
    if matches!(kind, Kind::Leaf) {
        return;
    }
    match v {
        ron::Value::Option(Some(inner)) => walk(inner, kind, path, origin, out),
        ron::Value::Seq(items) => {
            for (i, item) in items.iter().enumerate() {
                walk(item, kind, &format!("{path}[{i}]"), origin, out);
            }
        }
        ron::Value::Map(m) => {
            let known = fields_of(kind);
            for (k, val) in m.iter() {
                let ron::Value::String(name) = k else {
                    continue;
                };
                let here = if path.is_empty() {
                    name.clone()
                } else {
                    format!("{path}.{name}")
                };
                if known.contains(&name.as_str()) {
                    walk(val, child(kind, name), &here, origin, out);
                } else {
                    out.push(Diagnostic::new(
                        origin,
                        &here,
                        format!("unknown field `{name}`"),
                        Some(suggest(name, known)),
                    ));
                }
            }
        }
        _ => {}
    }
}

fn suggest(name: &str, known: &[&str]) -> String {
    let best = known
        .iter()
        .map(|k| (strsim::levenshtein(name, k), *k))
        .min_by_key(|(d, _)| *d);
    match best {
        Some((d, k)) if d <= 2 => format!("did you mean `{k}`?"),
        _ => format!("expected one of: {}", known.join(", ")),
    }
}

/// The field names serde's derive gives a struct, captured by a deserializer
/// that records `deserialize_struct`'s `fields` argument and stops.
pub(crate) fn field_names<'de, T: Deserialize<'de>>() -> &'static [&'static str] {
    struct Capture<'a>(&'a Cell<&'static [&'static str]>);
    impl<'de> Deserializer<'de> for Capture<'_> {
        type Error = de::value::Error;
        fn deserialize_any<V: Visitor<'de>>(self, _: V) -> Result<V::Value, Self::Error> {
            Err(de::Error::custom("not a struct"))
        }
        fn deserialize_struct<V: Visitor<'de>>(
            self,
            _name: &'static str,
            fields: &'static [&'static str],
            _visitor: V,
        ) -> Result<V::Value, Self::Error> {
            self.0.set(fields);
            Err(de::Error::custom("captured"))
        }
        serde::forward_to_deserialize_any! {
            bool i8 i16 i32 i64 i128 u8 u16 u32 u64 u128 f32 f64 char str string
            bytes byte_buf option unit unit_struct newtype_struct seq tuple
            tuple_struct map enum identifier ignored_any
        }
    }
    let cell = Cell::new(&[][..]);
    let _ = T::deserialize(Capture(&cell));
    cell.get()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn field_names_come_from_serde() {
        assert_eq!(
            field_names::<RoadPatch>(),
            &[
                "lane_width",
                "lanes",
                "sidewalk_width",
                "goal_x",
                "friction",
                "surface",
                "air_density"
            ]
        );
        assert!(field_names::<MapPatch>().contains(&"pedestrians"));
        assert!(field_names::<SpawnRule>().contains(&"pause"));
    }

    #[test]
    fn suggestions() {
        assert_eq!(
            suggest("lane_widht", field_names::<RoadPatch>()),
            "did you mean `lane_width`?"
        );
        assert!(suggest("zzzzzz", &["a", "b"]).starts_with("expected one of"));
    }

    #[test]
    fn comments_only_is_empty() {
        assert_eq!(strip_comments("// x\n/* y */ ").trim(), "");
        assert_eq!(strip_comments("\"//\"").trim(), "\"//\"");
    }
}

#[cfg(test)]
mod doc_tests {
    use super::*;

    /// maps/README.md and the reference map document every field of every struct.
    #[test]
    fn every_field_is_documented() {
        let readme = include_str!("../../maps/README.md");
        let reference = include_str!("../../maps/intersection.ron");
        let kinds = [
            Kind::Map,
            Kind::Road,
            Kind::Surface,
            Kind::Crosswalk,
            Kind::Light,
            Kind::Phase,
            Kind::Vehicle,
            Kind::Rule,
            Kind::Pause,
            Kind::Bins,
            Kind::Reward,
            Kind::Episode,
            Kind::Expect,
            Kind::Junction,
            Kind::Outage,
            Kind::Traffic,
        ];
        for k in kinds {
            for f in fields_of(k) {
                assert!(readme.contains(&format!("`{f}`")), "README lacks `{f}`");
                assert!(reference.contains(f), "intersection.ron lacks {f}");
            }
        }
    }

    #[test]
    fn summary_mentions_the_essentials() {
        let shipped = |base: &str| crate::map_texts::source(base).map(|s| (base.to_string(), s.to_string()));
        let m = Map::from_str_named("jaywalk.ron", crate::map_texts::JAYWALK, &shipped).unwrap();
        let s = m.summary();
        for needle in [
            "map jaywalk",
            "destination at x = 90 m",
            "distance to goal 26..22 m",
            "green 12 s, amber 2 s, red 10 s",
            "within 4.8 s",
            "speed [0.5, 4.5, 7.5]",
            "expect Scaled: min_success 0.9",
        ] {
            assert!(s.contains(needle), "summary lacks {needle:?}:\n{s}");
        }
        assert_eq!(m.crosswalk_distance_to_goal(), (26.0, 22.0));
    }

    /// Expectations keep their names as written (the harness checks them); a name that
    /// is not a bare identifier is a type error at its line and column.
    #[test]
    fn expectation_names_are_plain_data() {
        let m = Map::from_str_named(
            "e.ron",
            "Map(expect: [(method: Anything, protocol: Whatever), (method: Scaled, protocol: None)])",
            &|_| None,
        )
        .unwrap();
        assert_eq!(
            (m.expect[0].method.as_str(), m.expect[0].protocol.as_deref()),
            ("Anything", Some("Whatever"))
        );
        assert_eq!(
            (m.expect[1].method.as_str(), m.expect[1].protocol.as_deref()),
            ("Scaled", None)
        );
        assert!(m.summary().contains("expect Anything (Whatever): "), "{}", m.summary());
        for bad in [
            "Map(expect: [\n  (method: \"Scaled\")])",
            "Map(expect: [\n  (method: Scaled(1))])",
            "Map(expect: [\n  (method: Scaled, protocol: \"Continual\")])",
        ] {
            let e = Map::from_str_named("e.ron", bad, &|_| None).unwrap_err();
            let d = &e.diagnostics()[0];
            assert_eq!(d.position.map(|(line, _)| line), Some(2), "{bad}: {e}");
            assert!(d.path.starts_with("expect[0]."), "{bad}: {e}");
        }
    }

    #[test]
    fn empty_map_is_the_default() {
        let m = Map::from_str_named("plain.ron", "Map()", &|_| None).unwrap();
        assert_eq!(
            m,
            Map {
                name: "plain".into(),
                ..Map::default()
            }
        );
    }
}
