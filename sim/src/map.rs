//! The map: every parameter of one scenario, in real units (metres, seconds,
//! m/s, m/s², kg). Every field has a default; the defaults are the training
//! intersection of the paper (see `maps/intersection.ron` and `maps/README.md`).
//!
//! Coordinates: the road runs along +x; y = 0 is the road's centre line. The
//! car drives in the lane on the negative-y side ("near" side); pedestrians
//! cross along y.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Defines a configuration struct with documented defaults, plus a crate-private
/// "patch" twin whose fields are all optional: a scenario built on a base map
/// only sets the fields that differ, and `apply` copies them over the base.
/// A value given for a field of a map section, converted to the field's type (the typed
/// overrides of `overrides.rs`: `Map::with_overrides`).
pub(crate) trait Convert {
    /// Why a value does not convert.
    type Error;
    /// The value as a `T`.
    fn to<T: serde::de::DeserializeOwned>(&self) -> Result<T, Self::Error>;
    /// Whether a field of type `T` takes whole numbers only.
    fn whole<T: serde::de::DeserializeOwned>() -> bool;
}

macro_rules! config_struct {
    (
        $(#[$meta:meta])*
        pub struct $name:ident / $patch:ident as $ron_name:literal {
            $(
                $(#[$fmeta:meta])*
                $field:ident : $ty:ty = $default:expr
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[derive(Debug, Clone, PartialEq, Serialize)]
        pub struct $name {
            $(
                $(#[$fmeta])*
                pub $field: $ty,
            )*
        }

        impl Default for $name {
            fn default() -> Self {
                Self { $( $field: $default, )* }
            }
        }

        #[doc = concat!("Partial `", $ron_name, "`: only the fields a map file sets.")]
        #[derive(Debug, Clone, Default, Deserialize)]
        #[serde(deny_unknown_fields, rename = $ron_name)]
        pub(crate) struct $patch {
            $(
                #[serde(default)]
                $field: Option<$ty>,
            )*
        }

        impl $patch {
            /// Overwrite the fields of `base` that this patch sets.
            pub(crate) fn apply(self, base: &mut $name) {
                $( if let Some(v) = self.$field { base.$field = v; } )*
            }
        }

        impl $name {
            /// The fields, each with whether it takes a whole number only (as `C` says).
            pub(crate) fn override_fields<C: $crate::map::Convert>() -> Vec<(&'static str, bool)> {
                vec![$( (stringify!($field), C::whole::<$ty>()) ),*]
            }

            /// Sets `field` to `value` converted to its type; `None` when there is no
            /// such field.
            pub(crate) fn set<C: $crate::map::Convert>(&mut self, field: &str, value: &C) -> Option<Result<(), C::Error>> {
                match field {
                    $( stringify!($field) => Some(value.to::<$ty>().map(|v| self.$field = v)), )*
                    _ => None,
                }
            }
        }
    };
}

config_struct! {
    /// The straight road from the start to the destination.
    pub struct Road / RoadPatch as "Road" {
        /// Width of one lane, m. Default 3.5.
        lane_width: f64 = 3.5,
        /// Number of lanes (the car drives in the first lane on the near, negative-y side). Default 2.
        lanes: u32 = 2,
        /// Width of each sidewalk beyond the kerb, m (pedestrians wait and finish there). Default 2.0.
        sidewalk_width: f64 = 2.0,
        /// x of the destination line, m; the episode succeeds when the car's front reaches it. Default 90.0.
        goal_x: f64 = 90.0,
        /// Tyre-road friction coefficient μ of the road where no surface patch lies, in (0, 2]
        /// (used by `dynamics: Forces`). Default 0.8 (dry asphalt).
        friction: f64 = 0.8,
        /// Stretches of road with their own μ (wet asphalt, ice, gravel), possibly appearing
        /// at run time; a later patch lies over an earlier one where they overlap. Default [].
        surface: Vec<SurfacePatch> = Vec::new(),
        /// Density of the air, kg/m³ (aerodynamic drag under `dynamics: Forces`). Default 1.2.
        air_density: f64 = 1.2,
    }
}

/// A stretch of road surface with its own friction coefficient, from x `from` to x `to`
/// (the car's wheels on it feel `friction`). With a `trigger` the patch is absent until
/// the trigger holds (the trigger of a pedestrian spawn rule, without its light
/// condition): a puddle can appear as a jaywalker does.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfacePatch {
    /// Start of the patch along the road, m.
    pub from: f64,
    /// End of the patch along the road, m (> `from`).
    pub to: f64,
    /// Friction coefficient μ on the patch, in (0, 2] (wet asphalt ~0.4, ice ~0.1).
    pub friction: f64,
    /// When the patch appears; `None` (the default): it is there from the start.
    #[serde(default)]
    pub trigger: Option<Trigger>,
}

config_struct! {
    /// The zebra crossing that pedestrians use.
    pub struct Crosswalk / CrosswalkPatch as "Crosswalk" {
        /// x of the crosswalk's centre line, m. Default 66.0 (24 m before the destination).
        x: f64 = 66.0,
        /// Width of the crosswalk along the road, m. Default 4.0 (so it spans x 64–68).
        width: f64 = 4.0,
    }
}

/// The colour the light shows. The discretizer maps amber to red.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum LightPhase {
    /// Go.
    Green,
    /// About to turn red (counts as red for the agent).
    Amber,
    /// Stop; pedestrians may cross.
    Red,
}

impl LightPhase {
    /// True for green only.
    pub fn is_green(self) -> bool {
        self == LightPhase::Green
    }
}

impl std::fmt::Display for LightPhase {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            LightPhase::Green => "green",
            LightPhase::Amber => "amber",
            LightPhase::Red => "red",
        })
    }
}

