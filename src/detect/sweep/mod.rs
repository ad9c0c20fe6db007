//! Sweep and prune: boxes sorted along one direction, each meeting only
//! the boxes whose least value lies within its own extent there, tested in
//! all eight directions of the swept hull at once.
//!
//! A step runs down this folder's files in order:
//! 1. [`hull`]: every line's padded swept hull, packed as eight `f32`
//!    lanes, made in last step's order (with several bands, the boxes
//!    that left their band noted as they are made);
//! 2. [`plan`]: now and then, the direction to sweep along and the bands
//!    to cut the plane into, chosen on a sample;
//! 3. with one band, [`order`]: the boxes sorted in place by their least
//!    value along that direction (nearly sorted already);
//! 4. with several, [`bands`] and [`layout`]: each box's home band (the
//!    one holding its least value across them), the boxes laid out band by
//!    band, each band sorted, and beside each band the boxes reaching into
//!    it from below (its guests), sorted too;
//! 5. [`scan`]: each band (or the one) swept, with several bands its homes
//!    among themselves and against its guests; the pairs whose hulls
//!    overlap go to the exact test;
//! 6. on a team, [`seams`]: now and then, the edges where the threads'
//!    groups of bands meet moved towards where their times would be even.
//!
//! Lines without a finite hull are tested against every line (wild) or
//! left out (inert), as for every broad phase (see [`super::swept`]).
//!
//! Words the files use:
//! - *box*: a line's padded swept hull, eight `f32` lanes ([`hull::Packed`]);
//! - *slot*: where a line sits in the world's storage; the arrays of boxes
//!   name lines by slot;
//! - *key*: a box's least value along the direction swept ([`hull::lo`]);
//! - *along*, *across*: the direction swept, and the one the bands cut;
//! - *boxed*: the boxes with a finite hull, first in the order;
//! - *band*: a stretch across; a box's *home* band holds its least value
//!   across, and it is a *guest* in each band above that its hull reaches
//!   into; *entries* are homes and guests together;
//! - *layout*: the boxes band by band, homes then guests, each sorted;
//!   *kept* (last step's, updated) or laid out *anew*;
//! - *mover*: a box whose home band changed since the last step, a
//!   *leaver* as its old band sees it and a *newcomer* as its new one does;
//! - *reach*: what a box's lanes are compared with ([`hull::reach`]);
//! - *group*: the consecutive bands one thread lays out and sweeps; a
//!   *seam* is where two groups meet;
//! - *plan*: the direction and the bands, chosen on a sample from the
//!   *spread* of each direction; a *trial* is a step with another band
//!   count;
//! - *chunk*: a thread's findings (events, counts, pairs), and in the
//!   one-band sweep on a team, a run of boxes swept at a time;
//! - *dense*: last step's candidates per entry were many, so the scan
//!   takes its loop for crowded bands.

pub(crate) mod bands;
pub(crate) mod hull;
pub(crate) mod layout;
pub(crate) mod order;
pub(crate) mod plan;
pub(crate) mod scan;
pub(crate) mod seams;

use super::clock::PhaseClock;
use super::swept::{test_ordered, test_wild, PairCounts};
use super::{Detector, DetectorConfig, DetectorStats};
use crate::line::{read_ahead, Line, LARGE_SCENE};
use crate::narrow::Event;
use crate::team::{self, Team};
use bands::Bands;
use hull::{lo, Packed};
use layout::{GroupView, Layout, Leavers};
use order::{Boxes, NO_KEY};
use plan::Plan;
use seams::Seams;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Steps between two plans (the first step always makes one).
const PLAN_EVERY: u64 = 256;

/// Scenes of this many lines or more have the world store their lines in
/// the sweep's order ([`crate::storage`]) even on one thread, as do scenes
/// that a team shares: each thread then moves and makes the hulls of the
/// same lines, and an exact test reads lines near each other. On one
/// thread a scene that fits the cache only pays for it: stored from the
/// first line on (every `STORE_EVERY` steps), `mit` 4000 frames took 0.143
/// s against 0.123 and `koch` 0.126 against 0.123 (medians of 7
/// interleaved rounds). Storing every step, when it was first measured,
/// made 100,000 lines 6% and a million 7% faster on one thread, and on
/// two threads 10,000 lines 11% and a million 16%.
const STORE_FROM: usize = LARGE_SCENE;

/// Steps between two times the world stores the lines in the sweep's
/// order; in between they move where they are. From step to step only the
/// few boxes that change band leave the order the lines are stored in, so
/// the hulls and the exact tests still read lines near each other, while
/// the move works in place instead of copying every line. Against storing
/// every step, on two threads (medians of 9 interleaved rounds): `koch`
/// 1000 frames 0.094 s against 0.099, 10,000 lines 0.343 s against 0.373,
/// a million lines 100 steps 4.75 s against 5.02; 8 and 32 steps did no
/// better in a trial.
const STORE_EVERY: u64 = 16;

