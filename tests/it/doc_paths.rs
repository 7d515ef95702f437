//! The files the documentation names exist: every path in README.md, docs/*.md, the
//! other top-level notes, maps/README.md and the comments of the Rust sources that
//! starts with one of the repository's folders (`maps/...`, `docs/...`, `src/...`, ...)
//! or names a top-level `*.md` file. A path counts as found relative to the repository,
//! to the crate of the file that names it, or to that file's folder. Outputs of runs
//! (`out/...`, `target/...`) and patterns (`maps/*.ron`) are not files to check.

use std::path::{Path, PathBuf};

/// Folders a documented path may start with.
const FOLDERS: [&str; 13] = [
    ".ci",
    "agent",
    "benches",
    "discretizer",
    "docs",
    "env",
    "harness",
    "maps",
    "scripts",
    "sim",
    "src",
    "tests",
    "examples",
];

/// Path-like words of `text`: runs of path characters, trimmed of sentence punctuation.
fn words(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| !(c.is_ascii_alphanumeric() || "_./-*{}$<>".contains(c)))
        .map(|w| w.trim_end_matches(['.', ',', ':', ';']).trim_start_matches("./"))
        .filter(|w| !w.is_empty())
}

/// The documented paths in `text`.
pub fn paths(text: &str) -> Vec<String> {
    words(text)
        .filter(|w| !w.contains(['*', '{', '}', '$', '<', '>']) && !w.starts_with('/') && !w.contains("//"))
        .filter(|w| {
            let first = w.split('/').next().unwrap_or("");
            (w.contains('/') && FOLDERS.contains(&first))
                || (!w.contains('/')
                    && w.ends_with(".md")
                    && w.len() > 3
                    && w[..w.len() - 3].chars().all(|c| c.is_ascii_uppercase() || c == '_'))
        })
        .map(String::from)
        .collect()
}

/// The crate folder of `file`: the nearest folder above it with a Cargo.toml.
fn crate_dir(file: &Path) -> PathBuf {
    let mut dir = file.parent();
    while let Some(d) = dir {
        if d.join("Cargo.toml").is_file() {
            return d.to_path_buf();
        }
        dir = d.parent();
    }
    PathBuf::new()
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let path = e.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|x| x == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn every_path_the_documentation_names_exists() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut docs: Vec<PathBuf> = ["README.md", "EXPERIMENTS.md", "BENCHMARKS.md", "maps/README.md"]
        .iter()
        .map(|p| root.join(p))
        .filter(|p| p.is_file())
        .collect();
    for entry in std::fs::read_dir(root.join("docs")).unwrap().flatten() {
        if entry.path().extension().is_some_and(|x| x == "md") {
            docs.push(entry.path());
        }
    }
    assert!(
        docs.iter().any(|d| d.ends_with("docs/ARCHITECTURE.md")),
        "the architecture document exists"
    );
    let mut sources = Vec::new();
    for dir in [
        "src",
        "harness",
        "tests",
        "benches",
        "agent",
        "sim",
        "discretizer",
        "env",
    ] {
        rust_files(&root.join(dir), &mut sources);
    }

    let mut missing = Vec::new();
    let mut checked = 0;
    let mut check = |file: &Path, line_no: usize, line: &str| {
        for path in paths(line) {
            checked += 1;
            let candidates = [
                root.join(&path),
                crate_dir(file).join(&path),
                file.parent().unwrap().join(&path),
            ];
            if !candidates.iter().any(|c| c.exists()) {
                missing.push(format!(
                    "{}:{}: {path}",
                    file.strip_prefix(root).unwrap_or(file).display(),
                    line_no + 1
                ));
            }
        }
    };
    for doc in &docs {
        let text = std::fs::read_to_string(doc).unwrap();
        for (i, line) in text.lines().enumerate() {
            check(doc, i, line);
        }
    }
    for src in &sources {
        let text = std::fs::read_to_string(src).unwrap();
        for (i, line) in text.lines().enumerate() {
            if let Some(comment) = line.trim_start().strip_prefix("//") {
                check(src, i, comment);
            }
        }
    }
    assert!(checked > 50, "found the documentation's paths ({checked})");
    assert!(
        missing.is_empty(),
        "documented paths that do not exist:\n{}",
        missing.join("\n")
    );
}

#[test]
fn paths_are_picked_out_of_prose() {
    let found = paths(
        "See `maps/intersection.ron`, docs/ARCHITECTURE.md §4, README.md. Not out/compare/x.json, \
         maps/*.ron, /work/DESIGN.md, https://a.b/src/x or sim's own words.",
    );
    assert_eq!(found, ["maps/intersection.ron", "docs/ARCHITECTURE.md", "README.md"]);
}
