//! [`intersect`](crate::narrow::intersect) with its orientation tests four
//! at a time, in AVX2 registers.
//!
//! The exact test asks whether `l1` crosses four segments (`l2` now, and
//! the three other sides of the parallelogram `l2` sweeps relative to
//! `l1`), four orientation tests each, and whether both of `l1`'s
//! endpoints lie inside that parallelogram, four more each, two of which
//! are among the first sixteen. Those twenty-two products of differences
//! are the whole cost of the test. Here the four segments are the four
//! lanes of a register: five registers of orientations make every one of
//! them in about forty instructions, where one at a time they took about
//! three hundred with the branches between them. Each lane computes
//! exactly what [`orient`](crate::geometry::orient) computes (the same
//! subtractions in the same order, then two products and their
//! difference, never fused), so every sign is the same; only the signs
//! are used. Where an orientation is zero the scalar test looks whether
//! the point lies in the other segment's box; so do the lanes, with the
//! same comparisons, when any lane needs it. The decision after the signs
//! is [`kind_of`], shared with the scalar test.

use super::max;
use crate::line::Line;
use crate::narrow::{kind_of, may_intersect, IntersectionKind};
use std::arch::x86_64::{
    __m128d, __m256d, _mm256_add_pd, _mm256_and_pd, _mm256_cmp_pd, _mm256_max_pd, _mm256_min_pd,
    _mm256_movemask_pd, _mm256_mul_pd, _mm256_or_pd, _mm256_permute2f128_pd, _mm256_permute4x64_pd,
    _mm256_permute_pd, _mm256_set1_pd, _mm256_set_m128d, _mm256_setzero_pd, _mm256_sub_pd,
    _mm256_unpackhi_pd, _mm256_unpacklo_pd, _mm256_xor_pd, _mm_mul_pd, _mm_set1_pd, _mm_sub_pd,
    _CMP_EQ_OQ, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ,
};

/// The signs of four lanes: bit `k` of `.0` set where lane `k` is
/// positive, of `.1` where it is negative (neither for zero or NaN).
#[derive(Clone, Copy)]
struct Signs(u32, u32);

impl Signs {
    #[inline]
    #[target_feature(enable = "avx2")]
    fn of(x: __m256d) -> Self {
        let zero = _mm256_setzero_pd();
        let positive = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_GT_OQ>(x, zero));
        let negative = _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_LT_OQ>(x, zero));
        Signs(positive as u32, negative as u32)
    }

    /// Bit `k` set where lane `k` here and lane `k` of `o` have opposite
    /// signs ([`crate::geometry::opposite`]).
    #[inline(always)]
    fn opposite(self, o: Self) -> u32 {
        (self.0 & o.1) | (self.1 & o.0)
    }

    /// Bit `k` set where lanes `k` and `k + 1` have opposite signs.
    #[inline(always)]
    fn opposite_next(self) -> u32 {
        (self.0 & (self.1 >> 1)) | (self.1 & (self.0 >> 1))
    }

    /// Bit `k` set where lane `k` is zero or NaN.
    #[inline(always)]
    fn neither(self) -> u32 {
        !(self.0 | self.1) & 0b1111
    }
}

/// `(k - i) x (j - i)` of points given by coordinates in lanes, lane by
/// lane: [`orient`](crate::geometry::orient)`(i, j, k)`, the same
/// operations on the same values.
#[inline]
#[target_feature(enable = "avx2")]
fn orient(i: (__m256d, __m256d), j: (__m256d, __m256d), k: (__m256d, __m256d)) -> __m256d {
    let first = _mm256_mul_pd(_mm256_sub_pd(k.0, i.0), _mm256_sub_pd(j.1, i.1));
    let second = _mm256_mul_pd(_mm256_sub_pd(j.0, i.0), _mm256_sub_pd(k.1, i.1));
    _mm256_sub_pd(first, second)
}

/// Lanes `[a, b, c, d]` of `x` as `[x[a], x[b], x[c], x[d]]`; `IMM` is
/// `a | b << 2 | c << 4 | d << 6`.
#[inline]
#[target_feature(enable = "avx2")]
fn pick<const IMM: i32>(x: __m256d) -> __m256d {
    _mm256_permute4x64_pd::<IMM>(x)
}

