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

use super::boxes::BoxSlice;
use super::hull::{self, overlaps, reach, Packed, NO_KEY};
use super::mend::MendIndex;
use crate::detect::swept::{DIAGONAL_X, DIAGONAL_Y};
use crate::detect::{Findings, KeepPairs, Stored};
use crate::geometry::Vec2;
use crate::index::{LineId, Slot};
use crate::line::Line;
use crate::team::{self, Parts, Team};
use multiversion::multiversion;

/// Steps of its line's travel a box is widened by: the steps it stays
/// inside its widened box if nothing turns its line. Wider keeps the pairs
/// longer but keeps more of them (docs/DESIGN.md, "Near pairs").
const MARGIN_STEPS: f64 = 8.0;

/// The most a diagonal's value moves for a unit of travel along `x` or
/// `y`.
const DIAGONAL: f64 = if DIAGONAL_X > DIAGONAL_Y {
    DIAGONAL_X
} else {
    DIAGONAL_Y
};

/// The most leavers mended one at a time rather than by a sweep.
const MEND_MOST: usize = 16;

/// Pairs kept from which their comparison is shared among the team, a
/// group a thread (fewer are compared on the stepping thread): `koch`'s
/// 4,000 or so take about 5 us a step on one thread, well over a
/// hand-off.
const SHARED_PAIRS_FROM: usize = 1024;

/// The widened box of a line that had no box at the sweep: no box lies
/// inside it, so a line that has a box again calls for a sweep.
const NOWHERE: Packed = [f32::INFINITY; 8];

/// Steps swept before pairs are first tried, and again after a good
/// stretch of keeping them.
const FIRST_WAIT: u64 = 16;

/// The most steps swept between two tries (the wait grows fourfold after
/// each try that failed).
const LONGEST_WAIT: u64 = 4096;

/// The part of a sweep's work a step (in candidates, [`LINE_WEIGHT`])
/// that the pairs kept must stay below: a kept pair is read at random
/// where a sweep reads its boxes in order, and on large scenes it waits on
/// memory for it.
const FEWER: f64 = 0.6;

/// A sweep's work on a line's box (gathered, laid out, swept), as many
/// candidates' worth: on `koch`, about 107 instructions a box and 62 a
/// candidate met, the work a kept pair takes about 16. So `koch`'s
/// 3,900 lines keep about 4,200 pairs a step against 2,900 candidates
/// and run 0.80x of the instructions sweeping; `box`'s 400 lines keep 4,700
/// against 3,500 and run 1.33x, `sin_wave`'s 1,180 lines 4,200 against
/// 380 and 1.35x (sweeps of widened boxes included).
const LINE_WEIGHT: f64 = 3.0;

/// The fewest steps between two sweeps of widened boxes: a scene whose
/// boxes leave sooner sweeps more than it keeps.
const SOONEST_SWEEP: u64 = 3;

/// Lines from which pairs are not tried where it pays: generated scenes
/// of 6,000 lines kept them (0.84x of the instructions on one thread) but
/// ran 0.98x of sweeping every step on one thread and 0.90x on two, where
/// the sweep shares its work better than a kept step; larger scenes lose
/// more (10,000 lines 0.99x and 0.86x, 30,000 0.93x and 0.72x), and each
/// try costs a few steps' worth.
const TRY_BELOW: usize = 4096;

/// Steps pairs are kept between two judgements of whether they pay.
const JUDGE_EVERY: u64 = 32;

/// Steps pairs are kept at most before the sweep runs every step again
/// for a while, to measure it anew.
const KEEP_MOST: u64 = 2048;

/// Whether pairs are kept, chosen by what each way meets: keeping pays
/// where the pairs kept, compared every step, are well under a sweep's
/// work every step (the candidates it meets and its lines' boxes,
/// [`FEWER`], [`LINE_WEIGHT`]), and the boxes stay inside their widened
/// boxes for a few steps ([`SOONEST_SWEEP`]).
/// Crowded scenes (many pairs close by, many events turning lines) fail
/// their tries and are swept every step, large ones ([`TRY_BELOW`]) are
/// not tried; scenes whose sweeps meet many boxes that do not overlap keep
/// their pairs. The counts are the same on every run, so the choices are
/// too; the events are the same either way.
#[derive(Debug)]
pub(crate) struct Choice {
    /// Always, never, or where it pays.
    mode: KeepPairs,
    /// Whether pairs are kept this step.
    keeping: bool,
    /// Steps until the next try (sweeping) or judgement (keeping).
    left: u64,
    /// The wait before the next try after a failed one.
    wait: u64,
    /// Candidates met and steps, in this stretch of sweeping every step.
    swept: (u64, u64),
    /// A step's work sweeping every step, as last measured, in
    /// candidates: those met, and [`LINE_WEIGHT`] a line.
    sweeping_rate: f64,
    /// Candidates met and steps since the last judgement, and steps in
    /// this stretch of keeping.
    kept: (u64, u64),
    kept_for: u64,
    /// Steps since the last sweep of widened boxes, this one included.
    since_sweep: u64,
}

