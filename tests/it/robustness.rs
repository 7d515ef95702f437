//! Issue 25: a closed pipe never reports success, an output never clobbers an input,
//! and nothing mixes runs silently. Each test is one class of the issue, run on the
//! built binary with tiny agents and one-episode batches of a scripted method.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_unforeseen"))
}

use crate::common::{assert_exit as assert_code, output_text as text, run_cli as unforeseen};

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A tiny agent file in `dir` (3 training episodes on the embedded intersection).
fn agent(dir: &Path) -> PathBuf {
    let path = dir.join("a.ron");
    let out = unforeseen(&["train", "--episodes", "3", "-q", "--out", s(&path)]);
    assert!(out.status.success(), "{}", text(&out));
    path
}

/// A one-episode never-brake batch of jaywalk into `out` with the agent `a`.
fn batch(a: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "batch",
        "maps/jaywalk.ron",
        "--method",
        "never-brake",
        "--episodes",
        "1",
        "-q",
        "--agent",
        s(a),
        "--out",
        s(out),
    ];
    args.extend_from_slice(extra);
    unforeseen(&args)
}

/// Runs the binary with stdout and stderr pipes whose readers have gone (closed before
/// the program writes anything).
fn closed_pipes(args: &[&str]) -> Output {
    let mut child = bin()
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("run the binary");
    drop(child.stdout.take());
    drop(child.stderr.take());
    child.wait_with_output().unwrap()
}

#[test]
fn a_closed_pipe_changes_neither_the_work_nor_the_exit_code() {
    let dir = tempfile::tempdir().unwrap();
    // train: the agent is written, exit 0.
    let t = dir.path().join("t.ron");
    let out = closed_pipes(&["train", "--episodes", "3", "--out", s(&t)]);
    assert_eq!(out.status.code(), Some(0));
    assert!(t.is_file(), "train wrote nothing under a closed pipe");
    // check-map on a bad map: exit 2, as without the pipe.
    let bad = dir.path().join("bad.ron");
    std::fs::write(&bad, "Map(road: (lane_width: -1.0))").unwrap();
    assert_eq!(closed_pipes(&["check-map", s(&bad)]).status.code(), Some(2));
    // batch with a failed expectation: exit 1 and both files written.
    let map = dir.path().join("fails.ron");
    std::fs::write(
        &map,
        "Map(base: \"jaywalk\", name: \"fails\", expect: [(method: NeverBrake, min_reward: 1000000.0)])",
    )
    .unwrap();
    let a = agent(dir.path());
    let results = dir.path().join("r.jsonl");
    let out = closed_pipes(&[
        "batch",
        s(&map),
        "--method",
        "never-brake",
        "--episodes",
        "1",
        "--agent",
        s(&a),
        "--out",
        s(&results),
    ]);
    assert_eq!(out.status.code(), Some(1));
    assert!(results.is_file() && dir.path().join("r.summary.json").is_file());
    // A full disk under stdout is not a closed pipe: the run fails, naming the stream.
    let out = bin()
        .args(["check-map", "maps/jaywalk.ron", "--survivability-episodes", "0"])
        .stdout(std::fs::File::create("/dev/full").unwrap())
        .output()
        .unwrap();
    assert_code(&out, 1, &["cannot write stdout"]);
    // eval: its report is written.
    let eval_dir = dir.path().join("eval");
    let out = closed_pipes(&[
        "eval",
        "--method",
        "never-brake",
        "--episodes",
        "1",
        "--out",
        s(&eval_dir),
    ]);
    assert_eq!(out.status.code(), Some(0));
    assert!(eval_dir.join("eval.json").is_file());
}

#[test]
fn an_output_that_is_an_input_is_refused_naming_both_flags() {
    let dir = tempfile::tempdir().unwrap();
    let a = agent(dir.path());
    let before = std::fs::read(&a).unwrap();
    let map = dir.path().join("my.ron");
    std::fs::copy("maps/jaywalk.ron", &map).unwrap();
    let link = dir.path().join("link.ron");
    std::os::unix::fs::symlink(&a, &link).unwrap();
    assert_code(
        &unforeseen(&[
            "batch",
            s(&map),
            "--agent",
            s(&a),
            "--method",
            "never-brake",
            "--episodes",
            "1",
            "--out",
            s(&map),
        ]),
        2,
        &["--out", "MAP"],
    );
    assert_code(&batch(&a, &a, &[]), 2, &["--out", "--agent"]);
    assert_code(
        &unforeseen(&["trace", "--agent", s(&a), "--html", s(&link), "-q"]),
        2,
        &["--html", "--agent"],
    );
    assert_code(
        &unforeseen(&["export-model", "--agent", s(&a), "--out", s(&a)]),
        2,
        &["--out", "--agent"],
    );
    assert_eq!(std::fs::read(&a).unwrap(), before);
    assert_eq!(std::fs::read(&map).unwrap(), std::fs::read("maps/jaywalk.ron").unwrap());
}

