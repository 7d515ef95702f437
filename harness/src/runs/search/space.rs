//! The space file: which fields of a base map vary, and over what range or set
//! (`maps/README.md`, "Space files"). A point of the space (one value per parameter) laid
//! over the base map gives a candidate map; every candidate is checked by the map
//! loader's own validation, so it is a valid map or is rejected with the loader's reason.
//!
//! A space file is read with the map loader's rules: syntax, type and unknown-field
//! errors carry `file:line:column`; semantic errors (an empty range, a range outside the
//! map limits, a rule the base map does not have) carry the line and column of the
//! parameter's `field` string, and every error has a hint saying how to fix it. All of
//! them are [`MapError`]s of [`Diagnostic`]s, so the command line exits 2 on them.

use serde::{Deserialize, Serialize};
use std::path::Path;
use unforeseen_sim::{
    Behaviour, Diagnostic, LightCondition, Map, MapError, Offset, Pause, Route, Side, SpawnRule, TrafficRule, Trigger,
};

/// Most parameters one space may have (dimensions of the scrambled Sobol sequence).
pub const MAX_PARAMS: usize = 64;

/// Largest space file accepted, bytes.
pub const MAX_SPACE_BYTES: usize = 1 << 20;

/// Width of a `CarWithin` window made by `trigger.kind` from another trigger, m.
pub const CAR_WITHIN_WIDTH: f64 = 2.0;

/// Values are rounded to this step (so candidate maps read as written numbers).
pub const VALUE_STEP: f64 = 1e-3;

/// A space file as written.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields, rename = "Space")]
pub struct SpaceFile {
    /// Short name; candidates are named `NAME_c0042`. Default: the file name.
    #[serde(default)]
    pub name: Option<String>,
    /// One line saying what the space is about.
    #[serde(default)]
    pub description: String,
    /// Pedestrian rules added after the base map's own (absent from the base: their
    /// `copies` default to 0, the base's rules' to 1). Refer to them as
    /// `pedestrians[N + j]` for a base with N rules.
    #[serde(default)]
    pub rules: Vec<SpawnRule>,
    /// Traffic rules added after the base map's own (absent from the base: their
    /// `copies` default to 0, the base's rules' to 1). Refer to them as `traffic[N + j]`
    /// for a base with N traffic rules.
    #[serde(default)]
    pub traffic: Vec<TrafficRule>,
    /// The parameters, in order (the order of the point's coordinates).
    pub params: Vec<ParamSpec>,
}

/// One parameter as written: a field and either a range or a set of choices.
#[derive(Debug, Clone, PartialEq, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ParamSpec {
    /// The field, e.g. `pedestrians[0].speed` or `vehicle.start_speed`.
    pub field: String,
    /// For numeric fields: (low, high), low < high.
    #[serde(default)]
    pub range: Option<(f64, f64)>,
    /// For named fields (`side`, `light`, `trigger.kind`): the names to choose from.
    #[serde(default)]
    pub choose: Option<Vec<String>>,
}

/// What a parameter sets on the map.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    /// A field of pedestrian rule `rule` (base rules first, then the space's `rules`).
    Rule(usize, RuleField),
    /// `vehicle.start_speed`, m/s.
    StartSpeed,
    /// `vehicle.max_brake`, m/s².
    MaxBrake,
    /// `vehicle.max_accel`, m/s².
    MaxAccel,
    /// `vehicle.max_speed`, m/s.
    MaxSpeed,
    /// `light.cycle[i].duration`, s.
    PhaseDuration(usize),
    /// `light.offset`: a fixed offset into the cycle, s.
    LightOffset,
    /// `bins.observation_noise`, probability.
    ObservationNoise,
    /// `crosswalk.x`, m.
    CrosswalkX,
    /// `road.friction`, μ.
    Friction,
    /// `vehicle.mass`, kg.
    Mass,
    /// `vehicle.brake_lag`, s.
    BrakeLag,
    /// `vehicle.brake_dead_time`, s.
    BrakeDeadTime,
    /// `vehicle.brake_force`, N.
    BrakeForce,
    /// A field of the base map's surface patch `i` (`road.surface[i]`).
    Surface(usize, SurfaceField),
    /// A field of traffic rule `rule` (base rules first, then the space's `traffic`).
    Traffic(usize, TrafficField),
}

/// A field of one traffic rule (sim's `TrafficRule`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TrafficField {
    /// Where it drives: `Lead`, `Oncoming`, `FromSouth`, `FromNorth` or `OncomingLeft`.
    Route,
    /// How it deviates from a careful driver: `Careful`, `RunsRed`, `DoesNotYield`,
    /// `Stalls` or `BrakesHard` (a variant's numbers from the rule if it has that
    /// variant, else [`DEFAULT_STALL`] and [`DEFAULT_BRAKES_HARD`]).
    Behaviour,
    /// The trigger's number, as for pedestrian rules.
    TriggerValue,
    /// The trigger's kind, as for pedestrian rules.
    TriggerKind,
    /// The car's signal required when it fires: `Any`, `Green` or `Red`.
    Light,
    /// The desired speed's low end, m/s (the rule's width kept).
    Speed,
    /// The delay's low end, s (width kept).
    Delay,
    /// Where it appears, m before its stop line (`Lead`: ahead of the car's front).
    Start,
    /// Probability that a firing spawns a vehicle.
    Probability,
    /// How many copies of the rule the map has (a whole number).
    Copies,
    /// `Stalls`' `at`: metres past its stop line where it stalls (no effect on another
    /// behaviour).
    StallAt,
    /// `BrakesHard`'s `after`, s (no effect on another behaviour).
    BrakeAfter,
    /// `BrakesHard`'s `decel`, m/s² (no effect on another behaviour).
    BrakeDecel,
}

/// The stall a space's `behaviour: Stalls` gives a rule that has none: 3 m into the box,
/// for ever.
pub const DEFAULT_STALL: Behaviour = Behaviour::Stalls {
    at: 3.0,
    hold: f64::INFINITY,
};

/// The hard stop a space's `behaviour: BrakesHard` gives a rule that has none: 3 s after
/// appearing, at 8 m/s², standing 3 s.
pub const DEFAULT_BRAKES_HARD: Behaviour = Behaviour::BrakesHard {
    after: 3.0,
    decel: 8.0,
    hold: 3.0,
};

