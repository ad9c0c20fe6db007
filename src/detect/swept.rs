//! Swept hulls, the currency of every broad phase, and the pair test that
//! every broad phase ends in.
//!
//! A line's swept hull holds its segment now and one step ahead. If two
//! lines collide during the step, their hulls overlap (the meeting point
//! lies in both), so a broad phase may skip any pair whose hulls are apart.
//! Hulls are padded by `2^-20` of their largest coordinate, which keeps them
//! conservative for the floating-point predicates of `intersect` (whose
//! errors are near `2^-50` of the coordinates).
//!
//! Lines fall into three groups:
//! - *inert* lines (NaN in both endpoints) can never collide again and are
//!   left out;
//! - lines with a finite hull go through the broad phase;
//! - the rest (a finite segment with a non-finite velocity, or coordinates
//!   too large to bound) are *wild*: each is tested against every other
//!   line.

use crate::geometry::Vec2;
use crate::lanes::One;
use crate::line::{Line, WINDOW_HEIGHT, WINDOW_WIDTH};

/// A line's padded swept hull, bounded in eight directions: the axes `x`
/// and `y` and the window's diagonals `u = 1180 x + 800 y` and
/// `w = 1180 x - 800 y` (45 degrees on screen, where scenes are drawn). The
/// diagonals make it tight for slanted lines, whose axis-aligned boxes are
/// loose.
/// Any direction is conservative: the meeting point of a collision lies in
/// both lines' hulls, so their projections on every direction overlap.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SweptBox {
    /// Left edge.
    pub min_x: f64,
    /// Bottom edge.
    pub min_y: f64,
    /// Least `u`.
    pub min_u: f64,
    /// Least `w`.
    pub min_w: f64,
    /// Right edge.
    pub max_x: f64,
    /// Top edge.
    pub max_y: f64,
    /// Greatest `u`.
    pub max_u: f64,
    /// Greatest `w`.
    pub max_w: f64,
}

/// Weight of `x` in the diagonals: the window's width.
pub const DIAGONAL_X: f64 = WINDOW_WIDTH;
/// Weight of `y` in the diagonals: the window's height.
pub const DIAGONAL_Y: f64 = WINDOW_HEIGHT;

impl SweptBox {
    /// The smallest axis-aligned box holding both (diagonals included).
    #[inline]
    pub fn union(&self, other: &SweptBox) -> SweptBox {
        SweptBox {
            min_x: min(self.min_x, other.min_x),
            min_y: min(self.min_y, other.min_y),
            max_x: max(self.max_x, other.max_x),
            max_y: max(self.max_y, other.max_y),
            min_u: min(self.min_u, other.min_u),
            max_u: max(self.max_u, other.max_u),
            min_w: min(self.min_w, other.min_w),
            max_w: max(self.max_w, other.max_w),
        }
    }
}

pub(crate) use crate::lanes::{max, min};

/// A line's endpoints now and one step ahead.
#[inline]
fn corners(line: &Line, dt: f64) -> [Vec2; 4] {
    [
        line.p1,
        line.p2,
        line.p1 + line.v * dt,
        line.p2 + line.v * dt,
    ]
}

/// The extent of `corners` as `[min_x, max_x, min_y, max_y]` (meaningful
/// when they are finite) and their magnitude: a bound on the absolute
/// values of their coordinates.
#[inline]
fn extent(c: &[Vec2; 4]) -> ([f64; 4], f64) {
    let min_x = min(min(c[0].x, c[1].x), min(c[2].x, c[3].x));
    let max_x = max(max(c[0].x, c[1].x), max(c[2].x, c[3].x));
    let min_y = min(min(c[0].y, c[1].y), min(c[2].y, c[3].y));
    let max_y = max(max(c[0].y, c[1].y), max(c[2].y, c[3].y));
    // For lo <= hi, max(-lo, hi) = max(|lo|, |hi|).
    let magnitude = max(max(-min_x, max_x), max(-min_y, max_y));
    ([min_x, max_x, min_y, max_y], magnitude)
}

/// The magnitude of a finite line's coordinates now and one step ahead:
/// the scale of the prefilter's margin.
#[inline]
pub(crate) fn magnitude(line: &Line, dt: f64) -> f64 {
    extent(&corners(line, dt)).1
}

