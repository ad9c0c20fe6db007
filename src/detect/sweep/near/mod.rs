//! Near pairs: the pairs a sweep finds, kept for the steps after it.
//!
//! A line's box moves little in a step. So when the sweep runs, it widens
//! every box by a margin (a few steps of its line's travel, [`MARGIN_STEPS`])
//! and keeps the pairs whose *widened* boxes overlap. On the steps after
//! it, each line's box is made where the line is stored (in slot order,
//! with no gathering) and checked to lie inside its widened box: while
//! every box does, two boxes that overlap lie inside two widened boxes
//! that overlap, so every pair whose boxes overlap is a kept pair, and
//! comparing the kept pairs' boxes finds them all. The first step a box
//! leaves its widened box (a line sped up by an event, or one that
//! travelled its margin), the sweep runs again. The boxes compared, the
//! exact test and the events are the same as the sweep's own: only the
//! pairs looked at differ.
//!
//! Containment is checked on the packed `f32` boxes themselves, lane by
//! lane, so no rounding can let a box out unnoticed; the margin is only a
//! guess at how long the boxes stay in.
//!
//! Here: the pairs, their widening, mending and comparison. Whether pairs
//! are kept at all is [`choice`]'s; the frame the widened boxes move with,
//! [`frame`]'s; the check of the boxes against their widened boxes,
//! [`settle`](mod@settle)'s.

use super::boxes::BoxSlice;
use super::hull::{self, overlaps, reach, Packed, NO_KEY};
use super::mend::MendIndex;
use crate::detect::swept::{max, DIAGONAL_X, DIAGONAL_Y};
use crate::detect::{Findings, Stored};
use crate::geometry::Vec2;
use crate::index::{LineId, Slot};
use crate::line::Line;
use crate::team::{self, Parts, Team};
use multiversion::multiversion;

mod choice;
mod frame;
mod settle;

use crate::detect::sweep::tuning::{FRAME_EVERY, MARGIN_STEPS, MEND_MOST, SHARED_PAIRS_FROM};
pub(crate) use choice::Choice;
use frame::{Frame, Shift};
use settle::settle;

/// The widened box of a line that had no box at the sweep: no box lies
/// inside it, so a line that has a box again calls for a sweep.
const NOWHERE: Packed = [f32::INFINITY; 8];

/// The boxes by slot, their widened boxes and the pairs kept.
#[derive(Debug, Default)]
pub(crate) struct Near {
    /// Each slot's box this step, and its least `x` ([`NO_KEY`] where the
    /// line has no box, its box then [`NOWHERE`]).
    boxes: Vec<Packed>,
    keys: Vec<f32>,
    /// Each slot's widened box, from the last sweep.
    wide: Vec<Packed>,
    /// The pairs of slots whose widened boxes overlapped at the last
    /// sweep, each once, in groups: group `k` holds those whose first slot
    /// lies in share `k` of the slots ([`owner`]), as the move splits the
    /// lines among the team, so each thread compares the pairs of the
    /// boxes it made, which are in its core's cache.
    pairs: Vec<Vec<(Slot, Slot)>>,
    /// Whether `wide` and `pairs` are of the lines as stored now.
    kept: bool,
    /// `0..n` as slots: the boxes are made in slot order.
    identity: Vec<Slot>,
    /// The lines without a box this step.
    unboxed: usize,
    /// Whether the boxes by slot were made in the move before this step,
    /// and of what time step.
    made: Option<f64>,
    /// Whether that move also checked them against their widened boxes
    /// ([`Check`]): the lines it found without a box, and the pieces whose
    /// leavers are in `share_leavers`.
    checked: Option<(u64, usize)>,
    /// The least travel a box was widened for at the last sweep
    /// ([`Frame::choose`]).
    least: f64,
    /// The frame: the velocity the widened boxes move with, and the steps
    /// since the last sweep ([`Frame`]).
    frame: Frame,
    /// The lines that choose the frame, with their velocities, and the
    /// sweeps before it is chosen again.
    sample: Vec<(LineId, Vec2)>,
    frame_in: u64,
    /// This step's leavers, each share's, and which slots they are
    /// ([`Near::mend`]).
    leavers: Vec<Slot>,
    share_leavers: Vec<Vec<Slot>>,
    leaving: Vec<bool>,
    /// The widened boxes as the last sweep laid them out, searched by the
    /// mends, and the boxes one leaver's widened box meets.
    index: MendIndex,
    met: Vec<u32>,
    found: Vec<u32>,
    /// The pairs a mend found, kept in place of the leavers' old pairs by
    /// [`Near::test`], and they in their groups.
    fresh: Vec<(Slot, Slot)>,
    fresh_groups: Vec<Vec<(Slot, Slot)>>,
    /// Each group's pairs whose boxes overlap this step, to test.
    hits: Vec<Vec<(Slot, Slot)>>,
    /// The findings of each group's comparison.
    pieces: Vec<Findings>,
    /// Steps, and sweeps among them, while kept pairs were used, and the
    /// boxes mended in them.
    pub(crate) steps: u64,
    pub(crate) sweeps: u64,
    pub(crate) mended: u64,
    /// The sweeps that chose a moving frame.
    pub(crate) moving: u64,
}

