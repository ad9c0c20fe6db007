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
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
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

    /// The sign of `self.angle() - other.angle()`, the difference the
    /// contract's intersection test compares with zero: `-1.0`, `0.0` or
    /// `1.0`, NaN when either angle is NaN. Bit for bit what the
    /// subtraction gives (the sign of a difference of doubles is that of
    /// the doubles' order), but mostly found without either angle:
    ///
    /// Where both vectors have a `y` of ordinary size (from 2^-400 to
    /// 2^400, `x` of that size or zero), their angles lie in (0, pi) for
    /// `y > 0` and in (-pi, 0) for `y < 0`. On opposite sides the one
    /// above is the larger. On the same side `cross = other x self`, which
    /// is `|self| |other| sin(difference)`, has the difference's sign; when
    /// it is above `2^-47 T` (`T = (|x1| + |y1|)(|x2| + |y2|)`, at least
    /// `|self| |other|`, and the products' and difference's rounding error
    /// below `2^-51 T`), the exact cross product is above `2^-48 T` and the
    /// exact angles differ by more than 2^-48, eight units in the last
    /// place of an angle near pi (more of smaller ones), so their correctly
    /// rounded values keep their order and differ. Below that (nearly
    /// parallel vectors, such as lines of one slope whose directions were
    /// rounded apart) the cross product is made again in double-double,
    /// within `2^-52` of itself: above `2^-49 T` the exact angles differ by
    /// more than 2^-50, two units in the last place near pi, which is
    /// still enough (about 60 instructions in place of two angles' 1,400).
    /// Vectors along an axis have the exact angles 0, pi/2 and pi (see
    /// `axis_against`). Anything else (parallel or within 2^-50, huge,
    /// tiny, infinite, NaN) takes both angles.
    #[inline]
    pub fn angle_difference_sign(self, other: Self) -> f64 {
        self.angle_order_fast(other)
            .unwrap_or_else(|| sign_of(self.angle() - other.angle()))
    }

    /// The fast path of [`Vec2::angle_difference_sign`]: `None` where it
    /// cannot be sure.
    #[inline(always)]
    fn angle_order_fast(self, other: Self) -> Option<f64> {
        // The platform's atan2 is not correctly rounded: only ours may be
        // told apart by order alone.
        if cfg!(feature = "platform-libm") {
            return None;
        }
        const fn power_of_two(e: i64) -> f64 {
            f64::from_bits(((1023 + e) as u64) << 52)
        }
        const LOW: f64 = power_of_two(-400);
        const HIGH: f64 = power_of_two(400);
        const MARGIN: f64 = power_of_two(-47);
        const FINE_MARGIN: f64 = power_of_two(-49);
        let ordinary = |z: f64| (LOW..=HIGH).contains(&z.abs());
        let x_ok = |x: f64| x == 0.0 || ordinary(x);
        let sign = |up: bool| if up { 1.0 } else { -1.0 };
        match (self.y == 0.0, other.y == 0.0) {
            (false, false) => {}
            // Both along the x axis: angles of 0 (x > 0) or pi with the
            // sign of the zero y (x < 0).
            (true, true) => {
                if !(ordinary(self.x) && ordinary(other.x)) {
                    return None;
                }
                let on_axis = |v: Vec2| {
                    if v.x > 0.0 {
                        0.0
                    } else {
                        std::f64::consts::PI.copysign(v.y)
                    }
                };
                return Some(sign_of(on_axis(self) - on_axis(other)));
            }
            (true, false) => {
                if !(ordinary(self.x) && ordinary(other.y) && x_ok(other.x)) {
                    return None;
                }
                return axis_against(self, other, MARGIN).map(sign);
            }
            (false, true) => {
                if !(ordinary(other.x) && ordinary(self.y) && x_ok(self.x)) {
                    return None;
                }
                return axis_against(other, self, MARGIN).map(|up| sign(!up));
            }
        }
        if !(ordinary(self.y) && ordinary(other.y) && x_ok(self.x) && x_ok(other.x)) {
            return None;
        }
        if (self.y > 0.0) != (other.y > 0.0) {
            return Some(sign(self.y > 0.0));
        }
        if self.x == 0.0 && other.x == 0.0 {
            // Both pi/2, or both -pi/2.
            return Some(0.0);
        }
        let cross = other.x * self.y - other.y * self.x;
        let bound = (self.x.abs() + self.y.abs()) * (other.x.abs() + other.y.abs());
        if cross.abs() > bound * MARGIN {
            return Some(sign(cross > 0.0));
        }
        // Nearly parallel: the cross product to a unit in its last place.
        let cross = crate::maths::difference_of_products(other.x, self.y, other.y, self.x);
        if cross.abs() > bound * FINE_MARGIN {
            Some(sign(cross > 0.0))
        } else {
            None
        }
    }

    /// True when either component is NaN.
    #[inline]
    pub fn has_nan(self) -> bool {
        self.x.is_nan() || self.y.is_nan()
    }
}

