//! The sweep itself: every box meets the boxes after it whose least value
//! along the sweep direction lies within its own extent; of those, the
//! ones its packed hull overlaps are reported.

use super::bands::Bands;
use super::hull::{hi, overlaps, reach, Packed};
use super::layout::{Layout, HOME};
use super::order::Boxes;
use super::plan::Plan;
use multiversion::multiversion;

/// Sweeps the bands `bands` of a plan: with one band, the first `boxed`
/// of `sorted`; with several, `layout`. Calls
/// `found(a, b)` with the ids of every pair whose hulls overlap, once
/// each. Returns the candidates met.
pub(crate) fn sweep_bands(
    sorted: &Boxes,
    boxed: usize,
    layout: &Layout,
    plan: &Plan,
    bands: std::ops::Range<usize>,
    mut found: impl FnMut(u32, u32),
) -> u64 {
    let cut: &Bands = &plan.bands;
    // The sweep only notes the pairs (its loops stay small, with nothing
    // else live in registers); they are handed on afterwards.
    let mut pairs = Vec::new();
    if cut.count == 1 {
        return sweep_sorted(sorted, 0..boxed, plan.along, &mut pairs, found);
    }
    let mut candidates = 0;
    for band in bands {
        let entries = layout.starts[band]..layout.starts[band + 1] - 1;
        pairs.clear();
        candidates += sweep(&layout.keys, &layout.hulls, entries, plan.along, &mut pairs);
        for &(i, j) in &pairs {
            let (i, j) = (i as usize, j as usize);
            if cut.reports(band, &layout.hulls[i], &layout.hulls[j]) {
                found(layout.ids[i] & !HOME, layout.ids[j] & !HOME);
            }
        }
    }
    candidates
}

/// With one band: sweeps the boxes `range` of `sorted` (each against the
/// boxes after it, wherever they lie) along direction `along`, noting the
/// overlapping pairs in `pairs` (cleared first) and then calling
/// `found(a, b)` with their ids. Returns the candidates met.
pub(crate) fn sweep_sorted(
    sorted: &Boxes,
    range: std::ops::Range<usize>,
    along: usize,
    pairs: &mut Vec<(u32, u32)>,
    mut found: impl FnMut(u32, u32),
) -> u64 {
    pairs.clear();
    let candidates = sweep(&sorted.keys, &sorted.hulls, range, along, pairs);
    for &(i, j) in pairs.iter() {
        found(sorted.ids[i as usize], sorted.ids[j as usize]);
    }
    candidates
}

/// Sweeps the boxes `range` of sorted `keys` and `hulls`, each against the
/// boxes after it up to the first whose key lies beyond its extent along
/// direction `along` (a sentinel after the last box guarantees one), and
/// appends to `found` every pair `(i, j)` whose hulls overlap. Returns the
/// pairs met (the candidates).
///
/// Compiled for the baseline and for AVX2 (one 8-lane comparison per
/// candidate instead of two 4-lane ones), chosen when the program starts.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn sweep(
    keys: &[f32],
    hulls: &[Packed],
    range: std::ops::Range<usize>,
    along: usize,
    found: &mut Vec<(u32, u32)>,
) -> u64 {
    let mut candidates = 0;
    for i in range {
        let hull = &hulls[i];
        // Keys are at most f32::MAX, so a box reaching to +inf still
        // stops at the sentinel.
        let end = hi(hull, along).min(f32::MAX);
        let reach = reach(hull);
        let mut j = i + 1;
        while keys[j] <= end {
            if overlaps(&hulls[j], &reach) {
                found.push((i as u32, j as u32));
            }
            j += 1;
        }
        candidates += (j - i - 1) as u64;
    }
    candidates
}
