//! The boxes laid out band by band: each box once in its home band, each
//! band sorted, and beside it its guests, sorted too.
//!
//! A pair of overlapping boxes is reported in the band holding the larger
//! of their two least values across: there both are homes, or one is a
//! home and the other a guest. So a band is swept as its homes among
//! themselves and against its guests ([`super::scan`]), and no pair needs a
//! test of which band reports it.
//!
//! The homes, band by band, are the order next step's boxes are made in,
//! so [`update`] keeps last step's layout and moves only the movers. A
//! layout made anew (on the first step, and whenever the bands change) is
//! the same update with every box a mover and no stayers, the movers put
//! in their bands by a counting sort and each band sorted by radix.

mod update;

use super::bands::Bands;
use super::boxes::{sort_nearly_sorted, Boxes};
use super::boxes::{BoxList, BoxSlice, BoxSliceMut};
use super::hull::hi;
use std::ops::Range;

/// The boxes band by band (see the [module docs](self)).
#[derive(Debug, Default)]
pub(crate) struct Layout {
    /// Where each band's homes start among the laid-out boxes, then where
    /// the boxes without a key start, then their end: `count + 2` values.
    pub starts: Vec<usize>,
    /// The same for last step's layout, which the boxes arrive in (empty
    /// when they arrive in another order).
    old_starts: Vec<usize>,
    /// Per group of bands, its guests and working buffers (the first
    /// `group_count` in use); kept from step to step.
    groups: Vec<Group>,
    group_count: usize,
    /// Per band (and the boxes without a key), its homes, then the
    /// furthest band they reach.
    counts: Vec<u32>,
    last_band: Vec<u32>,
    /// The bands the boxes are laid out in, while the arriving boxes are
    /// in that layout's order (so that [`Layout::lay_out`] can update it).
    kept: Option<Bands>,
    /// Per band (and the boxes without a key), the boxes that stayed in it
    /// this step.
    stayed: Vec<usize>,
    /// The least value of each band (`-inf` for the first), then `+inf`,
    /// for the bands in `kept`.
    edges: Vec<f32>,
    /// The movers of this step, each with its new home band as its end
    /// (sorted by it, each band's from its `mover_starts` on), and where
    /// they were: ascending, each band's from its `gap_starts` on.
    movers: BoxList,
    mover_starts: Vec<usize>,
    gaps: Vec<usize>,
    gap_starts: Vec<usize>,
    /// What shares of the arriving boxes noted as their hulls were made
    /// (the first `noted_shares`), and the bands and groups they were
    /// noted for.
    noted: Vec<update::Noted>,
    noted_shares: usize,
    noted_for: Option<(Bands, usize)>,
    /// Per band, where the guests of the next group's first band begin
    /// (see [`update::MoverCheck`]), for the bands and groups noted for.
    carry: Vec<f32>,
    /// The laid-out boxes, exchanged with the arriving boxes once laid out.
    laid: Boxes,
    /// Boxes from which one thread copies a kept layout rather than
    /// updating it in place, where not [`Schedule::LAYOUT_COPIED_FROM`]
    /// (tests copy small layouts).
    ///
    /// [`Schedule::LAYOUT_COPIED_FROM`]: crate::schedule::Schedule::LAYOUT_COPIED_FROM
    copied_from: Option<usize>,
}

/// One group of bands as its member laid it out, for the member to sweep
/// before the others finish.
pub(crate) struct GroupView<'a> {
    /// The group's number, in band order.
    pub index: usize,
    /// The group's stretch of the laid-out boxes: its homes.
    pub boxes: BoxSlice<'a>,
    /// Where each band starts among all the boxes.
    starts: &'a [usize],
    group: &'a Group,
}

