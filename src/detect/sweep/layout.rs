//! The boxes laid out band by band: each box copied once, into the band
//! holding its least value across the bands (its *home*), each band sorted;
//! the boxes that reach up into a band from below (its *guests*) listed
//! beside it, sorted too.
//!
//! A pair of overlapping boxes is reported in the band holding the larger
//! of their two least values: there both are homes, or one is a home and
//! the other a guest. Two guests of a band are never a pair it reports, so
//! a band is swept as its homes among themselves and its homes against its
//! guests ([`super::scan`]), and no pair needs a test of which band reports
//! it.
//!
//! The homes, band by band, are the order next step's hulls are made in,
//! so a step lays out boxes that arrive nearly in place:
//! 1. [`Layout::classify`]: every box's home band, and per band how many
//!    homes it has and how far up they reach;
//! 2. [`Layout::lay_out`]: each box copied to its home band in arrival
//!    order. A box that stays in the band it came from (nearly all of them)
//!    goes to the front, still nearly sorted, and is finished by an
//!    insertion sort in place; a box that moved in from another band is
//!    held aside, and the few that came to a band are sorted and merged in
//!    from the back. Each band's guests are the entries of the band below
//!    that reach up into it, taken in sorted order as that band is done.
//!
//! The bands are split into groups of about equal size, one per thread;
//! each group owns its stretch of the arrays and its guests (its first
//! band's guests it picks out of the arriving boxes), so the groups are
//! laid out at once without sharing anything they write.

use super::bands::Bands;
use super::hull::{hi, lo, Packed};
use super::order::{insert, Boxes, NO_KEY};
use crate::team::{self, Team};
use std::ops::Range;
use std::sync::Mutex;

/// Moves an insertion sort of one band may make per entry before the band
/// is sorted by radix instead.
const MOVES_PER_ENTRY: usize = 8;

/// Boxes classified at a time by one thread.
const CLASSIFY_CHUNK: usize = 1 << 15;

/// The boxes band by band (see the [module docs](self)).
#[derive(Debug, Default)]
pub(crate) struct Layout {
    /// Where each band's homes start among the laid-out boxes, then where
    /// the boxes without a key start, then their end: `count + 2` values.
    pub starts: Vec<usize>,
    /// The same for last step's layout, which the boxes arrive in (empty
    /// when they arrive in another order).
    old_starts: Vec<usize>,
    /// Per band, the group holding its guests and their range there.
    guest_at: Vec<(u32, Range<u32>)>,
    /// Per group, its bands' guests one band after another, and its
    /// working buffers; kept from step to step.
    groups: Vec<Group>,
    /// Per box (in arrival order), its home band; `count` for a box
    /// without a key.
    home: Vec<u32>,
    /// Per band (and the boxes without a key), its homes, then the
    /// furthest band they reach.
    counts: Vec<u32>,
    reach: Vec<u32>,
    /// The bands the boxes are laid out in, while the arriving boxes are
    /// in that layout's order (so that [`Layout::keep`] can update it).
    kept: Option<Bands>,
    /// Per band (and the boxes without a key), the boxes that stayed in it
    /// this step.
    stayed: Vec<usize>,
    /// The least value of each band (`-inf` for the first), then `+inf`,
    /// for the bands in `kept`.
    edges: Vec<f32>,
    /// Where boxes left their band this step, in order.
    gaps: Vec<usize>,
    /// The laid-out keys, hulls and ids, exchanged with the arriving
    /// boxes' arrays once laid out.
    keys: Vec<f32>,
    hulls: Vec<Packed>,
    ids: Vec<u32>,
}

/// Entries as parallel arrays, with the band after the last they reach.
#[derive(Debug, Default)]
struct Run {
    keys: Vec<f32>,
    hulls: Vec<Packed>,
    ids: Vec<u32>,
    ends: Vec<u32>,
}

impl Run {
    fn clear(&mut self) {
        self.keys.clear();
        self.hulls.clear();
        self.ids.clear();
        self.ends.clear();
    }

