//! The sweep itself: every box meets the boxes after it whose least value
//! along the sweep direction lies within its own extent; of those, the
//! ones its packed hull overlaps are reported.

use super::boxes::BoxSlice;
use super::hull::{hi, overlaps, reach, Packed};
use super::layout::GroupView;
use crate::detect::sweep::tuning::DENSE_WITHOUT_AVX2;
use crate::detect::{Findings, Stored};
use crate::index::Slot;
#[cfg(target_arch = "x86_64")]
use crate::lanes::blocks;
use crate::lanes::blocks::BLOCK;
use crate::line::{read_ahead, Line, LARGE_SCENE, READ_AHEAD};
use crate::narrow::IntersectionKind;
use multiversion::multiversion;

/// Hands `found` the noted `pairs` of places to test, the first of each
/// pair's slot from `first`, the second's from `second`. In scenes larger
/// than the cache, each pair's lines are read a few pairs ahead of its
/// test, so that their loads wait on memory together (docs/DESIGN.md,
/// "Reading ahead"). Compiled for the baseline and for AVX2, chosen when
/// the program starts: with AVX2 the test's own lanes are called from
/// here (see [`Findings::test_with`]).
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2"), dispatcher = "static")
)]
pub(crate) fn test_pairs(
    found: &mut Findings,
    (stored, dt): (Stored, f64),
    pairs: &[(u32, u32)],
    first: &[Slot],
    second: &[Slot],
) {
    let slots = (first, second);
    multiversion::target::match_target! {
        "x86_64+avx2" => {
            let screen = |l1: &Line, l2: &Line, dt| crate::lanes::intersect::screen(l1, l2, dt);
            test_each(found, (stored, dt), pairs, slots, screen)
        }
        _ => test_each(found, (stored, dt), pairs, slots, crate::detect::pairs::screen),
    }
}

/// [`test_pairs`]'s loop, with the prefilter and exact test `screen`.
#[inline(always)]
fn test_each(
    found: &mut Findings,
    (stored, dt): (Stored, f64),
    pairs: &[(u32, u32)],
    (first, second): (&[Slot], &[Slot]),
    screen: impl Fn(&Line, &Line, f64) -> Option<Option<IntersectionKind>>,
) {
    let slots = |&(i, j): &(u32, u32)| (first[i as usize], second[j as usize]);
    if stored.lines.len() < LARGE_SCENE {
        for (a, b) in pairs.iter().map(slots) {
            found.test_with(stored, (a, b), dt, &screen);
        }
        return;
    }
    for (k, pair) in pairs.iter().enumerate() {
        if let Some((a, b)) = pairs.get(k + READ_AHEAD).map(slots) {
            read_ahead(stored.line(a));
            read_ahead(stored.line(b));
        }
        found.test_with(stored, slots(pair), dt, &screen);
    }
}

/// Sweeps the bands of one group as its member laid it out
/// ([`GroupView`]): each band's homes among themselves and against its
/// guests, the pairs of places noted in `pairs`, and hands every pair
/// whose hulls overlap, once each, to `hand_on(pairs, first, second)`,
/// the first of each pair's slot from `first`, the second's from
/// `second`. Returns the candidates met.
pub(crate) fn sweep_group(
    group: &GroupView,
    (along, dense): (usize, bool),
    pairs: &mut Vec<(u32, u32)>,
    mut hand_on: impl FnMut(&[(u32, u32)], &[Slot], &[Slot]),
) -> u64 {
    let mut met = 0;
    for band in group.bands() {
        let (all, homes, guests) = (group.boxes, group.homes(band), group.guests(band));
        let (keys, hulls) = (&all.keys[..homes.end], &all.hulls[..homes.end]);
        pairs.clear();
        met += sweep(keys, hulls, homes.clone(), along, dense, pairs);
        hand_on(pairs, all.slots, all.slots);
        if guests.len() > 0 {
            pairs.clear();
            let homes = all.at(homes);
            met += sweep_across(homes, guests, along, pairs);
            hand_on(pairs, homes.slots, guests.slots);
        }
    }
    met
}

