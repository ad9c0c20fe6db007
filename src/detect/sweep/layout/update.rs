//! Last step's layout updated ([`Layout::lay_out`]): only the boxes that
//! changed band are moved apart and merged in. Kept from step to step, a
//! layout costs about 65 instructions a box on `koch` (made anew every
//! step, 230): 10,000 lines, 1000 frames, took 0.262 s on two threads
//! against 0.372 made anew every step, and `koch` 0.063 against 0.093
//! (medians of 5 interleaved rounds).
//!
//! The boxes that left their band (the *leavers*) are found as the hulls
//! are made, a block at a time while the block is at hand
//! ([`Layout::leaver_check`], [`LeaverCheck::note`]), by each share of the
//! hull phase; a million lines on two threads kept their layout in 7.7 ms
//! a step instead of 12.1 when the layout read every box again to find
//! them (8% faster in all, 5% on one thread; `koch`, in the cache, the
//! same within noise). With several groups of bands, the boxes that stay
//! in their band and reach up into the next group's first band are noted
//! too: that group's thread would otherwise pick its first band's guests
//! out of the bands below, which the other thread made the hulls of (on
//! `koch`, two threads, about 330 boxes and 2.4 to 3.5 us a step).
//!
//! Then each group of bands copies each of its bands to its new place in
//! the other arrays in one pass (the stayers a run at a time between the
//! leavers' places, the newcomers merged in) and sorts it there, each
//! group writing only its own stretch. (Closing the bands up in place
//! first, and inserting the newcomers after the copy, moved each band two
//! more times: at 100,000 lines on two threads, 67 M instructions of
//! copying in 10 steps instead of 26 M.) On one thread, with the layout
//! kept, the one group updates it in place instead
//! ([`Layout::finish_in_place`]).

use super::{
    end_guests, groups_of_bands, insert_runs, run_each, set_starts, sort_in_place, sort_movers,
    stretches, Group, GroupView, Layout, Run, Stretch, ThenEach,
};
use crate::detect::sweep::bands::Bands;
use crate::detect::sweep::hull::{hi, lo, Packed};
use crate::detect::sweep::{hull::NO_KEY, order::Boxes};
use crate::team::Team;
use std::ops::Range;

/// What every group reads while it finishes its bands.
struct Closed<'a> {
    /// Last step's boxes, where they arrived.
    keys: &'a [f32],
    hulls: &'a [Packed],
    ids: &'a [u32],
    old_starts: &'a [usize],
    starts: &'a [usize],
    /// Where boxes left their band, in order, and where each band's
    /// start among them.
    gaps: &'a [usize],
    gap_starts: &'a [usize],
    /// Per band, the last band its homes (this step's) reach.
    reach: &'a [u32],
    /// The boxes that changed band, sorted by band and then by key.
    movers: &'a Run,
    /// Where each band's movers start in `movers`, and their end.
    mover_starts: &'a [usize],
    bands: &'a Bands,
    /// What the shares noted, the boxes that stayed in their band and
    /// reach a group's first band among it ([`Leavers`]).
    carried: &'a [Leavers],
}

impl Closed<'_> {
    /// The runs of band `b`'s boxes that stayed in it, where they arrived.
    fn stayers(&self, b: usize) -> impl Iterator<Item = Range<usize>> + '_ {
        let band = self.old_starts[b]..self.old_starts[b + 1];
        runs_between(band, &self.gaps[self.gap_starts[b]..self.gap_starts[b + 1]])
    }
}

/// What a share of the boxes, as they arrive in last step's layout with
/// their hulls made anew, holds that left their band: found as the hulls
/// are made ([`LeaverCheck::note`]), while they are at hand, so that
/// keeping the layout need not read every box once more to find them.
#[derive(Debug, Default)]
pub(crate) struct Leavers {
    /// The first band the share touches.
    first_band: usize,
    /// Per band from `first_band` on: the share's boxes that left it, and
    /// the greatest value across the bands that those that stayed reach.
    left: Vec<usize>,
    tops: Vec<f32>,
    /// The boxes that left, with their new home band, and their places
    /// (ascending).
    movers: Run,
    gaps: Vec<usize>,
    /// The boxes that stayed and reach up into the first band of a group
    /// of bands above their own (see [`LeaverCheck`]), with the band after
    /// the last they reach; and their bands.
    carried: Run,
    carried_from: Vec<u32>,
}

