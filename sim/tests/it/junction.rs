//! The junction, its signal controller and other vehicles: bad junction maps refused
//! with file:line:col, the controller's states in the world, IDM stops and gaps, no
//! vehicle through another, crashes with vehicles, and determinism.

use unforeseen_sim::{Action, Aspect, LightPhase, Map, MapError, Route, Snapshot, World};

use crate::common::run;

fn load(text: &str) -> Result<Map, MapError> {
    Map::from_str_named("j.ron", text, &|_| None)
}

/// The diagnostic of `path` in the refusal of `text`, as printed.
fn refusal(text: &str, path: &str) -> String {
    let e = load(text).expect_err("the map should be refused");
    let d = (e.diagnostics().iter())
        .find(|d| d.path == path)
        .unwrap_or_else(|| panic!("no diagnostic at {path}: {e}"));
    assert!(d.position.is_some(), "no line:col: {d}");
    d.to_string()
}

#[test]
fn bad_junctions_are_refused_with_their_place() {
    let d = refusal("Map(\n  junction: (x: 95.0),\n)", "junction.x");
    assert!(
        d.starts_with("j.ron:2:14: junction.x: ") && d.contains("outside the road"),
        "{d}"
    );
    let d = refusal("Map(junction: (x: 60.0))", "junction.x");
    assert!(d.contains("does not lie past the map's crosswalk"), "{d}");
    let d = refusal("Map(\n  junction: (stop_gap: -8.0),\n)", "junction.stop_gap");
    assert!(
        d.starts_with("j.ron:2:") && d.contains("past the crosswalk's near edge"),
        "{d}"
    );
    for field in ["lane_width", "sidewalk_width"] {
        for v in ["0.0", "-1.0"] {
            let d = refusal(&format!("Map(junction: ({field}: {v}))"), &format!("junction.{field}"));
            assert!(d.contains("greater than 0"), "{d}");
        }
    }
    let d = refusal("Map(junction: (crosswalks: [South, South]))", "junction.crosswalks");
    assert!(d.contains("twice"), "{d}");
    let d = refusal("Map(traffic: [(route: FromNorth)])", "traffic[0].route");
    assert!(d.contains("no junction"), "{d}");
    // A vehicle faster than its street's limit, on the road and on the cross street.
    let d = refusal(
        "Map(junction: (),\n  traffic: [(route: Lead, speed: (8.0, 20.0))])",
        "traffic[0].speed",
    );
    assert!(
        d.starts_with("j.ron:2:") && d.contains("above the road's limit of 13.9 m/s"),
        "{d}"
    );
    let d = refusal(
        "Map(junction: (cross_speed_limit: 8.0), traffic: [(route: FromSouth, speed: (8.0, 9.0))])",
        "traffic[0].speed",
    );
    assert!(d.contains("cross street's limit of 8 m/s"), "{d}");
    // A lead vehicle that would appear beyond the road's end.
    let d = refusal("Map(traffic: [(route: Lead, start: 95.0)])", "traffic[0].start");
    assert!(d.contains("outside the road"), "{d}");
    // An unknown field inside the junction is named with a suggestion.
    let e = load("Map(junction: (stop_gp: 1.0))").unwrap_err();
    assert!(e.to_string().contains("did you mean `stop_gap`?"), "{e}");
}

#[test]
fn two_crossing_directions_green_at_once_are_refused() {
    // The car's default cycle is green for its first 12 s; a cross green from 10 s overlaps it.
    let text = "Map(junction: (cross: Cycle([\n  (phase: Red, duration: 10.0),\n  (phase: Green, duration: 10.0),\n  (phase: Red, duration: 4.0),\n])))";
    let d = refusal(text, "junction.cross");
    assert!(
        d.contains("from 10 s to 12 s") && d.contains("green and the cross street green"),
        "{d}"
    );
    let d = refusal(
        "Map(junction: (cross: Cycle([(phase: Red, duration: 20.0)])))",
        "junction.cross",
    );
    assert!(d.contains("the same length"), "{d}");
    let d = refusal(
        "Map(light: (cycle: [(phase: Green, duration: 10.0), (phase: Red, duration: 3.0)]), junction: ())",
        "light.cycle",
    );
    assert!(d.contains("too short"), "{d}");
    // A conflict-free explicit cycle loads.
    let ok = "Map(junction: (cross: Cycle([(phase: Red, duration: 15.0), (phase: Green, duration: 6.0), (phase: Amber, duration: 2.0), (phase: Red, duration: 1.0)])))";
    assert!(load(ok).is_ok(), "{:?}", load(ok).err());
}

