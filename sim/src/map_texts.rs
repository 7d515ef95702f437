//! The texts of the maps shipped in `maps/`, compiled into the binary (data only:
//! [`crate::embedded`] loads them, and the loader resolves bases among them).

/// `maps/intersection.ron`: the training intersection (pedestrians cross on red only).
pub const INTERSECTION: &str = include_str!("../../maps/intersection.ron");
/// `maps/jaywalk.ron`: the paper's test (a pedestrian crosses on green in front of the car).
pub const JAYWALK: &str = include_str!("../../maps/jaywalk.ron");
/// `maps/jaywalk_late.ron`: a faster jaywalker who steps out later.
pub const JAYWALK_LATE: &str = include_str!("../../maps/jaywalk_late.ron");
/// `maps/two_pedestrians.ron`: jaywalkers from both kerbs.
pub const TWO_PEDESTRIANS: &str = include_str!("../../maps/two_pedestrians.ron");
/// `maps/stuck_green.ron`: the light never leaves green, plus a jaywalker.
pub const STUCK_GREEN: &str = include_str!("../../maps/stuck_green.ron");
/// `maps/stop_midway.ron`: a jaywalker who stops in the car's lane.
pub const STOP_MIDWAY: &str = include_str!("../../maps/stop_midway.ron");
/// `maps/far_appearance.ron`: a jaywalker appears while the car is still far away (d = 3).
pub const FAR_APPEARANCE: &str = include_str!("../../maps/far_appearance.ron");
/// `maps/slow_walker.ron`: a slow jaywalker from the near kerb.
pub const SLOW_WALKER: &str = include_str!("../../maps/slow_walker.ron");
/// `maps/long_pause.ron`: a jaywalker who stops in the car's lane for 10 s.
pub const LONG_PAUSE: &str = include_str!("../../maps/long_pause.ron");
/// `maps/near_kerb.ron`: a walker steps out from the near kerb close in front of the car.
pub const NEAR_KERB: &str = include_str!("../../maps/near_kerb.ron");
/// `maps/late_fast.ron`: a fast runner steps out late.
pub const LATE_FAST: &str = include_str!("../../maps/late_fast.ron");

/// `maps/junction/training.ron`: the training junction (cross traffic and pedestrians obey the signals).
pub const JUNCTION_TRAINING: &str = include_str!("../../maps/junction/training.ron");
/// `maps/junction/red_runner.ron`: a cross-street car runs its red on the car's green.
pub const JUNCTION_RED_RUNNER: &str = include_str!("../../maps/junction/red_runner.ron");
/// `maps/junction/dark_signal.ron`: the signals go dark with cross traffic.
pub const JUNCTION_DARK_SIGNAL: &str = include_str!("../../maps/junction/dark_signal.ron");
/// `maps/junction/stalled_box.ron`: a lead car stalls in the junction box.
pub const JUNCTION_STALLED_BOX: &str = include_str!("../../maps/junction/stalled_box.ron");
/// `maps/junction/lead_brakes.ron`: the lead car brakes hard.
pub const JUNCTION_LEAD_BRAKES: &str = include_str!("../../maps/junction/lead_brakes.ron");
/// `maps/junction/left_turner.ron`: an oncoming car turns left across the car's path without yielding.
pub const JUNCTION_LEFT_TURNER: &str = include_str!("../../maps/junction/left_turner.ron");
/// `maps/junction/jaywalk.ron`: the paper's jaywalker at the junction.
pub const JUNCTION_JAYWALK: &str = include_str!("../../maps/junction/jaywalk.ron");

/// Every embedded map: its name (the map's own `name`), its file in `maps/` and its text.
const ALL: &[(&str, &str, &str)] = &[
    ("intersection", "intersection.ron", INTERSECTION),
    ("jaywalk", "jaywalk.ron", JAYWALK),
    ("jaywalk_late", "jaywalk_late.ron", JAYWALK_LATE),
    ("two_pedestrians", "two_pedestrians.ron", TWO_PEDESTRIANS),
    ("stuck_green", "stuck_green.ron", STUCK_GREEN),
    ("stop_midway", "stop_midway.ron", STOP_MIDWAY),
    ("far_appearance", "far_appearance.ron", FAR_APPEARANCE),
    ("slow_walker", "slow_walker.ron", SLOW_WALKER),
    ("long_pause", "long_pause.ron", LONG_PAUSE),
    ("near_kerb", "near_kerb.ron", NEAR_KERB),
    ("late_fast", "late_fast.ron", LATE_FAST),
    ("junction_training", "junction/training.ron", JUNCTION_TRAINING),
    ("junction_red_runner", "junction/red_runner.ron", JUNCTION_RED_RUNNER),
    ("junction_dark_signal", "junction/dark_signal.ron", JUNCTION_DARK_SIGNAL),
    ("junction_stalled_box", "junction/stalled_box.ron", JUNCTION_STALLED_BOX),
    ("junction_lead_brakes", "junction/lead_brakes.ron", JUNCTION_LEAD_BRAKES),
    ("junction_left_turner", "junction/left_turner.ron", JUNCTION_LEFT_TURNER),
    ("junction_jaywalk", "junction/jaywalk.ron", JUNCTION_JAYWALK),
];

const NAMES: &[&str] = &[
    "intersection",
    "jaywalk",
    "jaywalk_late",
    "two_pedestrians",
    "stuck_green",
    "stop_midway",
    "far_appearance",
    "slow_walker",
    "long_pause",
    "near_kerb",
    "late_fast",
    "junction_training",
    "junction_red_runner",
    "junction_dark_signal",
    "junction_stalled_box",
    "junction_lead_brakes",
    "junction_left_turner",
    "junction_jaywalk",
];

/// Names of the embedded maps (without `.ron`).
pub fn names() -> &'static [&'static str] {
    NAMES
}

/// The text of an embedded map, by name with or without `.ron`.
pub fn source(name: &str) -> Option<&'static str> {
    let name = name.strip_prefix("maps/").unwrap_or(name);
    let name = name.strip_suffix(".ron").unwrap_or(name);
    ALL.iter().find(|(n, _, _)| *n == name).map(|(_, _, s)| *s)
}

/// The file of an embedded map in `maps/` (`"junction/red_runner.ron"`), by name.
pub fn path(name: &str) -> Option<&'static str> {
    ALL.iter().find(|(n, _, _)| *n == name).map(|(_, p, _)| *p)
}

/// The embedded map a base names, as the map file `including` (a name) would find it
/// in `maps/`: the base as a file relative to the including map's folder (as written,
/// then with `.ron` added; `..` climbs a folder), else by name. Its name and text.
pub fn base_of(including: &str, base: &str) -> Option<(&'static str, &'static str)> {
    let folder = path(including)
        .and_then(|p| p.rsplit_once('/'))
        .map_or("", |(dir, _)| dir);
    let mut parts: Vec<&str> = folder.split('/').filter(|p| !p.is_empty()).collect();
    let mut inside = true;
    for part in base.split('/') {
        match part {
            ".." => inside &= parts.pop().is_some(),
            "." | "" => {}
            p => parts.push(p),
        }
    }
    let by_path = |p: &str| ALL.iter().find(|(_, f, _)| *f == p).map(|(n, _, s)| (*n, *s));
    let relative = parts.join("/");
    (inside
        .then(|| by_path(&relative).or_else(|| by_path(&format!("{relative}.ron"))))
        .flatten())
    .or_else(|| {
        let name = base.strip_suffix(".ron").unwrap_or(base);
        ALL.iter().find(|(n, _, _)| *n == name).map(|(n, _, s)| (*n, *s))
    })
}
