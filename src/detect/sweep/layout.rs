//! The boxes laid out band by band: each box copied into every band it
//! reaches, each band sorted on its own and closed by a sentinel.
//!
//! A box's *home* is the band holding its least value across the bands;
//! it is a *guest* in the other bands it reaches, all above its home.
//! Boxes arrive in last step's order, homes band by band, so each band's
//! homes arrive nearly sorted (only boxes that crossed from a neighbour
//! are out of place) and an insertion sort of them, small enough to stay
//! in the nearest cache, finishes in about one pass. A band's guests are
//! the entries of the band below (homes and guests) that reach up into it:
//! taken from that band once it is sorted, they come sorted, and one merge
//! with the homes finishes the band.
//!
//! The bands are split into groups of about equal size, one per thread;
//! each group owns its stretch of the arrays (its first band's guests it
//! gathers and sorts itself), so the groups are laid out, sorted and swept
//! at once without sharing anything they write.

use super::bands::Bands;
use super::hull::Packed;
use super::order::{Boxes, NO_KEY};
use std::ops::Range;

/// Marks, in a laid-out id, the band that holds the box's least value
/// across the bands (its home): the order for next step is the home
/// entries, band by band. Ids are below 2^31 (a world holds fewer lines).
pub(crate) const HOME: u32 = 1 << 31;

/// Moves an insertion sort of one band may make per entry before the band
/// is sorted by radix instead.
const MOVES_PER_ENTRY: usize = 8;

/// The boxes band after band (see the [module docs](self)).
#[derive(Debug, Default)]
pub(crate) struct Layout {
    /// Least value along the sweep direction, per entry; [`NO_KEY`] for
    /// each band's sentinel.
    pub keys: Vec<f32>,
    /// Packed hull, per entry.
    pub hulls: Vec<Packed>,
    /// Line id (or box index), per entry, with [`HOME`] set in the band
    /// that is the box's home.
    pub ids: Vec<u32>,
    /// Where each band's entries start; band `b` ends at `starts[b + 1] - 1`,
    /// its sentinel.
    pub starts: Vec<usize>,
    /// Per band, its entries while counting.
    counts: Vec<usize>,
    /// Per group, its working buffers, kept from step to step.
    scratch: Vec<Scratch>,
}

/// One group's working buffers.
#[derive(Debug, Default)]
struct Scratch {
    /// The group's homes, band by band in slot order.
    homes: Run,
    /// Where each band's homes start in `homes`, and a cursor per band.
    home_starts: Vec<usize>,
    cursor: Vec<usize>,
    /// One band's homes as keys and positions, to sort.
    order: Vec<(f32, u32)>,
    /// The current band's guests, and the next band's.
    guests: Run,
    next: Run,
    /// One band's entries' ends, as merged.
    ends: Vec<u32>,
}

/// One group's stretch of the layout: its bands and their arrays.
struct Stretch<'a> {
    bands: Range<usize>,
    /// The first entry of the stretch.
    offset: usize,
    keys: &'a mut [f32],
    hulls: &'a mut [Packed],
    ids: &'a mut [u32],
}

impl Layout {
    /// Lays out the first `n` boxes of `slots` (in last step's order; those
    /// keyed [`NO_KEY`] are left out) in `bands`, where `spans[k]` gives the
    /// bands box `k` reaches (first, and one past the last), and sorts
    /// every band, in `groups` groups of bands on the current rayon pool
    /// (one group: on this thread).
    pub(crate) fn build(
        &mut self,
        slots: &Boxes,
        n: usize,
        spans: &[(u32, u32)],
        bands: &Bands,
        groups: usize,
    ) {
        debug_assert!(n < HOME as usize);
        self.counts.clear();
        self.counts.resize(bands.count, 0);
        for (&key, &(first, end)) in slots.keys[..n].iter().zip(&spans[..n]) {
            if key != NO_KEY {
                for c in &mut self.counts[first as usize..end as usize] {
                    *c += 1;
                }
            }
        }
        let total = self.set_starts();
        self.keys.resize(total, NO_KEY);
        self.hulls.resize(total, [0.0; 8]);
        self.ids.resize(total, u32::MAX);

        let Layout {
            keys,
            hulls,
            ids,
            starts,
            scratch,
            ..
        } = self;
        let stretches = stretches(starts, keys, hulls, ids, groups);
        scratch.resize_with(stretches.len().max(scratch.len()), Scratch::default);
        let lay = |(s, scratch): (Stretch, &mut Scratch)| {
            lay_out_and_sort(s, scratch, starts, slots, n, spans)
        };
        if stretches.len() > 1 {
            use rayon::prelude::*;
            stretches
                .into_par_iter()
                .zip(scratch.par_iter_mut())
                .for_each(lay);
        } else {
            stretches.into_iter().zip(scratch.iter_mut()).for_each(lay);
        }
    }