    fn len(&self) -> usize {
        self.keys.len()
    }

    #[inline]
    fn push(&mut self, key: f32, hull: Packed, id: u32, end: u32) {
        self.keys.push(key);
        self.hulls.push(hull);
        self.ids.push(id);
        self.ends.push(end);
    }

    /// Appends the entries `range` of `other`.
    fn extend_from(&mut self, other: &Run, range: Range<usize>) {
        self.keys.extend_from_slice(&other.keys[range.clone()]);
        self.hulls.extend_from_slice(&other.hulls[range.clone()]);
        self.ids.extend_from_slice(&other.ids[range.clone()]);
        self.ends.extend_from_slice(&other.ends[range]);
    }

    /// Sorts the entries `range` by key (through `order` and `spare`).
    fn sort(&mut self, range: Range<usize>, order: &mut Vec<(f32, u32)>, spare: &mut Run) {
        order.clear();
        order.extend(
            self.keys[range.clone()]
                .iter()
                .zip(range.start as u32..)
                .map(|(&key, at)| (key, at)),
        );
        radsort::sort_by_key(order, |k| k.0);
        spare.clear();
        for &(key, at) in order.iter() {
            let at = at as usize;
            spare.push(key, self.hulls[at], self.ids[at], self.ends[at]);
        }
        let r = range.clone();
        self.keys[r.clone()].copy_from_slice(&spare.keys);
        self.hulls[r.clone()].copy_from_slice(&spare.hulls);
        self.ids[r.clone()].copy_from_slice(&spare.ids);
        self.ends[r].copy_from_slice(&spare.ends);
    }
}

/// One group's guests and working buffers.
#[derive(Debug, Default)]
struct Group {
    /// The guests of the group's bands, one band after another.
    guests: Run,
    /// Where each of the group's bands' guests start in `guests`, and
    /// their end.
    guest_starts: Vec<u32>,
    /// The boxes that moved into the group's bands from other bands, with
    /// their home band in place of an end.
    movers: Run,
    /// Keys and positions, to sort.
    order: Vec<(f32, u32)>,
    /// Spare entries for sorting.
    spare: Run,
}