/// One phase of the traffic-light cycle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Phase {
    /// Which light is shown.
    pub phase: LightPhase,
    /// How long it is shown, s (> 0).
    pub duration: f64,
}

/// Where in its cycle the light is at time 0.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Offset {
    /// Seconds into the cycle at time 0 (taken modulo the cycle length).
    Fixed(f64),
    /// Uniformly random over the cycle, drawn from the episode seed.
    Random,
}

fn default_cycle() -> Vec<Phase> {
    vec![
        Phase {
            phase: LightPhase::Green,
            duration: 12.0,
        },
        Phase {
            phase: LightPhase::Amber,
            duration: 2.0,
        },
        Phase {
            phase: LightPhase::Red,
            duration: 10.0,
        },
    ]
}

config_struct! {
    /// The traffic light at the crosswalk.
    pub struct Light / LightPatch as "Light" {
        /// Phases in order, repeated forever. Default green 12 s, amber 2 s, red 10 s.
        cycle: Vec<Phase> = default_cycle(),
        /// Position in the cycle at time 0. Default `Fixed(0.0)` (the start of green).
        offset: Offset = Offset::Fixed(0.0),
    }
}

/// How the three actions move the car (docs/ARCHITECTURE.md §2).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Dynamics {
    /// The paper's kinematics: each sub-step sets the body's velocity to the speed
    /// integrated at `max_accel` / `max_brake`, clamped to [0, `max_speed`]; mass, road
    /// friction, drag and lag play no part.
    #[default]
    Ideal,
    /// Forces on the body: drive `min(drive_force, power / v)`, brakes through a dead
    /// time and a first-order lag, rolling resistance, aerodynamic drag, all within the
    /// tyre-road friction limit `μ m g`; `max_speed` is a speed governor.
    Forces,
}

config_struct! {
    /// The ego car: a dynamic rigid body, driven as `dynamics` says.
    pub struct Vehicle / VehiclePatch as "Vehicle" {
        /// The vehicle model: `Ideal` (velocity control, the paper's) or `Forces`. Default `Ideal`.
        dynamics: Dynamics = Dynamics::Ideal,
        /// Body length, m. Default 4.5.
        length: f64 = 4.5,
        /// Body width, m. Default 1.8.
        width: f64 = 1.8,
        /// Mass, kg. Default 1500.
        mass: f64 = 1500.0,
        /// x of the front bumper at time 0, m. Default 0.0.
        start_x: f64 = 0.0,
        /// Speed at time 0, m/s. Default 3.0.
        start_speed: f64 = 3.0,
        /// Acceleration of "speed up", m/s². Default 3.0.
        max_accel: f64 = 3.0,
        /// Deceleration of "slow down", m/s² (never below 0 m/s). Default 3.0.
        max_brake: f64 = 3.0,
        /// Speed cap, m/s. Default 9.0.
        max_speed: f64 = 9.0,
        /// Linear damping coefficient, 1/s (0 = "maintain" holds speed exactly). Default 0.0.
        damping: f64 = 0.0,
        /// `Forces`: the largest drive force at the tyres, N. Default 5000 (3.3 m/s² on 1500 kg).
        drive_force: f64 = 5000.0,
        /// `Forces`: the engine's power at the tyres, W; the drive force is at most
        /// power / speed. Default 60000.
        power: f64 = 60_000.0,
        /// `Forces`: the brake force "slow down" demands, N. Default 7500 (5 m/s² on 1500 kg).
        brake_force: f64 = 7500.0,
        /// `Forces`: time constant of the brake's first-order lag, s (0: none). Default 0.2.
        brake_lag: f64 = 0.2,
        /// `Forces`: dead time before the brake responds to a new demand, s. Default 0.1.
        brake_dead_time: f64 = 0.1,
        /// `Forces`: rolling resistance coefficient (force = coefficient × m g). Default 0.012.
        rolling_resistance: f64 = 0.012,
        /// `Forces`: aerodynamic drag coefficient C_d. Default 0.3.
        drag_coefficient: f64 = 0.3,
        /// `Forces`: frontal area A, m² (drag = ½ ρ C_d A v²). Default 2.2.
        frontal_area: f64 = 2.2,
    }
}

/// Where the distance bins' edges lie (the paper's `d` factor, §VI).
///
/// Written in a map as a list (`[0.0, 30.0, 60.0]`: edges on the distance to the goal,
/// the same on every map) or as `Crosswalk(lead: 0.0, approach: 34.0)`: edges derived
/// from the map's crosswalk and car, so that `d` means the same on every map
/// (`d = 1` the crosswalk zone, `d = 2` the approach, `d = 3` beyond). The discretizer
/// derives the edges (`unforeseen_discretizer::distance_edges`).
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(untagged)]
pub enum DistanceEdges {
    /// Edges on the distance to the goal, m, strictly increasing; `d` = the number of
    /// edges `e` with distance > `e`.
    Goal(Vec<f64>),
    /// Three edges anchored to the crosswalk's near edge.
    Crosswalk(CrosswalkBins),
}

/// The crosswalk-anchored distance bins: `d = 1` from `lead` metres before the
/// crosswalk's near edge to the goal, `d = 2` the approach before it, at least `approach`
/// metres and at least the car's stopping distance from its top speed with one decision
/// tick of reaction, `d = 3` beyond.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename = "Crosswalk")]
pub struct CrosswalkBins {
    /// Metres before the crosswalk's near edge where `d = 1` starts (>= 0). Default 0:
    /// `d = 1` is the crosswalk and what lies beyond it, so a car observed there has
    /// entered the crosswalk.
    pub lead: f64,
    /// Shortest length of the approach bin `d = 2`, m (> 0). Default 34.
    pub approach: f64,
}