fn snaps(map: &Map, seed: u64, mut policy: impl FnMut(&Snapshot) -> Action) -> Vec<Snapshot> {
    let mut world = World::from_map(map, seed);
    run(&mut world, &mut policy).0
}

/// With a junction but no outage, the car's reading is its light, and the cross street
/// is red whenever the car's signal is not.
#[test]
fn the_world_shows_every_head() {
    let map = load("Map(junction: (), light: (offset: Random), episode: (max_steps: 100))").unwrap();
    let plain = load("Map(light: (offset: Random), episode: (max_steps: 100))").unwrap();
    let s = snaps(&map, 3, |_| Action::SlowDown);
    let p = snaps(&plain, 3, |_| Action::SlowDown);
    assert_eq!(s.len(), p.len());
    let mut cross_green = 0;
    for (a, b) in s.iter().zip(&p) {
        assert_eq!(
            (a.light, a.light_time_left.to_bits()),
            (b.light, b.light_time_left.to_bits())
        );
        assert_eq!(a.signals.road, Aspect::Lit(a.light));
        if a.signals.cross == Aspect::Lit(LightPhase::Green) {
            cross_green += 1;
            assert_eq!(a.light, LightPhase::Red);
        }
        assert_eq!(b.signals.cross, Aspect::Lit(LightPhase::Red));
    }
    assert!(cross_green > 10, "{cross_green}");
}

#[test]
fn an_outage_reads_as_the_map_chooses() {
    for (reads, want) in [("Red", LightPhase::Red), ("Green", LightPhase::Green)] {
        let map = load(&format!(
            "Map(light: (offset: Fixed(14.5)), junction: (outages: [(start: AtTime(3.0), duration: 20.0)], dark_reads_as: {reads}), episode: (max_steps: 30))"
        ))
        .unwrap();
        let s = snaps(&map, 1, |_| Action::SlowDown);
        for snap in &s {
            let dark = (3.0..23.0).contains(&snap.time);
            assert_eq!(snap.signals.dark(), dark, "t = {}", snap.time);
            if dark {
                assert_eq!((snap.light, snap.light_time_left), (want, 0.0));
            }
        }
        // Before the outage the car's signal shows red (14.5 s into the cycle).
        assert_eq!(s[1].light, LightPhase::Red);
    }
}

/// The map of one lead vehicle (and what else `traffic` adds) before a red light, the
/// car standing well behind.
fn red_light_map(traffic: &str) -> Map {
    load(&format!(
        "Map(light: (cycle: [(phase: Red, duration: 3600.0)]), vehicle: (start_speed: 0.0), junction: (), traffic: [{traffic}], episode: (max_steps: 60))"
    ))
    .unwrap()
}

#[test]
fn idm_stops_at_the_stop_line_and_keeps_its_gap() {
    let map = red_light_map("(route: Lead, start: 20.0), (route: Lead, start: 8.0, speed: (6.0, 6.0))");
    let s = snaps(&map, 5, |_| Action::SlowDown);
    let last = s.last().unwrap();
    assert_eq!(last.vehicles.len(), 2);
    let (first, second) = (last.vehicles[0], last.vehicles[1]);
    assert!(first.speed < 1e-3 && second.speed < 1e-3, "{first:?} {second:?}");
    // The first stands with its front on the stop line, within 0.5 m.
    assert!(first.past_stop_line.abs() <= 0.5, "{first:?}");
    // The second stands s0 = 2 m behind the first's rear, within 0.5 m.
    let gap = first.past_stop_line - first.length - second.past_stop_line;
    assert!((gap - 2.0).abs() <= 0.5, "gap {gap}");
    // So do the cross street's vehicles at their (red) stop line, on the car's green.
    let map = load(
        "Map(light: (cycle: [(phase: Green, duration: 3600.0)]), junction: (crosswalks: [South]), traffic: [(route: FromSouth, start: 40.0), (route: FromNorth, start: 25.0, speed: (12.0, 13.5))], episode: (max_steps: 20))",
    )
    .unwrap();
    let s = snaps(&map, 2, |_| Action::SlowDown);
    for v in &s.last().unwrap().vehicles {
        assert!(v.speed < 1e-3 && v.past_stop_line.abs() <= 0.5, "{v:?}");
    }
}