// Scenes of `LARGE_SCENE` lines or more also wait on lines read in no
// order of memory's in two places, when they are not stored in the
// sweep's order: the hulls, which gather their lines a block at a time
// first ([`hull::make_gathered`]: a million lines made their hulls in 17
// ms a step instead of 39, two threads), and the exact tests, which read
// each pair's lines a few pairs ahead ([`Tester`]: a million lines swept
// and tested in 26 ms a step instead of 36). In a scene that fits the
// cache either only adds instructions (the gather: `koch` 6% more).

/// Boxes whose hulls are made at a time before the ones among them that
/// left their band are noted (16 KB of hulls, at hand in the cache).
const NOTE_BLOCK: usize = 512;

/// Candidates a box (in last step) above which the sweep meets every box's
/// candidates a block of eight at a time, with no branch on how many it
/// has ([`scan::sweep`]): 10,000 lines (four candidates a box) ran 8%
/// faster on one thread, 100,000 lines 5%, a million 3%; `mit` (fourteen a
/// box, most of which take blocks anyway) the same within noise, and
/// `koch` (under one a box) 20% slower in a trial, so sparse scenes keep
/// the branches.
const DENSE: f64 = 2.0;

/// Groups of bands per thread in a sweep on rayon's pool: more groups
/// than threads even out bands that meet more pairs than others.
const SWEEP_GROUPS_PER_THREAD: usize = 4;

/// Scenes of fewer boxes keep the sweep on one thread even with a team:
/// below this the hand-offs and the lines' travel between the cores' caches
/// cost more than the shared work saves. On two threads, against one
/// (medians of 9 interleaved rounds, the move shared from the same size):
/// generated scenes of 300 lines ran 0.85x, of 400 1.13x, of 500 1.24x and
/// of 700 1.29x; `beaver` (294 lines) 0.83x, `box` (401) 1.15x, `mit`
/// (809) 1.28x, `explosion` (600) 1.38x, the built-in 1000-line scene
/// 1.37x.
pub(crate) const TEAM_MIN_BOXES: usize = 384;

/// Boxes a team member sweeps at a time (with one band).
const TEAM_SWEEP_CHUNK: usize = 256;

/// Steps between two trials of another band count: a trial (and its end)
/// lays every box out anew, where the layout is otherwise kept from step
/// to step.
const TRIAL_EVERY: u64 = 128;

/// A trial's band count is kept when its work is below this share of the
/// work with the current count.
const TRIAL_GAIN: f64 = 0.97;

/// The sweep's phases, as [`Detector::phase_times`] names them.
#[derive(Clone, Copy, Debug)]
enum Phase {
    /// Making the packed hulls, noting the boxes that left their band
    /// (and, now and then, the plan).
    Hulls,
    /// With one band, sorting them along the sweep direction; with
    /// several, finding each one's home band.
    Sort,
    /// With several bands, laying them out band by band, each sorted, with
    /// their guests; listing the wild lines. (On a team, with the layout
    /// kept, each member sweeps its bands as soon as it has laid them out:
    /// the layout then ends where the caller's own part of it ended.)
    Layout,
    /// Sweeping the bands and testing the pairs that overlap; testing the
    /// wild lines.
    Sweep,
}

impl Phase {
    const ALL: [Phase; 4] = [Phase::Hulls, Phase::Sort, Phase::Layout, Phase::Sweep];

    fn name(self) -> &'static str {
        match self {
            Phase::Hulls => "hulls",
            Phase::Sort => "sort",
            Phase::Layout => "layout",
            Phase::Sweep => "sweep and test",
        }
    }
}

/// The sweep's phase timing.
type Clock = PhaseClock<{ Phase::ALL.len() }>;

/// The band count in use and the one on trial, with the work each did.
#[derive(Debug, Default)]
struct BandTuner {
    /// The work (entries and candidates, in the plan's cost units) of the
    /// last step with the band count in use.
    work: f64,
    /// Steps since the last trial.
    since_trial: u64,
    /// The count to try next: more (true) or fewer (false) bands.
    try_more: bool,
    /// The plan in use while a trial runs.
    kept: Option<Plan>,
}