/// Hands the world's pairs of places swept on, the first of each pair's
/// slot from `first`, the second's from `second`: to `found` to test
/// ([`test_pairs`]), or with `keep` to the pairs kept (`near`), as slots.
#[inline]
pub(crate) fn hand_on(
    (found, near): (&mut Findings, &mut Vec<(Slot, Slot)>),
    (keep, stored, dt): (bool, Stored, f64),
    pairs: &[(u32, u32)],
    (first, second): (&[Slot], &[Slot]),
) {
    let slots = |&(i, j): &(u32, u32)| (first[i as usize], second[j as usize]);
    match keep {
        true => near.extend(pairs.iter().map(slots)),
        false => test_pairs(found, (stored, dt), pairs, first, second),
    }
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
#[inline(always)]
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
/// starts; the scan is written once ([`sweep_with`]) over the masks of a
/// block of eight boxes, which AVX2 makes in a few instructions
/// ([`blocks`]), WebAssembly's SIMD in a few more, and the rest lane by
/// lane ([`masks`]).
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
    multiversion::target::match_target! {
        "x86_64+avx2+popcnt+bmi1" => {
            let masks = |end, reach: &Packed| {
                let (end8, reach8) = (blocks::splat(end), blocks::packed(reach));
                move |k8: &[f32; BLOCK], h8: &[Packed; BLOCK]| {
                    (blocks::within(k8, end8), blocks::overlapping(h8, reach8))
                }
            };
            let reaching = |k8: &[f32; BLOCK], h8: &[Packed; BLOCK]| blocks::reaching(k8, h8, along);
            let blocks = (masks, Some(reaching));
            sweep_with(keys, hulls, range, along, dense, found, blocks, true)
        }
        _ => {
            let blocks = (masks, reaching_without_avx2(along));
            sweep_with(keys, hulls, range, along, dense && DENSE_WITHOUT_AVX2, found, blocks, false)
        }
    }
}

/// The places in `hulls` of the hulls that overlap the box whose reach is
/// `reach`, into `met` in order: with AVX2 a block of eight at a time,
/// by the sweep's own masks.
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2"), dispatcher = "static")
)]
pub(crate) fn meeting(hulls: &[Packed], reach: &Packed, met: &mut Vec<u32>) {
    met.clear();
    let whole = hulls.len() / BLOCK * BLOCK;
    multiversion::target::match_target! {
        "x86_64+avx2" => {
            let reach8 = blocks::packed(reach);
            for (c, h8) in hulls[..whole].chunks_exact(BLOCK).enumerate() {
                let mut mask = blocks::overlapping(h8.try_into().expect("a block"), reach8);
                while mask != 0 {
                    met.push((c * BLOCK) as u32 + mask.trailing_zeros());
                    mask &= mask - 1;
                }
            }
        }
        _ => {
            for (j, h) in hulls[..whole].iter().enumerate() {
                if overlaps(h, reach) {
                    met.push(j as u32);
                }
            }
        }
    }
    for (j, h) in hulls.iter().enumerate().skip(whole) {
        if overlaps(h, reach) {
            met.push(j as u32);
        }
    }
}

/// Which of a block of boxes meet the key after them (see [`sweep_with`]).
#[cfg(any(test, not(all(target_arch = "wasm32", target_feature = "simd128"))))]
type Reaching = fn(&[f32; BLOCK], &[Packed; BLOCK]) -> u32;

