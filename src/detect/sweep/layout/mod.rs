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
//! so a step lays out boxes that arrive nearly in place: [`update`] keeps
//! last step's layout and moves only the boxes that changed band. A layout
//! made anew (on the first step, and whenever the bands change) is the
//! same update of a layout that held every box among the boxes without a
//! key: every box is then a newcomer to its band.
//!
//! A box that stayed in its band arrives nearly sorted and is finished by
//! an insertion sort in place; the few that moved in are sorted apart and
//! merged in; and each band's guests are the entries of the band below
//! that reach up into it, taken in sorted order as that band is done.
//! This file holds the layout's arrays and the steps of a band.

mod update;

use super::bands::Bands;
use super::hull::{hi, Packed};
use super::order::{insert, Boxes};
use crate::team::Team;
use std::ops::Range;
use std::sync::Mutex;

/// Moves an insertion sort of one band may make per entry before the band
/// is sorted by radix instead.
const MOVES_PER_ENTRY: usize = 8;

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
    /// Per band (and the boxes without a key), its homes, then the
    /// furthest band they reach.
    counts: Vec<u32>,
    reach: Vec<u32>,
    /// The bands the boxes are laid out in, while the arriving boxes are
    /// in that layout's order (so that [`Layout::lay_out`] can update it).
    kept: Option<Bands>,
    /// Per band (and the boxes without a key), the boxes that stayed in it
    /// this step.
    stayed: Vec<usize>,
    /// The least value of each band (`-inf` for the first), then `+inf`,
    /// for the bands in `kept`.
    edges: Vec<f32>,
    /// The boxes that changed band this step, when a layout kept is
    /// shared among groups, and where they were: ascending, each band's
    /// from the start `gap_starts` gives.
    movers: Run,
    gaps: Vec<usize>,
    gap_starts: Vec<usize>,
    /// What shares of the arriving boxes noted as their hulls were made
    /// (the first `noted_shares`), and the bands they were noted for.
    noted: Vec<update::Leavers>,
    noted_shares: usize,
    noted_for: Option<(Bands, usize)>,
    /// Per band, where the guests of the next group's first band begin
    /// (see [`update::LeaverCheck`]), for the bands and groups noted for.
    carry: Vec<f32>,
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

    /// Sorts the entries `range` by key (through `order` and `spare`), in
    /// `f32`'s total order, entries with equal keys kept in their order.
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

/// One group of bands as its member laid it out: its homes (the group's
/// stretch of the laid-out boxes) and its guests, band by band, for the
/// member to sweep before the others finish.
pub(crate) struct GroupView<'a> {
    /// The group's number, in band order.
    pub index: usize,
    /// The group's bands (without the boxes that have no key).
    pub bands: Range<usize>,
    /// The group's stretch: keys, hulls and ids.
    pub keys: &'a [f32],
    pub hulls: &'a [Packed],
    pub ids: &'a [u32],
    /// Where the stretch starts among all the boxes, and where each band
    /// starts there.
    offset: usize,
    starts: &'a [usize],
    guests: &'a Run,
    guest_starts: &'a [u32],
}