impl Near {
    /// The pairs kept.
    pub(crate) fn pairs(&self) -> usize {
        self.pairs.iter().map(Vec::len).sum()
    }

    /// Forgets the pairs kept: the next step that keeps pairs sweeps.
    pub(crate) fn forget(&mut self) {
        self.kept = false;
        self.frame_in = 0;
        self.pairs.iter_mut().for_each(Vec::clear);
        self.index.forget();
    }

    /// Makes room for `n` lines' boxes by slot (forgetting the pairs
    /// where the number of lines changed).
    fn fit(&mut self, n: usize) {
        if self.identity.len() != n {
            self.identity = (0..n as u32).map(Slot).collect();
            self.boxes.resize(n, NOWHERE);
            self.keys.resize(n, NO_KEY);
            self.wide.resize(n, NOWHERE);
            self.kept = false;
            (self.made, self.checked) = (None, None);
        }
    }

    /// The boxes by slot and their least `x`, for `n` lines, to make in
    /// the world's move ([`Detector::advance`](crate::detect::Detector))
    /// of `dt`, in `pieces` pieces, and what checks each piece's boxes
    /// against their widened boxes as [`Near::make`] would next step;
    /// [`Near::made`] says when they are made and checked.
    pub(crate) fn boxes_to_make(&mut self, n: usize, pieces: usize, dt: f64) -> ToMake<'_> {
        self.fit(n);
        // The frame's shift next step, as `make` will count it.
        let steps = self.frame.steps + u64::from(self.kept);
        let pieces = pieces.max(1);
        self.share_leavers
            .resize_with(pieces.max(self.share_leavers.len()), Vec::new);
        ToMake {
            boxes: &mut self.boxes,
            keys: &mut self.keys,
            check: Check {
                wide: &self.wide,
                kept: self.kept,
                shift: self.frame.shift_after(steps, dt),
                leavers: Parts::new(self.share_leavers[..pieces].iter_mut()),
            },
        }
    }

    /// The boxes by slot were made of `dt` for the lines as they are now
    /// stored, for the next step, and checked in `pieces` pieces
    /// ([`Check::settle`]), which found `unboxed` lines without a box.
    pub(crate) fn made(&mut self, dt: f64, (unboxed, pieces): (u64, usize)) {
        self.made = Some(dt);
        self.checked = Some((unboxed, pieces.max(1)));
    }

    /// Forgets that the move made the boxes by slot: this step sweeps.
    pub(crate) fn discard_made(&mut self) {
        (self.made, self.checked) = (None, None);
    }

    /// Whether this step's boxes by slot were made (of `dt`) in the move
    /// before it, and checked there (the lines without a box, and the
    /// pieces of leavers); asked once a step.
    fn take_made(&mut self, n: usize, dt: f64) -> (bool, Option<(u64, usize)>) {
        self.fit(n);
        let checked = self.checked.take();
        match self.made.take() == Some(dt) {
            true => (true, checked),
            false => (false, None),
        }
    }

    /// Makes every line's box in slot order (unless the move before this
    /// step made them), checks it lies in its widened box, a share a
    /// thread of `team`, and returns whether the pairs kept still hold:
    /// every box lies in its widened box, or the few that left were
    /// mended.
    pub(crate) fn make(&mut self, lines: &[Line], dt: f64, team: &Team, laid: Laid) -> bool {
        let n = lines.len();
        let (made, checked) = self.take_made(n, dt);
        self.steps += 1;
        if self.kept {
            self.frame.steps += 1;
        }
        let shift = self.frame.shift(dt);
        if let Some((unboxed, pieces)) = checked {
            // The move checked the boxes as it made them.
            #[cfg(test)]
            self.check_again((unboxed, pieces), &shift);
            return self.settled(unboxed, pieces, (lines, dt, &shift, laid));
        }
        let threads = team.threads();
        let (boxes, keys) = (
            team::split_mut(&mut self.boxes, threads),
            team::split_mut(&mut self.keys, threads),
        );
        let (identity, wide, kept) = (&self.identity, &self.wide, self.kept);
        self.share_leavers
            .resize_with(threads.max(self.share_leavers.len()), Vec::new);
        let leavers = Parts::new(self.share_leavers.iter_mut());
        // Each share's lines without a box, and its leavers.
        let unboxed = team.run_sum(&|k| {
            let share = team::share(n, threads, k);
            let (boxes, keys, leavers) = (boxes.take(k), keys.take(k), leavers.take(k));
            if !made {
                hull::make(lines, &identity[share.clone()], boxes, keys, 0, dt);
            }
            leavers.clear();
            let wide = &wide[share.clone()];
            settle(boxes, keys, (wide, kept, &shift), (share.start, leavers))
        });
        drop(leavers);
        self.settled(unboxed, threads, (lines, dt, &shift, laid))
    }

    /// Tests: the move's check of the boxes (the lines without a box, the
    /// pieces' leavers) is the one this step makes of them.
    #[cfg(test)]
    fn check_again(&mut self, (unboxed, pieces): (u64, usize), shift: &Shift) {
        let moved: Vec<Slot> = self.share_leavers[..pieces].concat();
        let mut leavers = Vec::new();
        let (wide, kept) = (&self.wide[..], self.kept);
        let again = settle(
            &mut self.boxes,
            &self.keys,
            (wide, kept, shift),
            (0, &mut leavers),
        );
        assert!(
            (unboxed, &moved) == (again, &leavers),
            "the move found {} leavers and {unboxed} lines without a box, the step {} and {again}",
            moved.len(),
            leavers.len(),
        );
    }

    /// The end of [`Near::make`], the boxes checked in `pieces` pieces
    /// and `unboxed` lines found without one: whether the pairs kept
    /// hold, with this step's leavers mended.
    fn settled(
        &mut self,
        unboxed: u64,
        pieces: usize,
        (lines, dt, shift, laid): (&[Line], f64, &Shift, Laid),
    ) -> bool {
        self.unboxed = unboxed as usize;
        self.leavers.clear();
        for share in &self.share_leavers[..pieces] {
            self.leavers.extend_from_slice(share);
        }
        if !self.kept || self.leavers.len() > MEND_MOST {
            return false;
        }
        self.leavers.is_empty() || self.mend(lines, dt, shift, laid)
    }

    /// Widens again the boxes that left their widened boxes (the
    /// *leavers*, a few), and keeps anew the pairs they are in: each
    /// leaver's widened box against those the last sweep laid out near it
    /// and those mended since ([`MendIndex`]), on this thread (a few
    /// dozen boxes a leaver, far fewer than a sweep).
    #[inline(never)] // Rare, and a phase of its own in profiles.
    fn mend(&mut self, lines: &[Line], dt: f64, shift: &Shift, (laid, along): Laid) -> bool {
        let n = lines.len();
        self.index.build(laid, along);
        for &Slot(i) in &self.leavers {
            let i = i as usize;
            let wide = widened(
                &self.boxes[i],
                &lines[i],
                dt,
                (self.frame.velocity, self.least),
            );
            match shift.back(&self.boxes[i], &wide) {
                Some(wide) => self.wide[i] = wide,
                // Rounding left the box outside however widened: sweep.
                None => return false,
            }
        }
        self.leaving.resize(n, false);
        for &s in &self.leavers {
            self.leaving[s.0 as usize] = true;
            self.index.remake(s);
        }
        self.mended += self.leavers.len() as u64;
        // Each leaver's boxes met, in ascending order.
        let (wide, leaving) = (&self.wide, &self.leaving);
        for &Slot(i) in &self.leavers {
            let met = &mut self.met;
            let found = &mut self.found;
            self.index
                .meeting(laid, wide, &reach(&wide[i as usize]), (met, found));
            // Two leavers meet once, from the lower slot.
            let new = met.iter().copied();
            let new = new.filter(|&j| j != i && (j > i || !leaving[j as usize]));
            self.fresh.extend(new.map(|j| (Slot(i), Slot(j))));
        }
        true
    }

    /// Clears the marks of this step's leavers.
    fn end_mend(&mut self) {
        for &Slot(i) in &self.leavers {
            self.leaving[i as usize] = false;
        }
        self.leavers.clear();
    }

    /// Widens every line's box by its margin, for a sweep of the widened
    /// boxes, a share a thread of `team`.
    pub(crate) fn widen(&mut self, stored: Stored, dt: f64, team: &Team) {
        let lines = stored.lines;
        let n = lines.len();
        let threads = team.threads();
        if self.frame_in == 0 {
            self.least = self.frame.choose(stored, &mut self.sample);
            self.frame_in = FRAME_EVERY;
        }
        (self.frame.steps, self.frame_in) = (0, self.frame_in - 1);
        self.moving += u64::from(self.frame.velocity != [0.0; 2]);
        let frame = (self.frame.velocity, self.least);
        let wide = team::split_mut(&mut self.wide, threads);
        let (boxes, keys) = (&self.boxes, &self.keys);
        team.run(&|k| {
            let share = team::share(n, threads, k);
            let (lines, boxes) = (&lines[share.clone()], &boxes[share.clone()]);
            widen_each((lines, boxes, &keys[share]), wide.take(k), dt, frame);
        });
        self.sweeps += 1;
    }

    /// The widened box of each line `slots[k]` into `hulls[k]`, and its
    /// least value along `along` into `keys[k]` ([`NO_KEY`] for a line
    /// without a box): the boxes the sweep lays out.
    pub(crate) fn gather(
        &self,
        slots: &[Slot],
        hulls: &mut [Packed],
        keys: &mut [f32],
        along: usize,
    ) {
        let along = along % hull::DIRECTIONS;
        for ((s, hull), key) in slots.iter().zip(hulls).zip(keys) {
            let (w, by_key) = (&self.wide[s.0 as usize], self.keys[s.0 as usize]);
            *hull = *w;
            // Read from the box in place (a copy indexed by `along` would
            // go through memory).
            let lo = hull::lo(w, along);
            *key = if by_key == NO_KEY { NO_KEY } else { lo };
        }
    }

    /// Keeps the pairs of slots whose widened boxes overlap (each once),
    /// as the pieces of the sweep found them, in place of the pairs kept
    /// before, in `groups` groups (the threads of the team that compares
    /// them); empties the pieces.
    pub(crate) fn keep<'a>(
        &mut self,
        swept: impl Iterator<Item = &'a mut Vec<(Slot, Slot)>>,
        groups: usize,
    ) {
        // Leavers that called for this sweep have nothing to mend.
        debug_assert!(self.fresh.is_empty() && !self.leaving.contains(&true));
        self.leavers.clear();
        self.pairs.iter_mut().for_each(Vec::clear);
        self.pairs.resize_with(groups.max(1), Vec::new);
        let n = self.boxes.len();
        let (pairs, groups) = (&mut self.pairs, groups.max(1));
        for piece in swept {
            for &pair in piece.iter() {
                pairs[owner(pair.0, n, groups)].push(pair);
            }
            piece.clear();
        }
        self.kept = true;
        self.index.forget();
    }

    /// Compares the boxes of every pair kept and hands each pair whose
    /// boxes overlap to `found`'s test, a group a piece among `team` (on
    /// this thread where they are few), the groups' findings put together
    /// in order. Where leavers were mended, each group first drops its
    /// pairs of a leaver and takes their fresh pairs of its own.
    pub(crate) fn test(&mut self, (stored, dt): (Stored, f64), found: &mut Findings, team: &Team) {
        let mended = !self.leavers.is_empty();
        let leaving = mended.then_some(&self.leaving[..]);
        let (n, groups) = (self.boxes.len(), self.pairs.len());
        self.fresh_groups.resize_with(groups, Vec::new);
        for &pair in &self.fresh {
            self.fresh_groups[owner(pair.0, n, groups)].push(pair);
        }
        self.fresh.clear();
        self.pieces
            .resize_with(groups.max(self.pieces.len()), Findings::default);
        let total = self.pairs();
        let boxes = &self.boxes;
        let parts = Parts::new(self.pieces[..groups].iter_mut());
        self.hits.resize_with(groups, Vec::new);
        let (pairs, fresh, hits) = (
            Parts::new(self.pairs.iter_mut()),
            Parts::new(self.fresh_groups.iter_mut()),
            Parts::new(self.hits.iter_mut()),
        );
        let job = |k: usize| {
            let (found, pairs, fresh) = (parts.take(k), pairs.take(k), fresh.take(k));
            found.clear();
            compare(
                (pairs, fresh, leaving, hits.take(k)),
                boxes,
                (stored, dt),
                found,
            );
        };
        match team.threads() > 1 && total >= SHARED_PAIRS_FROM {
            true => team.run_pieces(groups, &job),
            false => (0..groups).for_each(job),
        }
        drop((parts, pairs, fresh, hits));
        self.pieces[..groups]
            .iter_mut()
            .for_each(|piece| found.append(piece));
        if mended {
            self.end_mend();
        }
    }

    /// The lines with a box and, into `wild`, those without one that are
    /// not inert.
    pub(crate) fn wild(&self, stored: Stored, wild: &mut Vec<Slot>) {
        wild.clear();
        if self.unboxed == 0 {
            return;
        }
        let unboxed = self
            .identity
            .iter()
            .filter(|s| self.keys[s.0 as usize] == NO_KEY);
        wild.extend(unboxed.filter(|&&s| !stored.line(s).is_inert()));
    }

    /// The slots of the lines with a box, in order.
    pub(crate) fn boxed(&self) -> impl Iterator<Item = Slot> + Clone + '_ {
        let keys = &self.keys;
        (self.identity.iter().copied()).filter(move |s| keys[s.0 as usize] != NO_KEY)
    }

    /// The lines are stored anew, `order[k]` the old slot of the line now
    /// at `k`: the widened boxes and the pairs follow them.
    pub(crate) fn reorder(&mut self, order: &[Slot]) {
        if !self.kept {
            return;
        }
        let old = std::mem::take(&mut self.wide);
        self.wide = order.iter().map(|s| old[s.0 as usize]).collect();
        let mut new_slot = vec![Slot(0); order.len()];
        for (k, s) in order.iter().enumerate() {
            new_slot[s.0 as usize] = Slot(k as u32);
        }
        // Each pair by its new slots, in the group of its new first slot.
        let (n, groups) = (order.len(), self.pairs.len());
        let mut all = std::mem::take(&mut self.fresh_groups);
        all.resize_with(groups, Vec::new);
        for (group, old) in all.iter_mut().zip(&mut self.pairs) {
            group.clear();
            group.append(old);
        }
        for &(a, b) in all.iter().flatten() {
            let (a, b) = (new_slot[a.0 as usize], new_slot[b.0 as usize]);
            self.pairs[owner(a, n, groups)].push((a, b));
        }
        all.iter_mut().for_each(Vec::clear);
        self.fresh_groups = all;
        self.index.reorder(&new_slot);
    }
}

