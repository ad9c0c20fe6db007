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
use super::swept::{swept_box, SweptBox};
use super::{Detector, DetectorStats, Findings, Report, Setup, Stored};
use crate::index::{Index, Slot};
use crate::line::{Line, BOX_MAX, BOX_MIN};
use crate::team::{Parts, Team, MAX_PIECES};
use entries::{Entry, Refill};
use grid::{Cells, Grid};
use std::sync::Arc;
use std::time::Instant;
use tree::Tree;

/// Default for the largest number of lines a leaf holds before it splits.
pub const DEFAULT_LEAF_SIZE: usize = 16;
/// Default for the deepest level a node may split at.
pub const DEFAULT_MAX_DEPTH: u32 = 12;

/// The quadtree's phases, as [`Report::phases`](crate::detect::Report) names them.
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
/// Each step the lines are copied, in the order of the last walk of the
/// tree (boxed lines in key order, then the others), so that lines near
/// each other in space are near each other in memory: the tree and the
/// pair test work on places in the copies, and only the one gather per
/// step reads the lines in scattered order.
#[derive(Debug)]
pub struct Quadtree {
    tree: Tree,
    /// The team to split large phases over (none: one thread).
    team: Option<Arc<Team>>,
    grain: usize,
    grid: Grid,
    /// Every line's slot in the world's storage, in the order the copies
    /// are made.
    order: Vec<Slot>,
    /// Where `reorder` builds the next `order`.
    next_order: Vec<Slot>,
    /// This step's lines in `order`: place `p` holds a copy of the line in
    /// slot `order[p]`.
    copies: Vec<Line>,
    /// Whether each place's line has a finite hull and is in the tree.
    boxed: Vec<bool>,
    /// Slots of this step's lines that are not boxed: wild, then inert.
    unboxed: Vec<Slot>,
    /// Slots of this step's wild lines.
    wild: Vec<Slot>,
    stats: DetectorStats,
    /// Time per phase, while timing is on.
    clock: Option<Clock>,
}

impl Default for Quadtree {
    fn default() -> Self {
        Self::new(&super::DetectorConfig::default())
    }
}

/// The sort key given to slots left out of the tree: above every real key.
const UNBOXED_KEY: u64 = u64::MAX;

/// Hands the world's sink a walk's pairs (places in the copies), a few
/// at a time.
struct EventCollector<'a> {
    copies: &'a [Line],
    /// Each place's slot in the world's storage.
    order: &'a [Slot],
    stored: Stored<'a>,
    dt: f64,
    /// Pairs waiting for their test, in the order they came.
    pending: Vec<(u32, u32)>,
    /// The pending pairs' lines, copied for their test.
    pairs: Vec<(Line, Line)>,
    found: Findings,
}

/// Pairs an [`EventCollector`] holds before testing them together.
const PENDING: usize = 64;

impl<'a> EventCollector<'a> {
    /// A collector testing pairs of places in `copies`, whose slots are
    /// `order`, adding to `found`.
    fn new(
        copies: &'a [Line],
        order: &'a [Slot],
        stored: Stored<'a>,
        dt: f64,
        found: Findings,
    ) -> Self {
        EventCollector {
            copies,
            order,
            stored,
            dt,
            pending: Vec::with_capacity(PENDING),
            pairs: Vec::with_capacity(PENDING),
            found,
        }
    }

    /// Tests the pending pairs, in order. Their lines are copied first, in
    /// a loop whose scattered reads can all be in flight at once, where a
    /// test per pair as the walk meets it waits on each of its reads in
    /// turn.
    fn flush(&mut self) {
        let copies = self.copies;
        self.pairs.clear();
        self.pairs.extend(
            self.pending
                .iter()
                .map(|&(a, b)| (copies[a as usize], copies[b as usize])),
        );
        for ((a, b), &(p, q)) in self.pairs.iter().zip(&self.pending) {
            let (s, t) = (self.order[p as usize], self.order[q as usize]);
            (self.found).test_copies(self.stored, (s, a), (t, b), self.dt);
        }
        self.pending.clear();
    }

    /// What was found, once every pending pair is tested.
    fn finish(mut self) -> Findings {
        self.flush();
        self.found
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
        let found = Findings::default();
        EventCollector::new(self.copies, self.order, self.stored, self.dt, found)
    }

    fn join(&mut self, other: Self) {
        // Events stay in the order of the pairs: these, then the other's.
        self.flush();
        self.found.append(&mut other.finish());
    }
}