impl Default for Choice {
    fn default() -> Self {
        Self::new(KeepPairs::Auto)
    }
}

impl Choice {
    /// Keeping pairs as `mode` says; where it pays, first tried after
    /// [`FIRST_WAIT`] steps.
    pub(crate) fn new(mode: KeepPairs) -> Self {
        Self {
            mode,
            keeping: mode == KeepPairs::Always,
            left: FIRST_WAIT,
            wait: FIRST_WAIT,
            swept: (0, 0),
            sweeping_rate: 0.0,
            kept: (0, 0),
            kept_for: 0,
            since_sweep: 0,
        }
    }

    /// Whether pairs are kept this step.
    pub(crate) fn keeping(&self) -> bool {
        self.keeping
    }

    /// Takes in a step of `lines` lines: the candidates it met, whether it
    /// swept, and the pairs kept (when keeping). Returns true when keeping
    /// begins with the next step (the pairs held are stale and must be
    /// forgotten).
    pub(crate) fn after(
        &mut self,
        candidates: u64,
        swept: bool,
        pairs: usize,
        lines: usize,
    ) -> bool {
        if self.mode != KeepPairs::Auto || (!self.keeping && lines >= TRY_BELOW) {
            return false;
        }
        self.left = self.left.saturating_sub(1);
        if !self.keeping {
            self.swept.0 += candidates;
            self.swept.1 += 1;
            if self.left > 0 {
                return false;
            }
            let met = self.swept.0 as f64 / self.swept.1 as f64;
            self.sweeping_rate = met + LINE_WEIGHT * lines as f64;
            self.swept = (0, 0);
            (self.keeping, self.left, self.kept) = (true, JUDGE_EVERY, (0, 0));
            (self.kept_for, self.since_sweep) = (0, 0);
            return true;
        }
        self.kept.0 += candidates;
        self.kept.1 += 1;
        let (met, steps) = self.kept;
        // A sweep of widened boxes that keeps more than a part of the
        // candidates a sweep meets, or that comes within a few steps of
        // the last, fails the stretch at once.
        let too_many = swept && pairs as f64 >= FEWER * self.sweeping_rate;
        let too_soon = swept && self.kept_for > 0 && self.since_sweep < SOONEST_SWEEP;
        self.kept_for += 1;
        self.since_sweep = if swept { 1 } else { self.since_sweep + 1 };
        if !(too_many || too_soon) && self.left > 0 {
            return false;
        }
        let pays = !(too_many || too_soon)
            && (met as f64 / steps as f64) < FEWER * self.sweeping_rate
            && self.kept_for < KEEP_MOST;
        if pays {
            (self.left, self.kept, self.wait) = (JUDGE_EVERY, (0, 0), FIRST_WAIT);
            return false;
        }
        // Back to sweeping every step: soon after a good stretch, later
        // and later after tries that failed.
        if self.kept_for > JUDGE_EVERY {
            self.wait = FIRST_WAIT;
        } else {
            self.wait = (4 * self.wait).min(LONGEST_WAIT);
        }
        (self.keeping, self.left) = (false, self.wait);
        false
    }
}

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
            let wide = wide.take(k);
            let each = lines[share.clone()].iter().zip(&boxes[share.clone()]);
            for (((line, b), &key), w) in each.zip(&keys[share]).zip(wide) {
                *w = match key == NO_KEY {
                    true => NOWHERE,
                    false => widened(b, line, dt, frame),
                };
            }
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
        let (pairs, fresh) = (
            Parts::new(self.pairs.iter_mut()),
            Parts::new(self.fresh_groups.iter_mut()),
        );
        let job = |k: usize| {
            let (found, pairs, fresh) = (parts.take(k), pairs.take(k), fresh.take(k));
            found.clear();
            if let Some(leaving) = leaving {
                drop_leavers(pairs, leaving);
            }
            pairs.append(fresh);
            compare(pairs, boxes, (stored, dt), found);
        };
        match team.threads() > 1 && total >= SHARED_PAIRS_FROM {
            true => team.run_pieces(groups, &job),
            false => (0..groups).for_each(job),
        }
        drop((parts, pairs, fresh));
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
/// its `f32` steps more, for the rounding of boxes that move with it.
fn widened(b: &Packed, line: &Line, dt: f64, (velocity, least): ([f64; 2], f64)) -> Packed {
    let margin = MARGIN_STEPS * dt * travel(line.v, velocity).max(least);
    // The diagonals' values are as many times larger.
    let (straight, diagonal) = (margin as f32, (margin * DIAGONAL) as f32);
    let mut wide = *b;
    for (l, w) in wide.iter_mut().enumerate() {
        *w -= match l % 4 < 2 {
            true => straight,
            false => diagonal,
        };
    }
    if velocity != [0.0; 2] {
        for (w, b) in wide.iter_mut().zip(b) {
            *w -= b.abs() * ROUNDING;
        }
    }
    wide
}