/// The sort-based broad phase: packed hulls sorted along one direction and
/// swept, in bands across the other where one direction meets too much
/// (the design write-up, `docs/DESIGN.md`, tells how and why).
#[derive(Debug)]
pub struct Sweep {
    threads: usize,
    grain: usize,
    plan: Plan,
    /// Steps until the next plan.
    until_plan: u64,
    tuner: BandTuner,
    /// Every line's key, packed hull and id: this step's boxed lines first
    /// (with one band in sorted order, with several band by band, each
    /// band's own in sorted order), then the others. Next step's hulls are
    /// made in this order, so that its sort has little to do.
    sorted: Boxes,
    /// With several bands: where each band starts in `sorted`, its guests,
    /// and the buffers that lay them out.
    layout: Layout,
    /// Slots of this step's wild lines.
    wild: Vec<u32>,
    stats: DetectorStats,
    clock: Option<Clock>,
    /// The world's team of threads, which shares the phases from
    /// `TEAM_MIN_BOXES` boxes up to [`team::TEAM_GRAINS`] grains.
    team: Option<Arc<Team>>,
    /// The team's findings, a chunk of boxes each.
    chunks: Vec<Mutex<Chunk>>,
    /// Whether last step met many candidates a box ([`DENSE`]).
    dense: bool,
    /// Steps until the world next stores the lines in the boxes' order
    /// ([`Detector::storage_order`], `STORE_EVERY`).
    until_store: u64,
    /// On a team, where its groups of bands meet.
    seams: Seams,
}

impl Sweep {
    /// A sweep detector tuned by `config` (threads and grain apply).
    pub fn new(config: &DetectorConfig) -> Self {
        Self {
            threads: config.threads.max(1),
            grain: config.grain.max(1),
            plan: Plan {
                along: 0,
                bands: Bands::one(),
                spread: (0.0, 0.0),
            },
            until_plan: 0,
            tuner: BandTuner::default(),
            sorted: Boxes::default(),
            layout: Layout::default(),
            wild: Vec::new(),
            stats: DetectorStats::default(),
            clock: None,
            team: None,
            chunks: Vec::new(),
            until_store: 0,
            dense: false,
            seams: Seams::default(),
        }
    }

    /// The direction swept along (`x`, `y`, `u` or `w`) and the number of
    /// bands, as they stand.
    fn plan_text(&self) -> String {
        let name = ["x", "y", "u", "w"];
        let bands = self.plan.bands;
        if bands.count == 1 {
            format!("along {}, one band", name[self.plan.along])
        } else {
            format!(
                "along {}, {} bands across {}",
                name[self.plan.along], bands.count, name[bands.across]
            )
        }
    }

    fn lap(&mut self, phase: Phase) {
        if let Some(clock) = &mut self.clock {
            clock.lap(phase as usize);
        }
    }

    /// Whether `work` boxes' worth of a phase is shared on the current
    /// rayon pool: when it is at least two grains and not the team's.
    fn parallel(&self, work: usize) -> bool {
        self.threads > 1 && work >= 2 * self.grain && self.team_for(work).is_none()
    }

    /// The team to share `work` boxes' worth of a phase among, if there is
    /// one: from `TEAM_MIN_BOXES` to `TEAM_GRAINS` grains.
    fn team_for(&self, work: usize) -> Option<&Team> {
        self.team
            .as_deref()
            .filter(|_| team::takes(work, TEAM_MIN_BOXES, self.grain))
    }

    /// The groups of bands the layout of `n` boxes is shared in: one per
    /// thread of the team or the pool, if either shares it.
    fn layout_groups(&self, n: usize) -> usize {
        match (self.parallel(n), self.team_for(n)) {
            (true, _) => self.threads,
            (false, Some(team)) => team.threads(),
            (false, None) => 1,
        }
    }

