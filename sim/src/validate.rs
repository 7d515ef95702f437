//! Semantic checks on a fully merged map. Every violated rule is reported,
//! each with its field path and a hint.
//!
//! Besides consistency, a map is bounded in what it may ask of a run (the limits below,
//! listed with their reasons in maps/README.md): physical quantities lie in sensible
//! ranges, an episode has a bounded number of physics sub-steps and pedestrians, and the
//! bins give a bounded number of joint states (so the agent's model fits in memory).

use crate::light::LightPhase;
use crate::map::{DistanceEdges, Dynamics, Map, Offset, Trigger};

mod junction_rules;

/// Largest number of physics sub-steps per decision tick.
pub const MAX_SUBSTEPS: f64 = 10_000.0;
/// Largest episode length, decision ticks.
pub const MAX_STEPS: u32 = 100_000;
/// Most physics sub-steps per episode (`max_steps x decision_dt x physics_hz`): a
/// sub-step takes about 1.75 µs here, so an episode stays under about 0.35 s of
/// physics (the default episode has 2400).
pub const MAX_EPISODE_SUBSTEPS: f64 = 200_000.0;
/// Most planning work per episode, `max_steps x (joint states)²`: Bayesian RL plans on
/// dense N x N matrices every decision tick (about 740 µs a tick at the default 64
/// states here), so an episode of it stays under about 10 s (max_steps ≤ 12207 at 64
/// states, ≤ 47 at 1024; the default episode is 40 x 64² = 163840).
pub const MAX_EPISODE_PLANNING: f64 = 5e7;
/// Largest length / coordinate accepted, m.
pub const MAX_METRES: f64 = 100_000.0;
/// Most entries in any list (light phases, bin edges, expectations).
pub const MAX_LIST: usize = 64;
/// Most pedestrian spawn rules.
pub const MAX_SPAWN_RULES: usize = 16;
/// Most pedestrians one episode can spawn (every rule firing every time it can): each
/// is a physics body simulated every sub-step.
pub const MAX_PEDESTRIANS: f64 = 100.0;
/// Most joint discrete states the bins may give (`(distance edges + 1) x (speed edges + 1)
/// x 2 x 2`): the agent's world model and Bayesian RL keep dense N x N matrices per
/// action, about 370 bytes x N² per trained agent (400 MB at 1024 states). Equal to
/// the agent crate's `limits::MAX_STATES`.
pub const MAX_JOINT_STATES: usize = 1024;
/// Longest map name, characters: a name is printed in tables and logs and becomes
/// part of a file name (a search's failure maps).
pub const MAX_NAME_CHARS: usize = 128;
/// Longest map description, characters (printed in `check-map`'s summary).
pub const MAX_DESCRIPTION_CHARS: usize = 4096;
/// Decision interval range, s.
pub const DECISION_DT: (f64, f64) = (0.05, 60.0);
/// Physics rate range, Hz.
pub const PHYSICS_HZ: (f64, f64) = (10.0, 10_000.0);

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

    /// A finite number in `[lo, hi]` (`unit` for messages, `why` the reason of the range);
    /// with `lo > 0`, zero and negative values get the plain "must be greater than 0".
    fn within(&mut self, path: &str, v: f64, (lo, hi): (f64, f64), unit: &str, why: &str) {
        if !self.finite(path, v) {
            return;
        }
        if lo > 0.0 && v <= 0.0 {
            self.positive(path, v);
        } else if v < lo {
            self.fail(
                path,
                format!("{} {unit} is below the accepted range [{lo}, {hi}] {unit}", short(v)),
                why,
            );
        } else if v > hi {
            self.fail(
                path,
                format!("{} {unit} is above the accepted range [{lo}, {hi}] {unit}", short(v)),
                why,
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
        self.range_within(path, r, positive, None);
    }

    /// [`Check::range`], each end also within `bounds` (`(lo, hi, unit, why)`).
    fn range_within(&mut self, path: &str, r: (f64, f64), positive: bool, bounds: Option<((f64, f64), &str, &str)>) {
        let before = self.out.len();
        if let Some((b, unit, why)) = bounds {
            self.within(&format!("{path}.0"), r.0, b, unit, why);
            self.within(&format!("{path}.1"), r.1, b, unit, why);
        } else if positive {
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

/// `v` as written in messages: plain, or in scientific notation when tiny or huge.
fn short(v: f64) -> String {
    if v != 0.0 && !(1e-4..1e9).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// All rule violations of `map` (empty when it is valid).
pub(crate) fn validate(map: &Map) -> Vec<Problem> {
    let mut c = Check { out: Vec::new() };
    for (path, text, most) in [
        ("name", &map.name, MAX_NAME_CHARS),
        ("description", &map.description, MAX_DESCRIPTION_CHARS),
    ] {
        let chars = text.chars().count();
        if chars > most {
            c.fail(
                path,
                format!("is {chars} characters long (at most {most})"),
                "names and descriptions are printed in tables and logs: shorten it",
            );
        } else if text.chars().any(char::is_control) {
            c.fail(
                path,
                format!("contains a control character ({text:?})"),
                "names and descriptions are printed in tables and logs: use plain text",
            );
        }
    }
    let r = &map.road;
    let body = "use real units: metres, seconds, m/s, kg";
    c.within(
        "road.lane_width",
        r.lane_width,
        (1.0, 10.0),
        "m",
        "a lane is 2.5 to 4 m wide",
    );
    if r.lanes == 0 || r.lanes > 16 {
        c.fail(
            "road.lanes",
            format!("must be 1..=16, got {}", r.lanes),
            "two lanes is the usual road",
        );
    }
    c.within(
        "road.sidewalk_width",
        r.sidewalk_width,
        (0.0, 20.0),
        "m",
        "pedestrians wait on the sidewalk",
    );
    c.finite("road.goal_x", r.goal_x);

    let w = &map.crosswalk;
    c.finite("crosswalk.x", w.x);
    c.within(
        "crosswalk.width",
        w.width,
        (0.5, 50.0),
        "m",
        "a zebra crossing is 2.5 to 6 m wide",
    );

    let v = &map.vehicle;
    c.within(
        "vehicle.length",
        v.length,
        (1.0, 20.0),
        "m",
        "a car is about 4.5 m long, a lorry up to 20 m",
    );
    c.within("vehicle.width", v.width, (0.5, 4.0), "m", "a car is about 1.8 m wide");
    c.within(
        "vehicle.mass",
        v.mass,
        (50.0, 60_000.0),
        "kg",
        "a car is about 1500 kg, a lorry up to 60 t",
    );
    c.finite("vehicle.start_x", v.start_x);
    c.non_negative("vehicle.start_speed", v.start_speed);
    c.within(
        "vehicle.max_accel",
        v.max_accel,
        (0.1, 20.0),
        "m/s²",
        "2 g is beyond any car",
    );
    c.within(
        "vehicle.max_brake",
        v.max_brake,
        (0.1, 20.0),
        "m/s²",
        "2 g is beyond any car",
    );
    c.within(
        "vehicle.max_speed",
        v.max_speed,
        (0.1, 70.0),
        "m/s",
        "70 m/s is 252 km/h",
    );
    c.within("vehicle.damping", v.damping, (0.0, 10.0), "1/s", body);
    check_forces(&mut c, map);
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
        // A phase shorter than one physics sub-step is never shown (checked once the
        // physics rate itself is valid).
        let hz = map.episode.physics_hz;
        let shortest = if (PHYSICS_HZ.0..=PHYSICS_HZ.1).contains(&hz) {
            1.0 / hz
        } else {
            0.0
        };
        for (i, p) in l.cycle.iter().enumerate() {
            let path = format!("light.cycle[{i}].duration");
            if p.duration == 0.0 || (p.duration > 0.0 && p.duration < shortest) {
                // 0 s too: a phase that never shows is as wrong as one shorter than a sub-step.
                c.fail(
                    &path,
                    format!("{} s is shorter than one physics sub-step ({shortest} s)", p.duration),
                    "a phase must last at least one sub-step (1 / episode.physics_hz)",
                );
            } else {
                c.within(&path, p.duration, (0.0, 1e6), "s", "a phase lasts seconds to hours");
            }
        }
    }
    if let Offset::Fixed(o) = l.offset {
        c.finite("light.offset", o);
    }

    if map.pedestrians.len() > MAX_SPAWN_RULES {
        c.fail(
            "pedestrians",
            format!(
                "{} spawn rules is too many (at most {MAX_SPAWN_RULES})",
                map.pedestrians.len()
            ),
            "every rule is checked every physics sub-step; merge rules or split the scenario",
        );
    }
    for (i, p) in map.pedestrians.iter().enumerate().take(MAX_SPAWN_RULES) {
        let path = format!("pedestrians[{i}]");
        match p.trigger {
            Trigger::RedStarts | Trigger::GreenStarts => {}
            Trigger::AtTime(t) => c.non_negative(&format!("{path}.trigger"), t),
            Trigger::CarWithin { min, max } => c.range(&format!("{path}.trigger"), (min, max), false),
            Trigger::CarArrivesWithin(t) => c.within(&format!("{path}.trigger"), t, (0.0, 3600.0), "s", body),
        }
        c.probability(&format!("{path}.probability"), p.probability, false);
        c.range_within(
            &format!("{path}.speed"),
            p.speed,
            true,
            Some((
                (0.01, 12.0),
                "m/s",
                "people walk at 0.5 to 2 m/s and sprint at up to 12",
            )),
        );
        c.range_within(
            &format!("{path}.delay"),
            p.delay,
            false,
            Some(((0.0, 3600.0), "s", "a delay of seconds to an hour")),
        );
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
        c.within(
            &format!("{path}.radius"),
            p.radius,
            (0.05, 1.5),
            "m",
            "a person's body radius is about 0.3 m",
        );
        if let Some(pa) = p.pause {
            c.non_negative(&format!("{path}.pause.after"), pa.after);
            c.within(&format!("{path}.pause.duration"), pa.duration, (0.0, 3600.0), "s", body);
        }
    }
    if map.pedestrians.len() <= MAX_SPAWN_RULES {
        let most = most_pedestrians(map);
        if most > MAX_PEDESTRIANS {
            c.fail(
                "pedestrians",
                format!(
                    "the rules can spawn up to {most:.0} pedestrians in one episode (at most {MAX_PEDESTRIANS}: each is a physics body simulated every sub-step)"
                ),
                "lengthen the light cycle, shorten the episode or use fewer RedStarts/GreenStarts rules",
            );
        }
    }

    let b = &map.bins;
    match &b.distance_edges {
        DistanceEdges::Goal(edges) => c.edges("bins.distance_edges", edges, "m"),
        DistanceEdges::Crosswalk(cw) => {
            c.within("bins.distance_edges.lead", cw.lead, (0.0, MAX_METRES), "m", "");
            c.within(
                "bins.distance_edges.approach",
                cw.approach,
                (f64::MIN_POSITIVE, MAX_METRES),
                "m",
                "",
            );
        }
    }
    c.edges("bins.speed_edges", &b.speed_edges, "m/s");
    c.probability("bins.observation_noise", b.observation_noise, true);
    if b.distance_edges.bin_count() <= MAX_LIST + 1 && b.speed_edges.len() <= MAX_LIST {
        let (nd, nv) = (b.distance_edges.bin_count(), b.speed_edges.len() + 1);
        let states = nd * nv * 4;
        if states > MAX_JOINT_STATES {
            let gb = (states * states * 370) as f64 / 1e9;
            c.fail(
                "bins",
                format!(
                    "the bins give {nd} x {nv} x 2 x 2 = {states} joint states (at most {MAX_JOINT_STATES}: the agent keeps dense N x N matrices per action, about {gb:.1} GB here)"
                ),
                "use fewer distance_edges or speed_edges (the default 3 + 3 give 64 states)",
            );
        }
    }

    let rw = &map.reward;
    c.finite("reward.progress_per_metre", rw.progress_per_metre);
    c.finite("reward.goal", rw.goal);
    c.finite("reward.crash", rw.crash);
    c.finite("reward.step_cost", rw.step_cost);
    c.finite("reward.red_light", rw.red_light);

    let e = &map.episode;
    c.within(
        "episode.decision_dt",
        e.decision_dt,
        DECISION_DT,
        "s",
        "the agent decides a few times a second to once a minute",
    );
    c.within(
        "episode.physics_hz",
        e.physics_hz,
        PHYSICS_HZ,
        "Hz",
        "below 10 Hz a car at speed skips past a pedestrian between steps",
    );
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
    } else if n.is_finite() && n.round() * f64::from(e.max_steps) > MAX_EPISODE_SUBSTEPS {
        c.fail(
            "episode",
            format!(
                "max_steps x decision_dt x physics_hz = {} x {} = {} physics sub-steps per episode (at most {MAX_EPISODE_SUBSTEPS}: about 0.35 s of physics per episode here)",
                e.max_steps,
                n.round(),
                n.round() * f64::from(e.max_steps)
            ),
            "lower max_steps or physics_hz (60 Hz is plenty for road speeds)",
        );
    }

    // Planning cost per episode: ticks x N² (checked when both are valid).
    let b = &map.bins;
    if e.max_steps >= 1
        && e.max_steps <= MAX_STEPS
        && b.distance_edges.bin_count() <= MAX_LIST + 1
        && b.speed_edges.len() <= MAX_LIST
    {
        let states = (b.distance_edges.bin_count() * (b.speed_edges.len() + 1) * 4) as f64;
        let work = f64::from(e.max_steps) * states * states;
        if states <= MAX_JOINT_STATES as f64 && work > MAX_EPISODE_PLANNING {
            c.fail(
                "episode.max_steps",
                format!(
                    "max_steps x (joint states)² = {} x {states}² = {work:.0} (at most {MAX_EPISODE_PLANNING:e}: Bayesian RL plans on N x N matrices every tick, so an episode would take minutes)",
                    e.max_steps
                ),
                &format!(
                    "at {states} states, at most {} ticks per episode: lower max_steps or use fewer bins",
                    (MAX_EPISODE_PLANNING / (states * states)).floor()
                ),
            );
        }
    }

    junction_rules::check(&mut c, map);

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
            ("max_red_light", x.max_red_light),
            ("max_timeout", x.max_timeout),
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

/// The road surface (always: a map may set it before switching to `Forces`) and the
/// parameters of the force-driven vehicle model (under `dynamics: Forces`).
fn check_forces(c: &mut Check, map: &Map) {
    let friction = |c: &mut Check, path: &str, mu: f64| {
        let hint = "μ is about 0.8 on dry asphalt, 0.4 wet, 0.1 on ice; racing tyres reach 2";
        if mu.is_finite() && mu <= 0.0 {
            c.fail(
                path,
                format!("a friction coefficient must be greater than 0, got {mu}"),
                hint,
            );
        } else {
            c.within(path, mu, (0.0, 2.0), "", hint);
        }
    };
    friction(c, "road.friction", map.road.friction);
    c.within(
        "road.air_density",
        map.road.air_density,
        (0.0, 5.0),
        "kg/m³",
        "air is 1.2 kg/m³ at sea level",
    );
    if map.road.surface.len() > MAX_LIST {
        c.fail(
            "road.surface",
            format!(
                "{} surface patches is too many (at most {MAX_LIST})",
                map.road.surface.len()
            ),
            "merge neighbouring patches",
        );
    }
    // The road the car can drive on: from its rear at the start to the destination.
    let (start, end) = (map.vehicle.start_x - map.vehicle.length, map.road.goal_x);
    for (i, p) in map.road.surface.iter().enumerate().take(MAX_LIST) {
        let path = format!("road.surface[{i}]");
        friction(c, &format!("{path}.friction"), p.friction);
        if !(c.finite(&format!("{path}.from"), p.from) & c.finite(&format!("{path}.to"), p.to)) {
            continue;
        }
        if p.from >= p.to {
            c.fail(
                &format!("{path}.to"),
                format!(
                    "the patch ends (x {} m) where or before it starts (x {} m)",
                    p.to, p.from
                ),
                "give from < to",
            );
        } else if start.is_finite() && end.is_finite() && (p.to <= start || p.from >= end) {
            c.fail(
                &path,
                format!(
                    "the patch (x {}..{} m) lies outside the road the car drives (x {start}..{end} m)",
                    p.from, p.to
                ),
                "place it between the car's rear at the start and road.goal_x",
            );
        }
        match p.trigger {
            None | Some(Trigger::RedStarts | Trigger::GreenStarts) => {}
            Some(Trigger::AtTime(t)) => c.non_negative(&format!("{path}.trigger"), t),
            Some(Trigger::CarWithin { min, max }) => c.range(&format!("{path}.trigger"), (min, max), false),
            Some(Trigger::CarArrivesWithin(t)) => c.within(
                &format!("{path}.trigger"),
                t,
                (0.0, 3600.0),
                "s",
                "use real units: seconds",
            ),
        }
    }
    let v = &map.vehicle;
    if v.dynamics != Dynamics::Forces {
        return;
    }
    let force = "a car's tyres carry up to about m g: 15 kN on 1500 kg";
    c.within("vehicle.drive_force", v.drive_force, (1e-9, 1e6), "N", force);
    c.within("vehicle.brake_force", v.brake_force, (1e-9, 1e6), "N", force);
    if v.power.is_finite() && v.power <= 0.0 && v.max_speed > 0.0 {
        c.fail(
            "vehicle.power",
            format!(
                "a power of {} W cannot move the car, yet max_speed is {} m/s",
                v.power, v.max_speed
            ),
            "give the engine's power at the tyres, e.g. 60000 W",
        );
    } else {
        c.within(
            "vehicle.power",
            v.power,
            (1e-9, 1e8),
            "W",
            "a car has about 60 kW, a lorry 400 kW",
        );
    }
    let lag = "brakes respond in about 0.1 to 0.5 s";
    c.within("vehicle.brake_lag", v.brake_lag, (0.0, 10.0), "s", lag);
    c.within("vehicle.brake_dead_time", v.brake_dead_time, (0.0, 10.0), "s", lag);
    c.within(
        "vehicle.rolling_resistance",
        v.rolling_resistance,
        (0.0, 0.5),
        "",
        "about 0.012 for car tyres on asphalt",
    );
    c.within(
        "vehicle.drag_coefficient",
        v.drag_coefficient,
        (0.0, 3.0),
        "",
        "a car's C_d is about 0.3",
    );
    c.within(
        "vehicle.frontal_area",
        v.frontal_area,
        (0.0, 50.0),
        "m²",
        "a car's is about 2.2 m²",
    );
}

/// The most pedestrians `map`'s rules can spawn in one episode: each one-off trigger
/// once, each phase-start trigger at every start of its phase (at most once per such
/// phase per cycle, plus the phase in force at time 0), whatever the probabilities.
fn most_pedestrians(map: &Map) -> f64 {
    let episode = f64::from(map.episode.max_steps) * map.episode.decision_dt;
    let cycle = map.light.cycle_length();
    map.pedestrians
        .iter()
        .map(|p| {
            let want = match p.trigger {
                Trigger::RedStarts => LightPhase::Red,
                Trigger::GreenStarts => LightPhase::Green,
                _ => return 1.0,
            };
            let k = map.light.cycle.iter().filter(|ph| ph.phase == want).count() as f64;
            if k == 0.0 {
                0.0
            } else if cycle > 0.0 && cycle.is_finite() && episode.is_finite() {
                k * ((episode / cycle).floor() + 2.0)
            } else {
                f64::INFINITY
            }
        })
        .sum()
}
