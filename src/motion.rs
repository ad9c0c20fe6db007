//! The move and wall phases of a step, in one pass over the lines: each
//! line moves by its velocity for one time step, then bounces off the
//! walls it has crossed, exactly as the reference checks them.

use crate::geometry::Vec2;
use crate::lanes::{set_points, DefaultLanes, One};
use crate::line::Line;
use crate::team::Team;

/// The move and wall phases for `lines`: each line moves by `v * dt`, then
/// bounces off the walls. Returns the lines that hit a wall.
///
/// [`advance_lanes!`] a batch of lines at a time in the target's lanes
/// ([`crate::lanes`]: four with AVX2, two with the baseline's SSE2 and in
/// WebAssembly), the rest one at a time. Compiled for the baseline and for
/// AVX2 (with POPCNT, which every processor with AVX2 has, to count the
/// lines that hit a wall in one instruction), chosen when the program
/// starts; every path performs the same
/// operations in the same order, so their results are the same bits.
#[cfg_attr(
    not(screensaver_baseline),
    multiversion::multiversion(targets("x86_64+avx2+popcnt"))
)]
#[cfg_attr(
    screensaver_baseline,
    multiversion::multiversion(targets("x86_64+avx2+popcnt"), dispatcher = "static")
)]
pub(crate) fn advance_and_bounce(lines: &mut [Line]) -> u64 {
    multiversion::target::match_target! {
        "x86_64+avx2+popcnt" => advance_each_avx2(lines),
        _ => advance_each::<{ DefaultLanes::WIDTH }>(lines, batch_default),
    }
}

/// [`advance_and_bounce`] of `W` lines at a time by `batch`, the rest one
/// at a time.
#[inline(always)]
fn advance_each<const W: usize>(lines: &mut [Line], batch: impl Fn(&mut [Line]) -> u64) -> u64 {
    let mut blocks = lines.chunks_exact_mut(W);
    let mut hits = 0;
    for block in &mut blocks {
        hits += batch(block);
    }
    for line in blocks.into_remainder() {
        hits += u64::from(advance_one(line));
    }
    hits
}

/// [`advance_each`] with the AVX2 batch (the closure is compiled with
/// AVX2, as the function it is in).
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
fn advance_each_avx2(lines: &mut [Line]) -> u64 {
    advance_each::<{ crate::lanes::Avx2::WIDTH }>(lines, |block: &mut [Line]| batch_avx2(block))
}

