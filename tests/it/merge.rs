//! `unforeseen merge`: shards of one run merge into the file and summary one machine
//! writes (timing aside); missing, duplicated and foreign shards are refused, naming the
//! units or the differences.

use crate::common::{TINY_MAP, assert_exit, run_cli, tiny_agent_text};
use std::path::{Path, PathBuf};
use unforeseen_harness::runs::batch::{ResultLine, read_lines};
use unforeseen_harness::runs::outputs::summary_path;

struct Setup {
    dir: tempfile::TempDir,
}

impl Setup {
    fn new() -> Self {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("tiny.ron"), TINY_MAP).unwrap();
        std::fs::write(dir.path().join("agent.ron"), tiny_agent_text()).unwrap();
        Setup { dir }
    }

    fn path(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn p(&self, name: &str) -> String {
        self.path(name).display().to_string()
    }

    /// `batch` of the tiny map with the tiny agent, `episodes` each, into `out`.
    fn batch(&self, out: &str, episodes: &str, shard: Option<&str>) {
        let (map, agent, out) = (self.p("tiny.ron"), self.p("agent.ron"), self.p(out));
        let mut args = vec![
            "batch",
            &map,
            "--agent",
            &agent,
            "--episodes",
            episodes,
            "--seed",
            "5",
            "--jobs",
            "2",
            "--quiet",
            "--set",
            "horizon=1,2",
            "--out",
            &out,
        ];
        if let Some(s) = shard {
            args.extend(["--shard", s]);
        }
        let run = run_cli(&args);
        // The tiny agent fails some expectations of the intersection (exit 1): what is
        // compared here is the results, not the gate.
        assert!(
            matches!(run.status.code(), Some(0 | 1)),
            "{}",
            crate::common::output_text(&run)
        );
    }

    fn merge(&self, parts: &[&str], out: &str) -> std::process::Output {
        let mut args: Vec<String> = vec!["merge".into()];
        args.extend(parts.iter().map(|p| self.p(p)));
        args.extend(["--out".into(), self.p(out)]);
        run_cli(&args.iter().map(String::as_str).collect::<Vec<_>>())
    }
}

fn without_timing(path: &Path) -> Vec<ResultLine> {
    read_lines(path)
        .unwrap()
        .into_iter()
        .map(|mut l| {
            l.timing_us_per_tick = 0.0;
            l
        })
        .collect()
}

/// The summary file without its clock-measured figures and its own file name.
fn summary_without_timing(path: &Path) -> serde_json::Value {
    let mut v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(summary_path(path)).unwrap()).unwrap();
    v["results"] = serde_json::Value::Null;
    for row in v["rows"].as_array_mut().unwrap() {
        row["timing_us_per_tick"] = serde_json::Value::Null;
    }
    v
}

#[test]
fn shards_merge_into_the_file_of_one_run_and_gaps_overlaps_and_other_runs_are_refused() {
    let s = Setup::new();
    s.batch("whole.jsonl", "2", None);
    for i in 1..=3 {
        s.batch(&format!("part-{i}.jsonl"), "2", Some(&format!("{i}/3")));
    }
    // In any order, the parts merge into the whole run's lines and summary.
    let merged = s.merge(&["part-3.jsonl", "part-1.jsonl", "part-2.jsonl"], "merged.jsonl");
    assert!(
        matches!(merged.status.code(), Some(0 | 1)),
        "{}",
        crate::common::output_text(&merged)
    );
    assert!(crate::common::output_text(&merged).contains("merged 3 part(s)"));
    let whole = without_timing(&s.path("whole.jsonl"));
    assert!(
        whole.len() >= 6,
        "the run should have several units, has {}",
        whole.len()
    );
    assert_eq!(without_timing(&s.path("merged.jsonl")), whole);
    assert_eq!(
        summary_without_timing(&s.path("merged.jsonl")),
        summary_without_timing(&s.path("whole.jsonl"))
    );
    // The same exit code as the whole run: the gate is the same.
    let whole_code = {
        let again = s.merge(&["whole.jsonl"], "again.jsonl");
        again.status.code()
    };
    assert_eq!(merged.status.code(), whole_code);

    // A shard missing: refused, naming the units; no merged file written.
    let units: Vec<usize> = read_lines(&s.path("part-2.jsonl"))
        .unwrap()
        .iter()
        .map(|l| l.unit)
        .collect();
    assert!(!units.is_empty());
    let gap = s.merge(&["part-1.jsonl", "part-3.jsonl"], "gap.jsonl");
    let first = format!("unit {} (tiny", units[0]);
    assert_exit(&gap, 2, &["do not cover the run", &first]);
    assert!(!s.path("gap.jsonl").exists() && !summary_path(&s.path("gap.jsonl")).exists());

    // A shard given twice (named once, as given twice), or overlapping the whole:
    // refused, naming both places.
    let twice = s.merge(
        &["part-1.jsonl", "part-2.jsonl", "part-2.jsonl", "part-3.jsonl"],
        "twice.jsonl",
    );
    assert_exit(&twice, 2, &["part-2.jsonl is given twice", "give each shard file once"]);
    let overlap = s.merge(&["whole.jsonl", "part-3.jsonl"], "overlap.jsonl");
    assert_exit(&overlap, 2, &["in two places", "whole.jsonl line", "part-3.jsonl line"]);

    // A shard of another run (3 episodes instead of 2): refused, saying what differs.
    s.batch("other-2.jsonl", "3", Some("2/3"));
    let mixed = s.merge(&["part-1.jsonl", "other-2.jsonl", "part-3.jsonl"], "mixed.jsonl");
    assert_exit(&mixed, 2, &["other-2.jsonl", "another run", "episodes"]);
    assert!(!s.path("mixed.jsonl").exists());

    // A shard killed while writing (its last line cut): its unit is named as missing.
    let text = std::fs::read_to_string(s.path("part-3.jsonl")).unwrap();
    let cut = &text[..text.len() - 10];
    std::fs::write(s.path("cut-3.jsonl"), cut).unwrap();
    let last = read_lines(&s.path("part-3.jsonl")).unwrap().last().unwrap().unit;
    let killed = s.merge(&["part-1.jsonl", "part-2.jsonl", "cut-3.jsonl"], "killed.jsonl");
    assert_exit(&killed, 2, &[&format!("unit {last} (tiny"), "cut line"]);

    // Not a results file: refused, naming it.
    std::fs::write(s.path("notes.jsonl"), "hello\n").unwrap();
    let notes = s.merge(&["notes.jsonl"], "notes-out.jsonl");
    assert_exit(&notes, 2, &["notes.jsonl", "line 1"]);
}