/// The boxes by slot for the world's move to make, and their check
/// ([`Near::boxes_to_make`]).
pub(crate) struct ToMake<'a> {
    /// Every line's box, by slot.
    pub(crate) boxes: &'a mut [Packed],
    /// Every line's least value along `x`, or [`NO_KEY`].
    pub(crate) keys: &'a mut [f32],
    /// The check of each piece's boxes once made.
    pub(crate) check: Check<'a>,
}

/// [`Near::make`]'s check of the boxes against their widened boxes,
/// made by the world's move a piece at a time while the boxes are at
/// hand, and in the same hand-off.
pub(crate) struct Check<'a> {
    /// Each slot's widened box, and whether they are of the lines as
    /// stored now.
    wide: &'a [Packed],
    kept: bool,
    /// The frame's shift at the next step.
    shift: Shift,
    /// Each piece's leavers.
    leavers: Parts<&'a mut Vec<Slot>>,
}

impl Check<'_> {
    /// Checks piece `k`'s boxes and keys, made for the lines at `slots`,
    /// noting its leavers; returns the lines it found without a box.
    pub(crate) fn settle(
        &self,
        k: usize,
        slots: std::ops::Range<usize>,
        (boxes, keys): (&mut [Packed], &[f32]),
    ) -> u64 {
        let leavers = self.leavers.take(k);
        leavers.clear();
        let wide = &self.wide[slots.clone()];
        settle(
            boxes,
            keys,
            (wide, self.kept, &self.shift),
            (slots.start, leavers),
        )
    }
}

