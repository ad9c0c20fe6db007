//! Sweep and prune: boxes sorted along one direction, each meeting only
//! the boxes whose least value lies within its own extent there, tested in
//! all eight directions of the swept hull at once.
//!
//! Every phase runs on the world's team of threads (a team of one on one
//! thread, and for scenes too small to share), in the same code whatever
//! its size. A step runs down this folder's files in order:
//! 1. [`hull`]: every line's box, made in last step's order (with several
//!    bands, the movers noted as they are made), on one thread already in
//!    the move that ended last step ([`Detector::advance`]);
//! 2. [`plan`]: now and then, the direction to sweep along and the bands
//!    to cut the plane into, chosen on a sample;
//! 3. with one band, [`boxes`]: the boxes sorted in place by key (nearly
//!    sorted already);
//! 4. with several, [`bands`] and [`layout`]: the boxes laid out band by
//!    band, homes and guests, each sorted; a group of bands a thread;
//! 5. [`scan`]: with one band, the sorted boxes swept a chunk at a time;
//!    with several, each group's bands swept by the thread that laid them
//!    out, as soon as it has; the pairs whose boxes overlap go to the
//!    exact test;
//! 6. [`near`], where it pays: the boxes widened before the sweep, and the
//!    pairs it finds kept instead of tested; on the steps after, while
//!    every box lies in its widened box, steps 1 to 5 give way to the
//!    boxes made in slot order (in the move before) and the kept pairs'
//!    boxes compared, the few boxes that left mended through [`mend`].
//!
//! Lines without a finite hull are tested against every line (wild) or
//! left out (inert), as for every broad phase (see [`super::swept`]).
//!
//! Words the files use, one concept each:
//! - *box*: a line's padded swept hull, eight `f32` lanes ([`hull::Packed`]);
//!   *boxes* are kept as parallel arrays of keys, hulls and slots ([`boxes`]);
//! - *slot*: a line's place in the lines the detector is handed (where the
//!   world stores it); boxes name their lines by slot, and [`Stored::id`]
//!   gives the line's id in the scene;
//! - *key*: a box's least value along the direction swept ([`hull::lo`]);
//!   the boxes without a finite hull have none ([`hull::NO_KEY`]) and come
//!   last, after the *boxed* ones;
//! - *along*, *across*: the direction swept, and the one the bands cut;
//! - *plan*: the direction and the bands, chosen on a sample from the
//!   *spread* of each direction;
//! - *band*: a stretch across; a box's *home* band holds its least value
//!   across, and it is a *guest* in each band above that it reaches;
//!   its *end* is the band after the last it reaches;
//! - *layout*: the boxes band by band, homes then guests, each sorted;
//!   *kept* (last step's, updated) or laid out *anew*;
//! - *mover*: a box whose home band changed since the last step; a
//!   *stayer* kept its band;
//! - *reach*: the upper bounds another box's lanes are compared with
//!   ([`hull::reach`]); as a verb, a box reaches the bands it spans;
//! - *group*: the consecutive bands one thread lays out and sweeps;
//! - *share*: the boxes `team::share` gives a thread in a phase;
//! - *chunk*: what one piece of the sweep finds (events, counts, pairs):
//!   a group's, or with one band, a run of boxes swept at a time;
//! - *dense*: last step's candidates per box were many, so the scan
//!   takes its loop for crowded bands;
//! - *widened box*: a box with room for a few steps' travel; *kept pairs*:
//!   those whose widened boxes overlapped at the last sweep; a *leaver*'s
//!   box left its widened box, and is *mended* (widened again, its pairs
//!   found anew) or calls for a sweep.

pub(crate) mod bands;
pub(crate) mod boxes;
pub(crate) mod hull;
pub(crate) mod layout;
mod mend;
mod near;
pub(crate) mod plan;
pub(crate) mod scan;
pub(crate) mod tuning;

