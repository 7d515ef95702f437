//! What a file holds, recognised by its content (not its name), for the output guard
//! ([`crate::runs::outputs`]): a writer replaces a file of its own kind and refuses any
//! other, naming what the file holds ([`Held::describe`]).

use std::io::Read;
use std::path::Path;

/// How much of a file is read to recognise it (bytes); a JSON document is parsed whole
/// up to [`MAX_JSON_BYTES`].
const HEAD_BYTES: u64 = 64 << 10;

/// Largest JSON document parsed to recognise it (bytes): larger ones are "a JSON document".
const MAX_JSON_BYTES: u64 = 64 << 20;

/// What a file holds: one of the kinds this program reads or writes, or something else.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Held {
    /// Nothing (an empty file).
    Empty,
    /// A map file (`Map(...)`, or an anonymous struct of map fields).
    Map,
    /// A failure map `unforeseen search` wrote (its first line says so).
    FailureMap,
    /// A search space file (`Space(...)`).
    Space,
    /// A deployment stream file (`Stream(...)`).
    Stream,
    /// An agent file (`(format_version: ...`).
    Agent,
    /// A batch's results file: its first line is a run identity (`{"run": ...}`).
    BatchRun,
    /// Result lines without a run identity (Python's `evaluate`).
    ResultLines,
    /// A search's candidates file (`{"search": ...}` first).
    Candidates,
    /// An estimate's draws file (`{"estimate": ...}` first).
    Estimates,
    /// The summary beside a batch's results file.
    BatchSummary,
    /// A search's `summary.json`.
    SearchSummary,
    /// An estimate's `summary.json`.
    EstimateSummary,
    /// `eval.json`.
    Evaluation,
    /// `compare.json`.
    Comparison,
    /// `learn.json`.
    LearningCurves,
    /// A planning model in the `inspect` layout (`export-model`).
    Model,
    /// The summary of a gated agent's run on a model in pymdp's layout (`run-model`).
    ModelRun,
    /// Another JSON document.
    Json,
    /// A CSV table (a header of names).
    Csv,
    /// An HTML page (`trace --html`).
    Html,
    /// An SVG figure.
    Svg,
    /// Text of another kind (notes, code, a RON file of another kind).
    Text,
    /// Not text.
    Binary,
}

impl Held {
    /// What the file at `path` holds (a file that cannot be read is [`Held::Binary`]).
    pub fn of(path: &Path) -> Held {
        let mut head = Vec::new();
        let read = std::fs::File::open(path).and_then(|f| f.take(HEAD_BYTES).read_to_end(&mut head));
        if read.is_err() {
            return Held::Binary;
        }
        if head.is_empty() {
            return Held::Empty;
        }
        let text = match std::str::from_utf8(&head) {
            Ok(t) => t,
            // A character cut at the end of the head is still text.
            Err(e) if e.error_len().is_none() => std::str::from_utf8(&head[..e.valid_up_to()]).unwrap_or_default(),
            Err(_) => return Held::Binary,
        };
        let body = text.trim_start();
        if body.starts_with('{') || body.starts_with('[') {
            return json_kind(path, body);
        }
        let lower = body.get(..15).unwrap_or(body).to_ascii_lowercase();
        if lower.starts_with("<!doctype html") || lower.starts_with("<html") {
            return Held::Html;
        }
        if body.starts_with("<svg") || (body.starts_with("<?xml") && body.contains("<svg")) {
            return Held::Svg;
        }
        if let Some(kind) = ron_kind(text) {
            return kind;
        }
        let first = text.lines().next().unwrap_or_default().trim_end();
        let names = first.split(',').collect::<Vec<_>>();
        if names.len() > 1
            && names
                .iter()
                .all(|c| !c.is_empty() && c.chars().all(|ch| ch.is_ascii_alphanumeric() || ch == '_'))
        {
            return Held::Csv;
        }
        Held::Text
    }

    /// What it is, for an error ("exists and holds a map").
    pub fn describe(self) -> &'static str {
        match self {
            Held::Empty => "nothing (an empty file)",
            Held::Map => "a map",
            Held::FailureMap => "a failure map written by `unforeseen search`",
            Held::Space => "a search space (a space file)",
            Held::Stream => "a deployment stream",
            Held::Agent => "an agent file",
            Held::BatchRun => "a batch's results (its first line names the run)",
            Held::ResultLines => "result lines (as Python's `evaluate` writes them)",
            Held::Candidates => "a search's candidates",
            Held::Estimates => "an estimate's draws",
            Held::BatchSummary => "a batch's summary",
            Held::SearchSummary => "a search's summary",
            Held::EstimateSummary => "an estimate's summary",
            Held::Evaluation => "an evaluation (eval.json)",
            Held::Comparison => "a comparison (compare.json)",
            Held::LearningCurves => "learning curves (learn.json)",
            Held::Model => "a planning model (the `inspect` JSON layout)",
            Held::ModelRun => "a gated run's summary (`run-model`)",
            Held::Json => "a JSON document",
            Held::Csv => "a CSV table",
            Held::Html => "an HTML page",
            Held::Svg => "an SVG figure",
            Held::Text => "text of another kind",
            Held::Binary => "data that is not text",
        }
    }
}