/// One group's stretch of the laid-out arrays: its bands and their boxes.
struct Stretch<'a> {
    bands: Range<usize>,
    /// The first entry of the stretch.
    offset: usize,
    keys: &'a mut [f32],
    hulls: &'a mut [Packed],
    ids: &'a mut [u32],
}

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
    /// counts each band's homes: on the current rayon pool when `parallel`,
    /// else shared with `team` if there is one.
    pub(crate) fn classify(
        &mut self,
        slots: &Boxes,
        n: usize,
        bands: &Bands,
        parallel: bool,
        team: Option<&Team>,
    ) {
        let buckets = bands.count + 1;
        self.home.resize(n, 0);
        self.counts.clear();
        self.counts.resize(buckets, 0);
        self.reach.clear();
        self.reach.resize(buckets, 0);
        let (keys, hulls) = (&slots.keys[..n], &slots.hulls[..n]);
        if parallel && n > CLASSIFY_CHUNK {
            use rayon::prelude::*;
            let found: Vec<(Vec<u32>, Vec<u32>)> = self
                .home
                .par_chunks_mut(CLASSIFY_CHUNK)
                .zip(keys.par_chunks(CLASSIFY_CHUNK))
                .zip(hulls.par_chunks(CLASSIFY_CHUNK))
                .map(|((home, keys), hulls)| {
                    let (mut counts, mut reach) = (vec![0; buckets], vec![0; buckets]);
                    classify(keys, hulls, bands, home, &mut counts, &mut reach);
                    (counts, reach)
                })
                .collect();
            for (counts, reach) in found {
                self.add_counts(&counts, &reach);
            }
        } else if let Some(team) = team {
            let threads = team.threads();
            let homes = team::shares_mut(&mut self.home, threads);
            let found: Vec<Mutex<(Vec<u32>, Vec<u32>)>> = (0..threads)
                .map(|_| Mutex::new((vec![0; buckets], vec![0; buckets])))
                .collect();
            team.run(&|k| {
                let share = team::share(n, threads, k);
                let mut found = found[k].lock().expect("a member's counts");
                let (counts, reach) = &mut *found;
                classify(
                    &keys[share.clone()],
                    &hulls[share],
                    bands,
                    &mut homes[k].lock().expect("a share"),
                    counts,
                    reach,
                );
            });
            drop(homes);
            for found in found {
                let (counts, reach) = found.into_inner().expect("a member's counts");
                self.add_counts(&counts, &reach);
            }
        } else {
            classify(
                keys,
                hulls,
                bands,
                &mut self.home,
                &mut self.counts,
                &mut self.reach,
            );
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
    /// found them, band by band in `groups` groups (when more than one,
    /// shared with `team` if there is one, else on the current rayon pool),
    /// and leaves them in `slots`, sentinel last; returns the boxes with a
    /// key, which come first.
    pub(crate) fn lay_out(
        &mut self,
        slots: &mut Boxes,
        n: usize,
        bands: &Bands,
        groups: usize,
        team: Option<&Team>,
    ) -> usize {
        let count = bands.count;
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
        let mut bounds = group_bounds(&self.starts[..=count], groups);
        match bounds.last_mut() {
            Some(last) => last.end = count + 1,
            None => bounds.push(0..count + 1),
        }
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
        let lay = |(s, g): (Stretch, &mut Group)| lay_out_group(s, g, &arrivals);
        if let Some(team) = team.filter(|_| stretches.len() > 1) {
            // Stretch `k` to member `k` (there are no more stretches than
            // members): the boxes whose hulls it made, near enough.
            let count = stretches.len();
            let work: Vec<Mutex<Option<(Stretch, &mut Group)>>> = stretches
                .into_iter()
                .zip(group_bufs.iter_mut())
                .map(|w| Mutex::new(Some(w)))
                .collect();
            debug_assert!(count <= team.threads());
            team.run(&|k| {
                let taken = work
                    .get(k)
                    .and_then(|w| w.lock().expect("a stretch").take());
                if let Some(w) = taken {
                    lay(w);
                }
            });
        } else if stretches.len() > 1 {
            use rayon::prelude::*;
            stretches
                .into_par_iter()
                .zip(group_bufs.par_iter_mut())
                .for_each(lay);
        } else {
            stretches
                .into_iter()
                .zip(group_bufs.iter_mut())
                .for_each(lay);
        }

        self.guest_at.clear();
        for (g, range) in bounds.iter().enumerate() {
            let gs = &self.groups[g].guest_starts;
            for b in range.start..range.end.min(count) {
                let k = b - range.start;
                self.guest_at.push((g as u32, gs[k]..gs[k + 1]));
            }
        }
        std::mem::swap(&mut slots.keys, &mut self.keys);
        std::mem::swap(&mut slots.hulls, &mut self.hulls);
        std::mem::swap(&mut slots.ids, &mut self.ids);
        if self.kept != Some(*bands) {
            self.edges.clear();
        }
        self.kept = Some(*bands);
        self.starts[count]
    }

    /// Lays out the first `n` boxes of `slots` again in place, when they
    /// arrive in the order of last step's layout in the same `bands` (their
    /// hulls made anew); returns the boxes with a key (which come first),
    /// or `None`, changing nothing, when they do not.
    ///
    /// Each band's boxes that stayed in it are closed up at its front in
    /// one pass, and the ones that left are held aside; the bands' runs
    /// then move to their new starts (a copy of whole runs, in the order
    /// that overwrites nothing unmoved); each band's stayers are finished
    /// by insertion and its newcomers merged in from the back; and the
    /// guests are listed band by band. On one thread.
    pub(crate) fn keep(&mut self, slots: &mut Boxes, n: usize, bands: &Bands) -> Option<usize> {
        let count = bands.count;
        if self.kept != Some(*bands)
            || self.starts.len() != count + 2
            || self.starts[count + 1] != n
            || slots.len() != n
        {
            return None;
        }
        if self.groups.is_empty() {
            self.groups.push(Group::default());
        }
        let Group {
            guests,
            guest_starts,
            movers,
            order,
            spare,
        } = &mut self.groups[0];
        let (keys, hulls, ids) = (
            &mut slots.keys[..n],
            &mut slots.hulls[..n],
            &mut slots.ids[..n],
        );
        // The bands' edges, so that a box that stays is told by two
        // comparisons.
        if self.edges.len() != count + 1 {
            self.edges.clear();
            self.edges.push(f32::NEG_INFINITY);
            self.edges.extend((1..count).map(|b| bands.edge(b)));
            self.edges.push(f32::INFINITY);
        }
        // The boxes that left their band aside; each band's stayers closed
        // up at its front, a run at a time.
        std::mem::swap(&mut self.starts, &mut self.old_starts);
        let (old, edges) = (&self.old_starts, &self.edges);
        movers.clear();
        self.stayed.clear();
        for b in 0..=count {
            let band = old[b]..old[b + 1];
            self.gaps.clear();
            for k in band.clone() {
                let key = keys[k];
                let stays = if b == count {
                    key == NO_KEY
                } else {
                    let v = lo(&hulls[k], bands.across);
                    key != NO_KEY && edges[b] <= v && v < edges[b + 1]
                };
                if !stays {
                    let home = if key == NO_KEY {
                        count
                    } else {
                        bands.of(lo(&hulls[k], bands.across))
                    };
                    movers.push(key, hulls[k], ids[k], home as u32);
                    self.gaps.push(k);
                }
            }
            let mut w = band.start;
            let mut r = band.start;
            for &gap in self.gaps.iter().chain(std::iter::once(&band.end)) {
                if w != r {
                    keys.copy_within(r..gap, w);
                    hulls.copy_within(r..gap, w);
                    ids.copy_within(r..gap, w);
                }
                w += gap - r;
                r = gap + 1;
            }
            self.stayed.push(w - band.start);
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
        // Each band sorted, its newcomers merged in; then its guests.
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
            let own = guest_starts[b] as usize..guests.len();
            guest_starts.push(guests.len() as u32);
            if b + 1 < count {
                let homes = (&keys[out.clone()], &hulls[out.clone()], &ids[out]);
                push_next_guests(guests, own, homes, b, bands, spare);
            }
        }
        self.guest_at.clear();
        for b in 0..count {
            self.guest_at
                .push((0, guest_starts[b]..guest_starts[b + 1]));
        }
        Some(self.starts[count])
    }

    /// Consecutive ranges of bands, at most `groups` of them, each holding
    /// about the same number of homes.
    pub(crate) fn group_bounds(&self, groups: usize) -> Vec<Range<usize>> {
        group_bounds(&self.starts[..self.starts.len() - 1], groups)
    }

    /// Where the homes of band `band` lie among the laid-out boxes.
    pub(crate) fn homes(&self, band: usize) -> Range<usize> {
        self.starts[band]..self.starts[band + 1]
    }

    /// The guests of band `band`: keys, hulls and ids, sorted by key.
    pub(crate) fn guests(&self, band: usize) -> (&[f32], &[Packed], &[u32]) {
        let (g, range) = &self.guest_at[band];
        let run = &self.groups[*g as usize].guests;
        let r = range.start as usize..range.end as usize;
        (&run.keys[r.clone()], &run.hulls[r.clone()], &run.ids[r])
    }

    /// Forgets last step's layout: the boxes will arrive in another order.
    pub(crate) fn forget(&mut self) {
        self.starts.clear();
        self.kept = None;
        self.edges.clear();
    }

    /// Guests in all bands.
    pub(crate) fn guest_count(&self) -> usize {
        self.guest_at.iter().map(|(_, r)| r.len()).sum()
    }
}

/// Sets `starts` to where each band's homes start, from the homes counted
/// in each (`n` in all), and their end.
fn set_starts(counts: &[u32], starts: &mut Vec<usize>, n: usize) {
    starts.clear();
    let mut total = 0;
    for &c in counts {
        starts.push(total);
        total += c as usize;
    }
    starts.push(total);
    debug_assert_eq!(total, n);
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
fn group_bounds(starts: &[usize], groups: usize) -> Vec<Range<usize>> {
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

/// Splits the arrays into stretches of whole bands, one per range of
/// `bounds`.
fn stretches<'a>(
    starts: &[usize],
    mut keys: &'a mut [f32],
    mut hulls: &'a mut [Packed],
    mut ids: &'a mut [u32],
    bounds: &[Range<usize>],
) -> Vec<Stretch<'a>> {
    let mut out = Vec::with_capacity(bounds.len());
    let mut at = 0;
    for bands in bounds {
        let (offset, end) = (starts[bands.start], starts[bands.end]);
        debug_assert_eq!(offset, at);
        let len = end - offset;
        let (k, rest_k) = std::mem::take(&mut keys).split_at_mut(len);
        let (h, rest_h) = std::mem::take(&mut hulls).split_at_mut(len);
        let (i, rest_i) = std::mem::take(&mut ids).split_at_mut(len);
        (keys, hulls, ids) = (rest_k, rest_h, rest_i);
        out.push(Stretch {
            bands: bands.clone(),
            offset,
            keys: k,
            hulls: h,
            ids: i,
        });
        at = end;
    }
    out
}

/// Lays out one group's stretch (see the [module docs](self)).
fn lay_out_group(s: Stretch, group: &mut Group, a: &Arrivals) {
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
        let own = guest_starts[k] as usize..guests.len();
        guest_starts.push(guests.len() as u32);
        if band + 1 < range.end.min(count) {
            let homes = (&keys[out.clone()], &hulls[out.clone()], &ids[out]);
            push_next_guests(guests, own, homes, band, a.bands, spare);
        }
    }
}

