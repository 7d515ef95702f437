//! `unforeseen estimate`: the same request gives the same files whatever `--jobs`, the
//! summary states its estimates and threshold, and bad input is refused with exit 2.
//! Budgets are the estimators' smallest, of one episode per draw.

use crate::common::{assert_exit, run_cli};

/// Runs an estimate of never-brake on the jaywalk space into `out` with `extra` flags.
fn estimate(out: &std::path::Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "estimate",
        "--space",
        "maps/spaces/jaywalk.ron",
        "--method",
        "never-brake",
        "--episodes",
        "1",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    run_cli(&args)
}

#[test]
fn estimates_are_the_same_whatever_the_jobs() {
    let d = tempfile::tempdir().unwrap();
    for (estimator, budget) in [("mc", "50"), ("is", "200"), ("is-fails", "200")] {
        let files = |jobs: &str| {
            let out = d.path().join(format!("{estimator}-{jobs}"));
            let run = estimate(&out, &["--estimator", estimator, "--budget", budget, "--jobs", jobs]);
            assert_exit(&run, 0, &["P(never-brake fails | fair)"]);
            ["estimate.jsonl", "summary.json"].map(|f| std::fs::read(out.join(f)).unwrap())
        };
        assert_eq!(files("1"), files("2"), "{estimator}");
    }
    let summary: serde_json::Value =
        serde_json::from_slice(&std::fs::read(d.path().join("mc-1/summary.json")).unwrap()).unwrap();
    assert_eq!(summary["failure_threshold"]["survivable_min_success"], 0.99);
    assert_eq!(summary["evaluations"], 50);
    // One block of 50: one checkpoint, the estimate reported.
    let checkpoints = summary["checkpoints"].as_array().unwrap();
    assert_eq!(checkpoints.len(), 1);
    assert_eq!(checkpoints[0]["evaluations"], 50);
    assert_eq!(checkpoints[0]["p_fail"], summary["estimates"]["p_fail"]);
    let p = &summary["estimates"]["p_fail"];
    assert!(
        p["ci95_low"].as_f64() <= p["p"].as_f64() && p["p"].as_f64() <= p["ci95_high"].as_f64(),
        "{p}"
    );
    let lines = std::fs::read_to_string(d.path().join("mc-1/estimate.jsonl")).unwrap();
    assert!(lines.starts_with("{\"estimate\":"));
    assert_eq!(lines.lines().count(), 51);
    // never-brake fails by a collision: its failed draws' margins are 0, its others' not.
    let draws: Vec<serde_json::Value> = lines
        .lines()
        .skip(1)
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let failed = |d: &&serde_json::Value| d["failed"] == 1;
    assert!(draws.iter().filter(failed).count() > 10);
    for d in draws.iter().filter(failed) {
        assert_eq!(
            (d["min_clearance_m"].as_f64(), d["min_ttc_s"].as_f64()),
            (Some(0.0), Some(0.0)),
            "{d}"
        );
    }
    for d in draws.iter().filter(|d| d["failed"] == 0 && d["rejected"].is_null()) {
        assert!(d["min_clearance_m"].as_f64().is_none_or(|c| c > 0.0), "{d}");
    }
}

#[test]
fn bad_requests_are_refused_with_their_reason() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out");
    assert_exit(
        &estimate(&out, &["--estimator", "splitting"]),
        2,
        &["'splitting'", "mc, is"],
    );
    for r in ["0", "1", "-0.5"] {
        assert_exit(
            &estimate(&out, &["--target-rel-error", r]),
            2,
            &["--target-rel-error", "(0, 1)"],
        );
    }
    assert_exit(
        &estimate(&out, &["--estimator", "is", "--budget", "150"]),
        2,
        &["--budget 150", "200"],
    );
    assert_exit(
        &estimate(&out, &["--estimator", "mc", "--budget", "20"]),
        2,
        &["--budget 20", "50"],
    );
    // No pedestrian: never-brake always arrives, so no scenario is dangerous, none fair.
    let calm = d.path().join("calm.ron");
    std::fs::write(&calm, "Map(base: \"jaywalk\", name: \"calm\", pedestrians: [])").unwrap();
    let space = d.path().join("calm_space.ron");
    std::fs::write(
        &space,
        "Space(name: \"calm\", params: [(field: \"vehicle.start_speed\", range: (1.0, 5.0))])",
    )
    .unwrap();
    let run = run_cli(&[
        "estimate",
        "--map",
        calm.to_str().unwrap(),
        "--space",
        space.to_str().unwrap(),
        "--method",
        "never-brake",
        "--estimator",
        "mc",
        "--budget",
        "50",
        "--episodes",
        "1",
        "-q",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_exit(&run, 2, &["--space", "none of the first 50 draws", "is fair"]);
    assert!(!out.join("summary.json").exists() && !out.join("estimate.jsonl").exists());
}