#[test]
fn batch_replaces_only_results_files_and_one_run_at_a_time() {
    let dir = tempfile::tempdir().unwrap();
    let a = agent(dir.path());
    let precious = dir.path().join("precious.txt");
    std::fs::write(&precious, "my notes\n").unwrap();
    assert_code(&batch(&a, &precious, &[]), 2, &["precious.txt", "--force"]);
    assert_eq!(std::fs::read_to_string(&precious).unwrap(), "my notes\n");
    assert_code(&batch(&a, &precious, &["--force"]), 0, &[]);
    // A results file is replaced by a rerun.
    assert_code(&batch(&a, &precious, &[]), 0, &[]);
    // While another run holds the lock, a second is refused.
    let lock = std::fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(dir.path().join("precious.txt.lock"))
        .unwrap();
    lock.lock().unwrap();
    assert_code(&batch(&a, &precious, &[]), 2, &["another run"]);
    drop(lock);
    // A folder with no maps is an error; an empty shard says so.
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).unwrap();
    let out = dir.path().join("e.jsonl");
    assert_code(
        &unforeseen(&["batch", s(&empty), "--agent", s(&a), "--out", s(&out), "-q"]),
        2,
        &["no map files"],
    );
    assert_code(
        &batch(&a, &out, &["--shard", "5/1000"]),
        0,
        &["shard 5/1000 has no units"],
    );
}

/// The lines of a one-episode batch results file, as JSON values (the header first).
fn lines(path: &Path) -> Vec<serde_json::Value> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

fn write_lines(path: &Path, lines: &[serde_json::Value]) {
    let text: String = lines.iter().map(|l| format!("{l}\n")).collect();
    std::fs::write(path, text).unwrap();
}

#[test]
fn resume_refuses_lines_of_another_run_or_out_of_range() {
    let dir = tempfile::tempdir().unwrap();
    let a = agent(dir.path());
    let out = dir.path().join("r.jsonl");
    assert_code(&batch(&a, &out, &["--seed", "7"]), 0, &[]);
    let good = lines(&out);
    assert_eq!(good.len(), 2);
    for (field, value, needle) in [
        ("seed", serde_json::json!(8), "seed 8"),
        ("episodes", serde_json::json!(4), "4 episodes"),
        ("success_rate", serde_json::json!(7.5), "success_rate 7.5"),
        ("mean_reward", serde_json::json!(1e300), "mean_reward"),
    ] {
        let mut spliced = good.clone();
        spliced[1][field] = value;
        write_lines(&out, &spliced);
        assert_code(&batch(&a, &out, &["--seed", "7", "--resume"]), 2, &["line 2", needle]);
    }
    // A last line cut inside a UTF-8 character (a full disk) is a cut line: resumed.
    write_lines(&out, &good[..1]);
    let mut f = std::fs::OpenOptions::new().append(true).open(&out).unwrap();
    f.write_all(&"{\"scenario\":\"é".as_bytes()[..14]).unwrap();
    drop(f);
    assert_code(&batch(&a, &out, &["--seed", "7", "--resume"]), 0, &[]);
    assert_eq!(lines(&out).len(), 2);
    // Binary garbage is bad input (exit 2), for --resume and plot-sweep alike.
    let garbage = dir.path().join("g.jsonl");
    std::fs::write(&garbage, [0xff, 0xfe, 0x00, b'\n', 0x80]).unwrap();
    assert_code(&batch(&a, &garbage, &["--resume"]), 2, &["UTF-8"]);
    let svg = dir.path().join("s.svg");
    assert_code(
        &unforeseen(&["plot-sweep", s(&garbage), "--out", s(&svg)]),
        2,
        &["UTF-8"],
    );
}

#[test]
fn plot_sweep_refuses_two_runs_and_reports_cut_and_repeated_lines() {
    let dir = tempfile::tempdir().unwrap();
    let a = agent(dir.path());
    let one = dir.path().join("one.jsonl");
    let two = dir.path().join("two.jsonl");
    assert_code(&batch(&a, &one, &["--seed", "7"]), 0, &[]);
    assert_code(&batch(&a, &two, &["--seed", "8"]), 0, &[]);
    let (l1, l2) = (lines(&one), lines(&two));
    let both = dir.path().join("both.jsonl");
    write_lines(&both, &[&l1[..], &l2[..]].concat());
    let svg = dir.path().join("s.svg");
    assert_code(
        &unforeseen(&["plot-sweep", s(&both), "--out", s(&svg)]),
        2,
        &["two runs", "seed"],
    );
    let dup = dir.path().join("dup.jsonl");
    write_lines(&dup, &[l1[0].clone(), l1[1].clone(), l1[1].clone()]);
    let mut f = std::fs::OpenOptions::new().append(true).open(&dup).unwrap();
    f.write_all(b"{\"unit\": 0, \"scen").unwrap();
    drop(f);
    assert_code(
        &unforeseen(&["plot-sweep", s(&dup), "--out", s(&svg)]),
        0,
        &["line 4 is cut", "1 line(s) repeat"],
    );
}