use super::clock::PhaseClock;
use super::{Detector, DetectorConfig, Findings, Handover, Report, Setup, Stored, SweepReport};
use crate::detect::sweep::tuning::{
    DENSE, LAYOUT_COST, NOTE_BLOCK, PLAN_EVERY, PLAN_EVERY_MOST, SAMPLE, TEAM_SWEEP_CHUNK,
};
use crate::index::Slot;
use crate::line::{Line, DT};
use crate::schedule::Schedule;
use crate::team::{self, Team};
use boxes::{BoxSliceMut, Boxes};
use hull::Packed;
use layout::{GroupView, Layout};
use near::{Choice, Near, ToMake};
use plan::Plan;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// The sweep's phases, as [`Report::phases`](crate::detect::Report) names them: making
/// the boxes and noting the movers (and now and then the plan); with one
/// band, sorting them; with several, laying them out band by band (until
/// the stepping thread's own part of it ended: each thread sweeps its
/// bands as soon as it laid them out); sweeping and testing the pairs that
/// overlap, and the wild lines.
const PHASES: [&str; 4] = ["hulls", "sort", "layout", "sweep and test"];

/// The sweep's phases, in [`PHASES`]' order.
#[derive(Clone, Copy)]
enum Phase {
    Hulls,
    Sort,
    Layout,
    Sweep,
}

/// The sweep's phase timing.
type Clock = PhaseClock<{ PHASES.len() }>;

/// The sort-based broad phase: boxes sorted along one direction and
/// swept, in bands across the other where one direction meets too much
/// (`docs/DESIGN.md` tells how and why).
#[derive(Debug, Default)]
pub struct Sweep {
    plan: Plan,
    /// Steps until the next plan.
    until_plan: u64,
    /// Steps between the last plan and the next ([`PLAN_EVERY`]).
    plan_every: u64,
    /// Every line's box: this step's boxed lines first (with one band in
    /// sorted order, with several band by band, each band's homes in
    /// sorted order), then the others. Next step's boxes are made in this
    /// order, so that its sort has little to do.
    sorted: Boxes,
    /// With several bands: where each band starts in `sorted`, its guests,
    /// and the buffers that lay them out.
    layout: Layout,
    /// Slots of this step's wild lines.
    wild: Vec<Slot>,
    clock: Option<Clock>,
    /// The team that shares the phases ([`Schedule::shares`]):
    /// the world's, or a team of one.
    team: Arc<Team>,
    /// A team of one: this thread alone, for scenes too small to share.
    solo: Arc<Team>,
    /// The findings of the chunks swept.
    chunks: Vec<Chunk>,
    /// Whether last step met many candidates a box ([`DENSE`]).
    dense: bool,
    /// Steps until the world next stores the lines in the boxes' order
    /// ([`Detector::hand_over`], [`Schedule::STORE_EVERY`]).
    until_store: u64,
    /// The pairs the last sweep found, kept for the steps after it while
    /// they hold ([`near`]), and whether they are used.
    near: Near,
    choice: Choice,
    /// Whether this step keeps pairs.
    keep: bool,
    /// Whether the move before this step made its boxes, in `sorted`'s
    /// order, and of what time step ([`Detector::advance`]).
    made: Option<f64>,
    /// Whether that move also noted their movers, for one group of bands
    /// ([`Sweep::advance_in_order`]).
    noted_in_move: bool,
    /// Steps detected.
    steps: u64,
}

impl Sweep {
    /// A sweep detector on the calling thread alone, until
    /// [`Detector::configure`] gives it a team, keeping pairs as
    /// `config.keep_pairs` says.
    pub fn new(config: &DetectorConfig) -> Self {
        Self {
            choice: Choice::new(config.keep_pairs),
            ..Self::default()
        }
    }

    fn lap(&mut self, phase: Phase) {
        if let Some(clock) = &mut self.clock {
            clock.lap(phase as usize);
        }
    }

    /// The team to share `work` boxes' (or a kept step's lines') worth of
    /// a phase among: the team where [`Schedule::shares`], else this
    /// thread alone. (A handle of its own, as the phases borrow the boxes
    /// mutably.)
    fn team_for(&self, work: usize) -> Arc<Team> {
        match Schedule::shares(work) {
            true => Arc::clone(&self.team),
            false => Arc::clone(&self.solo),
        }
    }