    /// Makes every line's packed hull and key, in last step's order; with
    /// `by_id`, the lines are stored in the order of their ids rather than
    /// (nearly) in that order. When last step's layout may be kept, notes
    /// the boxes that left their band as it goes
    /// ([`Layout::leaver_check`]), a block at a time while its hulls are at
    /// hand.
    fn make_hulls(&mut self, lines: &[Line], dt: f64, by_id: bool) {
        let along = self.plan.along;
        let n = self.sorted.len();
        let gather = n >= LARGE_SCENE && by_id;
        let (parallel, chunk) = (self.parallel(n), self.grain);
        // A handle of its own, as the boxes are about to be borrowed mutably.
        let team = match self.team_for(n) {
            Some(_) => self.team.clone(),
            None => None,
        };
        let team = team.as_deref().map(|t| (t, t.threads()));
        let shares = match (team, parallel) {
            (Some((_, threads)), _) => threads,
            (None, true) => n.div_ceil(chunk),
            (None, false) => 1,
        };
        let groups = self.layout_groups(n);
        let (check, noted) = self
            .layout
            .leaver_check(n, &self.plan.bands, shares, groups);
        // The boxes from `at` on: `ids`' hulls and keys, noted in `noted`.
        let fill = |at: usize,
                    ids: &[u32],
                    hulls: &mut [Packed],
                    keys: &mut [f32],
                    noted: &mut Leavers| {
            noted.clear();
            let blocks = ids.chunks(NOTE_BLOCK).zip(hulls.chunks_mut(NOTE_BLOCK));
            for (k, ((ids, hulls), keys)) in blocks.zip(keys.chunks_mut(NOTE_BLOCK)).enumerate() {
                if gather {
                    hull::make_gathered(lines, ids, hulls, keys, along, dt);
                } else {
                    hull::make(lines, ids, hulls, keys, along, dt);
                }
                if let Some(check) = &check {
                    check.note(at + k * NOTE_BLOCK, (keys, hulls, ids), noted);
                }
            }
        };
        let b = &mut self.sorted;
        let (ids, hulls, keys) = (&b.ids[..n], &mut b.hulls[..n], &mut b.keys[..n]);
        if let Some((team, threads)) = team {
            let (hulls, keys, noted) = (
                team::shares_mut(hulls, threads),
                team::shares_mut(keys, threads),
                team::shares_mut(noted, threads),
            );
            team.run(&|k| {
                let share = team::share(n, threads, k);
                fill(
                    share.start,
                    &ids[share],
                    &mut hulls[k].lock().expect("a share"),
                    &mut keys[k].lock().expect("a share"),
                    &mut noted[k].lock().expect("a share")[0],
                );
            });
        } else if parallel {
            use rayon::prelude::*;
            ids.par_chunks(chunk)
                .zip(hulls.par_chunks_mut(chunk))
                .zip(keys.par_chunks_mut(chunk))
                .zip(noted.par_iter_mut())
                .enumerate()
                .for_each(|(c, (((ids, hulls), keys), noted))| {
                    fill(c * chunk, ids, hulls, keys, noted)
                });
        } else {
            fill(0, ids, hulls, keys, &mut noted[0]);
        }
    }

    /// Sets the seams of the plan's bands where the team's groups meet, if
    /// a team lays them out in groups; else none.
    fn seam_bands(&mut self) {
        let n = self.sorted.len();
        let seams = match self.team_for(n) {
            Some(team) if self.plan.bands.count >= team.threads() => self.seams.values(),
            _ => &[],
        };
        self.plan.bands = self.plan.bands.with_seams(seams);
    }

    /// Draws up a new plan from a sample of this step's boxes, and re-keys
    /// them if the direction changed.
    fn make_plan(&mut self) {
        let n = self.sorted.len();
        let sample = plan::Sample::of(&self.sorted.keys[..n], &self.sorted.hulls[..n]);
        let spread = |a| plan::spread(sample.extents(a), sample.boxed);
        // On a team the members share the directions: on one thread a
        // plan of `koch`'s 3,900 boxes takes as long as five steps.
        let spreads: Vec<plan::Spread> = match self.team_for(n) {
            Some(team) => {
                let threads = team.threads();
                let spreads: Vec<Mutex<Option<plan::Spread>>> =
                    (0..hull::DIRECTIONS).map(|_| Mutex::default()).collect();
                team.run(&|k| {
                    for a in team::share(hull::DIRECTIONS, threads, k) {
                        *spreads[a].lock().expect("a direction's spread") = Some(spread(a));
                    }
                });
                (spreads.into_iter())
                    .map(|s| s.into_inner().expect("a direction's spread"))
                    .map(|s| s.expect("every direction looked at"))
                    .collect()
            }
            None if self.parallel(n) => {
                use rayon::prelude::*;
                (0..hull::DIRECTIONS).into_par_iter().map(spread).collect()
            }
            None => (0..hull::DIRECTIONS).map(spread).collect(),
        };
        let plan = plan::choose_from(plan::LAYOUT, &spreads, sample.boxed);
        if plan.along != self.plan.along {
            let b = &mut self.sorted;
            for (key, hull) in b.keys.iter_mut().zip(&b.hulls) {
                if *key != NO_KEY {
                    *key = lo(hull, plan.along);
                }
            }
        }
        self.plan = plan;
        self.seams.clear();
        self.tuner = BandTuner::default();
        self.until_plan = PLAN_EVERY;
    }

    /// Picks this step's band count: now and then, one step tries a count
    /// next to the one in use.
    ///
    /// Only counts of two bands and more are tried: one band keeps its
    /// boxes in one sorted order and several keep them band by band, so a
    /// step across would cost a whole re-sort there and another back. The
    /// plan decides between one band and several.
    fn start_trial(&mut self) {
        let t = &mut self.tuner;
        t.since_trial += 1;
        if t.since_trial < TRIAL_EVERY || t.work == 0.0 || self.plan.bands.count == 1 {
            return;
        }
        t.since_trial = 0;
        t.try_more = !t.try_more;
        let bands = self.plan.bands;
        let count = if t.try_more {
            (bands.count * 5 / 4).max(bands.count + 1)
        } else {
            bands.count * 4 / 5
        };
        if count < 2 || count == bands.count {
            return;
        }
        let (from, to) = self.plan.spread;
        let across = plan::across(self.plan.along);
        t.kept = Some(self.plan);
        self.plan.bands = Bands::spanning(across, count, from, to);
    }

