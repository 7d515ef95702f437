//! Batch runs: expectations pass and fail as declared; results do not depend on
//! `--jobs`; `--resume` completes a truncated file without duplicates; shards
//! concatenate into the unsharded file.

use crate::common;
use unforeseen_harness::fixtures;

use std::path::Path;
use std::sync::OnceLock;
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::Protocol;
use unforeseen_harness::progress::NoProgress;
use unforeseen_harness::runs::batch::{
    BatchConfig, ParamSet, ResultLine, Scenario, Shard, load_scenarios, read_lines, run, sweep,
};
use unforeseen_harness::training::Agent;

fn scenarios() -> Vec<Scenario> {
    let names = ["jaywalk".to_string(), "intersection".to_string()];
    load_scenarios(&names.iter().map(Into::into).collect::<Vec<_>>()).unwrap()
}

/// The shared test agent (training seed 7).
fn agents() -> &'static [Agent] {
    static AGENTS: OnceLock<Vec<Agent>> = OnceLock::new();
    AGENTS.get_or_init(|| vec![Agent::from_bundle(fixtures::bundle().clone())])
}

fn config<'a>(scenarios: &'a [Scenario], params: &'a [ParamSet], jobs: usize, shard: Option<Shard>) -> BatchConfig<'a> {
    BatchConfig {
        agents: agents(),
        train_seeds: &[Some(7)],
        scenarios,
        methods: &Method::PAPER,
        params,
        protocols: &Protocol::ALL,
        episodes: 3,
        seed: 9,
        jobs,
        shard,
        agents_identity: "the shared test agent, training seed 7".into(),
    }
}

fn without_timing(lines: &[ResultLine]) -> Vec<ResultLine> {
    lines
        .iter()
        .cloned()
        .map(|mut l| {
            l.timing_us_per_tick = 0.0;
            l
        })
        .collect()
}

fn file_without_timing(path: &Path) -> Vec<ResultLine> {
    without_timing(&read_lines(path).unwrap())
}

#[test]
fn jobs_do_not_change_results_and_shards_concatenate_to_the_whole() {
    let scenarios = scenarios();
    let params = sweep(&["horizon=1,2".to_string()]).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one.jsonl");
    let two = dir.path().join("two.jsonl");
    let a = run(&config(&scenarios, &params, 1, None), &one, false, &NoProgress).unwrap();
    let b = run(&config(&scenarios, &params, 2, None), &two, false, &NoProgress).unwrap();
    // Per scenario: q-learning once (covers both protocols) and bayes-rl once per protocol,
    // both with the defaults only (the sweep does not affect them); scaled once per
    // protocol and parameter set.
    assert_eq!(a.len(), 2 * (1 + 2 + 2 * 2));
    assert!(a.iter().all(|l| l.method == "scaled" || l.param_set == "default"));
    assert!(
        a.iter()
            .all(|l| l.covers.contains(&l.protocol) && l.train_seed == Some(7))
    );
    assert_eq!(without_timing(&a), without_timing(&b));
    assert_eq!(file_without_timing(&one), file_without_timing(&two));

    let mut concatenated = Vec::new();
    for i in 1..=3 {
        let part = dir.path().join(format!("shard{i}.jsonl"));
        run(
            &config(&scenarios, &params, 2, Some(Shard { index: i, count: 3 })),
            &part,
            false,
            &NoProgress,
        )
        .unwrap();
        concatenated.extend(read_lines(&part).unwrap());
    }
    assert_eq!(without_timing(&concatenated), file_without_timing(&one));
}

#[test]
fn resume_after_a_truncated_file_completes_the_set_without_duplicates() {
    let scenarios = scenarios();
    let params = vec![ParamSet(Vec::new())];
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full.jsonl");
    let whole = run(&config(&scenarios, &params, 2, None), &full, false, &NoProgress).unwrap();

    // Simulate a kill: the run's identity, two complete lines and half of the third.
    let text = std::fs::read_to_string(&full).unwrap();
    let lines: Vec<&str> = text.split_inclusive('\n').collect();
    assert!(lines[0].starts_with("{\"run\":"), "{}", lines[0]);
    let cut = format!(
        "{}{}{}{}",
        lines[0],
        lines[1],
        lines[2],
        &lines[3][..lines[3].len() / 2]
    );
    let partial = dir.path().join("partial.jsonl");
    std::fs::write(&partial, cut).unwrap();
    assert_eq!(read_lines(&partial).unwrap().len(), 2);

    let resumed = run(&config(&scenarios, &params, 2, None), &partial, true, &NoProgress).unwrap();
    assert_eq!(resumed.len(), whole.len());
    let mut keys: Vec<_> = resumed.iter().map(ResultLine::key).collect();
    keys.dedup();
    assert_eq!(keys.len(), whole.len(), "no duplicates");
    assert_eq!(without_timing(&resumed), without_timing(&whole));
    assert_eq!(file_without_timing(&partial), without_timing(&whole));
    // The kept lines are the old bytes (their wall-clock timing included).
    let after = std::fs::read_to_string(&partial).unwrap();
    assert!(after.starts_with(&format!("{}{}{}", lines[0], lines[1], lines[2])));
}

