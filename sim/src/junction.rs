//! The junction: a cross street meeting the road at `junction.x` (map section
//! [`crate::map::Junction`]), the box it makes, its crosswalks (one per arm at most: the map's
//! `crosswalk` on the near approach, mirrored copies on the others) and the stop line
//! of every approach ([`Layout`], docs/ARCHITECTURE.md §2).
//!
//! Coordinates are the road's: the road runs along +x with its centre line at y = 0,
//! the cross street along y with its centre line at x = `junction.x`. Traffic keeps
//! right, as the car does (it drives +x in the lane at negative y).

use crate::map::{Arm, DEFAULT_STOP_GAP, Map};

/// An axis-aligned rectangle, m.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rect {
    /// Least x.
    pub x0: f64,
    /// Greatest x.
    pub x1: f64,
    /// Least y.
    pub y0: f64,
    /// Greatest y.
    pub y1: f64,
}

impl Rect {
    /// Whether the point lies inside (edges included).
    pub fn contains(&self, x: f64, y: f64) -> bool {
        (self.x0..=self.x1).contains(&x) && (self.y0..=self.y1).contains(&y)
    }
}

/// Where a vehicle comes from: the arm it approaches the box on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Approach {
    /// From the west, eastbound: the car's direction (governed by the car's signal).
    FromWest,
    /// From the east, westbound: oncoming (the car's signal).
    FromEast,
    /// From the south, northbound (the cross street's signal).
    FromSouth,
    /// From the north, southbound (the cross street's signal).
    FromNorth,
}

impl Approach {
    /// The arm it comes in on.
    pub fn arm(self) -> Arm {
        match self {
            Approach::FromWest => Arm::West,
            Approach::FromEast => Arm::East,
            Approach::FromSouth => Arm::South,
            Approach::FromNorth => Arm::North,
        }
    }

    /// Unit direction of travel.
    pub fn direction(self) -> (f64, f64) {
        match self {
            Approach::FromWest => (1.0, 0.0),
            Approach::FromEast => (-1.0, 0.0),
            Approach::FromSouth => (0.0, 1.0),
            Approach::FromNorth => (0.0, -1.0),
        }
    }
}

/// The junction's geometry derived from a map (for a map without a junction: the road
/// and its crosswalk only, where lead and oncoming traffic still drive).
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// The junction box (road kerb to kerb by cross street kerb to kerb), if any.
    pub junction_box: Option<Rect>,
    /// The crosswalks on the road part, by arm (the map's `crosswalk` is West's).
    pub crosswalks: Vec<(Arm, Rect)>,
    road_half: f64,
    road_lane: f64,
    cross_x: f64,
    cross_half: f64,
    cross_lane: f64,
    /// Gap between a crosswalk and the box, m (the near one's).
    gap: f64,
    crosswalk_width: f64,
    stop_gap: f64,
    crosswalk_near_x: f64,
    crosswalk_far_x: f64,
}

impl Layout {
    /// The layout of `map` (a valid one: the checks are validation's).
    pub fn new(map: &Map) -> Layout {
        let road_half = map.road.half_width();
        let cw = &map.crosswalk;
        let near = Rect {
            x0: cw.x - cw.width / 2.0,
            x1: cw.x + cw.width / 2.0,
            y0: -road_half,
            y1: road_half,
        };
        let mut layout = Layout {
            junction_box: None,
            crosswalks: vec![(Arm::West, near)],
            road_half,
            road_lane: map.road.lane_width,
            cross_x: 0.0,
            cross_half: 0.0,
            cross_lane: 0.0,
            gap: 0.0,
            crosswalk_width: cw.width,
            stop_gap: DEFAULT_STOP_GAP,
            crosswalk_near_x: near.x0,
            crosswalk_far_x: near.x1,
        };
        let Some(j) = &map.junction else {
            return layout;
        };
        let cross_half = f64::from(j.lanes) * j.lane_width / 2.0;
        let bx = Rect {
            x0: j.x - cross_half,
            x1: j.x + cross_half,
            y0: -road_half,
            y1: road_half,
        };
        let gap = bx.x0 - near.x1;
        let w = cw.width;
        for &arm in &j.crosswalks {
            let r = match arm {
                Arm::West => continue,
                Arm::East => Rect {
                    x0: bx.x1 + gap,
                    x1: bx.x1 + gap + w,
                    ..near
                },
                Arm::South => Rect {
                    x0: bx.x0,
                    x1: bx.x1,
                    y0: bx.y0 - gap - w,
                    y1: bx.y0 - gap,
                },
                Arm::North => Rect {
                    x0: bx.x0,
                    x1: bx.x1,
                    y0: bx.y1 + gap,
                    y1: bx.y1 + gap + w,
                },
            };
            layout.crosswalks.push((arm, r));
        }
        layout.junction_box = Some(bx);
        layout.cross_x = j.x;
        layout.cross_half = cross_half;
        layout.cross_lane = j.lane_width;
        layout.gap = gap;
        layout.stop_gap = j.stop_gap;
        layout
    }