    /// Makes every line's box and key, in last step's order, a share a
    /// thread (where pairs are kept, the widened boxes, gathered; where
    /// the move before `made` them, none). When
    /// last step's layout may be kept, each share notes its movers as it
    /// goes ([`Layout::mover_check`]), a block at a time while its boxes
    /// are at hand. Where the move made the boxes and noted their movers,
    /// there is nothing to do.
    fn make_hulls(&mut self, lines: &[Line], dt: f64, (keep, made): (bool, bool)) {
        if std::mem::take(&mut self.noted_in_move) && made {
            return;
        }
        let along = self.plan.along;
        let n = self.sorted.len();
        let team = self.team_for(n);
        let threads = team.threads();
        let (check, noted) = (self.layout).mover_check(n, &self.plan.bands, threads, threads);
        let shares = self.sorted.slice_mut(n).shares(threads);
        let noted = team::split_mut(noted, threads);
        let near = keep.then_some(&self.near);
        team.run(&|k| {
            let start = team::share(n, threads, k).start;
            let mut share = shares.take(k);
            let noted = &mut noted.take(k)[0];
            noted.clear();
            for at in (0..share.len()).step_by(NOTE_BLOCK) {
                let block = share.at(at..(at + NOTE_BLOCK).min(share.len()));
                match near {
                    Some(near) => near.gather(block.slots, block.hulls, block.keys, along),
                    None if made => {}
                    None => hull::make(lines, block.slots, block.hulls, block.keys, along, dt),
                }
                if let Some(check) = &check {
                    check.note(start + at, block.view(), noted);
                }
            }
        });
    }

    /// [`Detector::advance`] making the boxes by slot, for a step that
    /// keeps pairs ([`Near::make`]), in `shared`'s pieces.
    fn advance_by_slot(&mut self, lines: &mut [Line], shared: Option<(&Team, usize)>) -> u64 {
        let n = lines.len();
        let pieces = shared.map_or(1, |(_, pieces)| pieces);
        let ToMake { boxes, keys, check } = self.near.boxes_to_make(n, pieces, DT);
        let unboxed = AtomicU64::new(0);
        // Each piece moves its lines, makes their boxes and checks them.
        let piece = |k: usize, lines: &mut [Line], boxes: &mut [Packed], keys: &mut [f32]| {
            let hits = hull::advance_and_make(lines, None, boxes, keys, (0, DT));
            let slots = team::share(n, pieces, k);
            let found = check.settle(k, slots, (boxes, keys));
            unboxed.fetch_add(found, Ordering::Relaxed);
            hits
        };
        let hits = match shared {
            Some((team, pieces)) => {
                let lines = team::split_mut(lines, pieces);
                let (boxes, keys) = (
                    team::split_mut(boxes, pieces),
                    team::split_mut(keys, pieces),
                );
                team.run_pieces_sum(pieces, &|k| {
                    piece(k, lines.take(k), boxes.take(k), keys.take(k))
                })
            }
            None => piece(0, lines, boxes, keys),
        };
        drop(check);
        self.near.made(DT, (unboxed.into_inner(), pieces));
        hits
    }

    /// [`Detector::advance`] making the boxes in this step's order, for a
    /// step that sweeps on this thread ([`Sweep::make_hulls`]). Where the
    /// layout of several bands may be kept, the movers are noted a block
    /// at a time as the boxes are made, as the next step's first phase
    /// would (for one group of bands: this step's team is this thread
    /// alone), while the boxes are at hand rather than read again.
    fn advance_in_order(&mut self, lines: &mut [Line]) -> u64 {
        let (n, along) = (lines.len(), self.plan.along);
        let (check, noted) = (self.layout).mover_check(n, &self.plan.bands, 1, 1);
        let mut boxes = self.sorted.slice_mut(n);
        let make = |lines: &mut [Line], b: BoxSliceMut| {
            hull::advance_and_make(lines, Some(b.slots), b.hulls, b.keys, (along, DT))
        };
        let hits = match (check, noted) {
            (Some(check), [noted]) => {
                noted.clear();
                let mut hits = 0;
                for at in (0..n).step_by(NOTE_BLOCK) {
                    let mut block = boxes.at(at..(at + NOTE_BLOCK).min(n));
                    hits += make(lines, block.at(0..block.len()));
                    check.note(at, block.view(), noted);
                }
                self.noted_in_move = true;
                hits
            }
            _ => make(lines, boxes),
        };
        self.made = Some(DT);
        hits
    }

