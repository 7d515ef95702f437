//! The junction as every picture of an episode draws it: the Gymnasium frame
//! (`python/src/render.rs`), the filmstrip ([`crate::reports::figures::filmstrip`]) and
//! the replay page ([`crate::reports::replay_html`]). One geometry, so that the three
//! agree: the cross street with its lanes and sidewalks, the crosswalks of the other
//! arms, every approach's stop line, the signal heads besides the car's and what each
//! shows ([`Lamp`]), and the other vehicles as oriented rectangles
//! (docs/ARCHITECTURE.md §2 for the junction, §6 for the pictures).
//!
//! Coordinates are the simulator's: x along the road, y across it, the car driving +x
//! in the lane at negative y.

use unforeseen_sim::junction::Rect;
use unforeseen_sim::{Approach, Arm, Aspect, Layout, LightPhase, Map, SignalState, Snapshot, VehicleSnapshot, Walk};

/// Metres of the cross street shown beyond the road's sidewalks on either side.
pub const CROSS_VIEW: f64 = 20.0;

/// Length of a vehicle's front band (its windscreen, which shows where it heads), m.
pub const FRONT_BAND: f64 = 0.6;

/// What a head shows, as drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Lamp {
    /// A vehicle head lit green.
    Green,
    /// A vehicle head lit amber.
    Amber,
    /// A vehicle head lit red.
    Red,
    /// A pedestrian head showing walk.
    Walk,
    /// A pedestrian head showing don't walk.
    DontWalk,
    /// Any head, dark (an outage).
    Dark,
}

impl Lamp {
    /// What a vehicle head showing `aspect` looks like.
    pub fn of_aspect(aspect: Aspect) -> Lamp {
        match aspect {
            Aspect::Lit(LightPhase::Green) => Lamp::Green,
            Aspect::Lit(LightPhase::Amber) => Lamp::Amber,
            Aspect::Lit(LightPhase::Red) => Lamp::Red,
            Aspect::Dark => Lamp::Dark,
        }
    }

    /// What a pedestrian head showing `walk` looks like.
    pub fn of_walk(walk: Walk) -> Lamp {
        match walk {
            Walk::Walk => Lamp::Walk,
            Walk::DontWalk => Lamp::DontWalk,
            Walk::Dark => Lamp::Dark,
        }
    }

    /// Its name, as the replay page's data and the trace write it: `green`, `amber`,
    /// `red`, `walk`, `dont_walk`, `dark`.
    pub fn name(self) -> &'static str {
        match self {
            Lamp::Green => "green",
            Lamp::Amber => "amber",
            Lamp::Red => "red",
            Lamp::Walk => "walk",
            Lamp::DontWalk => "dont_walk",
            Lamp::Dark => "dark",
        }
    }
}

/// Which of the controller's heads a drawn head repeats ([`SignalState`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Shows {
    /// The road's vehicle heads (the car's and oncoming traffic's).
    Road,
    /// The cross street's vehicle heads.
    Cross,
    /// The pedestrian heads of the crosswalks across the road.
    WalkRoad,
    /// The pedestrian heads of the crosswalks across the cross street.
    WalkCross,
}

/// A signal head where a picture draws it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Head {
    /// Where, m.
    pub x: f64,
    /// Where, m.
    pub y: f64,
    /// What it repeats.
    pub shows: Shows,
}

impl Head {
    /// What it shows in `signals`.
    pub fn lamp(&self, signals: &SignalState) -> Lamp {
        match self.shows {
            Shows::Road => Lamp::of_aspect(signals.road),
            Shows::Cross => Lamp::of_aspect(signals.cross),
            Shows::WalkRoad => Lamp::of_walk(signals.walk_road),
            Shows::WalkCross => Lamp::of_walk(signals.walk_cross),
        }
    }

    /// Whether it is a pedestrian head (drawn square; vehicle heads are round).
    pub fn pedestrian(&self) -> bool {
        matches!(self.shows, Shows::WalkRoad | Shows::WalkCross)
    }
}

/// A straight line from one point to another, m.
pub type Segment = [(f64, f64); 2];

