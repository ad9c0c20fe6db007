//! The quadtree detector: the design write-up's tree (see [`tree`]), used in
//! one of two ways, or in whichever of the two is faster at the moment.
//!
//! - **Cached**: each line gets a *fat hull*, its swept hull stretched
//!   forward by eight more steps of its motion. The tree is built over fat
//!   hulls and yields every pair whose fat hulls overlap; those pairs are
//!   kept. Each step then only checks that every line's swept hull is still
//!   inside its fat hull; the few lines that left theirs get a new one, drop
//!   their pairs and ask the tree for their new ones; and the kept pairs
//!   whose actual swept hulls overlap go to the exact test. Since a swept
//!   hull is always inside its fat hull, every colliding pair is among the
//!   kept ones. The tree is rebuilt from scratch when many lines move at
//!   once, when the grid must grow, or when a line turns NaN.
//! - **Rebuilt**: the tree is built over the swept hulls every step and its
//!   pairs go straight to the exact test, as in the write-up.
//! - **Auto** (the default): whichever of the two is measured to be faster.
//!   Scenes where lines change course all the time (dense collisions) wear
//!   out fat hulls faster than they pay off, and so do huge scenes of tiny
//!   lines. The detector starts rebuilding; after its first few steps, and
//!   once every [`PERIOD`] steps after, it tries the other way for a few
//!   steps (giving up early once it is behind and no longer gaining) and
//!   keeps whichever took less time per step.
//!
//! All find exactly the all-pairs detector's events, so the choice affects
//! speed only, never results; so does the number of threads the work is
//! split over. The buffers live in the detector and are reused: once they
//! have grown to the scene's size, a step on one thread allocates nothing
//! (parallel tasks get buffers of their own).

pub mod tree;

use super::clock::PhaseClock;
use super::swept::{swept_box, test_pair, test_wild, PairCounts, SweptBox, DIAGONAL_X, DIAGONAL_Y};
use super::{Detector, DetectorStats};
use crate::line::{Line, BOX_MAX, BOX_MIN};
use crate::narrow::Event;
use std::fmt;
use std::str::FromStr;
use std::time::{Duration, Instant};
use tree::{Cells, Entry, Grid, Refill, Tree};

/// Default for the largest number of lines a leaf holds before it splits.
pub const DEFAULT_LEAF_SIZE: usize = 16;
/// Default for the deepest level a node may split at.
pub const DEFAULT_MAX_DEPTH: u32 = 12;

/// Steps of a line's motion that its fat hull has room for ahead of it. (Lines moving
/// alike leave their hulls together and bring a rebuild, which is cheaper
/// than refitting them one by one.)
const FAT_STEPS: f64 = 8.0;
/// The margin of a fat hull all round, in box units (about a third of a
/// pixel).
const FAT_MIN: f64 = 1.0 / 4096.0;
/// The cache is rebuilt from scratch when more than this share of the lines
/// leave their fat hulls in one step.
const REBUILD_SHARE: usize = 4;

/// How the quadtree detector keeps its tree from step to step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TreeMode {
    /// Rebuilt at first, then the cached way tried now and then; whichever
    /// is measured to be faster is kept.
    Auto,
    /// Fat hulls and their pairs kept from step to step.
    Cached,
    /// The tree rebuilt over the swept hulls every step.
    Rebuilt,
}

impl TreeMode {
    /// Every mode, in the order they are listed to users.
    pub const ALL: &'static [TreeMode] = &[TreeMode::Auto, TreeMode::Cached, TreeMode::Rebuilt];

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            TreeMode::Auto => "auto",
            TreeMode::Cached => "cached",
            TreeMode::Rebuilt => "rebuilt",
        }
    }
}

impl fmt::Display for TreeMode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for TreeMode {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        crate::parse_named(Self::ALL, Self::name, "tree mode", s)
    }
}

/// The quadtree's phases, as [`Detector::phase_times`] names them.
#[derive(Clone, Copy, Debug)]
enum Phase {
    /// Copying the lines into slots with their hulls (rebuilt: with their
    /// tree entries; cached: checking each against its fat hull); testing
    /// wild lines.
    Fill,
    /// Rebuilt: sorting the tree's entries.
    Sort,
    /// Rebuilt: walking the tree and testing its pairs.
    Walk,
    /// Rebuilt: putting the slots in the tree's order for the next step.
    Reorder,
    /// Cached: refitting the lines that left their fat hulls (their
    /// entries, their pairs).
    Upkeep,
    /// Cached: rebuilding the tree and its pairs from scratch.
    Rebuild,
    /// Cached: testing the kept pairs.
    Tests,
}

impl Phase {
    const ALL: [Phase; 7] = [
        Phase::Fill,
        Phase::Sort,
        Phase::Walk,
        Phase::Reorder,
        Phase::Upkeep,
        Phase::Rebuild,
        Phase::Tests,
    ];