    /// Sets where each band starts from the entries counted in each, with
    /// room for its sentinel; returns the entries laid out in all.
    fn set_starts(&mut self) -> usize {
        self.starts.clear();
        let mut total = 0;
        for &c in &self.counts {
            self.starts.push(total);
            total += c + 1;
        }
        self.starts.push(total);
        total
    }

    /// Consecutive ranges of bands, at most `groups` of them, each holding
    /// about the same number of entries.
    pub(crate) fn group_bounds(&self, groups: usize) -> Vec<Range<usize>> {
        group_bounds(&self.starts, groups)
    }

    /// Appends the ids of the home entries, band by band in sorted order:
    /// next step's order.
    pub(crate) fn home_order(&self, order: &mut Vec<u32>) {
        order.extend(
            self.ids
                .iter()
                .filter(|&&id| id != u32::MAX && id & HOME != 0)
                .map(|&id| id & !HOME),
        );
    }

    /// Entries laid out, sentinels included.
    pub(crate) fn len(&self) -> usize {
        self.keys.len()
    }
}

/// Consecutive ranges of the bands that start at `starts`, at most
/// `groups` of them, each holding about the same number of entries.
fn group_bounds(starts: &[usize], groups: usize) -> Vec<Range<usize>> {
    let count = starts.len() - 1;
    let total = starts[count];

    let groups = groups.clamp(1, count.max(1));
    let mut bounds = Vec::with_capacity(groups);
    let mut first = 0;
    for g in 1..=groups {
        let target = total * g / groups;
        // The band boundary nearest the target.
        let mut last = if g == groups {
            count
        } else {
            let after = starts.partition_point(|&s| s < target).min(count);
            if after > 0 && target - starts[after - 1] < starts[after] - target {
                after - 1
            } else {
                after
            }
        };
        last = last.max(first);
        if last > first {
            bounds.push(first..last);
        }
        first = last;
    }
    bounds
}

/// Splits the arrays into stretches of whole bands, one per group.
fn stretches<'a>(
    starts: &[usize],
    mut keys: &'a mut [f32],
    mut hulls: &'a mut [Packed],
    mut ids: &'a mut [u32],
    groups: usize,
) -> Vec<Stretch<'a>> {
    let bounds = group_bounds(starts, groups);
    let mut out = Vec::with_capacity(bounds.len());
    for bands in bounds {
        let (offset, end) = (starts[bands.start], starts[bands.end]);
        let len = end - offset;
        let (k, rest_k) = std::mem::take(&mut keys).split_at_mut(len);
        let (h, rest_h) = std::mem::take(&mut hulls).split_at_mut(len);
        let (i, rest_i) = std::mem::take(&mut ids).split_at_mut(len);
        (keys, hulls, ids) = (rest_k, rest_h, rest_i);
        out.push(Stretch {
            bands,
            offset,
            keys: k,
            hulls: h,
            ids: i,
        });
    }
    out
}

/// Entries as parallel arrays: a group's homes, or a band's guests.
#[derive(Debug, Default)]
struct Run {
    keys: Vec<f32>,
    hulls: Vec<Packed>,
    ids: Vec<u32>,
    /// One past the last band each entry reaches.
    ends: Vec<u32>,
}

impl Run {
    fn clear(&mut self) {
        self.keys.clear();
        self.hulls.clear();
        self.ids.clear();
        self.ends.clear();
    }

    fn push(&mut self, key: f32, hull: Packed, id: u32, end: u32) {
        self.keys.push(key);
        self.hulls.push(hull);
        self.ids.push(id);
        self.ends.push(end);
    }

    /// Puts the entries in the order of `order` (positions), using `spare`.
    fn gather(&mut self, order: &[(f32, u32)], spare: &mut Run) {
        spare.clear();
        for &(key, at) in order {
            let at = at as usize;
            spare.push(key, self.hulls[at], self.ids[at], self.ends[at]);
        }
        std::mem::swap(self, spare);
    }
}