impl Leavers {
    /// Empties it for a share's boxes.
    pub(crate) fn clear(&mut self) {
        self.first_band = 0;
        self.left.clear();
        self.tops.clear();
        self.movers.clear();
        self.gaps.clear();
        self.carried.clear();
        self.carried_from.clear();
    }

    /// Adds what a run of band `b`'s boxes held: `left` leavers, and
    /// stayers reaching up to `top` across.
    fn add(&mut self, b: usize, left: usize, top: f32) {
        if self.left.is_empty() {
            self.first_band = b;
        }
        let at = b - self.first_band;
        if at >= self.left.len() {
            // Bands between without a box of the share left nothing.
            self.left.resize(at + 1, 0);
            self.tops.resize(at + 1, f32::NEG_INFINITY);
        }
        self.left[at] += left;
        self.tops[at] = self.tops[at].max(top);
    }
}

/// Last step's layout, to find the boxes that left their band as their
/// hulls are made (see [`Leavers`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct LeaverCheck<'a> {
    starts: &'a [usize],
    edges: &'a [f32],
    bands: Bands,
    /// Per band, the least value of the first band of the next group of
    /// bands above it (`+inf` for the last group's bands; empty with one
    /// group): a box that stays in its band and reaches that far is one of
    /// that group's first band's guests, noted as the hulls are made so
    /// that the group need not read the bands below it.
    carry: &'a [f32],
}

impl LeaverCheck<'_> {
    /// Notes into `into` which of the boxes `at..` (`keys`, `hulls` and
    /// `ids`, just made) left their band; the boxes of a share are noted in
    /// order, from a cleared `into` ([`Leavers::clear`]).
    pub(crate) fn note(
        &self,
        at: usize,
        (keys, hulls, ids): (&[f32], &[Packed], &[u32]),
        into: &mut Leavers,
    ) {
        let end = at + keys.len();
        let mut k = at;
        // The band holding `at` (the last band starting there or before).
        let mut b = self.starts.partition_point(|&s| s <= at) - 1;
        while k < end {
            while self.starts[b + 1] <= k {
                b += 1;
            }
            let run = k - at..self.starts[b + 1].min(end) - at;
            let before = into.gaps.len();
            let arrays = (keys, hulls, ids);
            let carry = self.carry.get(b).copied().unwrap_or(f32::INFINITY);
            let (edges, bands, next) = (self.edges, &self.bands, at + run.end);
            // Only the bands below a group's first band have stayers to
            // note as its guests; the rest skip the comparison.
            let top = match carry < f32::INFINITY {
                true => close_up::<true>(arrays, at, run, (b, carry), edges, bands, into),
                false => close_up::<false>(arrays, at, run, (b, carry), edges, bands, into),
            };
            into.add(b, into.gaps.len() - before, top);
            k = next;
        }
    }
}

impl Layout {
    /// Whether last step's layout was of `bands` and of `n` boxes, and so
    /// may be kept.
    pub(crate) fn keeps(&self, bands: &Bands, n: usize) -> bool {
        let count = bands.count;
        self.kept == Some(*bands) && self.starts.len() == count + 2 && self.starts[count + 1] == n
    }

    /// Last step's layout, to note the boxes that leave their band as the
    /// hulls of the `n` boxes are made, if the layout of `bands` may be
    /// kept this step (else `None`), in `groups` groups of bands; and
    /// `shares` buffers to note them in, one per share of the boxes in
    /// order. [`Layout::lay_out`] then takes what they hold.
    pub(crate) fn leaver_check(
        &mut self,
        n: usize,
        bands: &Bands,
        shares: usize,
        groups: usize,
    ) -> (Option<LeaverCheck<'_>>, &mut [Leavers]) {
        let count = bands.count;
        let keeps = self.keeps(bands, n);
        self.noted_for = keeps.then_some((*bands, groups));
        self.noted
            .resize_with(shares.max(self.noted.len()), Leavers::default);
        self.noted_shares = shares;
        self.carry.clear();
        if keeps && groups > 1 {
            // Per band, the least value of the next group's first band.
            let firsts: Vec<usize> = groups_of_bands(&self.starts, groups)[1..]
                .iter()
                .map(|g| g.start)
                .filter(|&first| first < count)
                .collect();
            let edges = &self.edges;
            self.carry.extend(
                (0..=count).map(|b| match firsts.iter().find(|&&first| first > b) {
                    Some(&first) if b < count => edges[first],
                    _ => f32::INFINITY,
                }),
            );
        }
        let check = keeps.then_some(LeaverCheck {
            starts: &self.starts,
            edges: &self.edges,
            bands: *bands,
            carry: &self.carry,
        });
        (check, &mut self.noted[..shares])
    }

