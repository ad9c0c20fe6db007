//! The boxes laid out band by band: each box copied into every band it
//! reaches, each band sorted on its own and closed by a sentinel.
//!
//! Boxes arrive in last step's order, which is band by band, so every band
//! receives its boxes nearly sorted (only boxes that crossed into it from
//! a neighbour are out of place) and an insertion sort of the band, small
//! enough to stay in the nearest cache, finishes in about one pass. The
//! bands are split into groups of about equal size, one per thread; each
//! group owns its stretch of the arrays, so the groups are laid out,
//! sorted and swept at once without sharing anything they write.

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
        self.starts.clear();
        let mut total = 0;
        for &c in &self.counts {
            self.starts.push(total);
            total += c + 1;
        }
        self.starts.push(total);
        self.keys.resize(total, NO_KEY);
        self.hulls.resize(total, [0.0; 8]);
        self.ids.resize(total, u32::MAX);

        let Layout {
            keys,
            hulls,
            ids,
            starts,
            ..
        } = self;
        let stretches = stretches(starts, keys, hulls, ids, groups);
        let lay = |s: Stretch| lay_out_and_sort(s, starts, slots, n, spans);
        if stretches.len() > 1 {
            use rayon::prelude::*;
            stretches.into_par_iter().for_each(lay);
        } else {
            stretches.into_iter().for_each(lay);
        }
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

/// Copies into one stretch every box that reaches its bands, in slot
/// order, then sorts each of its bands.
///
/// A band's home entries come in last step's order, nearly sorted; its
/// guests (boxes whose home is a band below) come in their own bands'
/// orders. Homes are written from the front of the band and guests from
/// its back, each run is sorted, and the two are merged.
fn lay_out_and_sort(s: Stretch, starts: &[usize], slots: &Boxes, n: usize, spans: &[(u32, u32)]) {
    let Stretch {
        bands,
        offset,
        keys,
        hulls,
        ids,
    } = s;
    let (first_band, end_band) = (bands.start as u32, bands.end as u32);
    // Per band: where the next home goes, and one past where the next
    // guest goes (the sentinel's place, to begin with).
    let mut fronts: Vec<usize> = starts[bands.clone()].iter().map(|&s| s - offset).collect();
    let mut backs: Vec<usize> = starts[bands.start + 1..=bands.end]
        .iter()
        .map(|&s| s - 1 - offset)
        .collect();
    for k in 0..n {
        let (first, end) = spans[k];
        let key = slots.keys[k];
        if key == NO_KEY || end <= first_band || first >= end_band {
            continue;
        }
        let (hull, id) = (slots.hulls[k], slots.ids[k]);
        if first >= first_band {
            let at = &mut fronts[(first - first_band) as usize];
            keys[*at] = key;
            hulls[*at] = hull;
            ids[*at] = id | HOME;
            *at += 1;
        }
        for band in (first + 1).max(first_band)..end.min(end_band) {
            let at = &mut backs[(band - first_band) as usize];
            *at -= 1;
            keys[*at] = key;
            hulls[*at] = hull;
            ids[*at] = id;
        }
    }
    let mut scratch = Scratch::default();
    for (g, band) in bands.enumerate() {
        let range = starts[band] - offset..starts[band + 1] - 1 - offset;
        keys[range.end] = NO_KEY;
        ids[range.end] = u32::MAX;
        debug_assert_eq!(fronts[g], backs[g], "homes and guests fill the band");
        let homes = fronts[g] - range.start;
        sort_band(
            &mut keys[range.clone()],
            &mut hulls[range.clone()],
            &mut ids[range],
            homes,
            &mut scratch,
        );
    }
}

/// Room to merge a band's two runs in.
#[derive(Default)]
struct Scratch {
    keys: Vec<f32>,
    hulls: Vec<Packed>,
    ids: Vec<u32>,
}