#[test]
fn expectations_pass_and_fail_as_declared() {
    let mut scenarios = scenarios();
    scenarios.truncate(1); // jaywalk
    let map = scenarios[0].map_mut().unwrap();
    use unforeseen_sim::Expectation;
    let none = Expectation {
        method: "QLearning".into(),
        min_success: None,
        max_success: None,
        min_reward: None,
        max_reward: None,
        max_collision: None,
        max_inference_rate: None,
        max_red_light: None,
        max_timeout: None,
        protocol: None,
    };
    map.expect = vec![
        Expectation {
            min_success: Some(0.0),
            max_collision: Some(1.0),
            ..none.clone()
        },
        Expectation {
            min_success: Some(1.0),
            ..none.clone()
        },
        Expectation {
            method: "BayesRl".into(),
            max_inference_rate: Some(1.0),
            ..none.clone()
        },
        Expectation {
            method: "BayesRl".into(),
            protocol: Some("Continual".into()),
            min_success: Some(0.0),
            ..none.clone()
        },
    ];
    let params = vec![ParamSet(Vec::new())];
    let dir = tempfile::tempdir().unwrap();
    let lines = run(
        &config(&scenarios, &params, 2, None),
        &dir.path().join("r.jsonl"),
        false,
        &NoProgress,
    )
    .unwrap();
    let q = lines.iter().find(|l| l.method == "q-learning").unwrap();
    assert_eq!(q.checks.len(), 3);
    assert!(q.checks[0].pass && q.checks[1].pass);
    assert!(
        !q.checks[2].pass
            && q.checks[2].figure == "success_rate"
            && q.checks[2].bound == "min"
            && q.checks[2].limit == 1.0
    );
    assert_eq!(q.covers, Protocol::ALL, "q-learning runs once for both protocols");
    let bayes = |p: Protocol| {
        lines
            .iter()
            .find(|l| l.method == "bayes-rl" && l.protocol == p)
            .unwrap()
    };
    let b = bayes(Protocol::ZeroShot);
    assert_eq!(b.checks.len(), 1, "the continual-only expectation skips zero-shot");
    assert!(b.checks[0].pass);
    let b = bayes(Protocol::Continual);
    assert_eq!(b.checks.len(), 2);
    assert!(b.checks[1].pass && b.checks[1].figure == "success_rate");
    assert!(lines.iter().find(|l| l.method == "scaled").unwrap().checks.is_empty());

    // In a sweep, expectations gate the default parameters only: a scaled expectation no
    // point of `horizon=1,2` could meet is reported on neither, and q-learning (not swept)
    // is still checked once.
    scenarios[0].map_mut().unwrap().expect = vec![
        Expectation {
            method: "Scaled".into(),
            min_success: Some(1.1),
            ..none.clone()
        },
        Expectation {
            max_collision: Some(1.0),
            ..none
        },
    ];
    let sweep = sweep(&["horizon=1,2".to_string()]).unwrap();
    let lines = run(
        &config(&scenarios, &sweep, 2, None),
        &dir.path().join("s.jsonl"),
        false,
        &NoProgress,
    )
    .unwrap();
    assert!(
        lines
            .iter()
            .filter(|l| l.method == "scaled")
            .all(|l| l.checks.is_empty())
    );
    let q: Vec<_> = lines.iter().filter(|l| l.method == "q-learning").collect();
    assert_eq!((q.len(), q[0].param_set.as_str(), q[0].checks.len()), (1, "default", 1));
}