    /// Records this step's work; a trial that did less than the count in
    /// use becomes the count in use.
    fn end_step(&mut self, entries: usize, candidates: u64) {
        let banded = self.plan.bands.count > 1;
        let work = plan::work(
            plan::LAYOUT.per_box,
            entries as f64,
            candidates as f64,
            banded,
        );
        let t = &mut self.tuner;
        match t.kept.take() {
            Some(kept) if work >= TRIAL_GAIN * t.work => self.plan = kept,
            _ => t.work = work,
        }
    }

    /// Sweeps the bands `range` (or, with one band, the boxed lines) and
    /// tests the pairs whose hulls overlap.
    fn sweep_bands(
        &self,
        lines: Stored,
        dt: f64,
        boxed: usize,
        range: std::ops::Range<usize>,
        events: &mut Vec<Event>,
    ) -> PairCounts {
        let mut counts = PairCounts::default();
        let candidates = scan::sweep_bands(
            &self.sorted,
            boxed,
            &self.layout,
            &self.plan,
            range,
            self.dense,
            tester(lines, dt, events, &mut counts),
        );
        counts.candidates = candidates;
        counts
    }

    /// Finds the events among `stored`'s lines (see [`Detector::detect`]
    /// and [`Detector::detect_stored`]): the hulls (and now and then a
    /// plan), the boxes in order (one band) or laid out band by band, the
    /// sweep, then the wild lines against every box.
    fn detect_lines(&mut self, stored: Stored, dt: f64, events: &mut Vec<Event>) {
        let lines = stored.lines;
        let before = events.len();
        if let Some(clock) = &mut self.clock {
            clock.start(Instant::now());
        }
        if self.sorted.len() != lines.len() {
            self.sorted.reset(lines.len());
            self.layout.forget();
            self.until_plan = 0;
        }

        self.seam_bands();
        self.make_hulls(lines, dt, stored.ids.is_none());
        if self.until_plan == 0 {
            self.make_plan();
        }
        self.until_plan -= 1;
        self.lap(Phase::Hulls);

        self.start_trial();
        self.seam_bands();
        let n = lines.len();
        let (boxed, entries, swept) = if self.plan.bands.count > 1 {
            self.lay_out_bands(stored, dt)
        } else {
            self.layout.forget();
            // A handle of its own, as the boxes are about to be borrowed
            // mutably.
            let team = self.team_for(n).and(self.team.clone());
            let boxed = self.sorted.sort(team.as_deref());
            self.lap(Phase::Sort);
            (boxed, boxed, None)
        };
        self.wild.clear();
        self.wild.extend(
            self.sorted.ids[boxed..n]
                .iter()
                .copied()
                .filter(|&slot| !lines[slot as usize].is_inert()),
        );
        match (&mut self.clock, swept) {
            (Some(clock), Some(layout_end)) => clock.lap_at(
                Phase::Layout as usize,
                layout_end.unwrap_or_else(Instant::now),
            ),
            _ => self.lap(Phase::Layout),
        }

        let mut counts = if swept.is_some() {
            self.join_swept_groups(events)
        } else {
            self.sweep_boxes(stored, dt, boxed, entries, events)
        };
        test_wild(
            lines,
            |k| stored.id(k),
            &self.wild,
            self.sorted.ids[..boxed].iter().copied(),
            dt,
            events,
            &mut counts,
        );
        self.end_step(entries, counts.candidates);
        self.dense = counts.candidates as f64 > DENSE * entries as f64;
        self.lap(Phase::Sweep);

        self.stats.candidate_pairs += counts.candidates;
        self.stats.exact_tests += counts.exact;
        self.stats.events += (events.len() - before) as u64;
    }