#[test]
fn flags_and_output_paths_are_checked_before_any_work() {
    for bad in [" 5", "+5", "5 "] {
        assert_code(&unforeseen(&["eval", "--episodes", bad]), 2, &["digits only"]);
    }
    assert_code(
        &unforeseen(&["check-map", "maps/jaywalk.ron", "--survivability-episodes", "2000000"]),
        2,
        &["at most"],
    );
    // Refused at once, before the default training of 6000 episodes.
    let started = Instant::now();
    assert_code(&unforeseen(&["compare", "--out", "/dev/full", "-q"]), 2, &["/dev/full"]);
    assert_code(
        &unforeseen(&["batch", "maps/jaywalk.ron", "--out", "/proc/version", "-q"]),
        2,
        &["/proc"],
    );
    assert!(started.elapsed() < Duration::from_secs(5));
    // No advice to write an agent over a device.
    let out = unforeseen(&["eval", "--agent", "/dev/zero", "--episodes", "1"]);
    assert_code(&out, 2, &["not a regular file"]);
    assert!(!text(&out).contains("--out /dev/zero"), "{}", text(&out));
    // A huge RAYON_NUM_THREADS is capped, with a warning.
    let dir = tempfile::tempdir().unwrap();
    let out = bin()
        .args(["eval", "--method", "never-brake", "--episodes", "1", "-q", "--out"])
        .arg(dir.path())
        .env("RAYON_NUM_THREADS", "100000")
        .output()
        .unwrap();
    assert_code(&out, 0, &["RAYON_NUM_THREADS", "256"]);
}

#[test]
fn map_validation_edges_of_issue_25() {
    let dir = tempfile::tempdir().unwrap();
    // A light phase of 0 s is refused like one shorter than a sub-step.
    let zero = dir.path().join("zero.ron");
    std::fs::write(
        &zero,
        "Map(light: (cycle: [(phase: Green, duration: 0.0), (phase: Red, duration: 5.0)]))",
    )
    .unwrap();
    let err = unforeseen_sim::Map::load(&zero).unwrap_err().to_string();
    assert!(err.contains("light.cycle[0].duration"), "{err}");
    // A chain of exactly MAX_BASE_DEPTH base maps is accepted; one more is refused.
    let depth = unforeseen_sim::MAX_BASE_DEPTH;
    std::fs::write(dir.path().join("m0.ron"), "Map()").unwrap();
    for i in 1..=depth + 1 {
        std::fs::write(
            dir.path().join(format!("m{i}.ron")),
            format!("Map(base: \"m{}.ron\")", i - 1),
        )
        .unwrap();
    }
    let top = |i: usize| unforeseen_sim::Map::load(&dir.path().join(format!("m{i}.ron")));
    assert!(top(depth).is_ok(), "{:?}", top(depth).err().map(|e| e.to_string()));
    let err = top(depth + 1).unwrap_err().to_string();
    assert!(err.contains("levels of base maps"), "{err}");
    // A map whose Bayesian-RL episode would plan for minutes is refused (the issue's map).
    let long = dir.path().join("long.ron");
    std::fs::write(
        &long,
        "Map(light: (cycle: [(phase: Green, duration: 3600.0)]), episode: (max_steps: 100000, decision_dt: 0.05, physics_hz: 20.0))",
    )
    .unwrap();
    let err = unforeseen_sim::Map::load(&long).unwrap_err().to_string();
    assert!(
        err.contains("episode.max_steps") && err.contains("at most 12207 ticks"),
        "{err}"
    );
    // A base that is a folder says so, as the same path given directly does.
    std::fs::create_dir(dir.path().join("folder.ron")).unwrap();
    let uses = dir.path().join("uses.ron");
    std::fs::write(&uses, "Map(base: \"folder.ron\")").unwrap();
    let err = unforeseen_sim::Map::load(&uses).unwrap_err().to_string();
    assert!(err.contains("not a regular file"), "{err}");
}

#[test]
fn sigint_leaves_no_temporary_file_and_exits_130() {
    let dir = tempfile::tempdir().unwrap();
    let t = dir.path().join("t.ron");
    let child = bin()
        .args(["train", "--episodes", "1000000", "-q", "--out"])
        .arg(&t)
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(300));
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{}", String::from_utf8_lossy(&out.stderr));
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(left.is_empty(), "{left:?}");
}
