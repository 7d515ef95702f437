//! Deployment streams in `batch` and `learn` (`--stream FILE`): a batch's per-map figures
//! are those of `eval --stream` (the same episodes run); results do not depend on
//! `--jobs`, shards merge into the whole and `--resume` completes a cut file; `learn`
//! names each episode's map; bad streams and `--stream` with maps exit 2 writing nothing.

use crate::common::{assert_exit, run_cli};
use unforeseen_harness::fixtures;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::progress::NoProgress;
use unforeseen_harness::runs::batch::{
    BatchConfig, ParamSet, ResultLine, Shard, load_stream_scenario, read_lines, run,
};
use unforeseen_harness::training::Agent;

/// A stream over two embedded maps in a fixed sequence (intersection, intersection,
/// jaywalk, repeated), and the shared test agent's file, in `dir`.
fn inputs(dir: &Path) -> (PathBuf, PathBuf) {
    let stream = dir.join("mix.ron");
    std::fs::write(
        &stream,
        "Stream(maps: [(map: \"intersection\", weight: 2), (map: \"jaywalk\")], order: Sequence)",
    )
    .unwrap();
    let agent = dir.join("agent.ron");
    unforeseen_harness::training::agent_file::save(&agent, fixtures::bundle()).unwrap();
    (stream, agent)
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn batch_per_map_figures_are_those_of_eval_stream_and_the_summary_is_per_map() {
    let dir = tempfile::tempdir().unwrap();
    let (stream, agent) = inputs(dir.path());
    let out = dir.path().join("r.jsonl");
    let batch = run_cli(&[
        "batch",
        "--stream",
        s(&stream),
        "--agent",
        s(&agent),
        "--method",
        "scaled",
        "--method",
        "q-learning",
        "--episodes",
        "6",
        "--protocol",
        "both",
        "--jobs",
        "2",
        "-q",
        "--out",
        s(&out),
    ]);
    assert_exit(
        &batch,
        0,
        &["mix/intersection", "mix/jaywalk", "learning within the stream"],
    );
    let lines = read_lines(&out).unwrap();
    // scaled once per protocol; q-learning does not learn across episodes: once, covering both.
    assert_eq!(lines.len(), 3);
    for l in &lines {
        assert_eq!(l.scenario, "mix");
        let maps: Vec<(&str, u64)> = l.per_map.iter().map(|f| (f.map.as_str(), f.episodes)).collect();
        assert_eq!(maps, [("intersection", 4), ("jaywalk", 2)]);
    }
    for l in lines.iter().filter(|l| l.method == "scaled") {
        let eval_dir = dir.path().join(format!("eval-{}", l.protocol.name()));
        let eval = run_cli(&[
            "eval",
            "--stream",
            s(&stream),
            "--agent",
            s(&agent),
            "--method",
            "scaled",
            "--protocol",
            l.protocol.name(),
            "--episodes",
            "6",
            "--seed",
            "7",
            "-q",
            "--out",
            s(&eval_dir),
        ]);
        assert_exit(&eval, 0, &[]);
        let rows = json(&eval_dir.join("eval.json"))["per_map"].clone();
        let rows = rows.as_array().unwrap();
        assert_eq!(rows.len(), l.per_map.len());
        for (row, f) in rows.iter().zip(&l.per_map) {
            let a = &row["aggregate"];
            assert_eq!(row["map"], f.map.as_str());
            assert_eq!(a["episodes"].as_u64(), Some(f.episodes), "{}", f.map);
            for (key, value) in [
                ("success_rate", f.success_rate),
                ("collision_rate", f.collision_rate),
                ("mean_reward", f.mean_reward),
                ("inference_rate", f.inference_rate),
                ("mean_ticks", f.mean_ticks),
            ] {
                assert_eq!(a[key].as_f64(), Some(value), "{} {key} ({})", f.map, l.protocol.name());
            }
        }
    }
    // The summary: the stream's row, then one per map within it; what learning does per map.
    let summary = json(&dir.path().join("r.summary.json"));
    let rows = summary["rows"].as_array().unwrap();
    let names: Vec<String> = rows
        .iter()
        .map(|r| match r["stream"].as_str() {
            Some(stream) => format!("{stream}/{}", r["scenario"].as_str().unwrap()),
            None => r["scenario"].as_str().unwrap().to_string(),
        })
        .collect();
    assert_eq!(names, ["mix", "mix/intersection", "mix/jaywalk"].repeat(3));
    let learning = summary["learning"].as_array().unwrap();
    let maps: Vec<&str> = learning.iter().map(|l| l["map"].as_str().unwrap()).collect();
    assert_eq!(
        maps,
        ["intersection", "jaywalk"],
        "scaled only: q-learning does not learn"
    );
}

/// The shared test agent, for the library's batch.
fn agents() -> &'static [Agent] {
    static AGENTS: OnceLock<Vec<Agent>> = OnceLock::new();
    AGENTS.get_or_init(|| vec![Agent::from_bundle(fixtures::bundle().clone())])
}

fn without_timing(lines: Vec<ResultLine>) -> Vec<ResultLine> {
    lines
        .into_iter()
        .map(|mut l| {
            l.timing_us_per_tick = 0.0;
            l.per_map.iter_mut().for_each(|f| f.timing_us_per_tick = 0.0);
            l
        })
        .collect()
}