    /// Draws up a new plan from a sample of this step's boxes, and re-keys
    /// them if the direction changed; the next comes later where this plan
    /// and the last are both of one band along one direction
    /// ([`PLAN_EVERY`]).
    fn make_plan(&mut self) {
        let n = self.sorted.len();
        let from = (SAMPLE, hull::DIRECTIONS);
        let plan = plan::replan(&mut self.sorted, n, from, LAYOUT_COST, self.plan.along);
        // Bands follow the scene's spread, which a wait of thousands of
        // steps would leave behind: only a plain sweep settles.
        let one_band = plan.bands.count == 1 && self.plan.bands.count == 1;
        let settled = one_band && plan.along == self.plan.along;
        self.plan_every = match settled {
            true => (self.plan_every * 2).clamp(PLAN_EVERY, PLAN_EVERY_MOST),
            false => PLAN_EVERY,
        };
        self.plan = plan;
        self.until_plan = self.plan_every;
    }

    /// Finds the events among `stored`'s lines (see [`Detector::detect`]):
    /// where pairs are kept and still hold, the kept pairs' boxes
    /// compared ([`near`]); else the boxes (and now and then a plan), the
    /// boxes in order (one band) or laid out band by band, the sweep; then
    /// the wild lines against every box.
    fn detect_lines(&mut self, stored: Stored, dt: f64, found: &mut Findings) {
        let lines = stored.lines;
        let n = lines.len();
        let before = found.counts;
        if let Some(clock) = &mut self.clock {
            clock.start(Instant::now());
        }
        if self.sorted.len() != n {
            self.sorted.reset(n);
            self.made = None;
            self.layout.forget();
            self.near.forget();
            self.until_plan = 0;
            self.plan_every = 0;
        }
        let keep = self.choice.keeping();
        self.keep = keep;
        // Whether the move before made this step's boxes in the sweep's
        // order (taken once: the next move makes them anew or not at all).
        let made = self.made.take() == Some(dt);
        if !keep {
            self.near.discard_made();
        }
        self.steps += 1;
        let laid = (self.sorted.slice(n), self.plan.along);
        if keep && self.near.make(lines, dt, &self.team_for(n), laid) {
            // The pairs kept hold: no sweep this step.
            for phase in [Phase::Hulls, Phase::Sort, Phase::Layout] {
                self.lap(phase);
            }
            self.test_kept((stored, dt), found, &self.team_for(n));
            self.lap(Phase::Sweep);
            self.choose(found.counts.candidates - before.candidates, false);
            return;
        }

        if keep {
            self.near.widen(stored, dt, &self.team_for(n));
        }
        self.make_hulls(lines, dt, (keep, made));
        if self.until_plan == 0 {
            self.make_plan();
        }
        self.until_plan = self.until_plan.saturating_sub(1);
        self.lap(Phase::Hulls);

        let (boxed, swept) = if self.plan.bands.count > 1 {
            self.lay_out_and_sweep(stored, dt, found)
        } else {
            self.layout.forget();
            let boxed = self.sorted.sort(&self.team_for(n));
            self.lap(Phase::Sort);
            self.lap(Phase::Layout);
            self.sweep_chunks(stored, dt, boxed, found);
            (boxed, boxed)
        };
        let candidates = found.counts.candidates - before.candidates;
        self.dense = candidates as f64 > DENSE * swept as f64;
        if keep {
            let groups = self.team_for(n).threads();
            let chunks = self.chunks.iter_mut();
            self.near.keep(chunks.map(|c| &mut c.near), groups);
            self.test_kept((stored, dt), found, &self.team_for(n));
        } else {
            let (boxed_slots, wild) = self.sorted.slots[..n].split_at(boxed);
            self.wild.clear();
            self.wild
                .extend(wild.iter().filter(|&&s| !stored.line(s).is_inert()));
            found.test_wild(stored, &self.wild, boxed_slots.iter().copied(), dt);
        }
        self.lap(Phase::Sweep);
        self.choose(found.counts.candidates - before.candidates, true);
    }

