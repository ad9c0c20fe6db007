//! The sweep on boxes of one's own: the plane cut into bands across one
//! axis, each box copied into every band it reaches, and each band sorted
//! along the other axis and swept, in `f64` so that what the sweep meets
//! needs no second, exact test.
//!
//! Boxes come in any order. One pass copies each box into its bands, one
//! stream of entries a band, which the cache keeps up with however
//! scattered the boxes are. Each band, small enough to stay in the cache,
//! is then sorted and swept on its own while it is there, the test across
//! the sweep made without a branch (in clustered boxes a fifth of the
//! boxes met overlap, too many for a predictor). A pair that overlaps lies
//! together in every band from the one holding the larger of their least
//! values across the bands; it is reported only there, so once.
//!
//! The bands' buffers are kept for the thread's next call, so that a
//! program finding pairs every frame does not ask the system for fresh
//! memory (and fault its pages in) every frame.

use super::Aabb;
use crate::detect::sweep::bands::Bands;
use std::cell::Cell;

/// One box in one band: the box, its index, and its first band.
#[derive(Clone, Copy, Debug)]
struct Entry {
    aabb: Aabb,
    index: u32,
    first: u32,
}

/// Working buffers, kept per thread from call to call.
#[derive(Default)]
struct Scratch {
    /// Each band's entries.
    bands: Vec<Vec<Entry>>,
    /// One band's keys (rounded to `f32`) and entries, for sorting.
    keyed: Vec<(f32, u32)>,
    /// One band's entries, sorted.
    sorted: Vec<Entry>,
    /// The boxes one box meets in the sweep.
    hits: Vec<u32>,
}

thread_local! {
    /// The thread's buffers between calls (taken during one, so that a
    /// call made from within `found` simply starts with fresh ones).
    static SCRATCH: Cell<Scratch> = Cell::new(Scratch::default());
}

/// Calls `found(a, b)`, `a < b`, for every overlapping pair of `boxes`,
/// sweeping along axis `along` (0: `x`, 1: `y`) in the `bands` cut across
/// the other axis (whose `across` must be that axis).
pub(super) fn for_each_pair(
    boxes: &[Aabb],
    along: usize,
    bands: &Bands,
    found: &mut impl FnMut(u32, u32),
) {
    let across = 1 - along;
    debug_assert!(bands.count == 1 || bands.across == across);
    // Band numbers come from the values rounded to `f32`, the same way for
    // a box's bands and for a pair's reporting band: rounding is monotone,
    // so the reporting band lies within both boxes' bands.
    let band_of = |v: f64| bands.of(v as f32);
    let mut scratch = SCRATCH.with(Cell::take);
    let Scratch {
        bands: streams,
        keyed,
        sorted,
        hits,
    } = &mut scratch;
    streams.resize_with(bands.count.max(streams.len()), Vec::new);
    for stream in streams.iter_mut() {
        stream.clear();
    }
    for (index, aabb) in boxes.iter().enumerate() {
        if aabb.is_empty() {
            continue;
        }
        let (first, last) = (band_of(aabb.min[across]), band_of(aabb.max[across]));
        let entry = Entry {
            aabb: *aabb,
            index: index as u32,
            first: first as u32,
        };
        for stream in &mut streams[first..=last] {
            stream.push(entry);
        }
    }
    for (band, entries) in streams[..bands.count].iter().enumerate() {
        keyed.clear();
        keyed.extend(
            entries
                .iter()
                .enumerate()
                .map(|(k, e)| (e.aabb.min[along] as f32, k as u32)),
        );
        // Sorted by the keys rounded to f32 (four radix passes instead of
        // eight; rounding is monotone), then finished on the exact keys,
        // which only reorders boxes whose keys round alike.
        radsort::sort_by_key(keyed, |k| k.0);
        sorted.clear();
        sorted.extend(keyed.iter().map(|&(_, k)| entries[k as usize]));
        insertion_sort(sorted, along);
        sweep(sorted, along, hits, |a, b| {
            // Reported in the band holding the larger least value across:
            // the later of the two first bands, as banding is monotone.
            if a.first.max(b.first) as usize == band {
                found(a.index.min(b.index), a.index.max(b.index));
            }
        });
    }
    SCRATCH.with(|s| s.set(scratch));
}

/// Sorts entries that are nearly in order by their least value along
/// `along`.
fn insertion_sort(entries: &mut [Entry], along: usize) {
    for i in 1..entries.len() {
        let key = entries[i].aabb.min[along];
        if entries[i - 1].aabb.min[along] <= key {
            continue;
        }
        let entry = entries[i];
        let mut j = i;
        while j > 0 && entries[j - 1].aabb.min[along] > key {
            entries[j] = entries[j - 1];
            j -= 1;
        }
        entries[j] = entry;
    }
}

/// Sweeps `entries`, sorted by their least value along `along`: calls
/// `overlap(a, b)` for every pair that overlaps. Along the sweep axis two
/// boxes overlap when the later one starts within the earlier one; across
/// it the two comparisons are made, without a branch: the boxes that pass
/// are noted in `hits` (one slot per entry at least), and only they are
/// handed on.
#[inline]
fn sweep(
    entries: &[Entry],
    along: usize,
    hits: &mut Vec<u32>,
    mut overlap: impl FnMut(&Entry, &Entry),
) {
    let across = 1 - along;
    // Room for every entry; what is in it does not matter (each slot is
    // written before it is read), so it is only ever grown, not cleared.
    if hits.len() < entries.len() {
        hits.resize(entries.len(), 0);
    }
    for (i, a) in entries.iter().enumerate() {
        let (end, low, high) = (a.aabb.max[along], a.aabb.min[across], a.aabb.max[across]);
        let mut met = 0;
        for (j, b) in entries.iter().enumerate().skip(i + 1) {
            if b.aabb.min[along] > end {
                break;
            }
            hits[met] = j as u32;
            met += usize::from((b.aabb.min[across] <= high) & (low <= b.aabb.max[across]));
        }
        for &j in &hits[..met] {
            overlap(a, &entries[j as usize]);
        }
    }
}
