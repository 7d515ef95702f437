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

const ALL: &[(&str, &str)] = &[
    ("intersection", INTERSECTION),
    ("jaywalk", JAYWALK),
    ("jaywalk_late", JAYWALK_LATE),
    ("two_pedestrians", TWO_PEDESTRIANS),
    ("stuck_green", STUCK_GREEN),
    ("stop_midway", STOP_MIDWAY),
    ("far_appearance", FAR_APPEARANCE),
    ("slow_walker", SLOW_WALKER),
    ("long_pause", LONG_PAUSE),
    ("near_kerb", NEAR_KERB),
    ("late_fast", LATE_FAST),
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
];

/// Names of the embedded maps (without `.ron`).
pub fn names() -> &'static [&'static str] {
    NAMES
}

/// The text of an embedded map, by name with or without `.ron`.
pub fn source(name: &str) -> Option<&'static str> {
    let name = name.strip_prefix("maps/").unwrap_or(name);
    let name = name.strip_suffix(".ron").unwrap_or(name);
    ALL.iter().find(|(n, _)| *n == name).map(|(_, s)| *s)
}
