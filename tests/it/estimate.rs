//! `unforeseen estimate`: the same request gives the same files whatever `--jobs`, the
//! summary states its estimates and threshold, a killed run resumed (`--resume`) and
//! shards concatenated and resumed (`--shard I/N`) give the files of one uninterrupted,
//! unsharded run byte for byte, and bad input (a request, a shard, a file `--resume`
//! cannot continue) is refused with exit 2, naming the flag or the file and line.
//! Budgets are small, of one episode per draw.

use crate::common::{assert_exit, output_text, run_cli};

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

/// The two files of an estimate's folder.
fn files(out: &std::path::Path) -> [Vec<u8>; 2] {
    ["estimate.jsonl", "summary.json"].map(|f| std::fs::read(out.join(f)).unwrap())
}

#[test]
fn a_killed_estimate_resumes_to_the_files_of_one_never_killed() {
    let d = tempfile::tempdir().unwrap();
    for (estimator, budget) in [("mc", "100"), ("is", "200"), ("is-fails", "200")] {
        let flags = [
            "--estimator",
            estimator,
            "--budget",
            budget,
            "--target-rel-error",
            "0.05",
            "--jobs",
            "2",
        ];
        let whole = d.path().join(format!("{estimator}-whole"));
        assert_exit(&estimate(&whole, &flags), 0, &[]);
        // A kill leaves the part, its last line cut, and no estimate.jsonl.
        let killed = d.path().join(format!("{estimator}-killed"));
        std::fs::create_dir_all(&killed).unwrap();
        let draws = std::fs::read(whole.join("estimate.jsonl")).unwrap();
        std::fs::write(killed.join("estimate.jsonl.part"), &draws[..draws.len() * 3 / 5]).unwrap();
        let resume = [&flags[..], &["--resume"]].concat();
        assert_exit(&estimate(&killed, &resume), 0, &["P(never-brake fails | fair)"]);
        assert_eq!(files(&killed), files(&whole), "{estimator}");
        assert!(!killed.join("estimate.jsonl.part").exists());
        // A finished folder resumes to itself.
        assert_exit(&estimate(&killed, &resume), 0, &[]);
        assert_eq!(files(&killed), files(&whole), "{estimator}");
    }
}

#[test]
fn shards_concatenated_then_resumed_give_the_unsharded_files() {
    let d = tempfile::tempdir().unwrap();
    // `is` and `is-fails` with 250 draws: at most two rounds of 50 (half the budget; one
    // when never-brake's failures fill the first round's elite), then final blocks of 50
    // dealt at once; each round's proposal refitted from the joined draws, as the whole
    // run did. The steps go on until the shards hold every draw.
    for (estimator, budget, most) in [("mc", "100", 1), ("is", "250", 3), ("is-fails", "250", 3)] {
        let flags = [
            "--estimator",
            estimator,
            "--budget",
            budget,
            "--target-rel-error",
            "0.05",
        ];
        let whole = d.path().join(format!("{estimator}-whole"));
        assert_exit(&estimate(&whole, &flags), 0, &[]);
        let joined = d.path().join(format!("{estimator}-joined"));
        std::fs::create_dir_all(&joined).unwrap();
        // Each step: every shard takes its share of the next stage of the joined draws.
        let mut steps = 0;
        loop {
            let mut concatenated = Vec::new();
            let mut done = 0;
            for shard in ["1/2", "2/2"] {
                let out = d.path().join(format!("{estimator}-shard{}", &shard[..1]));
                std::fs::create_dir_all(&out).unwrap();
                if let Ok(text) = std::fs::read(joined.join("estimate.jsonl")) {
                    std::fs::write(out.join("estimate.jsonl"), text).unwrap();
                }
                let run = estimate(&out, &[&flags[..], &["--shard", shard, "--resume"]].concat());
                assert_exit(&run, 0, &[]);
                done += usize::from(output_text(&run).contains("holds every draw the estimate needs"));
                assert!(!out.join("summary.json").exists(), "a shard writes no summary");
                concatenated.extend(std::fs::read(out.join("estimate.jsonl")).unwrap());
            }
            std::fs::write(joined.join("estimate.jsonl"), concatenated).unwrap();
            if done > 0 {
                assert_eq!(done, 2, "{estimator}: the shards agree that the draws are all in");
                break;
            }
            steps += 1;
            assert!(steps <= most, "{estimator}: more than {most} stages dealt");
        }
        assert!(steps >= 1, "{estimator}: at least one stage dealt");
        assert_exit(&estimate(&joined, &[&flags[..], &["--resume"]].concat()), 0, &[]);
        assert_eq!(files(&joined), files(&whole), "{estimator}");
    }
}

