//! The command line on bad arguments and bad files: exit code 2, a message that names
//! the file and the fix, and never a panic.

use std::path::Path;
use std::process::{Command, Output};

use crate::common::{output_text as text, run_cli as unforeseen};

fn assert_bad_input(out: &Output, needles: &[&str]) {
    crate::common::assert_exit(out, 2, needles);
}

#[test]
fn unknown_commands_flags_and_values_exit_2() {
    assert_bad_input(&unforeseen(&["fly"]), &["fly"]);
    assert_bad_input(&unforeseen(&["compare", "--episodes", "many"]), &["many"]);
    assert_bad_input(&unforeseen(&["eval", "--method", "magic"]), &["magic"]);
    assert_bad_input(&unforeseen(&["batch", "--shard", "4/3"]), &["4/3"]);
    // Episode counts: at least one, and bounded (a huge count used to abort on allocation).
    for cmd in ["eval", "batch", "compare", "learn", "train"] {
        assert_bad_input(&unforeseen(&[cmd, "--episodes", "0"]), &["--episodes", "at least 1"]);
        assert_bad_input(
            &unforeseen(&[cmd, "--episodes", "4294967296"]),
            &["--episodes", "at most"],
        );
    }
    assert_bad_input(
        &unforeseen(&["compare", "--train-episodes", "0"]),
        &["--train-episodes"],
    );
}

#[test]
fn bad_sweeps_and_job_counts_exit_2() {
    let batch = |extra: &[&str]| {
        let mut args = vec![
            "batch",
            "maps/jaywalk.ron",
            "--method",
            "never-brake",
            "--episodes",
            "1",
        ];
        args.extend_from_slice(extra);
        unforeseen(&args)
    };
    assert_bad_input(&batch(&["--jobs", "0"]), &["--jobs", "1 to 256"]);
    assert_bad_input(&batch(&["--jobs", "100000"]), &["--jobs", "1 to 256"]);
    assert_bad_input(&batch(&["--set", "horizon=1,,2"]), &["horizon=1,,2", "empty value"]);
    assert_bad_input(
        &batch(&["--set", "horizon=1", "--set", "horizon=2"]),
        &["horizon", "set twice"],
    );
    assert_bad_input(
        &batch(&["--set", "max_scaling_iters=4294967297"]),
        &["max_scaling_iters", "1..=10000"],
    );
    // A cross product beyond the bound is refused before anything is built.
    let many: String = (1..=200).map(|i| format!("0.{i:03}")).collect::<Vec<_>>().join(",");
    let (omega, gamma) = (format!("omega={many}"), format!("gamma={many}"));
    assert_bad_input(
        &batch(&["--set", &omega, "--set", &gamma]),
        &["40000 parameter sets", "at most 10000"],
    );
}

#[test]
fn bad_parameter_overrides_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let agent = dir.path().join("a.ron");
    assert!(
        unforeseen(&["train", "--episodes", "3", "--out", agent.to_str().unwrap(), "-q"])
            .status
            .success()
    );
    let a = agent.to_str().unwrap();
    assert_bad_input(
        &unforeseen(&["eval", "--agent", a, "--episodes", "1", "--set", "omega"]),
        &["KEY=VALUE"],
    );
    assert_bad_input(
        &unforeseen(&["eval", "--agent", a, "--episodes", "1", "--set", "colour=red"]),
        &["colour", "omega"],
    );
    assert_bad_input(
        &unforeseen(&["eval", "--agent", a, "--episodes", "1", "--set", "gamma=-1"]),
        &["gamma"],
    );
    assert_bad_input(
        &unforeseen(&["eval", "--agent", a, "--episodes", "1", "--set", "scaling_mode=fast"]),
        &["scaling_mode", "iterative, closed-form"],
    );
    assert_bad_input(
        &unforeseen(&["eval", "--agent", a, "--episodes", "1", "--set", "gate_factor=x"]),
        &["gate_factor", "d, v, L, p"],
    );
    // Every parameter is settable from the command line, the closed form of Theorem 1 too.
    let out = unforeseen(&[
        "eval",
        "--agent",
        a,
        "--episodes",
        "1",
        "--set",
        "scaling_mode=closed-form",
        "--set",
        "perception.vmp_tol=1e-4",
    ]);
    assert!(out.status.success(), "{}", text(&out));
}