    /// Lays the boxes out in this step's bands: last step's layout updated
    /// when it has the same bands, otherwise laid out anew. Returns the
    /// boxes with a finite hull, the entries (homes and guests), and, on a
    /// team that kept the layout, `Some` of when the stepping thread's own
    /// layout ended: each member has then swept its group of bands as soon
    /// as it laid it out, into its chunk's findings.
    fn lay_out_bands(
        &mut self,
        stored: Stored,
        dt: f64,
    ) -> (usize, usize, Option<Option<Instant>>) {
        let n = stored.lines.len();
        let bands = self.plan.bands;
        let mut swept = None;
        let parallel = self.parallel(n);
        // A handle of its own, as the boxes are about to be borrowed
        // mutably.
        let team = self.team_for(n).and(self.team.clone());
        let groups = self.layout_groups(n);
        self.lap(Phase::Sort);
        let mut found = std::mem::take(&mut self.chunks);
        let kept = match team.as_deref() {
            Some(team) => {
                // Each member sweeps the bands it laid out while they are
                // at hand, with no wait for the others in between.
                // A member without a group (fewer bands than threads)
                // finds nothing: every member's chunk starts empty.
                found.resize_with(team.threads().max(found.len()), Mutex::default);
                for chunk in &mut found[..team.threads()] {
                    chunk.get_mut().expect("a group's findings").counts = PairCounts::default();
                }
                let layout_end = Mutex::new(None);
                let (along, dense) = (self.plan.along, self.dense);
                let sweep_each = |group: GroupView| {
                    if group.index == 0 {
                        *layout_end.lock().expect("the layout's end") = Some(Instant::now());
                    }
                    let mut chunk = found[group.index].lock().expect("a group's findings");
                    let Chunk {
                        events,
                        counts,
                        pairs,
                        entries,
                    } = &mut *chunk;
                    let test = tester(stored, dt, events, counts);
                    let candidates = scan::sweep_group(&group, along, dense, pairs, test);
                    counts.candidates = candidates;
                    *entries = group.keys.len() + group.guest_count();
                };
                let then = Some(&sweep_each as layout::ThenEach);
                let kept =
                    (self.layout).keep(&mut self.sorted, n, &bands, groups, Some(team), then);
                if kept.is_some() {
                    swept = Some(layout_end.into_inner().expect("the layout's end"));
                }
                kept
            }
            None => self
                .layout
                .keep(&mut self.sorted, n, &bands, groups, None, None),
        };
        self.chunks = found;
        let boxed = match kept {
            Some(boxed) => boxed,
            None => {
                self.layout
                    .classify(&self.sorted, n, &bands, parallel, team.as_deref());
                self.lap(Phase::Sort);
                self.layout
                    .lay_out(&mut self.sorted, n, &bands, groups, team.as_deref())
            }
        };
        (boxed, boxed + self.layout.guest_count(), swept)
    }

    /// The findings of groups swept as they were laid out, put together in
    /// group order (a member without a group found nothing); their times
    /// go to the seams.
    fn join_swept_groups(&mut self, events: &mut Vec<Event>) -> PairCounts {
        let mut counts = PairCounts::default();
        let threads = self.team.as_deref().map_or(1, Team::threads);
        if let Some(team) = self.team.as_deref() {
            let entries = (self.chunks[..threads].iter_mut())
                .map(|c| c.get_mut().expect("a group's findings").entries);
            let groups = team.last_parts().zip(entries);
            (self.seams).add_step(&self.plan.bands, &self.layout, groups);
        }
        join_findings(&mut self.chunks[..threads], events, &mut counts);
        counts
    }

    /// Sweeps the boxed lines laid out (or sorted, with one band) and
    /// tests the pairs whose hulls overlap: on the pool in groups of
    /// bands, on a team one group of bands a member (or with one band,
    /// chunks of the order as the members come), or on this thread.
    fn sweep_boxes(
        &mut self,
        stored: Stored,
        dt: f64,
        boxed: usize,
        entries: usize,
        events: &mut Vec<Event>,
    ) -> PairCounts {
        let bands = self.plan.bands;
        // A handle of its own: the chunks' buffers are taken from `self`.
        let team = self.team_for(entries).and(self.team.clone());
        let mut counts = PairCounts::default();
        if self.parallel(entries) && bands.count > 1 {
            use rayon::prelude::*;
            let groups = self
                .layout
                .group_bounds(&bands, SWEEP_GROUPS_PER_THREAD * self.threads);
            let found: Vec<(Vec<Event>, PairCounts)> = groups
                .into_par_iter()
                .map(|range| {
                    let mut found = Vec::new();
                    let c = self.sweep_bands(stored, dt, boxed, range, &mut found);
                    (found, c)
                })
                .collect();
            for (found, c) in found {
                events.extend(found);
                counts.add(&c);
            }
        } else if let (Some(team), true) = (team.as_deref(), bands.count > 1) {
            self.sweep_groups_on(team, stored, dt, boxed, events, &mut counts);
        } else if let Some(team) = team.as_deref() {
            self.sweep_chunks_on(team, stored, dt, boxed, events, &mut counts);
        } else {
            counts.add(&self.sweep_bands(stored, dt, boxed, 0..bands.count, events));
        }
        counts
    }