/// A list of numbers is [`DistanceEdges::Goal`]; a struct, named `Crosswalk` or not, is
/// [`DistanceEdges::Crosswalk`] (its fields checked as the struct's own).
impl<'de> Deserialize<'de> for DistanceEdges {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        struct EdgesVisitor;
        impl<'de> serde::de::Visitor<'de> for EdgesVisitor {
            type Value = DistanceEdges;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str(
                    "a list of edges in m to the goal, e.g. [0.0, 30.0, 60.0], or Crosswalk(lead: 0.0, approach: 34.0)",
                )
            }
            fn visit_seq<A: serde::de::SeqAccess<'de>>(self, seq: A) -> Result<DistanceEdges, A::Error> {
                Vec::deserialize(serde::de::value::SeqAccessDeserializer::new(seq)).map(DistanceEdges::Goal)
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, map: A) -> Result<DistanceEdges, A::Error> {
                CrosswalkBins::deserialize(serde::de::value::MapAccessDeserializer::new(map))
                    .map(DistanceEdges::Crosswalk)
            }
        }
        deserializer.deserialize_any(EdgesVisitor)
    }
}

impl Default for DistanceEdges {
    /// `Crosswalk(lead: 0.0, approach: 34.0)`: on the training intersection (near edge
    /// 26 m from the goal) the edges `[0, 26, 60]`, the paper's `[0, 30, 60]` with the
    /// first edge moved to the crosswalk.
    fn default() -> Self {
        DistanceEdges::Crosswalk(CrosswalkBins {
            lead: 0.0,
            approach: 34.0,
        })
    }
}

impl std::fmt::Display for DistanceEdges {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DistanceEdges::Goal(edges) => write!(f, "{edges:?} m to the goal"),
            DistanceEdges::Crosswalk(c) => write!(
                f,
                "anchored to the crosswalk ({} m lead, approach at least {} m)",
                c.lead, c.approach
            ),
        }
    }
}

impl DistanceEdges {
    /// Number of distance bins `n_d` (edges + 1).
    pub fn bin_count(&self) -> usize {
        match self {
            DistanceEdges::Goal(edges) => edges.len() + 1,
            DistanceEdges::Crosswalk(_) => 4,
        }
    }
}

config_struct! {
    /// Discretizer bins (the paper's d and v factors).
    pub struct Bins / BinsPatch as "Bins" {
        /// Distance bins: anchored to the crosswalk (default `Crosswalk(lead: 0.0,
        /// approach: 34.0)`, `[0, 26, 60]` on the training intersection) or
        /// fixed edges on the distance to the goal (`[0.0, 30.0, 60.0]`); see [`DistanceEdges`].
        distance_edges: DistanceEdges = DistanceEdges::default(),
        /// Edges on speed, m/s, strictly increasing; v = number of edges e with speed >= e.
        /// Default [0.5, 4.5, 7.5] (the paper's are [1.5, 4.5, 7.5]; `v = 0` is a car
        /// that stands, below 0.5 m/s, not one that still rolls).
        speed_edges: Vec<f64> = vec![0.5, 4.5, 7.5],
        /// Probability in [0, 1) that an observed factor is misreported. Default 0.
        observation_noise: f64 = 0.0,
    }
}

config_struct! {
    /// Reward per decision tick (used by the runner, not by the physics).
    pub struct Reward / RewardPatch as "Reward" {
        /// Reward per metre of progress along +x. Default 0.5.
        progress_per_metre: f64 = 0.5,
        /// Reward on reaching the destination. Default 50.
        goal: f64 = 50.0,
        /// Reward on a collision with a pedestrian. Default -25.
        crash: f64 = -25.0,
        /// Cost subtracted every decision tick. Default 4.5: what a tick at the default
        /// top speed earns in progress (0.5 per metre × 9 m/s × 1 s), so a full-speed tick
        /// nets 0 and every slower or waiting tick costs: the paper's reward "encourages
        /// rapid goal approach" (§VI). Set it to 1 for the per-metre reward of
        /// `maps/per_metre/`, under which waiting costs little.
        step_cost: f64 = 4.5,
        /// Reward (negative: a penalty) paid on the tick in which the car's front crosses the
        /// crosswalk's near edge while the light shows `Red` (amber is allowed: it is the
        /// warning a car that cannot stop any more may still clear on). Default 0: no rule.
        /// The world reports the violation whatever this value ([`crate::StepOutcome`]).
        red_light: f64 = 0.0,
    }
}

config_struct! {
    /// Episode timing.
    pub struct Episode / EpisodePatch as "Episode" {
        /// Seconds of simulated time per decision tick. Default 1.0.
        decision_dt: f64 = 1.0,
        /// Physics sub-steps per second; decision_dt × physics_hz must be a whole number. Default 60.
        physics_hz: f64 = 60.0,
        /// Decision ticks before the episode times out. Default 40.
        max_steps: u32 = 40,
    }
}

/// What starts a pedestrian crossing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Trigger {
    /// At the start of every red phase (repeats each cycle).
    RedStarts,
    /// At the start of every green phase (repeats each cycle).
    GreenStarts,
    /// Once, at this episode time, s.
    AtTime(f64),
    /// Once, when the car's front is between `min` and `max` metres before the
    /// crosswalk's near edge.
    CarWithin {
        /// Closest distance, m.
        min: f64,
        /// Farthest distance, m.
        max: f64,
    },
    /// Once, when the car (still before the crosswalk) would reach the
    /// crosswalk's near edge within this many seconds at its current speed.
    CarArrivesWithin(f64),
}