/// The part of a box's value it is widened by for rounding: four of its
/// `f32` steps.
const ROUNDING: f32 = 1.0 / (1 << 21) as f32;

/// The frame the widened boxes move with: the lines' median velocity at
/// the last sweep, where that saves travel. Where most lines move alike
/// (a shape moving as one, as on `koch`), they stand still in it, and
/// their widened boxes need a margin only for rounding and the few lines
/// that do not; where velocities differ it is at rest.
#[derive(Debug, Default)]
struct Frame {
    velocity: [f64; 2],
    /// Steps since the widened boxes were made.
    steps: u64,
}

/// The most lines whose velocities choose a frame.
const FRAME_SAMPLE: usize = 64;

/// Sweeps of widened boxes between two choices of the frame (and of the
/// least travel): the lines' velocities change slowly as a whole, and
/// the choice costs a tiny scene a few per cent.
const FRAME_EVERY: u64 = 8;

/// The part of the lines' mean travel at rest that their mean travel in a
/// moving frame must be below for the frame to be taken.
const FRAME_PAYS: f64 = 0.8;

/// The part of the lines' mean travel in a moving frame that a line at
/// rest in it is widened by: most such lines stay at rest (they move with
/// the shape), so a little, against rounding and nudges, where a frame at
/// rest gives its slow lines the whole mean.
const FRAME_FLOOR: f64 = 0.1;

impl Frame {
    /// Chooses the frame for boxes widened now: the median velocity of
    /// `lines` along each axis (the velocity of least travel to all), of
    /// at most [`FRAME_SAMPLE`] lines spread over them, if the lines'
    /// mean travel in it is below [`FRAME_PAYS`] of their travel at rest;
    /// else at rest. Returns the least travel a line's box is widened for
    /// ([`widened`]).
    fn choose(&mut self, stored: Stored, sample: &mut Vec<(LineId, Vec2)>) -> f64 {
        // The lines whose ids are a multiple of `every`, in id order: the
        // same lines and sums however the lines are stored.
        let lines = stored.lines;
        let every = (lines.len() / FRAME_SAMPLE).next_power_of_two();
        sample.clear();
        for (k, line) in lines.iter().enumerate() {
            let id = stored.id(Slot(k as u32));
            if id.0 as usize & (every - 1) == 0 && line.v.x.is_finite() && line.v.y.is_finite() {
                sample.push((id, line.v));
            }
        }
        // In id order, then each median picked in place: the same order
        // of the sample for the sums below, however the lines are stored.
        sample.sort_unstable_by_key(|&(id, _)| id);
        let mut median = |speed: fn(Vec2) -> f64| {
            if sample.is_empty() {
                return 0.0;
            }
            let by_speed =
                |a: &(LineId, Vec2), b: &(LineId, Vec2)| speed(a.1).total_cmp(&speed(b.1));
            let half = sample.len() / 2;
            let (_, &mut (_, v), _) = sample.select_nth_unstable_by(half, by_speed);
            speed(v)
        };
        let median = [median(|v| v.x), median(|v| v.y)];
        // The mean travel in the frame and at rest.
        let (mut moving, mut still) = (0.0, 0.0);
        for &(_, v) in sample.iter() {
            (moving, still) = (moving + travel(v, median), still + travel(v, [0.0; 2]));
        }
        let counted = sample.len().max(1) as f64;
        let (moving, still) = (moving / counted, still / counted);
        if moving < FRAME_PAYS * still {
            self.velocity = median;
            FRAME_FLOOR * moving
        } else {
            self.velocity = [0.0; 2];
            still
        }
    }

