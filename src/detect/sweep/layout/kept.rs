//! A layout kept from last step and updated ([`Layout::keep`]): only the
//! boxes that changed band are moved apart and inserted, which costs a
//! quarter of a layout made anew.
//!
//! On one thread the layout is updated in place. With several groups of
//! bands (a team or rayon's pool) each group first closes up its own
//! bands, then, once the boxes that left their band are sorted, copies its
//! bands to their new places in the other arrays and finishes them, each
//! group writing only its own stretch.

use super::{
    end_guests, finish_band, groups_of_bands, run_each, set_starts, sort_movers, stretches, Group,
    Layout, Run, Stretch,
};
use crate::detect::sweep::bands::Bands;
use crate::detect::sweep::hull::{hi, lo, Packed};
use crate::detect::sweep::order::{Boxes, NO_KEY};
use crate::team::Team;
use std::ops::Range;

/// What every group reads while it finishes its bands.
struct Closed<'a> {
    /// Last step's boxes, each band's stayers closed up at its front.
    keys: &'a [f32],
    hulls: &'a [Packed],
    ids: &'a [u32],
    old_starts: &'a [usize],
    starts: &'a [usize],
    stayed: &'a [usize],
    /// Per band, the last band its homes (this step's) reach.
    reach: &'a [u32],
    /// The boxes that changed band, sorted by band and then by key.
    movers: &'a Run,
    /// Where each band's movers start in `movers`, and their end.
    mover_starts: &'a [usize],
    bands: &'a Bands,
}

impl Layout {
    /// Lays out the first `n` boxes of `slots` again, when they arrive in
    /// the order of last step's layout in the same `bands` (their hulls
    /// made anew); returns the boxes with a key (which come first), or
    /// `None`, changing nothing, when they do not.
    ///
    /// With `groups` above one, the work is shared among the groups of
    /// bands, with `team` if there is one, else on the current rayon pool.
    pub(crate) fn keep(
        &mut self,
        slots: &mut Boxes,
        n: usize,
        bands: &Bands,
        groups: usize,
        team: Option<&Team>,
    ) -> Option<usize> {
        let count = bands.count;
        if self.kept != Some(*bands)
            || self.starts.len() != count + 2
            || self.starts[count + 1] != n
            || slots.len() != n
        {
            return None;
        }
        if groups <= 1 {
            return Some(self.keep_in_place(slots, n, bands));
        }
        std::mem::swap(&mut self.starts, &mut self.old_starts);
        // Groups of bands by last step's starts, the last also holding the
        // boxes without a key.
        let bounds = groups_of_bands(&self.old_starts, groups);
        self.groups
            .resize_with(bounds.len().max(self.groups.len()), Group::default);
        self.stayed.clear();
        self.stayed.resize(count + 1, 0);
        let mut tops = vec![f32::NEG_INFINITY; count + 1];

        // Each group closes up its own bands and holds aside the boxes
        // that left them.
        {
            let (edges, old) = (&self.edges, &self.old_starts);
            let (keys, hulls, ids) = (&mut slots.keys, &mut slots.hulls, &mut slots.ids);
            let work: Vec<_> = stretches(old, keys, hulls, ids, &bounds)
                .into_iter()
                .zip(per_group(&mut self.stayed, &bounds))
                .zip(per_group(&mut tops, &bounds))
                .zip(self.groups.iter_mut())
                .collect();
            run_each(work, team, |(((arrived, stayed), tops), g)| {
                close_up_group(arrived, (stayed, tops), g, old, edges, bands)
            });
        }

        // The movers of all groups, sorted by band and key; the new starts.
        let mut movers = std::mem::take(&mut self.movers);
        movers.clear();
        for g in &self.groups[..bounds.len()] {
            movers.extend_from(&g.movers, 0..g.movers.len());
        }
        self.counts.clear();
        self.counts.extend(self.stayed.iter().map(|&s| s as u32));
        for (&b, hull) in movers.ends.iter().zip(&movers.hulls) {
            self.counts[b as usize] += 1;
            if (b as usize) < count {
                let top = &mut tops[b as usize];
                *top = top.max(hi(hull, bands.across));
            }
        }
        set_starts(&self.counts, &mut self.starts, n);
        if movers.len() > 0 {
            let g = &mut self.groups[0];
            sort_movers(&mut movers, &mut g.order, &mut g.spare);
        }
        let mut mover_starts = Vec::with_capacity(count + 2);
        mover_starts.push(0);
        for b in 0..=count {
            let moved = self.counts[b] as usize - self.stayed[b];
            mover_starts.push(mover_starts[b] + moved);
        }
        self.reach.clear();
        self.reach.extend(
            tops.iter()
                .enumerate()
                .map(|(b, &top)| match top > f32::NEG_INFINITY {
                    true => bands.of(top).max(b) as u32,
                    false => b as u32,
                }),
        );

        // Each group copies its bands' stayers to their new places in the
        // other arrays and finishes them there, with their guests.
        self.keys.resize(n + 1, NO_KEY);
        self.hulls.resize(n + 1, [0.0; 8]);
        self.ids.resize(n + 1, u32::MAX);
        self.keys[n] = NO_KEY;
        self.ids[n] = u32::MAX;
        {
            let closed = Closed {
                keys: &slots.keys[..n],
                hulls: &slots.hulls[..n],
                ids: &slots.ids[..n],
                old_starts: &self.old_starts,
                starts: &self.starts,
                stayed: &self.stayed,
                reach: &self.reach,
                movers: &movers,
                mover_starts: &mover_starts,
                bands,
            };
            let stretches = stretches(
                &self.starts,
                &mut self.keys,
                &mut self.hulls,
                &mut self.ids,
                &bounds,
            );
            let work: Vec<_> = stretches.into_iter().zip(self.groups.iter_mut()).collect();
            run_each(work, team, |(s, g)| finish_group(s, g, &closed));
        }
        self.movers = movers;

        self.hand_over(slots, &bounds, count);
        Some(self.starts[count])
    }