/// Which light the trigger requires when it fires.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum LightCondition {
    /// Any phase.
    #[default]
    Any,
    /// Only while the light is green (a jaywalker).
    Green,
    /// Only while the light is amber or red.
    Red,
}

/// The kerb a pedestrian starts from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Side {
    /// The car's side (negative y): steps straight into the car's lane.
    Near,
    /// The opposite side (positive y): crosses the other lane first.
    Far,
    /// Either, with equal probability, drawn from the seed.
    #[default]
    Random,
}

/// A pause in the middle of a crossing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pause {
    /// Metres walked (from the start point) before stopping.
    pub after: f64,
    /// Seconds standing still.
    pub duration: f64,
}

/// A rule that spawns pedestrians crossing the crosswalk.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SpawnRule {
    /// When the rule fires. Default `RedStarts`.
    pub trigger: Trigger,
    /// Light required when it fires. Default `Any`.
    pub light: LightCondition,
    /// Probability that a firing spawns a pedestrian, in [0, 1]. Default 1.0.
    pub probability: f64,
    /// Start kerb. Default `Random`.
    pub side: Side,
    /// Walking speed range (min, max), m/s, uniform. Default (1.1, 1.5).
    pub speed: (f64, f64),
    /// Delay between firing and starting to walk (min, max), s, uniform. Default (0.0, 0.0).
    pub delay: (f64, f64),
    /// Offset of the walking line from the crosswalk's centre line along x (min, max), m. Default (0.0, 0.0).
    pub x_offset: (f64, f64),
    /// Metres behind the kerb where the pedestrian starts (and past the far kerb where it leaves). Default 0.5.
    pub start_back: f64,
    /// Body radius, m. Default 0.3.
    pub radius: f64,
    /// Optional stop in the middle of the crossing. Default `None`.
    pub pause: Option<Pause>,
}

impl Default for SpawnRule {
    fn default() -> Self {
        SpawnRule {
            trigger: Trigger::RedStarts,
            light: LightCondition::Any,
            probability: 1.0,
            side: Side::Random,
            speed: (1.1, 1.5),
            delay: (0.0, 0.0),
            x_offset: (0.0, 0.0),
            start_back: 0.5,
            radius: 0.3,
            pause: None,
        }
    }
}

/// Expected outcome of a batch run of one method on this map. Plain data: the loader
/// reads the names as written and checks only their shape (a bare identifier such as
/// `Scaled`); the harness that runs the batch checks them against its own methods and
/// protocols.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Expectation {
    /// Which method, as written in the map (e.g. `"Scaled"`).
    #[serde(deserialize_with = "names::identifier", serialize_with = "names::write_identifier")]
    pub method: String,
    /// Lowest acceptable success rate, in [0, 1].
    #[serde(default)]
    pub min_success: Option<f64>,
    /// Highest acceptable success rate, in [0, 1].
    #[serde(default)]
    pub max_success: Option<f64>,
    /// Lowest acceptable mean return.
    #[serde(default)]
    pub min_reward: Option<f64>,
    /// Highest acceptable mean return.
    #[serde(default)]
    pub max_reward: Option<f64>,
    /// Highest acceptable collision rate, in [0, 1].
    #[serde(default)]
    pub max_collision: Option<f64>,
    /// Highest acceptable share of ticks that ran planning, in [0, 1].
    #[serde(default)]
    pub max_inference_rate: Option<f64>,
    /// Highest acceptable rate of red-light violations (the car's front entering the
    /// crosswalk on red) per episode, in [0, 1].
    #[serde(default)]
    pub max_red_light: Option<f64>,
    /// Highest acceptable time-out rate (episodes that ran out of decision ticks), in [0, 1].
    #[serde(default)]
    pub max_timeout: Option<f64>,
    /// The evaluation protocol the bounds apply to, as written in the map (e.g.
    /// `"Continual"`); absent: every protocol the batch ran the method under.
    #[serde(
        default,
        deserialize_with = "names::optional_identifier",
        serialize_with = "names::write_optional_identifier"
    )]
    pub protocol: Option<String>,
}

/// Reading a name written as a bare RON identifier (`method: Scaled`) into a string,
/// whatever the name: RON parses such an identifier as a unit enum variant, so the
/// name is taken as the variant's name.
mod names {
    use serde::Deserializer;
    use serde::de::{self, EnumAccess, VariantAccess, Visitor};
    use std::fmt;

    struct Identifier;

    impl<'de> Visitor<'de> for Identifier {
        type Value = String;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("a name such as `Scaled`")
        }