    /// A step's tests where pairs are kept: the kept pairs whose boxes
    /// overlap, and the wild lines against every line with a box.
    fn test_kept(&mut self, (stored, dt): (Stored, f64), found: &mut Findings, team: &Team) {
        self.near.test((stored, dt), found, team);
        self.near.wild(stored, &mut self.wild);
        found.test_wild(stored, &self.wild, self.near.boxed(), dt);
    }

    /// Chooses whether to keep pairs next step, from this step's
    /// `candidates` and whether it `swept` ([`Choice`]).
    fn choose(&mut self, candidates: u64, swept: bool) {
        let (pairs, lines) = (self.near.pairs(), self.sorted.len());
        let begins = self.choice.after(candidates, swept, pairs, lines);
        // Pairs kept from before a stretch of sweeping are stale, and not
        // worth carrying through the world's reorders.
        if begins || !self.choice.keeping() {
            self.near.forget();
        }
    }

    /// Lays the boxes out in this step's bands and sweeps them, a group of
    /// bands a member of the team, each member sweeping its group as soon
    /// as it laid it out (while its boxes are at hand). Returns the
    /// boxed lines, the homes and guests, and what the groups found, put
    /// together in group order.
    fn lay_out_and_sweep(
        &mut self,
        stored: Stored,
        dt: f64,
        found: &mut Findings,
    ) -> (usize, usize) {
        let n = stored.lines.len();
        let bands = self.plan.bands;
        let team = self.team_for(n);
        let groups = team.threads();
        self.lap(Phase::Sort);
        let mut chunks = std::mem::take(&mut self.chunks);
        // A member without a group (fewer bands than threads) finds
        // nothing: every group's findings start empty.
        chunks.resize_with(groups.max(chunks.len()), Chunk::default);
        chunks[..groups].iter_mut().for_each(|c| c.found.clear());
        debug_assert!(chunks.iter().all(|c| c.near.is_empty()), "kept pairs taken");
        let parts = team::Parts::new(chunks[..groups].iter_mut());
        let layout_end = Mutex::new(None);
        let (along, dense, keep) = (self.plan.along, self.dense, self.keep);
        // The clock is read only when timing (WebAssembly has none).
        let timing = self.clock.is_some();
        let sweep_each = |group: GroupView| {
            if timing && group.index == 0 {
                *layout_end.lock().expect("the layout's end") = Some(Instant::now());
            }
            let Chunk { found, pairs, near } = parts.take(group.index);
            let met = scan::sweep_group(&group, (along, dense), pairs, |p, first, second| {
                scan::hand_on((found, near), (keep, stored, dt), p, (first, second))
            });
            found.met(met);
        };
        let boxed = (self.layout).lay_out(&mut self.sorted, n, &bands, &team, &sweep_each);
        if let Some(clock) = &mut self.clock {
            let end = layout_end.into_inner().expect("the layout's end");
            clock.lap_at(Phase::Layout as usize, end.unwrap_or_else(Instant::now));
        }
        drop(parts);
        chunks[..groups]
            .iter_mut()
            .for_each(|c| found.append(&mut c.found));
        self.chunks = chunks;
        (boxed, boxed + self.layout.guest_count())
    }