/// Axis-aligned rectangles of two vehicles overlap (their headings are multiples of 90°).
fn overlap(a: &unforeseen_sim::VehicleSnapshot, b: &unforeseen_sim::VehicleSnapshot) -> bool {
    let ext = |v: &unforeseen_sim::VehicleSnapshot| {
        let along_x = v.heading.cos().abs() > 0.5;
        let (hx, hy) = if along_x {
            (v.length / 2.0, v.width / 2.0)
        } else {
            (v.width / 2.0, v.length / 2.0)
        };
        (v.x - hx, v.x + hx, v.y - hy, v.y + hy)
    };
    let (a, b) = (ext(a), ext(b));
    a.0 < b.1 && b.0 < a.1 && a.2 < b.3 && b.2 < a.3
}

#[test]
fn no_vehicle_drives_through_another() {
    // A car stalls in the box; one follows it, a red-runner comes from the south into
    // its side, and a queue forms on a repeated rule.
    let map = load(
        "Map(light: (offset: Fixed(0.0)), vehicle: (start_speed: 0.0), junction: (), traffic: [
            (route: Lead, start: 40.0, behaviour: Stalls(at: 9.0)),
            (route: Lead, start: 10.0, speed: (9.0, 11.0)),
            (route: FromSouth, start: 30.0, trigger: AtTime(6.0), behaviour: RunsRed, speed: (10.0, 10.0)),
            (route: FromNorth, trigger: GreenStarts, start: 20.0),
            (route: FromNorth, trigger: RedStarts, start: 20.0),
        ], episode: (max_steps: 80))",
    )
    .unwrap();
    let s = snaps(&map, 9, |_| Action::SlowDown);
    let mut most = 0;
    for snap in &s {
        most = most.max(snap.vehicles.len());
        for (i, a) in snap.vehicles.iter().enumerate() {
            for b in &snap.vehicles[i + 1..] {
                assert!(!overlap(a, b), "t = {}: {a:?} and {b:?}", snap.time);
            }
        }
    }
    assert!(most >= 4, "{most}");
    // The red-runner stopped against the stalled car's side rather than through it.
    let last = s.last().unwrap();
    let runner = last.vehicles.iter().find(|v| v.route == Route::FromSouth).unwrap();
    assert!(runner.speed < 1e-3, "{runner:?}");
}

#[test]
fn hitting_a_vehicle_is_a_crash() {
    // A red-runner from the south on the car's green, timed to meet it in the box.
    let map = load(
        "Map(light: (cycle: [(phase: Green, duration: 3600.0)]), vehicle: (start_speed: 9.0), junction: (), traffic: [(route: FromSouth, start: 78.0, speed: (10.0, 10.0), behaviour: RunsRed)])",
    )
    .unwrap();
    let mut world = World::from_map(&map, 1);
    let (_, out) = run(&mut world, |_| Action::SpeedUp);
    assert!(out.collision && !out.goal, "{out:?}");
    // Braking to a stop before the box, the car lets it pass.
    let mut world = World::from_map(&map, 1);
    let (_, out) = run(&mut world, |s| {
        if s.car_x < 45.0 {
            Action::Maintain
        } else {
            Action::SlowDown
        }
    });
    assert!(!out.collision, "{out:?}");
}

#[test]
fn the_same_seed_gives_the_same_bits() {
    let map = load(
        "Map(light: (offset: Random), junction: (outages: [(start: CarWithin(min: 10.0, max: 30.0), duration: 8.0)]), traffic: [
            (route: Lead, start: 25.0, speed: (5.0, 9.0), behaviour: BrakesHard(after: 4.0, decel: 7.0, hold: 2.0)),
            (route: Oncoming, trigger: RedStarts, probability: 0.7, delay: (0.0, 3.0), speed: (6.0, 10.0)),
            (route: FromSouth, trigger: GreenStarts, delay: (0.0, 2.0)),
        ], episode: (max_steps: 60))",
    )
    .unwrap();
    let trace = |seed| {
        format!(
            "{:?}",
            snaps(&map, seed, |s| if s.car_x < 40.0 {
                Action::SpeedUp
            } else {
                Action::SlowDown
            })
        )
    };
    assert_eq!(trace(4), trace(4));
    assert_ne!(trace(4), trace(5));
}
