//! The packed hull: a box in up to four directions as eight `f32` lower
//! bounds, so that the overlap test of two boxes is one comparison of eight
//! lanes.
//!
//! A box with least values `lo[a]` and greatest values `hi[a]` along
//! directions `a = 0..4` is packed as `[lo[0..4], -hi[0..4]]`, every lane
//! rounded down to `f32` (so the packed box holds the `f64` one). Two boxes
//! overlap (closed: touching counts) when `lo_j[a] <= hi_i[a]` and
//! `lo_i[a] <= hi_j[a]` for every `a`, that is when every lane of `P_j` is
//! at most the matching lane of [`reach`]`(P_i)`, which is `P_i` with its
//! halves swapped and negated. An unused direction is packed as
//! `[-inf, .., -inf]` in both halves and never rules a pair out.

use crate::detect::swept::SweptBox;

/// Eight `f32` lower bounds: `[lo_x, lo_y, lo_u, lo_w, -hi_x, -hi_y, -hi_u, -hi_w]`.
pub(crate) type Packed = [f32; 8];

/// Lanes per half of a packed hull: one per direction.
pub(crate) const DIRECTIONS: usize = 4;

/// The largest `f32` at most `x` (`x` is not NaN). Values beyond `f32`'s
/// range round to its largest finite value or to `-inf`, both lower bounds.
#[inline]
pub(crate) fn round_down(x: f64) -> f32 {
    let f = x as f32;
    if f64::from(f) > x {
        f.next_down()
    } else {
        f
    }
}

/// A swept hull (finite, padded) packed and rounded down.
#[inline]
pub(crate) fn pack(b: &SweptBox) -> Packed {
    [
        round_down(b.min_x),
        round_down(b.min_y),
        round_down(b.min_u),
        round_down(b.min_w),
        round_down(-b.max_x),
        round_down(-b.max_y),
        round_down(-b.max_u),
        round_down(-b.max_w),
    ]
}

/// What a packed box reaches: the upper bounds that another box's lanes
/// must not exceed for the two to overlap.
#[inline]
pub(crate) fn reach(p: &Packed) -> Packed {
    [
        -p[4], -p[5], -p[6], -p[7], -p[0], -p[1], -p[2], -p[3],
    ]
}

/// True when the box packed as `p` overlaps the one whose [`reach`] is `r`.
/// Written without branches so that it compiles to one vector comparison.
#[inline]
pub(crate) fn overlaps(p: &Packed, r: &Packed) -> bool {
    let mut all = true;
    for k in 0..8 {
        all &= p[k] <= r[k];
    }
    all
}

/// The least value of the box packed as `p` along direction `a`.
#[inline]
pub(crate) fn lo(p: &Packed, a: usize) -> f32 {
    p[a]
}

/// The greatest value of the box packed as `p` along direction `a`.
#[inline]
pub(crate) fn hi(p: &Packed, a: usize) -> f32 {
    -p[a + DIRECTIONS]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rounding_down_never_rounds_up() {
        for x in [
            0.1,
            -0.1,
            0.75,
            1.0 / 3.0,
            -1.0 / 3.0,
            1e-300,
            -1e-300,
            1e39,
            -1e39,
            f64::from(f32::MAX),
            0.0,
            -0.0,
        ] {
            let f = round_down(x);
            assert!(f64::from(f) <= x, "{x} rounded to {f}");
            // And it is the largest such f32.
            assert!(f == f32::MAX || f64::from(f.next_up()) > x, "{x} rounded to {f}");
        }
        assert_eq!(round_down(-1e39), f32::NEG_INFINITY);
        assert_eq!(round_down(1e39), f32::MAX);
    }

    fn boxed(lo: [f64; 4], hi: [f64; 4]) -> Packed {
        pack(&SweptBox {
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