    /// Sweeps the boxed lines in one band and tests the pairs whose boxes
    /// overlap: a chunk of the order at a time (each box against the boxes
    /// after it, wherever they lie), the members taking the next chunk as
    /// they finish one, since some stretches of the order meet far more
    /// pairs than others; the findings put together in chunk order. This
    /// thread alone sweeps it whole.
    fn sweep_chunks(&mut self, stored: Stored, dt: f64, boxed: usize, found: &mut Findings) {
        let team = self.team_for(boxed);
        let size = match team.threads() {
            1 => boxed.max(1),
            _ => TEAM_SWEEP_CHUNK,
        };
        let chunks = boxed.div_ceil(size);
        let next = AtomicUsize::new(0);
        let mut pieces = std::mem::take(&mut self.chunks);
        pieces.resize_with(chunks.max(pieces.len()), Chunk::default);
        debug_assert!(pieces.iter().all(|c| c.near.is_empty()), "kept pairs taken");
        let parts = team::Parts::new(pieces[..chunks].iter_mut());
        let (sorted, along, dense) = (&self.sorted, self.plan.along, self.dense);
        let keep = self.keep;
        team.run(&|_| loop {
            let c = next.fetch_add(1, Ordering::Relaxed);
            if c >= chunks {
                break;
            }
            let chunk = parts.take(c);
            chunk.found.clear();
            chunk.pairs.clear();
            let range = c * size..((c + 1) * size).min(boxed);
            let (keys, hulls) = (&sorted.keys[..], &sorted.hulls[..]);
            let candidates = scan::sweep(keys, hulls, range, along, dense, &mut chunk.pairs);
            chunk.found.met(candidates);
            let (slots, sink) = (&sorted.slots[..], (&mut chunk.found, &mut chunk.near));
            scan::hand_on(sink, (keep, stored, dt), &chunk.pairs, (slots, slots));
        });
        drop(parts);
        pieces[..chunks]
            .iter_mut()
            .for_each(|c| found.append(&mut c.found));
        self.chunks = pieces;
    }
}

/// One piece's findings and the pairs of places it swept, kept from step
/// to step so that their buffers are not allocated anew every step.
#[derive(Debug, Default)]
pub(crate) struct Chunk {
    pub found: Findings,
    pub pairs: Vec<(u32, u32)>,
    /// The pairs of slots whose boxes overlap, where they are kept
    /// ([`near`]) rather than tested; emptied by [`Near::keep`] as soon
    /// as the sweep ends.
    pub near: Vec<(Slot, Slot)>,
}

impl Detector for Sweep {
    fn detect(&mut self, stored: Stored<'_>, dt: f64, found: &mut Findings) {
        self.detect_lines(stored, dt, found);
    }

    /// The move and the walls, and in the same pass every line's box for
    /// the next step ([`hull::advance_and_make`]), which then makes none:
    /// where it keeps pairs, in slot order, a share a thread as the world
    /// splits the lines; where it sweeps on this thread alone, in this
    /// step's order (reading and writing each line where it is stored).
    /// A sweep shared among threads makes its own boxes.
    fn advance(&mut self, lines: &mut [Line], shared: Option<(&Team, usize)>) -> u64 {
        match self.choice.keeping() {
            true => self.advance_by_slot(lines, shared),
            false if shared.is_none() && self.sorted.len() == lines.len() => {
                self.advance_in_order(lines)
            }
            false => crate::motion::advance(lines, shared),
        }
    }

    /// The boxes' order, band by band, where the lines are read by more
    /// than one thread or do not fit the cache
    /// ([`Schedule::stores_in_order`]), every [`Schedule::STORE_EVERY`]
    /// steps (the boxes then name their lines by their new slots, which
    /// are their places); and the world's phases not shared while the
    /// pairs are kept on a scene too small to share
    /// ([`Schedule::shares`]): those steps run on this thread, and
    /// need the lines in no other order.
    fn hand_over(&mut self) -> Handover {
        let shares_step = !self.keep || Schedule::shares(self.sorted.len());
        Handover {
            order: self.store_order(shares_step),
            shares_step,
        }
    }