/// The widened boxes as the last sweep laid them out (all of the lines'),
/// and the direction they are sorted along: what a mend searches
/// ([`MendIndex`]).
pub(crate) type Laid<'a> = (BoxSlice<'a>, usize);

/// How far a line of velocity `v` travels along `x` and `y` together in a
/// unit of time, relative to a frame moving with `frame`.
fn travel(v: Vec2, frame: [f64; 2]) -> f64 {
    (v.x - frame[0]).abs() + (v.y - frame[1]).abs()
}

/// `b`, the box of `line`, widened by [`MARGIN_STEPS`] of its travel
/// relative to the frame moving with `velocity`, or of `least` if it
/// travels less: a line at rest in the frame is given some travel
/// ([`Frame::choose`]), so that one set moving by an event does not leave
/// its box at once. In a moving frame every lane is widened by a few of
/// its `f32` steps more (a diagonal by a few of its parts' too), for the
/// rounding of boxes that move with it.
#[inline(always)]
fn widened(b: &Packed, line: &Line, dt: f64, (velocity, least): ([f64; 2], f64)) -> Packed {
    let margin = MARGIN_STEPS * dt * max(travel(line.v, velocity), least);
    // The diagonals' values are as many times larger.
    // The most a diagonal's value moves for a unit of travel along x or y.
    let diagonal = DIAGONAL_X.max(DIAGONAL_Y);
    let (s, d) = (margin as f32, (margin * diagonal) as f32);
    let by = [s, s, d, d, s, s, d, d];
    let rounding = match velocity == [0.0; 2] {
        true => 0.0,
        false => ROUNDING,
    };
    // A diagonal value is made of `x` and `y` in `f32`, and rounded as
    // they are: by steps of its parts, not its own.
    let part = |a: usize| match b[a].abs() > b[a + 4].abs() {
        true => b[a].abs(),
        false => b[a + 4].abs(),
    };
    let p = DIAGONAL_X as f32 * part(0) + DIAGONAL_Y as f32 * part(1);
    let parts = [0.0, 0.0, p, p, 0.0, 0.0, p, p];
    std::array::from_fn(|l| b[l] - (by[l] + (b[l].abs() + parts[l]) * rounding))
}