/// A field of one surface patch.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SurfaceField {
    /// Where it starts, m (its length kept).
    From,
    /// Its length, m (its start kept).
    Length,
    /// Its friction coefficient μ.
    Friction,
}

/// A field of one pedestrian rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RuleField {
    /// The trigger's number: s of `CarArrivesWithin` and `AtTime`, m of `CarWithin`'s `min`.
    TriggerValue,
    /// The trigger's kind: `CarArrivesWithin`, `AtTime` or `CarWithin`.
    TriggerKind,
    /// The light condition: `Any`, `Green` or `Red`.
    Light,
    /// The start kerb: `Near`, `Far` or `Random`.
    Side,
    /// The walking speed's low end, m/s (the rule's width kept).
    Speed,
    /// The delay's low end, s (width kept).
    Delay,
    /// The walking line's offset, low end, m (width kept).
    XOffset,
    /// Metres walked before the pause (a pause is added if the rule has none).
    PauseAfter,
    /// Seconds of the pause (a pause is added if the rule has none).
    PauseDuration,
    /// Probability that a firing spawns a pedestrian.
    Probability,
    /// Body radius, m.
    Radius,
    /// How many copies of the rule the map has (a whole number; each copy draws its own
    /// side, speed, delay and offset from the episode seed).
    Copies,
}

const RULE_FIELDS: [(&str, RuleField); 12] = [
    ("trigger.value", RuleField::TriggerValue),
    ("trigger.kind", RuleField::TriggerKind),
    ("light", RuleField::Light),
    ("side", RuleField::Side),
    ("speed", RuleField::Speed),
    ("delay", RuleField::Delay),
    ("x_offset", RuleField::XOffset),
    ("pause.after", RuleField::PauseAfter),
    ("pause.duration", RuleField::PauseDuration),
    ("probability", RuleField::Probability),
    ("radius", RuleField::Radius),
    ("copies", RuleField::Copies),
];

const GLOBAL_FIELDS: [(&str, Field); 12] = [
    ("vehicle.start_speed", Field::StartSpeed),
    ("vehicle.max_brake", Field::MaxBrake),
    ("vehicle.max_accel", Field::MaxAccel),
    ("vehicle.max_speed", Field::MaxSpeed),
    ("light.offset", Field::LightOffset),
    ("bins.observation_noise", Field::ObservationNoise),
    ("crosswalk.x", Field::CrosswalkX),
    ("road.friction", Field::Friction),
    ("vehicle.mass", Field::Mass),
    ("vehicle.brake_lag", Field::BrakeLag),
    ("vehicle.brake_dead_time", Field::BrakeDeadTime),
    ("vehicle.brake_force", Field::BrakeForce),
];

const SURFACE_FIELDS: [(&str, SurfaceField); 3] = [
    ("from", SurfaceField::From),
    ("length", SurfaceField::Length),
    ("friction", SurfaceField::Friction),
];

const TRAFFIC_FIELDS: [(&str, TrafficField); 13] = [
    ("route", TrafficField::Route),
    ("behaviour", TrafficField::Behaviour),
    ("trigger.value", TrafficField::TriggerValue),
    ("trigger.kind", TrafficField::TriggerKind),
    ("light", TrafficField::Light),
    ("speed", TrafficField::Speed),
    ("delay", TrafficField::Delay),
    ("start", TrafficField::Start),
    ("probability", TrafficField::Probability),
    ("copies", TrafficField::Copies),
    ("stall_at", TrafficField::StallAt),
    ("brake_after", TrafficField::BrakeAfter),
    ("brake_decel", TrafficField::BrakeDecel),
];

const ROUTES: [&str; 5] = ["Lead", "Oncoming", "FromSouth", "FromNorth", "OncomingLeft"];
const BEHAVIOURS: [&str; 5] = ["Careful", "RunsRed", "DoesNotYield", "Stalls", "BrakesHard"];
const TRIGGER_KINDS: [&str; 3] = ["CarArrivesWithin", "AtTime", "CarWithin"];
const LIGHTS: [&str; 3] = ["Any", "Green", "Red"];
const SIDES: [&str; 3] = ["Near", "Far", "Random"];

/// Every field a space may vary, for hints.
fn field_list() -> String {
    let rule: Vec<String> = RULE_FIELDS.iter().map(|(n, _)| format!("pedestrians[i].{n}")).collect();
    let global: Vec<&str> = GLOBAL_FIELDS.iter().map(|(n, _)| *n).collect();
    let surface: Vec<String> = SURFACE_FIELDS
        .iter()
        .map(|(n, _)| format!("road.surface[i].{n}"))
        .collect();
    let traffic: Vec<String> = TRAFFIC_FIELDS.iter().map(|(n, _)| format!("traffic[i].{n}")).collect();
    format!(
        "{}, light.cycle[i].duration, {}, {}, {}",
        global.join(", "),
        surface.join(", "),
        rule.join(", "),
        traffic.join(", ")
    )
}

