//! The pictures and the trace of an episode at a junction show the street: never-brake
//! on `maps/junction/red_runner.ron` drives into the car that runs its red from the cross
//! street, and its filmstrip, replay page and trace.csv have that car, the cross street
//! and its signal heads (docs/ARCHITECTURE.md §6). The straight road's stay as they were
//! (the filmstrip's and the CSV's columns here; the frame's bytes in
//! `python/tests/test_render.py`).

use unforeseen_harness::episodes::{Method, Protocol, Tick, trace};
use unforeseen_harness::fixtures;
use unforeseen_harness::fixtures::svg_text::assert_text_fits;
use unforeseen_harness::reports::figures::filmstrip;
use unforeseen_harness::reports::{junction_scene, replay_html};
use unforeseen_harness::runs::trace::TraceRequest;
use unforeseen_sim::Map;

const RED_RUNNER: &str = "maps/junction/red_runner.ron";

fn never_brake(map: &Map) -> Vec<Tick> {
    let (result, ticks) = trace(
        fixtures::bundle(),
        &Default::default(),
        Method::NeverBrake,
        map,
        2,
        Protocol::ZeroShot,
        0,
    )
    .unwrap();
    assert!(result.collision, "never-brake meets the red-runner");
    ticks
}

fn red_runner() -> Map {
    unforeseen_harness::maps::load(&fixtures::repo_path(RED_RUNNER).display().to_string()).unwrap()
}

/// The points of every `<polygon>` of `svg` filled with `fill`, as (x, y) pixels.
fn polygons(svg: &str, fill: &str) -> Vec<Vec<(f64, f64)>> {
    svg.split("<polygon")
        .skip(1)
        .filter(|p| p[..p.find('>').unwrap()].contains(&format!("fill=\"{fill}\"")))
        .map(|p| {
            let at = p.find("points=\"").unwrap() + 8;
            let pts = &p[at..at + p[at..].find('"').unwrap()];
            pts.split_whitespace()
                .map(|xy| {
                    let (x, y) = xy.split_once(',').unwrap();
                    (x.parse().unwrap(), y.parse().unwrap())
                })
                .collect()
        })
        .collect()
}

#[test]
fn the_filmstrip_of_a_junction_shows_the_cross_street_the_heads_and_the_vehicles() {
    let map = red_runner();
    let ticks = never_brake(&map);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("filmstrip.svg");
    filmstrip(&path, "never-brake on junction_red_runner", &map, &ticks).unwrap();
    assert_text_fits(&path);
    let svg = std::fs::read_to_string(&path).unwrap();
    for words in ["vehicle in the car", "head dark (outage)", "pedestrian head"] {
        assert!(svg.contains(words), "the key explains {words:?}");
    }
    // The runner in the car's path (raspberry), a real rectangle: wider and taller than
    // a few pixels, on at least one strip.
    let runner = polygons(&svg, "#C81E5A");
    assert!(!runner.is_empty(), "a vehicle in the car's path is drawn");
    let extent = |p: &Vec<(f64, f64)>, k: fn(&(f64, f64)) -> f64| {
        let v: Vec<f64> = p.iter().map(k).collect();
        v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
    };
    assert!(
        runner
            .iter()
            .any(|p| extent(p, |q| q.0) >= 5.0 && extent(p, |q| q.1) >= 10.0)
    );
    // The cross street: one asphalt rectangle per strip as tall as the strip; the stop
    // lines: four white bars per strip.
    let strips = ticks.len();
    let tall_asphalt = svg
        .split("<rect")
        .filter(|r| r.contains("fill=\"#CDCDCD\"") && r.contains("height=\"254\""))
        .count();
    assert_eq!(tall_asphalt, strips);
    assert_eq!(svg.matches("stroke=\"#FFFFFF\" stroke-width=\"3\"").count(), 4 * strips);
    // Heads: per strip three vehicle heads besides the car's (ringed, 5 px), and the
    // key's five dots.
    assert_eq!(svg.matches("r=\"5\"").count(), 3 * strips + 5);
}

#[test]
fn the_straight_road_filmstrip_has_no_street() {
    let map = unforeseen_harness::maps::load("jaywalk").unwrap();
    assert!(junction_scene(&map).is_none());
    let ticks = scaled(&map);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("filmstrip.svg");
    filmstrip(&path, "scaled on jaywalk", &map, &ticks).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    assert!(!svg.contains("<polygon") && !svg.contains("vehicle") && !svg.contains("stroke-width=\"3\""));
    // The straight road's strips keep their height: 60 px each.
    let head = svg.find("height=\"").map(|i| &svg[i + 8..]).unwrap();
    let height: u32 = head[..head.find('"').unwrap()].parse().unwrap();
    assert!(height as usize >= 60 * ticks.len() && (height as usize) < 60 * ticks.len() + 140);
}

