//! The output guard (`unforeseen_harness::runs::outputs`) on every command that writes
//! results: `search`, `merge`, and `eval`/`learn`/`batch` with `--stream` refuse, with
//! exit 2 and before any work, an output that is one of their inputs (a stream's maps,
//! any file inside a search's `--out`), an output that holds something else unless
//! `--force`, an output of the wrong kind, and a second writer; a space's name that
//! would become a path is refused up front; `search --resume` checks every kept line.

use std::path::Path;

use super::common::{assert_exit, output_text as common_text, run_cli};

const SPACE: &str = "maps/spaces/jaywalk.ron";

/// A quick search of `never-brake` (scripted: no agent) into `out`, with extra arguments.
fn search(out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "search",
        "--method",
        "never-brake",
        "--budget",
        "2",
        "--episodes",
        "1",
        "--seed",
        "9",
        "--jobs",
        "1",
        "--out",
        out.to_str().unwrap(),
    ];
    if !extra.contains(&"--space") {
        args.extend(["--space", SPACE]);
    }
    args.extend(extra);
    run_cli(&args)
}

fn read(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

#[test]
fn search_never_replaces_an_input_inside_its_out() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out");
    std::fs::create_dir_all(out.join("failures")).unwrap();
    let base = out.join("failures/jaywalk_space_c0046.ron");
    std::fs::copy("maps/jaywalk.ron", &base).unwrap();
    let other = out.join("failures/copied.ron");
    std::fs::copy("maps/crowd.ron", &other).unwrap();
    let r = search(&out, &["--map", base.to_str().unwrap()]);
    assert_exit(&r, 2, &["holds the file given as --map"]);
    assert_eq!(read(&base), read(Path::new("maps/jaywalk.ron")));
    assert_eq!(read(&other), read(Path::new("maps/crowd.ron")));
    // Inputs at the search's own file names, too.
    let space = out.join("candidates.jsonl");
    std::fs::copy(SPACE, &space).unwrap();
    let r = search(&out, &["--space", space.to_str().unwrap()]);
    assert_exit(&r, 2, &["--space"]);
    assert_eq!(read(&space), read(Path::new(SPACE)));
    let map = out.join("search.svg");
    std::fs::copy("maps/jaywalk.ron", &map).unwrap();
    assert_exit(&search(&out, &["--map", map.to_str().unwrap()]), 2, &["--map"]);
    assert_eq!(read(&map), read(Path::new("maps/jaywalk.ron")));
    // An agent file at the summary's name.
    let agent = out.join("summary.json");
    unforeseen_harness::training::agent_file::save(&agent, unforeseen_harness::fixtures::bundle()).unwrap();
    let before = read(&agent);
    let r = search(&out, &["--agent", agent.to_str().unwrap()]);
    assert_exit(&r, 2, &["--agent"]);
    assert_eq!(read(&agent), before);
}

#[test]
fn search_refuses_a_file_it_did_not_write_unless_forced() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out");
    std::fs::create_dir_all(out.join("failures")).unwrap();
    let mine = out.join("failures/mine.ron");
    std::fs::copy("maps/crowd.ron", &mine).unwrap();
    assert_exit(&search(&out, &[]), 2, &["mine.ron", "--force"]);
    assert_eq!(read(&mine), read(Path::new("maps/crowd.ron")));
    assert_exit(&search(&out, &["--force"]), 0, &[]);
    assert!(!mine.exists(), "--force replaces the set");
    // Its own outputs are replaced without --force.
    assert_exit(&search(&out, &[]), 0, &[]);
}

#[test]
fn search_checks_its_outputs_before_any_work() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("a");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("failures"), "a file").unwrap();
    assert_exit(&search(&out, &[]), 2, &["failures", "not a folder"]);
    assert!(!out.join("candidates.jsonl").exists(), "refused before any work");
    let out = d.path().join("b");
    std::fs::create_dir_all(out.join("summary.json")).unwrap();
    assert_exit(&search(&out, &[]), 2, &["summary.json", "not a regular file"]);
    assert!(!out.join("candidates.jsonl").exists(), "refused before any work");
    // --budget 0 is refused without creating --out.
    let out = d.path().join("c");
    assert_exit(&search(&out, &["--budget", "0"]), 2, &["--budget"]);
    assert!(!out.exists(), "--budget 0 created {}", out.display());
}

#[test]
fn a_second_search_into_one_out_is_refused() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out");
    std::fs::create_dir_all(&out).unwrap();
    // Another search holds the folder's lock.
    let lock = std::fs::File::create(out.join(".lock")).unwrap();
    lock.try_lock().unwrap();
    assert_exit(&search(&out, &[]), 2, &["another run is writing"]);
    drop(lock);
    assert_exit(&search(&out, &[]), 0, &[]);
}

