//! The sweep itself: every box meets the boxes after it whose least value
//! along the sweep direction lies within its own extent; of those, the
//! ones its packed hull overlaps are reported.

use super::boxes::BoxSlice;
use super::hull::{hi, overlaps, reach, Packed};
use super::layout::GroupView;
use super::Stored;
use crate::detect::swept::{test_ordered, PairCounts};
use crate::line::{read_ahead, LARGE_SCENE, READ_AHEAD};
use crate::narrow::Event;
use multiversion::multiversion;

/// The exact test of the pairs a sweep finds, appending to `events` and
/// counting in `counts`.
pub(crate) struct Tester<'a> {
    pub lines: Stored<'a>,
    pub dt: f64,
    pub events: &'a mut Vec<Event>,
    pub counts: &'a mut PairCounts,
}

impl Tester<'_> {
    /// Tests the noted `pairs` of places, the first of each pair's slot
    /// from `first`, the second's from `second`. In scenes larger than the
    /// cache, each pair's lines are read a few pairs ahead of its test, so
    /// that their loads wait on memory together (docs/DESIGN.md, "Reading
    /// ahead").
    #[inline(always)]
    pub(crate) fn test(&mut self, pairs: &[(u32, u32)], first: &[u32], second: &[u32]) {
        let slots = |&(i, j): &(u32, u32)| (first[i as usize], second[j as usize]);
        if self.lines.lines.len() < LARGE_SCENE {
            return pairs
                .iter()
                .map(slots)
                .for_each(|(a, b)| self.test_pair(a, b));
        }
        for (k, pair) in pairs.iter().enumerate() {
            if let Some((a, b)) = pairs.get(k + READ_AHEAD).map(slots) {
                read_ahead(&self.lines.lines[a as usize]);
                read_ahead(&self.lines.lines[b as usize]);
            }
            let (a, b) = slots(pair);
            self.test_pair(a, b);
        }
    }

    #[inline(always)]
    fn test_pair(&mut self, a: u32, b: u32) {
        let stored = self.lines;
        let swap = stored.id(a) >= stored.id(b);
        let (a, b) = if swap { (b, a) } else { (a, b) };
        let (line_a, line_b) = (&stored.lines[a as usize], &stored.lines[b as usize]);
        test_ordered(line_a, line_b, (a, b), self.dt, self.events, self.counts);
    }
}

/// Sweeps the bands of one group as its member laid it out
/// ([`GroupView`]): each band's homes among themselves and against its
/// guests. Tests every pair whose hulls overlap with `test`, once each,
/// through `pairs`. Returns the candidates met.
pub(crate) fn sweep_group(
    group: &GroupView,
    along: usize,
    dense: bool,
    pairs: &mut Vec<(u32, u32)>,
    test: &mut Tester,
) -> u64 {
    let mut candidates = 0;
    for band in group.bands() {
        let (all, homes, guests) = (group.boxes, group.homes(band), group.guests(band));
        let (keys, hulls) = (&all.keys[..homes.end], &all.hulls[..homes.end]);
        pairs.clear();
        candidates += sweep(keys, hulls, homes.clone(), along, dense, pairs);
        test.test(pairs, all.slots, all.slots);
        if guests.len() > 0 {
            pairs.clear();
            let homes = all.at(homes);
            candidates += sweep_across(homes, guests, along, pairs);
            test.test(pairs, homes.slots, guests.slots);
        }
    }
    candidates
}