/// `-1.0`, `0.0` or `1.0` by the sign of `difference` (either zero gives
/// `0.0`), NaN for NaN.
fn sign_of(difference: f64) -> f64 {
    if difference > 0.0 {
        1.0
    } else if difference < 0.0 {
        -1.0
    } else if difference == 0.0 {
        0.0
    } else {
        difference
    }
}

/// Whether the angle of `axis` (along the x axis: `y` zero, `x` of
/// ordinary size) is above the angle of `other` (`y` of ordinary size,
/// `x` zero or ordinary), for [`Vec2::angle_order_fast`]; `None` where
/// `other`'s angle may round to pi. Along +x the angle is 0, below any
/// angle with `y > 0`, above any with `y < 0`. Along -x it is pi (or -pi
/// for a `y` of -0), above every angle of `y > 0` (below every angle of
/// `y < 0`) that stays more than 2^-48 from pi, as one with
/// `|y| > margin (|x| + |y|)` does (a margin of 2^-47, the sum's rounding
/// taken off).
fn axis_against(axis: Vec2, other: Vec2, margin: f64) -> Option<bool> {
    if axis.x > 0.0 {
        return Some(other.y < 0.0);
    }
    let up = axis.y.is_sign_positive();
    let far_from_pi = other.x >= 0.0 || other.y.abs() > margin * (other.x.abs() + other.y.abs());
    (up != (other.y > 0.0) || far_from_pi).then_some(up)
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
/// Always inline: the exact test calls it up to four times for every pair
/// it tests, where a call costs more than the orientation tests it makes.
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

    /// The sign of the difference of both angles, taken in full.
    fn slow_sign(a: Vec2, b: Vec2) -> f64 {
        let d = a.angle() - b.angle();
        if d.is_nan() {
            d
        } else {
            (d > 0.0) as i32 as f64 - (d < 0.0) as i32 as f64
        }
    }

    fn same(x: f64, y: f64) -> bool {
        x.to_bits() == y.to_bits() || (x.is_nan() && y.is_nan()) || (x == 0.0 && y == 0.0)
    }

    #[test]
    fn angle_signs_agree_with_both_angles_on_awkward_vectors() {
        let values = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            0.5,
            -0.75,
            1e-300,
            -1e-300,
            1e300,
            -1e300,
            5e-324,
            f64::MAX,
            f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
            f64::EPSILON,
            3.0,
            -7.0,
            1e-17,
            -1e-17,
            1e-12,
            -2.0,
        ];
        // Every combination in an optimised build; a seventh of them in a
        // debug build, where each takes far longer.
        let stride = if cfg!(debug_assertions) { 7 } else { 1 };
        let (mut fast, mut k) = (0, 0usize);
        for &ax in &values {
            for &ay in &values {
                for &bx in &values {
                    for &by in &values {
                        k += 1;
                        if k % stride != 0 {
                            continue;
                        }
                        let (a, b) = (v(ax, ay), v(bx, by));
                        let got = a.angle_difference_sign(b);
                        let want = slow_sign(a, b);
                        assert!(same(got, want), "{a:?} {b:?}: {got} against {want}");
                        fast += usize::from(a.angle_order_fast(b).is_some());
                    }
                }
            }
        }
        assert!(fast > 1_000 / stride, "{fast}");
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(
            if cfg!(debug_assertions) { 2_000 } else { 20_000 }
        ))]

        #[test]
        fn angle_signs_agree_with_both_angles(
            ax in -1.0f64..1.0, ay in -1.0f64..1.0,
            turn in -1e-9f64..1e-9, scale in 1e-6f64..1e6, near in proptest::bool::ANY,
            bx in -1.0f64..1.0, by in -1.0f64..1.0,
            finely in proptest::bool::ANY, fine in 9.0f64..17.0,
        ) {
            // Either another direction, or nearly (or exactly) the same or
            // the opposite one: turned by up to 1e-9, half the time by
            // 1e-9 to 1e-17 of a turn (about the fast path's margin of
            // 2^-47, 7e-15, and the units in the last place).
            let turn = if finely { turn.signum() * 10f64.powf(-fine) } else { turn };
            let b = if near {
                let (s, c) = (turn.sin(), turn.cos());
                v((ax * c - ay * s) * scale, (ax * s + ay * c) * scale)
            } else {
                v(bx, by)
            };
            let a = v(ax, ay);
            for (p, q) in [(a, b), (b, a), (a, v(-b.x, -b.y)), (a, a)] {
                let got = p.angle_difference_sign(q);
                let want = slow_sign(p, q);
                proptest::prop_assert!(same(got, want), "{:?} {:?}: {} against {}", p, q, got, want);
            }
        }
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