    /// [`Sweep::sweep_boxes`] on a team, with several bands: one group of
    /// bands per member, about the bands whose layout it kept, so that
    /// each reads the boxes it wrote and the lines it moved, where bands
    /// taken as the members finish one (four groups a member) mixed them
    /// between the cores' caches (`koch` two threads 0.090 s against 0.097,
    /// 10,000 lines 0.348 against 0.370, medians of 15 and 7 interleaved
    /// rounds). The findings are put together in group order.
    fn sweep_groups_on(
        &mut self,
        team: &Team,
        stored: Stored,
        dt: f64,
        boxed: usize,
        events: &mut Vec<Event>,
        counts: &mut PairCounts,
    ) {
        let groups = self.layout.group_bounds(&self.plan.bands, team.threads());
        let mut found = std::mem::take(&mut self.chunks);
        found.resize_with(groups.len().max(found.len()), Mutex::default);
        let threads = team.threads();
        team.run(&|k| {
            for g in team::share(groups.len(), threads, k) {
                let mut chunk = found[g].lock().expect("a group's findings");
                let Chunk { events, counts, .. } = &mut *chunk;
                *counts = self.sweep_bands(stored, dt, boxed, groups[g].clone(), events);
            }
        });
        join_findings(&mut found[..groups.len()], events, counts);
        self.chunks = found;
    }

    /// [`Sweep::sweep_boxes`] on a team, with one band: the boxes are
    /// swept a chunk at a time (each box against the boxes after it,
    /// wherever they lie), the members taking the next chunk as they
    /// finish one, since some stretches of the order meet far more pairs
    /// than others; the findings are put together in chunk order.
    fn sweep_chunks_on(
        &mut self,
        team: &Team,
        stored: Stored,
        dt: f64,
        boxed: usize,
        events: &mut Vec<Event>,
        counts: &mut PairCounts,
    ) {
        let chunks = boxed.div_ceil(TEAM_SWEEP_CHUNK);
        let next = AtomicUsize::new(0);
        let mut found = std::mem::take(&mut self.chunks);
        found.resize_with(chunks.max(found.len()), Mutex::default);
        let (sorted, along, dense) = (&self.sorted, self.plan.along, self.dense);
        team.run(&|_| loop {
            let c = next.fetch_add(1, Ordering::Relaxed);
            if c >= chunks {
                break;
            }
            let mut chunk = found[c].lock().expect("a chunk's findings");
            let Chunk {
                events,
                counts,
                pairs,
                ..
            } = &mut *chunk;
            *counts = PairCounts::default();
            let range = c * TEAM_SWEEP_CHUNK..((c + 1) * TEAM_SWEEP_CHUNK).min(boxed);
            let candidates = scan::sweep_sorted(
                sorted,
                range,
                along,
                dense,
                pairs,
                tester(stored, dt, events, counts),
            );
            counts.candidates = candidates;
        });
        join_findings(&mut found[..chunks], events, counts);
        self.chunks = found;
    }
}

/// The lines as the world stores them: `lines[slot]` has id `ids[slot]`,
/// or id `slot` without `ids`.
#[derive(Clone, Copy, Debug)]
struct Stored<'a> {
    lines: &'a [Line],
    ids: Option<&'a [u32]>,
}

impl Stored<'_> {
    /// The id of the line in `slot`.
    #[inline(always)]
    fn id(self, slot: u32) -> u32 {
        match self.ids {
            Some(ids) => ids[slot as usize],
            None => slot,
        }
    }
}

/// What a sweep hands each pair of slots whose hulls overlap to: the exact
/// test, appending to `events` and counting in `counts`.
fn tester<'a>(
    lines: Stored<'a>,
    dt: f64,
    events: &'a mut Vec<Event>,
    counts: &'a mut PairCounts,
) -> Tester<'a> {
    Tester {
        lines,
        ahead: lines.lines.len() >= LARGE_SCENE,
        dt,
        events,
        counts,
    }
}

/// The exact test of the pairs a sweep finds (see [`tester`]).
struct Tester<'a> {
    lines: Stored<'a>,
    /// Whether to read each pair's lines ahead of its test.
    ahead: bool,
    dt: f64,
    events: &'a mut Vec<Event>,
    counts: &'a mut PairCounts,
}

impl scan::Found for Tester<'_> {
    /// In scenes larger than the cache.
    fn reads_ahead(&self) -> bool {
        self.ahead
    }

    /// Reads both lines ahead.
    #[inline(always)]
    fn ahead(&self, a: u32, b: u32) {
        for id in [a, b] {
            if let Some(line) = self.lines.lines.get(id as usize) {
                read_ahead(line);
            }
        }
    }

    #[inline(always)]
    fn found(&mut self, a: u32, b: u32) {
        let stored = self.lines;
        let (a, b) = if stored.id(a) < stored.id(b) {
            (a, b)
        } else {
            (b, a)
        };
        test_ordered(
            &stored.lines[a as usize],
            &stored.lines[b as usize],
            (a, b),
            self.dt,
            self.events,
            self.counts,
        )
    }
}

/// One chunk's findings when a team sweeps, kept from step to step so
/// that its buffers are not allocated anew every step.
#[derive(Debug, Default)]
struct Chunk {
    events: Vec<Event>,
    counts: PairCounts,
    pairs: Vec<(u32, u32)>,
    /// The boxes (homes and guests) of the group of bands it holds the
    /// findings of, if it does.
    entries: usize,
}