#[test]
fn missing_and_bad_maps_exit_2_naming_the_file() {
    assert_bad_input(
        &unforeseen(&["eval", "--map", "no/such/map.ron"]),
        &["no/such/map.ron", "embedded maps"],
    );
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.ron");
    std::fs::write(&bad, "(name: \"x\", road: (goal_x: -5.0, lane_width: 3.5)").unwrap();
    assert_bad_input(&unforeseen(&["check-map", bad.to_str().unwrap()]), &["bad.ron"]);
    std::fs::write(&bad, [0u8, 159, 146, 150, 0, 1]).unwrap();
    assert_bad_input(&unforeseen(&["check-map", bad.to_str().unwrap()]), &["bad.ron"]);
    // A map error reaching a command through the map lookup is printed once, not twice.
    std::fs::write(&bad, "Map(base: \"nowhere\")").unwrap();
    let out = unforeseen(&["eval", "--map", bad.to_str().unwrap(), "--method", "never-brake"]);
    assert_bad_input(&out, &["bad.ron", "\"nowhere\" not found"]);
    assert_eq!(text(&out).matches("not found").count(), 1, "{}", text(&out));
    // Expectations name this program's methods and protocols; check-map and batch say
    // which field is wrong and what it may be.
    std::fs::write(
        &bad,
        "Map(expect: [(method: Scaled), (method: Scaled), (method: Scald, protocol: Continual)])",
    )
    .unwrap();
    let expect_error = [
        "bad.ron",
        "expect[2].method",
        "unknown method `Scald`",
        "QLearning, BayesRl",
    ];
    assert_bad_input(&unforeseen(&["check-map", bad.to_str().unwrap()]), &expect_error);
    assert_bad_input(
        &unforeseen(&["batch", bad.to_str().unwrap(), "--episodes", "1"]),
        &expect_error,
    );
}

#[test]
fn missing_corrupt_and_foreign_agent_files_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.ron");
    assert_bad_input(
        &unforeseen(&["eval", "--agent", missing.to_str().unwrap()]),
        &["missing.ron", "unforeseen train"],
    );
    let corrupt = dir.path().join("corrupt.ron");
    std::fs::write(&corrupt, "(format_version: 1, q_learning: (").unwrap();
    assert_bad_input(
        &unforeseen(&["eval", "--agent", corrupt.to_str().unwrap()]),
        &["corrupt.ron"],
    );
    let foreign = dir.path().join("foreign.ron");
    std::fs::write(&foreign, "(format_version: 999)").unwrap();
    assert_bad_input(
        &unforeseen(&["eval", "--agent", foreign.to_str().unwrap()]),
        &["foreign.ron"],
    );
}

#[test]
fn inspect_rejects_bad_models_and_check_map_accepts_the_shipped_maps() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("m.json");
    std::fs::write(&model, r#"{"A": [[0.5, 0.5], [0.4, 0.5]], "B": [[[1,0],[0,1]]], "C": [0,0], "D": [0.5,0.5], "obs": [0], "actions": [], "policy_len": 1, "gamma": 1.0}"#).unwrap();
    assert_bad_input(
        &unforeseen(&["inspect", "--model", model.to_str().unwrap()]),
        &["m.json", "A"],
    );
    let maps: Vec<String> = std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("maps"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "ron"))
        .map(|p| p.display().to_string())
        .collect();
    assert!(maps.len() >= 4);
    // A few survivability episodes per map keep the check exercised but the test fast
    // (tests/it/reference.rs tests the warnings themselves).
    let mut args = vec!["check-map", "--survivability-episodes", "5"];
    args.extend(maps.iter().map(String::as_str));
    let out = unforeseen(&args);
    assert!(out.status.success(), "{}", text(&out));
}

