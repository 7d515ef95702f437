//! A fuzz test over the library API (no processes, so it is fast). Valid maps
//! (every shipped scenario) and a valid agent file are mutated by a seeded mutator —
//! numbers replaced by NaN, infinities, negatives, huge and tiny values, lines deleted
//! or repeated, unknown fields inserted, characters changed, files cut short — and each
//! result is loaded. Nothing may panic, abort on an allocation or hang: a rejected input
//! is a bad-input error (exit code 2) naming the file; an accepted map builds a world
//! that steps; an accepted agent drives a few episodes with finite, valid decisions.
//!
//! `UNFORESEEN_FUZZ_CASES=N` sets the number of cases of each kind (default 300).

use unforeseen_harness::fixtures;

use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::path::Path;
use unforeseen_agent::params::ScaledParams;
use unforeseen_discretizer::Discretizer;
use unforeseen_env::{Env, EnvConfig, ObservationForm};
use unforeseen_harness::episodes::Method;
use unforeseen_harness::episodes::{EpisodeSeeds, run_episode};
use unforeseen_sim::{Action, Map};

fn cases() -> usize {
    std::env::var("UNFORESEEN_FUZZ_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(300)
}

/// Values a number may be replaced with: out of range, non-finite, huge, tiny, edges.
const SPECIAL: &[&str] = &[
    "NaN",
    "inf",
    "-inf",
    "-1.0",
    "-0.5",
    "0.0",
    "0",
    "1",
    "2",
    "3",
    "64",
    "65",
    "1e-300",
    "1e300",
    "-1e308",
    "99999999999",
    "4294967296",
    "18446744073709551615",
    "0.999999",
];

/// Byte spans of the numbers in `text` (a digit, or a minus sign before one, then digits,
/// dots, exponents).
fn numbers(text: &str) -> Vec<(usize, usize)> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = b[i].is_ascii_digit() || (b[i] == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit));
        let after_word = i > 0 && (b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_');
        if starts && !after_word {
            let mut j = i + 1;
            while j < b.len() && (b[j].is_ascii_digit() || b"._eE+-".contains(&b[j])) {
                j += 1;
            }
            out.push((i, j));
            i = j;
        } else {
            i += 1;
        }
    }
    out
}

/// One to three random edits of `text`.
fn mutate(text: &str, rng: &mut ChaCha8Rng) -> String {
    let mut t = text.to_string();
    for _ in 0..rng.random_range(1..=3) {
        if t.is_empty() {
            break;
        }
        let lines: Vec<&str> = t.split_inclusive('\n').collect();
        t = match rng.random_range(0..8) {
            // A number becomes a special value (the most common edit: most bugs are here).
            0..=2 => {
                let spans = numbers(&t);
                if spans.is_empty() {
                    continue;
                }
                // Half the time among the first eighth of the numbers, so that the small
                // sections before the long count arrays (parameters, Q-table, CPTs) get
                // their share.
                let pick = if rng.random_range(0..2) == 0 {
                    spans.len()
                } else {
                    spans.len().div_ceil(8)
                };
                let (a, b) = spans[rng.random_range(0..pick)];
                let v = SPECIAL[rng.random_range(0..SPECIAL.len())];
                format!("{}{v}{}", &t[..a], &t[b..])
            }
            // A number scaled by a power of ten, perhaps negated.
            3 => {
                let spans = numbers(&t);
                if spans.is_empty() {
                    continue;
                }
                let (a, b) = spans[rng.random_range(0..spans.len())];
                let x: f64 = t[a..b].parse().unwrap_or(1.0);
                let sign = if rng.random_range(0..4) == 0 { -1.0 } else { 1.0 };
                let v = sign * x * 10f64.powi(rng.random_range(-12..=12));
                format!("{}{v:?}{}", &t[..a], &t[b..])
            }
            // A line deleted or repeated (list lengths, missing fields, duplicates).
            4 => {
                let i = rng.random_range(0..lines.len());
                let mut l = lines.clone();
                l.remove(i);
                l.concat()
            }
            5 => {
                let i = rng.random_range(0..lines.len());
                let n = rng.random_range(1..=8);
                let mut l = lines.clone();
                for _ in 0..n {
                    l.insert(i, lines[i]);
                }
                l.concat()
            }
            // An unknown field, or one character replaced.
            6 => {
                let i = rng.random_range(0..lines.len());
                let mut l: Vec<String> = lines.iter().map(|s| s.to_string()).collect();
                if rng.random_range(0..2) == 0 {
                    l.insert(i, "    zzz_unknown: 1,\n".into());
                } else {
                    let line = &l[i];
                    let chars: Vec<char> = line.chars().collect();
                    let k = rng.random_range(0..chars.len());
                    let pool = b"()[]{},:;\"'#/\\0-9aZ \x07";
                    let c = pool[rng.random_range(0..pool.len())] as char;
                    l[i] = chars[..k]
                        .iter()
                        .chain(std::iter::once(&c))
                        .chain(&chars[k + 1..])
                        .collect();
                }
                l.concat()
            }
            // Cut short.
            _ => {
                let mut k = rng.random_range(0..t.len());
                while !t.is_char_boundary(k) {
                    k -= 1;
                }
                t[..k].to_string()
            }
        };
    }
    t
}

