//! The quadtree detector: the design write-up's tree (see [`tree`]),
//! built over the lines' swept hulls every step, its pairs going straight
//! to the exact test.
//!
//! It finds exactly the all-pairs detector's events, on any number of
//! threads. The buffers live in the detector and are reused: once they
//! have grown to the scene's size, a step on one thread allocates nothing
//! (parallel tasks get buffers of their own).
//!
//! The tree is built anew every step rather than kept with fat hulls and
//! their pairs cached from step to step: the cached pairs pay only while
//! the fat hulls are fresh, and the sweep outruns both ways
//! (`docs/DESIGN.md`, "Tried and dropped").

mod entries;
mod grid;
mod tree;
mod walk;

use super::clock::PhaseClock;
use super::swept::{swept_box, test_pair, test_wild, PairCounts, SweptBox};
use super::{Detector, DetectorStats};
use crate::line::{Line, BOX_MAX, BOX_MIN};
use crate::narrow::Event;
use crate::team::{Parts, Team, MAX_PIECES};
use entries::{Entry, Refill};
use grid::{Cells, Grid};
use std::sync::Arc;
use std::time::{Duration, Instant};
use tree::Tree;

/// Default for the largest number of lines a leaf holds before it splits.
pub const DEFAULT_LEAF_SIZE: usize = 16;
/// Default for the deepest level a node may split at.
pub const DEFAULT_MAX_DEPTH: u32 = 12;

/// The quadtree's phases, as [`Detector::phase_times`] names them.
#[derive(Clone, Copy, Debug)]
enum Phase {
    /// Copying the lines into slots with their tree entries; testing wild
    /// lines.
    Fill,
    /// Sorting the tree's entries.
    Sort,
    /// Walking the tree and testing its pairs.
    Walk,
    /// Putting the slots in the tree's order for the next step.
    Reorder,
}

impl Phase {
    const ALL: [Phase; 4] = [Phase::Fill, Phase::Sort, Phase::Walk, Phase::Reorder];

    fn name(self) -> &'static str {
        match self {
            Phase::Fill => "fill",
            Phase::Sort => "sort",
            Phase::Walk => "walk and test",
            Phase::Reorder => "reorder",
        }
    }
}

/// The quadtree's phase timing.
type Clock = PhaseClock<{ Phase::ALL.len() }>;

/// A quadtree broad phase.
///
/// Each step the lines are copied into *slots*, in the order of the last
/// walk of the tree (boxed lines in key order, then the others), so that
/// lines near each other in space are near each other in memory: the tree
/// and the pair test work on slot numbers, and only the one gather per
/// step reads the lines in scattered order.
#[derive(Debug)]
pub struct Quadtree {
    tree: Tree,
    /// The team to split large phases over (none: one thread).
    team: Option<Arc<Team>>,
    grain: usize,
    grid: Grid,
    /// Every line's id, in the order slots are filled.
    order: Vec<u32>,
    /// Where `reorder` builds the next `order`.
    next_order: Vec<u32>,
    /// This step's lines in `order`: slot `s` holds a copy of line
    /// `order[s]`.
    slots: Vec<Line>,
    /// Whether each slot's line has a finite hull and is in the tree.
    boxed: Vec<bool>,
    /// Ids of this step's lines that are not boxed: wild, then inert.
    unboxed: Vec<u32>,
    /// Ids of this step's wild lines.
    wild: Vec<u32>,
    stats: DetectorStats,
    /// Time per phase, while timing is on.
    clock: Option<Clock>,
}

impl Default for Quadtree {
    fn default() -> Self {
        Self::new(&super::DetectorConfig::default())
    }
}

/// Default for the smallest piece of work handed to a thread, in lines.
pub const DEFAULT_GRAIN: usize = 16 * 1024;

/// The sort key given to slots left out of the tree: above every real key.
const UNBOXED_KEY: u64 = u64::MAX;

/// Collects a walk's pairs into events, testing each pair on the spot.
struct EventCollector<'a> {
    slots: &'a [Line],
    /// Each slot's line id.
    ids: &'a [u32],
    dt: f64,
    /// Pairs waiting for their test, in the order they came.
    pending: Vec<(u32, u32)>,
    /// The pending pairs' lines, copied for their test.
    copies: Vec<(Line, Line)>,
    events: Vec<Event>,
    counts: PairCounts,
}

