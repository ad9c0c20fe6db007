//! What a mend searches: the widened boxes as the last sweep laid them
//! out ([`super::near`]).
//!
//! The sweep leaves the widened boxes sorted by key, one run a band (one
//! run in all with one band). Each run is bounded by a box that holds all
//! of its boxes and by its longest extent along the sweep, so a mended box
//! meets only the runs its widened box reaches and, in each, the boxes
//! whose keys lie within its reach (a binary search finds the first),
//! rather than every box: on `koch` a few dozen boxes a mend instead of
//! 3,900. A box mended since the sweep has a new widened box; its old one
//! in the runs is skipped, and the boxes mended since are compared as
//! they are.

use super::boxes::BoxSlice;
use super::hull::{hi, overlaps, Packed, NO_KEY};
use super::scan;
use crate::index::Slot;
use multiversion::multiversion;
use std::ops::Range;

/// Appends to `runs` the runs of `laid` sorted along `along`: each
/// stretch of ascending keys (the boxes without a key come last and meet
/// nothing), its bound and its longest extent, each found by a loop of its
/// own over the run, which the AVX2 clone makes eight lanes at once.
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2"), dispatcher = "static")
)]
fn find_runs(laid: BoxSlice, along: usize, runs: &mut Vec<Run>) {
    let keys = laid.keys;
    let mut start = 0;
    while start < keys.len() && keys[start] != NO_KEY {
        // A run ends where the keys fall, or reach the boxes without one.
        let ends = |w: &[f32]| w[1] < w[0] || w[1] == NO_KEY;
        let rest = keys[start..].windows(2).position(ends);
        let stop = rest.map_or(keys.len(), |k| start + k + 1);
        let hulls = &laid.hulls[start..stop];
        let mut bound = [f32::INFINITY; 8];
        for hull in hulls {
            for (b, &h) in bound.iter_mut().zip(hull) {
                *b = if h < *b { h } else { *b };
            }
        }
        let mut longest = 0.0f32;
        for (hull, &key) in hulls.iter().zip(&keys[start..stop]) {
            let extent = hi(hull, along) - key;
            longest = if extent > longest { extent } else { longest };
        }
        // The extents were rounded to `f32`: the longest, rounded up.
        runs.push(Run {
            boxes: start..stop,
            bound,
            longest: longest.next_up(),
        });
        start = stop;
    }
}

/// A run of laid-out boxes sorted by key.
#[derive(Clone, Debug)]
struct Run {
    /// Where its boxes lie among the laid-out boxes.
    boxes: Range<usize>,
    /// The box holding all of them (each lane the least of theirs).
    bound: Packed,
    /// At least the greatest extent of any of them along the sweep.
    longest: f32,
}

/// The runs of the last sweep's widened boxes, and the boxes mended since
/// ([module docs](self)).
#[derive(Debug, Default)]
pub(crate) struct MendIndex {
    runs: Vec<Run>,
    /// The direction the boxes are sorted along.
    along: usize,
    /// Whether `runs` are of the boxes laid out now.
    built: bool,
    /// The slots widened anew since the sweep, and a mark for each slot.
    remade: Vec<Slot>,
    marked: Vec<bool>,
}

impl MendIndex {
    /// Forgets the runs and the boxes mended: a sweep laid the boxes out
    /// anew.
    pub(crate) fn forget(&mut self) {
        self.built = false;
        for &Slot(s) in &self.remade {
            self.marked[s as usize] = false;
        }
        self.remade.clear();
    }

    /// Finds the runs of `laid`, the widened boxes as the last sweep laid
    /// them out, sorted along `along`, unless found already.
    pub(crate) fn build(&mut self, laid: BoxSlice, along: usize) {
        self.marked.resize(laid.len(), false);
        if self.built {
            return;
        }
        (self.built, self.along) = (true, along);
        self.runs.clear();
        find_runs(laid, along, &mut self.runs);
    }

    /// Marks slot `s` widened anew: its box in the runs is stale.
    pub(crate) fn remake(&mut self, s: Slot) {
        let mark = &mut self.marked[s.0 as usize];
        if !*mark {
            *mark = true;
            self.remade.push(s);
        }
    }