impl Field {
    /// Parses a field path (`pedestrians[2].speed`).
    fn parse(text: &str) -> Option<Field> {
        if let Some((_, f)) = GLOBAL_FIELDS.iter().find(|(n, _)| *n == text) {
            return Some(*f);
        }
        let index = |rest: &str| -> Option<(usize, String)> {
            let (i, tail) = rest.split_once(']')?;
            Some((i.parse().ok()?, tail.to_string()))
        };
        if let Some(rest) = text.strip_prefix("light.cycle[") {
            let (i, tail) = index(rest)?;
            return (tail == ".duration").then_some(Field::PhaseDuration(i));
        }
        if let Some(rest) = text.strip_prefix("road.surface[") {
            let (i, tail) = index(rest)?;
            let name = tail.strip_prefix('.')?;
            return SURFACE_FIELDS
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, f)| Field::Surface(i, *f));
        }
        if let Some(rest) = text.strip_prefix("traffic[") {
            let (i, tail) = index(rest)?;
            let name = tail.strip_prefix('.')?;
            return TRAFFIC_FIELDS
                .iter()
                .find(|(n, _)| *n == name)
                .map(|(_, f)| Field::Traffic(i, *f));
        }
        let rest = text.strip_prefix("pedestrians[")?;
        let (i, tail) = index(rest)?;
        let name = tail.strip_prefix('.')?;
        RULE_FIELDS
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, f)| Field::Rule(i, *f))
    }

    /// The names a choice field takes, or `None` for a numeric field.
    fn choices(self) -> Option<&'static [&'static str]> {
        match self {
            Field::Rule(_, RuleField::TriggerKind) => Some(&TRIGGER_KINDS),
            Field::Rule(_, RuleField::Light) => Some(&LIGHTS),
            Field::Rule(_, RuleField::Side) => Some(&SIDES),
            Field::Traffic(_, TrafficField::Route) => Some(&ROUTES),
            Field::Traffic(_, TrafficField::Behaviour) => Some(&BEHAVIOURS),
            Field::Traffic(_, TrafficField::TriggerKind) => Some(&TRIGGER_KINDS),
            Field::Traffic(_, TrafficField::Light) => Some(&LIGHTS),
            _ => None,
        }
    }

    /// The values the map limits (maps/README.md, "Limits") allow, with the unit.
    fn limits(self, base: &Map) -> (f64, f64, &'static str) {
        use RuleField as R;
        use TrafficField as T;
        match self {
            Field::Traffic(_, T::TriggerValue) => (0.0, 3600.0, "s or m"),
            Field::Traffic(_, T::Speed) => (0.01, 70.0, "m/s"),
            Field::Traffic(_, T::Delay | T::BrakeAfter) => (0.0, 3600.0, "s"),
            Field::Traffic(_, T::Start | T::StallAt) => (0.0, unforeseen_sim::MAX_METRES, "m"),
            Field::Traffic(_, T::Probability) => (0.0, 1.0, "(a probability)"),
            Field::Traffic(_, T::Copies) => (0.0, unforeseen_sim::MAX_SPAWN_RULES as f64, "copies"),
            Field::Traffic(_, T::BrakeDecel) => (0.1, unforeseen_sim::traffic::MAX_DECEL, "m/s²"),
            Field::Traffic(_, T::Route | T::Behaviour | T::TriggerKind | T::Light) => (0.0, 0.0, ""),
            Field::Rule(_, R::TriggerValue) => (0.0, 3600.0, "s or m"),
            Field::Rule(_, R::Speed) => (0.01, 12.0, "m/s"),
            Field::Rule(_, R::Delay | R::PauseDuration) => (0.0, 3600.0, "s"),
            Field::Rule(_, R::XOffset) => {
                let h = base.crosswalk.width / 2.0;
                (-h, h, "m (within the crosswalk)")
            }
            Field::Rule(_, R::PauseAfter) => (0.0, 1000.0, "m"),
            Field::Rule(_, R::Probability) => (0.0, 1.0, "(a probability)"),
            Field::Rule(_, R::Radius) => (0.05, 1.5, "m"),
            Field::Rule(_, R::Copies) => (0.0, unforeseen_sim::MAX_SPAWN_RULES as f64, "copies"),
            Field::Rule(_, R::TriggerKind | R::Light | R::Side) => (0.0, 0.0, ""),
            Field::StartSpeed => (0.0, 70.0, "m/s"),
            Field::MaxBrake | Field::MaxAccel => (0.1, 20.0, "m/s²"),
            Field::MaxSpeed => (0.1, 70.0, "m/s"),
            Field::Friction | Field::Surface(_, SurfaceField::Friction) => (0.01, 2.0, "(μ)"),
            Field::Mass => (50.0, 60_000.0, "kg"),
            Field::BrakeLag | Field::BrakeDeadTime => (0.0, 10.0, "s"),
            Field::BrakeForce => (1.0, 1e6, "N"),
            Field::Surface(_, SurfaceField::From) => (
                base.vehicle.start_x - base.vehicle.length,
                base.road.goal_x,
                "m (on the road)",
            ),
            Field::Surface(_, SurfaceField::Length) => (0.01, unforeseen_sim::MAX_METRES, "m"),
            Field::PhaseDuration(_) => (1.0 / base.episode.physics_hz, 1e6, "s"),
            Field::LightOffset => (0.0, 1e6, "s"),
            Field::ObservationNoise => (0.0, 0.999, "(a probability below 1)"),
            Field::CrosswalkX => {
                let lo = base.vehicle.start_x + base.crosswalk.width / 2.0;
                (
                    lo,
                    base.road.goal_x - base.crosswalk.width / 2.0,
                    "m (between the car's start and the goal)",
                )
            }
        }
    }
}

/// One value of a parameter: a number or a name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum Value {
    /// A number (a whole number for `copies`).
    Num(f64),
    /// A name (`Near`, `Green`, `CarWithin`).
    Name(String),
}

impl std::fmt::Display for Value {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Value::Num(x) => write!(f, "{x}"),
            Value::Name(n) => f.write_str(n),
        }
    }
}

/// What a parameter ranges over.
#[derive(Debug, Clone, PartialEq)]
pub enum Domain {
    /// Numbers in [low, high].
    Range(f64, f64),
    /// Whole numbers low..=high.
    Count(u32, u32),
    /// One of these names.
    Choose(Vec<String>),
}

/// One checked parameter.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// The field path as written.
    pub name: String,
    /// What it sets.
    pub field: Field,
    /// What it ranges over.
    pub domain: Domain,
    /// Its value in the base map (what minimisation moves back to), if the base has one.
    pub base: Option<Value>,
}

impl Param {
    /// The value at coordinate `u` in [0, 1): a range maps linearly (rounded to
    /// [`VALUE_STEP`]), a count and a choice split [0, 1) into equal cells.
    pub fn value_at(&self, u: f64) -> Value {
        let u = u.clamp(0.0, 1.0);
        match &self.domain {
            Domain::Range(lo, hi) => Value::Num(round((lo + u * (hi - lo)).clamp(*lo, *hi))),
            Domain::Count(lo, hi) => {
                let n = (hi - lo + 1) as f64;
                Value::Num((*lo as f64 + (u * n).floor()).min(*hi as f64))
            }
            Domain::Choose(names) => {
                let i = ((u * names.len() as f64).floor() as usize).min(names.len() - 1);
                Value::Name(names[i].clone())
            }
        }
    }

