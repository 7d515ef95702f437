//! Semantic checks on a fully merged map. Every violated rule is reported,
//! each with its field path and a hint.

use crate::map::{Map, Offset, Trigger};

/// Largest number of physics sub-steps per decision tick.
pub const MAX_SUBSTEPS: f64 = 10_000.0;
/// Largest episode length, decision ticks.
pub const MAX_STEPS: u32 = 100_000;
/// Largest length / coordinate accepted, m.
pub const MAX_METRES: f64 = 100_000.0;
/// Most entries in any list (light phases, bin edges, rules, expectations).
pub const MAX_LIST: usize = 64;

/// One violated rule.
#[derive(Debug, Clone)]
pub(crate) struct Problem {
    pub path: String,
    pub message: String,
    pub hint: Option<String>,
}

struct Check {
    out: Vec<Problem>,
}

impl Check {
    fn fail(&mut self, path: &str, message: impl Into<String>, hint: &str) {
        self.out.push(Problem {
            path: path.to_string(),
            message: message.into(),
            hint: (!hint.is_empty()).then(|| hint.to_string()),
        });
    }

    /// A finite number within `max` in size.
    fn finite(&mut self, path: &str, v: f64) -> bool {
        if !v.is_finite() {
            self.fail(path, format!("must be a finite number, got {v}"), "");
            false
        } else if v.abs() > MAX_METRES * 10.0 {
            self.fail(
                path,
                format!("{v} is absurdly large"),
                "use real units: metres, seconds, m/s, kg",
            );
            false
        } else {
            true
        }
    }

    /// A finite number > 0.
    fn positive(&mut self, path: &str, v: f64) {
        if self.finite(path, v) && v <= 0.0 {
            self.fail(
                path,
                format!("must be greater than 0, got {v}"),
                "sizes, masses and durations are positive",
            );
        }
    }

    /// A finite number >= 0.
    fn non_negative(&mut self, path: &str, v: f64) {
        if self.finite(path, v) && v < 0.0 {
            self.fail(path, format!("must not be negative, got {v}"), "");
        }
    }

    /// A probability in [lo, hi] (hi inclusive unless `open`).
    fn probability(&mut self, path: &str, v: f64, open: bool) {
        if !v.is_finite() || !(0.0..=1.0).contains(&v) || (open && v >= 1.0) {
            let range = if open { "[0, 1)" } else { "[0, 1]" };
            self.fail(path, format!("must be in {range}, got {v}"), "a probability or a rate");
        }
    }

    /// A (min, max) range of positive/non-negative numbers.
    fn range(&mut self, path: &str, r: (f64, f64), positive: bool) {
        let before = self.out.len();
        if positive {
            self.positive(&format!("{path}.0"), r.0);
            self.positive(&format!("{path}.1"), r.1);
        } else {
            self.finite(&format!("{path}.0"), r.0);
            self.finite(&format!("{path}.1"), r.1);
        }
        if self.out.len() == before && r.0 > r.1 {
            self.fail(
                path,
                format!("min {} is greater than max {}", r.0, r.1),
                "write (min, max)",
            );
        }
    }

    fn edges(&mut self, path: &str, e: &[f64], unit: &str) {
        if e.is_empty() {
            self.fail(path, "needs at least one edge", "e.g. [0.0, 30.0, 60.0]");
            return;
        }
        if e.len() > MAX_LIST {
            self.fail(path, format!("{} edges is too many (at most {MAX_LIST})", e.len()), "");
            return;
        }
        for (i, &x) in e.iter().enumerate() {
            self.finite(&format!("{path}[{i}]"), x);
        }
        for i in 1..e.len() {
            if e[i].is_finite() && e[i - 1].is_finite() && e[i] <= e[i - 1] {
                self.fail(
                    &format!("{path}[{i}]"),
                    format!(
                        "edges must be strictly increasing, but {} {unit} follows {} {unit}",
                        e[i],
                        e[i - 1]
                    ),
                    "sort the edges and remove duplicates",
                );
            }
        }
    }
}