/// Appends to `guests` the guests of the band after `band`: the homes of
/// `band` (sorted) and its guests `own` (a range of `guests`, sorted) that
/// reach beyond it, merged in key order (through `spare`).
fn push_next_guests(
    guests: &mut Run,
    own: Range<usize>,
    (keys, hulls, ids): (&[f32], &[Packed], &[u32]),
    band: usize,
    bands: &Bands,
    spare: &mut Run,
) {
    let beyond = band as u32 + 1;
    spare.clear();
    // The next home that reaches beyond the band, and the band after the
    // last it reaches: one comparison with the next band's edge a home,
    // the band worked out only for those that reach.
    let edge = bands.edge(band + 1);
    let next_home = |i: &mut usize| {
        while *i < keys.len() {
            let top = hi(&hulls[*i], bands.across);
            if top >= edge {
                return Some(bands.of(top) as u32 + 1);
            }
            *i += 1;
        }
        None
    };
    let (mut i, mut j) = (0, own.start);
    let mut end_i = next_home(&mut i);
    loop {
        while j < own.end && guests.ends[j] <= beyond {
            j += 1;
        }
        let home_first = match (end_i, j < own.end) {
            (None, false) => break,
            (Some(_), false) => true,
            (None, true) => false,
            (Some(_), true) => keys[i] <= guests.keys[j],
        };
        if home_first {
            let end = end_i.expect("a home that reaches on");
            spare.push(keys[i], hulls[i], ids[i], end);
            i += 1;
            end_i = next_home(&mut i);
        } else {
            spare.push(
                guests.keys[j],
                guests.hulls[j],
                guests.ids[j],
                guests.ends[j],
            );
            j += 1;
        }
    }
    let len = spare.len();
    guests.extend_from(spare, 0..len);
}