#[test]
fn the_cli_fails_when_an_expectation_fails_and_names_it() {
    let dir = tempfile::tempdir().unwrap();
    let agent = dir.path().join("agent.ron");
    unforeseen_harness::training::agent_file::save(&agent, fixtures::bundle()).unwrap();
    let jay = Path::new(env!("CARGO_MANIFEST_DIR")).join("maps").join("jaywalk.ron");
    let map = dir.path().join("impossible.ron");
    std::fs::write(
        &map,
        format!(
            "(base: {:?}, name: \"impossible\", expect: [(method: QLearning, min_success: 1.0)])",
            jay.display().to_string()
        ),
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_unforeseen"))
        .args([
            "batch",
            map.to_str().unwrap(),
            "--agent",
            agent.to_str().unwrap(),
            "--episodes",
            "2",
            "--method",
            "q-learning",
            "-q",
            "--out",
        ])
        .arg(dir.path().join("r.jsonl"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("impossible")
            && err.contains("q-learning")
            && err.contains("success_rate")
            && err.contains("min 1"),
        "{err}"
    );
}

/// A results file names its run (episodes, seed, agents, sweep, ...), so `--resume`
/// of another run is refused saying what differs (and the file is left as it was), and
/// a resume with nothing to do leaves the file byte for byte (kept lines are not
/// rewritten, not even in their last float digits).
#[test]
fn resume_refuses_another_runs_file_and_keeps_its_own_byte_for_byte() {
    let scenarios = scenarios();
    let params = vec![ParamSet(Vec::new())];
    let methods = [Method::NeverBrake, Method::QLearning];
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("r.jsonl");
    let base = || BatchConfig {
        methods: &methods,
        ..config(&scenarios, &params, 2, None)
    };
    run(&base(), &out, false, &NoProgress).unwrap();
    let before = std::fs::read_to_string(&out).unwrap();
    run(&base(), &out, true, &NoProgress).unwrap();
    assert_eq!(
        std::fs::read_to_string(&out).unwrap(),
        before,
        "nothing to do: same bytes"
    );

    let sweep = sweep(&["horizon=1,2".to_string()]).unwrap();
    let scaled = [Method::NeverBrake, Method::Scaled];
    let one_map = &scenarios[..1];
    let refused = |cfg: BatchConfig<'_>, field: &str| {
        let err = run(&cfg, &out, true, &NoProgress).expect_err(field);
        let message = format!("{err:#}");
        assert_eq!(unforeseen::cli::exit_code(&err), 2, "{message}");
        assert!(
            message.contains("another run") && message.contains(&format!("{field}:")) && message.contains("--out"),
            "{field}: {message}"
        );
        assert_eq!(
            std::fs::read_to_string(&out).unwrap(),
            before,
            "{field}: the file is left alone"
        );
    };
    refused(BatchConfig { episodes: 4, ..base() }, "episodes");
    refused(BatchConfig { seed: 10, ..base() }, "seed");
    refused(
        BatchConfig {
            agents_identity: "another agent".into(),
            ..base()
        },
        "agents",
    );
    refused(
        BatchConfig {
            params: &sweep,
            methods: &scaled,
            ..base()
        },
        "param_sets",
    );
    refused(
        BatchConfig {
            scenarios: one_map,
            ..base()
        },
        "maps",
    );
    let mut edited = scenarios.clone();
    edited[0].map_mut().unwrap().reward.goal += 1.0;
    refused(
        BatchConfig {
            scenarios: &edited,
            ..base()
        },
        "maps",
    );

    // A file that does not name its run, one that repeats a unit, and one with a line of
    // another run are refused too.
    let lines: Vec<&str> = before.split_inclusive('\n').collect();
    for (name, text, needle) in [
        ("no identity", lines[1..].concat(), "does not say which run"),
        ("repeated unit", format!("{before}{}", lines[1]), "twice"),
        (
            "foreign unit",
            format!("{before}{}", lines[1].replace("\"unit\":0", "\"unit\":7")),
            "not a unit of this run",
        ),
    ] {
        std::fs::write(&out, &text).unwrap();
        let err = run(&base(), &out, true, &NoProgress).expect_err(name);
        assert!(format!("{err:#}").contains(needle), "{name}: {err:#}");
        assert_eq!(unforeseen::cli::exit_code(&err), 2);
    }
}

/// Two maps with one name in different folders would share result keys (a resume
/// would skip the second map's units): the batch refuses them.
#[test]
fn two_maps_with_one_name_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let jay = Path::new(env!("CARGO_MANIFEST_DIR")).join("maps").join("jaywalk.ron");
    let copy = dir.path().join("jaywalk.ron");
    std::fs::copy(&jay, &copy).unwrap();
    let err = load_scenarios(&[jay.clone(), copy.clone()]).unwrap_err();
    let message = format!("{err:#}");
    assert_eq!(unforeseen::cli::exit_code(&err), 2);
    assert!(
        message.contains("'jaywalk'") && message.contains(&copy.display().to_string()) && message.contains("name:"),
        "{message}"
    );
    // The same map listed twice (a folder and one of its files) too.
    let folder = jay.parent().unwrap().to_path_buf();
    assert!(load_scenarios(&[folder, jay]).is_err());
}