#[test]
fn export_model_writes_what_inspect_reads_and_rejects_bad_observations() {
    let dir = tempfile::tempdir().unwrap();
    let agent = dir.path().join("a.ron");
    let a = agent.to_str().unwrap();
    assert!(
        unforeseen(&["train", "--episodes", "3", "--out", a, "-q"])
            .status
            .success()
    );
    let model = dir.path().join("model.json");
    let m = model.to_str().unwrap();
    let out = unforeseen(&["export-model", "--agent", a, "--set", "horizon=2", "--out", m]);
    assert!(out.status.success(), "{}", text(&out));
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(json["B"].as_array().unwrap().len(), 3);
    assert_eq!(json["policy_len"], 2);
    let out = unforeseen(&["inspect", "--model", m]);
    assert!(out.status.success(), "{}", text(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["G"].as_array().unwrap().len(), 9);
    let bad = dir.path().join("bad.json");
    let b = bad.to_str().unwrap();
    assert_bad_input(
        &unforeseen(&["export-model", "--agent", a, "--obs", "1,2,5,0", "--out", b]),
        &["--obs", "L=5", "0..2"],
    );
    assert_bad_input(
        &unforeseen(&["export-model", "--agent", a, "--obs", "1,2", "--out", b]),
        &["--obs", "4 factors"],
    );
    assert!(!bad.exists(), "no file on bad input");
}

#[test]
fn a_closed_output_pipe_ends_the_program_quietly() {
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("m.json");
    std::fs::write(&model, r#"{"A": [[1,0],[0,1]], "B": [[[1,0],[0,1]]], "C": [0,0], "D": [0.5,0.5], "obs": [0], "actions": [], "policy_len": 1, "gamma": 1.0}"#).unwrap();
    let m = model.to_str().unwrap();
    // `check-map ... | head` and `inspect --model m.json | head`.
    for args in [
        &["check-map", "maps/jaywalk.ron", "--survivability-episodes", "0"][..],
        &["inspect", "--model", m][..],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_unforeseen"))
            .args(args)
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("run the binary");
        // Close the reading end before the program prints (it first reads its input).
        drop(child.stdout.take());
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            out.status.success() && !err.contains("panicked"),
            "{args:?}: {:?}: {err}",
            out.status
        );
    }
}

#[test]
fn only_regular_files_are_read_or_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let fifo = dir.path().join("pipe.ron");
    assert!(Command::new("mkfifo").arg(&fifo).status().unwrap().success());
    let f = fifo.to_str().unwrap();
    // A named pipe would block forever: refused at once.
    assert_bad_input(&unforeseen(&["check-map", f]), &["pipe.ron", "not a regular file"]);
    assert_bad_input(
        &unforeseen(&["eval", "--agent", f, "--map", "jaywalk", "--episodes", "1"]),
        &["pipe.ron", "not a regular file"],
    );
    // An output path that is not a regular file (here a folder) is refused, not replaced.
    let out = dir.path().join("taken");
    std::fs::create_dir(&out).unwrap();
    let o = out.to_str().unwrap();
    assert_bad_input(
        &unforeseen(&["train", "--episodes", "1", "-q", "--out", o]),
        &["taken", "not a regular file"],
    );
    assert!(out.is_dir());
}