/// Sweeps a band's homes against its guests (keys and hulls, each sorted
/// by key) along direction `along`: each home meets the guests whose key
/// lies within its extent from its own key on, and each guest the homes
/// whose key lies within its extent beyond its own key (so a pair with
/// equal keys is met once). Appends to `found` every pair `(i, j)`, `i` a
/// home and `j` a guest, whose hulls overlap. Returns the pairs met.
///
/// The two sorted lists are walked together, each box scanning the other
/// list from where the walk stands, so the work is the boxes of both and
/// the pairs met. A binary search a guest within the band's longest
/// extent would not bound it so: a long line makes every guest's window
/// wide (docs/DESIGN.md, "Tried and dropped").
fn sweep_across(
    homes: BoxSlice,
    guests: BoxSlice,
    along: usize,
    found: &mut Vec<(u32, u32)>,
) -> u64 {
    let (mut candidates, mut i) = (0, 0);
    for (j, (&guest_key, guest_hull)) in guests.keys.iter().zip(guests.hulls).enumerate() {
        // The homes whose key is at most this guest's: those that reach
        // it meet the guests from it on within their extent.
        while i < homes.len() && homes.keys[i] <= guest_key {
            let end = hi(&homes.hulls[i], along).min(f32::MAX);
            if guest_key <= end {
                let (home, reach_h) = (i as u32, reach(&homes.hulls[i]));
                let guest_boxes = (guests.keys, guests.hulls);
                let met = meet(guest_boxes, j, end, &reach_h, |g| found.push((home, g)));
                candidates += (met - j) as u64;
            }
            i += 1;
        }
        // The guest meets the homes beyond its key within its extent.
        let (end, reach_j) = (hi(guest_hull, along).min(f32::MAX), reach(guest_hull));
        let met = meet((homes.keys, homes.hulls), i, end, &reach_j, |h| {
            found.push((h, j as u32))
        });
        candidates += (met - i) as u64;
    }
    candidates
}

/// Meets the boxes from `from` on (keys and hulls, sorted by key) whose
/// key is at most `end`, one at a time, calling `hit` with each one whose
/// hull overlaps the box whose reach is `reach`; returns the first box
/// past them.
#[inline(always)]
fn meet(
    (keys, hulls): (&[f32], &[Packed]),
    from: usize,
    end: f32,
    reach: &Packed,
    mut hit: impl FnMut(u32),
) -> usize {
    let mut j = from;
    while keys.get(j).is_some_and(|&k| k <= end) {
        if overlaps(&hulls[j], reach) {
            hit(j as u32);
        }
        j += 1;
    }
    j
}

/// Sweeps the boxes `range` of sorted `keys` and `hulls`, each against the
/// boxes after it up to the first whose key lies beyond its extent along
/// direction `along` (a sentinel after the last box, or the end of the
/// arrays), and appends to `found` every pair `(i, j)` whose hulls overlap.
/// Returns the pairs met (the candidates).
///
/// Compiled for the baseline and for AVX2, chosen when the program
/// starts. The baseline takes one candidate at a time; with AVX2 a box
/// with two candidates or more takes them eight at a time
/// ([`blocks::sweep_box`]), which on `koch` and `mit` cuts the sweep by a
/// sixth, and the rest one at a time; in a `dense` scene every box takes
/// them eight at a time (see `DENSE` in the parent module).
#[cfg_attr(
    not(screensaver_baseline),
    multiversion(targets("x86_64+avx2+popcnt+bmi1"))
)]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2+popcnt+bmi1"), dispatcher = "static")
)]
pub(crate) fn sweep(
    keys: &[f32],
    hulls: &[Packed],
    range: std::ops::Range<usize>,
    along: usize,
    dense: bool,
    found: &mut Vec<(u32, u32)>,
) -> u64 {
    let mut candidates = 0;
    let from = multiversion::target::match_target! {
        "x86_64+avx2+popcnt+bmi1" => {
            // In a dense scene every box with a whole block after it takes
            // one, with no branch on how many candidates it has.
            let whole = range.end.min(keys.len().saturating_sub(8));
            let mut i = range.start;
            while dense && i < whole {
                let hull = &hulls[i];
                let end = hi(hull, along).min(f32::MAX);
                let reach = reach(hull);
                let start = blocks::sweep_box(keys, hulls, i, i + 1, end, &reach, found, &mut candidates);
                let met = meet((keys, hulls), start, end, &reach, |j| found.push((i as u32, j)));
                candidates += (met - start) as u64;
                i += 1;
            }
            i
        }
        _ => {
            let _ = dense;
            range.start
        }
    };
    for i in from..range.end {
        let hull = &hulls[i];
        // Keys are at most f32::MAX, so a box reaching to +inf still
        // stops at the sentinel.
        let end = hi(hull, along).min(f32::MAX);
        if keys.get(i + 1).is_none_or(|&k| k > end) {
            // Most boxes of sparse scenes: nothing within the extent (keys
            // are never NaN).
            continue;
        }
        let reach = reach(hull);
        let j = multiversion::target::match_target! {
            "x86_64+avx2+popcnt+bmi1" => {
                // A box with a single candidate is quicker one at a time.
                if keys.get(i + 2).is_some_and(|&k| k <= end) {
                    blocks::sweep_box(keys, hulls, i, i + 1, end, &reach, found, &mut candidates)
                } else {
                    i + 1
                }
            }
            _ => { i + 1 }
        };
        let met = meet((keys, hulls), j, end, &reach, |j| found.push((i as u32, j)));
        candidates += (met - j) as u64;
    }
    candidates
}