    /// [`Layout::keep`] on one thread, in place.
    ///
    /// Each band's boxes that stayed in it are closed up at its front in
    /// one pass, and the ones that left are held aside; the bands' runs
    /// then move to their new starts (a copy of whole runs, in the order
    /// that overwrites nothing unmoved); each band's stayers are finished
    /// by insertion and its newcomers inserted; and the guests are listed
    /// band by band.
    fn keep_in_place(&mut self, slots: &mut Boxes, n: usize, bands: &Bands) -> usize {
        let count = bands.count;
        if self.groups.is_empty() {
            self.groups.push(Group::default());
        }
        let Group {
            guests,
            guest_starts,
            movers,
            order,
            spare,
            gaps,
        } = &mut self.groups[0];
        let (keys, hulls, ids) = (
            &mut slots.keys[..n],
            &mut slots.hulls[..n],
            &mut slots.ids[..n],
        );
        std::mem::swap(&mut self.starts, &mut self.old_starts);
        let (old, edges) = (&self.old_starts, &self.edges);
        movers.clear();
        self.stayed.clear();
        for b in 0..=count {
            let band = old[b]..old[b + 1];
            let (stayed, _) = close_up::<false>(
                (&mut *keys, &mut *hulls, &mut *ids),
                band,
                b,
                edges,
                bands,
                movers,
                gaps,
            );
            self.stayed.push(stayed);
        }
        // The new starts: each band's stayers and newcomers.
        self.counts.clear();
        self.counts.extend(self.stayed.iter().map(|&s| s as u32));
        for &b in &movers.ends {
            self.counts[b as usize] += 1;
        }
        set_starts(&self.counts, &mut self.starts, n);
        // The runs of stayers to their new starts: those moving up from
        // the last band down, then those moving down from the first up,
        // so that no run lands on one not yet moved.
        let new = &self.starts;
        let shift = |b: usize, keys: &mut [f32], hulls: &mut [Packed], ids: &mut [u32]| {
            let run = old[b]..old[b] + self.stayed[b];
            keys.copy_within(run.clone(), new[b]);
            hulls.copy_within(run.clone(), new[b]);
            ids.copy_within(run, new[b]);
        };
        for b in (0..=count).rev().filter(|&b| new[b] > old[b]) {
            shift(b, keys, hulls, ids);
        }
        for b in (0..=count).filter(|&b| new[b] < old[b]) {
            shift(b, keys, hulls, ids);
        }
        // Each band sorted, its newcomers inserted; then its guests.
        if movers.len() > 0 {
            sort_movers(movers, order, spare);
        }
        guests.clear();
        guest_starts.clear();
        guest_starts.push(0);
        let mut mover_at = 0;
        for b in 0..=count {
            let out = new[b]..new[b + 1];
            let stayed = out.start..out.start + self.stayed[b];
            let moved = mover_at..mover_at + (out.len() - stayed.len());
            mover_at = moved.end;
            if b == count {
                // The boxes without a key: in any order.
                for (at, m) in (stayed.end..).zip(moved) {
                    keys[at] = movers.keys[m];
                    hulls[at] = movers.hulls[m];
                    ids[at] = movers.ids[m];
                }
                break;
            }
            let band_arrays = (
                &mut keys[out.clone()],
                &mut hulls[out.clone()],
                &mut ids[out.clone()],
            );
            finish_band(band_arrays, stayed.len(), movers, moved, order, spare);
            let homes = (&keys[out.clone()], &hulls[out.clone()], &ids[out]);
            end_guests(
                (guests, guest_starts),
                homes,
                b,
                b + 1 < count,
                bands,
                spare,
            );
        }
        self.guest_at.clear();
        for b in 0..count {
            self.guest_at
                .push((0, guest_starts[b]..guest_starts[b + 1]));
        }
        self.starts[count]
    }
}

