//! Helpers shared by the unit tests.

use crate::geometry::Vec2;
use crate::line::Line;

/// A line from its endpoints and velocity as tuples.
pub fn line(p1: (f64, f64), p2: (f64, f64), v: (f64, f64)) -> Line {
    Line {
        p1: Vec2::new(p1.0, p1.1),
        p2: Vec2::new(p2.0, p2.1),
        v: Vec2::new(v.0, v.1),
    }
}
