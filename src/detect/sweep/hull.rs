//! The packed hull: a box in up to four directions as eight `f32` lower
//! bounds, so that the overlap test of two boxes is one comparison of eight
//! lanes.
//!
//! A box with least values `lo[a]` and greatest values `hi[a]` along
//! directions `a = 0..4` is packed as `[lo[0..4], -hi[0..4]]`, every lane
//! rounded to the nearest `f32`. Two boxes overlap (closed: touching
//! counts) when `lo_j[a] <= hi_i[a]` and `lo_i[a] <= hi_j[a]` for every
//! `a`, that is when every lane of `P_j` is at most the matching lane of
//! [`reach`]`(P_i)`, which is `P_i` with its halves swapped and negated.
//! An unused direction is packed as `-inf` in both halves and never rules
//! a pair out.
//!
//! Rounding to `f32` never loses an overlap: rounding is monotone (and
//! symmetric about zero), so `lo_j <= hi_i` implies
//! `f32(lo_j) <= f32(hi_i)`, even where values beyond `f32`'s range
//! become infinite. It can only add overlaps between boxes closer than
//! `f32` resolves, which the exact test behind the sweep turns down.

use super::order::NO_KEY;
use crate::detect::swept::{DIAGONAL_X, DIAGONAL_Y, PAD};
use crate::line::Line;
use multiversion::multiversion;

/// Eight `f32` lower bounds: `[lo_x, lo_y, lo_u, lo_w, -hi_x, -hi_y, -hi_u, -hi_w]`.
pub(crate) type Packed = [f32; 8];

/// Lanes per half of a packed hull: one per direction.
pub(crate) const DIRECTIONS: usize = 4;

/// Lines whose coordinates (now or one step ahead) reach beyond this are
/// treated as wild (tested against every line), which keeps every packed
/// value finite: the same bound as every detector's.
pub(crate) use crate::detect::swept::LARGEST;

/// A line's padded swept hull (see [`crate::detect::swept::swept_box`],
/// whose bounds and padding it repeats) packed; `None` when the line is not
/// finite or reaches beyond [`LARGEST`].
///
/// The pad (`2^-20` of the magnitude `m`, and `1e-12`) is far wider than
/// the rounding to `f32` (`2^-24` of a bound, which is at most about `2m`,
/// or `1980` times that on the diagonals, whose pad is as much wider), so
/// every packed bound still lies beyond the segment by at least `2^-21 m`:
/// far more than the exact test's rounding errors (near `2^-50 m`).
#[inline(always)]
pub(crate) fn of_line(line: &Line, dt: f64) -> Option<Packed> {
    let (p1, p2) = (line.p1, line.p2);
    // The corners one step ahead are the corners now moved by `d`: along
    // `x` and `y` the extremes are found before adding `d` (rounding is
    // monotone, so this is exactly the corners' extent); along the
    // diagonals the sums differ from the corners' by a rounding, which
    // the pad covers many times over. The four directions are worked as
    // one array, which the compiler turns into vector operations.
    let d = line.v * dt;
    let (a, b, d) = (project(p1.x, p1.y), project(p2.x, p2.y), project(d.x, d.y));
    let mut lo = [0.0; DIRECTIONS];
    let mut hi = [0.0; DIRECTIONS];
    for k in 0..DIRECTIONS {
        lo[k] = min(a[k], b[k]) + min(d[k], 0.0);
        hi[k] = max(a[k], b[k]) + max(d[k], 0.0);
    }
    let magnitude = max(max(-lo[0], hi[0]), max(-lo[1], hi[1]));
    // NaN anywhere makes the sum NaN; an infinite coordinate makes it
    // infinite or NaN; past this test every min and max is exact.
    let sum = p1.x + p1.y + p2.x + p2.y + line.v.x + line.v.y;
    if !(sum.is_finite() && magnitude <= LARGEST) {
        return None;
    }
    let pad = magnitude * PAD + 1e-12;
    // The diagonals reach (1180 + 800) times the magnitude; so does their pad.
    let pad_diagonal = (DIAGONAL_X + DIAGONAL_Y) * pad;
    let pads = [pad, pad, pad_diagonal, pad_diagonal];
    let mut packed = [0.0; 8];
    for k in 0..DIRECTIONS {
        packed[k] = (lo[k] - pads[k]) as f32;
        packed[k + DIRECTIONS] = -(hi[k] + pads[k]) as f32;
    }
    Some(packed)
}