    fn name(self) -> &'static str {
        match self {
            Phase::Fill => "fill",
            Phase::Sort => "sort",
            Phase::Walk => "walk and test",
            Phase::Reorder => "reorder",
            Phase::Upkeep => "cache upkeep",
            Phase::Rebuild => "cache rebuild",
            Phase::Tests => "cached tests",
        }
    }
}

/// The quadtree's phase timing.
type Clock = PhaseClock<{ Phase::ALL.len() }>;

/// Auto mode: steps between the starts of two trials of the way not in
/// use (once the first trial is over).
pub const PERIOD: u64 = 256;
/// Auto mode: steps each trial lasts, unless it gives up early.
const TRIAL: u64 = 16;
/// Auto mode: steps the first stint lasts, before the first trial.
const FIRST_STINT: u64 = 8;
/// Auto mode: first steps of a stint or trial left out of its timing (a
/// switch to the cached way starts with a rebuild).
const WARM_UP: u64 = 2;
/// Auto mode: the share of the stint's time per step that a trial's
/// latest steps must stay under while the trial is behind: a trial that
/// has spent more than the stint would have (the cached way starts with a
/// rebuild) gives up unless it is still gaining ground.
const GAINING: f64 = 0.95;
/// Auto mode: a trial that runs its course takes over when its time per
/// step is below this share of the stint's (a margin against noise).
const TAKES_OVER: f64 = 0.95;
/// Cached mode on threads: moved lines handed to a thread at a time to
/// query the tree for their new pairs (each query is a short walk).
const QUERIES_PER_TASK: usize = 64;

/// Auto mode's bookkeeping: which way is preferred, where the current
/// stint (the preferred way) or trial (the other way) stands, and the time
/// per step of each.
#[derive(Debug)]
struct Chooser {
    prefer_rebuilt: bool,
    /// Whether the current steps are a trial of the other way.
    trial: bool,
    /// Steps taken so far in the current stint or trial.
    into: u64,
    /// Whether the current stint is the first.
    first: bool,
    /// Seconds and steps timed: index 0 for the trial, 1 for the stint.
    timed: [(f64, u32); 2],
    /// Seconds spent on the current trial, warm-up included.
    spent: f64,
    /// The trial's last step, in seconds.
    last: f64,
}

impl Default for Chooser {
    /// Starts rebuilding: it needs no warming up, so the first stint is
    /// short and cheap on any scene, and the cached way is tried next.
    fn default() -> Self {
        Self {
            prefer_rebuilt: true,
            trial: false,
            into: 0,
            first: true,
            timed: [(0.0, 0); 2],
            spent: 0.0,
            last: 0.0,
        }
    }
}

impl Chooser {
    /// Whether this step should use the rebuilt way.
    fn rebuilt_now(&self) -> bool {
        self.prefer_rebuilt != self.trial
    }

    /// Records this step's detection time. A trial that is clearly losing
    /// gives up early; one that runs its course takes over if it beat the
    /// stint by 5%.
    fn record(&mut self, seconds: f64) {
        let slot = usize::from(!self.trial);
        if self.into >= WARM_UP {
            self.timed[slot].0 += seconds;
            self.timed[slot].1 += 1;
        }
        self.into += 1;
        let mean = |(t, n): (f64, u32)| (n > 0).then(|| t / f64::from(n));
        if self.trial {
            let (trial, stint) = (mean(self.timed[0]), mean(self.timed[1]));
            // A way can start well and wear out (fat hulls), so it is the
            // latest steps that say whether to give up: the last two, so
            // that one slow step does not end it.
            let recent = seconds.min(self.last);
            self.spent += seconds;
            self.last = seconds;
            let losing = matches!(stint, Some(s) if self.into > WARM_UP
                && self.spent > s * self.into as f64
                && recent >= GAINING * s);
            if losing || self.into == TRIAL {
                if let (false, Some(t), Some(s)) = (losing, trial, stint) {
                    if t < TAKES_OVER * s {
                        self.prefer_rebuilt = !self.prefer_rebuilt;
                    }
                }
                self.trial = false;
                self.first = false;
                self.into = 0;
                self.timed = [(0.0, 0); 2];
                self.spent = 0.0;
                self.last = 0.0;
            }
        } else if self.into
            == if self.first {
                FIRST_STINT
            } else {
                PERIOD - TRIAL
            }
        {
            self.trial = true;
            self.into = 0;
        }
    }
}