/// What a picture adds to the straight road for a map with a junction.
#[derive(Debug, Clone, PartialEq)]
pub struct JunctionScene {
    /// The box, kerb to kerb both ways.
    pub junction_box: Rect,
    /// x of the cross street's west and east kerbs, m.
    pub cross_kerbs: (f64, f64),
    /// Width of each of the cross street's sidewalks, m.
    pub cross_sidewalk: f64,
    /// x of the lines between the cross street's lanes, m.
    pub cross_lane_lines: Vec<f64>,
    /// The crosswalks of the other arms than the car's (whose crosswalk, the map's
    /// `crosswalk`, every picture draws as on the straight road).
    pub crosswalks: Vec<(Arm, Rect)>,
    /// Every approach's stop line, across the lanes it governs.
    pub stop_lines: Vec<Segment>,
    /// The heads besides the car's (which every picture draws where it does on the
    /// straight road, from [`SignalState::road`]).
    pub heads: Vec<Head>,
    /// How far across the road the picture reaches, m: `|y|` up to the road's half
    /// width, its sidewalk and [`CROSS_VIEW`].
    pub reach: f64,
}

/// The junction of `map` as drawn, `None` for a map without one (a straight road, drawn
/// as the paper's).
pub fn junction_scene(map: &Map) -> Option<JunctionScene> {
    let j = map.junction.as_ref()?;
    let layout = Layout::new(map);
    let bx = layout.junction_box?;
    let half = map.road.half_width();
    let road_walk = half + map.road.sidewalk_width / 2.0;
    let cross_walk = j.sidewalk_width / 2.0;
    let stop = |a: Approach| layout.stop_point(a);
    let mut stop_lines = Vec::new();
    let mut heads = Vec::new();
    if let Some((x, _)) = stop(Approach::FromWest) {
        stop_lines.push([(x, -half), (x, 0.0)]);
    }
    if let Some((x, _)) = stop(Approach::FromEast) {
        stop_lines.push([(x, 0.0), (x, half)]);
        // On the oncoming driver's right: the far sidewalk, past its line.
        heads.push(Head {
            x: x + 1.0,
            y: road_walk,
            shows: Shows::Road,
        });
    }
    if let Some((_, y)) = stop(Approach::FromSouth) {
        stop_lines.push([(j.x, y), (bx.x1, y)]);
        heads.push(Head {
            x: bx.x1 + cross_walk,
            y: y - 1.0,
            shows: Shows::Cross,
        });
    }
    if let Some((_, y)) = stop(Approach::FromNorth) {
        stop_lines.push([(bx.x0, y), (j.x, y)]);
        heads.push(Head {
            x: bx.x0 - cross_walk,
            y: y + 1.0,
            shows: Shows::Cross,
        });
    }
    // A pedestrian head at each end of every crosswalk, on the sidewalk.
    for &(arm, r) in &layout.crosswalks {
        let ends = if arm.on_road() {
            let x = (r.x0 + r.x1) / 2.0;
            [(x, -road_walk), (x, road_walk)]
        } else {
            let y = (r.y0 + r.y1) / 2.0;
            [(bx.x0 - cross_walk, y), (bx.x1 + cross_walk, y)]
        };
        let shows = if arm.on_road() {
            Shows::WalkRoad
        } else {
            Shows::WalkCross
        };
        heads.extend(ends.map(|(x, y)| Head { x, y, shows }));
    }
    Some(JunctionScene {
        junction_box: bx,
        cross_kerbs: (bx.x0, bx.x1),
        cross_sidewalk: j.sidewalk_width,
        cross_lane_lines: (1..j.lanes).map(|k| bx.x0 + f64::from(k) * j.lane_width).collect(),
        crosswalks: layout.crosswalks.into_iter().filter(|(a, _)| *a != Arm::West).collect(),
        stop_lines,
        heads,
        reach: half + map.road.sidewalk_width + CROSS_VIEW,
    })
}

/// The part of `v`'s body from `from` to `to` m ahead of its rear (`0.0, v.length`: all
/// of it), as four corners: rear right, front right, front left, rear left.
pub fn vehicle_quad(v: &VehicleSnapshot, from: f64, to: f64) -> [(f64, f64); 4] {
    let (c, s) = (v.heading.cos(), v.heading.sin());
    let at = |along: f64, side: f64| {
        let a = along - v.length / 2.0;
        (v.x + a * c - side * s, v.y + a * s + side * c)
    };
    let w = v.width / 2.0;
    [at(from, -w), at(to, -w), at(to, w), at(from, w)]
}

/// Metres from the middle of the car's front bumper to the nearest point of `v`'s body
/// (0 when the point lies inside it).
pub fn gap_to_car(map: &Map, snap: &Snapshot, v: &VehicleSnapshot) -> f64 {
    let (dx, dy) = (snap.car_x - v.x, map.road.car_lane_y() - v.y);
    let (c, s) = (v.heading.cos(), v.heading.sin());
    let (along, side) = (dx * c + dy * s, -dx * s + dy * c);
    let out = |d: f64, half: f64| (d.abs() - half).max(0.0);
    out(along, v.length / 2.0).hypot(out(side, v.width / 2.0))
}

