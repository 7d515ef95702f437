//! Training-seed studies from the command line: `compare --train-seeds` writes one
//! table per protocol summarized over agents (mean, 95% interval, range, worst seed)
//! with the per-seed rows kept; reruns (from the agent cache or not) and runs with 1 or
//! 2 rayon threads give identical non-wall-clock fields; bad seed lists exit 2;
//! `batch --train-seeds` writes one line per seed and a summary checked on the mean.

use serde_json::Value;
use std::path::Path;
use std::process::{Command, Output};

fn unforeseen(args: &[&str], threads: &str) -> Output {
    Command::new(env!("CARGO_BIN_EXE_unforeseen"))
        .args(args)
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .unwrap()
}

fn ok(out: &Output) -> String {
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(
        out.status.success(),
        "{stdout}\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    stdout
}

/// Drops every wall-clock field (their names contain `us_per`) and the cache folder.
fn strip(v: &mut Value) {
    match v {
        Value::Object(m) => {
            m.retain(|k, _| !k.contains("us_per") && k != "agent_cache");
            m.values_mut().for_each(strip);
        }
        Value::Array(a) => a.iter_mut().for_each(strip),
        _ => {}
    }
}

fn compare(out: &Path, cache: &Path, threads: &str, extra: &[&str]) -> Value {
    let mut args = vec![
        "compare",
        "--train-episodes",
        "50",
        "--episodes",
        "3",
        "--train-seeds",
        "1..2",
        "-q",
        "--cache",
        cache.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend(extra);
    let stdout = ok(&unforeseen(&args, threads));
    assert!(
        stdout.contains("== zero-shot protocol") && stdout.contains("== continual protocol"),
        "{stdout}"
    );
    assert!(
        stdout.contains("worst seed") && stdout.contains("95% interval"),
        "{stdout}"
    );
    let mut v: Value = serde_json::from_str(&std::fs::read_to_string(out.join("compare.json")).unwrap()).unwrap();
    strip(&mut v);
    v
}

fn check_schema(v: &Value, out: &Path) {
    assert_eq!(v["schema"], 2);
    assert_eq!(v["protocols"], serde_json::json!(["zero-shot", "continual"]));
    assert_eq!(v["train_seeds"], serde_json::json!([1, 2]));
    assert_eq!(v["train_episodes"], 50);
    assert!(v["reward"]["test_map"]["goal"].is_number(), "{}", v["reward"]);
    for (t, protocol) in v["tables"].as_array().unwrap().iter().zip(["zero-shot", "continual"]) {
        assert_eq!(t["protocol"], protocol);
        for m in t["methods"].as_array().unwrap() {
            assert_eq!(m["protocol"], protocol);
            assert_eq!(
                (&m["train_seeds"], &m["episodes"], &m["seed"]),
                (&serde_json::json!([1, 2]), &Value::from(3), &Value::from(7))
            );
            for k in [
                "train_reward",
                "test_reward",
                "success_rate",
                "collision_rate",
                "inference_rate",
            ] {
                let s = &m[k];
                assert_eq!(s["n"], 2, "{k}: {s}");
                for f in ["mean", "ci95_low", "ci95_high", "min", "max"] {
                    assert!(s[f].is_number(), "{k}.{f}: {s}");
                }
                let (lo, mean, hi) = (
                    s["ci95_low"].as_f64().unwrap(),
                    s["mean"].as_f64().unwrap(),
                    s["ci95_high"].as_f64().unwrap(),
                );
                assert!(lo <= mean && mean <= hi, "{k}: {s}");
            }
            let worst = m["worst_seed"]["train_seed"].as_u64().unwrap();
            assert!(worst == 1 || worst == 2);
            let seeds: Vec<_> = m["per_seed"]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| r["train_seed"].as_u64().unwrap())
                .collect();
            assert_eq!(seeds, [1, 2]);
            let non_learner = m["method"] == "q-learning";
            assert_eq!(
                m["computed_under"],
                if non_learner { "zero-shot" } else { protocol },
                "{}",
                m["method"]
            );
        }
    }
    let csv = std::fs::read_to_string(out.join("compare.csv")).unwrap();
    assert!(
        csv.starts_with("protocol,method,computed_under,agents,train_seeds"),
        "{csv}"
    );
    assert_eq!(csv.lines().count(), 1 + 2 * 3);
    let seeds_csv = std::fs::read_to_string(out.join("compare_seeds.csv")).unwrap();
    assert_eq!(seeds_csv.lines().count(), 1 + 2 * 3 * 2);
    assert!(out.join("compare.svg").exists());
}

#[test]
fn compare_over_training_seeds_is_summarized_cached_and_thread_independent() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("agents");
    let first = compare(&dir.path().join("a"), &cache, "1", &[]);
    check_schema(&first, &dir.path().join("a"));
    let cached: Vec<_> = std::fs::read_dir(&cache)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(cached.len(), 2, "{cached:?}");
    // From the cache, on two threads.
    assert_eq!(first, compare(&dir.path().join("b"), &cache, "2", &[]));
    // Trained afresh, on two threads.
    assert_eq!(first, compare(&dir.path().join("c"), &cache, "2", &["--no-cache"]));
}