        fn visit_enum<A: EnumAccess<'de>>(self, data: A) -> Result<String, A::Error> {
            let (VariantName(name), variant) = data.variant()?;
            variant.unit_variant()?;
            Ok(name)
        }
    }

    /// A variant's name: deserializers hand it over as an identifier (RON's refuses
    /// `deserialize_string` there).
    struct VariantName(String);

    impl<'de> serde::Deserialize<'de> for VariantName {
        fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
            d.deserialize_identifier(VariantNameVisitor).map(VariantName)
        }
    }

    struct VariantNameVisitor;

    impl Visitor<'_> for VariantNameVisitor {
        type Value = String;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("a name")
        }

        fn visit_str<E: de::Error>(self, v: &str) -> Result<String, E> {
            Ok(v.to_string())
        }
    }

    /// A bare identifier, as its name.
    pub(super) fn identifier<'de, D: Deserializer<'de>>(d: D) -> Result<String, D::Error> {
        d.deserialize_enum("Name", &[], Identifier)
    }

    struct Optional;

    impl<'de> Visitor<'de> for Optional {
        type Value = Option<String>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("an optional name such as `Continual`")
        }

        fn visit_none<E: de::Error>(self) -> Result<Option<String>, E> {
            Ok(None)
        }

        fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<Option<String>, D::Error> {
            identifier(d).map(Some)
        }
    }

    /// Writes a name as RON reads it back (a bare identifier: a unit variant, which JSON
    /// writes as the plain string). Serde wants variant names `'static`: each distinct
    /// name is kept once for the program's life (a map has a handful).
    pub(super) fn write_identifier<S: serde::Serializer>(name: &str, s: S) -> Result<S::Ok, S::Error> {
        use std::collections::BTreeSet;
        use std::sync::Mutex;
        static NAMES: Mutex<BTreeSet<&'static str>> = Mutex::new(BTreeSet::new());
        let mut names = NAMES.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
        let name: &'static str = match names.get(name) {
            Some(n) => n,
            None => {
                let n: &'static str = Box::leak(name.to_owned().into_boxed_str());
                names.insert(n);
                n
            }
        };
        s.serialize_unit_variant("Name", 0, name)
    }

    /// [`write_identifier`] of an optional name (`None` as RON's and JSON's none).
    pub(super) fn write_optional_identifier<S: serde::Serializer>(
        name: &Option<String>,
        s: S,
    ) -> Result<S::Ok, S::Error> {
        struct Named<'a>(&'a str);
        impl serde::Serialize for Named<'_> {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                write_identifier(self.0, s)
            }
        }
        match name {
            Some(n) => s.serialize_some(&Named(n)),
            None => s.serialize_none(),
        }
    }

    /// `None`, or a bare identifier (implicitly or explicitly `Some`), as its name.
    pub(super) fn optional_identifier<'de, D: Deserializer<'de>>(d: D) -> Result<Option<String>, D::Error> {
        d.deserialize_option(Optional)
    }
}

// The junction's and the traffic's sections (issue 45; their run-time parts are
// junction.rs, signals.rs and traffic.rs).

/// One arm of the junction, named by the compass with the road's +x as east.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Arm {
    /// The car's approach (x below the box): its crosswalk is the map's `crosswalk`.
    West,
    /// The road beyond the box, where oncoming traffic comes from.
    East,
    /// The cross street at negative y (the car's right).
    South,
    /// The cross street at positive y (the car's left).
    North,
}

impl Arm {
    /// All arms.
    pub const ALL: [Arm; 4] = [Arm::West, Arm::East, Arm::South, Arm::North];

    /// Whether this arm belongs to the road (West, East) rather than the cross street.
    pub fn on_road(self) -> bool {
        matches!(self, Arm::West | Arm::East)
    }
}

/// The cross street's signal phases.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum CrossCycle {
    /// Derived from the car's signal (`light.cycle`): during each red run of it the
    /// cross street shows red for `all_red` s (the clearance), green, amber for
    /// `amber` s, and red again for the last `all_red` s; red whenever the car's
    /// signal is green or amber.
    Derived {
        /// Seconds of cross amber before the clearance.
        amber: f64,
        /// Seconds of all-red clearance at each end of the cross green.
        all_red: f64,
    },
    /// Explicit phases, one cycle exactly as long as `light.cycle` and starting with
    /// it (the same offset). A phase that gives the cross street green or amber while
    /// the car's signal shows green or amber is refused at load.
    Cycle(Vec<Phase>),
}

/// What the car's agent reads from a dark signal (its L factor): a named map choice,
/// since a dark head shows none of the phases L knows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum DarkReading {
    /// As red: road codes treat a dark signal as an all-way stop (e.g. California
    /// Vehicle Code §21800(d): stop, then proceed with caution when it is safe).
    Red,
    /// As green: the head is ignored and the road taken as unsignalised with right of
    /// way (what the agent does if it takes no signal for no restriction).
    Green,
}

/// A power outage: every head of the junction goes dark when `start` first holds
/// (`AtTime(t)` for one scheduled at t, or any trigger of the pedestrian rules, a
/// phase-start trigger holding while the car's signal shows that phase), for
/// `duration` s. The controller's cycle runs on underneath.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Outage {
    /// When the heads go dark.
    pub start: Trigger,
    /// How long they stay dark, s (> 0).
    pub duration: f64,
}

/// Stop lines lie this far before their crosswalk (or before the box where the arm has
/// none), m, on a map without a junction (lead and oncoming traffic still stop there).
pub const DEFAULT_STOP_GAP: f64 = 1.0;

config_struct! {
    /// A cross street meeting the road, with its own lanes and sidewalks, crosswalks
    /// on up to every arm, stop lines, and one signal controller for every approach.
    pub struct Junction / JunctionPatch as "Junction" {
        /// x of the cross street's centre line, m. Default 72.5 (with the default
        /// crosswalk and cross street, the box spans x 69..76, 1 m after the crosswalk).
        x: f64 = 72.5,
        /// Lanes of the cross street (the kerb lane each way is driven). Default 2.
        lanes: u32 = 2,
        /// Width of one cross-street lane, m. Default 3.5.
        lane_width: f64 = 3.5,
        /// Width of each cross-street sidewalk, m. Default 2.0.
        sidewalk_width: f64 = 2.0,
        /// Crosswalks on the other arms (East, South, North), each as wide as the map's
        /// `crosswalk` and as far from the box (the near approach's is `crosswalk`). Default [].
        crosswalks: Vec<Arm> = Vec::new(),
        /// Distance of every stop line before its approach's crosswalk (the box where the
        /// arm has none), m. Default 1.0.
        stop_gap: f64 = DEFAULT_STOP_GAP,
        /// The cross street's phases. Default `Derived(amber: 2.0, all_red: 1.0)`.
        cross: CrossCycle = CrossCycle::Derived { amber: 2.0, all_red: 1.0 },
        /// Outages: times the whole junction goes dark. Default [].
        outages: Vec<Outage> = Vec::new(),
        /// What the car's agent reads from a dark signal. Default `Red`.
        dark_reads_as: DarkReading = DarkReading::Red,
        /// Speed limit of the road (the car's street: lead and oncoming traffic), m/s: no
        /// traffic rule of it may draw a faster desired speed. Default 13.9 (50 km/h).
        road_speed_limit: f64 = 13.9,
        /// Speed limit of the cross street, m/s, as `road_speed_limit`. Default 13.9.
        cross_speed_limit: f64 = 13.9,
    }
}