/// A point's coordinates along the four directions `x`, `y`, `u`, `w`.
#[inline(always)]
fn project(x: f64, y: f64) -> [f64; DIRECTIONS] {
    let (x_, y_) = (x * DIAGONAL_X, y * DIAGONAL_Y);
    [x, y, x_ + y_, x_ - y_]
}

/// Lines gathered at a time by [`make_gathered`].
const GATHER_BLOCK: usize = 256;

/// Makes the packed hull of each line `ids[k]` into `hulls[k]`, and its
/// least value along direction `along` into `keys[k]` ([`NO_KEY`] for a
/// line without a hull).
///
/// Compiled twice, for the baseline and for AVX2 (which does the four
/// directions' `f64` arithmetic in one register), and chosen when the
/// program starts by what the processor has. Both clones perform the same
/// operations in the same order, so their results are the same bits.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn make(
    lines: &[Line],
    ids: &[u32],
    hulls: &mut [Packed],
    keys: &mut [f32],
    along: usize,
    dt: f64,
) {
    for ((&id, hull), key) in ids.iter().zip(hulls).zip(keys) {
        *key = make_one(&lines[id as usize], dt, along, hull);
    }
}

/// Makes `line`'s packed hull into `hull` and returns its key (least value
/// along `along`), or [`NO_KEY`] if it has no hull.
#[inline(always)]
fn make_one(line: &Line, dt: f64, along: usize, hull: &mut Packed) -> f32 {
    match of_line(line, dt) {
        Some(packed) => {
            *hull = packed;
            lo(hull, along)
        }
        None => NO_KEY,
    }
}

/// [`make`] for scenes larger than the cache: the lines are gathered a
/// block at a time in a loop that does nothing else, so that many of their
/// cache misses are under way at once, and then their hulls are made.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn make_gathered(
    lines: &[Line],
    ids: &[u32],
    hulls: &mut [Packed],
    keys: &mut [f32],
    along: usize,
    dt: f64,
) {
    let mut block = [Line::default(); GATHER_BLOCK];
    for ((ids, hulls), keys) in ids
        .chunks(GATHER_BLOCK)
        .zip(hulls.chunks_mut(GATHER_BLOCK))
        .zip(keys.chunks_mut(GATHER_BLOCK))
    {
        for (line, &id) in block.iter_mut().zip(ids) {
            *line = lines[id as usize];
        }
        for ((line, hull), key) in block.iter().zip(hulls).zip(keys) {
            *key = make_one(line, dt, along, hull);
        }
    }
}