/// Widens each line's box (`boxes[k]`, key `keys[k]`) into `wide[k]`
/// ([`widened`]; [`NOWHERE`] for a line without a box). Compiled for the
/// baseline and for AVX2, whose registers take a box's eight lanes at
/// once, chosen when the program starts.
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2"), dispatcher = "static")
)]
fn widen_each(
    (lines, boxes, keys): (&[Line], &[Packed], &[f32]),
    wide: &mut [Packed],
    dt: f64,
    frame: ([f64; 2], f64),
) {
    for (((line, b), &key), w) in lines.iter().zip(boxes).zip(keys).zip(wide) {
        *w = match key == NO_KEY {
            true => NOWHERE,
            false => widened(b, line, dt, frame),
        };
    }
}

/// The part of a box's value it is widened by for rounding: four of its
/// `f32` steps.
const ROUNDING: f32 = 1.0 / (1 << 21) as f32;

/// The group of the pairs whose first slot is `a`, among `groups` groups
/// of `n` slots: the share of the slots ([`team::share`]) that holds `a`.
#[inline]
fn owner(a: Slot, n: usize, groups: usize) -> usize {
    match groups {
        1 => 0,
        // Share `k` starts at `n k / groups`, rounded down.
        _ => (groups * (a.0 as usize + 1) - 1) / n.max(1),
    }
}