/// The route a vehicle drives (straight through the junction).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Route {
    /// In the car's lane, ahead of it (`start` m ahead of its front).
    Lead,
    /// In the opposite lane, towards the car, from beyond the junction.
    Oncoming,
    /// Across, northbound from the cross street's south arm (needs a junction).
    FromSouth,
    /// Across, southbound from the cross street's north arm (needs a junction).
    FromNorth,
    /// Oncoming, turning left in the box across the car's lane onto the cross street's
    /// south arm, as a quarter circle (needs a junction).
    OncomingLeft,
}

/// How a vehicle deviates from a careful driver, for the unforeseen.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Behaviour {
    /// Stops at its stop line on red, and on amber when it can stop with its
    /// comfortable deceleration; on a dark signal it stops at the line and goes after
    /// standing there 1 s (an all-way stop); follows what is ahead in its lane.
    Careful,
    /// Ignores its signal, and the car (still following other vehicles ahead).
    RunsRed,
    /// Obeys its signal but not the car: turning left (`OncomingLeft`) it takes its turn
    /// across the car's path without yielding (a careful turner waits at the box while
    /// the car comes within `YIELD_GAP` s of it), and it does not brake for the car.
    DoesNotYield,
    /// As `Careful`, until its front is `at` m past its stop line: there it stops as
    /// hard as it can and stands `hold` s (a breakdown in the junction box), then drives
    /// on as `Careful`.
    Stalls {
        /// Metres past its stop line where it stalls.
        at: f64,
        /// Seconds it stands. Default: for ever.
        #[serde(default = "for_ever")]
        hold: f64,
    },
    /// As `Careful`, until `after` s after it appeared: it brakes at `decel` m/s² to a
    /// standstill, stands `hold` s, and drives on.
    BrakesHard {
        /// Seconds after appearing.
        after: f64,
        /// Deceleration, m/s².
        decel: f64,
        /// Seconds standing before it drives on.
        hold: f64,
    },
}

fn for_ever() -> f64 {
    f64::INFINITY
}

/// A rule that spawns other vehicles.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TrafficRule {
    /// Where it drives. Default `Lead`.
    pub route: Route,
    /// When the rule fires (the pedestrian rules' triggers: phase starts repeat, the
    /// others fire once). Default `AtTime(0.0)`.
    pub trigger: Trigger,
    /// The car's signal required when it fires (never met while dark, except `Any`).
    /// Default `Any`.
    pub light: LightCondition,
    /// Probability that a firing spawns a vehicle, in [0, 1]. Default 1.0.
    pub probability: f64,
    /// Delay between firing and appearing (min, max), s, uniform. Default (0.0, 0.0).
    pub delay: (f64, f64),
    /// Desired speed (min, max), m/s, uniform; it appears at this speed. Default (8.0, 10.0).
    pub speed: (f64, f64),
    /// Where it appears: metres before its stop line (`Lead`: ahead of the car's front).
    /// Behind a vehicle of its route that is there, it appears standing `min_gap` behind
    /// it instead. Default 30.0.
    pub start: f64,
    /// How it deviates from a careful driver. Default `Careful`.
    pub behaviour: Behaviour,
    /// Body length, m. Default 4.5.
    pub length: f64,
    /// Body width, m. Default 1.8.
    pub width: f64,
    /// IDM's maximum acceleration A, m/s². Default 1.5.
    pub accel: f64,
    /// IDM's comfortable deceleration b, m/s². Default 2.0.
    pub brake: f64,
    /// IDM's time headway T, s. Default 1.5.
    pub headway: f64,
    /// IDM's minimum gap s0, m. Default 2.0.
    pub min_gap: f64,
}

impl Default for TrafficRule {
    fn default() -> Self {
        TrafficRule {
            route: Route::Lead,
            trigger: Trigger::AtTime(0.0),
            light: LightCondition::Any,
            probability: 1.0,
            delay: (0.0, 0.0),
            speed: (8.0, 10.0),
            start: 30.0,
            behaviour: Behaviour::Careful,
            length: 4.5,
            width: 1.8,
            accel: 1.5,
            brake: 2.0,
            headway: 1.5,
            min_gap: 2.0,
        }
    }
}

