//! Bad map files are rejected with clear messages, never a panic: one test per
//! class of problem, each asserting that the message names the file and the
//! place (line:column for syntax, the field path for semantics).

use std::path::{Path, PathBuf};

use proptest::prelude::*;
use unforeseen_sim::{Map, MapError};

/// Write `files` into a fresh folder and load the first one.
fn load_files(files: &[(&str, &[u8])]) -> (tempfile::TempDir, PathBuf, Result<Map, MapError>) {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let path = dir.path().join(files[0].0);
    let result = Map::load(&path);
    (dir, path, result)
}

/// Load a single map file that must be rejected; return the error's lines.
fn reject(text: &str) -> (String, Vec<String>) {
    let (_dir, path, result) = load_files(&[("bad.ron", text.as_bytes())]);
    let err = result.expect_err("the map should be rejected");
    let lines: Vec<String> = err.to_string().lines().map(str::to_string).collect();
    assert_eq!(lines.len(), err.diagnostics().len());
    for l in &lines {
        assert!(
            l.starts_with(&path.display().to_string()),
            "does not name the file: {l}"
        );
    }
    (path.display().to_string(), lines)
}

fn has(lines: &[String], needles: &[&str]) -> bool {
    lines.iter().any(|l| needles.iter().all(|n| l.contains(n)))
}

#[test]
fn syntax_error_names_line_and_column() {
    let (file, lines) = reject("Map(\n    road: (lane_width: 3.5,,),\n)\n");
    assert_eq!(lines.len(), 1);
    assert!(lines[0].starts_with(&format!("{file}:2:")), "{lines:?}");
}

#[test]
fn nan_size_is_rejected() {
    let (_, lines) = reject("Map(road: (lane_width: NaN))");
    assert!(has(&lines, &["road.lane_width", "finite"]), "{lines:?}");
}

#[test]
fn negative_size_is_rejected() {
    let (_, lines) = reject("Map(vehicle: (length: -4.5, mass: 0.0))");
    assert!(has(&lines, &["vehicle.length", "greater than 0", "hint:"]), "{lines:?}");
    assert!(has(&lines, &["vehicle.mass"]), "{lines:?}");
}

#[test]
fn crosswalk_beyond_destination_is_rejected() {
    let (_, lines) = reject("Map(crosswalk: (x: 95.0))");
    assert!(has(&lines, &["crosswalk.x", "beyond the destination"]), "{lines:?}");
}

#[test]
fn empty_light_cycle_is_rejected() {
    let (_, lines) = reject("Map(light: (cycle: []))");
    assert!(has(&lines, &["light.cycle", "empty", "hint:"]), "{lines:?}");
}

#[test]
fn non_increasing_bin_edges_are_rejected() {
    let (_, lines) = reject("Map(bins: (distance_edges: [0.0, 60.0, 30.0], speed_edges: [1.0, 1.0]))");
    assert!(
        has(&lines, &["bins.distance_edges[2]", "strictly increasing"]),
        "{lines:?}"
    );
    assert!(
        has(&lines, &["bins.speed_edges[1]", "strictly increasing"]),
        "{lines:?}"
    );
}

#[test]
fn bad_crosswalk_anchored_bins_are_rejected() {
    let (_, lines) = reject("Map(bins: (distance_edges: Crosswalk(lead: -1.0, approach: 0.0)))");
    assert!(has(&lines, &["bins.distance_edges.lead", "below"]), "{lines:?}");
    assert!(
        has(&lines, &["bins.distance_edges.approach", "greater than 0"]),
        "{lines:?}"
    );
    let (file, lines) = reject("Map(bins: (distance_edges: Crosswalk(lead: 0.0, aproach: 34.0)))");
    assert!(
        lines[0].starts_with(&format!("{file}:1:")) && has(&lines, &["aproach", "approach"]),
        "{lines:?}"
    );
    let (_, lines) = reject("Map(bins: (distance_edges: 30.0))");
    assert!(
        has(&lines, &["bins.distance_edges", "Crosswalk(lead: 0.0, approach: 34.0)"]),
        "{lines:?}"
    );
}

#[test]
fn every_unknown_field_is_listed() {
    let (_, lines) =
        reject("Map(\n  road: (lane_widht: 3.5),\n  colour: \"red\",\n  pedestrians: [(speeed: (1.0, 1.2))],\n)");
    assert_eq!(lines.len(), 3, "{lines:?}");
    assert!(has(
        &lines,
        &["road.lane_widht", "unknown field", "did you mean `lane_width`?"]
    ));
    assert!(has(&lines, &["colour", "unknown field", "expected one of"]));
    assert!(has(&lines, &["pedestrians[0].speeed", "did you mean `speed`?"]));
}

