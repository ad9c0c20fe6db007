//! The sweep's broad phase on boxes of your own: every pair of
//! axis-aligned boxes that overlap, found by sorting and sweeping in bands
//! (planned as the sweep detector plans its own) instead of testing every
//! pair. [`overlapping_pairs`] and [`for_each_overlapping_pair`] look at
//! each call's boxes afresh; a [`BroadPhase`] kept from one call to the
//! next is the sweep detector's own code, and puts boxes that moved a
//! little back in order by a few moves.
//!
//! Each thread keeps its working memory (about 40 bytes a box) from one
//! call to the next, so that a program that finds pairs every frame does
//! not ask the system for fresh memory every frame.
//!
//! ```
//! use screensaver::broad_phase::{overlapping_pairs, Aabb};
//!
//! let boxes = [
//!     Aabb { min: [0.0, 0.0], max: [1.0, 1.0] },
//!     Aabb { min: [1.0, 0.5], max: [2.0, 2.0] }, // touches the first
//!     Aabb { min: [5.0, 5.0], max: [6.0, 6.0] },
//! ];
//! assert_eq!(overlapping_pairs(&boxes), vec![(0, 1)]);
//! ```

mod banded;
mod kept;

pub use kept::BroadPhase;

use crate::detect::sweep::hull::{pack, Packed, DIRECTIONS};
use crate::detect::sweep::plan;
use crate::detect::sweep::tuning::LayoutCost;

/// An axis-aligned box, closed: boxes that only touch overlap. A box whose
/// least value exceeds its greatest on either axis, or that holds a NaN, is
/// empty and overlaps nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Aabb {
    /// Least `x` and `y`.
    pub min: [f64; 2],
    /// Greatest `x` and `y`.
    pub max: [f64; 2],
}

impl Aabb {
    /// True when the two boxes overlap: neither is empty, and on both axes
    /// each box's least value is at most the other's greatest.
    #[inline]
    pub fn overlaps(&self, other: &Aabb) -> bool {
        !self.is_empty()
            && !other.is_empty()
            && (self.min[0] <= other.max[0])
            && (other.min[0] <= self.max[0])
            && (self.min[1] <= other.max[1])
            && (other.min[1] <= self.max[1])
    }

    /// True when the box holds no point: its least value exceeds its
    /// greatest on an axis, or it has a NaN.
    #[inline]
    pub fn is_empty(&self) -> bool {
        !(self.min[0] <= self.max[0] && self.min[1] <= self.max[1])
    }

    /// The box packed as the sweep packs a line's hull, its diagonals
    /// unbounded and every lane held to `f32`'s largest value (so that
    /// keys are, as the sweep needs, at most that), which only widens it.
    fn packed(&self) -> Packed {
        let unbounded = f64::INFINITY;
        pack(
            [self.min[0], self.min[1], -unbounded, -unbounded],
            [self.max[0], self.max[1], unbounded, unbounded],
        )
        .map(|lane| lane.min(f32::MAX))
    }

    /// The box of everything `line` covers while it moves for `dt`
    /// (padded a little, as the detectors pad it, so that rounding never
    /// loses a collision); `None` for a line that is not finite or reaches
    /// beyond 1e30.
    pub fn swept(line: &crate::Line, dt: f64) -> Option<Aabb> {
        crate::detect::swept_box(line, dt).map(|b| Aabb {
            min: [b.min_x, b.min_y],
            max: [b.max_x, b.max_y],
        })
    }
}

/// Every pair of `boxes` that overlap ([`Aabb::overlaps`]), once each, the
/// lower index first, in no particular order.
///
/// ```
/// use screensaver::broad_phase::{overlapping_pairs, Aabb};
///
/// let square = |x: f64, y: f64| Aabb { min: [x, y], max: [x + 1.0, y + 1.0] };
/// let boxes = [square(0.0, 0.0), square(0.5, 0.5), square(3.0, 0.0), square(3.9, 0.9)];
/// let mut pairs = overlapping_pairs(&boxes);
/// pairs.sort();
/// assert_eq!(pairs, [(0, 1), (2, 3)]);
/// ```
///
/// # Panics
/// If there are more boxes than `u32` indices.
pub fn overlapping_pairs(boxes: &[Aabb]) -> Vec<(u32, u32)> {
    let mut pairs = Vec::new();
    for_each_overlapping_pair(boxes, |a, b| pairs.push((a, b)));
    pairs
}