/// The prefilter and the exact test of `l1` and `l2` (the lower id
/// first): `None` where [`may_intersect`] rules the pair out, else `Some`
/// of what [`intersect`](crate::narrow::intersect) finds. The same answers for
/// every pair of lines (the property tests of `crate::detect::pairs` hold
/// it to that); the magnitude the prefilter's margin takes is made in
/// lanes too, by the same operations.
#[inline]
#[target_feature(enable = "avx2")]
pub(crate) fn screen(l1: &Line, l2: &Line, dt: f64) -> Option<Option<IntersectionKind>> {
    if !may_intersect(l1, l2, dt, || magnitude(l1, l2, dt)) {
        return None;
    }
    Some(Lanes::of(l1, l2, dt).intersect(l1, l2))
}

/// A line's endpoints in lanes, `[p1.x, p1.y, p2.x, p2.y]`.
#[inline(always)]
fn row(l: &Line) -> __m256d {
    bytemuck::cast([l.p1.x, l.p1.y, l.p2.x, l.p2.y])
}

/// A line's velocity in lanes, `[v.x, v.y]`.
#[inline(always)]
fn velocity(l: &Line) -> __m128d {
    bytemuck::cast([l.v.x, l.v.y])
}

/// Both lanes of `v` in each half: `[v.0, v.1, v.0, v.1]`.
#[inline]
#[target_feature(enable = "avx2")]
fn twice(v: __m128d) -> __m256d {
    _mm256_set_m128d(v, v)
}

/// The larger of the two lines' magnitudes: the same operations as
/// [`magnitude`](crate::detect::swept::magnitude) of each (the least and
/// greatest of the endpoints, then of those moved by the line's own
/// velocity, then of the two), two lines a register. Made only where the
/// prefilter's margin decides ([`may_intersect`]).
#[inline]
#[target_feature(enable = "avx2")]
fn magnitude(l1: &Line, l2: &Line, dt: f64) -> f64 {
    let dt = _mm_set1_pd(dt);
    let ahead = |l: &Line| _mm256_add_pd(row(l), twice(_mm_mul_pd(velocity(l), dt)));
    let ([p1, p2], [m1, m2]) = (halves(row(l1), row(l2)), halves(ahead(l1), ahead(l2)));
    // Lanes `[x, y]` of `l1`, then of `l2`.
    let least = _mm256_min_pd(_mm256_min_pd(p1, p2), _mm256_min_pd(m1, m2));
    let greatest = _mm256_max_pd(_mm256_max_pd(p1, p2), _mm256_max_pd(m1, m2));
    let reach = _mm256_max_pd(_mm256_xor_pd(least, _mm256_set1_pd(-0.0)), greatest);
    let each = _mm256_max_pd(reach, _mm256_permute_pd::<0b0101>(reach));
    let [a, _, b, _]: [f64; 4] = bytemuck::cast(each);
    max(a, b)
}

/// The values of a pair of lines in lanes, as the exact test takes them.
#[derive(Clone, Copy)]
struct Lanes {
    /// `l1`'s endpoints, `l2`'s, and `l2`'s moved by the relative
    /// velocity (`q1`, `q2`): each as `[p1.x, p1.y, p2.x, p2.y]`.
    one: __m256d,
    two: __m256d,
    relative: __m256d,
}

impl Lanes {
    #[inline]
    #[target_feature(enable = "avx2")]
    fn of(l1: &Line, l2: &Line, dt: f64) -> Self {
        let (one, two) = (row(l1), row(l2));
        let travel = _mm_mul_pd(_mm_sub_pd(velocity(l2), velocity(l1)), _mm_set1_pd(dt));
        Lanes {
            one,
            two,
            relative: _mm256_add_pd(two, twice(travel)),
        }
    }

