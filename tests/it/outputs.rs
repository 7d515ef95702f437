//! Where results go and what a run says while it works: `--help` names every command's
//! default output; a rerun that replaces an earlier run's files warns on stderr; when
//! stderr is not a terminal (here: a pipe), each phase of a run prints one line.

use std::process::{Command, Output};

fn unforeseen(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_unforeseen"))
        .args(args)
        .output()
        .expect("run the binary");
    assert!(
        out.status.success(),
        "{args:?}: {}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

#[test]
fn help_names_the_default_outputs() {
    let top = String::from_utf8(unforeseen(&["--help"]).stdout).unwrap();
    for (command, default) in [
        ("compare", "out/compare"),
        ("train", "agent.ron"),
        ("eval", "out/eval"),
        ("trace", "out/trace"),
        ("learn", "out/learn"),
        ("batch", "results.jsonl"),
        ("plot-sweep", "sweep.svg"),
        ("export-model", "out/model.json"),
    ] {
        assert!(top.contains(default), "--help names {default} for {command}:\n{top}");
        let help = String::from_utf8(unforeseen(&[command, "--help"]).stdout).unwrap();
        assert!(
            help.contains(&format!("[default: {default}]")),
            "{command} --help shows its default output {default}:\n{help}"
        );
    }
}

#[test]
fn eval_says_what_it_does_and_warns_when_it_replaces_a_result() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("eval");
    let args = [
        "eval",
        "--method",
        "brake-on-pedestrian",
        "--episodes",
        "3",
        "--out",
        out.to_str().unwrap(),
    ];
    let first = String::from_utf8(unforeseen(&args).stderr).unwrap();
    // Not a terminal: one line per phase, with the time since the start.
    assert!(
        first.contains("s] evaluating brake-on-pedestrian on 'jaywalk'"),
        "{first}"
    );
    assert!(first.contains("s] writing"), "{first}");
    assert!(!first.contains("replacing"), "nothing to replace yet:\n{first}");
    let second = String::from_utf8(unforeseen(&args).stderr).unwrap();
    assert!(second.contains("warning: replacing eval.json in"), "{second}");
    // Quiet: no phase lines, but the warning still.
    let quiet: Vec<&str> = args.iter().copied().chain(["-q"]).collect();
    let third = String::from_utf8(unforeseen(&quiet).stderr).unwrap();
    assert!(!third.contains("s] "), "{third}");
    assert!(third.contains("warning: replacing eval.json"), "{third}");
}

#[test]
fn compare_says_which_map_each_column_is_on_and_how_many_episodes_ran() {
    let dir = tempfile::tempdir().unwrap();
    let out = unforeseen(&[
        "compare",
        "--train-episodes",
        "150",
        "--episodes",
        "4",
        "--protocol",
        "zero-shot",
        "-q",
        "--out",
        dir.path().to_str().unwrap(),
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    for needle in [
        "train reward: on the training map 'intersection'; every other column: on the test map 'jaywalk'",
        "(intersection)",
        "(jaywalk)",
        "150 training episodes each), 4 evaluation episodes per method, map and agent",
        "(n/a)",
        "n/a: the paper gives no collision rate",
    ] {
        assert!(text.contains(needle), "the table says {needle:?}:\n{text}");
    }
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("compare.json")).unwrap()).unwrap();
    assert!(
        json["columns"]["train_reward"]
            .as_str()
            .unwrap()
            .contains("training map 'intersection'")
    );
    assert!(
        json["columns"]["collision_rate"]
            .as_str()
            .unwrap()
            .contains("paper gives no value")
    );
    assert!(
        json["paper"]
            .as_array()
            .unwrap()
            .iter()
            .all(|p| p["collision_rate"].is_null() && p["red_light_rate"].is_null())
    );
    assert!(json["columns"]["red_light_rate"].as_str().unwrap().contains("red"));
    assert!(
        text.contains("red lights"),
        "the table has the red-light column:\n{text}"
    );
    assert!(csv_header_has(&dir.path().join("compare.csv"), "red_light_rate"));
    let csv = std::fs::read_to_string(dir.path().join("compare.csv")).unwrap();
    assert!(csv.lines().next().unwrap().contains("train_map,test_map"), "{csv}");
    assert!(csv.lines().nth(1).unwrap().contains("intersection,jaywalk"), "{csv}");
}

/// Whether the first line of a CSV file names `column`.
fn csv_header_has(path: &std::path::Path, column: &str) -> bool {
    let csv = std::fs::read_to_string(path).unwrap();
    csv.lines().next().unwrap().split(',').any(|c| c == column)
}