    /// Into `met`, in ascending order, the slots whose widened box (in
    /// `wide`, by slot) overlaps the box whose reach is `reach`, as
    /// comparing it with every widened box finds them: the runs' boxes
    /// within reach, those widened anew since compared as they are now.
    pub(crate) fn meeting(
        &self,
        laid: BoxSlice,
        wide: &[Packed],
        reach: &Packed,
        (met, found): (&mut Vec<u32>, &mut Vec<u32>),
    ) {
        debug_assert!(self.built, "the runs of the boxes laid out");
        met.clear();
        let along = self.along;
        // A box meets the reach's extent along the sweep from its least
        // value to its greatest; keys are the least values.
        let (least, most) = (-reach[along + 4], reach[along]);
        for run in &self.runs {
            if !overlaps(&run.bound, reach) {
                continue;
            }
            // The keys of boxes that reach `least`: from `least` less the
            // longest extent, rounded down (NaN, for extents without end,
            // takes the run from its start), to `most`.
            let from = (least - run.longest).next_down();
            let keys = &laid.keys[run.boxes.clone()];
            let first = keys.partition_point(|&k| k < from);
            let end = first + keys[first..].partition_point(|&k| k <= most);
            let start = run.boxes.start + first;
            scan::meeting(&laid.hulls[start..run.boxes.start + end], reach, found);
            let slots = found.iter().map(|&j| laid.slots[start + j as usize].0);
            met.extend(slots.filter(|&s| !self.marked[s as usize]));
        }
        for &Slot(s) in &self.remade {
            if overlaps(&wide[s as usize], reach) {
                met.push(s);
            }
        }
        met.sort_unstable();
    }

    /// The lines are stored anew: the slot of the line that was in slot
    /// `s` is `new_slot[s]`. (The laid-out boxes are renamed alike.)
    pub(crate) fn reorder(&mut self, new_slot: &[Slot]) {
        for s in &mut self.remade {
            self.marked[s.0 as usize] = false;
            *s = new_slot[s.0 as usize];
        }
        for &Slot(s) in &self.remade {
            self.marked[s as usize] = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::sweep::hull::reach;
    use proptest::prelude::*;

    /// A packed box from its least and greatest values along `x` and `y`
    /// (the diagonals unused).
    fn packed(x: (f32, f32), y: (f32, f32)) -> Packed {
        let none = f32::NEG_INFINITY;
        [x.0, y.0, none, none, -x.1, -y.1, none, none]
    }

    fn a_box() -> impl Strategy<Value = Packed> {
        let span = || (0.0f32..1.0, 0.0f32..0.3).prop_map(|(a, w)| (a, a + w));
        (span(), span()).prop_map(|(x, y)| packed(x, y))
    }

    proptest! {
        /// Laid out in runs sorted by key (as bands are), with some boxes
        /// widened anew since and some without a key, every box meets
        /// what comparing it with every widened box meets.
        #[test]
        fn a_mend_meets_what_every_box_meets(
            boxes in proptest::collection::vec(a_box(), 1..120),
            runs in 1usize..5,
            keyless in 0usize..4,
            remade in proptest::collection::vec((any::<proptest::sample::Index>(), a_box()), 0..6),
        ) {
            let n = boxes.len();
            // Slots in runs: each run's boxes sorted by least x.
            let mut order: Vec<usize> = (0..n).collect();
            order.sort_by_key(|&s| (s % runs, boxes[s][0].to_bits()));
            let keyless = keyless.min(n);
            let (mut keys, mut hulls, mut slots) = (vec![], vec![], vec![]);
            for &s in &order[..n - keyless] {
                keys.push(boxes[s][0]);
                hulls.push(boxes[s]);
                slots.push(Slot(s as u32));
            }
            let mut wide = boxes.clone();
            for &s in &order[n - keyless..] {
                keys.push(NO_KEY);
                hulls.push([f32::INFINITY; 8]);
                slots.push(Slot(s as u32));
                wide[s] = [f32::INFINITY; 8];
            }
            let laid = BoxSlice::new(&keys, &hulls, &slots);
            let mut index = MendIndex::default();
            index.build(laid, 0);
            for (at, anew) in &remade {
                let s = at.index(n);
                wide[s] = *anew;
                index.remake(Slot(s as u32));
            }
            let (mut met, mut found) = (vec![], vec![]);
            for w in &wide {
                index.meeting(laid, &wide, &reach(w), (&mut met, &mut found));
                let all: Vec<u32> = (0..n as u32)
                    .filter(|&j| overlaps(&wide[j as usize], &reach(w)))
                    .collect();
                prop_assert_eq!(&met, &all);
            }
        }
    }

    #[test]
    fn the_mended_boxes_follow_the_lines_stored_anew() {
        let mut index = MendIndex::default();
        let (keys, hulls) = ([0.0; 3], [[0.0; 8]; 3]);
        let slots = [Slot(0), Slot(1), Slot(2)];
        index.build(BoxSlice::new(&keys, &hulls, &slots), 0);
        index.remake(Slot(0));
        index.remake(Slot(0));
        assert_eq!(index.remade, [Slot(0)]);
        index.reorder(&[Slot(2), Slot(0), Slot(1)]);
        assert_eq!(index.remade, [Slot(2)]);
        assert_eq!(index.marked, [false, false, true]);
        index.forget();
        assert!(index.remade.is_empty() && !index.marked.contains(&true));
    }
}