impl<'a> GroupView<'a> {
    /// Group `index` of bands `bands`, laid out in its stretch (`keys`,
    /// `hulls` and `ids`, from `offset` among all the boxes, whose bands
    /// start at `starts`), its guests in `group`.
    fn of(
        index: usize,
        bands: Range<usize>,
        offset: usize,
        (keys, hulls, ids): (&'a [f32], &'a [Packed], &'a [u32]),
        starts: &'a [usize],
        group: &'a Group,
    ) -> Self {
        GroupView {
            index,
            bands,
            keys,
            hulls,
            ids,
            offset,
            starts,
            guests: &group.guests,
            guest_starts: &group.guest_starts,
        }
    }

    /// Where the homes of band `band` lie in the stretch.
    pub(crate) fn homes(&self, band: usize) -> Range<usize> {
        self.starts[band] - self.offset..self.starts[band + 1] - self.offset
    }

    /// The guests of band `band`: keys, hulls and ids, sorted by key.
    pub(crate) fn guests(&self, band: usize) -> (&[f32], &[Packed], &[u32]) {
        let k = band - self.bands.start;
        let r = self.guest_starts[k] as usize..self.guest_starts[k + 1] as usize;
        let g = self.guests;
        (&g.keys[r.clone()], &g.hulls[r.clone()], &g.ids[r])
    }
}

/// What a member does with its group once laid out ([`Layout::lay_out`]).
pub(crate) type ThenEach<'a> = &'a (dyn Fn(GroupView<'_>) + Sync);

/// One group's guests and working buffers.
#[derive(Debug, Default)]
struct Group {
    /// The guests of the group's bands, one band after another.
    guests: Run,
    /// Where each of the group's bands' guests start in `guests`, and
    /// their end.
    guest_starts: Vec<u32>,
    /// Keys and positions, to sort.
    order: Vec<(f32, u32)>,
    /// Bands and keys of the movers, and their positions, to sort.
    by_band: Vec<(u64, u32)>,
    /// Spare entries for sorting.
    spare: Run,
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

    /// Where the homes of band `band` lie among the laid-out boxes.
    #[cfg(test)]
    pub(crate) fn homes(&self, band: usize) -> Range<usize> {
        self.starts[band]..self.starts[band + 1]
    }

    /// The guests of band `band`: keys, hulls and ids, sorted by key.
    #[cfg(test)]
    pub(crate) fn guests(&self, band: usize) -> (&[f32], &[Packed], &[u32]) {
        let (g, range) = &self.guest_at[band];
        let run = &self.groups[*g as usize].guests;
        let r = range.start as usize..range.end as usize;
        (&run.keys[r.clone()], &run.hulls[r.clone()], &run.ids[r])
    }

    /// Lists each band's guests from the groups' buffers (laid out in
    /// `bounds`, of `count` bands).
    fn list_guests(&mut self, bounds: &[Range<usize>], count: usize) {
        self.guest_at.clear();
        for (g, range) in bounds.iter().enumerate() {
            let gs = &self.groups[g].guest_starts;
            for b in range.start..range.end.min(count) {
                let k = b - range.start;
                self.guest_at.push((g as u32, gs[k]..gs[k + 1]));
            }
        }
    }

    /// Hands the laid-out boxes to `slots`, taking its arrays as next
    /// step's working arrays.
    fn hand_over(&mut self, slots: &mut Boxes) {
        std::mem::swap(&mut slots.keys, &mut self.keys);
        std::mem::swap(&mut slots.hulls, &mut self.hulls);
        std::mem::swap(&mut slots.ids, &mut self.ids);
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

/// One group's stretch of the laid-out arrays: its bands and their boxes.
struct Stretch<'a> {
    bands: Range<usize>,
    /// The first entry of the stretch.
    offset: usize,
    keys: &'a mut [f32],
    hulls: &'a mut [Packed],
    ids: &'a mut [u32],
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

/// Consecutive ranges of the bands that start at `starts` (`count + 2`
/// values: the boxes without a key are one more band), at most `groups`
/// of them, with about the same number of homes; the last also holding
/// the boxes without a key.
fn groups_of_bands(starts: &[usize], groups: usize) -> Vec<Range<usize>> {
    let count = starts.len() - 2;
    let mut bounds = group_bounds(&starts[..=count], groups);
    match bounds.last_mut() {
        Some(last) => last.end = count + 1,
        None => bounds.push(0..count + 1),
    }
    bounds
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

/// Runs `each` on every item of `work` with `team`, item `k` as piece `k`
/// (there are no more items than members).
fn run_each<W: Send>(work: Vec<W>, team: &Team, each: impl Fn(W) + Sync) {
    debug_assert!(work.len() <= team.threads());
    let work: Vec<Mutex<Option<W>>> = work.into_iter().map(|w| Mutex::new(Some(w))).collect();
    team.run_pieces(work.len(), &|k| {
        let taken = work[k].lock().expect("an item").take();
        if let Some(w) = taken {
            each(w);
        }
    });
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

/// Ends band `band`'s guests (the last run of `guests`, which started at
/// the last of `guest_starts`) and, if the band after it is in the same
/// group (`next`), lists that band's guests after them: `band`'s homes
/// (`homes`, sorted) and guests that reach beyond it.
fn end_guests(
    (guests, guest_starts): (&mut Run, &mut Vec<u32>),
    homes: (&[f32], &[Packed], &[u32]),
    band: usize,
    next: bool,
    bands: &Bands,
    spare: &mut Run,
) {
    let own = *guest_starts.last().expect("the band's start") as usize..guests.len();
    guest_starts.push(guests.len() as u32);
    if next {
        push_next_guests(guests, own, homes, band, bands, spare);
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

/// Sorts movers by band, and with `by_key` by key within each band
/// (through `order` and `spare`); else in arrival order within each band,
/// each written in turn to its band's place, which reads them in order
/// (a layout made anew has every box a mover: gathered in sorted order
/// instead, a million lines' first step took 0.3 s to lay out against 0.12).
fn sort_movers(movers: &mut Run, by_key: bool, order: &mut Vec<(u64, u32)>, spare: &mut Run) {
    let len = movers.len();
    spare.clear();
    if !by_key {
        let bands = movers.ends.iter().max().map_or(0, |&b| b as usize + 1);
        let mut at = vec![0usize; bands + 1];
        for &b in &movers.ends {
            at[b as usize + 1] += 1;
        }
        for b in 0..bands {
            at[b + 1] += at[b];
        }
        spare.keys.resize(len, 0.0);
        spare.hulls.resize(len, [0.0; 8]);
        spare.ids.resize(len, 0);
        spare.ends.resize(len, 0);
        for k in 0..len {
            let b = movers.ends[k] as usize;
            let to = at[b];
            at[b] += 1;
            spare.keys[to] = movers.keys[k];
            spare.hulls[to] = movers.hulls[k];
            spare.ids[to] = movers.ids[k];
            spare.ends[to] = movers.ends[k];
        }
        std::mem::swap(movers, spare);
        return;
    }
    // The band in the high half, the key's bits in `f32`'s total order in
    // the low half.
    let keyed = |(&key, &band): (&f32, &u32)| {
        let bits = key.to_bits();
        let ordered = if bits >> 31 == 1 {
            !bits
        } else {
            bits | 1 << 31
        };
        u64::from(band) << 32 | u64::from(ordered)
    };
    order.clear();
    order.extend(movers.keys.iter().zip(&movers.ends).map(keyed).zip(0u32..));
    order.sort_unstable_by_key(|k| k.0);
    for &(_, at) in order.iter() {
        let at = at as usize;
        spare.push(
            movers.keys[at],
            movers.hulls[at],
            movers.ids[at],
            movers.ends[at],
        );
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
    use crate::detect::sweep::{hull::NO_KEY, order::Boxes};
    use crate::team::Team;

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

    /// Lays out `b` anew, a group of bands a member of `team`.
    fn lay_out(b: &mut Boxes, bands: &Bands, layout: &mut Layout, team: &Team) -> usize {
        layout.forget();
        layout.lay_out(b, b.len(), bands, team, &|_| {})
    }

    /// Updates the layout of `b` if it can, else lays it out anew; says
    /// which.
    fn keep_or_lay_out(
        b: &mut Boxes,
        bands: &Bands,
        layout: &mut Layout,
        team: &Team,
    ) -> (usize, bool) {
        let kept = layout.keeps(bands, b.len());
        (layout.lay_out(b, b.len(), bands, team, &|_| {}), kept)
    }

    #[test]
    fn boxes_go_home_sorted_with_their_guests_beside() {
        let bands = Bands::spanning(1, 2, 0.0, 1.0);
        // Ids 10..14; 11 spans both bands; 13 takes no part.
        let keys = [0.5, 0.0, 0.7, NO_KEY, 0.1];
        let ys = [(0.1, 0.2), (0.1, 0.9), (0.6, 0.7), (0.0, 0.0), (0.8, 0.9)];
        for threads in [1, 2, 3] {
            let mut b = slots(&keys, &ys);
            let mut layout = Layout::default();
            let team = Team::new(threads).unwrap();
            assert_eq!(lay_out(&mut b, &bands, &mut layout, &team), 4);
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
        let spans = (0..n).map(|_| (rand(), rand() * rand() * 0.3));
        let mut ys: Vec<(f32, f32)> = spans.map(|(y, h)| (y, y + h)).collect();
        (keys[7], keys[100]) = (NO_KEY, NO_KEY);
        let mut layout = Layout::default();
        let mut b = slots(&keys, &ys);
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
                let (boxed, was_kept) = keep_or_lay_out(&mut b, &bands, &mut layout, team);
                kept += usize::from(was_kept);
                boxed
            } else {
                lay_out(&mut b, &bands, &mut layout, team)
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
        // Steps 8, 9 and 11 on one thread; 13, 14 and 15 in groups.
        assert_eq!(kept, 6);
    }

    /// Leavers noted in shares as the hulls are made, many bands empty
    /// and shares cutting bands anywhere, give the layout that keeping it
    /// without them does, on one thread and in groups.
    #[test]
    fn leavers_noted_in_shares_keep_the_same_layout() {
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
            for noted in [false, true] {
                let mut b = slots(&keys, &ys);
                let mut layout = Layout::default();
                lay_out(&mut b, &bands, &mut layout, team);
                // A few boxes move to other bands, one loses its key.
                for k in 0..n {
                    let id = b.ids[k] as usize - 10;
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
                    let (check, into) = layout.leaver_check(n, &bands, 4, groups);
                    let check = check.unwrap();
                    for (s, leavers) in shares.windows(2).zip(into.iter_mut()) {
                        let range = s[0]..s[1];
                        leavers.clear();
                        let arrays = (
                            &b.keys[range.clone()],
                            &b.hulls[range.clone()],
                            &b.ids[range.clone()],
                        );
                        check.note(range.start, arrays, leavers);
                    }
                }
                // Each group as handed on once laid out: its bands' homes
                // and guests as the layout ends up.
                let handed = Mutex::new(Vec::new());
                let collect = |g: GroupView| {
                    let per_band: Vec<_> = (g.bands.clone())
                        .map(|band| {
                            (
                                band,
                                g.ids[g.homes(band)].to_vec(),
                                g.guests(band).2.to_vec(),
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
                    assert_eq!(homes, b.ids[layout.homes(band)], "band {band}");
                    assert_eq!(guests, layout.guests(band).2, "band {band}");
                }
                let guests: Vec<u32> = (0..40).flat_map(|g| layout.guests(g).2.to_vec()).collect();
                laid.push((b.ids.clone(), b.keys.clone(), layout.starts.clone(), guests));
            }
            assert!(laid[0] == laid[1], "{groups} groups");
        }
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