    /// The coordinate in [0, 1] of a value (the centre of its cell for counts and
    /// choices; values outside the domain, e.g. a base value, are clamped).
    pub fn coordinate(&self, v: &Value) -> f64 {
        match (&self.domain, v) {
            (Domain::Range(lo, hi), Value::Num(x)) => ((x - lo) / (hi - lo)).clamp(0.0, 1.0),
            (Domain::Count(lo, hi), Value::Num(x)) => {
                let n = (hi - lo + 1) as f64;
                ((x - *lo as f64 + 0.5) / n).clamp(0.0, 1.0)
            }
            (Domain::Choose(names), Value::Name(n)) => {
                let i = names.iter().position(|c| c == n).unwrap_or(0);
                (i as f64 + 0.5) / names.len() as f64
            }
            _ => 0.5,
        }
    }

    /// Number of cells of a discrete parameter (`None` for a range).
    pub fn cells(&self) -> Option<usize> {
        match &self.domain {
            Domain::Range(..) => None,
            Domain::Count(lo, hi) => Some((hi - lo + 1) as usize),
            Domain::Choose(n) => Some(n.len()),
        }
    }
}

fn round(x: f64) -> f64 {
    let r = (x / VALUE_STEP).round() * VALUE_STEP;
    // Print as written: 2.4 rather than 2.4000000000000004.
    format!("{r:.3}").parse().unwrap_or(r)
}

/// A checked space over a base map.
#[derive(Debug, Clone, PartialEq)]
pub struct Space {
    /// The space's name.
    pub name: String,
    /// Its description.
    pub description: String,
    /// Where it was read from.
    pub source: String,
    /// The base map.
    pub base: Map,
    /// The space's extra rules (after the base's).
    pub rules: Vec<SpawnRule>,
    /// The space's extra traffic rules (after the base's).
    pub traffic: Vec<TrafficRule>,
    /// The parameters, in order.
    pub params: Vec<Param>,
    /// The file as read (for the run's identity).
    pub text: String,
}

/// What made a point of the space not a valid map.
pub type Rejection = String;

impl Space {
    /// Reads and checks the space file `path` over `base`.
    pub fn load(path: &Path, base: &Map) -> Result<Space, MapError> {
        let origin = path.display().to_string();
        let one = |message: String, hint: &str| {
            MapError::new(vec![Diagnostic {
                file: origin.clone(),
                position: None,
                path: String::new(),
                message,
                hint: Some(hint.to_string()),
            }])
        };
        let meta = std::fs::metadata(path).map_err(|e| {
            one(
                format!("cannot read the space file: {e}"),
                "give the path of a space file (.ron)",
            )
        })?;
        if !meta.is_file() {
            return Err(one("not a regular file".into(), "give the path of a space file (.ron)"));
        }
        if meta.len() > MAX_SPACE_BYTES as u64 {
            return Err(one(
                format!("the file is larger than {MAX_SPACE_BYTES} bytes"),
                "a space file lists a few parameters",
            ));
        }
        let bytes =
            std::fs::read(path).map_err(|e| one(format!("cannot read the space file: {e}"), "check the path"))?;
        let text =
            String::from_utf8(bytes).map_err(|_| one("not text (invalid UTF-8)".into(), "a space file is RON text"))?;
        Space::parse(&origin, &text, base)
    }