/// [`sweep`], given `masks(end, reach)`, which makes a box's masks of a
/// block, `(keys, hulls)` to `(within, overlapping)`: bit `k` of the first
/// set where `keys[k] <= end`, of the second where `hulls[k]` overlaps the
/// box whose reach is `reach`. In a `dense` scene (see
/// `DENSE` in the parent module) every box meets its candidates a block at
/// a time, with no branch on how many it has; otherwise a box does so from
/// two candidates on if `blocks_from_two`, and one at a time below.
///
/// Most boxes of a sparse scene meet nothing, not even the key after
/// them. With `reaching(next_keys, hulls)`, whose bit `k` is set where
/// `next_keys[k]`, the key after box `k` of the block `hulls`, lies
/// within that box's extent, those boxes are passed over a block at a
/// time rather than one at a time.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn sweep_with<M: Fn(&[f32; BLOCK], &[Packed; BLOCK]) -> (u32, u32)>(
    keys: &[f32],
    hulls: &[Packed],
    range: std::ops::Range<usize>,
    along: usize,
    dense: bool,
    found: &mut Vec<(u32, u32)>,
    (masks, reaching): (
        impl Fn(f32, &Packed) -> M,
        Option<impl Fn(&[f32; BLOCK], &[Packed; BLOCK]) -> u32>,
    ),
    blocks_from_two: bool,
) -> u64 {
    let mut candidates = 0;
    // In a dense scene every box with a whole block after it takes one.
    let whole = range.end.min(keys.len().saturating_sub(BLOCK));
    let mut i = range.start;
    while dense && i < whole {
        let hull = &hulls[i];
        let end = hi(hull, along).min(f32::MAX);
        let reach = reach(hull);
        let block = masks(end, &reach);
        let start = sweep_box((keys, hulls), i, i + 1, found, &block);
        let met = meet((keys, hulls), start, end, &reach, |j| {
            found.push((i as u32, j))
        });
        // The boxes met are those from the next on.
        candidates += (met - (i + 1)) as u64;
        i += 1;
    }
    let one = (&masks, blocks_from_two);
    // Keys are at most f32::MAX, so a box reaching to +inf still stops at
    // the sentinel.
    let end = |i: usize| hi(&hulls[i], along).min(f32::MAX);
    if let Some(reaching) = reaching {
        // Whole blocks whose keys after them are all in the arrays.
        let blocks = range
            .end
            .min(keys.len().saturating_sub(1))
            .saturating_sub(i)
            / BLOCK
            * BLOCK;
        let next_keys = keys.get(i + 1..).unwrap_or_default()[..blocks].chunks_exact(BLOCK);
        for (next, block) in next_keys.zip(hulls[i..][..blocks].chunks_exact(BLOCK)) {
            let next: &[f32; BLOCK] = next.try_into().expect("a block");
            let mut near = reaching(next, block.try_into().expect("a block"));
            while near != 0 {
                let k = i + near.trailing_zeros() as usize;
                candidates += sweep_one((keys, hulls), (k, end(k)), found, one);
                near &= near - 1;
            }
            i += BLOCK;
        }
    }
    for i in i..range.end {
        let end = end(i);
        // Most boxes of sparse scenes: nothing within the extent (keys are
        // never NaN).
        if keys.get(i + 1).is_some_and(|&k| k <= end) {
            candidates += sweep_one((keys, hulls), (i, end), found, one);
        }
    }
    candidates
}

/// Sweeps box `i`, whose extent ends at `end` and which meets the key
/// after it, as [`sweep_with`] does: a block at a time (by `masks`) from
/// two candidates on if `blocks_from_two`, else one at a time. Returns the
/// candidates it met.
#[inline(always)]
fn sweep_one<M: Fn(&[f32; BLOCK], &[Packed; BLOCK]) -> (u32, u32)>(
    (keys, hulls): (&[f32], &[Packed]),
    (i, end): (usize, f32),
    found: &mut Vec<(u32, u32)>,
    (masks, blocks_from_two): (&impl Fn(f32, &Packed) -> M, bool),
) -> u64 {
    let reach = reach(&hulls[i]);
    // A box with a single candidate is quicker one at a time.
    let j = match blocks_from_two && keys.get(i + 2).is_some_and(|&k| k <= end) {
        true => sweep_box((keys, hulls), i, i + 1, found, &masks(end, &reach)),
        false => i + 1,
    };
    let met = meet((keys, hulls), j, end, &reach, |j| found.push((i as u32, j)));
    // The boxes met are those from the next on.
    (met - (i + 1)) as u64
}