#[test]
fn resume_and_shards_refuse_what_they_cannot_continue() {
    let d = tempfile::tempdir().unwrap();
    for bad in ["0/0", "3/2", "1/0", "2"] {
        assert_exit(
            &estimate(&d.path().join("x"), &["--budget", "50", "--shard", bad]),
            2,
            &["--shard", bad],
        );
    }
    let out = d.path().join("out");
    let flags = ["--budget", "50", "--seed", "5"];
    assert_exit(&estimate(&out, &flags), 0, &[]);
    let file = out.join("estimate.jsonl");
    let whole = std::fs::read_to_string(&file).unwrap();
    // `merge` joins batch runs: an estimate's shards are concatenated and resumed.
    assert_exit(
        &run_cli(&[
            "merge",
            file.to_str().unwrap(),
            "--out",
            d.path().join("m.jsonl").to_str().unwrap(),
        ]),
        2,
        &["estimate.jsonl", "an estimate's draws", "unforeseen estimate --resume"],
    );
    // Another request's file: its identity line says what differs.
    let run = estimate(&out, &["--budget", "50", "--seed", "6", "--resume"]);
    assert_exit(
        &run,
        2,
        &[
            "estimate.jsonl",
            "line 1",
            "another estimate",
            "seed: the file has 5, this run 6",
        ],
    );
    // A damaged line, an edited one, a draw moved, a draw twice: each named by its line.
    let lines: Vec<String> = whole.lines().map(str::to_string).collect();
    let resume_with = |changed: &[String]| {
        std::fs::write(&file, changed.join("\n") + "\n").unwrap();
        estimate(&out, &[&flags[..], &["--resume"]].concat())
    };
    let with_line = |line: usize, text: String| {
        let mut l = lines.clone();
        l[line - 1] = text;
        l
    };
    assert_exit(
        &resume_with(&with_line(3, "{\"draw\": 1, oops".into())),
        2,
        &["estimate.jsonl", "line 3: not a draw line"],
    );
    let extra = format!("{},\"note\":1}}", lines[3].strip_suffix('}').unwrap());
    assert_exit(
        &resume_with(&with_line(4, extra)),
        2,
        &["line 4 (draw 2)", "not a line this program writes"],
    );
    let at = lines[4].find("\"point\":[").unwrap() + "\"point\":[".len();
    let end = at + lines[4][at..].find([',', ']']).unwrap();
    let moved = format!("{}0.123{}", &lines[4][..at], &lines[4][end..]);
    assert_exit(
        &resume_with(&with_line(5, moved)),
        2,
        &["line 5 (draw 3)", "not the draw this estimate derives", "point differs"],
    );
    assert!(
        !out.join("estimate.jsonl.part").exists(),
        "a refusal leaves the folder as it was"
    );
    // A valid draw again with another failure count.
    let (n, valid) = lines
        .iter()
        .enumerate()
        .find(|(_, l)| l.contains("\"rejected\":null"))
        .unwrap();
    let flipped = if valid.contains("\"failed\":1") {
        valid.replace("\"failed\":1", "\"failed\":0")
    } else {
        valid.replace("\"failed\":0", "\"failed\":1")
    };
    let twice = [&lines[..], &[flipped]].concat();
    assert_exit(
        &resume_with(&twice),
        2,
        &[
            &format!("line {} (draw {})", lines.len() + 1, n - 1),
            &format!("twice, line {} otherwise", n + 1),
        ],
    );
    // The same draw twice, line for line (shards' files concatenated), is one draw.
    let again = [&lines[..], &[lines[n].clone()]].concat();
    assert_exit(&resume_with(&again), 0, &[]);
    assert_eq!(std::fs::read_to_string(&file).unwrap(), whole);
}