/// A quadtree broad phase.
///
/// Each step the lines are copied into *slots*, in the order of the last
/// walk of the tree (boxed lines in key order, then the others), so that
/// lines near each other in space are near each other in memory: the tree,
/// the cached pairs and the pair test all work on slot numbers, and only
/// the one gather per step reads the lines in scattered order.
#[derive(Debug)]
pub struct Quadtree {
    tree: Tree,
    mode: TreeMode,
    threads: usize,
    grain: usize,
    chooser: Chooser,
    grid: Grid,
    /// Every line's id, in the order slots are filled.
    order: Vec<u32>,
    /// Where `reorder` builds the next `order`.
    next_order: Vec<u32>,
    /// This step's lines in `order`: slot `s` holds a copy of line
    /// `order[s]`.
    slots: Vec<Line>,
    /// Each slot's swept hull this step (meaningful where `boxed`; cached
    /// mode only).
    hulls: Vec<SweptBox>,
    /// Whether each slot's line has a finite hull and is in the tree.
    boxed: Vec<bool>,
    /// Ids of this step's lines that are not boxed: wild, then inert.
    unboxed: Vec<u32>,
    /// Ids of this step's wild lines.
    wild: Vec<u32>,
    /// Cached mode: `boxed` as it was when the cache was built.
    cached_boxed: Vec<bool>,
    /// Cached mode: each slot's fat hull.
    fat: Vec<SweptBox>,
    /// Cached mode: where [`Quadtree::permute_slots`] works out the moves.
    permutation: Vec<u32>,
    /// Cached mode: the moved slots' new cells, to query the tree with, and
    /// the query's buffer.
    probes: Vec<Cells>,
    reaching: Vec<u32>,
    /// Cached mode: whether each slot left its fat hull this step.
    is_moved: Vec<bool>,
    /// Cached mode: the slots that left their fat hulls this step.
    moved: Vec<u32>,
    /// Cached mode: every pair of slots whose fat hulls overlap.
    pairs: Vec<(u32, u32)>,
    /// Cached mode: a second buffer for filtering `pairs` in parallel.
    spare_pairs: Vec<(u32, u32)>,
    /// Cached mode: whether the slots, the tree and the pairs are those of
    /// the last step and can be updated rather than rebuilt.
    valid: bool,
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

/// Cached mode: a rebuild puts the slots back in tree order once more than
/// one in this many of the tree's entries follow a higher slot.
const SLOTS_ASTRAY: usize = 8;

/// Cached mode: up to this many slots, a rebuild puts them in tree order
/// by moving them along the permutation's cycles (a scattered read and
/// write each); above it, where those miss the cache, by filling them again
/// from the lines (measured: moving is faster at 3,900 lines, slower at
/// 100,000 and at 1,000,000).
const PERMUTE_MAX: usize = 8192;

/// The sort key given to slots left out of the tree: above every real key.
const UNBOXED_KEY: u64 = u64::MAX;

/// Grows a swept hull into a fat hull: stretched forward by `FAT_STEPS`
/// more steps of the line's motion, so that a line keeping its velocity
/// stays inside that long, and padded by `FAT_MIN` all round.
fn fatten(hull: &SweptBox, line: &Line, dt: f64) -> SweptBox {
    let ahead = FAT_STEPS * dt;
    let (dx, dy) = (line.v.x * ahead, line.v.y * ahead);
    let (du, dw) = (
        dx * DIAGONAL_X + dy * DIAGONAL_Y,
        dx * DIAGONAL_X - dy * DIAGONAL_Y,
    );
    let (m, d) = (FAT_MIN, FAT_MIN * (DIAGONAL_X + DIAGONAL_Y));
    SweptBox {
        min_x: hull.min_x + dx.min(0.0) - m,
        min_y: hull.min_y + dy.min(0.0) - m,
        max_x: hull.max_x + dx.max(0.0) + m,
        max_y: hull.max_y + dy.max(0.0) + m,
        min_u: hull.min_u + du.min(0.0) - d,
        max_u: hull.max_u + du.max(0.0) + d,
        min_w: hull.min_w + dw.min(0.0) - d,
        max_w: hull.max_w + dw.max(0.0) + d,
    }
}

/// True when `inner` lies within `outer` in all eight directions.
#[inline]
fn holds(outer: &SweptBox, inner: &SweptBox) -> bool {
    (outer.min_x <= inner.min_x)
        & (outer.min_y <= inner.min_y)
        & (outer.max_x >= inner.max_x)
        & (outer.max_y >= inner.max_y)
        & (outer.min_u <= inner.min_u)
        & (outer.max_u >= inner.max_u)
        & (outer.min_w <= inner.min_w)
        & (outer.max_w >= inner.max_w)
}

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

impl tree::Collector for EventCollector<'_> {
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

/// Collects a walk's pairs as they are, lower slot first.
struct PairCollector(Vec<(u32, u32)>);

impl tree::Collector for PairCollector {
    #[inline]
    fn pair(&mut self, a: u32, b: u32) {
        self.0.push(if a < b { (a, b) } else { (b, a) });
    }

    fn fork(&self) -> Self {
        PairCollector(Vec::new())
    }