    /// The crosswalk on `arm`, if there is one.
    pub fn crosswalk(&self, arm: Arm) -> Option<Rect> {
        self.crosswalks.iter().find(|(a, _)| *a == arm).map(|(_, r)| *r)
    }

    /// The stop line of `approach` and the centre of the lane it drives, as the point
    /// where the line crosses the lane, m. The car's approach stops before the map's
    /// crosswalk; without a junction, oncoming traffic stops after it (mirrored) and
    /// cross traffic has no stop line (`None`).
    pub fn stop_point(&self, approach: Approach) -> Option<(f64, f64)> {
        let lane_y = self.road_half - self.road_lane / 2.0;
        let before_box = |arm: Arm| match self.crosswalk(arm) {
            Some(_) => self.gap + self.crosswalk_width + self.stop_gap,
            None => self.stop_gap,
        };
        match (approach, self.junction_box) {
            (Approach::FromWest, _) => Some((self.crosswalk_near_x - self.stop_gap, -lane_y)),
            (Approach::FromEast, None) => Some((self.crosswalk_far_x + self.stop_gap, lane_y)),
            (_, None) => None,
            (Approach::FromEast, Some(b)) => Some((b.x1 + before_box(Arm::East), lane_y)),
            (Approach::FromSouth, Some(b)) => Some((
                self.cross_x + self.cross_half - self.cross_lane / 2.0,
                b.y0 - before_box(Arm::South),
            )),
            (Approach::FromNorth, Some(b)) => Some((
                self.cross_x - self.cross_half + self.cross_lane / 2.0,
                b.y1 + before_box(Arm::North),
            )),
        }
    }

    /// Along `approach`'s route, measured from its stop line (positive past it): where the
    /// conflict area begins and ends, m (the box; without a junction, the crosswalk).
    pub fn conflict_span(&self, approach: Approach) -> Option<(f64, f64)> {
        let (sx, sy) = self.stop_point(approach)?;
        let (ux, uy) = approach.direction();
        let r = self.junction_box.unwrap_or(self.crosswalks[0].1);
        let along = |x: f64, y: f64| (x - sx) * ux + (y - sy) * uy;
        let (a, b) = if ux != 0.0 {
            (along(r.x0, sy), along(r.x1, sy))
        } else {
            (along(sx, r.y0), along(sx, r.y1))
        };
        Some((a.min(b), a.max(b)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Junction;

    #[test]
    fn default_layout() {
        let map = Map {
            junction: Some(Junction {
                crosswalks: vec![Arm::East, Arm::South],
                ..Junction::default()
            }),
            ..Map::default()
        };
        let l = Layout::new(&map);
        let b = l.junction_box.unwrap();
        assert_eq!((b.x0, b.x1, b.y0, b.y1), (69.0, 76.0, -3.5, 3.5));
        assert_eq!(l.crosswalk(Arm::East).map(|r| (r.x0, r.x1)), Some((77.0, 81.0)));
        assert_eq!(l.crosswalk(Arm::South).map(|r| (r.y0, r.y1)), Some((-8.5, -4.5)));
        assert_eq!(l.crosswalk(Arm::North), None);
        assert_eq!(l.stop_point(Approach::FromWest), Some((63.0, -1.75)));
        assert_eq!(l.stop_point(Approach::FromEast), Some((82.0, 1.75)));
        assert_eq!(l.stop_point(Approach::FromSouth), Some((74.25, -9.5)));
        assert_eq!(l.stop_point(Approach::FromNorth), Some((70.75, 4.5)));
        assert_eq!(l.conflict_span(Approach::FromWest), Some((6.0, 13.0)));
        assert_eq!(l.conflict_span(Approach::FromNorth), Some((1.0, 8.0)));
        let plain = Layout::new(&Map::default());
        assert_eq!(plain.junction_box, None);
        assert_eq!(plain.stop_point(Approach::FromSouth), None);
        assert_eq!(plain.stop_point(Approach::FromEast), Some((69.0, 1.75)));
    }
}