/// Lines whose coordinates (now or one step ahead) reach beyond this have
/// no hull and are treated as wild (tested against every line): every
/// bound of a hull, the diagonals' too, and of the quadtree's fat hulls
/// (which reach eight steps ahead) then stays finite. Near `f64::MAX` the
/// diagonals (`1180 x + 800 y`) overflow to infinities or NaN, which no
/// overlap test can be trusted with.
pub const LARGEST: f64 = 1e30;

/// The padded swept hull of one line, `None` when it is not finite or
/// reaches beyond `LARGEST` (1e30).
#[inline]
pub fn swept_box(line: &Line, dt: f64) -> Option<SweptBox> {
    let (lo, hi) = hull_bounds(line, dt)?;
    Some(SweptBox {
        min_x: lo[0],
        min_y: lo[1],
        min_u: lo[2],
        min_w: lo[3],
        max_x: hi[0],
        max_y: hi[1],
        max_u: hi[2],
        max_w: hi[3],
    })
}

/// A line's padded swept hull as its least and greatest values along `x`,
/// `y`, `u` and `w`, `None` when it is not finite or reaches beyond
/// [`LARGEST`]: [`padded_hull!`] on one line.
#[inline(always)]
pub(crate) fn hull_bounds(line: &Line, dt: f64) -> Option<([f64; 4], [f64; 4])> {
    let (p1, p2, v) = (line.p1, line.p2, line.v);
    let point = [p1.x, p1.y, p2.x, p2.y].map(One);
    let (low, high, sum, magnitude) = padded_hull!(One, point, One(v.x), One(v.y), dt, PAD);
    (sum.0.is_finite() && magnitude.0 <= LARGEST).then(|| (low.map(|l| l.0), high.map(|h| h.0)))
}

/// The padded swept hull of lines, written once over a lane type `$L`
/// whose lanes are lines (one value of each line a lane; [`One`] for a
/// line alone in `f64`, the sweep's `f32` lanes for its packed hulls,
/// [`crate::lanes::single`]): given `[p1.x, p1.y, p2.x, p2.y]`, `v.x`,
/// `v.y`, `dt` and the relative pad (`$pad` of the magnitude, and
/// `1e-12`), gives the least and greatest values along `x`, `y`, `u` and
/// `w`, padded, and the sum of the line's values and its magnitude, from
/// which the caller tells whether the hull holds (the sum finite, the
/// magnitude at most [`LARGEST`]). Every lane type of a precision
/// performs the same operations in the same order, so each gives the
/// same bits.
///
/// The corners one step ahead are the corners now moved by `d = v dt`:
/// along `x` and `y` the extremes are found before adding `d` (rounding
/// is monotone, so this is exactly the corners' extent); along the
/// diagonals the sums differ from the corners' by a rounding, which the
/// pad covers many times over. NaN anywhere makes the sum NaN, an
/// infinite value makes it infinite or NaN; past that test every `min`
/// and `max` (`a < b ? a : b`, `a > b ? a : b`) is exact.
macro_rules! padded_hull {
    ($L:ty, $point:expr, $vx:expr, $vy:expr, $dt:expr, $pad:expr) => {{
        use $crate::detect::swept::{DIAGONAL_X, DIAGONAL_Y};
        type L = $L;
        let [ax, ay, bx, by]: [L; 4] = $point;
        let (vx, vy): (L, L) = ($vx, $vy);
        let sum = ax.add(ay).add(bx).add(by).add(vx).add(vy);
        let dt = L::splat($dt);
        let (dx, dy) = (vx.mul(dt), vy.mul(dt));
        let zero = L::splat(0.0);
        // The extent along a direction of the points `a` and `b` moved by
        // `d`.
        let extent = |a: L, b: L, d: L| (a.min(b).add(d.min(zero)), a.max(b).add(d.max(zero)));
        let (lo_x, hi_x) = extent(ax, bx, dx);
        let (lo_y, hi_y) = extent(ay, by, dy);
        let magnitude = (lo_x.neg().max(hi_x)).max(lo_y.neg().max(hi_y));
        // The pad; the diagonals reach (1180 + 800) times the magnitude,
        // and so does their pad.
        let pad = magnitude.mul(L::splat($pad)).add(L::splat(1e-12));
        let pad_diagonal = L::splat(DIAGONAL_X + DIAGONAL_Y).mul(pad);
        let (low_x, high_x) = (lo_x.sub(pad), hi_x.add(pad));
        let (low_y, high_y) = (lo_y.sub(pad), hi_y.add(pad));
        // A point's values along the diagonals.
        let project = |x: L, y: L| -> (L, L) {
            let (x_, y_) = (x.mul(L::splat(DIAGONAL_X)), y.mul(L::splat(DIAGONAL_Y)));
            (x_.add(y_), x_.sub(y_))
        };
        let ((au, aw), (bu, bw), (du, dw)) = (project(ax, ay), project(bx, by), project(dx, dy));
        let (lo_u, hi_u) = extent(au, bu, du);
        let (lo_w, hi_w) = extent(aw, bw, dw);
        let (low_u, high_u) = (lo_u.sub(pad_diagonal), hi_u.add(pad_diagonal));
        let (low_w, high_w) = (lo_w.sub(pad_diagonal), hi_w.add(pad_diagonal));
        (
            [low_x, low_y, low_u, low_w],
            [high_x, high_y, high_u, high_w],
            sum,
            magnitude,
        )
    }};
}
pub(crate) use padded_hull;

