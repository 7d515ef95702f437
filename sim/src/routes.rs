//! The path a vehicle's route takes through the junction (docs/ARCHITECTURE.md §2):
//! straight along its approach, or straight to the box and a quarter circle across it
//! (a turn), then straight on. A vehicle's state is its front's distance `s` along the
//! path from its stop line; [`Path::pose`] gives the point and the heading there.

use std::f64::consts::FRAC_PI_2;

/// A quarter-circle turn to the left, starting `enter` m past the stop line.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Turn {
    enter: f64,
    radius: f64,
}

/// A route's path: the stop point, the direction of approach, and the turn, if any.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Path {
    origin: (f64, f64),
    dir: (f64, f64),
    turn: Option<Turn>,
}

impl Path {
    /// Straight through `origin` (s = 0) along the unit vector `dir`.
    pub fn straight(origin: (f64, f64), dir: (f64, f64)) -> Path {
        Path {
            origin,
            dir,
            turn: None,
        }
    }

    /// Straight along `dir` from `origin`, then a quarter circle of `radius` m to the
    /// left beginning `enter` m past the stop line, then straight on to the left of `dir`.
    pub fn left_turn(origin: (f64, f64), dir: (f64, f64), enter: f64, radius: f64) -> Path {
        Path {
            origin,
            dir,
            turn: Some(Turn { enter, radius }),
        }
    }

    /// Where the turn begins and ends along the path, m (`None`: straight).
    pub fn turn_span(&self) -> Option<(f64, f64)> {
        self.turn.map(|t| (t.enter, t.enter + t.radius * FRAC_PI_2))
    }

    /// The point `s` m along the path and the unit heading there.
    pub fn pose(&self, s: f64) -> ((f64, f64), (f64, f64)) {
        let (o, u) = (self.origin, self.dir);
        let along = |from: (f64, f64), d: (f64, f64), k: f64| (from.0 + d.0 * k, from.1 + d.1 * k);
        let Some(t) = self.turn.filter(|t| s > t.enter) else {
            return (along(o, u, s), u);
        };
        // The left normal; the circle's centre lies `radius` to the left of the turn's start.
        let n = (-u.1, u.0);
        let start = along(o, u, t.enter);
        let centre = along(start, n, t.radius);
        let theta = (s - t.enter) / t.radius;
        if theta >= FRAC_PI_2 {
            let exit = along(centre, u, t.radius);
            return (along(exit, n, (theta - FRAC_PI_2) * t.radius), n);
        }
        let (c, si) = (theta.cos(), theta.sin());
        let p = (
            centre.0 - n.0 * t.radius * c + u.0 * t.radius * si,
            centre.1 - n.1 * t.radius * c + u.1 * t.radius * si,
        );
        (p, (u.0 * c + n.0 * si, u.1 * c + n.1 * si))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: (f64, f64), b: (f64, f64)) -> bool {
        (a.0 - b.0).abs() < 1e-9 && (a.1 - b.1).abs() < 1e-9
    }

    /// An oncoming left-turner of the default junction: westbound at y = 1.75 from its
    /// stop line at x = 78, into the box at x = 76, round (76, −3.5) to the southbound
    /// lane at x = 70.75.
    #[test]
    fn a_left_turn_is_a_quarter_circle_between_two_lanes() {
        let p = Path::left_turn((78.0, 1.75), (-1.0, 0.0), 2.0, 5.25);
        assert_eq!(p.pose(-3.0), ((81.0, 1.75), (-1.0, 0.0)));
        assert_eq!(p.pose(2.0), ((76.0, 1.75), (-1.0, 0.0)));
        let (_, end) = p.turn_span().unwrap();
        let (q, h) = p.pose(end);
        assert!(close(q, (70.75, -3.5)) && close(h, (0.0, -1.0)), "{q:?} {h:?}");
        let (q, h) = p.pose(end + 10.0);
        assert!(close(q, (70.75, -13.5)) && close(h, (0.0, -1.0)), "{q:?} {h:?}");
        // Half way round: on the circle, heading south-west.
        let (q, h) = p.pose(2.0 + 5.25 * FRAC_PI_2 / 2.0);
        let r = ((q.0 - 76.0).powi(2) + (q.1 + 3.5).powi(2)).sqrt();
        assert!(
            (r - 5.25).abs() < 1e-9 && (h.0 - h.1).abs() < 1e-9 && h.0 < 0.0,
            "{q:?} {h:?}"
        );
    }
}
