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

/// A segment at rest on the line of one that slides along itself, 0.06
/// beyond the end of its sweep: the contract's parallelogram, built from
/// rounded corners, is a sliver that reaches the resting segment (the
/// "sliver" class of the contract's closing section). Returns the resting
/// line and the sliding one.
pub fn sliver_pair() -> (Line, Line) {
    let rest = line(
        (1.0647144347264588, 0.7249015338304577),
        (1.0687037965378123, 0.7194895144692043),
        (0.0, 0.0),
    );
    let sliding = line(
        (0.9979649053873545, 0.815454800799048),
        (0.9699591478722643, 0.8534477703679866),
        (0.020813462557612464, -0.028235810052612498),
    );
    (rest, sliding)
}