/// A complete scenario. `Map::default()` is the training intersection without
/// pedestrians.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct Map {
    /// Short name. Default: the file name without `.ron` (not inherited from a base).
    pub name: String,
    /// One-line description (not inherited from a base). Default "".
    pub description: String,
    /// The base map this one was built on, as written in the file (informational).
    pub base: Option<String>,
    /// Road geometry.
    pub road: Road,
    /// Crosswalk geometry.
    pub crosswalk: Crosswalk,
    /// Traffic light.
    pub light: Light,
    /// The ego car.
    pub vehicle: Vehicle,
    /// Pedestrian spawn rules (a map that sets this list replaces the base's list). Default [].
    pub pedestrians: Vec<SpawnRule>,
    /// The cross street, its box, crosswalks, stop lines and signals. Default `None`: the
    /// straight road of the paper (not serialised when absent, so a map without a
    /// junction keeps its content hash and results files keep their run identity).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub junction: Option<Junction>,
    /// Spawn rules of other vehicles (a map that sets this list replaces the base's list).
    /// Default [] (not serialised when empty, as `junction`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub traffic: Vec<TrafficRule>,
    /// The scaled agent's settings on this map, `{"KEY": "VALUE"}` with the keys and values
    /// of `--set` (maps/README.md, "The agent's settings"): the defaults a world needs, e.g.
    /// the junction's gate. A run's own `--set` wins over them. A map that sets this
    /// replaces the base's. Default {} (not serialised when empty, as `junction`).
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub agent: BTreeMap<String, String>,
    /// Discretizer bins.
    pub bins: Bins,
    /// Reward.
    pub reward: Reward,
    /// Episode timing.
    pub episode: Episode,
    /// Expected batch results (replaces the base's list when set). Default [].
    pub expect: Vec<Expectation>,
    /// The base whose `expect` list this map inherited (its file sets none), if any: said
    /// by `check-map`, since those checks decide batch's exit code for this map too.
    #[serde(skip)]
    pub expect_inherited_from: Provenance,
}

/// Where a map's value came from (a base's name), for diagnostics only: not part of
/// the map's content, so two maps that differ only in it are equal (a map written out
/// and read back states every value itself).
#[derive(Debug, Clone, Default)]
pub struct Provenance(pub Option<String>);

impl PartialEq for Provenance {
    fn eq(&self, _other: &Self) -> bool {
        true
    }
}

/// Partial map as read from a file, before it is laid over its base.
#[derive(Debug, Clone, Default, Deserialize)]
#[serde(deny_unknown_fields, rename = "Map")]
pub(crate) struct MapPatch {
    #[serde(default)]
    pub(crate) base: Option<String>,
    #[serde(default)]
    name: Option<String>,
    #[serde(default)]
    description: Option<String>,
    #[serde(default)]
    road: Option<RoadPatch>,
    #[serde(default)]
    crosswalk: Option<CrosswalkPatch>,
    #[serde(default)]
    light: Option<LightPatch>,
    #[serde(default)]
    vehicle: Option<VehiclePatch>,
    #[serde(default)]
    pedestrians: Option<Vec<SpawnRule>>,
    #[serde(default)]
    junction: Option<JunctionPatch>,
    #[serde(default)]
    traffic: Option<Vec<TrafficRule>>,
    #[serde(default)]
    agent: Option<BTreeMap<String, String>>,
    #[serde(default)]
    bins: Option<BinsPatch>,
    #[serde(default)]
    reward: Option<RewardPatch>,
    #[serde(default)]
    episode: Option<EpisodePatch>,
    #[serde(default)]
    expect: Option<Vec<Expectation>>,
}

impl MapPatch {
    /// Lay this patch over `base`. `default_name` is used when the patch has no name.
    pub(crate) fn apply(self, mut base: Map, default_name: &str) -> Map {
        base.name = self.name.unwrap_or_else(|| default_name.to_string());
        base.description = self.description.unwrap_or_default();
        base.base = self.base;
        if let Some(p) = self.road {
            p.apply(&mut base.road);
        }
        if let Some(p) = self.crosswalk {
            p.apply(&mut base.crosswalk);
        }
        if let Some(p) = self.light {
            p.apply(&mut base.light);
        }
        if let Some(p) = self.vehicle {
            p.apply(&mut base.vehicle);
        }
        if let Some(p) = self.pedestrians {
            base.pedestrians = p;
        }
        if let Some(p) = self.junction {
            p.apply(base.junction.get_or_insert_default());
        }
        if let Some(p) = self.traffic {
            base.traffic = p;
        }
        if let Some(p) = self.agent {
            base.agent = p;
        }
        if let Some(p) = self.bins {
            p.apply(&mut base.bins);
        }
        if let Some(p) = self.reward {
            p.apply(&mut base.reward);
        }
        if let Some(p) = self.episode {
            p.apply(&mut base.episode);
        }
        match self.expect {
            Some(p) => {
                base.expect = p;
                base.expect_inherited_from = Provenance(None);
            }
            None if !base.expect.is_empty() => base.expect_inherited_from = Provenance(base.base.clone()),
            None => {}
        }
        base
    }
}

impl Road {
    /// Half the paved width (kerb to kerb), m.
    pub fn half_width(&self) -> f64 {
        self.lanes as f64 * self.lane_width / 2.0
    }

    /// y of the car's lane centre (the first lane on the near side), m.
    pub fn car_lane_y(&self) -> f64 {
        -self.half_width() + self.lane_width / 2.0
    }
}

impl Light {
    /// Total cycle length, s.
    pub fn cycle_length(&self) -> f64 {
        self.cycle.iter().map(|p| p.duration).sum()
    }
}

impl Episode {
    /// Physics sub-steps per decision tick (decision_dt × physics_hz, rounded).
    pub fn substeps(&self) -> u32 {
        (self.decision_dt * self.physics_hz).round().max(1.0) as u32
    }
}

impl Map {
    /// Distances to the goal of the crosswalk's near (first met) and far edge, m:
    /// `(goal_x - (x - width/2), goal_x - (x + width/2))`. Defaults: (26, 22).
    pub fn crosswalk_distance_to_goal(&self) -> (f64, f64) {
        let half = self.crosswalk.width / 2.0;
        (
            self.road.goal_x - (self.crosswalk.x - half),
            self.road.goal_x - (self.crosswalk.x + half),
        )
    }