impl GroupView<'_> {
    /// The group's bands (without the boxes that have no key).
    pub(crate) fn bands(&self) -> Range<usize> {
        self.group.bands.clone()
    }

    /// Where the homes of band `band` lie in the stretch.
    pub(crate) fn homes(&self, band: usize) -> Range<usize> {
        let offset = self.starts[self.group.bands.start];
        self.starts[band] - offset..self.starts[band + 1] - offset
    }

    /// The guests of band `band`, sorted by key.
    pub(crate) fn guests(&self, band: usize) -> BoxSlice<'_> {
        self.group.guests(band)
    }
}

/// What a member does with its group once laid out ([`Layout::lay_out`]).
pub(crate) type ThenEach<'a> = &'a (dyn Fn(GroupView<'_>) + Sync);

/// One group's guests and working buffers.
#[derive(Debug, Default)]
struct Group {
    /// The group's bands (without the boxes that have no key).
    bands: Range<usize>,
    /// The guests of the group's bands, one band after another, and where
    /// each band's start (then their end).
    guests: BoxList,
    guest_starts: Vec<u32>,
    /// Keys and places, spare boxes, and places to write, to sort.
    order: Vec<(f32, u32)>,
    spare: BoxList,
    cursor: Vec<usize>,
}

impl Group {
    /// The guests of band `band`, sorted by key.
    fn guests(&self, band: usize) -> BoxSlice<'_> {
        let k = band - self.bands.start;
        let s = &self.guest_starts;
        self.guests.slice(s[k] as usize..s[k + 1] as usize)
    }

    /// Starts the guests of its bands `bands`.
    fn start(&mut self, bands: Range<usize>) {
        self.bands = bands;
        self.guests.clear();
        self.guest_starts.clear();
        self.guest_starts.push(0);
    }
}

impl Layout {
    /// The least value of each of `bands`, for the layouts kept from this
    /// one: a box that stays in its band is told by two comparisons.
    fn set_edges(&mut self, bands: &Bands) {
        self.edges.clear();
        self.edges.push(f32::NEG_INFINITY);
        self.edges.extend((1..bands.count).map(|b| bands.edge(b)));
        self.edges.push(f32::INFINITY);
    }

    /// The guests of band `band`, sorted by key.
    #[cfg(test)]
    pub(crate) fn guests(&self, band: usize) -> BoxSlice<'_> {
        let groups = &self.groups[..self.group_count];
        let group = groups.iter().find(|g| g.bands.contains(&band));
        group.expect("the band's group").guests(band)
    }

    /// Forgets last step's layout: the boxes will arrive in another order.
    pub(crate) fn forget(&mut self) {
        self.starts.clear();
        self.kept = None;
        self.edges.clear();
    }

    /// Guests in all bands.
    pub(crate) fn guest_count(&self) -> usize {
        let groups = &self.groups[..self.group_count];
        groups.iter().map(|g| g.guests.len()).sum()
    }
}

/// One group's stretch of the laid-out boxes: its bands and their boxes.
struct Stretch<'a> {
    bands: Range<usize>,
    boxes: BoxSliceMut<'a>,
}

/// Splits `rest` into stretches of whole bands (which start at
/// `starts`), one per range of `bounds`.
fn stretches<'a>(
    starts: &[usize],
    mut rest: BoxSliceMut<'a>,
    bounds: &[Range<usize>],
) -> Vec<Stretch<'a>> {
    let cut = |bands: &Range<usize>| {
        let len = starts[bands.end] - starts[bands.start];
        let (boxes, after) = std::mem::take(&mut rest).split_at(len);
        rest = after;
        let bands = bands.clone();
        Stretch { bands, boxes }
    };
    bounds.iter().map(cut).collect()
}