#[test]
fn a_space_name_that_is_a_path_is_refused_up_front() {
    let d = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(SPACE).unwrap();
    let long = "x".repeat(300);
    for name in ["../../escaped", "/tmp/x/absname", "a\\nb", long.as_str()] {
        let space = d.path().join("s.ron");
        let named = text.replacen("name: \"jaywalk_space\"", &format!("name: \"{name}\""), 1);
        std::fs::write(&space, named).unwrap();
        let out = d.path().join("deep/out");
        let r = search(&out, &["--space", space.to_str().unwrap()]);
        assert_exit(&r, 2, &["name", "file name"]);
        assert!(!out.exists(), "{name}: refused before writing");
        assert!(!d.path().join("escaped_c0000.ron").exists());
    }
}

#[test]
fn search_resume_checks_every_kept_line() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("out");
    assert_exit(&search(&out, &[]), 0, &[]);
    let file = out.join("candidates.jsonl");
    let text = std::fs::read_to_string(&file).unwrap();
    assert_exit(&search(&out, &["--resume"]), 0, &[]);
    let line = text.lines().nth(1).expect("a candidate line");
    let value: serde_json::Value = serde_json::from_str(line).unwrap();
    let edits: [(&str, serde_json::Value); 8] = [
        ("success_rate", (-3.0).into()),
        ("mean_reward", 1e300.into()),
        ("unit", 99.into()),
        ("scenario", "other".into()),
        ("method", "scaled".into()),
        ("protocol", "continual".into()),
        ("train_seed", 3.into()),
        ("surprise", 1.into()),
    ];
    for (field, v) in edits {
        let mut edited = value.clone();
        edited[field] = v;
        let bad = text.replacen(line, &edited.to_string(), 1);
        std::fs::write(&file, &bad).unwrap();
        assert_exit(&search(&out, &["--resume"]), 2, &["--resume: line 2"]);
        assert_eq!(
            std::fs::read_to_string(&file).unwrap(),
            bad,
            "{field}: the file is left as it was"
        );
    }
}

/// A stream file in `dir` listing the map file `map` (relative to the stream).
fn stream_with(dir: &Path, map: &str) -> std::path::PathBuf {
    let s = dir.join("s.ron");
    std::fs::write(
        &s,
        format!("Stream(maps: [(map: \"{map}\", weight: 1), (map: \"jaywalk\", weight: 1)], order: Sequence)"),
    )
    .unwrap();
    s
}