/// All rule violations of `map` (empty when it is valid).
pub(crate) fn validate(map: &Map) -> Vec<Problem> {
    let mut c = Check { out: Vec::new() };
    for (path, text) in [("name", &map.name), ("description", &map.description)] {
        if text.chars().any(char::is_control) {
            c.fail(
                path,
                format!("contains a control character ({text:?})"),
                "names and descriptions are printed in tables and logs: use plain text",
            );
        }
    }
    let r = &map.road;
    c.positive("road.lane_width", r.lane_width);
    if r.lanes == 0 || r.lanes > 16 {
        c.fail(
            "road.lanes",
            format!("must be 1..=16, got {}", r.lanes),
            "two lanes is the usual road",
        );
    }
    c.non_negative("road.sidewalk_width", r.sidewalk_width);
    c.finite("road.goal_x", r.goal_x);

    let w = &map.crosswalk;
    c.finite("crosswalk.x", w.x);
    c.positive("crosswalk.width", w.width);

    let v = &map.vehicle;
    c.positive("vehicle.length", v.length);
    c.positive("vehicle.width", v.width);
    c.positive("vehicle.mass", v.mass);
    c.finite("vehicle.start_x", v.start_x);
    c.non_negative("vehicle.start_speed", v.start_speed);
    c.positive("vehicle.max_accel", v.max_accel);
    c.positive("vehicle.max_brake", v.max_brake);
    c.positive("vehicle.max_speed", v.max_speed);
    c.non_negative("vehicle.damping", v.damping);
    if v.start_speed.is_finite() && v.max_speed.is_finite() && v.start_speed > v.max_speed {
        c.fail(
            "vehicle.start_speed",
            format!("{} m/s is above max_speed {} m/s", v.start_speed, v.max_speed),
            "lower start_speed or raise max_speed",
        );
    }
    if v.width.is_finite() && r.lane_width.is_finite() && v.width > r.lane_width {
        c.fail(
            "vehicle.width",
            format!("the car ({} m) is wider than its lane ({} m)", v.width, r.lane_width),
            "widen road.lane_width or narrow the car",
        );
    }

    // Geometry along the road: start < crosswalk < destination.
    let half = w.width / 2.0;
    if [r.goal_x, w.x, w.width, v.start_x].iter().all(|x| x.is_finite()) {
        if w.x + half > r.goal_x {
            c.fail(
                "crosswalk.x",
                format!(
                    "the crosswalk (x {}..{} m) lies beyond the destination (road.goal_x = {} m)",
                    w.x - half,
                    w.x + half,
                    r.goal_x
                ),
                "the crosswalk must end before road.goal_x",
            );
        }
        if w.x - half <= v.start_x {
            c.fail(
                "crosswalk.x",
                format!(
                    "the crosswalk's near edge (x {} m) is not ahead of the car's front (vehicle.start_x = {} m)",
                    w.x - half,
                    v.start_x
                ),
                "the car must start before the crosswalk",
            );
        }
        if r.goal_x <= v.start_x {
            c.fail(
                "road.goal_x",
                format!(
                    "the destination ({} m) is not ahead of the car ({} m)",
                    r.goal_x, v.start_x
                ),
                "goal_x must be greater than vehicle.start_x",
            );
        }
    }

    let l = &map.light;
    if l.cycle.is_empty() {
        c.fail(
            "light.cycle",
            "the light cycle is empty",
            "give at least one phase, e.g. [(phase: Green, duration: 12.0)]",
        );
    } else if l.cycle.len() > MAX_LIST {
        c.fail(
            "light.cycle",
            format!("{} phases is too many (at most {MAX_LIST})", l.cycle.len()),
            "",
        );
    } else {
        for (i, p) in l.cycle.iter().enumerate() {
            c.positive(&format!("light.cycle[{i}].duration"), p.duration);
        }
    }
    if let Offset::Fixed(o) = l.offset {
        c.finite("light.offset", o);
    }

    for (i, p) in map.pedestrians.iter().enumerate().take(MAX_LIST + 1) {
        if i == MAX_LIST {
            c.fail("pedestrians", format!("more than {MAX_LIST} spawn rules"), "");
            break;
        }
        let path = format!("pedestrians[{i}]");
        match p.trigger {
            Trigger::RedStarts | Trigger::GreenStarts => {}
            Trigger::AtTime(t) => c.non_negative(&format!("{path}.trigger"), t),
            Trigger::CarWithin { min, max } => c.range(&format!("{path}.trigger"), (min, max), false),
            Trigger::CarArrivesWithin(t) => c.positive(&format!("{path}.trigger"), t),
        }
        c.probability(&format!("{path}.probability"), p.probability, false);
        c.range(&format!("{path}.speed"), p.speed, true);
        c.range(&format!("{path}.delay"), p.delay, false);
        if p.delay.0 < 0.0 {
            c.fail(&format!("{path}.delay"), "delays cannot be negative", "");
        }
        let before = c.out.len();
        c.range(&format!("{path}.x_offset"), p.x_offset, false);
        if c.out.len() == before && (p.x_offset.0.abs() > half || p.x_offset.1.abs() > half) {
            c.fail(
                &format!("{path}.x_offset"),
                format!("walking lines must stay within the crosswalk (|offset| <= {half} m)"),
                "the offset is measured from the crosswalk's centre line",
            );
        }
        c.non_negative(&format!("{path}.start_back"), p.start_back);
        if p.start_back.is_finite() && r.sidewalk_width.is_finite() && p.start_back > r.sidewalk_width {
            c.fail(
                &format!("{path}.start_back"),
                format!(
                    "{} m is beyond the sidewalk ({} m wide)",
                    p.start_back, r.sidewalk_width
                ),
                "widen road.sidewalk_width or start closer to the kerb",
            );
        }
        c.positive(&format!("{path}.radius"), p.radius);
        if let Some(pa) = p.pause {
            c.non_negative(&format!("{path}.pause.after"), pa.after);
            c.non_negative(&format!("{path}.pause.duration"), pa.duration);
        }
    }

    let b = &map.bins;
    c.edges("bins.distance_edges", &b.distance_edges, "m");
    c.edges("bins.speed_edges", &b.speed_edges, "m/s");
    c.probability("bins.observation_noise", b.observation_noise, true);

    let rw = &map.reward;
    c.finite("reward.progress_per_metre", rw.progress_per_metre);
    c.finite("reward.goal", rw.goal);
    c.finite("reward.crash", rw.crash);
    c.finite("reward.step_cost", rw.step_cost);

    let e = &map.episode;
    c.positive("episode.decision_dt", e.decision_dt);
    c.positive("episode.physics_hz", e.physics_hz);
    let n = e.decision_dt * e.physics_hz;
    if e.decision_dt > 0.0 && e.physics_hz > 0.0 && n.is_finite() {
        if n.round() < 1.0 || (n - n.round()).abs() > 1e-6 * n.max(1.0) {
            c.fail(
                "episode.physics_hz",
                format!("decision_dt x physics_hz = {n} is not a whole number of sub-steps (at least 1)"),
                "e.g. decision_dt 1.0 with physics_hz 60",
            );
        } else if n > MAX_SUBSTEPS {
            c.fail(
                "episode.physics_hz",
                format!("{n} sub-steps per tick is too many (at most {MAX_SUBSTEPS})"),
                "60 Hz is plenty for road speeds",
            );
        }
    }
    if e.max_steps == 0 || e.max_steps > MAX_STEPS {
        c.fail(
            "episode.max_steps",
            format!("must be 1..={MAX_STEPS}, got {}", e.max_steps),
            "",
        );
    }

    if map.expect.len() > MAX_LIST {
        c.fail("expect", format!("more than {MAX_LIST} expectations"), "");
    }
    for (i, x) in map.expect.iter().enumerate().take(MAX_LIST) {
        let path = format!("expect[{i}]");
        for (name, val) in [
            ("min_success", x.min_success),
            ("max_success", x.max_success),
            ("max_collision", x.max_collision),
            ("max_inference_rate", x.max_inference_rate),
        ] {
            if let Some(v) = val {
                c.probability(&format!("{path}.{name}"), v, false);
            }
        }
        for (name, val) in [("min_reward", x.min_reward), ("max_reward", x.max_reward)] {
            if let Some(v) = val {
                c.finite(&format!("{path}.{name}"), v);
            }
        }
        if let (Some(lo), Some(hi)) = (x.min_success, x.max_success)
            && lo > hi
        {
            c.fail(&path, format!("min_success {lo} is above max_success {hi}"), "");
        }
        if let (Some(lo), Some(hi)) = (x.min_reward, x.max_reward)
            && lo > hi
        {
            c.fail(&path, format!("min_reward {lo} is above max_reward {hi}"), "");
        }
    }
    c.out
}