/// Lays out and sorts the bands of one stretch (see the [module
/// docs](self)).
fn lay_out_and_sort(
    s: Stretch,
    scratch: &mut Scratch,
    starts: &[usize],
    slots: &Boxes,
    n: usize,
    spans: &[(u32, u32)],
) {
    let Stretch {
        bands,
        offset,
        keys,
        hulls,
        ids,
    } = s;
    let (first_band, end_band) = (bands.start as u32, bands.end as u32);
    let home = |first: u32| (first.wrapping_sub(first_band)) as usize;
    let Scratch {
        homes,
        home_starts,
        cursor,
        order,
        guests,
        next,
        ends,
    } = scratch;
    // Where each band's homes start in `homes`.
    home_starts.clear();
    home_starts.resize(bands.len() + 1, 0);
    for (&key, &(first, _)) in slots.keys[..n].iter().zip(&spans[..n]) {
        if key != NO_KEY && (first_band..end_band).contains(&first) {
            home_starts[home(first) + 1] += 1;
        }
    }
    for b in 1..home_starts.len() {
        home_starts[b] += home_starts[b - 1];
    }
    // The homes, band by band in slot order, and the first band's guests.
    let total = home_starts[bands.len()];
    homes.keys.resize(total, 0.0);
    homes.hulls.resize(total, [0.0; 8]);
    homes.ids.resize(total, 0);
    homes.ends.resize(total, 0);
    cursor.clear();
    cursor.extend_from_slice(home_starts);
    guests.clear();
    for (k, &(first, end)) in spans[..n].iter().enumerate() {
        let key = slots.keys[k];
        if key == NO_KEY {
            continue;
        }
        if (first_band..end_band).contains(&first) {
            let at = &mut cursor[home(first)];
            homes.keys[*at] = key;
            homes.hulls[*at] = slots.hulls[k];
            homes.ids[*at] = slots.ids[k] | HOME;
            homes.ends[*at] = end;
            *at += 1;
        } else if first < first_band && end > first_band {
            guests.push(key, slots.hulls[k], slots.ids[k], end);
        }
    }
    keyed_order(&guests.keys, 0, order);
    guests.gather(order, next);

    for (g, band) in bands.enumerate() {
        // The homes are sorted as keys and positions (a few bytes to move
        // rather than a whole entry), and gathered by the merge.
        let run = home_starts[g]..home_starts[g + 1];
        keyed_order(&homes.keys[run.clone()], run.start, order);
        let out = starts[band] - offset..starts[band + 1] - 1 - offset;
        debug_assert_eq!(out.len(), run.len() + guests.keys.len());
        ends.clear();
        ends.resize(out.len(), 0);
        merge(
            order,
            homes,
            guests,
            (
                &mut keys[out.clone()],
                &mut hulls[out.clone()],
                &mut ids[out.clone()],
                ends,
            ),
        );
        keys[out.end] = NO_KEY;
        ids[out.end] = u32::MAX;
        // The next band's guests: this band's entries that reach into it.
        next.clear();
        let beyond = band as u32 + 1;
        for (k, at) in out.enumerate() {
            if ends[k] > beyond {
                next.push(keys[at], hulls[at], ids[at] & !HOME, ends[k]);
            }
        }
        std::mem::swap(guests, next);
    }
}

/// Fills `order` with `keys` and their positions (from `first`), sorted by
/// key.
fn keyed_order(keys: &[f32], first: usize, order: &mut Vec<(f32, u32)>) {
    order.clear();
    order.extend(keys.iter().zip(first as u32..).map(|(&key, at)| (key, at)));
    sort_keyed(order);
}

/// Sorts keys and positions by key: by insertion while that stays short,
/// else by radix.
fn sort_keyed(order: &mut [(f32, u32)]) {
    let mut budget = MOVES_PER_ENTRY * order.len() + 16;
    for i in 1..order.len() {
        let item = order[i];
        if order[i - 1].0 <= item.0 {
            continue;
        }
        let mut j = i;
        while j > 0 && order[j - 1].0 > item.0 {
            order[j] = order[j - 1];
            j -= 1;
        }
        order[j] = item;
        if i - j > budget {
            radsort::sort_by_key(order, |k| k.0);
            return;
        }
        budget -= i - j;
    }
}