    /// How far the frame has moved since the widened boxes were made.
    fn shift(&self, dt: f64) -> Shift {
        self.shift_after(self.steps, dt)
    }

    /// How far the frame moves in `steps` steps of `dt`.
    fn shift_after(&self, steps: u64, dt: f64) -> Shift {
        let t = steps as f64 * dt;
        let (x, y) = (t * self.velocity[0], t * self.velocity[1]);
        if x == 0.0 && y == 0.0 {
            return Shift::Still;
        }
        let (u, w) = (
            x * DIAGONAL_X + y * DIAGONAL_Y,
            x * DIAGONAL_X - y * DIAGONAL_Y,
        );
        let along = [x, y, u, w];
        Shift::By(std::array::from_fn(|l| match l < 4 {
            true => up(along[l]),
            false => up(-along[l - 4]),
        }))
    }
}

/// `x` rounded up to an `f32`.
fn up(x: f64) -> f32 {
    let r = x as f32;
    match (r as f64) < x {
        true => r.next_up(),
        false => r,
    }
}

/// How far the frame has moved, lane by lane: each lane's shift rounded
/// up (a box's lanes are lower bounds, its greatest values negated), so
/// that a box found inside a widened box moved by it lies inside the
/// widened box moved by the frame's exact shift.
#[derive(Clone, Copy, Debug)]
enum Shift {
    /// The frame is at rest, or has not moved yet.
    Still,
    By(Packed),
}

impl Shift {
    /// A widened box `wide` of `b` made now, as it was when the frame was
    /// made (every widened box is kept so), with `b` inside it moved by
    /// this shift; `None` if no widening found (rounding, huge values).
    fn back(&self, b: &Packed, wide: &Packed) -> Option<Packed> {
        let Shift::By(s) = self else {
            return Some(*wide);
        };
        let mut back: Packed = std::array::from_fn(|l| wide[l] - s[l]);
        for _ in 0..4 {
            if inside_moved(b, &back, s) {
                return Some(back);
            }
            back = back.map(|w| w - w.abs() * ROUNDING - f32::MIN_POSITIVE);
        }
        None
    }
}

/// Sets the boxes of the lines without one (key [`NO_KEY`]) to
/// [`NOWHERE`], which overlaps no box and lies in every box; if `kept`,
/// pushes to `leavers` the slot (from `start` on) of each box that does not
/// lie in its widened box `wide`. Returns the lines without a box. The
/// lines without a box are found in a loop of their own, and the rare
/// leaver is taken by a branch: with AVX2 one a block of eight boxes,
/// compared at once ([`lanes::blocks_not_within`]), and the boxes of a
/// block that may hold a leaver then checked one by one.
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2"), dispatcher = "static")
)]
fn settle(
    boxes: &mut [Packed],
    keys: &[f32],
    (wide, kept, shift): (&[Packed], bool, &Shift),
    (start, leavers): (usize, &mut Vec<Slot>),
) -> u64 {
    let unboxed = keys.iter().map(|&k| u64::from(k == NO_KEY)).sum::<u64>();
    if unboxed > 0 {
        for (b, &key) in boxes.iter_mut().zip(keys) {
            if key == NO_KEY {
                *b = NOWHERE;
            }
        }
    }
    let shift = match (kept, shift) {
        (false, _) => return unboxed,
        (true, Shift::Still) => None,
        (true, Shift::By(s)) => Some(s),
    };
    // A line without a box lies in anything.
    let within = |k: usize, b: &Packed, w: &Packed| match shift {
        None => inside(b, w),
        Some(s) => inside_moved(b, w, s) || keys[k] == NO_KEY,
    };
    let leave = |k: usize| leavers.push(Slot((start + k) as u32));
    multiversion::target::match_target! {
        "x86_64+avx2" => {
            let mut leave = leave;
            let mut check = |from: usize, to: usize| {
                (from..to).filter(|&k| !within(k, &boxes[k], &wide[k])).for_each(&mut leave)
            };
            let whole = lanes::blocks_not_within(boxes, wide, shift, &mut check);
            check(whole, boxes.len());
        }
        _ => {
            let each = boxes.iter().zip(wide).enumerate();
            let mut leave = leave;
            each.filter(|&(k, (b, w))| !within(k, b, w)).for_each(|(k, _)| leave(k));
        }
    }
    unboxed
}

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