    /// x of the crosswalk's near edge, m.
    pub fn crosswalk_near_x(&self) -> f64 {
        self.crosswalk.x - self.crosswalk.width / 2.0
    }

    /// A multi-line, human-readable summary of the scenario.
    pub fn summary(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        let _ = writeln!(s, "map {}", self.name);
        if !self.description.is_empty() {
            let _ = writeln!(s, "  {}", self.description);
        }
        if let Some(b) = &self.base {
            let _ = writeln!(s, "  based on {b}");
        }
        let r = &self.road;
        let (near, far) = self.crosswalk_distance_to_goal();
        let _ = writeln!(
            s,
            "road: {} lane(s) x {} m, sidewalks {} m, destination at x = {} m",
            r.lanes, r.lane_width, r.sidewalk_width, r.goal_x
        );
        let _ = writeln!(
            s,
            "crosswalk: x = {} m, {} m wide (distance to goal {near}..{far} m)",
            self.crosswalk.x, self.crosswalk.width
        );
        let v = &self.vehicle;
        let _ = writeln!(
            s,
            "car: {} x {} m, {} kg, front at x = {} m, {} m/s; accel {} m/s², brake {} m/s², max {} m/s, damping {}",
            v.length, v.width, v.mass, v.start_x, v.start_speed, v.max_accel, v.max_brake, v.max_speed, v.damping
        );
        if v.dynamics == Dynamics::Forces {
            let _ = writeln!(
                s,
                "dynamics: forces: drive {} N up to {} W, brake {} N after {} s dead time and a {} s lag, \
                 rolling {}, drag C_d {} x {} m²",
                v.drive_force,
                v.power,
                v.brake_force,
                v.brake_dead_time,
                v.brake_lag,
                v.rolling_resistance,
                v.drag_coefficient,
                v.frontal_area
            );
        }
        if v.dynamics == Dynamics::Forces || !r.surface.is_empty() {
            let _ = writeln!(s, "surface: μ {}, air {} kg/m³", r.friction, r.air_density);
        }
        for p in &r.surface {
            let when = p.trigger.map(|t| format!(" (appears {t:?})")).unwrap_or_default();
            let _ = writeln!(s, "surface patch: x {}..{} m, μ {}{when}", p.from, p.to, p.friction);
        }
        let cycle: Vec<String> = self
            .light
            .cycle
            .iter()
            .map(|p| format!("{} {} s", p.phase, p.duration))
            .collect();
        let offset = match self.light.offset {
            Offset::Fixed(o) => format!("offset {o} s"),
            Offset::Random => "random offset".to_string(),
        };
        let _ = writeln!(s, "light: {} ({offset})", cycle.join(", "));
        if self.pedestrians.is_empty() {
            let _ = writeln!(s, "pedestrians: none");
        }
        for (i, p) in self.pedestrians.iter().enumerate() {
            let trig = match p.trigger {
                Trigger::RedStarts => "at each red start".to_string(),
                Trigger::GreenStarts => "at each green start".to_string(),
                Trigger::AtTime(t) => format!("at t = {t} s"),
                Trigger::CarWithin { min, max } => {
                    format!("when the car is {min}..{max} m before the crosswalk")
                }
                Trigger::CarArrivesWithin(t) => {
                    format!("when the car would reach the crosswalk within {t} s")
                }
            };
            let pause = match p.pause {
                Some(pa) => format!(", stops {} s after {} m", pa.duration, pa.after),
                None => String::new(),
            };
            let _ = writeln!(
                s,
                "pedestrian rule {i}: {trig}, light {:?}, p = {}, side {:?}, {}..{} m/s, delay {}..{} s, radius {} m{pause}",
                p.light, p.probability, p.side, p.speed.0, p.speed.1, p.delay.0, p.delay.1, p.radius
            );
        }
        let b = &self.bins;
        let _ = writeln!(
            s,
            "bins: distance {}, speed {:?} m/s, observation noise {}",
            b.distance_edges, b.speed_edges, b.observation_noise
        );
        let w = &self.reward;
        let red_light = if w.red_light != 0.0 {
            format!(", entering the crosswalk on red {}", w.red_light)
        } else {
            String::new()
        };
        let _ = writeln!(
            s,
            "reward: {} per metre, goal {}, crash {}, step cost {}{red_light}",
            w.progress_per_metre, w.goal, w.crash, w.step_cost
        );
        let e = &self.episode;
        let _ = writeln!(
            s,
            "episode: {} s per tick, {} Hz physics ({} sub-steps), at most {} ticks",
            e.decision_dt,
            e.physics_hz,
            e.substeps(),
            e.max_steps
        );
        if let Some(from) = &self.expect_inherited_from.0 {
            let _ = writeln!(
                s,
                "expectations: {}, inherited from {from} (they decide batch's exit code here too; set `expect: []` for none)",
                self.expect.len()
            );
        }
        for x in &self.expect {
            let mut parts = Vec::new();
            for (label, val) in [
                ("min_success", x.min_success),
                ("max_success", x.max_success),
                ("min_reward", x.min_reward),
                ("max_reward", x.max_reward),
                ("max_collision", x.max_collision),
                ("max_inference_rate", x.max_inference_rate),
                ("max_red_light", x.max_red_light),
                ("max_timeout", x.max_timeout),
            ] {
                if let Some(v) = val {
                    parts.push(format!("{label} {v}"));
                }
            }
            let protocol = x.protocol.as_ref().map(|p| format!(" ({p})")).unwrap_or_default();
            let _ = writeln!(s, "expect {}{protocol}: {}", x.method, parts.join(", "));
        }
        s
    }
}