    fn join(&mut self, mut other: Self) {
        self.0.append(&mut other.0);
    }
}

/// Where a run of slots' swept hulls go.
enum HullSink<'a> {
    /// Kept as they are: the cached way refits and tests pairs with them.
    /// Given the slots' fat hulls (`fat` not empty), the slots whose hulls
    /// have left theirs are listed in `left`.
    Keep {
        hulls: &'a mut [SweptBox],
        fat: &'a [SweptBox],
        left: Vec<u32>,
    },
    /// Turned straight into the tree's entries (without spots) over the
    /// grid: the rebuilt way needs nothing else of them.
    Enter(Refill<'a>, Grid, u32),
}

impl<'a> HullSink<'a> {
    fn chunks(self, size: usize) -> Vec<HullSink<'a>> {
        match self {
            HullSink::Keep { hulls, fat, .. } => hulls
                .chunks_mut(size)
                .enumerate()
                .map(|(c, hulls)| {
                    // No fat hulls, or one per slot.
                    let start = c * size;
                    let fat = if fat.is_empty() {
                        fat
                    } else {
                        &fat[start..start + hulls.len()]
                    };
                    HullSink::Keep {
                        hulls,
                        fat,
                        left: Vec::new(),
                    }
                })
                .collect(),
            HullSink::Enter(refill, grid, max_depth) => refill
                .chunks(size)
                .into_iter()
                .map(|run| HullSink::Enter(run, grid, max_depth))
                .collect(),
        }
    }
}

/// Fills one run of slots (numbered from `first`) with the lines `ids`
/// names; returns the union of the hulls of the boxed ones, and the slots
/// a [`HullSink::Keep`] found outside their fat hulls.
fn fill_run(
    first: usize,
    ids: &[u32],
    lines: &[Line],
    slots: &mut [Line],
    mut sink: HullSink<'_>,
    boxed: &mut [bool],
    dt: f64,
) -> (Option<SweptBox>, Vec<u32>) {
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
            match &mut sink {
                HullSink::Keep { hulls, fat, left } => {
                    if let Some(hull) = hull {
                        hulls[k] = hull;
                        // Checked here, while the hull is at hand.
                        if !fat.is_empty() && !holds(&fat[k], &hull) {
                            left.push((first + k) as u32);
                        }
                    }
                }
                HullSink::Enter(refill, grid, max_depth) => {
                    let s = (first + k) as u32;
                    refill.set(k, entry(grid, hull, s, *max_depth, false));
                }
            }
        }
    }
    match sink {
        HullSink::Keep { left, .. } => (bounds, left),
        HullSink::Enter(..) => (bounds, Vec::new()),
    }
}

/// Lines the fill gathers at a time (12 KB of them).
const GATHER: usize = 256;

