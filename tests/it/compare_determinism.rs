//! `compare` writes the same JSON for the same seed, bit for bit, apart from the one
//! wall-clock figure (µs per tick).

use std::process::Command;

fn strip_timing(v: &mut serde_json::Value) {
    match v {
        serde_json::Value::Object(m) => {
            m.retain(|k, _| !k.contains("us_per"));
            m.values_mut().for_each(strip_timing);
        }
        serde_json::Value::Array(a) => a.iter_mut().for_each(strip_timing),
        _ => {}
    }
}

fn compare_json(dir: &std::path::Path) -> serde_json::Value {
    let out = Command::new(env!("CARGO_BIN_EXE_unforeseen"))
        .args([
            "compare",
            "--train-episodes",
            "150",
            "--episodes",
            "4",
            "--seed",
            "3",
            "-q",
            "--out",
        ])
        .arg(dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("compare.json")).unwrap()).unwrap();
    assert!(dir.join("compare.csv").exists() && dir.join("compare.svg").exists());
    strip_timing(&mut v);
    v
}

#[test]
fn compare_json_is_identical_across_runs_with_the_same_seed() {
    let (a, b) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let (ja, jb) = (compare_json(a.path()), compare_json(b.path()));
    assert_eq!(ja, jb);
    let tables = ja["tables"].as_array().unwrap();
    let protocols: Vec<_> = tables.iter().map(|t| t["protocol"].as_str().unwrap()).collect();
    assert_eq!(protocols, ["zero-shot", "continual"]);
    for t in tables {
        let methods: Vec<_> = t["methods"]
            .as_array()
            .unwrap()
            .iter()
            .map(|m| m["method"].as_str().unwrap().to_string())
            .collect();
        assert_eq!(methods, ["q-learning", "bayes-rl", "scaled"]);
        for m in t["methods"].as_array().unwrap() {
            assert_eq!(m["protocol"], t["protocol"]);
            assert_eq!(m["train_seeds"], serde_json::json!([3]));
            // Every row names the reward its returns are paid in: the maps' default,
            // rapid approach (a tick costs what a full-speed tick earns).
            for map in ["train_map", "test_map"] {
                assert_eq!(m["reward"][map]["step_cost"], serde_json::json!(4.5), "{m}");
                assert_eq!(m["reward"][map]["crash"], serde_json::json!(-25.0), "{m}");
            }
            for k in [
                "train_reward",
                "test_reward",
                "success_rate",
                "collision_rate",
                "red_light_rate",
                "inference_rate",
            ] {
                assert!(m[k]["mean"].is_number(), "{k} missing in {m}");
                assert!(m[k]["ci95_low"].is_null(), "one agent has no interval: {m}");
            }
        }
    }
}