/// Compares the boxes of each pair of slots in `pairs`, then in `fresh`,
/// and hands those that overlap (gathered in `hits`, then tested in one
/// loop, where the test is inlined once) to `found`'s test, counting every
/// pair compared as met; the fresh pairs then join the pairs. With `leaving`,
/// the pairs that have a line leaving are first dropped as they are met,
/// each replaced by the last pair: the pairs are read once, and only those
/// dropped (a few in thousands) are moved. The order of the pairs changes,
/// which changes nothing found: events are resolved in the contract's
/// order, whatever order they are found in. A line without a box has
/// [`NOWHERE`] for one: it is wild or inert, and tested as such.
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2"), dispatcher = "static")
)]
fn compare(
    (pairs, fresh, leaving, hits): ToCompare,
    boxes: &[Packed],
    (stored, dt): (Stored, f64),
    found: &mut Findings,
) {
    multiversion::target::match_target! {
        "x86_64+avx2" => {
            let screen = |l1: &Line, l2: &Line, dt| crate::lanes::intersect::screen(l1, l2, dt);
            compare_each((pairs, fresh, leaving, hits), boxes, (stored, dt), found, screen)
        }
        _ => compare_each((pairs, fresh, leaving, hits), boxes, (stored, dt), found, crate::detect::pairs::screen),
    }
    found.met(pairs.len() as u64);
}