/// `min` without NaN handling: one instruction.
#[inline(always)]
fn min(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// `max` without NaN handling: one instruction.
#[inline(always)]
fn max(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// A box with least values `lo` and greatest values `hi` along the four
/// directions, packed.
#[inline]
pub(crate) fn pack(lo: [f64; 4], hi: [f64; 4]) -> Packed {
    [
        lo[0] as f32,
        lo[1] as f32,
        lo[2] as f32,
        lo[3] as f32,
        -hi[0] as f32,
        -hi[1] as f32,
        -hi[2] as f32,
        -hi[3] as f32,
    ]
}

/// What a packed box reaches: the upper bounds that another box's lanes
/// must not exceed for the two to overlap.
#[inline(always)]
pub(crate) fn reach(p: &Packed) -> Packed {
    [-p[4], -p[5], -p[6], -p[7], -p[0], -p[1], -p[2], -p[3]]
}

/// True when the box packed as `p` overlaps the one whose [`reach`] is `r`.
/// Written without branches so that it compiles to one vector comparison.
#[inline(always)]
pub(crate) fn overlaps(p: &Packed, r: &Packed) -> bool {
    let mut all = true;
    for k in 0..8 {
        all &= p[k] <= r[k];
    }
    all
}

/// The least value of the box packed as `p` along direction `a`.
#[inline(always)]
pub(crate) fn lo(p: &Packed, a: usize) -> f32 {
    p[a]
}

/// The greatest value of the box packed as `p` along direction `a`.
#[inline(always)]
pub(crate) fn hi(p: &Packed, a: usize) -> f32 {
    -p[a + DIRECTIONS]
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// Packing keeps every overlap, however close or far the values.
        #[test]
        fn packing_never_loses_an_overlap(
            a in -1.0f64..1.0, b in -1.0f64..1.0, e in proptest::sample::select(vec![-300, -40, -5, 0, 5, 38, 39, 300]),
            gap in proptest::sample::select(vec![0.0, 1e-30, 1e-9, 1e-7]),
        ) {
            let scale = 10f64.powi(e);
            let (lo_j, hi_i) = (a * scale, a * scale + gap * scale.abs());
            let n = f64::NEG_INFINITY;
            let (p, q) = (pack([lo_j, n, n, n], [lo_j + b.abs() * scale, -n, -n, -n]), pack([hi_i - scale, n, n, n], [hi_i, -n, -n, -n]));
            proptest::prop_assert!(overlaps(&p, &reach(&q)));
        }

        /// The packed hull of a line holds the line now and one step ahead
        /// with a margin of at least `2^-21` of its magnitude.
        #[test]
        fn line_hulls_hold_their_lines_with_a_margin(
            x1 in -3.0f64..3.0, y1 in -3.0f64..3.0, x2 in -3.0f64..3.0, y2 in -3.0f64..3.0,
            vx in -1.0f64..1.0, vy in -1.0f64..1.0, scale in proptest::sample::select(vec![1e-9, 1.0, 1e5]),
        ) {
            let l = crate::test_util::line((x1 * scale, y1 * scale), (x2 * scale, y2 * scale), (vx * scale, vy * scale));
            let p = of_line(&l, 0.5).unwrap();
            let corners = [l.p1, l.p2, l.p1 + l.v * 0.5, l.p2 + l.v * 0.5];
            let magnitude = corners.iter().map(|c| c.x.abs().max(c.y.abs())).fold(0.0, f64::max);
            let margin = magnitude / 2097152.0;
            for c in corners {
                let (u, w) = (1180.0 * c.x + 800.0 * c.y, 1180.0 * c.x - 800.0 * c.y);
                let values = [c.x, c.y, u, w];
                for (a, value) in values.into_iter().enumerate() {
                    proptest::prop_assert!(f64::from(lo(&p, a)) <= value - margin);
                    proptest::prop_assert!(f64::from(hi(&p, a)) >= value + margin);
                }
            }
        }
    }

    #[test]
    fn lines_beyond_the_largest_or_not_finite_have_no_hull() {
        let l = |x: f64, v: f64| crate::test_util::line((x, 0.5), (0.6, 0.6), (v, 0.0));
        assert!(of_line(&l(0.7, 0.01), 0.5).is_some());
        assert!(of_line(&l(2e30, 0.01), 0.5).is_none());
        assert!(of_line(&l(0.7, f64::NAN), 0.5).is_none());
        assert!(of_line(&l(f64::INFINITY, 0.0), 0.5).is_none());
    }

    fn boxed(lo: [f64; 4], hi: [f64; 4]) -> Packed {
        pack(lo, hi)
    }

    #[test]
    fn overlap_is_closed_and_needs_every_direction() {
        let a = boxed([0.0; 4], [1.0; 4]);
        let touching = boxed([1.0, 0.0, 0.0, 0.0], [2.0; 4]);
        let apart_in_w = boxed([0.5, 0.5, 0.5, 1.5], [2.0; 4]);
        let inside = boxed([0.25; 4], [0.5; 4]);
        for (b, expected) in [(touching, true), (apart_in_w, false), (inside, true)] {
            assert_eq!(overlaps(&b, &reach(&a)), expected);
            assert_eq!(overlaps(&a, &reach(&b)), expected);
        }
        assert_eq!((lo(&a, 2), hi(&a, 2)), (0.0, 1.0));
    }
}