    /// Parses and checks space text; `origin` names it in diagnostics.
    pub fn parse(origin: &str, text: &str, base: &Map) -> Result<Space, MapError> {
        let diag = |position: Option<(usize, usize)>, path: &str, message: String, hint: String| Diagnostic {
            file: origin.to_string(),
            position,
            path: path.to_string(),
            message,
            hint: Some(hint),
        };
        if text.trim().is_empty() {
            return Err(MapError::new(vec![diag(
                None,
                "",
                "the space file is empty".into(),
                "write `Space(params: [(field: \"vehicle.start_speed\", range: (1.0, 5.0))])`".into(),
            )]));
        }
        let opts = ron::Options::default()
            .with_recursion_limit(64)
            .with_default_extension(ron::extensions::Extensions::IMPLICIT_SOME);
        let file: SpaceFile = opts.from_str(text).map_err(|e| {
            let hint = match &e.code {
                ron::Error::NoSuchStructField { expected, .. } => {
                    format!("the fields here are: {}", expected.join(", "))
                }
                ron::Error::Eof => "the file ends early: is it truncated or missing a `)`?".into(),
                _ => "see maps/README.md, \"Space files\", for the format".into(),
            };
            MapError::new(vec![diag(
                Some((e.span.start.line, e.span.start.col)),
                "",
                e.code.to_string(),
                hint,
            )])
        })?;
        let mut problems = Vec::new();
        let position = |field: &str| locate(text, field);
        let n_base = base.pedestrians.len();
        let n_rules = n_base + file.rules.len();
        let n_traffic_base = base.traffic.len();
        let n_traffic = n_traffic_base + file.traffic.len();
        if file.params.is_empty() {
            problems.push(diag(
                None,
                "params",
                "no parameters: the space has one point".into(),
                "add parameters, e.g. (field: \"vehicle.start_speed\", range: (1.0, 5.0))".into(),
            ));
        }
        if file.params.len() > MAX_PARAMS {
            problems.push(diag(
                None,
                "params",
                format!("{} parameters, at most {MAX_PARAMS}", file.params.len()),
                "vary fewer fields".into(),
            ));
        }
        if n_rules > unforeseen_sim::MAX_SPAWN_RULES {
            problems.push(diag(
                None,
                "rules",
                format!(
                    "the base's and the space's rules are {n_rules}, more than {}",
                    unforeseen_sim::MAX_SPAWN_RULES
                ),
                "add fewer rules".into(),
            ));
        }
        if n_traffic > unforeseen_sim::MAX_SPAWN_RULES {
            problems.push(diag(
                None,
                "traffic",
                format!(
                    "the base's and the space's traffic rules are {n_traffic}, more than {}",
                    unforeseen_sim::MAX_SPAWN_RULES
                ),
                "add fewer traffic rules".into(),
            ));
        }
        let mut params: Vec<Param> = Vec::new();
        for (i, p) in file.params.iter().enumerate() {
            let at = position(&p.field);
            let path = format!("params[{i}]");
            let mut bad = |message: String, hint: String| problems.push(diag(at, &path, message, hint));
            let Some(field) = Field::parse(&p.field) else {
                bad(
                    format!("unknown field `{}`", p.field),
                    format!("the fields a space can vary: {}", field_list()),
                );
                continue;
            };
            if params.iter().any(|q| q.field == field) {
                bad(
                    format!("`{}` is listed twice", p.field),
                    "give each field once, with its whole range".into(),
                );
                continue;
            }
            if let Field::Rule(r, _) = field
                && r >= n_rules
            {
                bad(
                    format!(
                        "pedestrian rule {r} does not exist: the base map has {n_base} rule(s) and the space adds {}",
                        file.rules.len()
                    ),
                    format!("use an index below {n_rules}, or add the rule to the space's `rules`"),
                );
                continue;
            }
            if let Field::Traffic(r, _) = field
                && r >= n_traffic
            {
                bad(
                    format!(
                        "traffic rule {r} does not exist: the base map has {n_traffic_base} traffic rule(s) and the space adds {}",
                        file.traffic.len()
                    ),
                    format!("use an index below {n_traffic}, or add the rule to the space's `traffic`"),
                );
                continue;
            }
            if let Field::Surface(k, _) = field
                && k >= base.road.surface.len()
            {
                bad(
                    format!(
                        "the base map's road has {} surface patch(es), not {}",
                        base.road.surface.len(),
                        k + 1
                    ),
                    "add the patch to the base map's road.surface, or use a lower index".to_string(),
                );
                continue;
            }
            if let Field::PhaseDuration(k) = field
                && k >= base.light.cycle.len()
            {
                bad(
                    format!(
                        "the base map's light cycle has {} phase(s), not {}",
                        base.light.cycle.len(),
                        k + 1
                    ),
                    format!("use an index below {}", base.light.cycle.len()),
                );
                continue;
            }
            let domain = match (field.choices(), &p.range, &p.choose) {
                (_, Some(_), Some(_)) => {
                    bad(
                        "both `range` and `choose`".into(),
                        "a numeric field takes `range: (low, high)`, a named one `choose: [..]`".into(),
                    );
                    continue;
                }
                (Some(allowed), _, None) => {
                    bad(
                        format!("`{}` is a named field: it takes `choose`", p.field),
                        format!(
                            "write choose: [{}]",
                            allowed
                                .iter()
                                .map(|a| format!("\"{a}\""))
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    );
                    continue;
                }
                (None, None, _) => {
                    bad(
                        format!("`{}` is a numeric field: it takes `range`", p.field),
                        "write range: (low, high)".into(),
                    );
                    continue;
                }
                (Some(allowed), None, Some(names)) => {
                    if names.is_empty() {
                        bad(
                            "an empty `choose`: nothing to choose from".into(),
                            format!("list some of {}", allowed.join(", ")),
                        );
                        continue;
                    }
                    if let Some(n) = names.iter().find(|n| !allowed.contains(&n.as_str())) {
                        bad(
                            format!("unknown choice `{n}`"),
                            format!("the choices are {}", allowed.join(", ")),
                        );
                        continue;
                    }
                    if names.iter().enumerate().any(|(j, n)| names[..j].contains(n)) {
                        bad("a choice is listed twice".into(), "list each choice once".into());
                        continue;
                    }
                    Domain::Choose(names.clone())
                }
                (None, Some((lo, hi)), None) => {
                    let (min, max, unit) = field.limits(base);
                    if !(lo.is_finite() && hi.is_finite()) || lo >= hi {
                        bad(
                            format!("an empty range ({lo}, {hi}): the low end must be below the high end"),
                            "write range: (low, high) with low < high; to fix a value, set it in the base map instead"
                                .into(),
                        );
                        continue;
                    }
                    if *lo < min || *hi > max {
                        bad(
                            format!("the range ({lo}, {hi}) leaves the map limits [{min}, {max}] {unit}"),
                            format!("keep the range within [{min}, {max}] (maps/README.md, \"Limits\")"),
                        );
                        continue;
                    }
                    if matches!(
                        field,
                        Field::Rule(_, RuleField::Copies) | Field::Traffic(_, TrafficField::Copies)
                    ) {
                        if lo.fract() != 0.0 || hi.fract() != 0.0 {
                            bad(
                                format!("copies are whole numbers, found ({lo}, {hi})"),
                                "write e.g. range: (0, 2)".into(),
                            );
                            continue;
                        }
                        Domain::Count(*lo as u32, *hi as u32)
                    } else {
                        Domain::Range(*lo, *hi)
                    }
                }
            };
            let rule_of = |r: usize| {
                if r < n_base {
                    &base.pedestrians[r]
                } else {
                    &file.rules[r - n_base]
                }
            };
            if let Field::Rule(r, RuleField::TriggerValue) = field {
                let kind_varies = file
                    .params
                    .iter()
                    .any(|q| Field::parse(&q.field) == Some(Field::Rule(r, RuleField::TriggerKind)));
                if !kind_varies && trigger_value(&rule_of(r).trigger).is_none() {
                    bad(
                        format!("pedestrian rule {r}'s trigger {:?} has no number to vary", rule_of(r).trigger),
                        "vary `trigger.value` of a rule triggered by CarArrivesWithin, AtTime or CarWithin, or vary its `trigger.kind` too".into(),
                    );
                    continue;
                }
            }
            let traffic_of = |r: usize| {
                if r < n_traffic_base {
                    &base.traffic[r]
                } else {
                    &file.traffic[r - n_traffic_base]
                }
            };
            if let Field::Traffic(r, TrafficField::TriggerValue) = field {
                let kind_varies = file
                    .params
                    .iter()
                    .any(|q| Field::parse(&q.field) == Some(Field::Traffic(r, TrafficField::TriggerKind)));
                if !kind_varies && trigger_value(&traffic_of(r).trigger).is_none() {
                    bad(
                        format!("traffic rule {r}'s trigger {:?} has no number to vary", traffic_of(r).trigger),
                        "vary `trigger.value` of a rule triggered by CarArrivesWithin, AtTime or CarWithin, or vary its `trigger.kind` too".into(),
                    );
                    continue;
                }
            }
            let base_value = match field {
                Field::Rule(r, f) => rule_value(rule_of(r), f, r < n_base),
                Field::Traffic(r, f) => traffic_value(traffic_of(r), f, r < n_traffic_base),
                _ => global_value(base, field),
            };
            params.push(Param {
                name: p.field.clone(),
                field,
                domain,
                base: base_value,
            });
        }
        let name = file.name.clone().unwrap_or_else(|| {
            let stem = origin.rsplit(['/', '\\']).next().unwrap_or(origin);
            stem.strip_suffix(".ron").unwrap_or(stem).to_string()
        });
        // The name becomes the failure maps' file names (`failures/NAME_c0042.ron`).
        if let Err(problem) = crate::runs::outputs::file_name("name", &name) {
            let fix = match file.name {
                Some(_) => "give `name:` a short plain name, such as \"jaywalk_space\"",
                None => "rename the space file, or give `name:` a short plain name",
            };
            problems.push(diag(None, "name", problem, fix.into()));
        }
        if !problems.is_empty() {
            return Err(MapError::new(problems));
        }
        Ok(Space {
            name,
            description: file.description,
            source: origin.to_string(),
            base: base.clone(),
            rules: file.rules,
            traffic: file.traffic,
            params,
            text: text.to_string(),
        })
    }

    /// The values of the parameters at the coordinates `u` (one per parameter).
    pub fn values_at(&self, u: &[f64]) -> Vec<Value> {
        self.params.iter().zip(u).map(|(p, &x)| p.value_at(x)).collect()
    }

    /// The map of a point: the base with `values` (one per parameter) laid over it, named
    /// `name`, checked by the map loader. A point that does not make a valid map (a
    /// walking speed range beyond the limits, a start speed above the top speed, too many
    /// pedestrians) is rejected with the loader's reason; nothing here panics.
    pub fn apply(&self, values: &[Value], name: &str) -> Result<Map, Rejection> {
        if values.len() != self.params.len() {
            return Err(format!("{} values for {} parameters", values.len(), self.params.len()));
        }
        let mut map = self.base.clone();
        let mut rules: Vec<SpawnRule> = map.pedestrians.iter().chain(&self.rules).cloned().collect();
        let n_base = map.pedestrians.len();
        let mut copies: Vec<u32> = (0..rules.len()).map(|r| u32::from(r < n_base)).collect();
        let mut traffic: Vec<TrafficRule> = map.traffic.iter().chain(&self.traffic).copied().collect();
        let n_traffic_base = map.traffic.len();
        let mut traffic_copies: Vec<u32> = (0..traffic.len()).map(|r| u32::from(r < n_traffic_base)).collect();
        // Kinds before the numbers they carry; copies last (the copies are of the varied rule).
        let order = |f: &Field| match f {
            Field::Rule(_, RuleField::TriggerKind)
            | Field::Traffic(_, TrafficField::TriggerKind | TrafficField::Behaviour) => 0,
            Field::Rule(_, RuleField::Copies) | Field::Traffic(_, TrafficField::Copies) => 2,
            _ => 1,
        };
        let mut todo: Vec<(&Param, &Value)> = self.params.iter().zip(values).collect();
        todo.sort_by_key(|(p, _)| order(&p.field));
        for (p, v) in todo {
            let num = || match v {
                Value::Num(x) if x.is_finite() => Ok(*x),
                _ => Err(format!("{}: expected a number, found {v}", p.name)),
            };
            let name_of = || match v {
                Value::Name(n) => Ok(n.as_str()),
                Value::Num(_) => Err(format!("{}: expected a name, found {v}", p.name)),
            };
            match p.field {
                Field::Rule(r, f) => {
                    let rule = &mut rules[r];
                    match f {
                        RuleField::Copies => copies[r] = num()?.max(0.0).round() as u32,
                        RuleField::TriggerKind => rule.trigger = with_kind(&rule.trigger, name_of()?, &p.name)?,
                        RuleField::TriggerValue => rule.trigger = with_value(&rule.trigger, num()?, &p.name)?,
                        RuleField::Light => rule.light = light_named(name_of()?, &p.name)?,
                        RuleField::Side => {
                            rule.side = match name_of()? {
                                "Near" => Side::Near,
                                "Far" => Side::Far,
                                "Random" => Side::Random,
                                other => return Err(format!("{}: unknown side {other}", p.name)),
                            }
                        }
                        RuleField::Speed => rule.speed = shifted(rule.speed, num()?),
                        RuleField::Delay => rule.delay = shifted(rule.delay, num()?),
                        RuleField::XOffset => rule.x_offset = shifted(rule.x_offset, num()?),
                        RuleField::PauseAfter => {
                            let old = rule.pause.unwrap_or(Pause {
                                after: 0.0,
                                duration: 0.0,
                            });
                            rule.pause = Some(Pause { after: num()?, ..old });
                        }
                        RuleField::PauseDuration => {
                            let old = rule.pause.unwrap_or(Pause {
                                after: 0.0,
                                duration: 0.0,
                            });
                            rule.pause = Some(Pause {
                                duration: num()?,
                                ..old
                            });
                        }
                        RuleField::Probability => rule.probability = num()?,
                        RuleField::Radius => rule.radius = num()?,
                    }
                }
                Field::Traffic(r, f) => {
                    let rule = &mut traffic[r];
                    match f {
                        TrafficField::Copies => traffic_copies[r] = num()?.max(0.0).round() as u32,
                        TrafficField::Route => {
                            rule.route = match name_of()? {
                                "Lead" => Route::Lead,
                                "Oncoming" => Route::Oncoming,
                                "FromSouth" => Route::FromSouth,
                                "FromNorth" => Route::FromNorth,
                                "OncomingLeft" => Route::OncomingLeft,
                                other => return Err(format!("{}: unknown route {other}", p.name)),
                            }
                        }
                        TrafficField::Behaviour => {
                            rule.behaviour = match (name_of()?, rule.behaviour) {
                                ("Careful", _) => Behaviour::Careful,
                                ("RunsRed", _) => Behaviour::RunsRed,
                                ("DoesNotYield", _) => Behaviour::DoesNotYield,
                                ("Stalls", b @ Behaviour::Stalls { .. }) => b,
                                ("Stalls", _) => DEFAULT_STALL,
                                ("BrakesHard", b @ Behaviour::BrakesHard { .. }) => b,
                                ("BrakesHard", _) => DEFAULT_BRAKES_HARD,
                                (other, _) => return Err(format!("{}: unknown behaviour {other}", p.name)),
                            }
                        }
                        TrafficField::TriggerKind => rule.trigger = with_kind(&rule.trigger, name_of()?, &p.name)?,
                        TrafficField::TriggerValue => rule.trigger = with_value(&rule.trigger, num()?, &p.name)?,
                        TrafficField::Light => rule.light = light_named(name_of()?, &p.name)?,
                        TrafficField::Speed => rule.speed = shifted(rule.speed, num()?),
                        TrafficField::Delay => rule.delay = shifted(rule.delay, num()?),
                        TrafficField::Start => rule.start = num()?,
                        TrafficField::Probability => rule.probability = num()?,
                        TrafficField::StallAt => {
                            if let Behaviour::Stalls { at, .. } = &mut rule.behaviour {
                                *at = num()?;
                            }
                        }
                        TrafficField::BrakeAfter => {
                            if let Behaviour::BrakesHard { after, .. } = &mut rule.behaviour {
                                *after = num()?;
                            }
                        }
                        TrafficField::BrakeDecel => {
                            if let Behaviour::BrakesHard { decel, .. } = &mut rule.behaviour {
                                *decel = num()?;
                            }
                        }
                    }
                }
                Field::StartSpeed => map.vehicle.start_speed = num()?,
                Field::MaxBrake => map.vehicle.max_brake = num()?,
                Field::MaxAccel => map.vehicle.max_accel = num()?,
                Field::MaxSpeed => map.vehicle.max_speed = num()?,
                Field::PhaseDuration(k) => map.light.cycle[k].duration = num()?,
                Field::LightOffset => map.light.offset = Offset::Fixed(num()?),
                Field::ObservationNoise => map.bins.observation_noise = num()?,
                Field::CrosswalkX => map.crosswalk.x = num()?,
                Field::Friction => map.road.friction = num()?,
                Field::Mass => map.vehicle.mass = num()?,
                Field::BrakeLag => map.vehicle.brake_lag = num()?,
                Field::BrakeDeadTime => map.vehicle.brake_dead_time = num()?,
                Field::BrakeForce => map.vehicle.brake_force = num()?,
                Field::Surface(k, f) => {
                    let patch = &mut map.road.surface[k];
                    let x = num()?;
                    match f {
                        SurfaceField::From => {
                            let length = patch.to - patch.from;
                            patch.from = x;
                            patch.to = x + length;
                        }
                        SurfaceField::Length => patch.to = patch.from + x,
                        SurfaceField::Friction => patch.friction = x,
                    }
                }
            }
        }
        let total: u64 = copies.iter().map(|&c| u64::from(c)).sum();
        if total > unforeseen_sim::MAX_SPAWN_RULES as u64 {
            return Err(format!(
                "{total} pedestrian rules after copying, more than {}",
                unforeseen_sim::MAX_SPAWN_RULES
            ));
        }
        let traffic_total: u64 = traffic_copies.iter().map(|&c| u64::from(c)).sum();
        if traffic_total > unforeseen_sim::MAX_SPAWN_RULES as u64 {
            return Err(format!(
                "{traffic_total} traffic rules after copying, more than {}",
                unforeseen_sim::MAX_SPAWN_RULES
            ));
        }
        map.pedestrians = rules
            .iter()
            .zip(&copies)
            .flat_map(|(r, &c)| std::iter::repeat_n(r.clone(), c as usize))
            .collect();
        map.traffic = traffic
            .iter()
            .zip(&traffic_copies)
            .flat_map(|(r, &c)| std::iter::repeat_n(*r, c as usize))
            .collect();
        map.name = name.to_string();
        map.description = format!("a candidate of the search space {}", self.name);
        map.base = None;
        map.expect.clear();
        checked(&map)
    }
}

/// The map through the loader's validation (written as RON and read back), or the
/// loader's diagnostics as the reason.
pub fn checked(map: &Map) -> Result<Map, Rejection> {
    let text = map_ron(map).map_err(|e| format!("cannot write the map: {e}"))?;
    Map::from_str_named(&map.name, &text, &|_| None).map_err(|e| {
        e.diagnostics()
            .iter()
            .map(|d| {
                let hint = d.hint.as_ref().map(|h| format!(" ({h})")).unwrap_or_default();
                format!("{}: {}{hint}", d.path, d.message)
            })
            .collect::<Vec<_>>()
            .join("; ")
    })
}

/// A whole map as RON text that [`Map::load`] reads back as the same map.
pub fn map_ron(map: &Map) -> Result<String, ron::Error> {
    let pretty = ron::ser::PrettyConfig::new().indentor("    ".to_string());
    ron::ser::to_string_pretty(map, pretty)
}

/// A (min, max) range moved so that its low end is `low`, its width kept.
fn shifted((a, b): (f64, f64), low: f64) -> (f64, f64) {
    (low, round(low + (b - a)))
}

/// `trigger` made of the kind `kind` (`CarArrivesWithin`, `AtTime`, `CarWithin`), keeping
/// its number where it has one; `param` names the parameter in the error.
fn with_kind(trigger: &Trigger, kind: &str, param: &str) -> Result<Trigger, Rejection> {
    let value = trigger_value(trigger);
    Ok(match kind {
        "CarArrivesWithin" => Trigger::CarArrivesWithin(value.unwrap_or(4.8)),
        "AtTime" => Trigger::AtTime(value.unwrap_or(5.0)),
        "CarWithin" => {
            let min = value.unwrap_or(40.0);
            Trigger::CarWithin {
                min,
                max: min + CAR_WITHIN_WIDTH,
            }
        }
        other => return Err(format!("{param}: unknown trigger kind {other}")),
    })
}

/// `trigger` with its number set to `x` (a `CarWithin`'s width kept).
fn with_value(trigger: &Trigger, x: f64, param: &str) -> Result<Trigger, Rejection> {
    Ok(match *trigger {
        Trigger::CarArrivesWithin(_) => Trigger::CarArrivesWithin(x),
        Trigger::AtTime(_) => Trigger::AtTime(x),
        Trigger::CarWithin { min, max } => Trigger::CarWithin {
            min: x,
            max: x + (max - min),
        },
        t => return Err(format!("{param}: the trigger {t:?} has no number")),
    })
}

/// The light condition named `name`.
fn light_named(name: &str, param: &str) -> Result<LightCondition, Rejection> {
    Ok(match name {
        "Any" => LightCondition::Any,
        "Green" => LightCondition::Green,
        "Red" => LightCondition::Red,
        other => return Err(format!("{param}: unknown light {other}")),
    })
}

/// The number a trigger carries, if any.
fn trigger_value(t: &Trigger) -> Option<f64> {
    match *t {
        Trigger::CarArrivesWithin(x) | Trigger::AtTime(x) => Some(x),
        Trigger::CarWithin { min, .. } => Some(min),
        Trigger::RedStarts | Trigger::GreenStarts => None,
    }
}

/// The name a trigger's kind is varied by, if it is one a space can choose.
fn trigger_kind_name(t: &Trigger) -> Option<Value> {
    let name = match t {
        Trigger::CarArrivesWithin(_) => "CarArrivesWithin",
        Trigger::AtTime(_) => "AtTime",
        Trigger::CarWithin { .. } => "CarWithin",
        _ => return None,
    };
    Some(Value::Name(name.to_string()))
}

/// The name of a light condition.
fn light_name(light: LightCondition) -> Value {
    Value::Name(
        match light {
            LightCondition::Any => "Any",
            LightCondition::Green => "Green",
            LightCondition::Red => "Red",
        }
        .to_string(),
    )
}

/// A traffic rule's value of a field (`in_base`: the rule is the base map's).
fn traffic_value(rule: &TrafficRule, f: TrafficField, in_base: bool) -> Option<Value> {
    let num = |x: f64| Some(Value::Num(x));
    let name = |n: &str| Some(Value::Name(n.to_string()));
    match f {
        TrafficField::Route => name(match rule.route {
            Route::Lead => "Lead",
            Route::Oncoming => "Oncoming",
            Route::FromSouth => "FromSouth",
            Route::FromNorth => "FromNorth",
            Route::OncomingLeft => "OncomingLeft",
        }),
        TrafficField::Behaviour => name(match rule.behaviour {
            Behaviour::Careful => "Careful",
            Behaviour::RunsRed => "RunsRed",
            Behaviour::DoesNotYield => "DoesNotYield",
            Behaviour::Stalls { .. } => "Stalls",
            Behaviour::BrakesHard { .. } => "BrakesHard",
        }),
        TrafficField::TriggerValue => trigger_value(&rule.trigger).map(Value::Num),
        TrafficField::TriggerKind => trigger_kind_name(&rule.trigger),
        TrafficField::Light => Some(light_name(rule.light)),
        TrafficField::Speed => num(rule.speed.0),
        TrafficField::Delay => num(rule.delay.0),
        TrafficField::Start => num(rule.start),
        TrafficField::Probability => num(rule.probability),
        TrafficField::Copies => num(if in_base { 1.0 } else { 0.0 }),
        TrafficField::StallAt => match rule.behaviour {
            Behaviour::Stalls { at, .. } => num(at),
            _ => None,
        },
        TrafficField::BrakeAfter => match rule.behaviour {
            Behaviour::BrakesHard { after, .. } => num(after),
            _ => None,
        },
        TrafficField::BrakeDecel => match rule.behaviour {
            Behaviour::BrakesHard { decel, .. } => num(decel),
            _ => None,
        },
    }
}

/// A rule's value of a field (`in_base`: the rule is the base map's, so it has one copy).
fn rule_value(rule: &SpawnRule, f: RuleField, in_base: bool) -> Option<Value> {
    let num = |x: f64| Some(Value::Num(x));
    let name = |n: &str| Some(Value::Name(n.to_string()));
    match f {
        RuleField::TriggerValue => trigger_value(&rule.trigger).map(Value::Num),
        RuleField::TriggerKind => trigger_kind_name(&rule.trigger),
        RuleField::Light => Some(light_name(rule.light)),
        RuleField::Side => name(match rule.side {
            Side::Near => "Near",
            Side::Far => "Far",
            Side::Random => "Random",
        }),
        RuleField::Speed => num(rule.speed.0),
        RuleField::Delay => num(rule.delay.0),
        RuleField::XOffset => num(rule.x_offset.0),
        // No pause is a pause of 0 s (after 0 m).
        RuleField::PauseAfter => num(rule.pause.map_or(0.0, |p| p.after)),
        RuleField::PauseDuration => num(rule.pause.map_or(0.0, |p| p.duration)),
        RuleField::Probability => num(rule.probability),
        RuleField::Radius => num(rule.radius),
        RuleField::Copies => num(if in_base { 1.0 } else { 0.0 }),
    }
}

/// The base map's value of a global field.
fn global_value(map: &Map, f: Field) -> Option<Value> {
    let x = match f {
        Field::StartSpeed => map.vehicle.start_speed,
        Field::MaxBrake => map.vehicle.max_brake,
        Field::MaxAccel => map.vehicle.max_accel,
        Field::MaxSpeed => map.vehicle.max_speed,
        Field::PhaseDuration(k) => map.light.cycle.get(k)?.duration,
        Field::LightOffset => match map.light.offset {
            Offset::Fixed(x) => x,
            Offset::Random => return None,
        },
        Field::ObservationNoise => map.bins.observation_noise,
        Field::CrosswalkX => map.crosswalk.x,
        Field::Friction => map.road.friction,
        Field::Mass => map.vehicle.mass,
        Field::BrakeLag => map.vehicle.brake_lag,
        Field::BrakeDeadTime => map.vehicle.brake_dead_time,
        Field::BrakeForce => map.vehicle.brake_force,
        Field::Surface(k, f) => {
            let patch = map.road.surface.get(k)?;
            match f {
                SurfaceField::From => patch.from,
                SurfaceField::Length => patch.to - patch.from,
                SurfaceField::Friction => patch.friction,
            }
        }
        Field::Rule(..) | Field::Traffic(..) => return None,
    };
    Some(Value::Num(x))
}

/// The 1-based line and column of the first `"field"` string in `text` outside comments.
fn locate(text: &str, field: &str) -> Option<(usize, usize)> {
    let needle = format!("\"{field}\"");
    for (line, l) in (1..).zip(text.lines()) {
        let code = l.split("//").next().unwrap_or("");
        if let Some(i) = code.find(&needle) {
            return Some((line, code[..i].chars().count() + 1));
        }
    }
    None
}