/// Pairs an [`EventCollector`] holds before testing them together.
const PENDING: usize = 64;

impl<'a> EventCollector<'a> {
    /// A collector testing pairs of `slots`, whose line ids are `ids`,
    /// adding to `events`.
    fn new(slots: &'a [Line], ids: &'a [u32], dt: f64, events: Vec<Event>) -> Self {
        EventCollector {
            slots,
            ids,
            dt,
            pending: Vec::with_capacity(PENDING),
            copies: Vec::with_capacity(PENDING),
            events,
            counts: PairCounts::default(),
        }
    }

    /// Tests the pending pairs, in order. Their slots are copied first, in
    /// a loop whose scattered reads can all be in flight at once, where a
    /// test per pair as the walk meets it waits on each of its reads in
    /// turn.
    fn flush(&mut self) {
        let slots = self.slots;
        self.copies.clear();
        self.copies.extend(
            self.pending
                .iter()
                .map(|&(a, b)| (slots[a as usize], slots[b as usize])),
        );
        for ((a, b), &(s, t)) in self.copies.iter().zip(&self.pending) {
            let (a, b) = ((a, self.ids[s as usize]), (b, self.ids[t as usize]));
            test_pair(a, b, self.dt, &mut self.events, &mut self.counts);
        }
        self.pending.clear();
    }

    /// The events found, once every pending pair is tested.
    fn finish(mut self) -> (Vec<Event>, PairCounts) {
        self.flush();
        (self.events, self.counts)
    }
}

impl walk::Collector for EventCollector<'_> {
    #[inline]
    fn pair(&mut self, a: u32, b: u32) {
        self.pending.push((a, b));
        if self.pending.len() == PENDING {
            self.flush();
        }
    }

    fn fork(&self) -> Self {
        EventCollector::new(self.slots, self.ids, self.dt, Vec::new())
    }

    fn join(&mut self, other: Self) {
        // Events stay in the order of the pairs: these, then the other's.
        self.flush();
        let (mut events, counts) = other.finish();
        self.events.append(&mut events);
        self.counts.add(&counts);
    }
}

/// Fills one run of slots (numbered from `first`) with the lines `ids`
/// names, and their tree entries over `grid` into
/// `refill`; returns the union of the hulls of the boxed ones.
#[allow(clippy::too_many_arguments)]
fn fill_run(
    first: usize,
    ids: &[u32],
    lines: &[Line],
    slots: &mut [Line],
    mut refill: Refill<'_>,
    (grid, max_depth): (Grid, u32),
    boxed: &mut [bool],
    dt: f64,
) -> Option<SweptBox> {
    let mut bounds: Option<SweptBox> = None;
    // Gather a block first, in a loop tight enough to keep many of its
    // scattered reads in flight; then work on the copies in order, while
    // they are still in the nearest cache.
    for start in (0..ids.len()).step_by(GATHER) {
        let end = (start + GATHER).min(ids.len());
        for (slot, &id) in slots[start..end].iter_mut().zip(&ids[start..end]) {
            *slot = lines[id as usize];
        }
        for k in start..end {
            let hull = swept_box(&slots[k], dt);
            boxed[k] = hull.is_some();
            if let Some(hull) = hull {
                bounds = Some(bounds.map_or(hull, |b| b.union(&hull)));
            }
            let s = (first + k) as u32;
            refill.set(k, entry(&grid, hull, s, max_depth));
        }
    }
    bounds
}

/// Lines the fill gathers at a time (12 KB of them).
const GATHER: usize = 256;

/// Slot `s`'s tree entry for its hull over `grid`; a slot without one (not
/// boxed) gets a key past every real one, which sorts it last to be cut
/// off.
#[inline]
fn entry(grid: &Grid, hull: Option<SweptBox>, s: u32, max_depth: u32) -> Entry {
    match hull {
        Some(hull) => {
            let cells = grid.cells(&hull, s);
            Entry {
                key: grid::key(&cells, max_depth),
                cells,
            }
        }
        None => Entry {
            key: UNBOXED_KEY,
            cells: Cells {
                id: s,
                ..Cells::default()
            },
        },
    }
}

