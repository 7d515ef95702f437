//! Build script: a fingerprint of the source that determines a trained agent (the sim,
//! discretizer, env and agent crates, the training loop, the rewards and the locked
//! dependency versions), so the agent cache of `--train-seeds`
//! (harness/src/training/seed_agents.rs) never serves an agent trained by different
//! code; and one of all the source that determines results (the same plus the whole
//! harness, `harness/src/`), so that `batch --resume` never mixes lines of two programs
//! (harness/src/runs/batch/identity.rs, `RunIdentity`).

use std::path::{Path, PathBuf};

/// Sources whose contents determine training, relative to the repository's root.
const INPUTS: &[&str] = &[
    "sim/src",
    "discretizer/src",
    "env/src",
    "agent/src",
    "harness/src/training/mod.rs",
    "harness/src/episodes/rewards.rs",
    "Cargo.lock",
];

/// Further sources whose contents determine evaluation results.
const RESULT_INPUTS: &[&str] = &["harness/src"];

fn main() {
    // This crate is `harness/` of the repository; paths are hashed relative to its root.
    let manifest = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let root = manifest
        .parent()
        .expect("harness/ lies in the repository")
        .to_path_buf();
    let training = fingerprint(&root, INPUTS);
    println!("cargo:rustc-env=UNFORESEEN_TRAINING_FINGERPRINT={training:016x}");
    let all: Vec<&str> = INPUTS.iter().chain(RESULT_INPUTS).copied().collect();
    println!(
        "cargo:rustc-env=UNFORESEEN_CODE_FINGERPRINT={:016x}",
        fingerprint(&root, &all)
    );
}

/// FNV-1a over the relative path and contents of every file under `inputs`, in order.
fn fingerprint(root: &Path, inputs: &[&str]) -> u64 {
    let mut files = Vec::new();
    for input in inputs {
        println!("cargo:rerun-if-changed={}", root.join(input).display());
        collect(&root.join(input), &mut files);
    }
    files.sort();
    files.dedup();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for f in &files {
        let rel = f.strip_prefix(root).unwrap_or(f).to_string_lossy().replace('\\', "/");
        let bytes = std::fs::read(f).unwrap_or_default();
        for &b in rel
            .as_bytes()
            .iter()
            .chain([0xff].iter())
            .chain(&bytes)
            .chain([0xff].iter())
        {
            h ^= u64::from(b);
            h = h.wrapping_mul(0x0000_0100_0000_01b3);
        }
    }
    h
}

/// Every file under `path` (or `path` itself).
fn collect(path: &Path, out: &mut Vec<PathBuf>) {
    if path.is_dir() {
        if let Ok(entries) = std::fs::read_dir(path) {
            for e in entries.flatten() {
                collect(&e.path(), out);
            }
        }
    } else if path.is_file() {
        out.push(path.to_path_buf());
    }
}
