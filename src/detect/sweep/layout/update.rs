//! Last step's layout updated ([`Layout::lay_out`]): only the movers move.
//! The movers are found as the hulls are made, a block at a time while it
//! is at hand ([`Layout::mover_check`], [`MoverCheck::note`]), with the
//! stayers that reach up into the next group's first band, so that group's
//! thread need not read the bands below. Then each group copies each of its
//! bands to its new place in the other arrays in one pass (the stayers a
//! run at a time, the movers merged in) and sorts it there; on one thread a
//! kept layout is updated in place instead ([`Layout::finish_in_place`]),
//! but for the largest scenes ([`Schedule::LAYOUT_COPIED_FROM`]).

use super::{
    groups_of_bands, insert_runs, member_runs, set_starts, stretches, Group, GroupView, Layout,
    Stretch, ThenEach,
};
use crate::detect::sweep::bands::Bands;
use crate::detect::sweep::boxes::{sort_nearly_sorted, Boxes};
use crate::detect::sweep::boxes::{BoxList, BoxSlice, BoxSliceMut};
use crate::detect::sweep::hull::{hi, lo, NO_KEY};
use crate::schedule::Schedule;
use crate::team::Team;
use std::ops::Range;

/// What a share of the boxes, as they arrive in last step's layout with
/// their hulls made anew, holds that left their band: found as the hulls
/// are made ([`MoverCheck::note`]), while they are at hand.
#[derive(Debug, Default)]
pub(crate) struct Noted {
    /// Per run of one band's boxes noted: the band, its movers, and the
    /// greatest value across the bands that its stayers reach.
    runs: Vec<(usize, usize, f32)>,
    /// The movers, each with its new home band as its end, and their
    /// places (ascending).
    movers: BoxList,
    gaps: Vec<usize>,
    /// The stayers that reach up into the first band of a group of bands
    /// above their own (see [`MoverCheck`]), with the band after the last
    /// they reach; and their bands.
    carried: BoxList,
    carried_from: Vec<u32>,
}

impl Noted {
    /// Empties it for a share's boxes.
    pub(crate) fn clear(&mut self) {
        self.runs.clear();
        self.movers.clear();
        self.gaps.clear();
        self.carried.clear();
        self.carried_from.clear();
    }
}

/// Last step's layout, to find the movers as the hulls are made (see
/// [`Noted`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct MoverCheck<'a> {
    starts: &'a [usize],
    edges: &'a [f32],
    bands: Bands,
    /// Per band, the least value of the first band of the next group of
    /// bands above it (`+inf` for the last group's bands; empty with one
    /// group): a stayer that reaches that far is one of that group's first
    /// band's guests.
    carry: &'a [f32],
}

