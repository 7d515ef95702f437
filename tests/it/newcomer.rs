//! What a new user meets first (issue 48): a negative count after a flag, a rerun that
//! replaces a results file, a map given where an agent is expected (and the reverse), a
//! misspelt parameter, expectations a map inherits, and the small print of the reports.

use std::path::Path;

use crate::common::{assert_exit, output_text as text, run_cli as unforeseen};

#[test]
fn a_negative_number_after_a_numeric_flag_reaches_the_flags_own_message() {
    for (args, needle) in [
        (&["batch", "maps/jaywalk.ron", "--episodes", "-5"][..], "--episodes"),
        (&["eval", "--episodes", "-5"][..], "--episodes"),
        (&["compare", "--train-episodes", "-5"][..], "--train-episodes"),
        (&["train", "--episodes", "-5"][..], "--episodes"),
        (&["learn", "--episodes", "-5"][..], "--episodes"),
        (&["batch", "--seed", "-1"][..], "--seed"),
        (&["batch", "--jobs", "-2"][..], "--jobs"),
        (&["trace", "--episode", "-3"][..], "--episode"),
    ] {
        let out = unforeseen(args);
        assert_exit(&out, 2, &[needle, "invalid value"]);
        let all = text(&out);
        // clap's tip `use '-- -5'` led to another error: no such tip.
        assert!(!all.contains("-- -"), "{args:?}:\n{all}");
    }
}

#[test]
fn an_episode_number_with_a_sign_is_refused() {
    assert_exit(
        &unforeseen(&["trace", "--episode", "+5", "--method", "never-brake"]),
        2,
        &["--episode", "'+5'", "digits only"],
    );
}

fn batch(out: &Path, extra: &[&str]) -> std::process::Output {
    let mut args = vec![
        "batch",
        "maps/jaywalk.ron",
        "--method",
        "never-brake",
        "--protocol",
        "zero-shot",
        "--episodes",
        "1",
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    unforeseen(&args)
}

#[test]
fn batch_says_which_results_file_it_replaces_and_how_many_lines_it_held() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.jsonl");
    let first = batch(&out, &["--seed", "3"]);
    assert_exit(&first, 0, &[]);
    let first_text = text(&first);
    assert!(!first_text.contains("replacing"), "{first_text}");
    // One unit: "1 line", not "1 lines".
    assert!(first_text.contains("(1 line)"), "{first_text}");
    assert!(!first_text.contains("(1 lines)"), "{first_text}");
    let held = std::fs::read_to_string(&out).unwrap().lines().count();
    let second = batch(&out, &["--seed", "4"]);
    assert_exit(
        &second,
        0,
        &[&format!(
            "replacing {} ({held} lines) from an earlier run",
            out.display()
        )],
    );
    let quiet = batch(&out, &["--seed", "5", "--quiet"]);
    assert_exit(&quiet, 0, &[]);
    assert!(!text(&quiet).contains("replacing"), "{}", text(&quiet));
}

#[test]
fn a_run_without_training_seeds_shows_no_question_mark_for_its_worst_seed() {
    let dir = tempfile::tempdir().unwrap();
    let out = batch(&dir.path().join("r.jsonl"), &[]);
    assert_exit(&out, 0, &[]);
    let all = text(&out);
    assert!(!all.contains("? ("), "{all}");
}

#[test]
fn a_map_given_as_the_agent_is_named_a_map_and_no_hint_points_at_it() {
    let out = unforeseen(&["eval", "--agent", "maps/near_kerb.ron", "--episodes", "1"]);
    assert_exit(&out, 2, &["maps/near_kerb.ron", "is a map file, not an agent file"]);
    let all = text(&out);
    assert!(!all.contains("--out maps/near_kerb.ron"), "{all}");
}

#[test]
fn an_agent_file_given_as_a_map_is_named_an_agent_file() {
    let dir = tempfile::tempdir().unwrap();
    let agent = dir.path().join("agent.ron");
    std::fs::write(&agent, unforeseen_harness::fixtures::tiny_agent_text()).unwrap();
    let out = unforeseen(&["check-map", agent.to_str().unwrap()]);
    assert_exit(&out, 2, &["agent.ron", "is an agent file, not a map"]);
}

#[test]
fn a_misspelt_parameter_gets_a_suggestion() {
    let out = unforeseen(&["eval", "--method", "never-brake", "--set", "epsillon=0.1"]);
    assert_exit(&out, 2, &["epsillon", "did you mean `epsilon`?"]);
}

#[test]
fn check_map_says_which_expectations_a_map_inherits() {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("variant.ron");
    std::fs::write(&map, "(\n    base: \"jaywalk\",\n    name: \"variant\",\n)\n").unwrap();
    let out = unforeseen(&["check-map", map.to_str().unwrap(), "--survivability-episodes", "0"]);
    assert_exit(&out, 0, &["inherited from jaywalk"]);
}