    /// [`intersect`](crate::narrow::intersect)`(l1, l2, dt)` of the lines these
    /// lanes hold (`dt` taken in the relative move).
    #[inline]
    #[target_feature(enable = "avx2")]
    fn intersect(self, l1: &Line, l2: &Line) -> Option<IntersectionKind> {
        let (one, two, moved) = (self.one, self.two, self.relative);
        // The four segments `a`-`b` that `l1` may cross, a lane each:
        // `l2` (`p1`-`p2`), the far side `q1`-`q2`, the top `q1`-`p1`, the
        // bottom `q2`-`p2`.
        let (xs, ys) = (
            _mm256_unpacklo_pd(two, moved),
            _mm256_unpackhi_pd(two, moved),
        ); // [p1, q1, p2, q2]
        let a = (pick::<0xD4>(xs), pick::<0xD4>(ys)); // [p1, q1, q1, q2]
        let b = (pick::<0x8E>(xs), pick::<0x8E>(ys)); // [p2, q2, p1, p2]
        let p1 = (pick::<0x00>(one), pick::<0x55>(one));
        let p2 = (pick::<0xAA>(one), pick::<0xFF>(one));
        let orientations = [
            orient(a, b, p1),
            orient(a, b, p2),
            orient(p1, p2, a),
            orient(p1, p2, b),
        ];
        let (d1, d2) = (Signs::of(orientations[0]), Signs::of(orientations[1]));
        let (d3, d4) = (Signs::of(orientations[2]), Signs::of(orientations[3]));
        let mut crossed = d1.opposite(d2) & d3.opposite(d4);
        // Where an orientation is zero (or NaN), a point of one segment on
        // the line of the other may lie on that segment too.
        if (d1.neither() | d2.neither() | d3.neither() | d4.neither()) & !crossed != 0 {
            crossed |= touching([a, b, p1, p2], &orientations);
        }
        if crossed & 1 != 0 {
            return Some(IntersectionKind::AlreadyIntersected);
        }
        let (top, bottom) = (crossed & 0b100 != 0, crossed & 0b1000 != 0);
        let crossings = (crossed & 0b1110).count_ones();
        let inside = || {
            // Each endpoint `t` of `l1` inside the parallelogram with sides
            // `p1`-`p2`, `q1`-`q2` (the first two lanes of `d1` for `l1.p1`,
            // of `d2` for `l1.p2`), `p1`-`q1` and `p2`-`q2` (lanes
            // `[p1-q1 to l1.p1, p2-q2 to l1.p1, p1-q1 to l1.p2, p2-q2 to l1.p2]`).
            let from = (pick::<0x88>(two), pick::<0xDD>(two)); // [p1, p2, p1, p2]
            let to = (pick::<0x88>(moved), pick::<0xDD>(moved)); // [q1, q2, q1, q2]
            let t = (pick::<0xA0>(one), pick::<0xF5>(one)); // [l1.p1, l1.p1, l1.p2, l1.p2]
            let sides = Signs::of(orient(from, to, t)).opposite_next();
            let ends = d1.opposite_next() & 1 != 0 && d2.opposite_next() & 1 != 0;
            ends && sides & 1 != 0 && sides & 0b100 != 0
        };
        kind_of(l1, l2, (crossings, top, bottom), inside)
    }
}

/// The lanes where a segment `a`-`b` and `l1` (`p1`-`p2`) touch though no
/// two of the `orientations` ([`Lanes::intersect`]'s four) have opposite
/// signs: an orientation is zero and its point lies in the other segment's
/// box, as [`segments_cross`](crate::geometry::segments_cross) finds.
/// Rare but for scenes on a grid, and kept out of the common path.
#[inline(never)]
#[target_feature(enable = "avx2")]
fn touching([a, b, p1, p2]: [(__m256d, __m256d); 4], orientations: &[__m256d; 4]) -> u32 {
    let zero = |k: usize| _mm256_cmp_pd::<_CMP_EQ_OQ>(orientations[k], _mm256_setzero_pd());
    let on = [
        _mm256_and_pd(zero(0), on_segment(a, b, p1)),
        _mm256_and_pd(zero(1), on_segment(a, b, p2)),
        _mm256_and_pd(zero(2), on_segment(p1, p2, a)),
        _mm256_and_pd(zero(3), on_segment(p1, p2, b)),
    ];
    let any = _mm256_or_pd(_mm256_or_pd(on[0], on[1]), _mm256_or_pd(on[2], on[3]));
    _mm256_movemask_pd(any) as u32
}

/// [`on_segment`](crate::geometry::on_segment)`(i, j, k)` of points given
/// by coordinates in lanes, lane by lane: all ones where `k` lies in the
/// closed box of `i` and `j` (the same comparisons; NaN lies nowhere).
#[inline]
#[target_feature(enable = "avx2")]
fn on_segment(i: (__m256d, __m256d), j: (__m256d, __m256d), k: (__m256d, __m256d)) -> __m256d {
    let le = |a, b| _mm256_cmp_pd::<_CMP_LE_OQ>(a, b);
    let between = |i, j, k| {
        _mm256_or_pd(
            _mm256_and_pd(le(i, k), le(k, j)),
            _mm256_and_pd(le(j, k), le(k, i)),
        )
    };
    _mm256_and_pd(between(i.0, j.0, k.0), between(i.1, j.1, k.1))
}

/// The low halves of `a` and `b` in one register, and their high halves
/// in another: `[a.0, a.1, b.0, b.1]`, `[a.2, a.3, b.2, b.3]`.
#[inline]
#[target_feature(enable = "avx2")]
fn halves(a: __m256d, b: __m256d) -> [__m256d; 2] {
    [
        _mm256_permute2f128_pd::<0x20>(a, b),
        _mm256_permute2f128_pd::<0x31>(a, b),
    ]
}