/// Appends each chunk's events to `events` and adds its counts to
/// `counts`, in chunk order, emptying its events.
fn join_findings(chunks: &mut [Mutex<Chunk>], events: &mut Vec<Event>, counts: &mut PairCounts) {
    for chunk in chunks {
        let chunk = chunk.get_mut().expect("a chunk's findings");
        events.append(&mut chunk.events);
        counts.add(&chunk.counts);
    }
}

impl Default for Sweep {
    fn default() -> Self {
        Self::new(&DetectorConfig::default())
    }
}

impl Detector for Sweep {
    fn name(&self) -> &'static str {
        "sweep"
    }

    fn detect(&mut self, lines: &[Line], dt: f64, events: &mut Vec<Event>) {
        self.detect_lines(Stored { lines, ids: None }, dt, events);
    }

    fn detect_stored(&mut self, lines: &[Line], ids: &[u32], dt: f64, events: &mut Vec<Event>) {
        let ids = Some(ids);
        self.detect_lines(Stored { lines, ids }, dt, events);
    }

    /// The boxes' order, band by band, where the lines are read by more
    /// than one thread or do not fit the cache (see `STORE_FROM`), every
    /// `STORE_EVERY` steps.
    fn storage_order(&mut self) -> Option<&mut [u32]> {
        let n = self.sorted.len();
        let shared = self.threads > 1 && n >= TEAM_MIN_BOXES;
        if !(shared || n >= STORE_FROM) {
            return None;
        }
        if self.until_store > 0 {
            self.until_store -= 1;
            return None;
        }
        self.until_store = STORE_EVERY - 1;
        Some(&mut self.sorted.ids[..n])
    }

    fn stats(&self) -> DetectorStats {
        self.stats
    }

    fn describe(&self) -> String {
        self.plan_text()
    }

    fn set_timing(&mut self, on: bool) {
        self.clock = on.then(Clock::new);
    }

    fn set_threads(&mut self, threads: usize, team: Option<Arc<Team>>) {
        self.threads = threads.max(1);
        self.team = team;
    }

    fn phase_times(&self) -> Vec<(&'static str, Duration)> {
        Clock::report_of(self.clock.as_ref(), Phase::ALL.map(Phase::name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::test_util::line;

    /// On a team, a seam put anywhere across the bands every step (often
    /// many bands from where it was) changes the bands the boxes fall into
    /// while the layout is kept, and every step finds the oracle's events.
    #[test]
    fn seams_moved_anywhere_keep_the_events_exact() {
        use crate::detect::Brute;
        use crate::generate::{generate, SceneKind};
        use rand::{Rng, SeedableRng};
        let scene = generate(SceneKind::Uniform, 2200, 5);
        let mut lines = crate::World::with_detector(&scene, super::super::DetectorKind::Brute)
            .lines()
            .into_owned();
        let config = DetectorConfig {
            threads: 2,
            ..DetectorConfig::default()
        };
        let mut sweep = Sweep::new(&config);
        sweep.set_threads(2, Some(Arc::new(Team::new(2).expect("a team"))));
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let (mut seamed, mut events, mut expected) = (0, Vec::new(), Vec::new());
        for step in 0..40 {
            let bands = sweep.plan.bands;
            if bands.count > 2 {
                let (from, to) = sweep.plan.spread;
                sweep.seams.set(vec![rng.random_range(from..to)]);
                seamed += 1;
            }
            events.clear();
            sweep.detect(&lines, 0.5, &mut events);
            events.sort_unstable_by_key(Event::order_key);
            expected.clear();
            Brute::default().detect(&lines, 0.5, &mut expected);
            expected.sort_unstable_by_key(Event::order_key);
            assert_eq!(
                events, expected,
                "step {step}, bands {:?}",
                sweep.plan.bands
            );
            crate::motion::advance_and_bounce(&mut lines);
        }
        assert!(seamed > 30, "the scene was not cut into bands: {seamed}");
        assert!(
            sweep.plan.bands.seams().len() == 1,
            "{:?}",
            sweep.plan.bands
        );
        assert!(sweep.stats().events > 0, "no events to compare");
    }

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
        let mut events = Vec::new();
        let shared = DetectorConfig {
            threads: 2,
            ..DetectorConfig::default()
        };
        let mut sweep = Sweep::new(&shared);
        sweep.detect(&lines, 0.5, &mut events);
        let steps: Vec<u64> = (0..40u64)
            .filter(|_| sweep.storage_order().is_some())
            .collect();
        assert_eq!(steps, [0, STORE_EVERY, 2 * STORE_EVERY]);
        let mut alone = Sweep::new(&DetectorConfig::default());
        alone.detect(&lines, 0.5, &mut events);
        assert!((0..40).all(|_| alone.storage_order().is_none()));
    }
}