/// Slot `s`'s tree entry for its hull over `grid`; a slot without one (not
/// boxed) gets a key past every real one, which sorts it last to be cut
/// off.
#[inline]
fn entry(grid: &Grid, hull: Option<SweptBox>, s: u32, max_depth: u32, spots: bool) -> Entry {
    match hull {
        Some(hull) => {
            let cells = grid.cells(&hull, s);
            Entry {
                key: tree::key(&cells, max_depth, spots),
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
    /// most 15, the grid's finest level) stops the splitting, kept from step
    /// to step as `config.tree_mode` says. With `config.threads` above 1 it
    /// splits its work on the current rayon pool, in pieces of at least
    /// `config.grain` lines.
    pub fn new(config: &super::DetectorConfig) -> Self {
        let (leaf_size, max_depth, mode) = (config.leaf_size, config.max_depth, config.tree_mode);
        let (threads, grain) = (config.threads, config.grain);
        Self {
            tree: Tree::new(leaf_size, max_depth),
            mode,
            threads: threads.max(1),
            grain: grain.max(1),
            chooser: Chooser::default(),
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
            hulls: Vec::new(),
            boxed: Vec::new(),
            unboxed: Vec::new(),
            wild: Vec::new(),
            cached_boxed: Vec::new(),
            fat: Vec::new(),
            permutation: Vec::new(),
            probes: Vec::new(),
            reaching: Vec::new(),
            is_moved: Vec::new(),
            moved: Vec::new(),
            pairs: Vec::new(),
            spare_pairs: Vec::new(),
            valid: false,
            stats: DetectorStats::default(),
            clock: None,
        }
    }

    fn parallel(&self) -> bool {
        self.threads > 1
    }

    /// With timing on, adds the time since the last lap to `phase`.
    fn lap(&mut self, phase: Phase) {
        if let Some(clock) = &mut self.clock {
            clock.lap(phase as usize);
        }
    }

    /// Copies the lines into slots in `order` and sorts out the wild and
    /// inert ones; keeps their swept hulls or, if `enter`, makes them the
    /// tree's entries over the current grid (left unsorted). Returns the
    /// union of the hulls. Keeping them while the cache is valid, it lists
    /// the slots that left their fat hulls in `moved`.
    fn fill_slots(&mut self, lines: &[Line], dt: f64, enter: bool) -> Option<SweptBox> {
        let n = lines.len();
        if self.order.len() != n {
            self.order.clear();
            self.order.extend(0..n as u32);
            self.valid = false;
        }
        self.slots.resize(n, Line::default());
        self.boxed.resize(n, false);
        let chunk = self.parallel_chunk(n);
        let sink = if enter {
            // Spots would change the swept hulls' keys too often for the
            // sort.
            self.tree.set_spots(false);
            let max_depth = self.tree.max_depth();
            HullSink::Enter(self.tree.refill_in_place(n), self.grid, max_depth)
        } else {
            self.hulls.resize(n, SweptBox::default());
            let check = self.valid && self.fat.len() == n;
            let mut left = std::mem::take(&mut self.moved);
            left.clear();
            HullSink::Keep {
                hulls: &mut self.hulls,
                fat: if check { &self.fat } else { &[] },
                left,
            }
        };
        let (bounds, left) = if let Some(chunk) = chunk {
            use rayon::prelude::*;
            self.order
                .par_chunks(chunk)
                .zip(self.slots.par_chunks_mut(chunk))
                .zip(sink.chunks(chunk))
                .zip(self.boxed.par_chunks_mut(chunk))
                .enumerate()
                .map(|(c, (((ids, slots), sink), boxed))| {
                    fill_run(c * chunk, ids, lines, slots, sink, boxed, dt)
                })
                .reduce(
                    || (None, Vec::new()),
                    |(a, mut left), (b, mut more)| {
                        left.append(&mut more);
                        (union(a, b), left)
                    },
                )
        } else {
            fill_run(
                0,
                &self.order,
                lines,
                &mut self.slots,
                sink,
                &mut self.boxed,
                dt,
            )
        };
        if !enter {
            self.moved = left;
        }
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
        test_wild(lines, &self.wild, boxed_ids, dt, events, counts);
    }

    /// Sets `order` to the tree's order of the boxed slots, then the others.
    fn reorder(&mut self) {
        // Slot `s` holds line `order[s]`: a small array to read, nearly in
        // order, where the slots themselves would be a large one.
        let parallel = self.parallel_chunk(self.tree.entries.len()).is_some();
        let (order, entries) = (&self.order, &self.tree.entries);
        let id = |e: &Entry| order[e.cells.id as usize];
        let next = &mut self.next_order;
        next.clear();
        if parallel {
            use rayon::prelude::*;
            next.par_extend(entries.par_iter().map(id));
        } else {
            next.extend(entries.iter().map(id));
        }
        next.extend_from_slice(&self.unboxed);
        std::mem::swap(&mut self.order, next);
    }

    /// Fills the tree's entries, in slot order, from the boxed slots' fat
    /// hulls, and sorts them (nearly sorted already when the slots are in
    /// last step's tree order).
    fn set_fat_entries(&mut self) {
        // Spots speed up the cached way's queries.
        self.tree.set_spots(true);
        let (grid, max_depth) = (self.grid, self.tree.max_depth());
        let (fat, boxed) = (&self.fat, &self.boxed);
        // Every slot gets an entry, in place.
        let make = |s: usize| entry(&grid, boxed[s].then(|| fat[s]), s as u32, max_depth, true);
        let n = fat.len();
        let chunk = self.parallel_chunk(n);
        self.tree.refill(n, chunk, make);
        self.tree.entries.truncate(n - self.unboxed.len());
    }

    /// The chunk size to split `n` items' work into, if it is worth
    /// splitting.
    fn parallel_chunk(&self, n: usize) -> Option<usize> {
        (self.parallel() && n >= 2 * self.grain).then_some(self.grain)
    }

    /// Rebuilt mode: builds the tree over this step's swept hulls (whose
    /// union is `bounds`) and tests its pairs.
    fn detect_rebuilt(
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
            self.fill_slots(lines, dt, true);
            self.lap(Phase::Fill);
        }
        let n = self.slots.len();
        self.tree.sort(self.parallel_chunk(n).is_some());
        self.tree.entries.truncate(n - self.unboxed.len());
        self.lap(Phase::Sort);
        let mut collector =
            EventCollector::new(&self.slots, &self.order, dt, std::mem::take(events));
        self.tree.pairs(&mut collector, self.threads, self.grain);
        let found;
        (*events, found) = collector.finish();
        counts.add(&found);
        self.lap(Phase::Walk);
        self.reorder();
        self.lap(Phase::Reorder);
    }

    /// Cached mode: brings the tree and the pairs up to date with this
    /// step's slots (whose hulls' union is `bounds`), then tests the pairs
    /// whose swept hulls overlap.
    fn detect_cached(
        &mut self,
        lines: &[Line],
        bounds: Option<SweptBox>,
        dt: f64,
        events: &mut Vec<Event>,
        counts: &mut PairCounts,
    ) {
        let n = self.slots.len();
        self.valid &= self.cached_boxed == self.boxed;
        if self.valid {
            // The fill has listed the slots that left their fat hulls.
            self.valid = self.moved.len() <= n / REBUILD_SHARE;
        } else {
            self.moved.clear();
        }
        if self.valid {
            for &m in &self.moved {
                let m = m as usize;
                self.fat[m] = fatten(&self.hulls[m], &self.slots[m], dt);
            }
            let grid = self.grid;
            self.valid = self
                .moved
                .iter()
                .all(|&m| grid.holds(&self.fat[m as usize]));
        }
        if self.valid {
            self.stats.refits += self.moved.len() as u64;
            self.update_cache();
            self.lap(Phase::Upkeep);
        } else if let Some(bounds) = bounds {
            self.lap(Phase::Upkeep);
            self.stats.rebuilds += 1;
            self.rebuild_cache(lines, dt, bounds);
            self.lap(Phase::Rebuild);
        } else {
            self.pairs.clear();
        }
        counts.candidates += self.pairs.len() as u64;
        self.test_cached_pairs(dt, events, counts);
        self.lap(Phase::Tests);
    }

    /// Tests the cached pairs whose swept hulls overlap (in parallel runs
    /// merged in order, if there are many).
    fn test_cached_pairs(&self, dt: f64, events: &mut Vec<Event>, counts: &mut PairCounts) {
        let (hulls, slots, ids) = (&self.hulls, &self.slots, &self.order);
        let test = |pairs: &[(u32, u32)], events: &mut Vec<Event>, counts: &mut PairCounts| {
            for &(a, b) in pairs {
                let (a, b) = (a as usize, b as usize);
                if hulls[a].overlaps(&hulls[b]) {
                    test_pair((&slots[a], ids[a]), (&slots[b], ids[b]), dt, events, counts);
                }
            }
        };
        let chunk = 2 * self.grain;
        if self.parallel() && self.pairs.len() >= 2 * chunk {
            use rayon::prelude::*;
            let runs: Vec<(Vec<Event>, PairCounts)> = self
                .pairs
                .par_chunks(chunk)
                .map(|run| {
                    let (mut events, mut counts) = (Vec::new(), PairCounts::default());
                    test(run, &mut events, &mut counts);
                    (events, counts)
                })
                .collect();
            for (mut run_events, run_counts) in runs {
                events.append(&mut run_events);
                counts.add(&run_counts);
            }
        } else {
            test(&self.pairs, events, counts);
        }
    }

    /// Rebuilds the cache: builds the tree over the fat hulls and takes all
    /// its pairs, first putting the slots in the tree's order (for
    /// locality) unless they nearly are already.
    fn rebuild_cache(&mut self, lines: &[Line], dt: f64, bounds: SweptBox) {
        self.fat_hulls(dt, bounds);
        self.set_fat_entries();
        let entries = &self.tree.entries;
        let out_of_order = entries
            .windows(2)
            .filter(|w| w[1].cells.id < w[0].cells.id)
            .count();
        if out_of_order > entries.len() / SLOTS_ASTRAY {
            self.reorder();
            if self.slots.len() <= PERMUTE_MAX {
                self.permute_slots();
            } else {
                let bounds = self
                    .fill_slots(lines, dt, false)
                    .expect("the same lines are boxed");
                self.fat_hulls(dt, bounds);
                self.set_fat_entries();
            }
        }
        let mut collector = PairCollector(std::mem::take(&mut self.pairs));
        collector.0.clear();
        self.tree.pairs(&mut collector, self.threads, self.grain);
        self.pairs = collector.0;
        self.is_moved.clear();
        self.is_moved.resize(self.slots.len(), false);
        self.cached_boxed.clone_from(&self.boxed);
        self.valid = true;
    }

    /// Moves the slots (lines, hulls, fat hulls, `boxed`) into the order
    /// [`Quadtree::reorder`] gave `order`: the tree's entries' slots in key
    /// order, then the unboxed ones; the entries, already sorted, are
    /// renumbered to match. Each slot moves along the cycles of the
    /// permutation, so no second copy of the arrays is needed.
    fn permute_slots(&mut self) {
        const DONE: u32 = u32::MAX;
        let n = self.slots.len();
        // Slot `k` takes what slot `from[k]` holds now.
        let from = &mut self.permutation;
        from.clear();
        from.extend(self.tree.entries.iter().map(|e| e.cells.id));
        from.extend((0..n as u32).filter(|&s| !self.boxed[s as usize]));
        debug_assert_eq!(from.len(), n);
        let (slots, hulls, fat, boxed) = (
            &mut self.slots,
            &mut self.hulls,
            &mut self.fat,
            &mut self.boxed,
        );
        for start in 0..n {
            if from[start] == DONE {
                continue;
            }
            let held = (slots[start], hulls[start], fat[start], boxed[start]);
            let mut k = start;
            loop {
                let s = std::mem::replace(&mut from[k], DONE) as usize;
                if s == start {
                    (slots[k], hulls[k], fat[k], boxed[k]) = held;
                    break;
                }
                (slots[k], hulls[k], fat[k], boxed[k]) = (slots[s], hulls[s], fat[s], boxed[s]);
                k = s;
            }
        }
        for (k, e) in self.tree.entries.iter_mut().enumerate() {
            e.cells.id = k as u32;
        }
    }

    /// Fresh fat hulls for every boxed slot, growing the grid if they leave
    /// it.
    fn fat_hulls(&mut self, dt: f64, mut bounds: SweptBox) {
        let (hulls, slots, boxed) = (&self.hulls, &self.slots, &self.boxed);
        self.fat.clear();
        self.fat
            .extend(hulls.iter().zip(slots).map(|(h, s)| fatten(h, s, dt)));
        for (f, &b) in self.fat.iter().zip(boxed) {
            if b {
                bounds = bounds.union(f);
            }
        }
        if !self.grid.holds(&bounds) {
            self.grid = Grid::over(&bounds);
        }
    }

    /// Moves the slots that left their fat hulls (their new fat hulls are
    /// set): new cells and keys, their old pairs out, their new pairs in.
    fn update_cache(&mut self) {
        if self.moved.is_empty() {
            return;
        }
        for &m in &self.moved {
            self.is_moved[m as usize] = true;
        }
        let parallel = self.parallel_chunk(self.slots.len()).is_some();
        let (grid, fat, is_moved) = (self.grid, &self.fat, &self.is_moved);
        let max_depth = self.tree.max_depth();
        let refit = |e: &mut Entry| {
            let s = e.cells.id;
            is_moved[s as usize] && {
                e.cells = grid.cells(&fat[s as usize], s);
                let key = tree::key(&e.cells, max_depth, true);
                std::mem::replace(&mut e.key, key) != key
            }
        };
        let kept = |&(a, b): &(u32, u32)| !is_moved[a as usize] && !is_moved[b as usize];
        // The new pairs of the moved slots `run`, from one walk of the tree
        // for all their queries (a pair of two moved slots is taken from the
        // lower one's query).
        let new_pairs = |tree: &Tree,
                         run: &[u32],
                         probes: &mut Vec<Cells>,
                         reaching: &mut Vec<u32>,
                         out: &mut Vec<(u32, u32)>| {
            probes.clear();
            probes.extend(run.iter().map(|&m| grid.cells(&fat[m as usize], m)));
            tree.query_many(probes, reaching, |p, j| {
                let m = run[p];
                if j != m && (!is_moved[j as usize] || j > m) {
                    out.push(if m < j { (m, j) } else { (j, m) });
                }
            })
        };
        if parallel {
            use rayon::prelude::*;
            self.tree.refit(true, refit);
            let mut spare = std::mem::take(&mut self.spare_pairs);
            spare.clear();
            spare.par_extend(self.pairs.par_iter().copied().filter(kept));
            std::mem::swap(&mut self.pairs, &mut spare);
            self.spare_pairs = spare;
            let tree = &self.tree;
            let found: Vec<(Vec<(u32, u32)>, tree::WalkCounts)> = self
                .moved
                .par_chunks(QUERIES_PER_TASK)
                .map(|run| {
                    let mut out = Vec::new();
                    let counts = new_pairs(tree, run, &mut Vec::new(), &mut Vec::new(), &mut out);
                    (out, counts)
                })
                .collect();
            for (mut pairs, counts) in found {
                self.pairs.append(&mut pairs);
                self.tree.count(&counts);
            }
        } else {
            let fresh = self
                .moved
                .iter()
                .map(|&m| entry(&grid, Some(fat[m as usize]), m, max_depth, true));
            self.tree.replace(is_moved, fresh);
            self.pairs.retain(kept);
            let counts = new_pairs(
                &self.tree,
                &self.moved,
                &mut self.probes,
                &mut self.reaching,
                &mut self.pairs,
            );
            self.tree.count(&counts);
        }
        for &m in &self.moved {
            self.is_moved[m as usize] = false;
        }
    }
}

impl Detector for Quadtree {
    fn name(&self) -> &'static str {
        "quadtree"
    }

    fn detect(&mut self, lines: &[Line], dt: f64, events: &mut Vec<Event>) {
        let before = events.len();
        let start = Instant::now();
        let rebuilt = match self.mode {
            TreeMode::Auto => self.chooser.rebuilt_now(),
            TreeMode::Cached => false,
            TreeMode::Rebuilt => true,
        };
        let mut counts = PairCounts::default();
        self.tree.counts = tree::WalkCounts::default();
        if let Some(clock) = &mut self.clock {
            clock.start(start);
        }
        let bounds = self.fill_slots(lines, dt, rebuilt);
        self.test_wild(lines, dt, events, &mut counts);
        self.lap(Phase::Fill);
        if rebuilt {
            // The tree will hold swept hulls and the slots another order:
            // the cache must be rebuilt before it is used again.
            self.valid = false;
            self.detect_rebuilt(lines, bounds, dt, events, &mut counts);
        } else {
            self.detect_cached(lines, bounds, dt, events, &mut counts);
        }
        if self.mode == TreeMode::Auto {
            self.chooser.record(start.elapsed().as_secs_f64());
        }
        let walk = self.tree.counts;
        self.stats.candidate_pairs += counts.candidates + walk.candidates;
        self.stats.exact_tests += counts.exact;
        self.stats.nodes += walk.nodes;
        self.stats.max_depth = self.stats.max_depth.max(walk.deepest);
        self.stats.events += (events.len() - before) as u64;
        self.stats.rebuilt_steps += u64::from(rebuilt);
    }

    fn stats(&self) -> DetectorStats {
        self.stats
    }

    fn set_timing(&mut self, on: bool) {
        self.clock = on.then(Clock::new);
    }

    fn phase_times(&self) -> Vec<(&'static str, Duration)> {
        Clock::report_of(self.clock.as_ref(), Phase::ALL.map(Phase::name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Runs `steps` steps of a chooser where a rebuilt step takes
    /// `rebuilt` seconds and a cached one `cached`; returns the ways used.
    fn run(c: &mut Chooser, steps: u64, rebuilt: f64, cached: f64) -> Vec<bool> {
        (0..steps)
            .map(|_| {
                let way = c.rebuilt_now();
                c.record(if way { rebuilt } else { cached });
                way
            })
            .collect()
    }

    #[test]
    fn the_chooser_tries_the_other_way_then_keeps_the_faster() {
        let mut c = Chooser::default();
        // A short rebuilt stint, then a full cached trial, which wins.
        let ways = run(&mut c, FIRST_STINT + TRIAL, 2.0, 1.0);
        assert!(ways[..FIRST_STINT as usize].iter().all(|&r| r));
        assert!(ways[FIRST_STINT as usize..].iter().all(|&r| !r));
        assert!(!c.prefer_rebuilt);
        // Now rebuilt is the trial, once a period, and it keeps losing.
        let ways = run(&mut c, PERIOD, 2.0, 1.0);
        let trial = PERIOD - TRIAL;
        assert!(ways[..trial as usize].iter().all(|&r| !r));
        // Twice as slow: it gives up after its warm-up and one timed step.
        let tried = ways[trial as usize..].iter().take_while(|&&r| r).count() as u64;
        assert_eq!(tried, WARM_UP + 1);
        assert!(!c.prefer_rebuilt);
        // A near tie does not switch.
        run(&mut c, 2 * PERIOD, 0.98, 1.0);
        assert!(!c.prefer_rebuilt);
        // A clear win does.
        run(&mut c, 2 * PERIOD, 0.5, 1.0);
        assert!(c.prefer_rebuilt);
    }

    #[test]
    fn a_trial_behind_gives_up_once_it_stops_gaining() {
        // A dear first step, two cheap ones, then as slow as the stint:
        // given up on the second slow step (the two latest are judged).
        let mut c = Chooser::default();
        run(&mut c, FIRST_STINT, 1.0, 1.0);
        for (k, t) in [5.0, 0.5, 0.5, 1.0, 1.0].into_iter().enumerate() {
            assert!(!c.rebuilt_now(), "still trying at step {k}");
            c.record(t);
        }
        assert!(c.rebuilt_now());
        assert!(c.prefer_rebuilt);

        // The same start with cheap steps after it wins the trial.
        let mut c = Chooser::default();
        run(&mut c, FIRST_STINT, 1.0, 1.0);
        c.record(5.0);
        let ways = run(&mut c, TRIAL - 1, 1.0, 0.5);
        assert!(ways.iter().all(|&r| !r));
        assert!(!c.prefer_rebuilt);

        // One slow step among cheap ones does not end it.
        let mut c = Chooser::default();
        run(&mut c, FIRST_STINT, 1.0, 1.0);
        for t in [5.0, 0.5, 0.5, 2.0, 0.5] {
            c.record(t);
        }
        assert!(!c.rebuilt_now());
    }

    #[test]
    fn mode_names_round_trip() {
        for &m in TreeMode::ALL {
            assert_eq!(m.name().parse::<TreeMode>(), Ok(m));
        }
        assert!("sometimes"
            .parse::<TreeMode>()
            .unwrap_err()
            .contains("auto"));
    }
}