    fn report(&self) -> Report {
        let plan = SweepReport {
            along: self.plan.along,
            bands: self.plan.bands.count,
            across: self.plan.bands.across,
            steps: self.steps,
            keeping: self.near.steps,
            sweeps: self.near.sweeps,
            mended: self.near.mended,
            moving: self.near.moving,
        };
        Report {
            plan: Some(plan),
            phases: Clock::report_of(self.clock.as_ref(), PHASES),
            ..Report::default()
        }
    }

    fn configure(&mut self, setup: &Setup) {
        if self.clock.is_some() != setup.timing {
            self.clock = setup.timing.then(Clock::new);
        }
        self.team = setup.team.clone().unwrap_or_default();
    }
}

impl Sweep {
    /// The order to store the lines in ([`Handover::order`]), if this step
    /// is one to store them on.
    fn store_order(&mut self, shares_step: bool) -> Option<Vec<Slot>> {
        let n = self.sorted.len();
        if !Schedule::stores_in_order(n, self.team.threads()) || !shares_step {
            return None;
        }
        if self.until_store > 0 {
            self.until_store -= 1;
            return None;
        }
        self.until_store = Schedule::STORE_EVERY - 1;
        let slots = &mut self.sorted.slots[..n];
        let order = slots.to_vec();
        for (place, slot) in slots.iter_mut().enumerate() {
            *slot = Slot(place as u32);
        }
        self.near.reorder(&order);
        Some(order)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::line;

    /// A scene shared between threads has its lines stored in the sweep's
    /// order at the first step's end and every `STORE_EVERY` steps after;
    /// a small scene on one thread never.
    #[test]
    fn the_lines_are_stored_in_order_every_few_steps_where_it_pays() {
        let lines: Vec<Line> = (0..3000)
            .map(|k| {
                let (x, y) = ((k % 60) as f64 / 60.0, (k / 60) as f64 / 50.0);
                line((x, y), (x + 0.005, y + 0.005), (0.001, 0.0))
            })
            .collect();
        let mut found = Findings::default();
        let mut sweep = Sweep::default();
        sweep.configure(&Setup {
            timing: false,
            team: Some(Arc::new(Team::new(2).expect("a team"))),
        });
        sweep.detect(Stored::by_id(&lines), 0.5, &mut found);
        let steps: Vec<u64> = (0..40u64)
            .filter(|_| sweep.hand_over().order.is_some())
            .collect();
        let every = Schedule::STORE_EVERY;
        assert_eq!(steps, [0, every, 2 * every]);
        let mut alone = Sweep::default();
        alone.detect(Stored::by_id(&lines), 0.5, &mut found);
        assert!((0..40).all(|_| alone.hand_over().order.is_none()));
    }

    /// Where pairs are kept, the move checks the boxes it makes against
    /// their widened boxes as the next step would (each step asserts it,
    /// `Near::check_again`): on one thread and shared, with the widened
    /// boxes at rest and moving with most lines, leavers every few steps.
    #[test]
    fn the_move_checks_the_boxes_as_the_next_step_would() {
        use crate::detect::{DetectorKind, KeepPairs};
        use crate::generate::{generate, SceneKind};
        use crate::world::World;
        for (threads, as_one) in [(1, false), (2, false), (2, true), (3, true)] {
            let mut scene = generate(SceneKind::Uniform, 2500, 5);
            if as_one {
                let v = scene.lines[0].v * 4.0;
                let alike = scene.lines.iter_mut().filter(|l| l.p1.x.to_bits() % 8 != 0);
                alike.for_each(|line| line.v = v);
            }
            let config = DetectorConfig {
                threads,
                keep_pairs: KeepPairs::Always,
                ..DetectorConfig::default()
            };
            let mut world = World::with_config(&scene, DetectorKind::Sweep, &config).unwrap();
            (0..150).for_each(|_| world.step());
            let plan = world.detector().report().plan.expect("a sweep's plan");
            assert!(plan.keeping > plan.sweeps, "pairs kept: {plan:?}");
            assert!(plan.mended > 0, "boxes mended: {plan:?}");
            assert_eq!(plan.moving > 0, as_one, "{plan:?}");
        }
    }
}