impl MoverCheck<'_> {
    /// Notes into `into` which of the boxes `boxes` (from place `at`, their
    /// hulls just made) left their band; the boxes of a share are noted in
    /// order, from a cleared `into` ([`Noted::clear`]).
    pub(crate) fn note(&self, at: usize, boxes: BoxSlice, into: &mut Noted) {
        let end = at + boxes.len();
        let mut k = at;
        // The band holding `at` (the last band starting there or before).
        let mut b = self.starts.partition_point(|&s| s <= at) - 1;
        while k < end {
            while self.starts[b + 1] <= k {
                b += 1;
            }
            let run = k - at..self.starts[b + 1].min(end) - at;
            let before = into.gaps.len();
            let carry = self.carry.get(b).copied().unwrap_or(f32::INFINITY);
            let next = at + run.end;
            // Only the bands below a group's first band have stayers to
            // note as its guests; the rest skip the comparison.
            let top = match carry < f32::INFINITY {
                true => close_up::<true>(boxes, at, run, (b, carry), self, into),
                false => close_up::<false>(boxes, at, run, (b, carry), self, into),
            };
            into.runs.push((b, into.gaps.len() - before, top));
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

    /// Last step's layout, to note the movers as the hulls of the `n`
    /// boxes are made, if the layout of `bands` may be kept this step (else
    /// `None`), in `groups` groups of bands; and `shares` buffers to note
    /// them in, one per share of the boxes in order. [`Layout::lay_out`]
    /// then takes what they hold.
    pub(crate) fn mover_check(
        &mut self,
        n: usize,
        bands: &Bands,
        shares: usize,
        groups: usize,
    ) -> (Option<MoverCheck<'_>>, &mut [Noted]) {
        let keeps = self.keeps(bands, n);
        self.noted_for = keeps.then_some((*bands, groups));
        let shares_noted = shares.max(self.noted.len());
        self.noted.resize_with(shares_noted, Noted::default);
        self.noted_shares = shares;
        self.carry.clear();
        if keeps && groups > 1 {
            // Per band, the least value of the next group's first band.
            let bounds = groups_of_bands(&self.starts, groups);
            for (g, group) in bounds.iter().enumerate() {
                let next = bounds.get(g + 1);
                let carry = next.map_or(f32::INFINITY, |next| self.edges[next.start]);
                self.carry.extend(group.clone().map(|_| carry));
            }
        }
        let check = keeps.then_some(MoverCheck {
            starts: &self.starts,
            edges: &self.edges,
            bands: *bands,
            carry: &self.carry,
        });
        (check, &mut self.noted[..shares])
    }

    /// Lays out the first `n` boxes of `arriving` in `bands` (their hulls
    /// made anew), as they arrive in the order of last step's layout:
    /// last step's layout updated if it was of `bands` and of as many
    /// boxes, else laid out anew, every box a mover to its band
    /// ([`Layout::gather_all`]). Leaves them in `arriving`, sentinel last,
    /// and returns the boxes with a key, which come first.
    ///
    /// The work is shared among groups of bands, one a member of `team`,
    /// and `then_each` is called with each group as soon as it is laid
    /// out, by the thread that laid it out.
    pub(crate) fn lay_out(
        &mut self,
        arriving: &mut Boxes,
        n: usize,
        bands: &Bands,
        team: &Team,
        then_each: ThenEach,
    ) -> usize {
        let groups = team.threads();
        let kept = self.keeps(bands, n) && arriving.len() == n;
        let tops = match kept {
            true => {
                self.note_movers(arriving, n, bands, team);
                self.gather_movers(bands.count)
            }
            false => self.gather_all(arriving.slice(n), bands, team),
        };
        let bounds = self.place_movers(n, bands, groups, kept, tops);
        self.group_count = bounds.len();
        let copied = self
            .copied_from
            .map_or(Schedule::layout_copied(n), |from| n >= from);
        if kept && groups == 1 && !copied {
            self.finish_in_place(arriving, n, bands, then_each);
        } else {
            self.finish_groups(arriving.slice(n), team, (&bounds, !kept), then_each);
            std::mem::swap(arriving, &mut self.laid);
        }
        self.starts[bands.count]
    }

    /// Notes the movers of last step's layout (of `bands` and `n` boxes
    /// arriving in its order), a share a thread of `team`, unless the
    /// hulls' shares noted them for these bands in as many groups.
    fn note_movers(&mut self, arriving: &Boxes, n: usize, bands: &Bands, team: &Team) {
        let groups = team.threads();
        if self.noted_for.take() == Some((*bands, groups)) {
            return;
        }
        let (check, noted) = self.mover_check(n, bands, groups, groups);
        let check = check.expect("a layout to update");
        let noted = crate::team::split_mut(noted, groups);
        team.run(&|k| {
            let share = crate::team::share(n, groups, k);
            let into = &mut noted.take(k)[0];
            into.clear();
            check.note(share.start, arriving.slice(n).at(share), into);
        });
        self.noted_for = None;
    }

    /// A layout made anew in `bands`: every box of `arriving` a mover to
    /// its band (the boxes without a key to the band after the last), put
    /// in `movers` band by band in the order they arrive, by a counting
    /// sort shared among `team` (each share counts its boxes per band,
    /// then copies each to its place), with no stayers and no gaps.
    /// Returns per band the greatest value across that its stayers reach
    /// (`-inf`: it has none).
    fn gather_all(&mut self, arriving: BoxSlice, bands: &Bands, team: &Team) -> Vec<f32> {
        let (n, count, shares) = (arriving.len(), bands.count, team.threads());
        self.kept = Some(*bands);
        self.set_edges(bands);
        // Last step's layout, which the stayers come from: none.
        self.starts.clear();
        self.starts.resize(count + 2, 0);
        self.noted_for = None;
        self.noted_shares = 0;
        self.stayed.clear();
        self.stayed.resize(count + 1, 0);
        self.gaps.clear();
        self.gap_starts.clear();
        self.gap_starts.resize(count + 2, 0);
        let home = |k: usize| match arriving.keys[k] == NO_KEY {
            true => count,
            false => bands.of(lo(&arriving.hulls[k], bands.across)),
        };
        let mut counts = vec![vec![0usize; count + 1]; shares];
        let parts = crate::team::split_mut(&mut counts, shares);
        team.run(&|k| {
            let counts = &mut parts.take(k)[0];
            for i in crate::team::share(n, shares, k) {
                counts[home(i)] += 1;
            }
        });
        self.movers.resize(n);
        let runs = crate::team::Parts::new(member_runs(&mut self.movers, &counts));
        team.run(&|k| {
            let mut runs = runs.take(k);
            let mut at = vec![0; count + 1];
            for i in crate::team::share(n, shares, k) {
                let b = home(i);
                let ((run, ends), to) = (&mut runs[b], at[b]);
                run.keys[to] = arriving.keys[i];
                run.hulls[to] = arriving.hulls[i];
                run.slots[to] = arriving.slots[i];
                ends[to] = b as u32;
                at[b] += 1;
            }
        });
        vec![f32::NEG_INFINITY; count + 1]
    }

    /// Sets the new layout's starts from the stayers of each band and the
    /// movers (sorted here by band and key if `kept`, else in their bands
    /// already), the last band each band's homes reach (given per band the
    /// greatest value across that its stayers reach, `tops`) and where its
    /// movers start; returns the groups of bands, one per thread.
    fn place_movers(
        &mut self,
        n: usize,
        bands: &Bands,
        groups: usize,
        kept: bool,
        mut tops: Vec<f32>,
    ) -> Vec<Range<usize>> {
        let count = bands.count;
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
        set_starts(self.counts.iter().copied(), &mut self.starts);
        debug_assert_eq!(self.starts[count + 1], n);
        // Groups of bands of about as many boxes, the last also holding the
        // boxes without a key: by last step's starts, for which the guests
        // of each group's first band were noted, or with none, by these.
        let by = if kept { &self.old_starts } else { &self.starts };
        let bounds = groups_of_bands(by, groups);
        self.groups
            .resize_with(bounds.len().max(self.groups.len()), Group::default);
        let moved = (0..=count).map(|b| self.counts[b] - self.stayed[b] as u32);
        set_starts(moved, &mut self.mover_starts);
        // Made anew, the movers are in their bands already, and the bands
        // have no stayers to merge them among: each band sorts them
        // itself, on its group's thread.
        if kept {
            self.groups[0].sort_movers(&mut self.movers, &self.mover_starts);
        }
        self.last_band.clear();
        self.last_band
            .extend(
                tops.iter()
                    .enumerate()
                    .map(|(b, &top)| match top > f32::NEG_INFINITY {
                        true => bands.of(top).max(b) as u32,
                        false => b as u32,
                    }),
            );
        bounds
    }

    /// Each group of bands (`bounds`) copies its bands' stayers (from
    /// `arrived`) and movers to their new places in the other arrays and
    /// finishes them there, with their guests, on its member of `team`,
    /// then hands itself to `then_each`. A layout made `anew` has movers
    /// alone, in no order.
    fn finish_groups(
        &mut self,
        arrived: BoxSlice,
        team: &Team,
        (bounds, anew): (&[Range<usize>], bool),
        then_each: ThenEach,
    ) {
        // Taken out while the groups write them and read the rest.
        let (mut groups, mut laid) = (
            std::mem::take(&mut self.groups),
            std::mem::take(&mut self.laid),
        );
        laid.set_len(arrived.len());
        let (layout, starts) = (&*self, &self.starts[..]);
        let stretches = stretches(starts, laid.slice_mut(arrived.len()), bounds);
        let work: Vec<_> = stretches.into_iter().zip(groups.iter_mut()).collect();
        let pieces = work.len();
        let work = crate::team::Parts::new(work);
        team.run_pieces(pieces, &|index| {
            let (mut s, group) = work.take(index);
            let boxes = layout.finish_group(&mut s, group, (arrived, anew));
            let group = &*group;
            then_each(GroupView {
                index,
                boxes,
                starts,
                group,
            });
        });
        (self.groups, self.laid) = (groups, laid);
    }

    /// [`Layout::lay_out`] of last step's layout on one thread, in place:
    /// each band's stayers closed up at its front (a run at a time between
    /// the movers' places), the bands' runs moved to their new starts
    /// (those moving up from the last band down, then those moving down
    /// from the first up, so that no run lands on one not yet moved), each
    /// band finished by insertion with its movers (`mover_starts` of the
    /// sorted movers) inserted, and its guests listed; then the one group
    /// handed to `then_each`. One thread has no other group to copy
    /// boxes past, so it moves only what changed instead of copying every
    /// box into the other arrays as the groups do (docs/DESIGN.md, "Sweep
    /// and prune", several bands); but where every band shifts, what
    /// changed is every box, moved up to three times, and the copy is
    /// quicker ([`Schedule::LAYOUT_COPIED_FROM`]).
    fn finish_in_place(
        &mut self,
        arriving: &mut Boxes,
        n: usize,
        bands: &Bands,
        then_each: ThenEach,
    ) {
        let count = bands.count;
        let mut boxes = arriving.slice_mut(n);
        let (old, new, stayed) = (&self.old_starts, &self.starts, &self.stayed);
        for b in 0..=count {
            let gaps = &self.gaps[self.gap_starts[b]..self.gap_starts[b + 1]];
            let mut w = old[b];
            for run in runs_between(old[b]..old[b + 1], gaps) {
                if w != run.start {
                    boxes.copy_within(run.clone(), w);
                }
                w += run.len();
            }
        }
        for b in (0..=count).rev().filter(|&b| new[b] > old[b]) {
            boxes.copy_within(old[b]..old[b] + stayed[b], new[b]);
        }
        for b in (0..=count).filter(|&b| new[b] < old[b]) {
            boxes.copy_within(old[b]..old[b] + stayed[b], new[b]);
        }
        let (movers, group) = (&self.movers, &mut self.groups[0]);
        group.start(0..count);
        for b in 0..=count {
            let moved = self.mover_starts[b]..self.mover_starts[b + 1];
            let mut band = boxes.at(new[b]..new[b + 1]);
            if b == count {
                // The boxes without a key: in any order.
                band.copy_from(stayed[b], movers.slice(0..movers.len()), moved);
                break;
            }
            sort_nearly_sorted(band.at(0..stayed[b]), &mut group.order, &mut group.spare);
            insert_runs(band.at(0..band.len()), stayed[b], movers, moved);
            group.end_guests(band.view(), b, b + 1 < count, bands);
        }
        let (starts, group) = (&self.starts, &self.groups[0]);
        then_each(GroupView {
            index: 0,
            boxes: boxes.view(),
            starts,
            group,
        });
    }

    /// Puts together what the shares noted (see [`Layout::mover_check`]):
    /// the movers and their places in `movers` and `gaps` (ascending),
    /// where each band's places start in `gap_starts`, and the stayers of
    /// each band in `stayed`, for last step's `starts` of `count` bands.
    /// Returns per band the greatest value across the bands that its
    /// stayers reach.
    fn gather_movers(&mut self, count: usize) -> Vec<f32> {
        let old = &self.starts;
        let mut tops = vec![f32::NEG_INFINITY; count + 1];
        self.stayed.clear();
        self.stayed.extend((0..=count).map(|b| old[b + 1] - old[b]));
        self.movers.clear();
        self.gaps.clear();
        for share in &self.noted[..self.noted_shares] {
            self.movers.extend(&share.movers);
            self.gaps.extend_from_slice(&share.gaps);
            for &(b, left, top) in &share.runs {
                self.stayed[b] -= left;
                tops[b] = tops[b].max(top);
            }
        }
        let stayed = &self.stayed;
        let left = (0..=count).map(|b| (old[b + 1] - old[b] - stayed[b]) as u32);
        set_starts(left, &mut self.gap_starts);
        tops
    }
}

/// Finds the boxes of band `b` (the boxes `band` of `boxes`, which start
/// at place `at`) that left it: pushes each to `into`'s movers with its
/// new home band and its place to its gaps; with `CARRY`, notes the
/// stayers that reach `carry` across as guests of the next group's first
/// band. Returns the greatest value across the bands that the stayers
/// reach.
fn close_up<const CARRY: bool>(
    boxes: BoxSlice,
    at: usize,
    band: Range<usize>,
    (b, carry): (usize, f32),
    check: &MoverCheck,
    into: &mut Noted,
) -> f32 {
    let BoxSlice { keys, hulls, slots } = boxes;
    let (bands, across) = (&check.bands, check.bands.across);
    let mut leave = |k: usize, home: usize| {
        into.movers.push(keys[k], hulls[k], slots[k], home as u32);
        into.gaps.push(at + k);
    };
    if b == bands.count {
        // The boxes without a key: those that have one now leave.
        for k in band.filter(|&k| keys[k] != NO_KEY) {
            leave(k, bands.of(lo(&hulls[k], across)));
        }
        return f32::NEG_INFINITY;
    }
    let (low, high) = (check.edges[b], check.edges[b + 1]);
    let home = |key: f32, v: f32| {
        if key == NO_KEY {
            bands.count
        } else {
            bands.of(v)
        }
    };
    let (first, band_keys, band_hulls) = (band.start, &keys[band.clone()], &hulls[band]);
    // Eight boxes at a time, in arrays the compiler works on as vectors:
    // which stay, and the greatest value across that those reach; the rare
    // box that leaves is taken on its own.
    let mut tops = [f32::NEG_INFINITY; 8];
    // A box that stays and reaches the next group's first band is noted as
    // one of its guests.
    let mut carry_one = |k: usize, h: f32| {
        let end = bands.of(h) as u32 + 1;
        into.carried.push(keys[k], hulls[k], slots[k], end);
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
                leave(first + c * 8 + j, home(keys8[j], v[j]));
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
            leave(first + k, home(key, v));
        }
    }
    top
}