/// Whether the boxes of the pair of slots `(a, b)` overlap.
#[inline(always)]
fn overlap(boxes: &[Packed], (a, b): (Slot, Slot)) -> bool {
    overlaps(&boxes[b.0 as usize], &reach(&boxes[a.0 as usize]))
}

/// The pairs a group compares ([`compare`]): those kept, the fresh ones,
/// which lines are leaving, if any are, and room for the pairs whose boxes
/// overlap.
type ToCompare<'a> = (
    &'a mut Vec<(Slot, Slot)>,
    &'a mut Vec<(Slot, Slot)>,
    Option<&'a [bool]>,
    &'a mut Vec<(Slot, Slot)>,
);

/// [`compare`]'s loops, with the prefilter and exact test `screen` (see
/// [`Findings::test_with`]).
#[inline(always)]
fn compare_each(
    (pairs, fresh, leaving, hits): ToCompare,
    boxes: &[Packed],
    (stored, dt): (Stored, f64),
    found: &mut Findings,
    screen: impl Fn(&Line, &Line, f64) -> Option<Option<crate::narrow::IntersectionKind>>,
) {
    let n = boxes.len();
    hits.clear();
    match leaving.map(|leaving| &leaving[..n]) {
        Some(leaving) => {
            let mut k = 0;
            while let Some(&(a, b)) = pairs.get(k) {
                if leaving[a.0 as usize] | leaving[b.0 as usize] {
                    pairs.swap_remove(k);
                    continue;
                }
                if overlap(boxes, (a, b)) {
                    hits.push((a, b));
                }
                k += 1;
            }
        }
        None => {
            for &pair in pairs.iter() {
                if overlap(boxes, pair) {
                    hits.push(pair);
                }
            }
        }
    }
    for &pair in fresh.iter() {
        if overlap(boxes, pair) {
            hits.push(pair);
        }
    }
    pairs.append(fresh);
    for &pair in hits.iter() {
        found.test_with(stored, pair, dt, &screen);
    }
}