#[test]
fn bad_training_seeds_exit_2_and_say_why() {
    for (bad, needle) in [
        ("3..1", "backwards"),
        ("x", "'x' is not a seed"),
        ("1,1", "listed twice"),
        ("", "empty"),
    ] {
        let out = unforeseen(&["compare", "--train-seeds", bad], "1");
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{bad:?}: {err}");
        assert!(err.contains(needle) && err.contains("--train-seeds"), "{bad:?}: {err}");
    }
    let out = unforeseen(&["compare", "--train-seeds", "1..2", "--agent", "a.ron"], "1");
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("cannot be used with"));
}

#[test]
fn batch_over_training_seeds_writes_one_line_per_seed_and_checks_the_mean() {
    let dir = tempfile::tempdir().unwrap();
    let jay = Path::new(env!("CARGO_MANIFEST_DIR")).join("maps").join("jaywalk.ron");
    let map = dir.path().join("suite.ron");
    std::fs::write(
        &map,
        format!(
            "(base: {:?}, name: \"suite\", expect: [(method: QLearning, min_success: 0.0), (method: Scaled, protocol: Continual, max_collision: 1.0)])",
            jay.display().to_string()
        ),
    )
    .unwrap();
    let out = dir.path().join("r.jsonl");
    let cache = dir.path().join("agents");
    let args = [
        "batch",
        map.to_str().unwrap(),
        "--train-seeds",
        "1,2",
        "--train-episodes",
        "50",
        "--episodes",
        "2",
        "--method",
        "q-learning",
        "--method",
        "scaled",
        "-q",
        "--cache",
        cache.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    let stdout = ok(&unforeseen(&args, "2"));
    assert!(stdout.contains("2 expectation(s) checked"), "{stdout}");
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("{\"run\":"), "the run's identity comes first");
    let lines: Vec<Value> = text.lines().skip(1).map(|l| serde_json::from_str(l).unwrap()).collect();
    // q-learning: one line per seed covering both protocols; scaled: per protocol and seed.
    let ids: Vec<(String, String, u64)> = lines
        .iter()
        .map(|l| {
            (
                l["method"].as_str().unwrap().into(),
                l["protocol"].as_str().unwrap().into(),
                l["train_seed"].as_u64().unwrap(),
            )
        })
        .collect();
    let id = |m: &str, p: &str, s| (m.to_string(), p.to_string(), s);
    assert_eq!(
        ids,
        [
            id("q-learning", "zero-shot", 1),
            id("q-learning", "zero-shot", 2),
            id("scaled", "zero-shot", 1),
            id("scaled", "zero-shot", 2),
            id("scaled", "continual", 1),
            id("scaled", "continual", 2)
        ]
    );
    assert_eq!(lines[0]["covers"], serde_json::json!(["zero-shot", "continual"]));
    assert_eq!(
        lines[4]["checks"].as_array().unwrap().len(),
        1,
        "the continual-only bound"
    );
    assert_eq!(lines[2]["checks"].as_array().unwrap().len(), 0);
    let summary: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.summary.json")).unwrap()).unwrap();
    let rows = summary["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 3);
    assert_eq!(rows[0]["train_seeds"], serde_json::json!([1, 2]));
    assert_eq!(rows[0]["success_rate"]["n"], 2);
    assert_eq!(rows[0]["checks"][0]["pass"], true);
    assert!(rows[0]["checks"][0]["worst_seed"].is_u64());
    assert_eq!(summary["failed"], 0);

    // Resume keys include the protocol and the seed: nothing is rerun or duplicated.
    let before = std::fs::read_to_string(&out).unwrap();
    let mut resume = args.to_vec();
    resume.push("--resume");
    ok(&unforeseen(&resume, "1"));
    let strip_lines = |t: &str| -> Vec<Value> {
        // Result lines only (concatenated shards carry one identity line each).
        t.lines()
            .filter(|l| !l.starts_with("{\"run\":"))
            .map(|l| {
                let mut v: Value = serde_json::from_str(l).unwrap();
                strip(&mut v);
                v.as_object_mut().unwrap().remove("timing_us_per_tick");
                v
            })
            .collect()
    };
    assert_eq!(before, std::fs::read_to_string(&out).unwrap(), "byte for byte");

    // Shards (each trains or loads only its seeds) concatenate into the whole file.
    let mut parts = String::new();
    for (i, shard) in ["1/2", "2/2"].into_iter().enumerate() {
        let part = dir.path().join(format!("part{i}.jsonl"));
        let mut sharded: Vec<&str> = args[..args.len() - 1].to_vec();
        sharded.extend([part.to_str().unwrap(), "--shard", shard]);
        ok(&unforeseen(&sharded, "2"));
        parts.push_str(&std::fs::read_to_string(&part).unwrap());
    }
    assert_eq!(strip_lines(&parts), strip_lines(&before));

    // The concatenated parts resume as one run (each part names the same run): nothing
    // is left to run, and the rewritten file has one identity line and the same lines.
    let joined = dir.path().join("joined.jsonl");
    std::fs::write(&joined, &parts).unwrap();
    let mut whole: Vec<&str> = args[..args.len() - 1].to_vec();
    whole.extend([joined.to_str().unwrap(), "--resume"]);
    ok(&unforeseen(&whole, "1"));
    let rewritten = std::fs::read_to_string(&joined).unwrap();
    assert_eq!(rewritten.matches("{\"run\":").count(), 1);
    assert_eq!(strip_lines(&rewritten), strip_lines(&before));
}
