//! The move and wall phases of a step, in one pass over the lines: each
//! line moves by its velocity for one time step, then bounces off the
//! walls it has crossed, exactly as the reference checks them.

use crate::line::{Line, BOX_MAX, BOX_MIN, DT};

/// The move and wall phases for `lines`: each line moves by `v * dt`, then
/// bounces off the walls. Returns the lines that hit a wall.
///
/// Compiled for the baseline and for AVX2, chosen when the program starts;
/// both clones perform the same operations in the same order.
#[cfg_attr(
    not(screensaver_baseline),
    multiversion::multiversion(targets("x86_64+avx2"))
)]
#[cfg_attr(
    screensaver_baseline,
    multiversion::multiversion(targets("x86_64+avx2"), dispatcher = "static")
)]
pub(crate) fn advance_and_bounce(lines: &mut [Line]) -> u64 {
    let mut hits = 0;
    for line in lines {
        line.p1 = line.p1 + line.v * DT;
        line.p2 = line.p2 + line.v * DT;
        hits += u64::from(bounce_off_walls(line));
    }
    hits
}

/// The wall phase for one line: reverses the velocity components that carry
/// it further out of the box. Returns whether any wall was hit.
///
/// The reference's four checks, in its order (each sees the velocity the
/// one before left), worked out with masks instead of branches, which
/// take fewer instructions in a loop that runs over every line every step.
#[inline(always)]
pub fn bounce_off_walls(line: &mut Line) -> bool {
    let (p1, p2) = (line.p1, line.p2);
    let (vx, hit_max_x) = flip_if(line.v.x, (p1.x > BOX_MAX) | (p2.x > BOX_MAX), |v| v > 0.0);
    let (vx, hit_min_x) = flip_if(vx, (p1.x < BOX_MIN) | (p2.x < BOX_MIN), |v| v < 0.0);
    let (vy, hit_max_y) = flip_if(line.v.y, (p1.y > BOX_MAX) | (p2.y > BOX_MAX), |v| v > 0.0);
    let (vy, hit_min_y) = flip_if(vy, (p1.y < BOX_MIN) | (p2.y < BOX_MIN), |v| v < 0.0);
    line.v.x = vx;
    line.v.y = vy;
    hit_max_x | hit_min_x | hit_max_y | hit_min_y
}

/// `v` negated (its sign bit flipped, exactly as `-v`) when `outside` and
/// `heading(v)`, and whether it was.
#[inline(always)]
fn flip_if(v: f64, outside: bool, heading: impl Fn(f64) -> bool) -> (f64, bool) {
    let flip = outside & heading(v);
    (f64::from_bits(v.to_bits() ^ (u64::from(flip) << 63)), flip)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec2;
    use crate::test_util::line;

    #[test]
    fn a_corner_hit_counts_once_and_reverses_both_components() {
        let mut l = line((0.99, 0.99), (1.01, 1.02), (0.1, 0.1));
        assert!(bounce_off_walls(&mut l));
        assert_eq!(l.v, Vec2::new(-0.1, -0.1));
        // Already heading back in: no hit.
        assert!(!bounce_off_walls(&mut l));
    }

    /// The reference's wall checks, branch by branch.
    fn bounce_as_the_reference(line: &mut Line) -> bool {
        let mut hit = false;
        if (line.p1.x > BOX_MAX || line.p2.x > BOX_MAX) && line.v.x > 0.0 {
            line.v.x = -line.v.x;
            hit = true;
        }
        if (line.p1.x < BOX_MIN || line.p2.x < BOX_MIN) && line.v.x < 0.0 {
            line.v.x = -line.v.x;
            hit = true;
        }
        if (line.p1.y > BOX_MAX || line.p2.y > BOX_MAX) && line.v.y > 0.0 {
            line.v.y = -line.v.y;
            hit = true;
        }
        if (line.p1.y < BOX_MIN || line.p2.y < BOX_MIN) && line.v.y < 0.0 {
            line.v.y = -line.v.y;
            hit = true;
        }
        hit
    }

    #[test]
    fn walls_bounce_as_the_reference_does_in_every_case() {
        // The endpoints' x take every pair of the coordinates below (inside,
        // on or beyond either wall, or NaN), their y the pairs (middle, a)
        // and (a, a), and the velocity (v, -v) every kind of v. A line
        // spanning the box is flipped twice.
        let coords = [0.4, BOX_MIN, 0.75, BOX_MAX, 1.1, f64::NAN];
        let speeds = [-0.3, -0.0, 0.0, 0.2, f64::NAN, f64::INFINITY];
        let mut cases = 0;
        for &a in &coords {
            for &b in &coords {
                for &v in &speeds {
                    for &c in &[0.75, a] {
                        let mut line = line((a, c), (b, a), (v, -v));
                        let mut expected = line;
                        let hit = bounce_off_walls(&mut line);
                        assert_eq!(hit, bounce_as_the_reference(&mut expected));
                        assert_eq!(line.v.x.to_bits(), expected.v.x.to_bits());
                        assert_eq!(line.v.y.to_bits(), expected.v.y.to_bits());
                        cases += 1;
                    }
                }
            }
        }
        assert_eq!(cases, 432);
        let mut spanning = line((0.4, 0.7), (1.1, 0.7), (0.2, 0.0));
        assert!(bounce_off_walls(&mut spanning));
        assert_eq!(spanning.v.x, 0.2);
    }

    #[test]
    fn nan_lines_never_hit_walls() {
        let mut l = line(
            (f64::NAN, f64::NAN),
            (f64::NAN, f64::NAN),
            (f64::NAN, f64::NAN),
        );
        assert!(!bounce_off_walls(&mut l));
    }
}