#[test]
fn a_streams_maps_are_inputs() {
    let d = tempfile::tempdir().unwrap();
    let map = d.path().join("mine.ron");
    std::fs::copy("maps/crowd.ron", &map).unwrap();
    let stream = stream_with(d.path(), "mine.ron");
    let s = stream.to_str().unwrap();
    let before = read(&map);
    let batch = |out: &Path| {
        run_cli(&[
            "batch",
            "--stream",
            s,
            "--method",
            "never-brake",
            "--episodes",
            "1",
            "--force",
            "--out",
            out.to_str().unwrap(),
        ])
    };
    assert_exit(&batch(&map), 2, &["--stream", "maps[0]"]);
    // The summary beside `X.jsonl` is `X.summary.json`.
    let summary_named = d.path().join("x.summary.json");
    std::fs::copy("maps/crowd.ron", &summary_named).unwrap();
    let stream2 = stream_with(d.path(), "x.summary.json");
    let r = run_cli(&[
        "batch",
        "--stream",
        stream2.to_str().unwrap(),
        "--method",
        "never-brake",
        "--episodes",
        "1",
        "--out",
        d.path().join("x.jsonl").to_str().unwrap(),
    ]);
    assert_exit(&r, 2, &["summary"]);
    assert_eq!(read(&summary_named), read(Path::new("maps/crowd.ron")));
    // eval --stream with a map at OUT/eval.json.
    let out = d.path().join("ev");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::copy("maps/crowd.ron", out.join("eval.json")).unwrap();
    let stream3 = stream_with(d.path(), "ev/eval.json");
    let r = run_cli(&[
        "eval",
        "--stream",
        stream3.to_str().unwrap(),
        "--method",
        "never-brake",
        "--episodes",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_exit(&r, 2, &["--stream"]);
    assert_eq!(read(&out.join("eval.json")), read(Path::new("maps/crowd.ron")));
    // learn --stream with a map at OUT/learn.csv (learn needs a real agent).
    let agent = d.path().join("agent.ron");
    unforeseen_harness::training::agent_file::save(&agent, unforeseen_harness::fixtures::bundle()).unwrap();
    let out = d.path().join("le");
    std::fs::create_dir_all(&out).unwrap();
    std::fs::copy("maps/crowd.ron", out.join("learn.csv")).unwrap();
    let stream4 = stream_with(d.path(), "le/learn.csv");
    let r = run_cli(&[
        "learn",
        "--stream",
        stream4.to_str().unwrap(),
        "--agent",
        agent.to_str().unwrap(),
        "--episodes",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_exit(&r, 2, &["--stream"]);
    assert_eq!(read(&out.join("learn.csv")), read(Path::new("maps/crowd.ron")));
    assert_eq!(read(&map), before);
}

#[test]
fn merge_refuses_to_replace_a_file_that_is_not_results() {
    let d = tempfile::tempdir().unwrap();
    let part = d.path().join("part.jsonl");
    assert_exit(
        &run_cli(&[
            "batch",
            "jaywalk",
            "--method",
            "never-brake",
            "--episodes",
            "1",
            "--out",
            part.to_str().unwrap(),
        ]),
        0,
        &[],
    );
    let map = d.path().join("map.ron");
    std::fs::copy("maps/crowd.ron", &map).unwrap();
    let merge = |extra: &[&str]| {
        let mut args = vec!["merge", part.to_str().unwrap(), "--out", map.to_str().unwrap()];
        args.extend(extra);
        run_cli(&args)
    };
    assert_exit(&merge(&[]), 2, &["--force"]);
    assert_eq!(read(&map), read(Path::new("maps/crowd.ron")));
    assert_exit(&merge(&["--force"]), 0, &[]);
}

#[test]
fn stream_descriptions_refuse_control_characters() {
    let d = tempfile::tempdir().unwrap();
    let s = d.path().join("s.ron");
    std::fs::write(&s, "Stream(description: \"a\\nb\", maps: [(map: \"jaywalk\")])").unwrap();
    let r = run_cli(&[
        "eval",
        "--stream",
        s.to_str().unwrap(),
        "--method",
        "never-brake",
        "--episodes",
        "1",
    ]);
    assert_exit(&r, 2, &["description", "control"]);
}

#[test]
fn merge_names_a_part_given_twice_or_not_a_file() {
    let d = tempfile::tempdir().unwrap();
    let part = d.path().join("part.jsonl");
    let p = part.to_str().unwrap();
    let out = d.path().join("m.jsonl");
    let o = out.to_str().unwrap();
    let batch = run_cli(&[
        "batch",
        "jaywalk",
        "--method",
        "never-brake",
        "--episodes",
        "1",
        "--out",
        p,
    ]);
    assert_exit(&batch, 0, &[]);
    assert_exit(&run_cli(&["merge", p, p, "--out", o]), 2, &["given twice"]);
    let folder = d.path().to_str().unwrap();
    assert_exit(
        &run_cli(&["merge", p, folder, "--out", o]),
        2,
        &["not a regular file", "shard files"],
    );
    // A pipe is not read (it would block) and is named as the input it is.
    let fifo = d.path().join("pipe.jsonl");
    if std::process::Command::new("mkfifo")
        .arg(&fifo)
        .status()
        .is_ok_and(|s| s.success())
    {
        let r = run_cli(&["merge", p, fifo.to_str().unwrap(), "--out", o]);
        assert_exit(&r, 2, &["pipe.jsonl", "not a regular file"]);
        assert!(!common_text(&r).contains("write results"), "{}", common_text(&r));
    }
    assert_exit(
        &run_cli(&["batch", "jaywalk", "--shard", " 1/2", "--out", o]),
        2,
        &["--shard"],
    );
}

/// Finding 12: a newline in `--out` (it is in the command written in each failure map's
/// `// Found by:` comment) ended the comment and broke the map's RON.
#[test]
fn a_newline_in_out_leaves_the_failure_maps_valid() {
    let d = tempfile::tempdir().unwrap();
    let out = d.path().join("a\nb");
    let r = run_cli(&[
        "search",
        "--space",
        SPACE,
        "--method",
        "never-brake",
        "--budget",
        "6",
        "--episodes",
        "2",
        "--seed",
        "9",
        "--max-failures",
        "1",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_exit(&r, 0, &[]);
    let maps: Vec<_> = std::fs::read_dir(out.join("failures"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert!(!maps.is_empty(), "never-brake fails on every fair candidate");
    for m in maps {
        let text = std::fs::read_to_string(&m).unwrap();
        let found = text.lines().find(|l| l.starts_with("// Found by:")).unwrap();
        assert!(found.contains("a\\nb"), "{found}");
        unforeseen_harness::maps::load_file(&m).unwrap_or_else(|e| panic!("{}: {e}\n{text}", m.display()));
    }
}