/// Relative padding of swept boxes: far above the rounding errors of the
/// predicates (near `2^-50` of the coordinates), far below any line's size.
pub const PAD: f64 = 1.0 / 1048576.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::line;

    #[test]
    fn the_box_holds_the_segment_now_and_one_step_ahead() {
        let l = line((0.6, 0.7), (0.8, 0.65), (0.1, -0.2));
        let (b, m) = (swept_box(&l, 0.5), magnitude(&l, 0.5));
        let (b, r) = (b.unwrap(), b.unwrap());
        assert!(b.min_x < 0.6 && b.max_x > 0.85);
        assert!(b.min_y < 0.55 && b.max_y > 0.7);
        assert!((b.max_x - 0.85).abs() < 1e-5);
        assert_eq!(m, 0.8 + 0.1 * 0.5);
        // Corners (0.6, 0.7), (0.8, 0.65), (0.65, 0.6), (0.85, 0.55).
        let corners = [(0.6, 0.7), (0.8, 0.65), (0.65, 0.6), (0.85, 0.55)];
        let u: Vec<f64> = corners
            .iter()
            .map(|(x, y)| 1180.0 * x + 800.0 * y)
            .collect();
        let w: Vec<f64> = corners
            .iter()
            .map(|(x, y)| 1180.0 * x - 800.0 * y)
            .collect();
        let least = |v: &[f64]| v.iter().copied().fold(f64::INFINITY, f64::min);
        let most = |v: &[f64]| v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        assert!(r.min_u < least(&u) && least(&u) - r.min_u < 1e-2);
        assert!(r.max_u > most(&u) && r.max_u - most(&u) < 1e-2);
        assert!(r.min_w < least(&w) && least(&w) - r.min_w < 1e-2);
        assert!(r.max_w > most(&w) && r.max_w - most(&w) < 1e-2);
    }

    proptest::proptest! {
        /// The box strictly contains the segment now and one step ahead, at
        /// any scale.
        #[test]
        fn boxes_strictly_contain_their_points(
            x1 in -3.0f64..3.0, y1 in -3.0f64..3.0, x2 in -3.0f64..3.0, y2 in -3.0f64..3.0,
            vx in -1.0f64..1.0, vy in -1.0f64..1.0, scale in proptest::sample::select(vec![1e-9, 1.0, 1e5]),
        ) {
            let l = line((x1 * scale, y1 * scale), (x2 * scale, y2 * scale), (vx * scale, vy * scale));
            let b = swept_box(&l, 0.5).unwrap();
            let r = b;
            for p in [l.p1, l.p2, l.p1 + l.v * 0.5, l.p2 + l.v * 0.5] {
                proptest::prop_assert!(b.min_x < p.x && p.x < b.max_x);
                proptest::prop_assert!(b.min_y < p.y && p.y < b.max_y);
                let (u, w) = (1180.0 * p.x + 800.0 * p.y, 1180.0 * p.x - 800.0 * p.y);
                proptest::prop_assert!(r.min_u < u && u < r.max_u);
                proptest::prop_assert!(r.min_w < w && w < r.max_w);
            }
        }
    }
}