fn union(a: Option<SweptBox>, b: Option<SweptBox>) -> Option<SweptBox> {
    match (a, b) {
        (Some(a), Some(b)) => Some(a.union(&b)),
        (a, b) => a.or(b),
    }
}

impl Quadtree {
    /// A quadtree tuned by `config`: its leaves hold at most
    /// `config.leaf_size` lines (at least 1) unless `config.max_depth` (at
    /// most 15, the grid's finest level) stops the splitting. Given a team
    /// ([`Detector::set_threads`]), it splits its work among it, in pieces
    /// of at least `config.grain` lines.
    pub fn new(config: &super::DetectorConfig) -> Self {
        Self {
            tree: Tree::new(config.leaf_size, config.max_depth),
            team: None,
            grain: config.grain.max(1),
            grid: Grid::over(&SweptBox {
                min_x: BOX_MIN,
                min_y: BOX_MIN,
                max_x: BOX_MAX,
                max_y: BOX_MAX,
                ..SweptBox::default()
            }),
            order: Vec::new(),
            next_order: Vec::new(),
            slots: Vec::new(),
            boxed: Vec::new(),
            unboxed: Vec::new(),
            wild: Vec::new(),
            stats: DetectorStats::default(),
            clock: None,
        }
    }

    /// With timing on, adds the time since the last lap to `phase`.
    fn lap(&mut self, phase: Phase) {
        if let Some(clock) = &mut self.clock {
            clock.lap(phase as usize);
        }
    }

    /// Copies the lines into slots in `order`, makes their tree entries
    /// over the current grid (left unsorted) and sorts out the wild and
    /// inert ones. Returns the union of the hulls.
    fn fill_slots(&mut self, lines: &[Line], dt: f64) -> Option<SweptBox> {
        let n = lines.len();
        if self.order.len() != n {
            self.order.clear();
            self.order.extend(0..n as u32);
        }
        self.slots.resize(n, Line::default());
        self.boxed.resize(n, false);
        let chunk = self.parallel_chunk(n);
        let grid = (self.grid, self.tree.max_depth());
        let refill = self.tree.entries.refill_in_place(n);
        let bounds = if let (Some(chunk), Some(team)) = (chunk, self.team.as_deref()) {
            // A piece per chunk of slots, each with its own runs to fill.
            let pieces = n.div_ceil(chunk);
            let order = &self.order;
            let slots = Parts::new(self.slots.chunks_mut(chunk));
            let refills = Parts::new(refill.chunks(chunk));
            let boxed = Parts::new(self.boxed.chunks_mut(chunk));
            let mut unions = vec![None; pieces];
            let outs = Parts::new(unions.iter_mut());
            team.run_pieces(pieces, &|c| {
                let ids = &order[c * chunk..((c + 1) * chunk).min(n)];
                let (slots, refill, boxed) = (slots.take(c), refills.take(c), boxed.take(c));
                *outs.take(c) = fill_run(c * chunk, ids, lines, slots, refill, grid, boxed, dt);
            });
            unions.into_iter().fold(None, union)
        } else {
            fill_run(
                0,
                &self.order,
                lines,
                &mut self.slots,
                refill,
                grid,
                &mut self.boxed,
                dt,
            )
        };
        self.unboxed.clear();
        self.wild.clear();
        // Almost always none: a count that vectorises says so quickly.
        if self.boxed.iter().filter(|&&b| !b).count() == 0 {
            return bounds;
        }
        for (k, &is_boxed) in self.boxed.iter().enumerate() {
            if !is_boxed {
                let id = self.order[k];
                self.unboxed.push(id);
                if !self.slots[k].is_inert() {
                    self.wild.push(id);
                }
            }
        }
        bounds
    }

    /// Tests the wild lines against every boxed line and each other.
    fn test_wild(&self, lines: &[Line], dt: f64, events: &mut Vec<Event>, counts: &mut PairCounts) {
        if self.wild.is_empty() {
            return;
        }
        let boxed_ids = self
            .order
            .iter()
            .zip(&self.boxed)
            .filter(|(_, &b)| b)
            .map(|(&id, _)| id);
        test_wild(lines, |k| k, &self.wild, boxed_ids, dt, events, counts);
    }