/// Closes up band `b`, the entries `band` of the arrays: the boxes still
/// in it go to its front in their order, a run at a time, and the ones
/// that left are pushed to `movers` with their new home band (`gaps` is
/// working space). Returns the boxes that stayed and, if `TOP`, the
/// greatest value across the bands they reach.
fn close_up<const TOP: bool>(
    (keys, hulls, ids): (&mut [f32], &mut [Packed], &mut [u32]),
    band: Range<usize>,
    b: usize,
    edges: &[f32],
    bands: &Bands,
    movers: &mut Run,
    gaps: &mut Vec<usize>,
) -> (usize, f32) {
    let count = bands.count;
    let mut top = f32::NEG_INFINITY;
    gaps.clear();
    for k in band.clone() {
        let key = keys[k];
        let stays = if b == count {
            key == NO_KEY
        } else {
            let v = lo(&hulls[k], bands.across);
            key != NO_KEY && edges[b] <= v && v < edges[b + 1]
        };
        if stays {
            if TOP {
                top = top.max(hi(&hulls[k], bands.across));
            }
        } else {
            let home = if key == NO_KEY {
                count
            } else {
                bands.of(lo(&hulls[k], bands.across))
            };
            movers.push(key, hulls[k], ids[k], home as u32);
            gaps.push(k);
        }
    }
    let mut w = band.start;
    let mut r = band.start;
    for &gap in gaps.iter().chain(std::iter::once(&band.end)) {
        if w != r {
            keys.copy_within(r..gap, w);
            hulls.copy_within(r..gap, w);
            ids.copy_within(r..gap, w);
        }
        w += gap - r;
        r = gap + 1;
    }
    (w - band.start, top)
}

/// Splits per-band `items` into one part per group of bands in `bounds`.
fn per_group<'a, T>(mut items: &'a mut [T], bounds: &[Range<usize>]) -> Vec<&'a mut [T]> {
    bounds
        .iter()
        .map(|range| {
            let (part, rest) = std::mem::take(&mut items).split_at_mut(range.len());
            items = rest;
            part
        })
        .collect()
}

