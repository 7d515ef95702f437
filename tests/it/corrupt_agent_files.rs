//! Corrupt agent files are refused by eval, batch and compare with a bad-input error,
//! never a panic (a Q-table one entry short, `n_actions: 5`, Bayes-RL `visits: []`,
//! `counts: []`, `n_states: 65`, `reward_sum: []`) and never loaded silently (NaN,
//! infinite or negative values, an out-of-range discount, tolerance, epsilon or terminal
//! state, a table one entry too long, unknown fields: a NaN in A would turn scaled's
//! success to 0% without a word, and export-model would write `null`).
//!
//! A corpus of damaged files, each made from a small valid agent by one edit: every one
//! is refused as bad input (exit code 2) with a message naming the file, the field and
//! the fix; a few go through the command line of each command that reads agents.

use unforeseen_harness::fixtures;

use std::path::Path;
use std::process::Command;
use unforeseen_harness::error::Error;

/// `text` with the list opened at the line found by following `path` (each entry the
/// start of a line, searched from the previous match) replaced by `f(items)`. Pretty
/// RON puts every number of a list on its own line.
fn edit_list(text: &str, path: &[&str], f: impl FnOnce(&mut Vec<String>)) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let open = locate(&lines, path);
    assert!(lines[open].ends_with('['), "{path:?} is not a list: {}", lines[open]);
    let close = (open + 1..lines.len())
        .find(|&i| lines[i].trim_start().starts_with(']'))
        .expect("list end");
    let indent = " ".repeat(lines[open].len() - lines[open].trim_start().len() + 4);
    let mut items: Vec<String> = lines[open + 1..close]
        .iter()
        .map(|l| l.trim().trim_end_matches(',').to_string())
        .collect();
    f(&mut items);
    let mut out: Vec<String> = lines[..=open].iter().map(|l| l.to_string()).collect();
    out.extend(items.iter().map(|i| format!("{indent}{i},")));
    out.extend(lines[close..].iter().map(|l| l.to_string()));
    out.join("\n") + "\n"
}

/// `text` with the scalar `field` (the first after following `path`) set to `value`.
fn set(text: &str, path: &[&str], field: &str, value: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let start = locate(&lines, path);
    let at = (start..lines.len())
        .find(|&i| lines[i].trim_start().starts_with(&format!("{field}:")))
        .unwrap_or_else(|| panic!("no {field} after {path:?}"));
    let indent = &lines[at][..lines[at].len() - lines[at].trim_start().len()];
    let mut out: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
    out[at] = format!("{indent}{field}: {value},");
    out.join("\n") + "\n"
}

fn locate(lines: &[&str], path: &[&str]) -> usize {
    let mut pos = 0;
    for anchor in path {
        pos = (pos..lines.len())
            .find(|&i| lines[i].trim_start().starts_with(anchor))
            .unwrap_or_else(|| panic!("{anchor} not found in {path:?}"));
    }
    pos
}

/// One damaged file: a name, its text and a phrase the error must contain (the field).
struct Case {
    name: &'static str,
    text: String,
    needle: &'static str,
}