/// Results never replace, or block on, something that is not a regular file.
#[test]
fn results_must_go_to_a_regular_file() {
    let scenarios = scenarios();
    let params = vec![ParamSet(Vec::new())];
    let methods = [Method::NeverBrake];
    let dir = tempfile::tempdir().unwrap();
    let cfg = BatchConfig {
        methods: &methods,
        ..config(&scenarios, &params, 1, None)
    };
    for resume in [false, true] {
        let err = run(&cfg, dir.path(), resume, &NoProgress).unwrap_err();
        assert!(format!("{err:#}").contains("not a regular file"), "{err:#}");
        assert_eq!(unforeseen::cli::exit_code(&err), 2);
    }
    assert!(dir.path().is_dir());
}

/// Issue 35, finding 12: `batch jaywalk --method never-brake` without an agent trained
/// one (6000 episodes) that nothing used. A run of scripted methods only trains and
/// loads none, with or without `--train-seeds`; its lines name no training episodes.
#[test]
fn scripted_methods_alone_train_no_agent() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    let run = |out: &str, extra: &[&str]| {
        let out = dir.path().join(out);
        let mut args = vec![
            "batch",
            "maps/jaywalk.ron",
            "--method",
            "never-brake",
            "--method",
            "brake-on-pedestrian",
            "--episodes",
            "2",
            "--train-episodes",
            "50",
            "--jobs",
            "1",
            "--cache",
            cache.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        args.extend(extra);
        let done = common::run_cli(&args);
        let text = common::output_text(&done);
        assert_eq!(done.status.code(), Some(0), "{text}");
        assert!(
            !text.contains("for 50 episodes") && !text.contains("training 50 episodes"),
            "nothing is trained: {text}"
        );
        assert!(text.contains("no agent (scripted methods only)"), "{text}");
        read_lines(&out).unwrap()
    };
    let lines = run("r.jsonl", &[]);
    assert_eq!(lines.len(), 2);
    assert!(
        lines
            .iter()
            .all(|l| l.train_seed.is_none() && l.train_episodes.is_none())
    );
    let head = std::fs::read_to_string(dir.path().join("r.jsonl")).unwrap();
    assert!(head.lines().next().unwrap().contains("none (scripted methods only)"));
    // With training seeds, one line per seed, still no agent trained or cached.
    let seeded = run("s.jsonl", &["--train-seeds", "1..2"]);
    assert_eq!(seeded.len(), 4);
    assert!(seeded.iter().all(|l| l.train_episodes.is_none()));
    assert!(!cache.exists() || std::fs::read_dir(&cache).unwrap().next().is_none());
    // The figures are those of the runs with an agent: scripted methods do not use one.
    for l in &seeded {
        let alone = lines.iter().find(|a| a.method == l.method).unwrap();
        assert_eq!(
            (l.success_rate, l.mean_reward, l.mean_ticks),
            (alone.success_rate, alone.mean_reward, alone.mean_ticks)
        );
    }
}

/// The force-driven maps (brakes through a lag, an ice patch) give the same results on
/// one worker and on two.
#[test]
fn force_driven_maps_do_not_depend_on_jobs() {
    let paths = ["maps/ice_before_crosswalk.ron", "maps/worn_brakes.ron"];
    let scenarios = load_scenarios(&paths.iter().map(Into::into).collect::<Vec<_>>()).unwrap();
    let params = vec![ParamSet(Vec::new())];
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one.jsonl");
    let two = dir.path().join("two.jsonl");
    let a = run(&config(&scenarios, &params, 1, None), &one, false, &NoProgress).unwrap();
    let b = run(&config(&scenarios, &params, 2, None), &two, false, &NoProgress).unwrap();
    assert_eq!(a.len(), 2 * (1 + 2 + 2));
    assert_eq!(without_timing(&a), without_timing(&b));
}

/// The junction's maps (signals, an outage, vehicles on routes spawned by rules) give the
/// same results on one worker and on two.
#[test]
fn junction_maps_do_not_depend_on_jobs() {
    let paths = [
        "maps/junction/training.ron",
        "maps/junction/dark_signal.ron",
        "maps/junction/left_turner.ron",
    ];
    let scenarios = load_scenarios(&paths.iter().map(Into::into).collect::<Vec<_>>()).unwrap();
    let params = vec![ParamSet(Vec::new())];
    let dir = tempfile::tempdir().unwrap();
    let one = dir.path().join("one.jsonl");
    let two = dir.path().join("two.jsonl");
    let a = run(&config(&scenarios, &params, 1, None), &one, false, &NoProgress).unwrap();
    let b = run(&config(&scenarios, &params, 2, None), &two, false, &NoProgress).unwrap();
    assert_eq!(a.len(), 3 * (1 + 2 + 2));
    assert_eq!(without_timing(&a), without_timing(&b));
}
