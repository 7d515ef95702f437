//! Issue 35, finding 6: a 2.3 KB stream file (64 maps, `weight: 1e6`, `order: Sequence`)
//! made `batch --episodes 1` take 0.9 GB at `--jobs 2`, because the schedule spelled
//! out the stream's whole cycle (64 × 10⁶ map indices, 512 MB) before running one
//! episode. A schedule now costs memory per episode run, whatever the weights
//! (maps/README.md, "Deployment streams").
//!
//! The run is measured in a child process, this test binary running only
//! [`child_runs_the_stream_and_reports_its_peak_memory`], by its peak resident memory
//! (`VmHWM`, Linux): the other tests of this binary allocate too.

use std::path::Path;

use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::progress::NoProgress;
use unforeseen_harness::runs::batch::{BatchConfig, ParamSet, SCRIPTED_ONLY, load_stream_scenario, run};
use unforeseen_harness::runs::stream::{MAX_MAPS, Stream};

/// Set to the child's folder: the child test runs the stream there.
const CHILD: &str = "UNFORESEEN_STREAM_MEMORY_CHILD";

/// Peak resident memory the run may take. One stream schedule of the old code alone
/// took 512 MB; the run takes about 30 MB now.
const LIMIT_KIB: u64 = 200 * 1024;

/// Writes the stream of the finding into `dir`: the most maps a stream may list, each
/// the largest weight, in sequence (a 2.4 KB file).
fn write_stream(dir: &Path) -> std::path::PathBuf {
    let mut entries = String::new();
    for i in 0..MAX_MAPS {
        std::fs::write(dir.join(format!("m{i:02}.ron")), "Map()\n").unwrap();
        entries.push_str(&format!("(map: \"m{i:02}.ron\", weight: 1e6), "));
    }
    let stream = dir.join("huge.ron");
    std::fs::write(&stream, format!("Stream(maps: [{entries}], order: Sequence)\n")).unwrap();
    assert!(std::fs::metadata(&stream).unwrap().len() < 2600);
    stream
}

/// The peak resident memory of this process so far, in KiB (Linux).
fn peak_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

#[test]
fn a_tiny_stream_with_huge_weights_runs_in_little_memory() {
    if peak_kib().is_none() {
        eprintln!("no /proc/self/status here: the peak memory cannot be measured");
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let stream = write_stream(dir.path());
    let loaded = Stream::load(&stream).unwrap();
    assert_eq!(loaded.maps.len(), MAX_MAPS);
    // A schedule is as long as the episodes asked, never the cycle.
    let schedule = loaded.schedule(3, 1);
    assert_eq!(schedule, [0, 0, 0]);
    let child = std::process::Command::new(std::env::current_exe().unwrap())
        .args([
            "stream_memory::child_runs_the_stream_and_reports_its_peak_memory",
            "--exact",
            "--nocapture",
            "--test-threads",
            "1",
        ])
        .env(CHILD, dir.path())
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&child.stdout).into_owned() + &String::from_utf8_lossy(&child.stderr);
    assert!(child.status.success(), "{text}");
    let peak: u64 = text
        .split("peak resident memory: ")
        .nth(1)
        .and_then(|t| t.split(" KiB").next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("the child did not report its peak: {text}"));
    assert!(
        peak < LIMIT_KIB,
        "a 64-map stream of weights 1e6 took {} MB for one episode (at most {} MB)",
        peak / 1024,
        LIMIT_KIB / 1024
    );
}

/// The child of [`a_tiny_stream_with_huge_weights_runs_in_little_memory`]: runs a batch
/// of one episode of the stream at `--jobs 2` and prints its peak memory. Does nothing
/// unless [`CHILD`] is set.
#[test]
fn child_runs_the_stream_and_reports_its_peak_memory() {
    let Some(dir) = std::env::var_os(CHILD) else {
        return;
    };
    let dir = Path::new(&dir);
    let scenarios = [load_stream_scenario(&dir.join("huge.ron")).unwrap()];
    let cfg = BatchConfig {
        agents: &[],
        train_seeds: &[None],
        scenarios: &scenarios,
        methods: &[Method::NeverBrake, Method::BrakeOnPedestrian],
        params: &[ParamSet(Vec::new())],
        protocols: &[Protocol::ZeroShot],
        episodes: 1,
        seed: 7,
        jobs: 2,
        shard: None,
        agents_identity: SCRIPTED_ONLY.to_string(),
    };
    let lines = run(&cfg, &dir.join("r.jsonl"), false, &NoProgress).unwrap();
    assert_eq!(lines.len(), 2);
    assert!(lines.iter().all(|l| l.per_map.len() == 1 && l.per_map[0].map == "m00"));
    println!("peak resident memory: {} KiB", peak_kib().unwrap());
}