fn corpus() -> Vec<Case> {
    let t = fixtures::tiny_agent_text();
    let q = ["q_learning: ("];
    let wm = ["world_model: ("];
    let b = ["bayes_rl: ("];
    let first = |v: &'static str| move |items: &mut Vec<String>| items[0] = v.to_string();
    let case = |name, text, needle| Case { name, text, needle };
    vec![
        case(
            "q_short",
            edit_list(t, &["table: ["], |i| {
                i.pop();
            }),
            "q_learning.table",
        ),
        case(
            "q_long",
            edit_list(t, &["table: ["], |i| i.push("0.0".into())),
            "q_learning.table",
        ),
        case("q_n_actions_5", set(t, &q, "n_actions", "5"), "q_learning.table"),
        case(
            "q_nan",
            edit_list(t, &["table: ["], first("NaN")),
            "q_learning.table[0]",
        ),
        case(
            "q_inf",
            edit_list(t, &["table: ["], first("inf")),
            "q_learning.table[0]",
        ),
        case(
            "q_discount_nan",
            set(t, &q, "discount", "NaN"),
            "q_learning.params.discount",
        ),
        case(
            "q_discount_2",
            set(t, &q, "discount", "2.0"),
            "q_learning.params.discount",
        ),
        case(
            "q_epsilon_minus_5",
            set(t, &["q_learning: (", "epsilon_min"], "epsilon", "-5.0"),
            "q_learning.epsilon",
        ),
        case(
            "q_params_epsilon",
            set(t, &q, "epsilon", "-5.0"),
            "q_learning.params.epsilon",
        ),
        case(
            "q_states_disagree",
            {
                let cut = set(t, &q, "n_states", "12");
                edit_list(&cut, &["table: ["], |i| i.truncate(36))
            },
            "q_learning.n_states",
        ),
        case(
            "wm_cpt_nan",
            edit_list(t, &["world_model: (", "cpt: [", "["], first("NaN")),
            "world_model.cpt[0][0]",
        ),
        case(
            "wm_cpt_negative",
            edit_list(t, &["world_model: (", "cpt: [", "["], first("-1.0")),
            "world_model.cpt[0][0]",
        ),
        case(
            "wm_cpt_short",
            edit_list(t, &["world_model: (", "cpt: [", "["], |i| {
                i.pop();
            }),
            "world_model.cpt[0]",
        ),
        case(
            "wm_a_nan",
            edit_list(t, &["world_model: (", "a_counts: (["], first("NaN")),
            "world_model.a_counts[0,0]",
        ),
        case(
            "wm_a_column_zero",
            edit_list(t, &["world_model: (", "a_counts: (["], |i| {
                i.iter_mut().take(24).for_each(|x| *x = "0.0".into());
            }),
            "world_model.a_counts[..,0]",
        ),
        case(
            "wm_a_overflowing_shape",
            t.replacen("], 24, 24)", "], 4294967296, 4294967296)", 1),
            "world_model.a_counts",
        ),
        case(
            "wm_c_nan",
            edit_list(t, &["world_model: (", "c: ["], first("NaN")),
            "world_model.c[0]",
        ),
        case(
            "wm_c_not_normalised",
            edit_list(t, &["world_model: (", "c: ["], |i| {
                for x in i.iter_mut() {
                    *x = format!("{}", x.parse::<f64>().unwrap() + 1.0);
                }
            }),
            "world_model.c",
        ),
        case(
            "wm_d_negative",
            edit_list(t, &["world_model: (", "d_counts: ["], first("-0.5")),
            "world_model.d_counts[0]",
        ),
        case(
            "wm_terminal_huge",
            edit_list(t, &["world_model: (", "terminal: ["], first("99999999")),
            "world_model.terminal[0]",
        ),
        case(
            "wm_prior_nan",
            set(t, &wm, "a_concentration", "NaN"),
            "world_model.priors.a_concentration",
        ),
        case(
            "wm_n_actions_4",
            set(t, &["world_model: (", "],"], "n_actions", "4"),
            "world_model.cpt",
        ),
        case(
            "bayes_visits_empty",
            edit_list(t, &["bayes_rl: (", "visits: ["], Vec::clear),
            "bayes_rl.visits",
        ),
        case(
            "bayes_counts_empty",
            edit_list(t, &["bayes_rl: (", "counts: ["], Vec::clear),
            "bayes_rl.counts",
        ),
        case(
            "bayes_reward_sum_empty",
            edit_list(t, &["bayes_rl: (", "reward_sum: ["], Vec::clear),
            "bayes_rl.reward_sum",
        ),
        case("bayes_n_states_65", set(t, &b, "n_states", "65"), "bayes_rl.counts"),
        case(
            "bayes_counts_nan",
            edit_list(t, &["bayes_rl: (", "counts: ["], first("NaN")),
            "bayes_rl.counts[0]",
        ),
        case(
            "bayes_visits_negative",
            edit_list(t, &["bayes_rl: (", "visits: ["], first("-1.0")),
            "bayes_rl.visits[0]",
        ),
        case(
            "bayes_visits_disagree",
            edit_list(t, &["bayes_rl: (", "visits: ["], first("1000.0")),
            "bayes_rl.visits[0]",
        ),
        case(
            "bayes_reward_inf",
            edit_list(t, &["bayes_rl: (", "reward_sum: ["], first("inf")),
            "bayes_rl.reward_sum[0]",
        ),
        case(
            "bayes_discount_1",
            set(t, &b, "discount", "1.0"),
            "bayes_rl.params.discount",
        ),
        case("bayes_tol_nan", set(t, &b, "tol", "NaN"), "bayes_rl.params.planner.tol"),
        case(
            "bayes_iterations_huge",
            set(t, &b, "iterations", "4000000000"),
            "bayes_rl.params.planner.iterations",
        ),
        case(
            "factored_a_negative",
            edit_list(t, &["bayes_rl_factored: Some((", "a_counts: (["], first("-1.0")),
            "bayes_rl_factored.factored.a_counts[0,0]",
        ),
        case(
            "unknown_top_field",
            t.replacen("format_version: 1,", "format_version: 1,\n    colour: \"red\",", 1),
            "colour",
        ),
        case(
            "unknown_nested_field",
            set(t, &q, "n_states", "24,\n        colour: 1"),
            "q_learning.colour",
        ),
        case(
            "other_format_version",
            t.replacen("format_version: 1,", "format_version: 2,", 1),
            "format version 2",
        ),
        case("truncated", t[..t.len() / 2].to_string(), "corrupt"),
    ]
}