/// The vehicle in the car's path nearest to its front bumper, and that distance, m
/// ([`gap_to_car`]; `None` when no vehicle is in its path).
pub fn nearest_in_path<'a>(map: &Map, snap: &'a Snapshot) -> Option<(&'a VehicleSnapshot, f64)> {
    snap.vehicles
        .iter()
        .filter(|v| v.in_path)
        .map(|v| (v, gap_to_car(map, snap, v)))
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use unforeseen_sim::{Junction, Route};

    fn vehicle(x: f64, y: f64, heading: f64) -> VehicleSnapshot {
        VehicleSnapshot {
            x,
            y,
            heading,
            speed: 5.0,
            length: 4.0,
            width: 2.0,
            route: Route::FromSouth,
            past_stop_line: 0.0,
            in_path: true,
        }
    }

    #[test]
    fn the_default_junction_as_drawn() {
        assert_eq!(junction_scene(&Map::default()), None);
        let map = Map {
            junction: Some(Junction {
                crosswalks: vec![Arm::South],
                ..Junction::default()
            }),
            ..Map::default()
        };
        let s = junction_scene(&map).unwrap();
        assert_eq!(s.cross_kerbs, (69.0, 76.0));
        assert_eq!(s.cross_lane_lines, vec![72.5]);
        assert_eq!(s.crosswalks.len(), 1);
        assert_eq!(s.reach, 3.5 + 2.0 + CROSS_VIEW);
        // The car's line across its lane before its crosswalk; the south arm's across
        // the northbound lane before its crosswalk; the others at the box.
        assert!(s.stop_lines.contains(&[(63.0, -3.5), (63.0, 0.0)]));
        assert!(s.stop_lines.contains(&[(72.5, -9.5), (76.0, -9.5)]));
        assert!(s.stop_lines.contains(&[(69.0, 4.5), (72.5, 4.5)]));
        assert_eq!(s.stop_lines.len(), 4);
        // Oncoming, two cross-street heads, and two pedestrian heads per crosswalk.
        let count = |shows| s.heads.iter().filter(|h| h.shows == shows).count();
        assert_eq!(
            [Shows::Road, Shows::Cross, Shows::WalkRoad, Shows::WalkCross].map(count),
            [1, 2, 2, 2]
        );
        let dark = SignalState {
            road: Aspect::Dark,
            cross: Aspect::Dark,
            walk_road: Walk::Dark,
            walk_cross: Walk::Dark,
        };
        assert!(s.heads.iter().all(|h| h.lamp(&dark) == Lamp::Dark));
    }

    #[test]
    fn a_vehicle_is_a_rectangle_along_its_heading() {
        let v = vehicle(10.0, 0.0, std::f64::consts::FRAC_PI_2);
        let q = vehicle_quad(&v, 0.0, v.length);
        let near = |a: (f64, f64), b: (f64, f64)| (a.0 - b.0).abs() < 1e-12 && (a.1 - b.1).abs() < 1e-12;
        // Heading north: the rear at y = -2, the front at y = 2, its right at x = 11.
        assert!(near(q[0], (11.0, -2.0)) && near(q[1], (11.0, 2.0)) && near(q[2], (9.0, 2.0)));
        let front = vehicle_quad(&v, v.length - FRONT_BAND, v.length);
        assert!(near(front[0], (11.0, 2.0 - FRONT_BAND)));
    }

    #[test]
    fn the_gap_is_to_the_nearest_point_of_the_body() {
        let map = Map::default();
        let snap_at = |car_x: f64, v: VehicleSnapshot| {
            let world = unforeseen_sim::World::from_map(&map, 0);
            let mut s = world.snapshot();
            s.car_x = car_x;
            s.vehicles = vec![v];
            s
        };
        let lane = map.road.car_lane_y();
        let ahead = vehicle(20.0, lane, 0.0);
        let s = snap_at(10.0, ahead);
        assert!((gap_to_car(&map, &s, &ahead) - 8.0).abs() < 1e-12);
        let (_, gap) = nearest_in_path(&map, &s).unwrap();
        assert!((gap - 8.0).abs() < 1e-12);
        // Inside the body: 0; not in the path: no nearest.
        assert_eq!(gap_to_car(&map, &snap_at(19.0, ahead), &ahead), 0.0);
        let aside = VehicleSnapshot {
            in_path: false,
            ..ahead
        };
        assert!(nearest_in_path(&map, &snap_at(10.0, aside)).is_none());
    }
}