#[test]
fn stream_batches_do_not_depend_on_jobs_and_shard_merge_and_resume_to_the_whole() {
    let dir = tempfile::tempdir().unwrap();
    let (stream, _) = inputs(dir.path());
    let scenarios = [load_stream_scenario(&stream).unwrap()];
    let params = [ParamSet(Vec::new())];
    let methods = [Method::QLearning, Method::Scaled];
    let config = |jobs: usize, shard: Option<Shard>| BatchConfig {
        agents: agents(),
        train_seeds: &[Some(7)],
        scenarios: &scenarios,
        methods: &methods,
        params: &params,
        protocols: &Protocol::ALL,
        episodes: 4,
        seed: 5,
        jobs,
        shard,
        agents_identity: "the shared test agent, training seed 7".into(),
    };
    let one = dir.path().join("one.jsonl");
    let two = dir.path().join("two.jsonl");
    let a = without_timing(run(&config(1, None), &one, false, &NoProgress).unwrap());
    let b = without_timing(run(&config(2, None), &two, false, &NoProgress).unwrap());
    assert_eq!(a.len(), 3);
    assert!(a.iter().all(|l| l.per_map.len() == 2), "{a:?}");
    assert_eq!(a, b);

    let parts: Vec<PathBuf> = (1..=2)
        .map(|i| {
            let part = dir.path().join(format!("part{i}.jsonl"));
            run(
                &config(2, Some(Shard { index: i, count: 2 })),
                &part,
                false,
                &NoProgress,
            )
            .unwrap();
            part
        })
        .collect();
    let merged = unforeseen_harness::runs::merge::merge(&parts).unwrap();
    assert_eq!(without_timing(merged.results()), a);

    // A kill after the first line: --resume runs the rest and keeps that line's bytes.
    let text = std::fs::read_to_string(&one).unwrap();
    let kept: Vec<&str> = text.split_inclusive('\n').collect();
    let cut = dir.path().join("cut.jsonl");
    std::fs::write(&cut, format!("{}{}{}", kept[0], kept[1], &kept[2][..kept[2].len() / 2])).unwrap();
    let resumed = run(&config(2, None), &cut, true, &NoProgress).unwrap();
    assert_eq!(without_timing(resumed), a);
    assert!(
        std::fs::read_to_string(&cut)
            .unwrap()
            .starts_with(&format!("{}{}", kept[0], kept[1]))
    );
    assert_eq!(without_timing(read_lines(&cut).unwrap()), a);

    // A line whose maps' episodes do not add up to its own is refused, naming it.
    let edited = dir.path().join("edited.jsonl");
    let text = text.replacen(
        "{\"map\":\"intersection\",\"episodes\":3,",
        "{\"map\":\"intersection\",\"episodes\":2,",
        1,
    );
    std::fs::write(&edited, text).unwrap();
    let err = run(&config(2, None), &edited, true, &NoProgress).unwrap_err();
    assert!(
        err.to_string().contains("line 2 (unit 0") && err.to_string().contains("per_map episodes adding up to 3"),
        "{err}"
    );
}

#[test]
fn learn_over_a_stream_names_each_episodes_map() {
    let dir = tempfile::tempdir().unwrap();
    let (stream, agent) = inputs(dir.path());
    let out = dir.path().join("learn");
    let learn = run_cli(&[
        "learn",
        "--stream",
        s(&stream),
        "--agent",
        s(&agent),
        "--episodes",
        "4",
        "-q",
        "--out",
        s(&out),
    ]);
    assert_exit(
        &learn,
        0,
        &["over the stream 'mix'", "intersection", "jaywalk", "successes"],
    );
    let csv = std::fs::read_to_string(out.join("learn.csv")).unwrap();
    let mut rows = csv.lines();
    assert!(rows.next().unwrap().starts_with("episode,map,"), "{csv}");
    let maps: Vec<&str> = rows.map(|r| r.split(',').nth(1).unwrap()).collect();
    assert_eq!(maps, ["intersection", "intersection", "jaywalk", "intersection"]);
    let points = json(&out.join("learn.json"));
    assert_eq!(points[2]["map"], "jaywalk");
    assert!(out.join("learn.svg").is_file());
}

#[test]
fn bad_streams_and_streams_with_maps_exit_2_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let (good, agent) = inputs(dir.path());
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let syntax = write("syntax.ron", "Stream(\n  maps: [(map: \"jaywalk\", weight: )],\n)");
    let missing = write(
        "missing.ron",
        "Stream(maps: [(map: \"jaywalk\"), (map: \"nowhere.ron\")])",
    );
    let absent = dir.path().join("absent.ron");
    let out = dir.path().join("out");
    let results = out.join("r.jsonl");
    let syntax_place = format!("{}:2:", syntax.display());
    let missing_place = format!("{}: maps[1]", missing.display());
    for (file, needles) in [
        (&syntax, vec![syntax_place.as_str(), "Stream(maps: ["]),
        (&missing, vec![missing_place.as_str(), "nowhere.ron", "pass a path"]),
        (&absent, vec!["absent.ron", "cannot read"]),
    ] {
        let batch = run_cli(&[
            "batch",
            "--stream",
            s(file),
            "--agent",
            s(&agent),
            "-q",
            "--out",
            s(&results),
        ]);
        assert_exit(&batch, 2, &needles);
        for command in ["eval", "learn"] {
            let other = run_cli(&[
                command,
                "--stream",
                s(file),
                "--agent",
                s(&agent),
                "-q",
                "--out",
                s(&out),
            ]);
            assert_exit(&other, 2, &needles);
        }
    }
    for command in ["eval", "learn"] {
        let both = run_cli(&[command, "--stream", s(&good), "--map", "jaywalk", "--out", s(&out)]);
        assert_exit(&both, 2, &["--stream", "--map", "cannot be used with"]);
    }
    let both = run_cli(&["batch", "maps/jaywalk.ron", "--stream", s(&good), "--out", s(&results)]);
    assert_exit(&both, 2, &["--stream", "cannot be used with"]);
    assert!(!out.exists(), "nothing written");
}