/// Sweeps box `i` against the boxes from `j` on, eight at a time: all
/// eight keys are compared with its end and all eight hulls with its reach
/// at once (`masks`, see [`sweep_with`]), and only the run of boxes from the
/// first whose keys lie within the extent counts (past a band's sentinel
/// the next band's keys start low again). The scan then ends with one
/// branch that no predictor foresees per box, after one block for most
/// boxes, instead of a branch per candidate. Returns the box to go on from
/// one at a time: the end of the scan, or a box too near the end of the
/// arrays for a whole block.
#[inline(always)]
fn sweep_box(
    (keys, hulls): (&[f32], &[Packed]),
    i: usize,
    mut j: usize,
    found: &mut Vec<(u32, u32)>,
    masks: &impl Fn(&[f32; BLOCK], &[Packed; BLOCK]) -> (u32, u32),
) -> usize {
    while let (Some(k8), Some(h8)) = (keys.get(j..j + BLOCK), hulls.get(j..j + BLOCK)) {
        let k8: &[f32; BLOCK] = k8.try_into().expect("a block of keys");
        let h8: &[Packed; BLOCK] = h8.try_into().expect("a block of hulls");
        let (within, overlapping) = masks(k8, h8);
        // The run of ones from the lowest bit.
        let run = (!within & within.wrapping_add(1)).wrapping_sub(1);
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

/// The masks of a block (see [`sweep_with`]) with WebAssembly's 128-bit
/// vectors: each hull's lanes beyond reach (NaN too) from two comparisons,
/// packed to bytes as the AVX2 masks pack them, and a hull within reach
/// exactly when its four bytes are zero.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
fn masks(end: f32, reach: &Packed) -> impl Fn(&[f32; BLOCK], &[Packed; BLOCK]) -> (u32, u32) {
    crate::lanes::blocks::masks_simd128(end, reach)
}

/// Which of a block of boxes meet the key after them (see
/// [`sweep_with`]) where the processor lacks AVX2: with WebAssembly's
/// SIMD, each box's end gathered lane by lane and compared four at a
/// time; other targets look at one box at a time.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
fn reaching_without_avx2(along: usize) -> Option<impl Fn(&[f32; BLOCK], &[Packed; BLOCK]) -> u32> {
    let reaching = crate::lanes::blocks::reaching_simd128;
    Some(move |next: &[f32; BLOCK], hulls: &[Packed; BLOCK]| reaching(next, hulls, along))
}

/// Other targets: one box at a time (see the WebAssembly version).
#[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
#[inline(always)]
fn reaching_without_avx2(_along: usize) -> Option<Reaching> {
    None
}

/// The masks of a block (see [`sweep_with`]) one lane at a time, for
/// targets without a lane type of their own here.
#[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
#[inline(always)]
fn masks(end: f32, reach: &Packed) -> impl Fn(&[f32; BLOCK], &[Packed; BLOCK]) -> (u32, u32) {
    let reach = *reach;
    move |k8, h8| {
        let (mut within, mut overlapping) = (0, 0);
        for k in 0..BLOCK {
            within |= u32::from(k8[k] <= end) << k;
            overlapping |= u32::from(overlaps(&h8[k], &reach)) << k;
        }
        (within, overlapping)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// Sorted boxes swept dense (eight at a time, by AVX2's masks and
        /// by the target's own) and sparse meet the
        /// same candidates and find every overlapping pair, each once, as
        /// the all-pairs loop does: with NaN in any lane but those along
        /// the sweep too, and on a grid of sixteenths, where keys and ends
        /// meet exactly (touching boxes overlap).
        #[test]
        fn dense_and_sparse_sweeps_find_the_all_pairs_overlaps(
            boxes in proptest::collection::vec(
                (0.0f32..1.0, 0.0f32..0.2, 0.0f32..1.0, 0.0f32..0.2, 0usize..16),
                0..300,
            ),
            along in 0usize..2,
            grid in proptest::bool::ANY,
        ) {
            let n = f32::NEG_INFINITY;
            let on_grid = |v: f32| if grid { (v * 16.0).round() / 16.0 } else { v };
            let mut hulls: Vec<Packed> = boxes
                .iter()
                .map(|&(x, w, y, h, nan)| {
                    let (x, w, y, h) = (on_grid(x), on_grid(w), on_grid(y), on_grid(h));
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
            proptest::prop_assert_eq!(met[0], met[2]);
            proptest::prop_assert_eq!(&found[0], &found[1]);
            proptest::prop_assert_eq!(&found[0], &found[2]);
            proptest::prop_assert_eq!(&found[1], &all_overlapping(&hulls));
        }
    }

    proptest::proptest! {
        /// Two bands of sparse boxes, each sorted by key and swept on its
        /// own over the keys up to its end, as a layout's bands are: sparse
        /// and dense, a block at a time or not, each meets the same
        /// candidates and finds every overlapping pair within each band,
        /// whether either band is empty or short of a block, also on a
        /// grid of 1/128ths, where keys and ends meet exactly.
        #[test]
        fn bands_swept_on_their_own_find_their_overlaps(
            boxes in proptest::collection::vec((0.0f32..1.0, 0.0f32..0.03, 0.0f32..1.0), 0..120),
            split in 0.0f64..1.0,
            along in 0usize..2,
            grid in proptest::bool::ANY,
        ) {
            let n = f32::NEG_INFINITY;
            let on_grid = |v: f32| if grid { (v * 128.0).round() / 128.0 } else { v };
            let hull = |&(x, w, y): &(f32, f32, f32)| {
                let (x, w, y) = (on_grid(x), on_grid(w), on_grid(y));
                [x, y, n, n, -(x + w), -(y + w), n, n]
            };
            let mut hulls: Vec<Packed> = boxes.iter().map(hull).collect();
            let m = (split * hulls.len() as f64) as usize;
            let by_key = |a: &Packed, b: &Packed| a[along].total_cmp(&b[along]);
            hulls[..m].sort_by(by_key);
            hulls[m..].sort_by(by_key);
            let keys: Vec<f32> = hulls.iter().map(|h| h[along]).collect();
            let total = hulls.len();
            let mut want: Vec<(u32, u32)> = all_overlapping(&hulls[..m]);
            let second = all_overlapping(&hulls[m..]).into_iter();
            want.extend(second.map(|(i, j)| (i + m as u32, j + m as u32)));
            want.sort_unstable();
            let mut met = Vec::new();
            for dense in [false, true] {
                for by_blocks in [false, true] {
                    let mut found = Vec::new();
                    let mut candidates = 0;
                    for band in [0..m, m..total] {
                        let (keys, hulls) = (&keys[..band.end], &hulls[..band.end]);
                        candidates += match by_blocks {
                            true => sweep(keys, hulls, band, along, dense, &mut found),
                            false => {
                                let blocks = (masks, None::<Reaching>);
                                sweep_with(keys, hulls, band, along, dense, &mut found, blocks, false)
                            }
                        };
                    }
                    found.sort_unstable();
                    proptest::prop_assert_eq!(&found, &want);
                    met.push(candidates);
                }
            }
            proptest::prop_assert!(met.iter().all(|&c| c == met[0]));
        }
    }

    /// The pairs `hulls` (sorted by key along `along`) swept sparse and
    /// dense find, each list sorted, and the candidates each met: dense as
    /// the processor's scan does it, and a block at a time by this
    /// target's own masks, whether or not its scan uses them.
    fn swept_sparse_and_dense(hulls: &[Packed], along: usize) -> ([Vec<(u32, u32)>; 3], [u64; 3]) {
        let keys: Vec<f32> = hulls.iter().map(|h| h[along]).collect();
        let mut found = [Vec::new(), Vec::new(), Vec::new()];
        let mut met = [0, 0, 0];
        for (k, dense) in [false, true].into_iter().enumerate() {
            met[k] = sweep(&keys, hulls, 0..keys.len(), along, dense, &mut found[k]);
        }
        let all = 0..keys.len();
        let blocks = (masks, None::<Reaching>);
        met[2] = sweep_with(&keys, hulls, all, along, true, &mut found[2], blocks, true);
        found.iter_mut().for_each(|f| f.sort_unstable());
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
