//! A layout made anew: every box's home band found ([`Layout::classify`]),
//! then each box copied to its home band in arrival order
//! ([`Layout::lay_out`]). A box that arrived from the band it is in goes to
//! the front of the band, nearly sorted; one that moved in is held aside
//! and inserted once the band is sorted.
//!
//! The bands are split into groups of about equal size, one per thread;
//! each group owns its stretch of the arrays and its guests (its first
//! band's guests it picks out of the arriving boxes), so the groups are
//! laid out at once without sharing anything they write.

use super::{
    end_guests, finish_band, groups_of_bands, run_each, set_starts, sort_movers, stretches, Group,
    GroupView, Layout, Stretch, ThenEach,
};
use crate::detect::sweep::bands::Bands;
use crate::detect::sweep::hull::{hi, Packed};
use crate::detect::sweep::order::{Boxes, NO_KEY};
use crate::team::{self, Team};
use std::ops::Range;
use std::sync::Mutex;

/// What every group reads: the arriving boxes and what [`Layout::classify`]
/// found of them.
struct Arrivals<'a> {
    slots: &'a Boxes,
    n: usize,
    home: &'a [u32],
    starts: &'a [usize],
    old_starts: &'a [usize],
    reach: &'a [u32],
    bands: &'a Bands,
}

impl Layout {
    /// Finds the home band of each of the first `n` boxes of `slots` and
    /// counts each band's homes, shared with `team`.
    pub(crate) fn classify(&mut self, slots: &Boxes, n: usize, bands: &Bands, team: &Team) {
        let buckets = bands.count + 1;
        self.home.resize(n, 0);
        self.counts.clear();
        self.counts.resize(buckets, 0);
        self.reach.clear();
        self.reach.resize(buckets, 0);
        let (keys, hulls) = (&slots.keys[..n], &slots.hulls[..n]);
        let threads = team.threads();
        let homes = team::shares_mut(&mut self.home, threads);
        let found: Vec<Mutex<(Vec<u32>, Vec<u32>)>> = (0..threads)
            .map(|_| Mutex::new((vec![0; buckets], vec![0; buckets])))
            .collect();
        team.run(&|k| {
            let share = team::share(n, threads, k);
            let mut found = found[k].lock().expect("a member's counts");
            let (counts, reach) = &mut *found;
            let home = &mut homes[k].lock().expect("a share");
            classify(
                &keys[share.clone()],
                &hulls[share],
                bands,
                home,
                counts,
                reach,
            );
        });
        drop(homes);
        for found in found {
            let (counts, reach) = found.into_inner().expect("a member's counts");
            self.add_counts(&counts, &reach);
        }
    }

    /// Adds one part's counts and reaches to the whole's.
    fn add_counts(&mut self, counts: &[u32], reach: &[u32]) {
        for (all, part) in self.counts.iter_mut().zip(counts) {
            *all += part;
        }
        for (all, part) in self.reach.iter_mut().zip(reach) {
            *all = (*all).max(*part);
        }
    }

    /// Lays out the first `n` boxes of `slots`, as [`Layout::classify`]
    /// found them, band by band in groups of bands, one a member of
    /// `team`, calling `then_each` with each group as soon as it is laid
    /// out, by the thread that laid it out; leaves them in `slots`,
    /// sentinel last; returns the boxes with a key, which come first.
    pub(crate) fn lay_out(
        &mut self,
        slots: &mut Boxes,
        n: usize,
        bands: &Bands,
        team: &Team,
        then_each: ThenEach,
    ) -> usize {
        let (count, groups) = (bands.count, team.threads());
        std::mem::swap(&mut self.starts, &mut self.old_starts);
        set_starts(&self.counts, &mut self.starts, n);
        // Last step's layout is what the boxes arrive in only if it had as
        // many bands and boxes.
        if self.old_starts.len() != self.starts.len() || self.old_starts.last() != Some(&n) {
            self.old_starts.clear();
        }
        self.keys.resize(n + 1, NO_KEY);
        self.hulls.resize(n + 1, [0.0; 8]);
        self.ids.resize(n + 1, u32::MAX);
        self.keys[n] = NO_KEY;
        self.ids[n] = u32::MAX;

        // Groups of bands, the last also holding the boxes without a key.
        let bounds = groups_of_bands(&self.starts, groups);
        self.groups
            .resize_with(bounds.len().max(self.groups.len()), Group::default);
        let Layout {
            starts,
            old_starts,
            groups: group_bufs,
            home,
            reach,
            keys,
            hulls,
            ids,
            ..
        } = self;
        let arrivals = Arrivals {
            slots,
            n,
            home,
            starts,
            old_starts,
            reach,
            bands,
        };
        let stretches = stretches(starts, keys, hulls, ids, &bounds);
        // Stretch `k` to member `k`: the boxes whose hulls it made, near
        // enough.
        let work: Vec<_> = (stretches.into_iter().zip(group_bufs.iter_mut()))
            .enumerate()
            .collect();
        run_each(work, team, |(index, (s, g))| {
            let (range, offset) = (s.bands.start..s.bands.end.min(count), s.offset);
            let laid_out = lay_out_group(s, g, &arrivals);
            then_each(GroupView::of(
                index,
                range,
                offset,
                laid_out,
                arrivals.starts,
                g,
            ));
        });

        self.hand_over(slots, &bounds, count);
        if self.kept != Some(*bands) {
            self.set_edges(bands);
        }
        self.kept = Some(*bands);
        self.starts[count]
    }
}