#[test]
fn every_damaged_agent_file_is_refused_naming_the_field() {
    let valid = fixtures::tiny_agent_text();
    let path = Path::new("agent.ron");
    unforeseen_harness::training::agent_file::parse(path, valid).expect("the undamaged agent loads");
    let cases = corpus();
    assert!(cases.len() >= 35);
    for c in &cases {
        assert_ne!(c.text, valid, "{}: the edit changed nothing", c.name);
        let err = unforeseen_harness::training::agent_file::parse(path, &c.text).expect_err(c.name);
        let message = format!("{err:#}");
        assert_eq!(unforeseen::cli::exit_code(&err), 2, "{}: {message}", c.name);
        assert!(matches!(err, Error::AgentFile { .. }), "{}: {message}", c.name);
        assert!(
            message.starts_with("agent.ron: ") && message.contains(c.needle) && message.contains("unforeseen train"),
            "{}: {message}",
            c.name
        );
    }
}

/// The command line on a few damaged files: each command that reads an agent exits 2
/// with the file, the field and the fix, and never panics.
#[test]
fn commands_refuse_damaged_agent_files_with_exit_code_2() {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("tiny.ron");
    std::fs::write(&map, fixtures::TINY_MAP).unwrap();
    let m = map.to_str().unwrap();
    let cases = corpus();
    let pick = |name: &str| cases.iter().find(|c| c.name == name).unwrap();
    let runs: [(&str, &[&str]); 6] = [
        (
            "q_short",
            &["eval", "--map", m, "--method", "q-learning", "--episodes", "1"],
        ),
        (
            "bayes_visits_empty",
            &["batch", m, "--method", "bayes-rl", "--episodes", "1"],
        ),
        ("bayes_n_states_65", &["compare", "--test-map", m, "--episodes", "1"]),
        ("wm_a_nan", &["export-model"]),
        ("q_n_actions_5", &["learn", "--map", m, "--episodes", "1"]),
        ("unknown_nested_field", &["trace", "--map", m]),
    ];
    for (name, args) in runs {
        let case = pick(name);
        let file = dir.path().join(format!("{name}.ron"));
        std::fs::write(&file, &case.text).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_unforeseen"))
            .args(args)
            .args(["-q", "--agent", file.to_str().unwrap(), "--out"])
            .arg(dir.path().join("out"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{name} {args:?}: {err}");
        assert!(
            err.contains(&format!("{name}.ron")) && err.contains(case.needle) && err.contains("unforeseen train"),
            "{name}: {err}"
        );
        assert!(!err.contains("panicked"), "{name}: {err}");
    }
}

/// export-model writes only finite numbers (JSON has no NaN: serde writes `null`).
#[test]
fn export_model_never_writes_null() {
    let dir = tempfile::tempdir().unwrap();
    let agent = dir.path().join("tiny_agent.ron");
    std::fs::write(&agent, fixtures::tiny_agent_text()).unwrap();
    let model = dir.path().join("model.json");
    let out = Command::new(env!("CARGO_BIN_EXE_unforeseen"))
        .args(["export-model", "--obs", "1,1,1,1", "--agent"])
        .arg(&agent)
        .arg("--out")
        .arg(&model)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let text = std::fs::read_to_string(&model).unwrap();
    assert!(!text.contains("null"), "{text}");
}