/// The batch: [`advance_lanes!`] of the lines in `block` (as many as a lane
/// type's lanes), written back; returns the lines that hit a wall. Stamped
/// out for each lane type, with the attributes its target needs.
macro_rules! batch {
    ($(#[$attr:meta])* fn $name:ident($lanes:ty)) => {
        $(#[$attr])*
        fn $name(block: &mut [Line]) -> u64 {
            type L = $lanes;
            let batch: [&Line; <$lanes>::WIDTH] = std::array::from_fn(|k| &block[k]);
            let (point, (vx, vy)) = (L::points(batch), L::velocities(batch));
            let (point, vx, vy, hit) = advance_lanes!($lanes, point, vx, vy);
            let hits = L::hits(hit);
            // Without a hit the velocities are as they were: only the
            // points are written.
            match hits {
                0 => block.iter_mut().zip(L::rows(point)).for_each(|(line, p)| set_points(line, p)),
                _ => block.iter_mut().zip(L::lines(point, vx, vy)).for_each(|(line, l)| *line = l),
            }
            hits
        }
    };
}

#[cfg(target_arch = "x86_64")]
batch!(
    #[inline]
    #[target_feature(enable = "avx2")]
    fn batch_avx2(crate::lanes::Avx2)
);

batch!(
    #[inline(always)]
    fn batch_default(DefaultLanes)
);

/// The move and wall phases for `lines` ([`advance_and_bounce`]), on
/// `shared`'s team in as many pieces, if given.
pub(crate) fn advance(lines: &mut [Line], shared: Option<(&Team, usize)>) -> u64 {
    match shared {
        Some((team, pieces)) => {
            let parts = crate::team::split_mut(lines, pieces);
            team.run_pieces_sum(pieces, &|k| advance_and_bounce(parts.take(k)))
        }
        None => advance_and_bounce(lines),
    }
}

/// The move and the walls of lines in lanes, written once over a lane
/// type `$L` whose lanes are lines (one value of each line a lane;
/// [`One`] for a line alone, the hull batch's four at a time): given
/// `[p1.x, p1.y, p2.x, p2.y]`, `v.x` and `v.y`, gives the points moved by
/// `v * DT` ([`add_first`](crate::lanes::add_first)), then [`bounce_lanes!`] of them: the velocity after the walls
/// and the mask of the lines that hit one. Every lane type performs the
/// same operations in the same order, so each gives the same bits.
macro_rules! advance_lanes {
    ($L:ty, $point:expr, $vx:expr, $vy:expr) => {{
        use $crate::line::{BOX_MAX, BOX_MIN};
        type L = $L;
        let [ax, ay, bx, by]: [L; 4] = $point;
        let (vx, vy): (L, L) = ($vx, $vy);
        let dt = L::splat($crate::line::DT);
        let (dx, dy) = (vx.mul(dt), vy.mul(dt));
        // Where every point lands inside the box, none is NaN (so each sum
        // is `add_first`'s) and no wall check holds: the move is the sums,
        // and the walls leave the velocities as they are. Nearly every
        // batch, every step, takes this way.
        let sums = [ax.add(dx), ay.add(dy), bx.add(dx), by.add(dy)];
        let (low, high) = (L::splat(BOX_MIN), L::splat(BOX_MAX));
        let inside = (sums[0].inside(low, high)).and(sums[1].inside(low, high));
        let inside = inside.and(sums[2].inside(low, high).and(sums[3].inside(low, high)));
        if L::all(inside) {
            (sums, vx, vy, L::splat(0.0))
        } else {
            let point = [
                ax.add_first(dx),
                ay.add_first(dy),
                bx.add_first(dx),
                by.add_first(dy),
            ];
            let (vx, vy, hit) = $crate::motion::bounce_lanes!($L, point, vx, vy);
            (point, vx, vy, hit)
        }
    }};
}
pub(crate) use advance_lanes;

/// The walls of lines in lanes (as [`advance_lanes!`] takes them): the
/// reference's four checks, in its order, each seeing the velocity the
/// one before left, worked out with masks instead of branches (fewer
/// instructions in a pass over every line every step); a velocity is
/// turned by flipping its sign bit, exactly as `-v`. Gives the velocity
/// after the walls and the mask of the lines that hit one.
macro_rules! bounce_lanes {
    ($L:ty, $point:expr, $vx:expr, $vy:expr) => {{
        use $crate::line::{BOX_MAX, BOX_MIN};
        type L = $L;
        let [ax, ay, bx, by]: [L; 4] = $point;
        let (vx, vy): (L, L) = ($vx, $vy);
        let (high, low, zero) = (L::splat(BOX_MAX), L::splat(BOX_MIN), L::splat(0.0));
        let hit_max_x = ax.gt(high).or(bx.gt(high)).and(vx.gt(zero));
        let vx = vx.flip(hit_max_x);
        let hit_min_x = ax.lt(low).or(bx.lt(low)).and(vx.lt(zero));
        let vx = vx.flip(hit_min_x);
        let hit_max_y = ay.gt(high).or(by.gt(high)).and(vy.gt(zero));
        let vy = vy.flip(hit_max_y);
        let hit_min_y = ay.lt(low).or(by.lt(low)).and(vy.lt(zero));
        let vy = vy.flip(hit_min_y);
        (vx, vy, hit_max_x.or(hit_min_x).or(hit_max_y.or(hit_min_y)))
    }};
}
pub(crate) use bounce_lanes;

/// The line's `[p1.x, p1.y, p2.x, p2.y]`, `v.x` and `v.y`, one lane each.
#[inline(always)]
fn lanes_of(line: &Line) -> ([One; 4], One, One) {
    let (p1, p2, v) = (line.p1, line.p2, line.v);
    ([p1.x, p1.y, p2.x, p2.y].map(One), One(v.x), One(v.y))
}

/// The move and wall phases for one line ([`advance_lanes!`] on the line
/// alone); returns whether it hit a wall.
#[inline(always)]
pub(crate) fn advance_one(line: &mut Line) -> bool {
    let (point, vx, vy) = lanes_of(line);
    let ([ax, ay, bx, by], vx, vy, hit) = advance_lanes!(One, point, vx, vy);
    line.p1 = Vec2::new(ax.0, ay.0);
    line.p2 = Vec2::new(bx.0, by.0);
    line.v = Vec2::new(vx.0, vy.0);
    One::hits(hit) != 0
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::line::{BOX_MAX, BOX_MIN};
    use crate::test_util::line;

    /// The wall phase for one line ([`bounce_lanes!`] on the line alone):
    /// reverses the velocity components that carry it further out of the
    /// box. Returns whether any wall was hit.
    fn bounce_off_walls(line: &mut Line) -> bool {
        let (point, vx, vy) = lanes_of(line);
        let (vx, vy, hit) = bounce_lanes!(One, point, vx, vy);
        line.v = Vec2::new(vx.0, vy.0);
        One::hits(hit) != 0
    }

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
    fn a_line_moves_by_v_dt_then_bounces_as_the_reference_does() {
        let coords = [0.4, 0.499, BOX_MIN, 0.75, 0.999, BOX_MAX, 1.1, f64::NAN];
        let speeds = [-0.3, -0.003, -0.0, 0.0, 0.002, 0.2, f64::NAN, f64::INFINITY];
        for &a in &coords {
            for &b in &coords {
                for &v in &speeds {
                    let start = line((a, 0.75), (b, a), (v, -v));
                    let mut expected = start;
                    expected.p1 = expected.p1 + expected.v * crate::line::DT;
                    expected.p2 = expected.p2 + expected.v * crate::line::DT;
                    let hit = bounce_as_the_reference(&mut expected);
                    let mut moved = start;
                    assert_eq!(advance_one(&mut moved), hit);
                    // Every NaN alike: which one an operation on NaNs gives
                    // is the compiler's choice, and means nothing.
                    let value = |x: f64| {
                        if x.is_nan() {
                            f64::NAN.to_bits()
                        } else {
                            x.to_bits()
                        }
                    };
                    let bits = |l: &Line| [l.p1, l.p2, l.v].map(|p| [value(p.x), value(p.y)]);
                    assert_eq!(bits(&moved), bits(&expected));
                    let mut all = [start; 3];
                    assert_eq!(advance_and_bounce(&mut all), 3 * u64::from(hit));
                    assert!(all.iter().all(|l| bits(l) == bits(&expected)));
                }
            }
        }
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