#[test]
fn all_semantic_errors_are_listed() {
    let (_, lines) = reject(
        "Map(road: (lane_width: -1.0), light: (cycle: []), bins: (speed_edges: [3.0, 2.0]), episode: (max_steps: 0))",
    );
    for path in [
        "road.lane_width",
        "light.cycle",
        "bins.speed_edges[1]",
        "episode.max_steps",
    ] {
        assert!(has(&lines, &[path]), "{path} missing from {lines:?}");
    }
}

#[test]
fn missing_base_is_rejected() {
    let (_, lines) = reject("Map(base: \"nowhere.ron\")");
    assert!(
        has(&lines, &["base", "\"nowhere.ron\" not found", "hint:"]),
        "{lines:?}"
    );
}

#[test]
fn control_characters_in_a_name_are_rejected() {
    let (_, lines) = reject("Map(name: \"evil\\u{1b}[2J\", description: \"ok\")");
    assert!(has(&lines, &["name", "control character"]), "{lines:?}");
}

#[test]
fn missing_base_hint_names_the_embedded_maps() {
    let (_, lines) = reject("Map(base: \"nowhere\")");
    assert!(has(&lines, &["not found", "embedded map", "jaywalk"]), "{lines:?}");
}

#[test]
fn a_base_not_beside_the_map_is_an_embedded_map() {
    for base in ["jaywalk", "jaywalk.ron"] {
        let text = format!("Map(name: \"mine\", base: \"{base}\")");
        let (_dir, _path, result) = load_files(&[("mine.ron", text.as_bytes())]);
        let map = result.unwrap_or_else(|e| panic!("base {base}: {e}"));
        assert_eq!(map.name, "mine");
        assert_eq!(
            map.pedestrians.len(),
            1,
            "jaywalk's rule, inherited through base {base}"
        );
        assert_eq!(
            map.expect.len(),
            3,
            "jaywalk's expectations, inherited through base {base}"
        );
    }
}

#[test]
fn a_base_beside_the_map_wins_over_the_embedded_one() {
    let (_dir, _path, result) = load_files(&[
        ("mine.ron", b"Map(name: \"mine\", base: \"jaywalk\")"),
        ("jaywalk.ron", b"Map(base: \"intersection\", road: (goal_x: 100.0))"),
    ]);
    let map = result.unwrap();
    assert_eq!(map.road.goal_x, 100.0, "the copy beside the map");
    // The copy's own base, not found beside it, is the embedded training map: its rule
    // (pedestrians on red) and its expectations, not the embedded jaywalk's.
    assert_eq!(map.pedestrians.len(), 1);
    let training = unforeseen_sim::embedded::load("intersection").unwrap();
    assert_eq!(map.expect, training.expect);
    assert_ne!(map.expect, unforeseen_sim::embedded::load("jaywalk").unwrap().expect);
}

#[test]
fn base_including_itself_is_rejected() {
    let (_, lines) = reject("Map(base: \"bad.ron\")");
    assert!(has(&lines, &["base", "names itself"]), "{lines:?}");
}

#[test]
fn base_cycle_is_rejected() {
    let (_dir, _path, result) = load_files(&[("a.ron", b"Map(base: \"b.ron\")"), ("b.ron", b"Map(base: \"a.ron\")")]);
    let msg = result.unwrap_err().to_string();
    assert!(
        msg.contains("b.ron: base: base maps include each other: a -> b -> a"),
        "{msg}"
    );
}

#[test]
fn error_in_a_base_names_the_base_file() {
    let (_dir, _path, result) = load_files(&[
        ("child.ron", b"Map(base: \"parent.ron\")"),
        ("parent.ron", b"Map(road: (lanes: \"two\"))"),
    ]);
    let msg = result.unwrap_err().to_string();
    assert!(msg.contains("parent.ron:1:"), "{msg}");
    assert!(msg.contains("road.lanes"), "{msg}");
}

#[test]
fn wrong_type_names_line_column_and_field() {
    let (file, lines) = reject("Map(\n  episode: (max_steps: \"forty\"),\n)");
    assert!(lines[0].starts_with(&format!("{file}:2:")), "{lines:?}");
    assert!(lines[0].contains("episode.max_steps"), "{lines:?}");
}

#[test]
fn empty_file_is_rejected() {
    let (_, lines) = reject("");
    assert!(has(&lines, &["empty"]), "{lines:?}");
    let (_, lines) = reject("// only a comment\n");
    assert!(has(&lines, &["empty"]), "{lines:?}");
}