fn scaled(map: &Map) -> Vec<Tick> {
    trace(
        fixtures::bundle(),
        &Default::default(),
        Method::Scaled,
        map,
        11,
        Protocol::ZeroShot,
        0,
    )
    .unwrap()
    .1
}

#[test]
fn the_replay_page_carries_the_vehicles_and_every_head() {
    let map = red_runner();
    let ticks = never_brake(&map);
    let page = replay_html("red runner", "hit it", &map, &ticks, 0.2).unwrap();
    let start_tag = "<script type=\"application/json\" id=\"episode\">";
    let start = page.find(start_tag).unwrap() + start_tag.len();
    let end = start + page[start..].find("</script>").unwrap();
    let episode: serde_json::Value = serde_json::from_str(&page[start..end]).unwrap();
    let j = &episode["scene"]["junction"];
    assert_eq!(j["stop_lines"].as_array().unwrap().len(), 4);
    assert_eq!(j["cross_kerbs"], serde_json::json!([69.0, 76.0]));
    let shows: Vec<&str> = (j["heads"].as_array().unwrap().iter())
        .map(|h| h[2].as_str().unwrap())
        .collect();
    assert_eq!(shows, ["road", "cross", "cross", "walk_road", "walk_road"]);
    let ticks = episode["ticks"].as_array().unwrap();
    // The runner's pose at the collision: in the box, heading north, in the car's path.
    let last = &ticks.last().unwrap();
    let runner = &last["vehicles"][0];
    let (x, y, heading) = (
        runner[0].as_f64().unwrap(),
        runner[1].as_f64().unwrap(),
        runner[2].as_f64().unwrap(),
    );
    assert!((69.0..=76.0).contains(&x) && y.abs() < 6.0, "{runner}");
    assert!((heading - std::f64::consts::FRAC_PI_2).abs() < 1e-3);
    assert_eq!(runner[5], true);
    assert_eq!(last["vehicle_in_path"], true);
    // The heads: the car's green while the runner runs the cross street's red.
    assert_eq!(last["signals"]["road"], "green");
    assert_eq!(last["signals"]["cross"], "red");
    assert_eq!(last["signals"]["walk_road"], "dont_walk");
    assert!(
        ticks
            .iter()
            .all(|t| t["vehicles"].is_array() && t["signals"]["walk_cross"].is_string())
    );
    // Without a junction the page has no street.
    let jaywalk = unforeseen_harness::maps::load("jaywalk").unwrap();
    let page = replay_html("jaywalk", "ended", &jaywalk, &scaled(&jaywalk), 0.2).unwrap();
    assert!(page.contains("\"junction\":null"));
}

#[test]
fn trace_csv_lists_the_vehicles_on_a_map_with_traffic_only() {
    let dir = tempfile::tempdir().unwrap();
    let csv_of = |map: &str, out: &str| {
        let job = TraceRequest {
            map: map.to_string(),
            method: Method::NeverBrake,
            seed: 2,
            out: Some(dir.path().join(out)),
            ..TraceRequest::default()
        }
        .plan(Some(fixtures::bundle().clone()))
        .unwrap();
        let report = job.run(fixtures::bundle()).unwrap();
        job.write(&report).unwrap();
        std::fs::read_to_string(dir.path().join(out).join("trace.csv")).unwrap()
    };
    let csv = csv_of(&fixtures::repo_path(RED_RUNNER).display().to_string(), "junction");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(
        header[15..],
        [
            "vehicles",
            "vehicle_in_path",
            "nearest_in_path_m",
            "nearest_in_path_speed",
            "road_head",
            "cross_head"
        ]
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    // Some tick sees the runner in the car's path, metres ahead at its 12-13 m/s.
    let seen: Vec<&Vec<&str>> = rows.iter().filter(|r| r[16] == "1").collect();
    assert!(!seen.is_empty(), "{csv}");
    for r in &seen {
        assert_eq!(r[15], "1");
        let (gap, speed): (f64, f64) = (r[17].parse().unwrap(), r[18].parse().unwrap());
        assert!((0.0..60.0).contains(&gap) && (11.0..=13.5).contains(&speed), "{r:?}");
        assert_eq!((r[19], r[20]), ("green", "red"));
    }
    assert!(rows.iter().any(|r| r[15] == "0" && r[17] == "-"));
    // The paper's straight road: the columns it always had.
    let csv = csv_of("jaywalk", "straight");
    assert!(csv.lines().next().unwrap().ends_with(",car_x,car_speed,light"));
}