/// Calls `found(a, b)` for every pair of `boxes` that overlap, once each,
/// with `a < b`, in no particular order; allocates no list of pairs.
///
/// ```
/// use screensaver::broad_phase::{for_each_overlapping_pair, Aabb};
///
/// let boxes: Vec<Aabb> = (0..100)
///     .map(|k| {
///         let x = f64::from(k);
///         Aabb { min: [x, 0.0], max: [x + 1.5, 1.0] }
///     })
///     .collect();
/// let mut count = 0;
/// for_each_overlapping_pair(&boxes, |a, b| {
///     assert!(a < b && b - a <= 1);
///     count += 1;
/// });
/// assert_eq!(count, 99);
/// ```
///
/// # Panics
/// If there are more boxes than `u32` indices.
pub fn for_each_overlapping_pair(boxes: &[Aabb], mut found: impl FnMut(u32, u32)) {
    assert!(
        u32::try_from(boxes.len()).is_ok(),
        "too many boxes for u32 indices"
    );
    // The plan is drawn from an even sample of the boxes, packed as the
    // detector packs its hulls.
    let stride = boxes.len().div_ceil(BROAD_SAMPLE).max(1);
    let sample: Vec<_> = boxes
        .iter()
        .step_by(stride)
        .filter(|b| !b.is_empty())
        .map(Aabb::packed)
        .collect();
    // As many boxes as the sample stands for.
    let live = (sample.len() * stride).min(boxes.len());
    let chosen = plan::choose(LAYOUT_COST, &sample, live, 2);
    debug_assert!(chosen.along < 2 && DIRECTIONS == 4);
    banded::for_each_pair(boxes, chosen.along, &chosen.bands, &mut found);
}

/// Boxes the plan samples: fewer than the detector's, as the plan is
/// drawn for every call (and by [`BroadPhase`] every few hundred).
const BROAD_SAMPLE: usize = 2048;

/// The cost of laying one box out in one band, in units of one candidate
/// pair met, for the plan: a quarter of the detector's layout made anew,
/// since these bands are filled in one streaming pass and swept in `f64`
/// with two comparisons a candidate. Set where the plan's choices run
/// fastest on generated uniform and clustered boxes, clustered ones
/// gaining the most from the extra bands it buys (`versus_others`;
/// `docs/DESIGN.md`, "The broad phase on your own boxes").
const LAYOUT_COST: LayoutCost = LayoutCost {
    per_box: 4.0,
    per_guest: 0.0,
};