#[test]
fn binary_file_is_rejected() {
    let (_dir, path, result) = load_files(&[("bin.ron", &[0x7f, 0x45, 0x4c, 0x46, 0x02, 0x00, 0x00, 0xff])]);
    let msg = result.unwrap_err().to_string();
    assert!(
        msg.starts_with(&path.display().to_string()) && msg.contains("not a text file"),
        "{msg}"
    );
    let (_dir, _, result) = load_files(&[("latin1.ron", b"Map(name: \"caf\xe9\")")]);
    assert!(result.unwrap_err().to_string().contains("invalid UTF-8"));
}

#[test]
fn truncated_file_is_rejected() {
    let full = unforeseen_sim::embedded::INTERSECTION;
    // Cut at a line's end halfway through: the text stops, not a word in it.
    let cut = &full[..full[..full.len() / 2].rfind('\n').expect("a line break")];
    let (_, lines) = reject(cut);
    assert!(has(&lines, &["truncated"]) || has(&lines, &["end"]), "{lines:?}");
    assert!(
        lines[0].split(':').nth(1).is_some_and(|l| l.parse::<usize>().is_ok()),
        "{lines:?}"
    );
}

#[test]
fn absurdly_nested_file_is_rejected() {
    let text = format!("Map(name: {}1{})", "[".repeat(10_000), "]".repeat(10_000));
    let (_, lines) = reject(&text);
    assert!(has(&lines, &["nested more than"]), "{lines:?}");
}

#[test]
fn huge_file_is_rejected() {
    let text = format!("Map(description: \"{}\")", "x".repeat(2 << 20));
    let (_, lines) = reject(&text);
    assert!(has(&lines, &["too large"]), "{lines:?}");
}

#[test]
fn missing_file_is_an_error_not_a_panic() {
    let err = Map::load(Path::new("/nonexistent/map.ron")).unwrap_err();
    assert!(
        err.to_string().starts_with("/nonexistent/map.ron: cannot read"),
        "{err}"
    );
}

#[test]
fn shipped_maps_load_from_disk_with_bases() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps");
    for name in unforeseen_sim::embedded::names() {
        let file = unforeseen_sim::embedded::path(name).unwrap();
        let m = Map::load(&dir.join(file)).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(m, unforeseen_sim::embedded::load(name).unwrap());
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, failure_persistence: None, ..ProptestConfig::default() })]

    /// Arbitrary text never panics the loader.
    #[test]
    fn arbitrary_text_never_panics(src in "\\PC{0,200}") {
        let _ = Map::from_str_named("fuzz.ron", &src, &|_| None);
    }

    /// Mutations of a real map never panic the loader.
    #[test]
    fn mutated_maps_never_panic(cut in 0usize..3000, junk in "[\\[\\](){}:,\"a-z0-9.-]{0,8}") {
        let src = unforeseen_sim::embedded::JAYWALK;
        let cut = cut.min(src.len());
        let cut = (0..=cut).rev().find(|&i| src.is_char_boundary(i)).unwrap_or(0);
        let text = format!("{}{}{}", &src[..cut], junk, &src[cut..]);
        let _ = Map::from_str_named("fuzz.ron", &text, &|b| {
            unforeseen_sim::embedded::source(b).map(|s| (b.to_string(), s.to_string()))
        });
    }
}

/// Maps that would run for hours, ask for terabytes, or make no physical sense are
/// refused, each with the field, the limit and its reason.
#[test]
fn runaway_and_absurd_maps_are_refused_with_the_limit() {
    let edges = |n: usize, step: f64| {
        (0..n)
            .map(|i| format!("{:.1}", i as f64 * step))
            .collect::<Vec<_>>()
            .join(", ")
    };
    let many_rules = vec!["(trigger: RedStarts)"; 64].join(", ");
    let sixteen_rules = vec!["(trigger: RedStarts)"; 16].join(", ");
    let cases: Vec<(String, &[&str])> = vec![
        (
            format!(
                "Map(bins: (distance_edges: [{}], speed_edges: [{}]))",
                edges(64, 1.0),
                edges(64, 0.1)
            ),
            &["bins", "16900 joint states", "at most 1024", "GB"],
        ),
        (
            "Map(episode: (max_steps: 100000, physics_hz: 10000.0))".into(),
            &["episode", "sub-steps per episode", "at most 200000"],
        ),
        (
            format!(
                "Map(pedestrians: [{many_rules}], light: (cycle: [(phase: Red, duration: 0.0167), (phase: Green, duration: 0.0167)]))"
            ),
            &["pedestrians", "64 spawn rules", "at most 16"],
        ),
        (
            format!(
                "Map(pedestrians: [{sixteen_rules}], light: (cycle: [(phase: Red, duration: 0.0167), (phase: Green, duration: 0.0167)]))"
            ),
            &["pedestrians", "in one episode", "at most 100"],
        ),
        (
            "Map(light: (cycle: [(phase: Red, duration: 0.001), (phase: Green, duration: 10.0)]))".into(),
            &["light.cycle[0].duration", "shorter than one physics sub-step"],
        ),
        (
            "Map(pedestrians: [(radius: 999999.0)])".into(),
            &["pedestrians[0].radius", "[0.05, 1.5] m"],
        ),
        (
            "Map(pedestrians: [(speed: (1.0, 999.0))])".into(),
            &["pedestrians[0].speed.1", "m/s"],
        ),
        (
            "Map(vehicle: (max_speed: 999999.0))".into(),
            &["vehicle.max_speed", "[0.1, 70] m/s"],
        ),
        ("Map(vehicle: (length: 500.0))".into(), &["vehicle.length", "[1, 20] m"]),
        ("Map(vehicle: (length: 1e-300))".into(), &["vehicle.length", "1e-300"]),
        ("Map(vehicle: (mass: 1e-300))".into(), &["vehicle.mass", "1e-300 kg"]),
        ("Map(road: (lane_width: 1e-300))".into(), &["road.lane_width", "1e-300"]),
        (
            "Map(episode: (decision_dt: 10000.0, physics_hz: 0.01))".into(),
            &["episode.decision_dt", "[0.05, 60] s"],
        ),
        (
            "Map(episode: (decision_dt: 10000.0, physics_hz: 0.01))".into(),
            &["episode.physics_hz", "[10, 10000] Hz"],
        ),
    ];
    for (text, needles) in &cases {
        let (_, lines) = reject(text);
        assert!(has(&lines, needles), "{text}\n{lines:#?}");
        assert!(
            lines.iter().all(|l| l.contains("(hint: ")),
            "a reason for every limit: {lines:#?}"
        );
    }
}