/// Closes up one group's bands (see [`close_up`]), last step's boxes of
/// those bands in `arrived`, its movers in the group's buffer; notes per
/// band the boxes that stayed and the greatest value across the bands
/// that one of them reaches.
fn close_up_group(
    arrived: Stretch,
    (stayed_in, tops): (&mut [usize], &mut [f32]),
    group: &mut Group,
    old: &[usize],
    edges: &[f32],
    bands: &Bands,
) {
    let a = arrived;
    group.movers.clear();
    for (k, b) in a.bands.clone().enumerate() {
        let band = old[b] - a.offset..old[b + 1] - a.offset;
        let arrays = (&mut *a.keys, &mut *a.hulls, &mut *a.ids);
        let (stayed, top) = close_up::<true>(
            arrays,
            band,
            b,
            edges,
            bands,
            &mut group.movers,
            &mut group.gaps,
        );
        (stayed_in[k], tops[k]) = (stayed, top);
    }
}

/// Finishes one group's bands in its stretch of the new arrays: each
/// band's stayers copied in, sorted, its movers inserted; then its guests,
/// the first band's picked out of the bands below.
fn finish_group(s: Stretch, group: &mut Group, c: &Closed) {
    let Stretch {
        bands: range,
        offset,
        keys,
        hulls,
        ids,
    } = s;
    let count = c.bands.count;
    let Group {
        guests,
        guest_starts,
        order,
        spare,
        ..
    } = group;
    // The first band's guests: the boxes of the bands below whose reach
    // ends in it or above, stayers and movers alike.
    let b0 = range.start;
    let from = (0..b0).find(|&b| c.reach[b] as usize >= b0).unwrap_or(b0);
    guests.clear();
    let across = c.bands.across;
    for b in from..b0 {
        let run = c.old_starts[b]..c.old_starts[b] + c.stayed[b];
        let moved = c.mover_starts[b]..c.mover_starts[b + 1];
        let (keys, hulls, ids) = (c.keys, c.hulls, c.ids);
        let stayers = run.map(|k| (keys[k], &hulls[k], ids[k]));
        let m = c.movers;
        let movers = moved.map(|k| (m.keys[k], &m.hulls[k], m.ids[k]));
        for (key, hull, id) in stayers.chain(movers) {
            let end = c.bands.of(hi(hull, across)) as u32 + 1;
            if end as usize > b0 {
                guests.push(key, *hull, id, end);
            }
        }
    }
    if guests.len() > 0 {
        guests.sort(0..guests.len(), order, spare);
    }

    guest_starts.clear();
    guest_starts.push(0);
    for band in range.start..range.end {
        let out = c.starts[band] - offset..c.starts[band + 1] - offset;
        let stayed = c.stayed[band];
        let from = c.old_starts[band]..c.old_starts[band] + stayed;
        let moved = c.mover_starts[band]..c.mover_starts[band + 1];
        keys[out.start..out.start + stayed].copy_from_slice(&c.keys[from.clone()]);
        hulls[out.start..out.start + stayed].copy_from_slice(&c.hulls[from.clone()]);
        ids[out.start..out.start + stayed].copy_from_slice(&c.ids[from]);
        if band == count {
            // The boxes without a key: in any order.
            let at = out.start + stayed;
            let m = c.movers;
            keys[at..out.end].copy_from_slice(&m.keys[moved.clone()]);
            hulls[at..out.end].copy_from_slice(&m.hulls[moved.clone()]);
            ids[at..out.end].copy_from_slice(&m.ids[moved]);
            break;
        }
        let band_arrays = (
            &mut keys[out.clone()],
            &mut hulls[out.clone()],
            &mut ids[out.clone()],
        );
        finish_band(band_arrays, stayed, c.movers, moved, order, spare);
        let homes = (&keys[out.clone()], &hulls[out.clone()], &ids[out]);
        let next = band + 1 < range.end.min(count);
        end_guests((guests, guest_starts), homes, band, next, c.bands, spare);
    }
}