/// Fills one run of places (numbered from `first`) with copies of the
/// lines in slots `order`, and their tree entries over `grid` into
/// `refill`; returns the union of the hulls of the boxed ones.
#[allow(clippy::too_many_arguments)]
fn fill_run(
    first: usize,
    order: &[Slot],
    lines: &[Line],
    copies: &mut [Line],
    mut refill: Refill<'_>,
    (grid, max_depth): (Grid, u32),
    boxed: &mut [bool],
    dt: f64,
) -> Option<SweptBox> {
    let mut bounds: Option<SweptBox> = None;
    // Gather a block first, in a loop tight enough to keep many of its
    // scattered reads in flight; then work on the copies in order, while
    // they are still in the nearest cache.
    for start in (0..order.len()).step_by(GATHER) {
        let end = (start + GATHER).min(order.len());
        for (copy, &slot) in copies[start..end].iter_mut().zip(&order[start..end]) {
            *copy = lines[slot.at()];
        }
        for k in start..end {
            let hull = swept_box(&copies[k], dt);
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

/// Place `s`'s tree entry for its hull over `grid`; a place without one
/// (not boxed) gets a key past every real one, which sorts it last to be
/// cut off.
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
    /// ([`Detector::configure`]), it splits its work among it, in pieces
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
            copies: Vec::new(),
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

    /// Copies the lines in `order`, makes their tree entries over the
    /// current grid (left unsorted) and sorts out the wild and inert ones.
    /// Returns the union of the hulls.
    fn fill_copies(&mut self, lines: &[Line], dt: f64) -> Option<SweptBox> {
        let n = lines.len();
        if self.order.len() != n {
            self.order.clear();
            self.order.extend((0..n as u32).map(Slot));
        }
        self.copies.resize(n, Line::default());
        self.boxed.resize(n, false);
        let chunk = self.parallel_chunk(n);
        let grid = (self.grid, self.tree.max_depth());
        let refill = self.tree.entries.refill_in_place(n);
        let bounds = if let (Some(chunk), Some(team)) = (chunk, self.team.as_deref()) {
            // A piece per chunk of places, each with its own runs to fill.
            let pieces = n.div_ceil(chunk);
            let order = &self.order;
            let copies = Parts::new(self.copies.chunks_mut(chunk));
            let refills = Parts::new(refill.chunks(chunk));
            let boxed = Parts::new(self.boxed.chunks_mut(chunk));
            let mut unions = vec![None; pieces];
            let outs = Parts::new(unions.iter_mut());
            team.run_pieces(pieces, &|c| {
                let order = &order[c * chunk..((c + 1) * chunk).min(n)];
                let (copies, refill, boxed) = (copies.take(c), refills.take(c), boxed.take(c));
                *outs.take(c) = fill_run(c * chunk, order, lines, copies, refill, grid, boxed, dt);
            });
            unions.into_iter().fold(None, union)
        } else {
            fill_run(
                0,
                &self.order,
                lines,
                &mut self.copies,
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
                let slot = self.order[k];
                self.unboxed.push(slot);
                if !self.copies[k].is_inert() {
                    self.wild.push(slot);
                }
            }
        }
        bounds
    }

    /// Tests the wild lines against every boxed line and each other.
    fn test_wild(&self, stored: Stored, dt: f64, found: &mut Findings) {
        if self.wild.is_empty() {
            return;
        }
        let boxed = (self.order.iter().zip(&self.boxed))
            .filter(|(_, &b)| b)
            .map(|(&slot, _)| slot);
        found.test_wild(stored, &self.wild, boxed, dt);
    }

    /// Sets `order` to the tree's order of the boxed slots, then the others.
    fn reorder(&mut self) {
        // Place `p` holds the line in slot `order[p]`: a small array to
        // read, nearly in order, where the copies would be a large one.
        let chunk = self.parallel_chunk(self.tree.entries.list.len());
        let (order, entries) = (&self.order, &self.tree.entries.list);
        let slot = |e: &Entry| order[e.cells.id as usize];
        let next = &mut self.next_order;
        next.clear();
        if let (Some(chunk), Some(team)) = (chunk, self.team.as_deref()) {
            next.resize(entries.len(), Slot::default());
            let parts = Parts::new(next.chunks_mut(chunk));
            team.run_pieces(entries.len().div_ceil(chunk), &|c| {
                let mine = parts.take(c);
                let from = &entries[c * chunk..c * chunk + mine.len()];
                mine.iter_mut().zip(from).for_each(|(to, e)| *to = slot(e));
            });
        } else {
            next.extend(entries.iter().map(slot));
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
        stored: Stored,
        bounds: Option<SweptBox>,
        dt: f64,
        found: &mut Findings,
    ) {
        let Some(bounds) = bounds else { return };
        if !self.grid.holds(&bounds) {
            // Rare (lines escaping the box): fill again over a grid that
            // holds them. Cells clamped at the old grid's edge would still
            // be conservative (clamping keeps order), but would pile up there.
            self.grid = Grid::over(&bounds);
            self.fill_copies(stored.lines, dt);
            self.lap(Phase::Fill);
        }
        let n = self.copies.len();
        let team = self.team.as_deref();
        self.tree
            .entries
            .sort(team.filter(|_| self.parallel_chunk(n).is_some()));
        self.tree.entries.list.truncate(n - self.unboxed.len());
        self.lap(Phase::Sort);
        let taken = std::mem::take(found);
        let mut collector = EventCollector::new(&self.copies, &self.order, stored, dt, taken);
        self.tree
            .pairs(&mut collector, self.team.as_deref(), self.grain);
        *found = collector.finish();
        self.lap(Phase::Walk);
        self.reorder();
        self.lap(Phase::Reorder);
    }
}

impl Detector for Quadtree {
    fn detect(&mut self, stored: Stored<'_>, dt: f64, found: &mut Findings) {
        self.tree.counts = walk::WalkCounts::default();
        if let Some(clock) = &mut self.clock {
            clock.start(Instant::now());
        }
        let bounds = self.fill_copies(stored.lines, dt);
        self.test_wild(stored, dt, found);
        self.lap(Phase::Fill);
        self.build_and_walk(stored, bounds, dt, found);
        let walk = self.tree.counts;
        found.met(walk.candidates);
        self.stats.nodes += walk.nodes;
        self.stats.max_depth = self.stats.max_depth.max(walk.deepest);
    }

    fn report(&self) -> Report {
        Report {
            stats: self.stats,
            phases: Clock::report_of(self.clock.as_ref(), Phase::ALL.map(Phase::name)),
            ..Report::default()
        }
    }

    fn configure(&mut self, setup: &Setup) {
        if self.clock.is_some() != setup.timing {
            self.clock = setup.timing.then(Clock::new);
        }
        self.team = setup.team.clone();
    }
}