/// Sorts one band's entries by key: its first `homes` entries are one run
/// and the rest (in reverse) another; each is sorted, then they are
/// merged.
fn sort_band(
    keys: &mut [f32],
    hulls: &mut [Packed],
    ids: &mut [u32],
    homes: usize,
    scratch: &mut Scratch,
) {
    keys[homes..].reverse();
    hulls[homes..].reverse();
    ids[homes..].reverse();
    sort_run(&mut keys[..homes], &mut hulls[..homes], &mut ids[..homes]);
    sort_run(&mut keys[homes..], &mut hulls[homes..], &mut ids[homes..]);
    if homes == 0 || homes == keys.len() || keys[homes - 1] <= keys[homes] {
        return;
    }
    // Move the first run aside and merge both into place: the write
    // position never passes the second run's read position.
    scratch.keys.clear();
    scratch.hulls.clear();
    scratch.ids.clear();
    scratch.keys.extend_from_slice(&keys[..homes]);
    scratch.hulls.extend_from_slice(&hulls[..homes]);
    scratch.ids.extend_from_slice(&ids[..homes]);
    let (mut a, mut b, mut at) = (0, homes, 0);
    while a < homes {
        if b < keys.len() && keys[b] < scratch.keys[a] {
            keys[at] = keys[b];
            hulls[at] = hulls[b];
            ids[at] = ids[b];
            b += 1;
        } else {
            keys[at] = scratch.keys[a];
            hulls[at] = scratch.hulls[a];
            ids[at] = scratch.ids[a];
            a += 1;
        }
        at += 1;
    }
}

/// Sorts a run by key: by insertion while that stays short, else by
/// radix.
fn sort_run(keys: &mut [f32], hulls: &mut [Packed], ids: &mut [u32]) {
    let n = keys.len();
    let mut budget = MOVES_PER_ENTRY * n + 16;
    for i in 1..n {
        let key = keys[i];
        if keys[i - 1] <= key {
            continue;
        }
        let (hull, id) = (hulls[i], ids[i]);
        let mut j = i;
        while j > 0 && keys[j - 1] > key {
            keys[j] = keys[j - 1];
            hulls[j] = hulls[j - 1];
            ids[j] = ids[j - 1];
            j -= 1;
        }
        keys[j] = key;
        hulls[j] = hull;
        ids[j] = id;
        if i - j > budget {
            radix_sort_band(keys, hulls, ids);
            return;
        }
        budget -= i - j;
    }
}

/// Sorts a run by key with a radix sort of keys and positions, then a
/// gather.
fn radix_sort_band(keys: &mut [f32], hulls: &mut [Packed], ids: &mut [u32]) {
    let mut keyed: Vec<(f32, u32)> = keys
        .iter()
        .enumerate()
        .map(|(k, &key)| (key, k as u32))
        .collect();
    radsort::sort_by_key(&mut keyed, |k| k.0);
    let old_hulls = hulls.to_vec();
    let old_ids = ids.to_vec();
    for (at, &(key, k)) in keyed.iter().enumerate() {
        keys[at] = key;
        hulls[at] = old_hulls[k as usize];
        ids[at] = old_ids[k as usize];
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
            assert_eq!(
                ids,
                vec![11, 10, u32::MAX & !HOME, 11, 14, 12, u32::MAX & !HOME]
            );
            assert_eq!(layout.keys, vec![0.0, 0.5, NO_KEY, 0.0, 0.1, 0.7, NO_KEY]);
            // 11's home is band 0; it is a guest in band 1.
            assert_eq!(layout.ids[3], 11);
            let mut order = Vec::new();
            layout.home_order(&mut order);
            assert_eq!(order, vec![11, 10, 14, 12]);
        }
    }

    #[test]
    fn a_scrambled_band_is_sorted() {
        let n = 500;
        let keys: Vec<f32> = (0..n).map(|i| ((i * 7919) % n) as f32).collect();
        let mut k = keys.clone();
        let mut h: Vec<Packed> = keys.iter().map(|&key| [key; 8]).collect();
        let mut ids: Vec<u32> = (0..n as u32).collect();
        sort_band(&mut k, &mut h, &mut ids, n / 3, &mut Scratch::default());
        assert!(k.windows(2).all(|w| w[0] <= w[1]));
        for at in 0..n {
            assert_eq!(h[at][0], k[at]);
            assert_eq!(keys[ids[at] as usize], k[at]);
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