/// Merges the homes taken in `order` and the sorted `guests` into `out`,
/// which holds exactly both.
fn merge(
    order: &[(f32, u32)],
    homes: &Run,
    guests: &Run,
    out: (&mut [f32], &mut [Packed], &mut [u32], &mut [u32]),
) {
    let (keys, hulls, ids, ends) = out;
    let (mut i, mut j) = (0, 0);
    for at in 0..keys.len() {
        let take_guest = i == order.len() || (j < guests.keys.len() && guests.keys[j] < order[i].0);
        if take_guest {
            keys[at] = guests.keys[j];
            hulls[at] = guests.hulls[j];
            ids[at] = guests.ids[j];
            ends[at] = guests.ends[j];
            j += 1;
        } else {
            let (key, from) = order[i];
            keys[at] = key;
            hulls[at] = homes.hulls[from as usize];
            ids[at] = homes.ids[from as usize];
            ends[at] = homes.ends[from as usize];
            i += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hull(lo_y: f32, hi_y: f32) -> Packed {
        let n = f32::NEG_INFINITY;
        [0.0, lo_y, n, n, -1.0, -hi_y, n, n]
    }

    /// Boxes keyed `keys` with spans across y from `ys`.
    fn slots(keys: &[f32], ys: &[(f32, f32)], bands: &Bands) -> (Boxes, Vec<(u32, u32)>) {
        let mut b = Boxes::default();
        b.reset(keys.len());
        let mut spans = Vec::new();
        for (k, (&key, &(lo, hi))) in keys.iter().zip(ys).enumerate() {
            b.keys[k] = key;
            b.hulls[k] = hull(lo, hi);
            b.ids[k] = 10 + k as u32;
            let (first, last) = bands.span(&b.hulls[k]);
            spans.push((first as u32, last as u32 + 1));
        }
        (b, spans)
    }

    #[test]
    fn boxes_go_into_every_band_they_reach_each_band_sorted() {
        let bands = Bands::spanning(1, 2, 0.0, 1.0);
        // Ids 10..14; 11 spans both bands; 13 takes no part.
        let keys = [0.5, 0.0, 0.7, NO_KEY, 0.1];
        let ys = [(0.1, 0.2), (0.1, 0.9), (0.6, 0.7), (0.0, 0.0), (0.8, 0.9)];
        let (b, spans) = slots(&keys, &ys, &bands);
        for groups in [1, 2, 3] {
            let mut layout = Layout::default();
            layout.build(&b, keys.len(), &spans, &bands, groups);
            assert_eq!(layout.starts, vec![0, 3, 7]);
            let ids: Vec<u32> = layout.ids.iter().map(|&id| id & !HOME).collect();
            assert_eq!(ids, vec![11, 10, !HOME, 11, 14, 12, !HOME]);
            assert_eq!(layout.keys, vec![0.0, 0.5, NO_KEY, 0.0, 0.1, 0.7, NO_KEY]);
            // 11's home is band 0; it is a guest in band 1.
            assert_eq!(layout.ids[3], 11);
            let mut order = Vec::new();
            layout.home_order(&mut order);
            assert_eq!(order, vec![11, 10, 14, 12]);
        }
    }

    #[test]
    fn keys_are_sorted_with_their_positions_however_scrambled() {
        for n in [0, 1, 5, 500] {
            for step in [1, 7919] {
                let keys: Vec<f32> = (0..n).map(|i| ((i * step) % n.max(1)) as f32).collect();
                let mut order = Vec::new();
                keyed_order(&keys, 100, &mut order);
                assert!(order.windows(2).all(|w| w[0].0 <= w[1].0));
                let mut at: Vec<u32> = order.iter().map(|o| o.1).collect();
                at.sort_unstable();
                assert_eq!(at, (100..100 + n as u32).collect::<Vec<_>>());
                assert!(order
                    .iter()
                    .all(|&(key, at)| keys[at as usize - 100] == key));
            }
        }
    }

    #[test]
    fn groups_split_bands_by_entries() {
        let layout = Layout {
            starts: vec![0, 10, 11, 12, 40],
            ..Layout::default()
        };
        assert_eq!(layout.group_bounds(1), vec![0..4]);
        assert_eq!(layout.group_bounds(2), vec![0..3, 3..4]);
        let all: usize = layout.group_bounds(8).iter().map(|r| r.len()).sum();
        assert_eq!(all, 4);
    }
}