/// Finds each box's home band (keys and hulls, in arrival order) into
/// `home`, counting the homes of each band in `counts` and noting the
/// furthest band they reach in `reach`.
fn classify(
    keys: &[f32],
    hulls: &[Packed],
    bands: &Bands,
    home: &mut [u32],
    counts: &mut [u32],
    reach: &mut [u32],
) {
    let none = bands.count as u32;
    // Boxes arrive band by band, so the counts are kept for a run of boxes
    // with the same home and written when the home changes: each box
    // adding to the count in memory would wait for the box before it.
    let (mut run_home, mut run, mut run_reach) = (none, 0, none);
    for ((&key, hull), home) in keys.iter().zip(hulls).zip(home) {
        let (h, last) = if key == NO_KEY {
            (none, none)
        } else {
            let (first, last) = bands.span(hull);
            (first as u32, last as u32)
        };
        *home = h;
        if h != run_home {
            counts[run_home as usize] += run;
            let r = &mut reach[run_home as usize];
            *r = (*r).max(run_reach);
            (run_home, run, run_reach) = (h, 0, 0);
        }
        run += 1;
        run_reach = run_reach.max(last);
    }
    counts[run_home as usize] += run;
    let r = &mut reach[run_home as usize];
    *r = (*r).max(run_reach);
}

/// Consecutive ranges of the bands that start at `starts` (one past the
/// last band's start being its end), at most `groups` of them, each holding
/// about the same number of entries.
pub(super) fn group_bounds(starts: &[usize], groups: usize) -> Vec<Range<usize>> {
    let count = starts.len() - 1;
    let (first_start, total) = (starts[0], starts[count]);

    let groups = groups.clamp(1, count.max(1));
    let mut bounds = Vec::with_capacity(groups);
    let mut first = 0;
    for g in 1..=groups {
        let target = first_start + (total - first_start) * g / groups;
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

/// Lays out one group's stretch (see the [module docs](self)); returns
/// its keys, hulls and ids, laid out.
fn lay_out_group<'a>(
    s: Stretch<'a>,
    group: &mut Group,
    a: &Arrivals,
) -> (&'a [f32], &'a [Packed], &'a [u32]) {
    let Stretch {
        bands: range,
        offset,
        keys,
        hulls,
        ids,
    } = s;
    let count = a.bands.count;
    let (b0, b1) = (range.start as u32, range.end as u32);
    let Group {
        guests,
        guest_starts,
        movers,
        order,
        spare,
        ..
    } = group;
    // The lowest band whose homes reach into the group's first band.
    let from = (0..b0).find(|&b| a.reach[b as usize] >= b0).unwrap_or(b0);
    let across = a.bands.across;

    // Every box whose home is in the group: one that arrived from the
    // same band to the front of its band, in arrival order; one that
    // moved, aside. The boxes from below that reach into the first band:
    // its guests.
    let mut cursor: Vec<usize> = a.starts[range.clone()].iter().map(|s| s - offset).collect();
    movers.clear();
    guests.clear();
    let (slots, old) = (a.slots, a.old_starts);
    // The band each box arrived from; with no layout to arrive from, every
    // box counts as arriving from its home.
    let mut came_from = 0usize;
    let mut next_old = old.get(1).copied().unwrap_or(usize::MAX);
    for k in 0..a.n {
        if k == next_old {
            came_from += 1;
            while old[came_from + 1] == k {
                came_from += 1;
            }
            next_old = old[came_from + 1];
        }
        let h = a.home[k];
        if (b0..b1).contains(&h) {
            let (key, hull, id) = (slots.keys[k], slots.hulls[k], slots.ids[k]);
            if old.is_empty() || h as usize == came_from || h as usize == count {
                let at = &mut cursor[(h - b0) as usize];
                keys[*at] = key;
                hulls[*at] = hull;
                ids[*at] = id;
                *at += 1;
            } else {
                movers.push(key, hull, id, h);
            }
        } else if (from..b0).contains(&h) {
            let end = a.bands.of(hi(&slots.hulls[k], across)) as u32 + 1;
            if end > b0 {
                guests.push(slots.keys[k], slots.hulls[k], slots.ids[k], end);
            }
        }
    }
    // The movers by band, then by key within it.
    if movers.len() > 0 {
        sort_movers(movers, order, spare);
    }
    if guests.len() > 0 {
        guests.sort(0..guests.len(), order, spare);
    }

    guest_starts.clear();
    guest_starts.push(0);
    let mut mover_at = 0;
    for band in range.start..range.end.min(count) {
        let k = band - range.start;
        let out = a.starts[band] - offset..a.starts[band + 1] - offset;
        let stayed = out.start..cursor[k];
        let moved = mover_at..mover_at + (out.end - stayed.end);
        debug_assert!(movers.ends[moved.clone()]
            .iter()
            .all(|&b| b as usize == band));
        let band_arrays = (
            &mut keys[out.clone()],
            &mut hulls[out.clone()],
            &mut ids[out.clone()],
        );
        finish_band(
            band_arrays,
            stayed.len(),
            movers,
            moved.clone(),
            order,
            spare,
        );
        mover_at = moved.end;
        // The next band's guests: this band's homes and guests that reach
        // into it, merged in key order, after this band's guests.
        let homes = (&keys[out.clone()], &hulls[out.clone()], &ids[out]);
        let next = band + 1 < range.end.min(count);
        end_guests((guests, guest_starts), homes, band, next, a.bands, spare);
    }
    (keys, hulls, ids)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_split_bands_by_entries() {
        let starts = vec![0, 10, 11, 12, 40];
        assert_eq!(group_bounds(&starts, 1), vec![0..4]);
        assert_eq!(group_bounds(&starts, 2), vec![0..3, 3..4]);
        let all: usize = group_bounds(&starts, 8).iter().map(|r| r.len()).sum();
        assert_eq!(all, 4);
    }
}
