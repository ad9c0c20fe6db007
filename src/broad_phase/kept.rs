//! [`BroadPhase`]: the world's sweep (its boxes, plan, layout and scan)
//! run on boxes of your own, keeping its order from one call to the next.

use super::{Aabb, BROAD_SAMPLE};
use crate::detect::sweep::boxes::Boxes;
use crate::detect::sweep::hull::{lo, NO_KEY};
use crate::detect::sweep::layout::{GroupView, Layout};
use crate::detect::sweep::plan::{self, Plan};
use crate::detect::sweep::scan;
use crate::detect::sweep::tuning::{DENSE, LAYOUT_COST, PLAN_EVERY};
use crate::index::Slot;
use crate::team::Team;
use std::sync::Mutex;

/// Finds every pair of overlapping boxes, call after call, keeping what
/// the last call learnt: the order the boxes were swept in, their layout
/// in bands and the plan. Boxes that moved a little since the last call
/// are put back in order by a few moves rather than sorted anew, as the
/// world's own sweep does from step to step. Any boxes may be given; the
/// order kept only makes the next call quicker when they are the same
/// boxes, in the same places of the slice, moved a little. That pays up
/// to some tens of thousands of boxes (at 10^4, 1.6 to 1.7 times as
/// fast as [`for_each_overlapping_pair`](super::for_each_overlapping_pair));
/// from about 10^5 the one-shot call is as fast or faster, its bands
/// holding copies of the boxes where this form reads the caller's boxes
/// in the sweep's order (`docs/PERFORMANCE.md`).
///
/// ```
/// use screensaver::broad_phase::{Aabb, BroadPhase};
///
/// let square = |x: f64| Aabb { min: [x, 0.0], max: [x + 1.0, 1.0] };
/// // Ten squares in a row, a square's width apart.
/// let mut boxes: Vec<Aabb> = (0..10).map(|i| square(2.0 * f64::from(i))).collect();
/// let mut broad = BroadPhase::new();
/// let mut pairs = Vec::new();
/// broad.for_each_pair(&boxes, |a, b| pairs.push((a, b)));
/// assert!(pairs.is_empty());
///
/// // Every other square moves left until it touches its neighbour.
/// for b in boxes.iter_mut().skip(1).step_by(2) {
///     *b = square(b.min[0] - 1.0);
/// }
/// broad.for_each_pair(&boxes, |a, b| pairs.push((a, b)));
/// pairs.sort();
/// assert_eq!(pairs, [(0, 1), (2, 3), (4, 5), (6, 7), (8, 9)]);
/// ```
#[derive(Debug, Default)]
pub struct BroadPhase {
    /// The boxes in last call's order (band by band where there are
    /// bands), each with its place in the caller's slice, then a sentinel.
    boxes: Boxes,
    layout: Layout,
    plan: Plan,
    /// Calls until the next plan.
    until_plan: u64,
    /// Whether last call met many candidates a box ([`DENSE`]).
    dense: bool,
    /// The pairs of places swept, and where there are bands, the pairs of
    /// slots their groups found.
    pairs: Vec<(u32, u32)>,
    banded: Vec<(Slot, Slot)>,
    /// Where each of the caller's boxes stands in `boxes`.
    places: Vec<u32>,
    /// A team of one: this thread alone.
    team: Team,
}

impl BroadPhase {
    /// A broad phase that has seen no boxes yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Calls `found(a, b)` for every pair of `boxes` that overlap
    /// ([`Aabb::overlaps`]), once each, the lower index first, in no
    /// particular order.
    ///
    /// # Panics
    /// If there are `u32::MAX` boxes or more.
    pub fn for_each_pair(&mut self, boxes: &[Aabb], mut found: impl FnMut(u32, u32)) {
        let n = boxes.len();
        assert!(
            u32::try_from(n).is_ok_and(|n| n < u32::MAX),
            "too many boxes for u32 indices"
        );
        if self.boxes.slots.len() != n + 1 {
            self.forget();
            self.boxes.reset(n);
            self.places.clear();
            self.places.extend(0..n as u32);
        }
        self.make_boxes(boxes);
        if self.until_plan == 0 {
            self.make_plan();
        }
        self.until_plan -= 1;
        let mut report = |a: Slot, b: Slot| {
            let (a, b) = (a.0.min(b.0), a.0.max(b.0));
            if boxes[a as usize].overlaps(&boxes[b as usize]) {
                found(a, b);
            }
        };
        let (along, dense) = (self.plan.along, self.dense);
        let (candidates, swept) = if self.plan.bands.count > 1 {
            let (pairs, banded) = (&mut self.pairs, &mut self.banded);
            banded.clear();
            let met = Mutex::new((0, pairs, banded));
            let sweep_each = |group: GroupView| {
                let (met, pairs, banded) = &mut *met.lock().expect("one member");
                *met += scan::sweep_group(&group, (along, dense), pairs, |p, first, second| {
                    banded.extend(
                        p.iter()
                            .map(|&(i, j)| (first[i as usize], second[j as usize])),
                    )
                });
            };
            let bands = self.plan.bands;
            let boxed = (self.layout).lay_out(&mut self.boxes, n, &bands, &self.team, &sweep_each);
            let (met, ..) = met.into_inner().expect("one member");
            self.banded.iter().for_each(|&(a, b)| report(a, b));
            (met, boxed + self.layout.guest_count())
        } else {
            self.layout.forget();
            let boxed = self.boxes.sort(&self.team);
            self.pairs.clear();
            let (keys, hulls, slots) = (&self.boxes.keys, &self.boxes.hulls, &self.boxes.slots);
            let met = scan::sweep(keys, hulls, 0..boxed, along, dense, &mut self.pairs);
            for &(i, j) in &self.pairs {
                report(slots[i as usize], slots[j as usize]);
            }
            (met, boxed)
        };
        self.dense = candidates as f64 > DENSE * swept as f64;
        for (k, slot) in self.boxes.slots[..n].iter().enumerate() {
            self.places[slot.0 as usize] = k as u32;
        }
    }