/// The sweep of one box eight boxes at a time, with AVX2.
#[cfg(target_arch = "x86_64")]
mod blocks {
    use super::Packed;
    use std::arch::x86_64::{
        __m256, __m256i, _mm256_castps_si256, _mm256_castsi256_ps, _mm256_cmp_ps,
        _mm256_cmpeq_epi32, _mm256_movemask_ps, _mm256_or_si256, _mm256_packs_epi16,
        _mm256_packs_epi32, _mm256_permute2x128_si256, _mm256_set1_ps, _mm256_setzero_si256,
        _CMP_LE_OQ, _CMP_NLE_UQ,
    };

    /// Boxes compared at a time.
    const BLOCK: usize = 8;

    /// Sweeps box `i` against the boxes from `j` on, eight at a time: all
    /// eight keys are compared with `end` in one instruction and all eight
    /// hulls with `reach`, and only the run of boxes from the first whose
    /// keys lie within the extent counts (past a band's sentinel the next
    /// band's keys start low again). The scan then ends with one branch
    /// that no predictor foresees per box, after one block for most boxes,
    /// instead of a branch per candidate. Returns the box to go on from
    /// one at a time: the end of the scan, or a box too near the end of
    /// the arrays for a whole block.
    #[inline]
    #[target_feature(enable = "avx2")]
    #[allow(clippy::too_many_arguments)]
    pub(super) fn sweep_box(
        keys: &[f32],
        hulls: &[Packed],
        i: usize,
        mut j: usize,
        end: f32,
        reach: &Packed,
        found: &mut Vec<(u32, u32)>,
        candidates: &mut u64,
    ) -> usize {
        let end8 = _mm256_set1_ps(end);
        let reach8: __m256 = bytemuck::cast(*reach);
        while let (Some(k8), Some(h8)) = (keys.get(j..j + BLOCK), hulls.get(j..j + BLOCK)) {
            let k8: [f32; BLOCK] = k8.try_into().expect("a block of keys");
            let k8: __m256 = bytemuck::cast(k8);
            let within = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(k8, end8)) as u32;
            // The run of ones from the lowest bit.
            let run = (!within & within.wrapping_add(1)).wrapping_sub(1);
            let h8: &[Packed; BLOCK] = h8.try_into().expect("a block of hulls");
            let overlapping = overlapping(h8, reach8);
            *candidates += u64::from(run.count_ones());
            let mut hits = overlapping & run;
            while hits != 0 {
                found.push((i as u32, (j + hits.trailing_zeros() as usize) as u32));
                hits &= hits - 1;
            }
            if run != (1 << BLOCK) - 1 {
                // Past the run: the box that ends the scan.
                return j + run.count_ones() as usize;
            }
            j += BLOCK;
        }
        j
    }

    /// Which of eight hulls overlap the box whose reach is `reach8`: bit
    /// `k` for `hulls[k]`. Each hull's lanes beyond reach (NaN too) come
    /// out of one comparison as all ones; packing them to bytes, two hulls
    /// at a time then four, and folding each hull's two halves together
    /// leaves four bytes a hull, which are all zero exactly when no lane
    /// is beyond. That is a few vector instructions for the whole block,
    /// rather than a mask, a test and a shift for each hull
    /// (docs/DESIGN.md, "Sweep and prune", the sweep).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn overlapping(hulls: &[Packed; BLOCK], reach8: __m256) -> u32 {
        let beyond = |k: usize| {
            let hull: __m256 = bytemuck::cast(hulls[k]);
            _mm256_castps_si256(_mm256_cmp_ps::<_CMP_NLE_UQ>(hull, reach8))
        };
        // Per 128-bit half, as 16-bit lanes: hull 2m's four lanes of that
        // half, then hull 2m + 1's.
        let pairs = [0, 2, 4, 6].map(|k| _mm256_packs_epi32(beyond(k), beyond(k + 1)));
        // As bytes: in the low half, lanes 0 to 3 of hulls 0..4 (a 32-bit
        // word each); in the high half, their lanes 4 to 7.
        let low: __m256i = _mm256_packs_epi16(pairs[0], pairs[1]);
        let high: __m256i = _mm256_packs_epi16(pairs[2], pairs[3]);
        // Word k: hull k's lanes 0 to 3, or'ed with word k of its lanes 4
        // to 7.
        let halves = _mm256_or_si256(
            _mm256_permute2x128_si256::<0x20>(low, high),
            _mm256_permute2x128_si256::<0x31>(low, high),
        );
        let within = _mm256_cmpeq_epi32(halves, _mm256_setzero_si256());
        _mm256_movemask_ps(_mm256_castsi256_ps(within)) as u32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// Sorted boxes swept dense (eight at a time) and sparse meet the
        /// same candidates and find every overlapping pair, each once, as
        /// the all-pairs loop does: with NaN in any lane but those along
        /// the sweep too.
        #[test]
        fn dense_and_sparse_sweeps_find_the_all_pairs_overlaps(
            boxes in proptest::collection::vec(
                (0.0f32..1.0, 0.0f32..0.2, 0.0f32..1.0, 0.0f32..0.2, 0usize..16),
                0..300,
            ),
            along in 0usize..2,
        ) {
            let n = f32::NEG_INFINITY;
            let mut hulls: Vec<Packed> = boxes
                .iter()
                .map(|&(x, w, y, h, nan)| {
                    let mut hull = [x, y, n, n, -(x + w), -(y + h), n, n];
                    if nan < 8 && nan % 4 != along {
                        hull[nan] = f32::NAN;
                    }
                    hull
                })
                .collect();
            hulls.sort_by(|a, b| a[along].total_cmp(&b[along]));
            let (found, met) = swept_sparse_and_dense(&hulls, along);
            proptest::prop_assert_eq!(met[0], met[1]);
            proptest::prop_assert_eq!(&found[0], &found[1]);
            proptest::prop_assert_eq!(&found[1], &all_overlapping(&hulls));
        }
    }

    /// The pairs `hulls` (sorted by key along `along`) swept sparse and
    /// dense find, each list sorted, and the candidates each met.
    fn swept_sparse_and_dense(hulls: &[Packed], along: usize) -> ([Vec<(u32, u32)>; 2], [u64; 2]) {
        let keys: Vec<f32> = hulls.iter().map(|h| h[along]).collect();
        let mut found = [Vec::new(), Vec::new()];
        let mut met = [0, 0];
        for dense in [false, true] {
            let out = &mut found[usize::from(dense)];
            met[usize::from(dense)] = sweep(&keys, hulls, 0..keys.len(), along, dense, out);
            out.sort_unstable();
        }
        (found, met)
    }

    /// Every pair of `hulls` that overlap, by the all-pairs loop.
    fn all_overlapping(hulls: &[Packed]) -> Vec<(u32, u32)> {
        let mut want = Vec::new();
        for i in 0..hulls.len() {
            for j in i + 1..hulls.len() {
                if overlaps(&hulls[j], &reach(&hulls[i])) {
                    want.push((i as u32, j as u32));
                }
            }
        }
        want
    }
}