/// Drops the pairs that have a line `leaving`, each replaced by the last
/// pair: the pairs are only read up to each that is dropped (a few in
/// thousands), not moved up one by one. The order of the pairs changes,
/// which changes nothing found: events are resolved in the contract's
/// order, whatever order they are found in.
fn drop_leavers(pairs: &mut Vec<(Slot, Slot)>, leaving: &[bool]) {
    let leaves = |&(a, b): &(Slot, Slot)| leaving[a.0 as usize] | leaving[b.0 as usize];
    let mut from = 0;
    while let Some(k) = pairs[from..].iter().position(leaves) {
        pairs.swap_remove(from + k);
        from += k;
    }
}

/// [`settle`]'s check of a block of boxes at once with AVX2.
#[cfg(target_arch = "x86_64")]
mod lanes {
    use super::Packed;
    use std::arch::x86_64::{
        __m256, _mm256_add_ps, _mm256_and_ps, _mm256_cmp_ps, _mm256_movemask_ps, _CMP_GE_OQ,
        _CMP_GT_OQ,
    };

    /// Boxes checked at once: each compared with its widened box, the
    /// comparisons put together, and one branch on them, which is nearly
    /// always not taken.
    const BLOCK: usize = 8;

    /// Calls `check(from, to)` for each block of boxes `from..to` of
    /// `boxes` (a whole block at a time) of which one may not lie in its
    /// widened box of `wide` (moved by `shift`, if any) as
    /// [`inside`](super::inside) or [`inside_moved`](super::inside_moved)
    /// tells (the same comparisons, lane by lane). Returns where the
    /// whole blocks end.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn blocks_not_within(
        boxes: &[Packed],
        wide: &[Packed],
        shift: Option<&Packed>,
        check: &mut impl FnMut(usize, usize),
    ) -> usize {
        let lanes = |p: &Packed| -> __m256 { bytemuck::cast(*p) };
        let whole = boxes.len().min(wide.len()) / BLOCK * BLOCK;
        let blocks = boxes[..whole]
            .chunks_exact(BLOCK)
            .zip(wide.chunks_exact(BLOCK));
        let all = |each: &dyn Fn(usize) -> __m256| {
            let pairs: [__m256; BLOCK / 2] =
                std::array::from_fn(|k| _mm256_and_ps(each(2 * k), each(2 * k + 1)));
            let all = _mm256_and_ps(
                _mm256_and_ps(pairs[0], pairs[1]),
                _mm256_and_ps(pairs[2], pairs[3]),
            );
            _mm256_movemask_ps(all) == 0xFF
        };
        match shift {
            None => {
                for (c, (b, w)) in blocks.enumerate() {
                    let each = |k: usize| _mm256_cmp_ps::<_CMP_GE_OQ>(lanes(&b[k]), lanes(&w[k]));
                    if !all(&each) {
                        check(c * BLOCK, (c + 1) * BLOCK);
                    }
                }
            }
            Some(s) => {
                let s = lanes(s);
                for (c, (b, w)) in blocks.enumerate() {
                    let each = |k: usize| {
                        _mm256_cmp_ps::<_CMP_GT_OQ>(lanes(&b[k]), _mm256_add_ps(lanes(&w[k]), s))
                    };
                    if !all(&each) {
                        check(c * BLOCK, (c + 1) * BLOCK);
                    }
                }
            }
        }
        whole
    }
}

/// Compares the boxes of each pair of slots in `pairs` and hands those
/// that overlap to `found`'s test, counting every pair compared as met.
/// A line without a box has [`NOWHERE`] for one: it is wild or inert, and
/// tested as such.
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2"), dispatcher = "static")
)]
fn compare(
    pairs: &[(Slot, Slot)],
    boxes: &[Packed],
    (stored, dt): (Stored, f64),
    found: &mut Findings,
) {
    found.met(pairs.len() as u64);
    multiversion::target::match_target! {
        "x86_64+avx2" => {
            let screen = |l1: &Line, l2: &Line, dt| crate::narrow::four::screen(l1, l2, dt);
            compare_each(pairs, boxes, (stored, dt), found, screen)
        }
        _ => compare_each(pairs, boxes, (stored, dt), found, crate::detect::pairs::screen),
    }
}

