//! Build script: a fingerprint of the source that determines a trained agent (the sim,
//! discretizer and agent crates, the training loop, the rewards and the locked
//! dependency versions), so the agent cache of `--train-seeds` (src/agents.rs) never
//! serves an agent trained by different code.

use std::path::{Path, PathBuf};

/// Sources whose contents determine training.
const INPUTS: &[&str] = &[
    "sim/src",
    "discretizer/src",
    "agent/src",
    "src/training.rs",
    "src/rewards.rs",
    "Cargo.lock",
];

fn main() {
    let root = PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    for input in INPUTS {
        println!("cargo:rerun-if-changed={input}");
        collect(&root.join(input), &mut files);
    }
    files.sort();
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for f in &files {
        let rel = f.strip_prefix(&root).unwrap_or(f).to_string_lossy().replace('\\', "/");
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
    println!("cargo:rustc-env=UNFORESEEN_TRAINING_FINGERPRINT={h:016x}");
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