/// The movers cut into runs for a counting sort shared among members:
/// band by band, each band's run of each member (of `counts[member][band]`
/// boxes) in member order. Returns each member's runs, in band order,
/// with their ends.
fn member_runs<'a>(
    movers: &'a mut BoxList,
    counts: &[Vec<usize>],
) -> Vec<Vec<(BoxSliceMut<'a>, &'a mut [u32])>> {
    let BoxList {
        keys,
        hulls,
        slots,
        ends,
    } = movers;
    let (mut rest, mut rest_ends) = (BoxSliceMut::new(keys, hulls, slots), &mut ends[..]);
    let mut runs: Vec<Vec<_>> = counts.iter().map(|_| Vec::new()).collect();
    for b in 0..counts.first().map_or(0, Vec::len) {
        for (member, member_counts) in counts.iter().enumerate() {
            let (run, tail) = std::mem::take(&mut rest).split_at(member_counts[b]);
            let (run_ends, tail_ends) = std::mem::take(&mut rest_ends).split_at_mut(run.len());
            runs[member].push((run, run_ends));
            (rest, rest_ends) = (tail, tail_ends);
        }
    }
    runs
}

/// Consecutive ranges of the bands that start at `starts` (`count + 2`
/// values: the boxes without a key are one more band), at most `groups`
/// of them, with about the same number of homes; the last also holding
/// the boxes without a key.
fn groups_of_bands(starts: &[usize], groups: usize) -> Vec<Range<usize>> {
    let count = starts.len() - 2;
    let (total, groups) = (starts[count], groups.clamp(1, count.max(1)));
    let mut bounds = Vec::with_capacity(groups);
    let mut first = 0;
    for g in 1..=groups {
        let target = total * g / groups;
        // The band boundary nearest the target.
        let after = starts[..=count].partition_point(|&s| s < target).min(count);
        let nearer = after > 0 && target - starts[after - 1] < starts[after] - target;
        let last = match g == groups {
            true => count,
            false => after - usize::from(nearer),
        };
        let last = last.max(first);
        if last > first {
            bounds.push(first..last);
        }
        first = last;
    }
    match bounds.last_mut() {
        Some(last) => last.end = count + 1,
        None => bounds.push(0..count + 1),
    }
    bounds
}

/// Sets `starts` to where each band's boxes start, from the boxes counted
/// in each, and their end.
fn set_starts(counts: impl Iterator<Item = u32>, starts: &mut Vec<usize>) {
    starts.clear();
    starts.push(0);
    for c in counts {
        starts.push(starts[starts.len() - 1] + c as usize);
    }
}