    /// Lays out the first `n` boxes of `slots` in `bands` (their hulls
    /// made anew), as they arrive in the order of last step's layout:
    /// last step's layout updated if it was of `bands` and of as many
    /// boxes, else laid out anew, as from a layout that held every box
    /// among the boxes without a key, so that every box with a key is a
    /// newcomer to its band. Leaves them in `slots`, sentinel last, and
    /// returns the boxes with a key, which come first.
    ///
    /// The work is shared among groups of bands, one a member of `team`,
    /// and `then_each` is called with each group as soon as it is laid
    /// out, by the thread that laid it out.
    pub(crate) fn lay_out(
        &mut self,
        slots: &mut Boxes,
        n: usize,
        bands: &Bands,
        team: &Team,
        then_each: ThenEach,
    ) -> usize {
        let groups = team.threads();
        let kept = self.note_leavers(slots, n, bands, team);
        let (bounds, mover_starts) = self.place_movers(n, bands, groups, kept);
        if kept && groups == 1 {
            self.finish_in_place(slots, n, bands, &mover_starts, then_each);
        } else {
            self.finish_groups(slots, n, bands, team, (&bounds, &mover_starts), then_each);
            self.hand_over(slots);
        }
        self.list_guests(&bounds, bands.count);
        self.starts[bands.count]
    }

    /// Takes last step's layout to update if it was of `bands` and `n`
    /// boxes (and says so), else an empty one (every box among the boxes
    /// without a key); notes the boxes that left their band here, a share
    /// a thread of `team`, unless the hulls' shares noted them for these
    /// bands in as many groups.
    fn note_leavers(&mut self, slots: &Boxes, n: usize, bands: &Bands, team: &Team) -> bool {
        let (count, groups) = (bands.count, team.threads());
        // Noted for these bands in as many groups (the guests that reach
        // each group's first band are noted with the leavers).
        let noted = self.noted_for.take() == Some((*bands, groups));
        let kept = self.keeps(bands, n) && slots.len() == n;
        if !kept {
            self.kept = Some(*bands);
            self.set_edges(bands);
            self.starts.clear();
            self.starts.resize(count + 1, 0);
            self.starts.push(n);
        }
        if !(kept && noted) {
            let (check, noted) = self.leaver_check(n, bands, groups, groups);
            let check = check.expect("a layout to update");
            let noted = crate::team::shares_mut(noted, groups);
            team.run(&|k| {
                let share = crate::team::share(n, groups, k);
                let into = &mut noted[k].lock().expect("a share")[0];
                into.clear();
                let r = share.clone();
                check.note(
                    share.start,
                    (
                        &slots.keys[r.clone()],
                        &slots.hulls[r.clone()],
                        &slots.ids[r],
                    ),
                    into,
                );
            });
            self.noted_for = None;
        }
        kept
    }