/// Flags and maps that ask for more memory than any machine has, e.g. a VMP window of
/// 99999999999 ticks (2.4 TB) or a map of 64 x 64 bin edges, are refused up front with
/// the bound and its reason (not an allocation abort).
#[test]
fn allocation_bounds_are_stated_and_enforced() {
    assert_bad_input(
        &unforeseen(&["eval", "--set", "vmp_window=99999999999", "--episodes", "1"]),
        &["vmp_window", "1..=1000"],
    );
    assert_bad_input(
        &unforeseen(&[
            "batch",
            "maps/jaywalk.ron",
            "--method",
            "never-brake",
            "--episodes",
            "1",
            "--set",
            "max_scaling_iters=4000000",
        ]),
        &["max_scaling_iters", "1..=10000"],
    );
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("fine_bins.ron");
    let edges = |step: f64| {
        (0..64)
            .map(|i| format!("{:.1}", i as f64 * step))
            .collect::<Vec<_>>()
            .join(", ")
    };
    std::fs::write(
        &map,
        format!(
            "Map(bins: (distance_edges: [{}], speed_edges: [{}]))",
            edges(1.0),
            edges(0.1)
        ),
    )
    .unwrap();
    let out = dir.path().join("agent.ron");
    assert_bad_input(
        &unforeseen(&[
            "train",
            "--map",
            map.to_str().unwrap(),
            "--episodes",
            "1",
            "-q",
            "--out",
            out.to_str().unwrap(),
        ]),
        &["fine_bins.ron", "bins", "at most 1024"],
    );
    assert!(!out.exists());
}

/// `run-model` runs the gated agent on the shipped T-maze files and says which file is
/// wrong when one is; `inspect` takes the same multi-factor model.
#[test]
fn run_model_runs_the_gated_tmaze_and_names_a_bad_file() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models");
    let model = root.join("tmaze_model.json");
    let env = root.join("tmaze_env.json");
    let (m, e) = (model.to_str().unwrap(), env.to_str().unwrap());
    let args = [
        "run-model",
        "--model",
        m,
        "--env",
        e,
        "--episodes",
        "3",
        "--steps",
        "5",
        "--epsilon",
        "0.5",
        "--learn",
    ];
    let out = unforeseen(&args);
    assert!(out.status.success(), "{}", text(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["episodes"].as_array().unwrap().len(), 3);
    let f = v["planned_fraction"].as_f64().unwrap();
    assert!(f > 0.0 && f < 1.0, "planned fraction {f}");
    assert_eq!(unforeseen(&args).stdout, out.stdout, "same seed, same run");

    let dir = tempfile::tempdir().unwrap();
    let mut bad: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&env).unwrap()).unwrap();
    bad["B"][1] = serde_json::json!([[[0.5], [0.0]], [[0.2], [1.0]]]);
    let bad_env = dir.path().join("env.json");
    std::fs::write(&bad_env, bad.to_string()).unwrap();
    assert_bad_input(
        &unforeseen(&["run-model", "--model", m, "--env", bad_env.to_str().unwrap()]),
        &["env.json", "B[1] column (s=0, u=0) sums to 0.7, must be 1"],
    );
    bad["B"] = serde_json::json!([bad["B"][0].clone()]);
    bad["B_dependencies"] = serde_json::json!([[0]]);
    bad["A_dependencies"] = serde_json::json!([[0], [0, 3], [0, 1]]);
    std::fs::write(&bad_env, bad.to_string()).unwrap();
    assert_bad_input(
        &unforeseen(&["run-model", "--model", m, "--env", bad_env.to_str().unwrap()]),
        &[
            "env.json",
            "A_dependencies[1] lists factor 3, but the model has 1 factors",
        ],
    );

    let mut run: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    run["obs"] = serde_json::json!([[0, 0, 0], [3, 0, 1]]);
    run["actions"] = serde_json::json!([[3, 0]]);
    let run_file = dir.path().join("run.json");
    std::fs::write(&run_file, run.to_string()).unwrap();
    let out = unforeseen(&["inspect", "--model", run_file.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out));
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(r["qs"].as_array().unwrap().len(), 2, "one marginal per factor");
    assert_eq!(r["G"].as_array().unwrap().len(), 125);
}