#[test]
fn mutated_maps_are_refused_or_run_within_the_limits() {
    let names = unforeseen_sim::embedded::names();
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let (mut accepted, n) = (0, cases());
    for case in 0..n {
        let name = names[case % names.len()];
        let text = mutate(unforeseen_sim::embedded::source(name).unwrap(), &mut rng);
        let bases = |b: &str| unforeseen_sim::embedded::base_in(name, b);
        let map = match Map::from_str_named("fuzz.ron", &text, &bases) {
            Ok(map) => map,
            Err(e) => {
                assert!(e.to_string().starts_with("fuzz.ron"), "case {case}: {e}");
                continue;
            }
        };
        accepted += 1;
        // Accepted maps stay within the stated limits...
        let states = Discretizer::new(&map).expect("valid bins").n_states();
        assert!(
            states <= unforeseen_sim::MAX_JOINT_STATES,
            "case {case}: {states} states\n{text}"
        );
        let per_episode = f64::from(map.episode.substeps()) * f64::from(map.episode.max_steps);
        assert!(
            per_episode <= unforeseen_sim::MAX_EPISODE_SUBSTEPS,
            "case {case}\n{text}"
        );
        // ...and their envs step, with finite kinematic observations.
        let config = EnvConfig {
            observation: ObservationForm::Kinematic,
            ..EnvConfig::default()
        };
        let mut env = Env::new(&map, config).expect("a valid map makes an env");
        env.reset(case as u64);
        for _ in 0..3 {
            if env.is_done() {
                break;
            }
            let step = env.step(Action::SpeedUp.index()).expect("a valid action");
            assert!(step.info.reward.progress.is_finite(), "case {case}\n{text}");
            let obs = step.observation.kinematic().expect("kinematic");
            assert!(obs.iter().all(|x| x.is_finite()), "case {case}: {obs:?}\n{text}");
        }
    }
    eprintln!("maps: {n} mutated, {accepted} accepted");
    assert!(accepted > 0 && accepted < n, "the mutator should make both kinds");
}

#[test]
fn mutated_agent_files_are_refused_or_drive_the_car() {
    let valid = fixtures::tiny_agent_text();
    let map = fixtures::tiny_map();
    let mut env = Env::new(&map, EnvConfig::default()).unwrap();
    let path = Path::new("agent.ron");
    let params = ScaledParams::default();
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let (mut accepted, n) = (0, cases());
    for case in 0..n {
        let text = mutate(valid, &mut rng);
        let bundle = match unforeseen_harness::training::agent_file::parse(path, &text) {
            Ok(b) => b,
            Err(e) => {
                assert!(
                    unforeseen_harness::error::in_chain(&e),
                    "case {case}: not input the user can fix: {e:#}"
                );
                assert!(format!("{e:#}").starts_with("agent.ron: "), "case {case}: {e:#}");
                continue;
            }
        };
        accepted += 1;
        if unforeseen_harness::episodes::check_compatible(&bundle, &map).is_err() {
            continue;
        }
        for method in [
            Method::QLearning,
            Method::BayesRl,
            Method::BayesRlFactored,
            Method::Scaled,
        ] {
            let Ok(mut controller) = method.controller(&bundle, &params, &map) else {
                continue;
            };
            // Two episodes on one controller: the second after test-time learning.
            for episode in 0..2 {
                let seeds = EpisodeSeeds {
                    world: case as u64 + episode,
                    controller: episode,
                };
                let (result, ticks) = run_episode(&mut env, controller.as_mut(), seeds, true).unwrap();
                assert!(result.ret.is_finite(), "case {case} {method}");
                // Every decision (the last frame is the terminal state, with no decision).
                for t in &ticks[..ticks.len() - 1] {
                    assert!(
                        t.policy.len() == 3 && t.policy.iter().all(|p| p.is_finite() && *p >= 0.0),
                        "case {case} {method}: policy {:?}",
                        t.policy
                    );
                }
            }
        }
    }
    eprintln!("agent files: {n} mutated, {accepted} accepted");
    assert!(accepted > 0 && accepted < n, "the mutator should make both kinds");
}