    /// Sets the new layout's starts from the boxes that stayed in each
    /// band and the movers (sorted by band and key), and each band's
    /// reach; returns the groups of bands, one per thread, and where each
    /// band's movers start.
    fn place_movers(
        &mut self,
        n: usize,
        bands: &Bands,
        groups: usize,
        kept: bool,
    ) -> (Vec<Range<usize>>, Vec<usize>) {
        let count = bands.count;
        let mut tops = self.gather_leavers(count);
        std::mem::swap(&mut self.starts, &mut self.old_starts);
        self.counts.clear();
        self.counts.extend(self.stayed.iter().map(|&s| s as u32));
        for (&b, hull) in self.movers.ends.iter().zip(&self.movers.hulls) {
            self.counts[b as usize] += 1;
            if (b as usize) < count {
                let top = &mut tops[b as usize];
                *top = top.max(hi(hull, bands.across));
            }
        }
        set_starts(&self.counts, &mut self.starts, n);
        // Groups of bands of about as many boxes, the last also holding the
        // boxes without a key: by last step's starts, for which the guests
        // of each group's first band were noted, or with none, by these.
        let by = if kept { &self.old_starts } else { &self.starts };
        let bounds = groups_of_bands(by, groups);
        self.groups
            .resize_with(bounds.len().max(self.groups.len()), Group::default);
        if self.movers.len() > 0 {
            let g = &mut self.groups[0];
            // Made anew, the bands have no stayers to merge the movers
            // among: each band sorts them itself, on its group's thread.
            let by_key = kept;
            sort_movers(&mut self.movers, by_key, &mut g.by_band, &mut g.spare);
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
        (bounds, mover_starts)
    }

    /// Each group of bands (`bounds`) copies its bands' stayers and
    /// newcomers to their new places in the layout's arrays and finishes
    /// them there, with their guests, on its member of `team`, then hands
    /// itself to `then_each`.
    fn finish_groups(
        &mut self,
        slots: &Boxes,
        n: usize,
        bands: &Bands,
        team: &Team,
        (bounds, mover_starts): (&[Range<usize>], &[usize]),
        then_each: ThenEach,
    ) {
        self.keys.resize(n + 1, NO_KEY);
        self.hulls.resize(n + 1, [0.0; 8]);
        self.ids.resize(n + 1, u32::MAX);
        self.keys[n] = NO_KEY;
        self.ids[n] = u32::MAX;
        let closed = Closed {
            keys: &slots.keys[..n],
            hulls: &slots.hulls[..n],
            ids: &slots.ids[..n],
            old_starts: &self.old_starts,
            starts: &self.starts,
            gaps: &self.gaps,
            gap_starts: &self.gap_starts,
            reach: &self.reach,
            movers: &self.movers,
            mover_starts,
            bands,
            carried: &self.noted[..self.noted_shares],
        };
        let (keys, hulls, ids) = (&mut self.keys, &mut self.hulls, &mut self.ids);
        let stretches = stretches(closed.starts, keys, hulls, ids, bounds);
        let work: Vec<_> = (stretches.into_iter().zip(self.groups.iter_mut()))
            .enumerate()
            .collect();
        let count = bands.count;
        run_each(work, team, |(index, (s, g))| {
            let (range, offset) = (s.bands.start..s.bands.end.min(count), s.offset);
            let laid_out = finish_group(s, g, &closed);
            then_each(GroupView::of(
                index,
                range,
                offset,
                laid_out,
                closed.starts,
                g,
            ));
        });
    }

    /// [`Layout::lay_out`] of last step's layout on one thread, in place:
    /// each band's stayers closed up at its front (a run at a time between
    /// the leavers' places), the bands' runs moved to their new starts
    /// (those moving up from the last band down, then those moving down
    /// from the first up, so that no run lands on one not yet moved), each
    /// band finished by insertion with its newcomers (`mover_starts` of the
    /// sorted movers) inserted, and its guests listed; then the one group
    /// handed to `then_each`. Against copying every box into the other
    /// arrays, as the groups do, 100,000 lines (100 frames) ran 1.13x as
    /// fast on one thread (0.566 s against 0.642, medians of 15
    /// interleaved rounds; 0.91x and 0.90x against the build with it in
    /// two sets); `mit`, `koch`, 10,000 and a million lines within noise.
    fn finish_in_place(
        &mut self,
        slots: &mut Boxes,
        n: usize,
        bands: &Bands,
        mover_starts: &[usize],
        then_each: ThenEach,
    ) {
        let count = bands.count;
        let (keys, hulls, ids) = (
            &mut slots.keys[..n],
            &mut slots.hulls[..n],
            &mut slots.ids[..n],
        );
        let (old, new, stayed) = (&self.old_starts, &self.starts, &self.stayed);
        for b in 0..=count {
            let gaps = &self.gaps[self.gap_starts[b]..self.gap_starts[b + 1]];
            let arrays = (&mut *keys, &mut *hulls, &mut *ids);
            close_gaps(arrays, old[b]..old[b + 1], gaps);
        }
        let shift = |b: usize, keys: &mut [f32], hulls: &mut [Packed], ids: &mut [u32]| {
            let run = old[b]..old[b] + stayed[b];
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
        let movers = &self.movers;
        let group = &mut self.groups[0];
        group.guests.clear();
        group.guest_starts.clear();
        group.guest_starts.push(0);
        for b in 0..=count {
            let out = new[b]..new[b + 1];
            let moved = mover_starts[b]..mover_starts[b + 1];
            let (k, h, i) = (
                &mut keys[out.clone()],
                &mut hulls[out.clone()],
                &mut ids[out.clone()],
            );
            if b == count {
                // The boxes without a key: in any order.
                let all = (&movers.keys[..], &movers.hulls[..], &movers.ids[..]);
                copy_run((k, h, i), stayed[b], all, moved);
                break;
            }
            let s = stayed[b];
            sort_in_place(
                &mut k[..s],
                &mut h[..s],
                &mut i[..s],
                &mut group.order,
                &mut group.spare,
            );
            insert_runs((k, h, i), s, movers, moved);
            let homes = (&keys[out.clone()], &hulls[out.clone()], &ids[out]);
            let next = b + 1 < count;
            let Group {
                guests,
                guest_starts,
                spare,
                ..
            } = &mut *group;
            end_guests((guests, guest_starts), homes, b, next, bands, spare);
        }
        let laid_out = (&keys[..], &hulls[..], &ids[..]);
        then_each(GroupView::of(
            0,
            0..count,
            0,
            laid_out,
            &self.starts,
            &self.groups[0],
        ));
    }

    /// Puts together what the shares noted (see [`Layout::leaver_check`]):
    /// the movers and their places in `movers` and `gaps` (ascending),
    /// where each band's places start in `gap_starts`, and the boxes that
    /// stayed in each band in `stayed`, for last step's `starts` of
    /// `count` bands. Returns per band the greatest value across the bands
    /// that its stayers reach.
    fn gather_leavers(&mut self, count: usize) -> Vec<f32> {
        let old = &self.starts;
        let mut tops = vec![f32::NEG_INFINITY; count + 1];
        self.stayed.clear();
        self.stayed.extend((0..=count).map(|b| old[b + 1] - old[b]));
        self.movers.clear();
        self.gaps.clear();
        for share in &self.noted[..self.noted_shares] {
            self.movers
                .extend_from(&share.movers, 0..share.movers.len());
            self.gaps.extend_from_slice(&share.gaps);
            let bands = share.first_band..share.first_band + share.left.len();
            for ((b, &left), &top) in bands.zip(&share.left).zip(&share.tops) {
                self.stayed[b] -= left;
                tops[b] = tops[b].max(top);
            }
        }
        self.gap_starts.clear();
        self.gap_starts.push(0);
        for b in 0..=count {
            let left = old[b + 1] - old[b] - self.stayed[b];
            self.gap_starts.push(self.gap_starts[b] + left);
        }
        tops
    }
}

/// Finds the boxes of band `b` (the entries `band` of the arrays, which
/// start at place `at`) that left it: pushes each to `into`'s movers with
/// its new home band and its place to its gaps; with `CARRY`, notes those
/// that stayed and reach `carry` across as guests of the next group's
/// first band. Returns the greatest value across the bands that the boxes
/// that stayed reach.
fn close_up<const CARRY: bool>(
    (keys, hulls, ids): (&[f32], &[Packed], &[u32]),
    at: usize,
    band: Range<usize>,
    (b, carry): (usize, f32),
    edges: &[f32],
    bands: &Bands,
    into: &mut Leavers,
) -> f32 {
    let count = bands.count;
    let across = bands.across;
    let mut leave = |k: usize, home: usize| {
        into.movers.push(keys[k], hulls[k], ids[k], home as u32);
        into.gaps.push(at + k);
    };
    if b == count {
        // The boxes without a key: those that have one now leave.
        for k in band.filter(|&k| keys[k] != NO_KEY) {
            leave(k, bands.of(lo(&hulls[k], across)));
        }
        return f32::NEG_INFINITY;
    }
    let (low, high) = (edges[b], edges[b + 1]);
    let (first, band_keys, band_hulls) = (band.start, &keys[band.clone()], &hulls[band]);
    // Eight boxes at a time, in arrays the compiler works on as vectors:
    // which stay, and the greatest value across that those reach; the rare
    // box that leaves is taken on its own.
    let mut tops = [f32::NEG_INFINITY; 8];
    // A box that stays and reaches the next group's first band is noted as
    // one of its guests.
    let mut carry_one = |k: usize, h: f32| {
        let end = bands.of(h) as u32 + 1;
        into.carried.push(keys[k], hulls[k], ids[k], end);
        into.carried_from.push(b as u32);
    };
    let blocks = band_keys.chunks_exact(8).zip(band_hulls.chunks_exact(8));
    for (c, (keys8, hulls8)) in blocks.enumerate() {
        let v: [f32; 8] = std::array::from_fn(|j| lo(&hulls8[j], across));
        let mut stays = [false; 8];
        let mut carries = [false; 8];
        for j in 0..8 {
            stays[j] = (keys8[j] != NO_KEY) & (low <= v[j]) & (v[j] < high);
            let h = hi(&hulls8[j], across);
            tops[j] = if stays[j] & (h > tops[j]) { h } else { tops[j] };
            carries[j] = stays[j] & (h >= carry);
        }
        if CARRY && carries != [false; 8] {
            for j in (0..8).filter(|&j| carries[j]) {
                carry_one(first + c * 8 + j, hi(&hulls8[j], across));
            }
        }
        if stays != [true; 8] {
            for j in (0..8).filter(|&j| !stays[j]) {
                let home = if keys8[j] == NO_KEY {
                    count
                } else {
                    bands.of(v[j])
                };
                leave(first + c * 8 + j, home);
            }
        }
    }
    let mut top = tops.into_iter().fold(f32::NEG_INFINITY, f32::max);
    let whole = band_keys.len() - band_keys.len() % 8;
    for (k, (&key, hull)) in band_keys.iter().zip(band_hulls).enumerate().skip(whole) {
        let v = lo(hull, across);
        let stays = (key != NO_KEY) & (low <= v) & (v < high);
        let h = hi(hull, across);
        top = if stays & (h > top) { h } else { top };
        if CARRY && stays & (h >= carry) {
            carry_one(first + k, h);
        }
        if !stays {
            let home = if key == NO_KEY { count } else { bands.of(v) };
            leave(first + k, home);
        }
    }
    top
}

/// The runs of the entries `band` between its `gaps` (ascending places
/// within it), in order.
fn runs_between(band: Range<usize>, gaps: &[usize]) -> impl Iterator<Item = Range<usize>> + '_ {
    let ends = gaps.iter().copied().chain(std::iter::once(band.end));
    let starts = std::iter::once(band.start).chain(gaps.iter().map(|&g| g + 1));
    starts.zip(ends).filter(|(s, e)| s < e).map(|(s, e)| s..e)
}

/// Fills a band's arrays with its boxes that stayed (copied from where
/// they arrived, a run at a time) and its newcomers `moved` of the sorted
/// movers, each newcomer before the stayer that `place(keys, key)` gives
/// in a run, or after the run.
fn merge_in(
    band_arrays: (&mut [f32], &mut [Packed], &mut [u32]),
    c: &Closed,
    band: usize,
    moved: Range<usize>,
    place: impl Fn(&[f32], f32) -> usize,
) {
    let (keys, hulls, ids) = band_arrays;
    let m = c.movers;
    let (stayers, movers) = (
        (c.keys, c.hulls, c.ids),
        (&m.keys[..], &m.hulls[..], &m.ids[..]),
    );
    let mut at = 0;
    let mut next = moved.start;
    for mut run in c.stayers(band) {
        while next < moved.end {
            let split = run.start + place(&c.keys[run.clone()], m.keys[next]);
            if split == run.end {
                break;
            }
            at = copy_run((keys, hulls, ids), at, stayers, run.start..split);
            at = copy_run((keys, hulls, ids), at, movers, next..next + 1);
            (next, run.start) = (next + 1, split);
        }
        at = copy_run((keys, hulls, ids), at, stayers, run);
    }
    at = copy_run((keys, hulls, ids), at, movers, next..moved.end);
    debug_assert_eq!(at, keys.len());
}

/// Copies the entries `from` of `src` to `dst` at `at`; returns where they
/// end there.
fn copy_run(
    (keys, hulls, ids): (&mut [f32], &mut [Packed], &mut [u32]),
    at: usize,
    src: (&[f32], &[Packed], &[u32]),
    from: Range<usize>,
) -> usize {
    let to = at..at + from.len();
    keys[to.clone()].copy_from_slice(&src.0[from.clone()]);
    hulls[to.clone()].copy_from_slice(&src.1[from.clone()]);
    ids[to.clone()].copy_from_slice(&src.2[from]);
    to.end
}

/// Finishes one group's bands in its stretch of the new arrays: each
/// band's stayers copied in with its newcomers merged in, then sorted;
/// then its guests, the first band's from the stayers below noted as
/// reaching it and the newcomers to the bands below that do.
/// Returns the stretch's keys, hulls and ids, finished.
fn finish_group<'a>(
    s: Stretch<'a>,
    group: &mut Group,
    c: &Closed,
) -> (&'a [f32], &'a [Packed], &'a [u32]) {
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
    // The stayers among them were noted as their hulls were made, by the
    // thread that made them: the bands below, which another thread laid
    // out, are not read again.
    for share in c.carried {
        let noted = &share.carried;
        let boxes = noted.keys.iter().zip(&noted.hulls).zip(&noted.ids);
        let ends = noted.ends.iter().zip(&share.carried_from);
        for (((&key, hull), &id), (&end, &band)) in boxes.zip(ends) {
            if (band as usize) < b0 && end as usize > b0 {
                guests.push(key, *hull, id, end);
            }
        }
    }
    let m = c.movers;
    for k in c.mover_starts[from]..c.mover_starts[b0] {
        let end = c.bands.of(hi(&m.hulls[k], across)) as u32 + 1;
        if end as usize > b0 {
            guests.push(m.keys[k], m.hulls[k], m.ids[k], end);
        }
    }
    if guests.len() > 0 {
        guests.sort(0..guests.len(), order, spare);
    }

    guest_starts.clear();
    guest_starts.push(0);
    for band in range.start..range.end {
        let out = c.starts[band] - offset..c.starts[band + 1] - offset;
        let moved = c.mover_starts[band]..c.mover_starts[band + 1];
        let band_arrays = (
            &mut keys[out.clone()],
            &mut hulls[out.clone()],
            &mut ids[out.clone()],
        );
        if band == count {
            // The boxes without a key: in any order.
            merge_in(band_arrays, c, band, moved, |keys, _| keys.len());
            break;
        }
        // The newcomers merged in as the stayers are copied, each before
        // the first stayer past it (a place found by binary search in the
        // nearly sorted stayers, so possibly a little off); then the band
        // sorted, which puts right what is off.
        merge_in(band_arrays, c, band, moved, |keys, key| {
            keys.partition_point(|&k| k <= key)
        });
        sort_in_place(
            &mut keys[out.clone()],
            &mut hulls[out.clone()],
            &mut ids[out.clone()],
            order,
            spare,
        );
        let homes = (&keys[out.clone()], &hulls[out.clone()], &ids[out]);
        let next = band + 1 < range.end.min(count);
        end_guests((guests, guest_starts), homes, band, next, c.bands, spare);
    }
    (keys, hulls, ids)
}

/// Closes up the entries `band` of the arrays: the ones between its `gaps`
/// move to its front in their order, a run at a time.
fn close_gaps(
    (keys, hulls, ids): (&mut [f32], &mut [Packed], &mut [u32]),
    band: Range<usize>,
    gaps: &[usize],
) {
    let mut w = band.start;
    for run in runs_between(band, gaps) {
        if w != run.start {
            keys.copy_within(run.clone(), w);
            hulls.copy_within(run.clone(), w);
            ids.copy_within(run.clone(), w);
        }
        w += run.len();
    }
}