    /// Sets `order` to the tree's order of the boxed slots, then the others.
    fn reorder(&mut self) {
        // Slot `s` holds line `order[s]`: a small array to read, nearly in
        // order, where the slots themselves would be a large one.
        let chunk = self.parallel_chunk(self.tree.entries.list.len());
        let (order, entries) = (&self.order, &self.tree.entries.list);
        let id = |e: &Entry| order[e.cells.id as usize];
        let next = &mut self.next_order;
        next.clear();
        if let (Some(chunk), Some(team)) = (chunk, self.team.as_deref()) {
            next.resize(entries.len(), 0);
            let parts = Parts::new(next.chunks_mut(chunk));
            team.run_pieces(entries.len().div_ceil(chunk), &|c| {
                let mine = parts.take(c);
                let from = &entries[c * chunk..c * chunk + mine.len()];
                mine.iter_mut().zip(from).for_each(|(to, e)| *to = id(e));
            });
        } else {
            next.extend(entries.iter().map(id));
        }
        next.extend_from_slice(&self.unboxed);
        std::mem::swap(&mut self.order, next);
    }

    /// The chunk size to split `n` items' work into, if it is worth
    /// splitting (at most [`MAX_PIECES`] chunks).
    fn parallel_chunk(&self, n: usize) -> Option<usize> {
        (self.team.is_some() && n >= 2 * self.grain).then(|| self.grain.max(n.div_ceil(MAX_PIECES)))
    }

    /// Builds the tree over this step's swept hulls (whose union is
    /// `bounds`) and tests its pairs.
    fn build_and_walk(
        &mut self,
        lines: &[Line],
        bounds: Option<SweptBox>,
        dt: f64,
        events: &mut Vec<Event>,
        counts: &mut PairCounts,
    ) {
        let Some(bounds) = bounds else { return };
        if !self.grid.holds(&bounds) {
            // Rare (lines escaping the box): fill again over a grid that
            // holds them. Cells clamped at the old grid's edge would still
            // be conservative (clamping keeps order), but would pile up there.
            self.grid = Grid::over(&bounds);
            self.fill_slots(lines, dt);
            self.lap(Phase::Fill);
        }
        let n = self.slots.len();
        let team = self.team.as_deref();
        self.tree
            .entries
            .sort(team.filter(|_| self.parallel_chunk(n).is_some()));
        self.tree.entries.list.truncate(n - self.unboxed.len());
        self.lap(Phase::Sort);
        let mut collector =
            EventCollector::new(&self.slots, &self.order, dt, std::mem::take(events));
        self.tree
            .pairs(&mut collector, self.team.as_deref(), self.grain);
        let found;
        (*events, found) = collector.finish();
        counts.add(&found);
        self.lap(Phase::Walk);
        self.reorder();
        self.lap(Phase::Reorder);
    }
}

impl Detector for Quadtree {
    fn name(&self) -> &'static str {
        "quadtree"
    }

    fn detect(&mut self, lines: &[Line], dt: f64, events: &mut Vec<Event>) {
        let before = events.len();
        let mut counts = PairCounts::default();
        self.tree.counts = walk::WalkCounts::default();
        if let Some(clock) = &mut self.clock {
            clock.start(Instant::now());
        }
        let bounds = self.fill_slots(lines, dt);
        self.test_wild(lines, dt, events, &mut counts);
        self.lap(Phase::Fill);
        self.build_and_walk(lines, bounds, dt, events, &mut counts);
        let walk = self.tree.counts;
        self.stats.candidate_pairs += counts.candidates + walk.candidates;
        self.stats.exact_tests += counts.exact;
        self.stats.nodes += walk.nodes;
        self.stats.max_depth = self.stats.max_depth.max(walk.deepest);
        self.stats.events += (events.len() - before) as u64;
    }

    fn stats(&self) -> DetectorStats {
        self.stats
    }

    fn set_timing(&mut self, on: bool) {
        self.clock = on.then(Clock::new);
    }

    fn set_threads(&mut self, team: Option<Arc<Team>>) {
        self.team = team;
    }

    fn phase_times(&self) -> Vec<(&'static str, Duration)> {
        Clock::report_of(self.clock.as_ref(), Phase::ALL.map(Phase::name))
    }
}