/// [`compare`]'s loop, with the prefilter and exact test `screen` (see
/// [`Findings::test_with`]).
#[inline(always)]
fn compare_each(
    pairs: &[(Slot, Slot)],
    boxes: &[Packed],
    (stored, dt): (Stored, f64),
    found: &mut Findings,
    screen: impl Fn(&Line, &Line, f64) -> Option<Option<crate::narrow::IntersectionKind>>,
) {
    for &(a, b) in pairs {
        if overlaps(&boxes[b.0 as usize], &reach(&boxes[a.0 as usize])) {
            found.test_with(stored, (a, b), dt, &screen);
        }
    }
}

/// Whether box `b` lies in box `w`: each of its lanes is at least the
/// other's (both are lower bounds). Written without branches, as
/// [`overlaps`] is, so that the AVX2 clones make it one comparison.
#[inline(always)]
fn inside(b: &Packed, w: &Packed) -> bool {
    (0..8).fold(true, |all, l| all & (b[l] >= w[l]))
}

/// Whether box `b` lies in box `w` moved by `s` (each lane's shift
/// rounded up): each lane of `b` is greater than the other's moved, as
/// rounded to nearest, so at least its exact value.
#[inline(always)]
fn inside_moved(b: &Packed, w: &Packed, s: &Packed) -> bool {
    (0..8).fold(true, |all, l| all & (b[l] > w[l] + s[l]))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// How far the frame moving with `v` moves in `steps` of `dt` along
    /// `x`, `y` and the diagonals, as the exact values the shift stands
    /// for.
    fn moved(v: [f64; 2], steps: u64, dt: f64) -> [f64; 4] {
        let (x, y) = (steps as f64 * dt * v[0], steps as f64 * dt * v[1]);
        [
            x,
            y,
            x * DIAGONAL_X + y * DIAGONAL_Y,
            x * DIAGONAL_X - y * DIAGONAL_Y,
        ]
    }

    proptest::proptest! {
        /// A box found inside a widened box moved by the frame's shift
        /// lies inside it moved by the exact distance, lane by lane: its
        /// least values at least the widened box's plus the distance, its
        /// greatest at most theirs plus the distance. Boxes are drawn
        /// about the moved widened box: one lane within a few of its `f32`
        /// steps, so that both answers come up, the others well inside.
        #[test]
        fn a_box_inside_the_moved_widened_box_lies_inside_it_exactly(
            wide in proptest::array::uniform8(-2000.0f32..2000.0),
            v in proptest::array::uniform2(-1.0f64..1.0),
            steps in 1u64..64,
            (lane, nudge) in (0usize..8, -8i32..8),
        ) {
            let dt = 0.5;
            let frame = Frame { velocity: v, steps };
            let Shift::By(s) = frame.shift(dt) else {
                return Ok(());
            };
            let d = moved(v, steps, dt);
            // Each lane's distance: the least values move by `d`, the
            // greatest (negated) by `-d`.
            let exact: [f64; 8] = std::array::from_fn(|l| match l < 4 {
                true => d[l],
                false => -d[l - 4],
            });
            let b: Packed = std::array::from_fn(|l| {
                let at = (wide[l] as f64 + exact[l]) as f32;
                let nudge = if l == lane { nudge } else { 64 };
                // Steps up from `at` (its bits count down below zero).
                let bits = at.to_bits() as i64 + nudge as i64 * at.signum() as i64;
                f32::from_bits(bits as u32)
            });
            if inside_moved(&b, &wide, &s) {
                for l in 0..8 {
                    // Exact: two `f32` values of these sizes differ by an
                    // `f64` exactly.
                    let room = b[l] as f64 - wide[l] as f64;
                    proptest::prop_assert!(room >= exact[l], "lane {l}: {room} < {}", exact[l]);
                }
            }
        }

        /// A leaver's widened box, taken back to the frame's start, holds
        /// its box moved by the frame's shift.
        #[test]
        fn a_widened_box_taken_back_holds_its_box(
            b in proptest::array::uniform4(-2000.0f32..2000.0),
            size in proptest::array::uniform4(0.0f32..50.0),
            v in proptest::array::uniform2(-1.0f64..1.0),
            steps in 1u64..64,
        ) {
            let b: Packed = std::array::from_fn(|l| match l < 4 {
                true => b[l],
                false => -(b[l - 4] + size[l - 4]),
            });
            let line = Line::default();
            let frame = Frame { velocity: v, steps };
            let shift = frame.shift(0.5);
            let wide = widened(&b, &line, 0.5, (v, 0.001));
            let back = shift.back(&b, &wide).expect("a widened box");
            if let Shift::By(s) = shift {
                proptest::prop_assert!(inside_moved(&b, &back, &s));
            }
        }
    }

    #[test]
    fn most_lines_moving_alike_choose_their_frame_and_others_rest() {
        let line = |vx, vy| Line {
            v: Vec2::new(vx, vy),
            ..Line::default()
        };
        // Nine in ten alike: their velocity.
        let mut lines: Vec<Line> = (0..1000).map(|_| line(0.25, -0.5)).collect();
        for (k, l) in lines.iter_mut().enumerate().filter(|(k, _)| k % 10 == 0) {
            *l = line(k as f64 * 1e-3 - 0.5, 0.125);
        }
        let mut frame = Frame::default();
        let least = frame.choose(Stored::by_id(&lines), &mut Vec::new());
        assert_eq!(frame.velocity, [0.25, -0.5]);
        assert!(least > 0.0 && least < 0.1 * 0.75, "{least}");
        // All different: at rest, and the mean travel.
        let lines: Vec<Line> = (0..1000)
            .map(|k| {
                line(
                    (k as f64 * 0.618).fract() - 0.5,
                    (k as f64 * 0.414).fract() - 0.5,
                )
            })
            .collect();
        let least = frame.choose(Stored::by_id(&lines), &mut Vec::new());
        assert_eq!(frame.velocity, [0.0; 2]);
        assert!(least > 0.3 && least < 0.7, "{least}");
    }

    /// Feeds `choice` steps of `candidates` each while sweeping every
    /// step, and of `kept` pairs (a sweep every `every` steps) while
    /// keeping; returns the steps kept.
    fn run(choice: &mut Choice, steps: u64, candidates: u64, kept: u64, every: u64) -> u64 {
        run_lines(choice, steps, (candidates, kept, every), 1000)
    }

    /// [`run`] on a scene of `lines` lines.
    fn run_lines(
        choice: &mut Choice,
        steps: u64,
        (candidates, kept, every): (u64, u64, u64),
        lines: usize,
    ) -> u64 {
        let (mut kept_steps, mut since) = (0, 0);
        for _ in 0..steps {
            if choice.keeping() {
                // Keeping begins with a sweep of the widened boxes.
                let swept = since % every == 0;
                (kept_steps, since) = (kept_steps + 1, since + 1);
                choice.after(kept, swept, kept as usize, lines);
            } else {
                since = 0;
                choice.after(candidates, true, 0, lines);
            }
        }
        kept_steps
    }

    #[test]
    fn pairs_are_kept_where_they_are_fewer_and_hold_for_a_few_steps() {
        // Fewer pairs than candidates, a sweep every 8 steps: kept nearly
        // throughout (swept every step for a short while now and then).
        let mut choice = Choice::new(KeepPairs::Auto);
        let kept = run(&mut choice, 4000, 9000, 2500, 8);
        assert!(kept > 3800, "{kept}");
        // More pairs than candidates: a try now and then, each one step.
        let mut choice = Choice::new(KeepPairs::Auto);
        assert!(run(&mut choice, 4000, 3000, 10_000, 8) <= 5);
        // Fewer, but a sweep every step: tried, and given up.
        let mut choice = Choice::new(KeepPairs::Auto);
        let kept = run(&mut choice, 4000, 9000, 2500, 1);
        assert!(kept <= 5 * JUDGE_EVERY, "{kept}");
        // A large scene is not tried, however it would fare.
        let mut choice = Choice::new(KeepPairs::Auto);
        assert_eq!(run_lines(&mut choice, 4000, (9000, 100, 8), TRY_BELOW), 0);
        // Always and never.
        assert_eq!(
            run(&mut Choice::new(KeepPairs::Always), 100, 1, 100, 1),
            100
        );
        assert_eq!(run(&mut Choice::new(KeepPairs::Never), 100, 100, 1, 100), 0);
    }
}