    /// Forgets the order, layout and plan: the next call's boxes are not
    /// last call's moved a little.
    fn forget(&mut self) {
        self.layout.forget();
        self.until_plan = 0;
        self.dense = false;
    }

    /// Each box packed, in last call's order, with its key along the
    /// plan's direction ([`NO_KEY`] for an empty box): the caller's boxes
    /// read in their order and written to their places in the sweep's.
    fn make_boxes(&mut self, boxes: &[Aabb]) {
        let along = self.plan.along;
        let b = &mut self.boxes;
        for (aabb, &at) in boxes.iter().zip(&self.places) {
            let (at, hull) = (at as usize, aabb.packed());
            b.hulls[at] = hull;
            b.keys[at] = match aabb.is_empty() {
                true => NO_KEY,
                false => lo(&hull, along),
            };
        }
    }

    /// A plan for the boxes, from an even sample of them, along `x` or
    /// `y` (the diagonals are unbounded), their keys along its direction.
    fn make_plan(&mut self) {
        let (n, from) = (self.boxes.len(), (BROAD_SAMPLE, 2));
        self.plan = plan::replan(&mut self.boxes, n, from, LAYOUT_COST, self.plan.along);
        self.until_plan = PLAN_EVERY;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::broad_phase::overlapping_pairs_brute;
    use crate::broad_phase::tests::{aabb, any_box, sorted};
    use proptest::prelude::*;
    use rand::{Rng, SeedableRng};

    fn pairs(broad: &mut BroadPhase, boxes: &[Aabb]) -> Vec<(u32, u32)> {
        let mut found = Vec::new();
        broad.for_each_pair(boxes, |a, b| found.push((a, b)));
        sorted(found)
    }

    /// Each box moved by up to `step` (at random, from `rng`).
    fn moved(boxes: &[Aabb], step: f64, rng: &mut impl Rng) -> Vec<Aabb> {
        let mut shift = || step * (rng.random::<f64>() - 0.5);
        let moved = |b: &Aabb| {
            let (dx, dy) = (shift(), shift());
            aabb(
                b.min[0] + dx,
                b.min[1] + dy,
                b.max[0] - b.min[0],
                b.max[1] - b.min[1],
            )
        };
        boxes.iter().map(moved).collect()
    }

    #[test]
    fn is_send_and_sync() {
        fn holds<T: Send + Sync>() {}
        holds::<BroadPhase>();
    }

    #[test]
    fn boxes_moving_through_kept_bands_agree_with_all_pairs() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
        let mut boxes: Vec<Aabb> = (0..8_000)
            .map(|_| {
                aabb(
                    rng.random(),
                    rng.random(),
                    0.01 * rng.random::<f64>(),
                    0.008,
                )
            })
            .collect();
        let mut broad = BroadPhase::new();
        for call in 0..6 {
            let expected = overlapping_pairs_brute(&boxes);
            assert!(expected.len() > 1000, "{} pairs", expected.len());
            assert_eq!(pairs(&mut broad, &boxes), expected, "call {call}");
            // Laid out in bands, and from the second call on, the layout
            // kept and updated rather than made anew.
            assert!(broad.plan.bands.count > 1, "{:?}", broad.plan);
            assert!(broad.layout.keeps(&broad.plan.bands, boxes.len()));
            boxes = moved(&boxes, 0.02, &mut rng);
        }
    }

    #[test]
    fn a_row_kept_in_one_band_agrees_with_all_pairs() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(12);
        let mut boxes: Vec<Aabb> = (0..3_000)
            .map(|i| aabb(0.5 * f64::from(i), 0.0, 1.0, 1.0))
            .collect();
        let mut broad = BroadPhase::new();
        for call in 0..5 {
            assert_eq!(
                pairs(&mut broad, &boxes),
                overlapping_pairs_brute(&boxes),
                "call {call}"
            );
            assert_eq!(broad.plan.bands.count, 1);
            boxes = moved(&boxes, 1.0, &mut rng);
        }
    }

    proptest! {
        /// Calls on boxes of every awkward kind, moved a little, some
        /// replaced, and now and then more or fewer of them.
        #[test]
        fn every_call_finds_exactly_the_all_pairs_overlaps(
            first in prop::collection::vec(any_box(), 0..120),
            calls in prop::collection::vec(
                (0.0f64..2.0, prop::collection::vec((any::<prop::sample::Index>(), any_box()), 0..6), 0usize..8),
                1..6,
            ),
            seed in any::<u64>(),
        ) {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let mut broad = BroadPhase::new();
            let mut boxes = first;
            prop_assert_eq!(pairs(&mut broad, &boxes), overlapping_pairs_brute(&boxes));
            for (step, replaced, resized) in calls {
                boxes = moved(&boxes, step, &mut rng);
                if !boxes.is_empty() {
                    for (at, b) in replaced {
                        let at = at.index(boxes.len());
                        boxes[at] = b;
                    }
                }
                // One call in eight on a few boxes more or fewer.
                match resized {
                    0 => boxes.truncate(boxes.len() / 2),
                    1 => boxes.extend_from_within(..boxes.len() / 3),
                    _ => {}
                }
                prop_assert_eq!(pairs(&mut broad, &boxes), overlapping_pairs_brute(&boxes));
            }
        }
    }
}