/// Sorts movers by band, then by key (through `order` and `spare`).
fn sort_movers(movers: &mut Run, order: &mut Vec<(f32, u32)>, spare: &mut Run) {
    order.clear();
    order.extend(movers.keys.iter().zip(0u32..).map(|(&k, at)| (k, at)));
    let bands = &movers.ends;
    order.sort_unstable_by(|x, y| {
        (bands[x.1 as usize].cmp(&bands[y.1 as usize])).then(x.0.total_cmp(&y.0))
    });
    spare.clear();
    for &(key, at) in order.iter() {
        let at = at as usize;
        spare.push(key, movers.hulls[at], movers.ids[at], movers.ends[at]);
    }
    std::mem::swap(movers, spare);
}

/// Sorts boxes by key in place: by insertion while that stays short (they
/// arrive nearly sorted), else by radix through `order` and `spare`.
fn sort_in_place(
    keys: &mut [f32],
    hulls: &mut [Packed],
    ids: &mut [u32],
    order: &mut Vec<(f32, u32)>,
    spare: &mut Run,
) {
    let budget = MOVES_PER_ENTRY * keys.len() + 16;
    if insert((&mut *keys, &mut *hulls, &mut *ids), 1, budget, false).is_some() {
        return;
    }
    // Too far from sorted: radix sort, then gather.
    order.clear();
    order.extend(keys.iter().zip(0u32..).map(|(&k, at)| (k, at)));
    radsort::sort_by_key(order, |k| k.0);
    spare.clear();
    for &(key, at) in order.iter() {
        let at = at as usize;
        spare.push(key, hulls[at], ids[at], 0);
    }
    keys.copy_from_slice(&spare.keys);
    hulls.copy_from_slice(&spare.hulls);
    ids.copy_from_slice(&spare.ids);
}