/// Every overlapping pair by testing all pairs: the oracle the sweep is
/// checked against, and as fast as anything for a few dozen boxes.
#[cfg(test)]
pub(crate) fn overlapping_pairs_brute(boxes: &[Aabb]) -> Vec<(u32, u32)> {
    let mut pairs = Vec::new();
    for (i, a) in boxes.iter().enumerate() {
        for (j, b) in boxes.iter().enumerate().skip(i + 1) {
            if a.overlaps(b) {
                pairs.push((i as u32, j as u32));
            }
        }
    }
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    pub(super) fn sorted(mut pairs: Vec<(u32, u32)>) -> Vec<(u32, u32)> {
        pairs.sort_unstable();
        pairs
    }

    pub(super) fn aabb(x: f64, y: f64, w: f64, h: f64) -> Aabb {
        Aabb {
            min: [x, y],
            max: [x + w, y + h],
        }
    }

    #[test]
    fn touching_nested_identical_and_nan() {
        let boxes = [
            aabb(0.0, 0.0, 1.0, 1.0),
            aabb(1.0, 1.0, 1.0, 1.0),   // touches 0 at a corner
            aabb(0.25, 0.25, 0.5, 0.5), // inside 0
            aabb(0.0, 0.0, 1.0, 1.0),   // same as 0
            aabb(f64::NAN, 0.0, 1.0, 1.0),
            aabb(0.5, 0.5, 0.0, 0.0), // a point inside 0
            aabb(3.0, 3.0, 0.0, 0.0),
            Aabb {
                min: [0.5, 0.5],
                max: [0.4, 0.6],
            }, // empty, inside 0
        ];
        let expected = vec![
            (0, 1),
            (0, 2),
            (0, 3),
            (0, 5),
            (1, 3),
            (2, 3),
            (2, 5),
            (3, 5),
        ];
        assert_eq!(sorted(overlapping_pairs(&boxes)), expected);
        assert_eq!(overlapping_pairs_brute(&boxes), expected);
        assert!(overlapping_pairs(&[]).is_empty());
    }

    #[test]
    fn values_closer_than_f32_resolves_are_told_apart() {
        // 1 and 1 + 2^-40 are one f32: only the exact test separates them.
        let gap = 1.0 + 2f64.powi(-40);
        let boxes = [
            aabb(0.0, 0.0, 1.0, 1.0),
            aabb(gap, 0.0, 1.0, 1.0),
            aabb(1.0, 0.0, 0.0, 1.0),
        ];
        assert_eq!(sorted(overlapping_pairs(&boxes)), vec![(0, 2)]);
    }

    #[test]
    fn many_small_boxes_agree_with_all_pairs() {
        // Enough to cut bands.
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let boxes: Vec<Aabb> = (0..20_000)
            .map(|_| {
                aabb(
                    rng.random(),
                    rng.random(),
                    0.006 * rng.random::<f64>(),
                    0.004,
                )
            })
            .collect();
        let found = sorted(overlapping_pairs(&boxes));
        assert!(found.len() > 1000, "{} pairs", found.len());
        assert_eq!(found, overlapping_pairs_brute(&boxes));
    }

    #[test]
    fn a_call_from_within_the_callback_gets_buffers_of_its_own() {
        let boxes: Vec<Aabb> = (0..500)
            .map(|i| aabb(f64::from(i % 25), f64::from(i / 25), 1.5, 1.5))
            .collect();
        let expected = overlapping_pairs_brute(&boxes);
        let mut outer = Vec::new();
        for_each_overlapping_pair(&boxes, |a, b| {
            outer.push((a, b));
            if outer.len() == 1 {
                assert_eq!(sorted(overlapping_pairs(&boxes)), expected);
            }
        });
        assert_eq!(sorted(outer), expected);
        // And the buffers left behind serve the next call.
        assert_eq!(sorted(overlapping_pairs(&boxes)), expected);
    }

    /// Coordinates of every awkward kind.
    fn coord() -> impl Strategy<Value = f64> {
        prop_oneof![
            4 => -10.0f64..10.0,
            2 => prop::sample::select(vec![0.0, -0.0, 1.0, 0.5, 2.0]),
            1 => prop::sample::select(vec![1e300, -1e300, 1e39, -1e39, 1e-300, -1e-300, f64::INFINITY, f64::NEG_INFINITY, f64::NAN]),
            1 => (-1.0f64..1.0).prop_map(|v| v * 1e-20),
        ]
    }

    pub(super) fn any_box() -> impl Strategy<Value = Aabb> {
        prop_oneof![
            // Possibly inverted, possibly wild.
            (coord(), coord(), coord(), coord()).prop_map(|(a, b, c, d)| Aabb {
                min: [a, b],
                max: [c, d]
            }),
            // Ordinary boxes, some of zero size.
            (
                -10.0f64..10.0,
                -10.0f64..10.0,
                prop::sample::select(vec![0.0, 0.1, 1.0, 5.0]),
                prop::sample::select(vec![0.0, 0.1, 1.0])
            )
                .prop_map(|(x, y, w, h)| aabb(x, y, w, h)),
        ]
    }

    proptest! {
        #[test]
        fn the_sweep_finds_exactly_the_all_pairs_overlaps(
            boxes in prop::collection::vec(any_box(), 0..80),
            copies in prop::collection::vec(any::<prop::sample::Index>(), 0..5),
        ) {
            let mut boxes = boxes;
            if !boxes.is_empty() {
                for c in copies {
                    boxes.push(boxes[c.index(boxes.len())]);
                }
            }
            let mut each = Vec::new();
            for_each_overlapping_pair(&boxes, |a, b| each.push((a, b)));
            prop_assert_eq!(sorted(each), overlapping_pairs_brute(&boxes));
        }
    }
}