/// The runs of the boxes `band` between its `gaps` (ascending places
/// within it), in order.
fn runs_between(band: Range<usize>, gaps: &[usize]) -> impl Iterator<Item = Range<usize>> + '_ {
    let ends = gaps.iter().copied().chain(std::iter::once(band.end));
    let starts = std::iter::once(band.start).chain(gaps.iter().map(|&g| g + 1));
    starts.zip(ends).filter(|(s, e)| s < e).map(|(s, e)| s..e)
}

impl Layout {
    /// The runs of band `b`'s stayers, where they arrived.
    fn stayers(&self, b: usize) -> impl Iterator<Item = Range<usize>> + '_ {
        let band = self.old_starts[b]..self.old_starts[b + 1];
        runs_between(band, &self.gaps[self.gap_starts[b]..self.gap_starts[b + 1]])
    }

    /// Fills band `band`'s boxes `out` with its stayers (copied from
    /// `arrived`, a run at a time) and its movers, each mover before the
    /// stayer that `place(keys, key)` gives in a run, or after the run.
    fn merge_in(
        &self,
        mut out: BoxSliceMut,
        arrived: BoxSlice,
        band: usize,
        place: impl Fn(&[f32], f32) -> usize,
    ) {
        let movers = self.movers.slice(0..self.movers.len());
        let moved = self.mover_starts[band]..self.mover_starts[band + 1];
        let (mut at, mut next) = (0, moved.start);
        for mut run in self.stayers(band) {
            while next < moved.end {
                let split = run.start + place(&arrived.keys[run.clone()], movers.keys[next]);
                if split == run.end {
                    break;
                }
                at = out.copy_from(at, arrived, run.start..split);
                at = out.copy_from(at, movers, next..next + 1);
                (next, run.start) = (next + 1, split);
            }
            at = out.copy_from(at, arrived, run);
        }
        at = out.copy_from(at, movers, next..moved.end);
        debug_assert_eq!(at, out.len());
    }

    /// Finishes one group's bands in its stretch of the other arrays:
    /// each band's stayers (from `arrived`) copied in with its movers
    /// merged in, then sorted (by radix at once where made `anew`); then
    /// its guests, the first band's from the stayers below noted as
    /// reaching it and the movers to the bands below that do. Returns the
    /// stretch, finished.
    fn finish_group<'a>(
        &self,
        s: &'a mut Stretch,
        group: &mut Group,
        (arrived, anew): (BoxSlice, bool),
    ) -> BoxSlice<'a> {
        let (range, boxes) = (s.bands.clone(), &mut s.boxes);
        let offset = self.starts[range.start];
        let bands = self.kept.as_ref().expect("the bands laid out");
        let count = bands.count;
        group.start(range.start..range.end.min(count));
        // The first band's guests: the boxes of the bands below whose reach
        // ends in it or above, stayers and movers alike.
        let b0 = range.start;
        let from = (0..b0)
            .find(|&b| self.last_band[b] as usize >= b0)
            .unwrap_or(b0);
        let Group {
            guests,
            order,
            spare,
            ..
        } = &mut *group;
        // The stayers among them were noted as their hulls were made, by the
        // thread that made them: the bands below, which another thread laid
        // out, are not read again.
        for share in &self.noted[..self.noted_shares] {
            let noted = &share.carried;
            for (k, &band) in share.carried_from.iter().enumerate() {
                if (band as usize) < b0 && noted.ends[k] as usize > b0 {
                    guests.push_from(noted, k);
                }
            }
        }
        let m = &self.movers;
        for k in self.mover_starts[from]..self.mover_starts[b0] {
            let end = bands.of(hi(&m.hulls[k], bands.across)) as u32 + 1;
            if end as usize > b0 {
                guests.push(m.keys[k], m.hulls[k], m.slots[k], end);
            }
        }
        if guests.len() > 1 {
            guests.sort(order, spare);
        }
        for band in range {
            let out = self.starts[band] - offset..self.starts[band + 1] - offset;
            if band == count {
                // The boxes without a key: in any order.
                self.merge_in(boxes.at(out), arrived, band, |keys, _| keys.len());
                break;
            }
            // The movers merged in as the stayers are copied, each before
            // the first stayer past it (a place found by binary search in
            // the nearly sorted stayers, so possibly a little off); then the
            // band sorted, which puts right what is off. A band made anew
            // holds movers alone, in no order.
            self.merge_in(boxes.at(out.clone()), arrived, band, |keys, key| {
                keys.partition_point(|&k| k <= key)
            });
            let (order, spare) = (&mut group.order, &mut group.spare);
            match anew {
                true => boxes.at(out.clone()).sort_by_radix(order, spare),
                false => sort_nearly_sorted(boxes.at(out.clone()), order, spare),
            }
            let next = band + 1 < group.bands.end;
            group.end_guests(boxes.view().at(out), band, next, bands);
        }
        let boxes: &'a BoxSliceMut = boxes;
        boxes.view()
    }
}