/// Finishes a band whose first `stayed` entries are the boxes that stayed
/// in it (nearly sorted) and whose rest is free: sorts them in place and
/// inserts its newcomers, `moved` of the sorted `movers`.
fn finish_band(
    (keys, hulls, ids): (&mut [f32], &mut [Packed], &mut [u32]),
    stayed: usize,
    movers: &Run,
    moved: Range<usize>,
    order: &mut Vec<(f32, u32)>,
    spare: &mut Run,
) {
    sort_in_place(
        &mut keys[..stayed],
        &mut hulls[..stayed],
        &mut ids[..stayed],
        order,
        spare,
    );
    insert_runs((keys, hulls, ids), stayed, movers, moved);
}

/// Inserts the sorted movers `moved` into a band whose first `stayed`
/// entries are sorted and whose rest is free: from the largest down, each
/// found by binary search and the entries above it moved up in one copy,
/// so that each entry moves at most once and a few newcomers cost a few
/// copies of contiguous memory.
fn insert_runs(
    band: (&mut [f32], &mut [Packed], &mut [u32]),
    stayed: usize,
    movers: &Run,
    moved: Range<usize>,
) {
    let (keys, hulls, ids) = band;
    debug_assert_eq!(keys.len(), stayed + moved.len());
    let mut end = stayed;
    for (up, m) in (1..=moved.len()).rev().zip(moved.rev()) {
        let key = movers.keys[m];
        let at = keys[..end].partition_point(|&k| k <= key);
        keys.copy_within(at..end, at + up);
        hulls.copy_within(at..end, at + up);
        ids.copy_within(at..end, at + up);
        keys[at + up - 1] = key;
        hulls[at + up - 1] = movers.hulls[m];
        ids[at + up - 1] = movers.ids[m];
        end = at;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hull(key: f32, lo_y: f32, hi_y: f32) -> Packed {
        let n = f32::NEG_INFINITY;
        [key, lo_y, n, n, -(key + 1.0), -hi_y, n, n]
    }

    /// Boxes keyed `keys` with spans across y from `ys`, ids from 10.
    fn slots(keys: &[f32], ys: &[(f32, f32)]) -> Boxes {
        let mut b = Boxes::default();
        b.reset(keys.len());
        for (k, (&key, &(lo, hi))) in keys.iter().zip(ys).enumerate() {
            b.keys[k] = key;
            b.hulls[k] = hull(key, lo, hi);
            b.ids[k] = 10 + k as u32;
        }
        b
    }

    /// Lays out `b` in `groups` groups: on rayon's pool, or with `team`.
    fn lay_out(
        b: &mut Boxes,
        bands: &Bands,
        groups: usize,
        layout: &mut Layout,
        team: Option<&Team>,
    ) -> usize {
        let n = b.len();
        layout.classify(b, n, bands, groups > 1 && team.is_none(), team);
        layout.lay_out(b, n, bands, groups, team)
    }

    /// Updates the layout of `b` in place if it can, else lays it out as
    /// [`lay_out`] does; says which.
    fn keep_or_lay_out(
        b: &mut Boxes,
        bands: &Bands,
        groups: usize,
        layout: &mut Layout,
        team: Option<&Team>,
    ) -> (usize, bool) {
        match layout.keep(b, b.len(), bands) {
            Some(boxed) => (boxed, true),
            None => (lay_out(b, bands, groups, layout, team), false),
        }
    }

    #[test]
    fn boxes_go_home_sorted_with_their_guests_beside() {
        let bands = Bands::spanning(1, 2, 0.0, 1.0);
        // Ids 10..14; 11 spans both bands; 13 takes no part.
        let keys = [0.5, 0.0, 0.7, NO_KEY, 0.1];
        let ys = [(0.1, 0.2), (0.1, 0.9), (0.6, 0.7), (0.0, 0.0), (0.8, 0.9)];
        for groups in [1, 2, 3] {
            let mut b = slots(&keys, &ys);
            let mut layout = Layout::default();
            assert_eq!(lay_out(&mut b, &bands, groups, &mut layout, None), 4);
            assert_eq!(layout.starts, vec![0, 2, 4, 5]);
            assert_eq!(b.ids, vec![11, 10, 14, 12, 13, u32::MAX]);
            assert_eq!(b.keys[..4], [0.0, 0.5, 0.1, 0.7]);
            assert_eq!(layout.guests(0).2, &[] as &[u32]);
            assert_eq!(layout.guests(1).2, &[11]);
            assert_eq!(layout.guest_count(), 1);
        }
    }

    /// Every layout, however the boxes arrive, holds each box with a key
    /// once at home, sorted, and as a guest in exactly the bands above its
    /// home that it reaches, sorted.
    #[test]
    fn layouts_hold_every_box_at_home_and_as_guest_where_it_reaches() {
        let n = 3000usize;
        let mut state = 12345u64;
        let mut rand = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) as f32) / (1u64 << 31) as f32
        };
        let mut keys: Vec<f32> = (0..n).map(|_| rand()).collect();
        let mut ys: Vec<(f32, f32)> = (0..n)
            .map(|_| {
                let y = rand();
                (y, y + rand() * rand() * 0.3)
            })
            .collect();
        keys[7] = NO_KEY;
        keys[100] = NO_KEY;
        let mut layout = Layout::default();
        let mut b = slots(&keys, &ys);
        let teams = [Team::new(2).unwrap(), Team::new(3).unwrap()];
        let mut kept = 0;
        for step in 0..12 {
            let count = [7, 7, 7, 13, 1000, 7, 7, 7, 7, 7, 3, 3][step];
            let bands = Bands::spanning(1, count, 0.0, 1.0);
            let groups = [1, 2, 3, 2, 8, 1, 2, 3, 1, 1, 2, 1][step];
            // Steps 6 and 7 with a team of as many members as groups.
            let team = (6..8).contains(&step).then(|| &teams[groups - 2]);
            // Boxes move a little (and a few far) between steps, arriving
            // in last step's layout order.
            if step > 0 {
                for k in 0..n {
                    let id = b.ids[k] as usize - 10;
                    if keys[id] != NO_KEY {
                        let shift = if k % 97 == 0 { 0.5 } else { 0.01 };
                        keys[id] = (keys[id] + (rand() - 0.5) * shift).abs();
                        let (lo, hi) = ys[id];
                        let dy = (rand() - 0.5) * shift;
                        ys[id] = ((lo + dy).abs(), (hi + dy).abs().max((lo + dy).abs()));
                    }
                    // Line 50 loses its hull at step 9 and has it back at
                    // step 11: it goes to the boxes without a key and back.
                    if id == 50 && step >= 9 {
                        keys[id] = if step < 11 { NO_KEY } else { 0.25 };
                    }
                    b.keys[k] = keys[id];
                    b.hulls[k] = hull(keys[id], ys[id].0, ys[id].1);
                }
            }
            // From step 8 on, the layout is kept where the bands are the
            // same as the step before's.
            let no_key = if (9..11).contains(&step) { 3 } else { 2 };
            let boxed = if step >= 8 {
                let (boxed, was_kept) = keep_or_lay_out(&mut b, &bands, groups, &mut layout, team);
                kept += usize::from(was_kept);
                boxed
            } else {
                lay_out(&mut b, &bands, groups, &mut layout, team)
            };
            assert_eq!(boxed, n - no_key);
            let mut seen: Vec<u32> = b.ids[..n].to_vec();
            seen.sort_unstable();
            assert_eq!(seen, (10..10 + n as u32).collect::<Vec<_>>());
            assert_eq!(b.ids[n], u32::MAX);
            for band in 0..count {
                let homes = layout.homes(band);
                assert!(b.keys[homes.clone()].windows(2).all(|w| w[0] <= w[1]));
                for at in homes {
                    let id = b.ids[at] as usize - 10;
                    assert_eq!(b.keys[at], keys[id]);
                    assert_eq!(bands.of(ys[id].0), band);
                }
                let (gk, _, gi) = layout.guests(band);
                assert!(gk.windows(2).all(|w| w[0] <= w[1]));
                let mut want: Vec<u32> = (0..n)
                    .filter(|&id| {
                        keys[id] != NO_KEY
                            && bands.of(ys[id].0) < band
                            && bands.of(ys[id].1) >= band
                    })
                    .map(|id| id as u32 + 10)
                    .collect();
                let mut got = gi.to_vec();
                want.sort_unstable();
                got.sort_unstable();
                assert_eq!(got, want, "step {step}, band {band}");
            }
        }
        // Steps 8, 9 and 11.
        assert_eq!(kept, 3);
    }

    #[test]
    fn groups_split_bands_by_entries() {
        let starts = vec![0, 10, 11, 12, 40];
        assert_eq!(group_bounds(&starts, 1), vec![0..4]);
        assert_eq!(group_bounds(&starts, 2), vec![0..3, 3..4]);
        let all: usize = group_bounds(&starts, 8).iter().map(|r| r.len()).sum();
        assert_eq!(all, 4);
    }

    #[test]
    fn far_out_of_order_bands_fall_back_to_radix() {
        let mut keys: Vec<f32> = (0..500u32).map(|i| ((i * 7919) % 500) as f32).collect();
        let mut hulls: Vec<Packed> = keys.iter().map(|&k| [k; 8]).collect();
        let mut ids: Vec<u32> = (0..500).collect();
        let (mut order, mut spare) = (Vec::new(), Run::default());
        sort_in_place(&mut keys, &mut hulls, &mut ids, &mut order, &mut spare);
        assert!(keys.windows(2).all(|w| w[0] <= w[1]));
        for k in 0..500 {
            assert_eq!(hulls[k][0], keys[k]);
            assert_eq!(keys[k], ((ids[k] * 7919) % 500) as f32);
        }
    }
}
