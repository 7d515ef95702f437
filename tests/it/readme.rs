//! Every command in README.md runs as written and exits 0, at small sizes: each ```sh
//! block runs under `bash -euo pipefail` in one scratch folder (a reader following the
//! README top to bottom, with `maps/` and `examples/` beside them), in order, and each ```ron block is
//! validated with `unforeseen check-map`. Every SVG figure the commands write is then
//! checked for overlapping or cut-off text.
//!
//! What is not the README's own text, and why:
//! * `unforeseen` on the PATH is a small wrapper around the binary under test that caps
//!   the sizes: every evaluation `--episodes` at [`EVAL`], training at [`TRAIN`]
//!   episodes for `compare` (which gates nothing) and at [`TRAIN_GATED`] for `train`
//!   and `batch` (whose agents must pass the maps' `expect` gates: at 200 episodes
//!   some did not), and gives those sizes to commands that would otherwise use their
//!   large defaults (6000 training, 100 evaluation episodes).
//! * `cargo run [--release] [-- ARGS]` runs that wrapper with ARGS; other cargo commands
//!   (`cargo test`, `cargo install`, `cargo bench`, ...) are skipped: `.ci/run` runs the
//!   test and bench builds itself, and this test is part of `cargo test`.
//! * `SLURM_ARRAY_TASK_ID` is 1, as for the first task of the array.
//! * The Python section's blocks (`console` and `python` fences) need Python and are not run
//!   here: `.ci/run` runs its two commands, and `python/tests/test_readme.py` its example.

#![cfg(unix)]

use std::path::{Path, PathBuf};
use std::process::Command;

use unforeseen_harness::fixtures::svg_text::assert_text_fits;

/// Training episodes at most for `compare`.
const TRAIN: u64 = 100;
/// Training episodes at most for `train` and `batch`: enough for the maps' gates.
const TRAIN_GATED: u64 = 600;
/// Evaluation episodes at most.
const EVAL: u64 = 2;

/// The fenced code blocks of `markdown` with their language: (language, body).
pub fn code_blocks(markdown: &str) -> Vec<(String, String)> {
    let mut blocks = Vec::new();
    let mut open: Option<(String, String)> = None;
    for line in markdown.lines() {
        let fence = line.trim_start().strip_prefix("```");
        match (&mut open, fence) {
            (None, Some(lang)) => open = Some((lang.trim().to_string(), String::new())),
            (Some(_), Some(_)) => blocks.extend(open.take()),
            (Some((_, body)), None) => {
                body.push_str(line);
                body.push('\n');
            }
            (None, None) => {}
        }
    }
    blocks
}

fn write_executable(path: &Path, text: &str) {
    use std::os::unix::fs::PermissionsExt;
    std::fs::write(path, text).unwrap();
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// The `unforeseen` wrapper (see the module docs).
fn wrapper(real: &Path) -> String {
    format!(
        r#"#!/usr/bin/env bash
# unforeseen, for the README test: sizes capped (see tests/it/readme.rs).
set -euo pipefail
if [[ $# -eq 0 ]]; then set -- compare; fi
cmd=$1
case $cmd in
  train|batch) cap={TRAIN_GATED} ;;
  *) cap={TRAIN} ;;
esac
args=()
prev=
has_train=0
has_eval=0
for a in "$@"; do
  case $prev in
    --train-episodes) a=$(( a < cap ? a : cap )); has_train=1 ;;
    --episodes)
      if [[ $cmd == train ]]; then a=$(( a < cap ? a : cap )); has_train=1
      else a=$(( a < {EVAL} ? a : {EVAL} )); has_eval=1; fi ;;
  esac
  args+=("$a")
  prev=$a
done
case $cmd in
  compare|batch)
    if [[ $has_train == 0 ]]; then args+=(--train-episodes "$cap"); fi
    if [[ $has_eval == 0 ]]; then args+=(--episodes {EVAL}); fi ;;
  train) if [[ $has_train == 0 ]]; then args+=(--episodes "$cap"); fi ;;
  eval|learn) if [[ $has_eval == 0 ]]; then args+=(--episodes {EVAL}); fi ;;
esac
exec {real:?} "${{args[@]}}"
"#
    )
}

/// What every block starts with: `cargo` as the module docs say.
const PRELUDE: &str = r#"
cargo() {
  case "$1" in
    run)
      shift
      while [[ $# -gt 0 && $1 != -- ]]; do shift; done
      if [[ $# -gt 0 ]]; then shift; fi
      unforeseen "$@" ;;
    *) echo "README test: skipping 'cargo $*'" ;;
  esac
}
"#;

fn run_block(dir: &Path, path_var: &str, script: &str, what: &str) {
    let out = Command::new("bash")
        .args(["-euo", "pipefail", "-c"])
        .arg(format!("{PRELUDE}\n{script}"))
        .current_dir(dir)
        .env("PATH", path_var)
        .env("SLURM_ARRAY_TASK_ID", "1")
        .output()
        .expect("bash");
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{script}\n--- stdout\n{}\n--- stderr\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

fn svgs(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let path = entry.path();
        if entry.file_type().unwrap().is_dir() {
            svgs(&path, out);
        } else if path.extension().is_some_and(|e| e == "svg") {
            out.push(path);
        }
    }
}

#[test]
fn every_command_in_the_readme_runs_as_written() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let readme = std::fs::read_to_string(root.join("README.md")).unwrap();
    let blocks = code_blocks(&readme);
    let sh: Vec<&String> = blocks.iter().filter(|(l, _)| l == "sh").map(|(_, b)| b).collect();
    assert!(sh.len() >= 3, "the README's command blocks were found: {}", sh.len());

    let scratch = tempfile::tempdir().unwrap();
    let dir = scratch.path();
    std::os::unix::fs::symlink(root.join("maps"), dir.join("maps")).unwrap();
    std::os::unix::fs::symlink(root.join("examples"), dir.join("examples")).unwrap();
    let bin = dir.join("bin");
    std::fs::create_dir(&bin).unwrap();
    write_executable(
        &bin.join("unforeseen"),
        &wrapper(Path::new(env!("CARGO_BIN_EXE_unforeseen"))),
    );
    let path_var = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());

    for (i, block) in sh.iter().enumerate() {
        run_block(dir, &path_var, block, &format!("README sh block {}", i + 1));
    }
    for (i, (_, body)) in blocks.iter().filter(|(l, _)| l == "ron").enumerate() {
        let file = format!("readme_map_{}.ron", i + 1);
        std::fs::write(dir.join(&file), body).unwrap();
        run_block(
            dir,
            &path_var,
            &format!("unforeseen check-map {file}"),
            &format!("README ron block {}", i + 1),
        );
    }

    let mut figures = Vec::new();
    svgs(dir, &mut figures);
    assert!(!figures.is_empty(), "the README's commands draw figures");
    for svg in &figures {
        assert_text_fits(svg);
    }
}

#[test]
fn code_blocks_are_found_with_their_language() {
    let md = "text\n```sh\na\nb\n```\n\n```ron\n(x: 1)\n```\n```\nplain\n```\n";
    assert_eq!(
        code_blocks(md),
        vec![
            ("sh".to_string(), "a\nb\n".to_string()),
            ("ron".to_string(), "(x: 1)\n".to_string()),
            (String::new(), "plain\n".to_string()),
        ]
    );
}
