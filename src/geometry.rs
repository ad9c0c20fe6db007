//! Two-dimensional vectors and the exact orientation predicates of the
//! simulation contract.
//!
//! Every function here evaluates its formula in the order the contract
//! writes it, in `f64`, with no fused multiply-add and no reciprocal
//! multiplication: the results must match the reference program bit for bit.
//! NaN is never special-cased; every comparison with NaN is simply false,
//! exactly as in the reference.

use std::ops::{Add, Mul, Sub};

/// A point or a vector in the plane.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vec2 {
    /// Horizontal component.
    pub x: f64,
    /// Vertical component.
    pub y: f64,
}

impl Vec2 {
    /// Makes a vector from its components.
    #[inline]
    pub const fn new(x: f64, y: f64) -> Self {
        Self { x, y }
    }

    /// `x * other.x + y * other.y`.
    #[inline]
    pub fn dot(self, other: Self) -> f64 {
        self.x * other.x + self.y * other.y
    }

    /// Euclidean length through the reference libm's `hypot`
    /// ([`crate::maths::hypot`], the same on every platform).
    #[inline]
    pub fn length(self) -> f64 {
        if cfg!(feature = "platform-libm") {
            return self.x.hypot(self.y);
        }
        crate::maths::hypot(self.x, self.y)
    }

    /// The vector divided (not multiplied by a reciprocal) by its length.
    /// A zero vector gives NaN components, as in the reference.
    #[inline]
    pub fn normalize(self) -> Self {
        let len = self.length();
        Self::new(self.x / len, self.y / len)
    }

    /// The vector turned a quarter turn counter-clockwise: `(-y, x)`.
    #[inline]
    pub fn orthogonal(self) -> Self {
        Self::new(-self.y, self.x)
    }

    /// The angle of the vector, `atan2(y, x)`, correctly rounded
    /// ([`crate::maths::atan2`], the same on every platform).
    #[inline]
    pub fn angle(self) -> f64 {
        if cfg!(feature = "platform-libm") {
            return self.y.atan2(self.x);
        }
        crate::maths::atan2(self.y, self.x)
    }

    /// True when either component is NaN.
    #[inline]
    pub fn has_nan(self) -> bool {
        self.x.is_nan() || self.y.is_nan()
    }
}

impl Add for Vec2 {
    type Output = Self;
    #[inline]
    fn add(self, rhs: Self) -> Self {
        Self::new(self.x + rhs.x, self.y + rhs.y)
    }
}

impl Sub for Vec2 {
    type Output = Self;
    #[inline]
    fn sub(self, rhs: Self) -> Self {
        Self::new(self.x - rhs.x, self.y - rhs.y)
    }
}

impl Mul<f64> for Vec2 {
    type Output = Self;
    #[inline]
    fn mul(self, s: f64) -> Self {
        Self::new(self.x * s, self.y * s)
    }
}

/// Orientation of `k` relative to the directed line `i -> j`:
/// `(k.x - i.x) * (j.y - i.y) - (j.x - i.x) * (k.y - i.y)`.
/// Positive on one side, negative on the other, zero when collinear.
#[inline]
pub fn orient(i: Vec2, j: Vec2, k: Vec2) -> f64 {
    (k.x - i.x) * (j.y - i.y) - (j.x - i.x) * (k.y - i.y)
}

/// True when one value is strictly positive and the other strictly negative.
/// Zero and NaN are neither.
#[inline]
pub fn opposite(a: f64, b: f64) -> bool {
    (a > 0.0 && b < 0.0) || (a < 0.0 && b > 0.0)
}

/// True when `k` lies in the closed bounding box of the segment `i`–`j`
/// (meaningful as "on the segment" once `k` is known to be collinear).
#[inline]
pub fn on_segment(i: Vec2, j: Vec2, k: Vec2) -> bool {
    ((i.x <= k.x && k.x <= j.x) || (j.x <= k.x && k.x <= i.x))
        && ((i.y <= k.y && k.y <= j.y) || (j.y <= k.y && k.y <= i.y))
}

/// True when the closed segments `p1`–`p2` and `p3`–`p4` share a point,
/// decided by the contract's orientation tests (touching counts).
#[inline]
pub fn segments_cross(p1: Vec2, p2: Vec2, p3: Vec2, p4: Vec2) -> bool {
    segments_cross_by(orient, p1, p2, p3, p4)
}