/// The limits leave every shipped map valid.
#[test]
fn the_shipped_maps_are_within_the_limits() {
    for name in unforeseen_sim::embedded::names() {
        unforeseen_sim::embedded::load(name).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    // maps/ and its subfolders (maps/per_metre/: the per-metre reward), but not
    // maps/spaces/, which holds the search's space files (not maps).
    let mut dirs = vec![Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps")];
    let mut loaded = 0;
    while let Some(dir) = dirs.pop() {
        for entry in std::fs::read_dir(dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() && path.file_name().is_some_and(|n| n == "spaces") {
                continue;
            }
            if path.is_dir() {
                // maps/streams/ holds deployment streams (lists of maps, harness/src/runs/stream.rs), not maps.
                if !path.ends_with("streams") {
                    dirs.push(path);
                }
            } else if path.extension().is_some_and(|x| x == "ron") {
                Map::load(&path).unwrap_or_else(|e| panic!("{e}"));
                loaded += 1;
            }
        }
    }
    assert!(loaded >= 13, "only {loaded} map files found under maps/");
}

/// The road surface and the force model's parameters: each bad value is named by its
/// field, with the accepted range or the reason.
#[test]
fn bad_surface_and_force_parameters_are_rejected() {
    let cases: [(&str, &[&str]); 8] = [
        ("Map(road: (friction: 0.0))", &["road.friction", "greater than 0"]),
        (
            "Map(road: (friction: 2.5))",
            &["road.friction", "above the accepted range"],
        ),
        (
            "Map(road: (surface: [(from: 10.0, to: 20.0, friction: -0.1)]))",
            &["road.surface[0].friction", "greater than 0"],
        ),
        (
            "Map(road: (surface: [(from: 200.0, to: 220.0, friction: 0.1)]))",
            &["road.surface[0]", "outside the road"],
        ),
        (
            "Map(road: (surface: [(from: 30.0, to: 20.0, friction: 0.1)]))",
            &["road.surface[0].to", "before it starts"],
        ),
        (
            "Map(vehicle: (dynamics: Forces, brake_lag: -0.1))",
            &["vehicle.brake_lag", "below"],
        ),
        ("Map(vehicle: (mass: 0.0))", &["vehicle.mass", "greater than 0"]),
        (
            "Map(vehicle: (dynamics: Forces, power: 0.0))",
            &["vehicle.power", "cannot move the car"],
        ),
    ];
    for (text, needles) in cases {
        let (_, lines) = reject(text);
        assert!(has(&lines, needles), "{text}: {lines:?}");
    }
}

/// A map on the force model with patches, one appearing at run time, loads.
#[test]
fn a_surface_with_a_triggered_patch_loads() {
    let text = "Map(vehicle: (dynamics: Forces), road: (friction: 0.4, surface: [\
                (from: 40.0, to: 64.0, friction: 0.1, trigger: Some(CarWithin(min: 0.0, max: 30.0)))]))";
    let (_dir, _path, result) = load_files(&[("ok.ron", text.as_bytes())]);
    let map = result.expect("valid");
    assert_eq!(map.road.surface.len(), 1);
    assert_eq!(map.road.friction, 0.4);
}