impl Group {
    /// Ends band `band`'s guests and, if the band after it is in the group
    /// (`next`), lists that band's guests after them: `band`'s `homes`
    /// (sorted) and guests that reach beyond it, merged in key order.
    fn end_guests(&mut self, homes: BoxSlice, band: usize, next: bool, bands: &Bands) {
        let Group {
            guests,
            guest_starts,
            spare,
            ..
        } = self;
        let own = *guest_starts.last().expect("the band's start") as usize..guests.len();
        guest_starts.push(guests.len() as u32);
        if !next {
            return;
        }
        spare.clear();
        // The next home that reaches beyond the band, and the band after
        // the last it reaches: one comparison with the next band's edge a
        // home, the band worked out only for those that reach.
        let edge = bands.edge(band + 1);
        let next_home = |i: &mut usize| {
            while *i < homes.len() {
                let top = hi(&homes.hulls[*i], bands.across);
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
            while j < own.end && guests.ends[j] as usize <= band + 1 {
                j += 1;
            }
            match end_i {
                Some(end) if j == own.end || homes.keys[i] <= guests.keys[j] => {
                    spare.push(homes.keys[i], homes.hulls[i], homes.slots[i], end);
                    i += 1;
                    end_i = next_home(&mut i);
                }
                _ if j < own.end => {
                    spare.push_from(guests, j);
                    j += 1;
                }
                _ => break,
            }
        }
        guests.extend(spare);
    }
}

impl Group {
    /// Sorts the movers of a kept layout by band (their end; band `b`'s to
    /// `starts[b]` on), in their order within a band, and each band's by
    /// key. A counting sort: each mover is read in turn and written to its
    /// band's place.
    fn sort_movers(&mut self, movers: &mut BoxList, starts: &[usize]) {
        let Group {
            order,
            spare,
            cursor,
            ..
        } = self;
        cursor.clear();
        cursor.extend_from_slice(starts);
        spare.resize(movers.len());
        for k in 0..movers.len() {
            let to = &mut cursor[movers.ends[k] as usize];
            spare.set(*to, movers, k);
            *to += 1;
        }
        std::mem::swap(movers, spare);
        for band in starts.windows(2).filter(|b| b[1] - b[0] > 1) {
            sort_nearly_sorted(movers.slice_mut(band[0]..band[1]), order, spare);
        }
    }
}

/// Inserts the sorted movers `moved` into a band whose first `stayed`
/// boxes are sorted and whose rest is free: from the largest down, each
/// found by binary search and the boxes above it moved up in one copy, so
/// that each box moves at most once and a few movers cost a few copies
/// of contiguous memory.
fn insert_runs(mut band: BoxSliceMut, stayed: usize, movers: &BoxList, moved: Range<usize>) {
    debug_assert_eq!(band.len(), stayed + moved.len());
    let mut end = stayed;
    for (up, m) in (1..=moved.len()).rev().zip(moved.rev()) {
        let at = band.keys[..end].partition_point(|&k| k <= movers.keys[m]);
        band.copy_within(at..end, at + up);
        band.copy_from(at + up - 1, movers.slice(m..m + 1), 0..1);
        end = at;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::sweep::hull::{Packed, NO_KEY};
    use crate::index::Slot;
    use crate::team::Team;
    use std::sync::Mutex;

    fn hull(key: f32, lo_y: f32, hi_y: f32) -> Packed {
        let n = f32::NEG_INFINITY;
        [key, lo_y, n, n, -(key + 1.0), -hi_y, n, n]
    }

    /// The numbers of `slots`.
    fn raw(slots: &[Slot]) -> Vec<u32> {
        slots.iter().map(|s| s.0).collect()
    }

    /// Boxes keyed `keys` with spans across y from `ys`, slots from 10.
    fn boxes_of(keys: &[f32], ys: &[(f32, f32)]) -> Boxes {
        let mut b = Boxes::default();
        b.reset(keys.len());
        for (k, (&key, &(lo, hi))) in keys.iter().zip(ys).enumerate() {
            b.keys[k] = key;
            b.hulls[k] = hull(key, lo, hi);
            b.slots[k] = Slot(10 + k as u32);
        }
        b
    }

    /// Lays out `b` anew, a group of bands a member of `team`.
    fn lay_out(b: &mut Boxes, bands: &Bands, layout: &mut Layout, team: &Team) -> usize {
        layout.forget();
        layout.lay_out(b, b.len(), bands, team, &|_| {})
    }

    #[test]
    fn boxes_go_home_sorted_with_their_guests_beside() {
        let bands = Bands::spanning(1, 2, 0.0, 1.0);
        // Ids 10..14; 11 spans both bands; 13 takes no part.
        let keys = [0.5, 0.0, 0.7, NO_KEY, 0.1];
        let ys = [(0.1, 0.2), (0.1, 0.9), (0.6, 0.7), (0.0, 0.0), (0.8, 0.9)];
        for threads in [1, 2, 3] {
            let mut b = boxes_of(&keys, &ys);
            let mut layout = Layout::default();
            let team = Team::new(threads).unwrap();
            assert_eq!(lay_out(&mut b, &bands, &mut layout, &team), 4);
            assert_eq!(layout.starts, vec![0, 2, 4, 5]);
            assert_eq!(raw(&b.slots), vec![11, 10, 14, 12, 13, u32::MAX]);
            assert_eq!(b.keys[..4], [0.0, 0.5, 0.1, 0.7]);
            assert_eq!(raw(layout.guests(0).slots), &[] as &[u32]);
            assert_eq!(raw(layout.guests(1).slots), &[11]);
            assert_eq!(layout.guest_count(), 1);
        }
    }

    /// Every layout, however the boxes arrive, holds each box with a key
    /// once at home, sorted, and as a guest in exactly the bands above its
    /// home that it reaches, sorted.
    #[test]
    fn layouts_hold_every_box_at_home_and_as_guest_where_it_reaches() {
        // One thread's kept layouts updated in place, then copied.
        for copied_from in [None, Some(0)] {
            every_box_at_home_and_as_guest(copied_from);
        }
    }

    fn every_box_at_home_and_as_guest(copied_from: Option<usize>) {
        let n = 3000usize;
        let mut state = 12345u64;
        let mut rand = move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 33) as f32) / (1u64 << 31) as f32
        };
        let mut keys: Vec<f32> = (0..n).map(|_| rand()).collect();
        let spans = (0..n).map(|_| (rand(), rand() * rand() * 0.3));
        let mut ys: Vec<(f32, f32)> = spans.map(|(y, h)| (y, y + h)).collect();
        (keys[7], keys[100]) = (NO_KEY, NO_KEY);
        let mut layout = Layout {
            copied_from,
            ..Layout::default()
        };
        let mut b = boxes_of(&keys, &ys);
        let teams = [1, 2, 3, 8].map(|threads| Team::new(threads).unwrap());
        let mut kept = 0;
        for step in 0..16 {
            let count = [7, 7, 7, 13, 1000, 7, 7, 7, 7, 7, 3, 3, 9, 9, 9, 9][step];
            let bands = Bands::spanning(1, count, 0.0, 1.0);
            let groups = [1, 2, 3, 2, 8, 1, 2, 3, 1, 1, 2, 1, 2, 3, 2, 3][step];
            // A group of bands a member.
            let team = teams.iter().find(|t| t.threads() == groups).unwrap();
            // Boxes move a little (and a few far) between steps, arriving
            // in last step's layout order.
            if step > 0 {
                for k in 0..n {
                    let id = b.slots[k].0 as usize - 10;
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
                    // Line 60 the same in layouts kept by groups, steps 13
                    // to 15.
                    if id == 60 && step >= 13 {
                        keys[id] = if step < 15 { NO_KEY } else { 0.75 };
                    }
                    b.keys[k] = keys[id];
                    b.hulls[k] = hull(keys[id], ys[id].0, ys[id].1);
                }
            }
            // From step 8 on, the layout is kept where the bands are the
            // same as the step before's.
            let no_key = if (9..11).contains(&step) || (13..15).contains(&step) {
                3
            } else {
                2
            };
            let boxed = if step >= 8 {
                kept += usize::from(layout.keeps(&bands, n));
                layout.lay_out(&mut b, n, &bands, team, &|_| {})
            } else {
                lay_out(&mut b, &bands, &mut layout, team)
            };
            assert_eq!(boxed, n - no_key);
            let mut seen: Vec<u32> = raw(&b.slots[..n]);
            seen.sort_unstable();
            assert_eq!(seen, (10..10 + n as u32).collect::<Vec<_>>());
            assert_eq!(b.slots[n].0, u32::MAX);
            for band in 0..count {
                let homes = layout.starts[band]..layout.starts[band + 1];
                assert!(b.keys[homes.clone()].windows(2).all(|w| w[0] <= w[1]));
                for at in homes {
                    let id = b.slots[at].0 as usize - 10;
                    assert_eq!(b.keys[at], keys[id]);
                    assert_eq!(bands.of(ys[id].0), band);
                }
                let (gk, gi) = (layout.guests(band).keys, layout.guests(band).slots);
                assert!(gk.windows(2).all(|w| w[0] <= w[1]));
                let mut want: Vec<u32> = (0..n)
                    .filter(|&id| {
                        keys[id] != NO_KEY
                            && bands.of(ys[id].0) < band
                            && bands.of(ys[id].1) >= band
                    })
                    .map(|id| id as u32 + 10)
                    .collect();
                let mut got = raw(gi);
                want.sort_unstable();
                got.sort_unstable();
                assert_eq!(got, want, "step {step}, band {band}");
            }
        }
        // Steps 8, 9 and 11 on one thread; 13, 14 and 15 in groups.
        assert_eq!(kept, 6);
    }

    /// Movers noted in shares as the hulls are made, many bands empty
    /// and shares cutting bands anywhere, give the layout that keeping it
    /// without them does, on one thread and in groups.
    #[test]
    fn movers_noted_in_shares_keep_the_same_layout() {
        let n = 2000usize;
        // Boxes in a few of 40 bands across y (most bands empty).
        let key = |k: usize| (k * 7919 % n) as f32 / n as f32;
        let ys: Vec<(f32, f32)> = (0..n)
            .map(|k| {
                let y = [0.05, 0.3, 0.31, 0.8][k % 4] + (k % 13) as f32 * 1e-3;
                (y, y + (k % 5) as f32 * 0.01)
            })
            .collect();
        let keys: Vec<f32> = (0..n).map(key).collect();
        let bands = Bands::spanning(1, 40, 0.0, 1.0);
        for groups in [1, 2, 3] {
            let team = &Team::new(groups).unwrap();
            let mut laid = Vec::new();
            // Kept without the movers noted, with them, and with them and
            // copied (on one thread, rather than in place).
            for (noted, copied) in [(false, false), (true, false), (true, true)] {
                let mut b = boxes_of(&keys, &ys);
                let mut layout = Layout {
                    copied_from: copied.then_some(0),
                    ..Layout::default()
                };
                lay_out(&mut b, &bands, &mut layout, team);
                // A few boxes move to other bands, one loses its key.
                for k in 0..n {
                    let id = b.slots[k].0 as usize - 10;
                    if id % 37 == 0 {
                        let (lo, hi) = (ys[id].0 + 0.25, ys[id].1 + 0.25);
                        b.hulls[k] = hull(b.keys[k], lo.min(0.99), hi.min(0.99));
                    }
                    if id == 100 {
                        b.keys[k] = NO_KEY;
                    }
                }
                if noted {
                    let shares = [0, 333, 1000, 1001, n];
                    let (check, into) = layout.mover_check(n, &bands, 4, groups);
                    let check = check.unwrap();
                    for (s, movers) in shares.windows(2).zip(into.iter_mut()) {
                        let range = s[0]..s[1];
                        movers.clear();
                        check.note(range.start, b.slice(n).at(range), movers);
                    }
                }
                // Each group as handed on once laid out: its bands' homes
                // and guests as the layout ends up.
                let handed = Mutex::new(Vec::new());
                let collect = |g: GroupView| {
                    let per_band: Vec<_> = g
                        .bands()
                        .map(|band| {
                            (
                                band,
                                g.boxes.slots[g.homes(band)].to_vec(),
                                g.guests(band).slots.to_vec(),
                            )
                        })
                        .collect();
                    handed.lock().unwrap().push((g.index, per_band));
                };
                assert!(layout.keeps(&bands, n));
                assert_eq!(layout.lay_out(&mut b, n, &bands, team, &collect), n - 1);
                let mut handed = handed.into_inner().unwrap();
                assert_eq!(handed.len(), groups);
                handed.sort_by_key(|h| h.0);
                let handed: Vec<_> = handed.into_iter().flat_map(|h| h.1).collect();
                let bands_handed: Vec<usize> = handed.iter().map(|h| h.0).collect();
                assert_eq!(bands_handed, (0..40).collect::<Vec<_>>(), "{groups} groups");
                for (band, homes, guests) in handed {
                    let at = layout.starts[band]..layout.starts[band + 1];
                    assert_eq!(homes, b.slots[at], "band {band}");
                    assert_eq!(guests, layout.guests(band).slots, "band {band}");
                }
                let guests: Vec<u32> = (0..40).flat_map(|g| raw(layout.guests(g).slots)).collect();
                laid.push((
                    b.slots.clone(),
                    b.keys.clone(),
                    layout.starts.clone(),
                    guests,
                ));
            }
            assert!(laid[0] == laid[1], "{groups} groups, noted");
            assert!(laid[0] == laid[2], "{groups} groups, copied");
        }
    }
}