/// [`segments_cross`] with the orientation test given: the contract's
/// [`orient`], or one in exact arithmetic, which tells whether segments
/// given as floating-point points truly meet (the tests use it to tell a
/// collision from rounding noise). Only the sign of `orient` matters.
/// Always inline: the exact test calls it up to four times, and as a call
/// `sin_wave` ran 5.8% more instructions.
#[inline(always)]
pub fn segments_cross_by(
    orient: impl Fn(Vec2, Vec2, Vec2) -> f64,
    p1: Vec2,
    p2: Vec2,
    p3: Vec2,
    p4: Vec2,
) -> bool {
    let d1 = orient(p3, p4, p1);
    let d2 = orient(p3, p4, p2);
    let d3 = orient(p1, p2, p3);
    let d4 = orient(p1, p2, p4);
    if opposite(d1, d2) && opposite(d3, d4) {
        return true;
    }
    (d1 == 0.0 && on_segment(p3, p4, p1))
        || (d2 == 0.0 && on_segment(p3, p4, p2))
        || (d3 == 0.0 && on_segment(p1, p2, p3))
        || (d4 == 0.0 && on_segment(p1, p2, p4))
}

/// True when `t` lies strictly inside the parallelogram whose sides are
/// `a`–`b`, `c`–`d`, `a`–`c` and `b`–`d`.
#[inline]
pub fn inside_parallelogram(t: Vec2, a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> bool {
    inside_parallelogram_by(orient, t, a, b, c, d)
}

/// [`inside_parallelogram`] with the orientation test given, as for
/// [`segments_cross_by`].
#[inline]
pub fn inside_parallelogram_by(
    orient: impl Fn(Vec2, Vec2, Vec2) -> f64,
    t: Vec2,
    a: Vec2,
    b: Vec2,
    c: Vec2,
    d: Vec2,
) -> bool {
    let e1 = orient(a, b, t);
    let e2 = orient(c, d, t);
    if !opposite(e1, e2) {
        return false;
    }
    let e3 = orient(a, c, t);
    let e4 = orient(b, d, t);
    opposite(e3, e4)
}

/// The point where the infinite lines through `p1`–`p2` and `p3`–`p4` meet,
/// as `p1 + (p2 - p1) * u`. Parallel lines give infinities or NaN.
#[inline]
pub fn crossing_point(p1: Vec2, p2: Vec2, p3: Vec2, p4: Vec2) -> Vec2 {
    let u = ((p4.x - p3.x) * (p1.y - p3.y) - (p4.y - p3.y) * (p1.x - p3.x))
        / ((p4.y - p3.y) * (p2.x - p1.x) - (p4.x - p3.x) * (p2.y - p1.y));
    p1 + (p2 - p1) * u
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64) -> Vec2 {
        Vec2::new(x, y)
    }

    #[test]
    fn arithmetic_is_componentwise() {
        assert_eq!(v(1.0, 2.0) + v(3.0, 5.0), v(4.0, 7.0));
        assert_eq!(v(1.0, 2.0) - v(3.0, 5.0), v(-2.0, -3.0));
        assert_eq!(v(1.5, -2.0) * 2.0, v(3.0, -4.0));
        assert_eq!(v(1.0, 2.0).dot(v(3.0, 4.0)), 11.0);
        assert_eq!(v(3.0, 4.0).length(), 5.0);
        assert_eq!(v(0.0, 2.0).normalize(), v(0.0, 1.0));
        assert_eq!(v(1.0, 2.0).orthogonal(), v(-2.0, 1.0));
        assert_eq!(v(0.0, 1.0).angle(), std::f64::consts::FRAC_PI_2);
    }

    #[test]
    fn normalizing_zero_gives_nan() {
        let n = v(0.0, 0.0).normalize();
        assert!(n.x.is_nan() && n.y.is_nan());
        assert!(n.has_nan());
        assert!(!v(1.0, 0.0).has_nan());
    }

    #[test]
    fn orient_sign_tells_the_side() {
        let (i, j) = (v(0.0, 0.0), v(1.0, 0.0));
        assert!(orient(i, j, v(0.5, 1.0)) < 0.0);
        assert!(orient(i, j, v(0.5, -1.0)) > 0.0);
        assert_eq!(orient(i, j, v(7.0, 0.0)), 0.0);
        // Zero-length base: every point is "collinear".
        assert_eq!(orient(i, i, v(3.0, 4.0)), 0.0);
    }

    #[test]
    fn opposite_ignores_zero_and_nan() {
        assert!(opposite(1.0, -1.0));
        assert!(opposite(-1e-300, 1e-300));
        assert!(!opposite(0.0, -1.0));
        assert!(!opposite(-0.0, 1.0));
        assert!(!opposite(1.0, 2.0));
        assert!(!opposite(f64::NAN, -1.0));
        assert!(!opposite(1.0, f64::NAN));
    }

    #[test]
    fn on_segment_is_a_closed_box_test() {
        let (i, j) = (v(0.0, 0.0), v(2.0, 1.0));
        assert!(on_segment(i, j, v(1.0, 0.5)));
        assert!(on_segment(j, i, v(0.0, 0.0)));
        assert!(on_segment(i, j, v(2.0, 1.0)));
        assert!(!on_segment(i, j, v(2.1, 0.5)));
        assert!(on_segment(i, i, i));
        assert!(!on_segment(i, j, v(f64::NAN, 0.5)));
    }

    #[test]
    fn crossing_touching_and_separate_segments() {
        let (a, b) = (v(0.0, 0.0), v(2.0, 2.0));
        assert!(segments_cross(a, b, v(0.0, 2.0), v(2.0, 0.0)));
        // An endpoint touching the other segment counts.
        assert!(segments_cross(a, b, v(1.0, 1.0), v(3.0, 0.0)));
        // Shared endpoints count.
        assert!(segments_cross(a, b, b, v(5.0, 0.0)));
        assert!(!segments_cross(a, b, v(3.0, 0.0), v(4.0, 5.0)));
        // Parallel, apart.
        assert!(!segments_cross(a, b, v(1.0, 0.0), v(3.0, 2.0)));
    }

    #[test]
    fn collinear_segments_cross_only_when_overlapping() {
        let (a, b) = (v(0.0, 0.0), v(2.0, 0.0));
        assert!(segments_cross(a, b, v(1.0, 0.0), v(3.0, 0.0)));
        assert!(segments_cross(a, b, v(2.0, 0.0), v(3.0, 0.0)));
        assert!(!segments_cross(a, b, v(2.5, 0.0), v(3.0, 0.0)));
        // Axis-aligned vertical and collinear.
        assert!(segments_cross(
            v(1.0, 0.0),
            v(1.0, 2.0),
            v(1.0, 1.0),
            v(1.0, 5.0)
        ));
    }

    #[test]
    fn zero_length_segments_cross_only_when_lying_on_the_other() {
        let (a, b) = (v(0.0, 0.0), v(2.0, 0.0));
        let p = v(1.0, 0.0);
        assert!(segments_cross(a, b, p, p));
        assert!(segments_cross(p, p, a, b));
        let q = v(1.0, 1.0);
        assert!(!segments_cross(a, b, q, q));
        assert!(segments_cross(q, q, q, q));
        assert!(!segments_cross(q, q, p, p));
    }

    #[test]
    fn nan_never_crosses() {
        let n = v(f64::NAN, f64::NAN);
        let (a, b) = (v(0.0, 0.0), v(2.0, 0.0));
        assert!(!segments_cross(a, b, n, n));
        assert!(!segments_cross(n, n, a, b));
        assert!(!inside_parallelogram(n, a, b, v(0.0, 1.0), v(2.0, 1.0)));
    }

    #[test]
    fn inside_parallelogram_is_strict() {
        let (a, b, c, d) = (v(0.0, 0.0), v(2.0, 0.0), v(0.0, 1.0), v(2.0, 1.0));
        assert!(inside_parallelogram(v(1.0, 0.5), a, b, c, d));
        assert!(!inside_parallelogram(v(1.0, 0.0), a, b, c, d));
        assert!(!inside_parallelogram(v(0.0, 0.5), a, b, c, d));
        assert!(!inside_parallelogram(v(3.0, 0.5), a, b, c, d));
        // A degenerate (flat) parallelogram contains nothing.
        assert!(!inside_parallelogram(v(1.0, 0.0), a, b, a, b));
    }

    #[test]
    fn crossing_point_of_two_lines() {
        let p = crossing_point(v(0.0, 0.0), v(2.0, 2.0), v(0.0, 2.0), v(2.0, 0.0));
        assert_eq!(p, v(1.0, 1.0));
        // Parallel lines: division by zero, not a panic.
        let q = crossing_point(v(0.0, 0.0), v(1.0, 0.0), v(0.0, 1.0), v(1.0, 1.0));
        assert!(!q.x.is_finite() || !q.y.is_finite());
        // Collinear lines: 0 / 0.
        let r = crossing_point(v(0.0, 0.0), v(1.0, 0.0), v(2.0, 0.0), v(3.0, 0.0));
        assert!(r.has_nan());
    }
}