#[test]
fn mutated_space_files_are_refused_or_sample_valid_names() {
    use unforeseen_harness::runs::search::{Space, candidate_name, sobol_candidates};
    let valid = std::fs::read_to_string(fixtures::repo_path("maps/spaces/jaywalk.ron")).unwrap();
    let base = unforeseen_harness::maps::load("jaywalk").unwrap();
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let (mut accepted, n) = (0, cases());
    for case in 0..n {
        let text = mutate(&valid, &mut rng);
        let space = match Space::parse("space.ron", &text, &base) {
            Ok(s) => s,
            Err(e) => {
                assert!(
                    unforeseen_harness::error::in_chain(&e),
                    "case {case}: not input the user can fix: {e}"
                );
                assert!(e.to_string().starts_with("space.ron"), "case {case}: {e}");
                continue;
            }
        };
        accepted += 1;
        // Its name becomes file names: never a path.
        let name = candidate_name(&space, 42);
        assert!(
            unforeseen_harness::runs::outputs::file_name("name", &name).is_ok(),
            "case {case}: {name:?}"
        );
        // Its first candidates are maps or reasons, never a panic.
        for c in sobol_candidates(&space, case as u64, 0..4) {
            if let Ok(map) = &c.map {
                Env::new(map, EnvConfig::default()).expect("a valid candidate makes an env");
            }
        }
    }
    eprintln!("space files: {n} mutated, {accepted} accepted");
    assert!(accepted > 0 && accepted < n, "the mutator should make both kinds");
}

#[test]
fn mutated_stream_files_are_refused_or_schedule_within_the_limits() {
    use unforeseen_harness::runs::stream::Stream;
    let dir = tempfile::tempdir().unwrap();
    // The shipped stream, with its maps beside it.
    let shipped = std::fs::read_to_string(fixtures::repo_path("maps/streams/deployment.ron")).unwrap();
    let valid = shipped.replace("../", &format!("{}/", fixtures::repo_path("maps").display()));
    let path = dir.path().join("stream.ron");
    let mut rng = ChaCha8Rng::seed_from_u64(12);
    let (mut accepted, n) = (0, cases() / 3);
    for case in 0..n {
        let text = mutate(&valid, &mut rng);
        std::fs::write(&path, &text).unwrap();
        let stream = match Stream::load(&path) {
            Ok(s) => s,
            Err(e) => {
                assert!(
                    unforeseen_harness::error::in_chain(&e),
                    "case {case}: not input the user can fix: {e}"
                );
                assert!(
                    e.to_string().starts_with(&path.display().to_string()),
                    "case {case}: {e}"
                );
                continue;
            }
        };
        accepted += 1;
        assert!(!stream.description.chars().any(char::is_control), "case {case}");
        // A schedule costs memory per episode, not per unit of weight.
        let schedule = stream.schedule(5, case as u64);
        assert_eq!(schedule.len(), 5);
        assert!(schedule.iter().all(|&m| m < stream.maps.len()), "case {case}");
    }
    eprintln!("stream files: {n} mutated, {accepted} accepted");
    assert!(accepted > 0 && accepted < n, "the mutator should make both kinds");
}