/// The kind of a file whose text starts with `{` or `[`.
fn json_kind(path: &Path, body: &str) -> Held {
    let first = body.lines().next().unwrap_or_default().trim_end();
    if first.starts_with("{\"run\":") {
        return Held::BatchRun;
    }
    if first.starts_with("{\"search\":") {
        return Held::Candidates;
    }
    if first.starts_with("{\"estimate\":") {
        return Held::Estimates;
    }
    let has = |v: &serde_json::Value, keys: &[&str]| keys.iter().all(|k| v.get(k).is_some());
    // A result line, whatever its keys' order and spacing (Python's `json.dumps`).
    if serde_json::from_str::<serde_json::Value>(first)
        .is_ok_and(|v| has(&v, &["unit", "scenario", "method", "param_set", "protocol"]))
    {
        return Held::ResultLines;
    }
    let len = std::fs::metadata(path).map_or(u64::MAX, |m| m.len());
    let value = (len <= MAX_JSON_BYTES)
        .then(|| std::fs::read(path).ok())
        .flatten()
        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok());
    let Some(value) = value else {
        return Held::Text;
    };
    if let Some(first) = value.as_array().and_then(|a| a.first()) {
        return if has(first, &["episode", "inference_rate", "reasoning_ticks"]) {
            Held::LearningCurves
        } else {
            Held::Json
        };
    }
    if has(&value, &["A", "B", "C", "D", "policy_len"]) {
        Held::Model
    } else if has(&value, &["episodes", "mean_return", "planned_fraction"]) {
        Held::ModelRun
    } else if has(&value, &["rows", "results", "run"]) {
        Held::BatchSummary
    } else if has(&value, &["counts", "fair_share", "space_file"]) {
        Held::SearchSummary
    } else if has(&value, &["estimates", "failure_threshold", "space_file"]) {
        Held::EstimateSummary
    } else if has(&value, &["protocols", "tables", "paper"]) {
        Held::Comparison
    } else if has(&value, &["method", "protocol", "computed_under", "episodes"]) {
        Held::Evaluation
    } else {
        Held::Json
    }
}

/// The kind of a RON file (comments and blank lines before its value), if it is one of
/// this program's.
fn ron_kind(text: &str) -> Option<Held> {
    if text
        .lines()
        .next()
        .is_some_and(|l| l.starts_with("// ") && l.contains("found by `unforeseen search`"))
    {
        return Some(Held::FailureMap);
    }
    let body = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty() && !l.starts_with("//"))
        .collect::<Vec<_>>()
        .join(" ");
    let named = |name: &str| {
        body.strip_prefix(name)
            .is_some_and(|rest| rest.trim_start().starts_with('('))
    };
    if named("Map") {
        return Some(Held::Map);
    }
    if named("Space") {
        return Some(Held::Space);
    }
    if named("Stream") {
        return Some(Held::Stream);
    }
    let field = body.strip_prefix('(')?.trim_start();
    let field = &field[..field.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))?];
    match field {
        "format_version" => Some(Held::Agent),
        "base" | "name" | "description" | "road" | "car" | "light" | "pedestrians" | "episode" | "bins" | "reward"
        | "expect" => Some(Held::Map),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn held(text: &str) -> Held {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("f");
        std::fs::write(&p, text).unwrap();
        Held::of(&p)
    }

    #[test]
    fn the_shipped_files_are_recognised_by_their_content() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        for (file, kind) in [
            ("maps/jaywalk.ron", Held::Map),
            ("maps/search/late_pair.ron", Held::FailureMap),
            ("maps/spaces/jaywalk.ron", Held::Space),
            ("maps/streams/deployment.ron", Held::Stream),
            ("README.md", Held::Text),
        ] {
            assert_eq!(Held::of(&root.join(file)), kind, "{file}");
        }
    }

    #[test]
    fn each_kind_is_told_apart() {
        assert_eq!(held(""), Held::Empty);
        assert_eq!(held("(\n    format_version: 1,\n"), Held::Agent);
        assert_eq!(held("// notes\nMap(base: \"x\")"), Held::Map);
        assert_eq!(held("{\"run\":{}}\n"), Held::BatchRun);
        assert_eq!(held("{\"search\":{}}\n"), Held::Candidates);
        assert_eq!(held("{\"estimate\":{}}\n"), Held::Estimates);
        assert_eq!(
            held("{\"estimates\": {}, \"failure_threshold\": {}, \"space_file\": \"s.ron\"}"),
            Held::EstimateSummary
        );
        let line = "{\"method\": \"m\", \"param_set\": \"default\", \"protocol\": \"zero-shot\", \"scenario\": \"s\", \"unit\": 0}\n";
        assert_eq!(held(line), Held::ResultLines);
        assert_eq!(
            held("{\"A\": [], \"B\": [], \"C\": [], \"D\": [], \"policy_len\": 1}"),
            Held::Model
        );
        assert_eq!(
            held("{\"rows\": [], \"results\": \"r.jsonl\", \"run\": {}}"),
            Held::BatchSummary
        );
        assert_eq!(
            held("{\"episodes\": [], \"mean_return\": 0.5, \"planned_fraction\": 1.0}"),
            Held::ModelRun
        );
        assert_eq!(held("{\"x\": 1}"), Held::Json);
        assert_eq!(
            held("[{\"episode\": 0, \"inference_rate\": 1, \"reasoning_ticks\": 2}]"),
            Held::LearningCurves
        );
        assert_eq!(held("<!DOCTYPE html>\n<html>"), Held::Html);
        assert_eq!(held("<svg width=\"1\">"), Held::Svg);
        assert_eq!(held("step,d,v\n0,1,2\n"), Held::Csv);
        assert_eq!(held("hello\n"), Held::Text);
        assert_eq!(held("{not json"), Held::Text);
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join("b"), [0xff, 0xfe, 0, 1]).unwrap();
        assert_eq!(Held::of(&d.path().join("b")), Held::Binary);
    }
}
