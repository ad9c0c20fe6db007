//! The quadtree as one sorted array, and the walks over it.
//!
//! The tree is the design write-up's: the root covers every line's hull; a
//! node holding more than `leaf_size` lines, and shallower than
//! `max_depth`, splits its region into four quadrants; a line whose hull
//! fits in one quadrant goes down to it, the others stay at the node as
//! *misfits*. A node's misfits are paired with each other and with every
//! line below the node; a leaf pairs its own lines. Each pair comes up
//! once, at the deepest node holding both lines.
//!
//! How it is kept is what makes it fast:
//! - Hulls are quantised to a grid of `2^15 x 2^15` cells over the root, a
//!   square centred on the box that grows (by doubling) only when lines
//!   leave it, so that cells stay put from step to step. The deepest
//!   quadrant holding a hull whole is where its corner cells' coordinates
//!   stop sharing leading bits, so a line's node is known without
//!   descending, and its Morton key (the node's cell interleaved, then the
//!   level) puts every node's misfits first and its subtree right after, in
//!   one sorted array.
//! - Lines hardly move in a step, so last step's order is nearly sorted:
//!   an insertion sort fixes it in close to linear time (falling back to a
//!   full sort when lines jump far).
//! - A node finds its children's runs by binary search over the keys, and
//!   the misfits from above travel down as an *active list* that each child
//!   filters by its cell block, so a misfit meets only the quadrants its
//!   hull reaches.
//! - Quantisation is monotone, so hulls that overlap still overlap in
//!   cells: every test on cells is conservative, with no rounding questions.
//!   Cells cover the window's diagonals as well as the axes.

use crate::detect::swept::{SweptBox, DIAGONAL_X, DIAGONAL_Y};
use crate::line::{BOX_MAX, BOX_MIN};

/// Levels of the quantisation grid: the deepest a tree can go.
pub const GRID_LEVELS: u32 = 15;
/// The last cell along any direction.
const CELL_MAX: u16 = (1 << GRID_LEVELS) - 1;

const LEVEL_BITS: u32 = 5;
const LEVEL_MASK: u64 = (1 << LEVEL_BITS) - 1;
/// A line's swept hull in finest-level grid cells (inclusive), along the
/// axes and the diagonals, with its id. Lowest cells come first, then
/// highest, each four in the order `x`, `y`, `u`, `w`, so that each group
/// reads as one `u64` of four 16-bit lanes (see [`Cells::overlaps`]). Every
/// cell is below `2^15`, as [`Grid::cells`] makes them: the overlap test
/// relies on it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(C)]
pub struct Cells {
    pub x0: u16,
    pub y0: u16,
    pub u0: u16,
    pub w0: u16,
    pub x1: u16,
    pub y1: u16,
    pub u1: u16,
    pub w1: u16,
    /// The line's id.
    pub id: u32,
}

/// The top bit of each 16-bit lane.
const LANE_TOPS: u64 = 0x8000_8000_8000_8000;

/// Four cells packed as 16-bit lanes of one `u64`, the first lowest.
#[inline]
fn lanes(cells: [u16; 4]) -> u64 {
    cells
        .iter()
        .rev()
        .fold(0, |packed, &c| packed << 16 | u64::from(c))
}

impl Cells {
    /// The lowest cells as four 16-bit lanes, `x` lowest.
    #[inline]
    fn lows(&self) -> u64 {
        lanes([self.x0, self.y0, self.u0, self.w0])
    }

    /// The highest cells as four 16-bit lanes, `x` lowest.
    #[inline]
    fn highs(&self) -> u64 {
        lanes([self.x1, self.y1, self.u1, self.w1])
    }

    /// True when the two overlap in all four directions. All four lanes at
    /// once: cells are below `2^15`, so in each lane `high + 2^15 - low`
    /// lies in `1..2^16` (no borrow crosses lanes) and keeps its top bit
    /// exactly when `low <= high`.
    #[inline]
    pub fn overlaps(&self, o: &Cells) -> bool {
        debug_assert_eq!(
            (self.lows() | self.highs() | o.lows() | o.highs()) & LANE_TOPS,
            0
        );
        let ahead = (o.highs() | LANE_TOPS) - self.lows();
        let behind = (self.highs() | LANE_TOPS) - o.lows();
        ahead & behind & LANE_TOPS == LANE_TOPS
    }

    /// The smallest cells holding both (no id).
    #[inline]
    fn union(&self, o: &Cells) -> Cells {
        Cells {
            x0: self.x0.min(o.x0),
            y0: self.y0.min(o.y0),
            u0: self.u0.min(o.u0),
            w0: self.w0.min(o.w0),
            x1: self.x1.max(o.x1),
            y1: self.y1.max(o.y1),
            u1: self.u1.max(o.u1),
            w1: self.w1.max(o.w1),
            id: 0,
        }
    }

    #[inline]
    fn overlaps_block(&self, b: &Block) -> bool {
        // As in `overlaps`: one branch on the result, not four.
        (u32::from(self.x0) <= b.x_last())
            & (b.x0 <= u32::from(self.x1))
            & (u32::from(self.y0) <= b.y_last())
            & (b.y0 <= u32::from(self.y1))
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Entry {
    /// Morton key of the line's node, then its level.
    pub key: u64,
    /// The line's cells.
    pub cells: Cells,
}

impl Entry {
    #[inline]
    fn level(&self) -> u32 {
        (self.key & LEVEL_MASK) as u32
    }
}

/// The finest-level cells a node covers: `size x size` from `(x0, y0)`.
#[derive(Clone, Copy, Debug)]
struct Block {
    x0: u32,
    y0: u32,
    size: u32,
}

impl Block {
    fn x_last(&self) -> u32 {
        self.x0 + self.size - 1
    }
    fn y_last(&self) -> u32 {
        self.y0 + self.size - 1
    }
    fn child(&self, c: usize) -> Block {
        let half = self.size / 2;
        Block {
            x0: self.x0 + if c & 1 == 1 { half } else { 0 },
            y0: self.y0 + if c & 2 == 2 { half } else { 0 },
            size: half,
        }
    }
}

/// Spreads the 16 bits of `v` to the even bits of a `u32`.
#[inline]
fn spread(v: u16) -> u32 {
    let mut x = u32::from(v);
    x = (x | (x << 8)) & 0x00ff_00ff;
    x = (x | (x << 4)) & 0x0f0f_0f0f;
    x = (x | (x << 2)) & 0x3333_3333;
    x = (x | (x << 1)) & 0x5555_5555;
    x
}

/// Maps coordinates onto the grid; monotone, so overlaps are preserved.
/// The diagonals span `(1180 + 800)` times the square's side and are
/// scaled to the same number of cells.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    min: f64,
    side: f64,
    /// Where cell 0 starts along `x`, `y`, `u` and `w`.
    origin: [f64; 4],
    /// Cells per unit along `x`, `y`, `u` and `w`.
    scale: [f64; 4],
}

impl Grid {
    /// The grid over the smallest square of a fixed family holding
    /// `bounds`: centred on the box, a little larger than it, doubling as
    /// needed. Fixed squares keep keys stable from step to step (so last
    /// step's order is nearly sorted), whereas a root fitted to the bounds
    /// would move every cell boundary whenever any line moved.
    pub fn over(bounds: &SweptBox) -> Self {
        const CENTRE: f64 = (BOX_MIN + BOX_MAX) / 2.0;
        let reach = (CENTRE - bounds.min_x)
            .max(bounds.max_x - CENTRE)
            .max(CENTRE - bounds.min_y)
            .max(bounds.max_y - CENTRE);
        let mut half = (BOX_MAX - BOX_MIN) / 2.0 * (1.0 + 1.0 / 16.0);
        while half < reach {
            half *= 2.0;
        }
        let (min, side) = (CENTRE - half, 2.0 * half);
        let scale = f64::from(1u32 << GRID_LEVELS) / side;
        let (wx, wy) = (DIAGONAL_X, DIAGONAL_Y);
        // The diagonals span (wx + wy) times the square's side.
        let (min_u, min_w) = (min * (wx + wy), min * wx - (min + side) * wy);
        let diagonal_scale = scale / (wx + wy);
        Grid {
            min,
            side,
            origin: [min, min, min_u, min_w],
            scale: [scale, scale, diagonal_scale, diagonal_scale],
        }
    }

    /// True when `bounds` lies within the grid's square.
    pub fn holds(&self, bounds: &SweptBox) -> bool {
        let max = self.min + self.side;
        bounds.min_x >= self.min
            && bounds.min_y >= self.min
            && bounds.max_x <= max
            && bounds.max_y <= max
    }

    /// The cell of `v` along direction `k`: the nearest, clamped to the
    /// grid (NaN goes to 0). Any monotone rounding keeps the cells'
    /// overlaps conservative; rounding by adding `2^52`, whose last
    /// mantissa bits then hold the result, takes no saturating cast.
    #[inline]
    fn cell(&self, v: f64, k: usize) -> u16 {
        const ROUNDER: f64 = (1u64 << 52) as f64;
        let c = (v - self.origin[k]) * self.scale[k];
        let c = if c > 0.0 { c } else { 0.0 };
        let c = if c < f64::from(CELL_MAX) {
            c
        } else {
            f64::from(CELL_MAX)
        };
        (c + ROUNDER).to_bits() as u16
    }

    /// `b`'s cells, for the line `id`.
    #[inline]
    pub fn cells(&self, b: &SweptBox, id: u32) -> Cells {
        Cells {
            x0: self.cell(b.min_x, 0),
            y0: self.cell(b.min_y, 1),
            u0: self.cell(b.min_u, 2),
            w0: self.cell(b.min_w, 3),
            x1: self.cell(b.max_x, 0),
            y1: self.cell(b.max_y, 1),
            u1: self.cell(b.max_u, 2),
            w1: self.cell(b.max_w, 3),
            id,
        }
    }
}

/// The sort key of a line: its node's cell (Morton order), then its
/// level.
#[inline]
pub fn key(c: &Cells, max_depth: u32) -> u64 {
    let differ = u32::from((c.x0 ^ c.x1) | (c.y0 ^ c.y1));
    let fits = GRID_LEVELS - (u32::BITS - differ.leading_zeros());
    let level = fits.min(max_depth);
    let keep = !((1u32 << (GRID_LEVELS - level)) - 1) as u16;
    let morton = spread(c.x0 & keep) | (spread(c.y0 & keep) << 1);
    (u64::from(morton) << LEVEL_BITS) | u64::from(level)
}

/// Sorts entries by key by insertion, fast when they are nearly sorted
/// already. Gives up, returning false with the entries in some order, once
/// too many have had to move far; the caller then sorts in full.
pub fn sort_nearly_sorted(entries: &mut [Entry]) -> bool {
    let mut budget = 8 * entries.len() + 64;
    for i in 1..entries.len() {
        let e = entries[i];
        let mut j = i;
        while j > 0 && entries[j - 1].key > e.key {
            entries[j] = entries[j - 1];
            j -= 1;
        }
        entries[j] = e;
        budget = budget.saturating_sub(i - j);
        if budget == 0 {
            return false;
        }
    }
    true
}

/// One task's share of a sort: the entries it keeps in place (in order),
/// and those it moves aside.
#[derive(Debug, Default)]
struct SortRun {
    kept: Vec<Entry>,
    movers: Vec<Entry>,
}

/// Merges `kept` and `movers`, both sorted, into `out`, which is as long
/// as both. Movers are few, so the kept entries between them are copied
/// in blocks.
fn merge_into(mut kept: &[Entry], movers: &[Entry], mut out: &mut [Entry]) {
    for m in movers {
        let below = kept.iter().take_while(|e| e.key <= m.key).count();
        let (block, rest) = std::mem::take(&mut out).split_at_mut(below + 1);
        block[..below].copy_from_slice(&kept[..below]);
        block[below] = *m;
        kept = &kept[below..];
        out = rest;
    }
    out.copy_from_slice(kept);
}

/// Where a walk's pairs go. Parallel walks give each task a fresh
/// collector ([`Collector::fork`]) and merge them back in tree order
/// ([`Collector::join`]), so the merged result does not depend on how the
/// work was split.
pub trait Collector: Send + Sized {
    /// Takes a pair of lines whose cells overlap.
    fn pair(&mut self, a: u32, b: u32);
    /// An empty collector for a task of a parallel walk.
    fn fork(&self) -> Self;
    /// Takes in what a task collected.
    fn join(&mut self, other: Self);
}

/// A line in a sweep: its interval on the sweep axis, whether it belongs to
/// the node (rather than to the active list), and its cells.
#[derive(Clone, Copy, Debug)]
struct Probe {
    lo: u16,
    hi: u16,
    own: bool,
    cells: Cells,
}

/// One of the four directions of the cells: a line's interval on it.
type Axis = fn(&Cells) -> (u16, u16);

/// Up to this many descents, [`Tree::sort`] tries insertion first.
const INSERTION_MAX: usize = 64;

/// Below this many lines in a node's pair set, plain loops beat sorting.
const SWEEP_MIN: usize = 48;

/// In the pairs walk, runs of up to this many entries are split by reading
/// them in order, not by binary search: a scan reads ahead (and the walk
/// goes on to read every entry of the run anyway, which the scan has
/// brought into the cache), where a search waits on one cache miss after
/// another. Queries, which read only the few children their probe reaches,
/// always search.
const SCAN_MAX: usize = 256;

/// What the walks have done, summed until reset.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WalkCounts {
    /// Pairs of lines the walks were responsible for (before any test).
    pub candidates: u64,
    /// Tree nodes visited.
    pub nodes: u64,
    /// Deepest level visited.
    pub deepest: u32,
}

impl WalkCounts {
    /// Adds another tally to this one.
    pub fn add(&mut self, other: &WalkCounts) {
        self.candidates += other.candidates;
        self.nodes += other.nodes;
        self.deepest = self.deepest.max(other.deepest);
    }
}

/// The buffers of one task of a walk.
#[derive(Debug, Default)]
struct Scratch {
    active: Vec<Cells>,
    /// The active lines that reach a node's own lines.
    near: Vec<Cells>,
    sweep: Vec<Probe>,
    counts: WalkCounts,
}

/// The quadtree over a set of lines: their entries in key order and the
/// buffers of the walks, reused from call to call.
#[derive(Debug)]
pub struct Tree {
    leaf_size: usize,
    max_depth: u32,
    /// The lines' entries; [`Tree::sort`] puts them in key order.
    pub entries: Vec<Entry>,
    /// Whether each entry's key may differ from that of the entry at its
    /// place when the entries were last sorted (see [`Tree::refill`]).
    changed: Vec<bool>,
    /// Buffers of [`Tree::sort`].
    runs: Vec<SortRun>,
    movers: Vec<Entry>,
    scratch: Scratch,
    /// What the walks have done.
    pub counts: WalkCounts,
}

/// A run of a tree's entries being set in place before a sort, each one
/// flagged if its key is not the one at its place before (which the sort
/// uses to keep the others where they are).
pub struct Refill<'a> {
    entries: &'a mut [Entry],
    changed: &'a mut [bool],
    /// Entries from this index on are new: they had no place before.
    old: usize,
}

impl<'a> Refill<'a> {
    /// Sets the run's `k`-th entry.
    #[inline]
    pub fn set(&mut self, k: usize, entry: Entry) {
        self.changed[k] = k >= self.old || entry.key != self.entries[k].key;
        self.entries[k] = entry;
    }

    /// Splits the run into runs of `size` entries (the last one shorter).
    pub fn chunks(self, size: usize) -> Vec<Refill<'a>> {
        let size = size.max(1);
        self.entries
            .chunks_mut(size)
            .zip(self.changed.chunks_mut(size))
            .enumerate()
            .map(|(c, (entries, changed))| Refill {
                entries,
                changed,
                old: self.old.saturating_sub(c * size),
            })
            .collect()
    }
}

/// A walk's fixed settings, shared by its tasks.
struct Walk<'t> {
    entries: &'t [Entry],
    leaf_size: usize,
    max_depth: u32,
    /// Subtrees of at least this many lines are split among threads; zero
    /// for a serial walk.
    parallel_min: usize,
    /// Runs up to this long are split by scanning (see [`SCAN_MAX`]).
    scan_max: usize,
}

impl Tree {
    /// An empty tree whose leaves hold at most `leaf_size` lines (at least
    /// 1) unless `max_depth` (at most [`GRID_LEVELS`]) stops the splitting.
    pub fn new(leaf_size: usize, max_depth: u32) -> Self {
        Self {
            leaf_size: leaf_size.max(1),
            max_depth: max_depth.min(GRID_LEVELS),
            entries: Vec::new(),
            changed: Vec::new(),
            runs: Vec::new(),
            movers: Vec::new(),
            scratch: Scratch::default(),
            counts: WalkCounts::default(),
        }
    }

    /// The depth limit in force.
    pub fn max_depth(&self) -> u32 {
        self.max_depth
    }

    /// The `n` entries, to be set one by one in place (all of them) before
    /// [`Tree::sort`]; for callers that make entries alongside other work.
    /// [`Tree::refill`] does both steps for entries made on their own.
    pub fn refill_in_place(&mut self, n: usize) -> Refill<'_> {
        let old = self.entries.len();
        self.entries.resize(n, Entry::default());
        self.changed.resize(n, true);
        Refill {
            entries: &mut self.entries,
            changed: &mut self.changed,
            old,
        }
    }

    /// Puts the entries in key order. Most lines keep their key from one
    /// step to the next, so the entries are mostly in order already: with
    /// few out of place they are fixed by insertion; with more, the ones out
    /// of place are taken out, sorted on their own and merged back, in time
    /// close to linear; only a scramble gets a full sort (on all threads,
    /// if `parallel`).
    pub fn sort(&mut self, parallel: bool) {
        let n = self.entries.len();
        let descent = |w: &[Entry]| w[1].key < w[0].key;
        let descents = if parallel {
            use rayon::prelude::*;
            self.entries.par_windows(2).filter(|w| descent(w)).count()
        } else {
            self.entries.windows(2).filter(|w| descent(w)).count()
        };
        if descents == 0 {
            return;
        }
        if descents <= INSERTION_MAX && sort_nearly_sorted(&mut self.entries) {
            return;
        }
        if descents <= n / 8 {
            self.merge_out_of_place(parallel);
            return;
        }
        if parallel {
            use rayon::slice::ParallelSliceMut;
            self.entries.par_sort_unstable_by_key(|e| e.key);
        } else {
            radsort::sort_by_key(&mut self.entries, |e| e.key);
        }
    }

    /// Takes the entries out of place out of the way, sorts them and merges
    /// them back. Each run of entries (one per task) keeps an ascending
    /// subsequence of its unchanged entries (see [`Tree::refill`]; when the
    /// changes are not known, of those not above their successor), and
    /// moves the rest aside; then each run drops the head of its kept
    /// entries that is below the previous run's last, so that the kept
    /// entries of all runs, in turn, are in order. The entries moved aside
    /// are sorted and merged with the kept ones, each run's part on its own.
    fn merge_out_of_place(&mut self, parallel: bool) {
        let n = self.entries.len();
        let tasks = if parallel {
            4 * rayon::current_num_threads()
        } else {
            1
        };
        let chunk = n.div_ceil(tasks).max(1);
        let runs = n.div_ceil(chunk);
        self.runs.resize_with(runs, SortRun::default);
        let (entries, changed) = (&self.entries, &self.changed);
        let known = changed.len() == n;
        let split = |first: usize, part: &[Entry], run: &mut SortRun| {
            run.kept.clear();
            run.movers.clear();
            let mut last = 0;
            for (k, e) in part.iter().enumerate() {
                let i = first + k;
                let stays = if known {
                    !changed[i]
                } else {
                    entries.get(i + 1).is_none_or(|next| e.key <= next.key)
                };
                if stays && e.key >= last {
                    run.kept.push(*e);
                    last = e.key;
                } else {
                    run.movers.push(*e);
                }
            }
        };
        let runs = &mut self.runs[..runs];
        if parallel {
            use rayon::prelude::*;
            entries
                .par_chunks(chunk)
                .zip(runs.par_iter_mut())
                .enumerate()
                .for_each(|(c, (part, run))| split(c * chunk, part, run));
        } else {
            for (c, (part, run)) in entries.chunks(chunk).zip(runs.iter_mut()).enumerate() {
                split(c * chunk, part, run);
            }
        }

        // Join the runs' kept entries into one ascending sequence, and
        // gather everything else.
        let movers = &mut self.movers;
        movers.clear();
        let mut last = 0;
        for run in runs.iter_mut() {
            let below = run.kept.partition_point(|e| e.key < last);
            movers.extend(run.kept.drain(..below));
            movers.extend_from_slice(&run.movers);
            if let Some(e) = run.kept.last() {
                last = e.key;
            }
        }
        if parallel {
            use rayon::slice::ParallelSliceMut;
            movers.par_sort_unstable_by_key(|e| e.key);
        } else {
            radsort::sort_by_key(movers, |e| e.key);
        }

        // Each run's part of the output: its kept entries and the movers
        // below the next run's first kept entry.
        let mut parts: Vec<(&[Entry], &[Entry], &mut [Entry])> = Vec::with_capacity(runs.len());
        let mut out: &mut [Entry] = &mut self.entries;
        let mut rest: &[Entry] = movers;
        let nonempty: Vec<&SortRun> = runs.iter().filter(|r| !r.kept.is_empty()).collect();
        for (k, run) in nonempty.iter().enumerate() {
            let take = match nonempty.get(k + 1) {
                Some(next) => rest.partition_point(|m| m.key < next.kept[0].key),
                None => rest.len(),
            };
            let (mine, later) = rest.split_at(take);
            let (part, tail) = std::mem::take(&mut out).split_at_mut(run.kept.len() + take);
            parts.push((&run.kept, mine, part));
            rest = later;
            out = tail;
        }
        if nonempty.is_empty() {
            out.copy_from_slice(rest);
        }
        let merge =
            |(kept, movers, out): (&[Entry], &[Entry], &mut [Entry])| merge_into(kept, movers, out);
        if parallel {
            use rayon::prelude::*;
            parts.into_par_iter().for_each(merge);
        } else {
            parts.into_iter().for_each(merge);
        }
    }

    fn root() -> Block {
        Block {
            x0: 0,
            y0: 0,
            size: 1 << GRID_LEVELS,
        }
    }

    /// Hands `collector` once every pair of lines whose cells overlap
    /// (entries must be sorted). With `threads` above 1 and at least `grain`
    /// lines, subtrees are walked in parallel on the current rayon pool,
    /// none smaller than `grain / 16` lines.
    pub fn pairs<C: Collector>(&mut self, collector: &mut C, threads: usize, grain: usize) {
        let n = self.entries.len();
        if n == 0 {
            return;
        }
        let walk = Walk {
            entries: &self.entries,
            leaf_size: self.leaf_size,
            max_depth: self.max_depth,
            // Enough tasks to balance the threads, none too small to pay;
            // a tree of less than a grain of lines stays on one thread
            // (measured: a walk of 4,000 or 10,000 lines split four ways
            // lost more to waking the pool than it gained).
            parallel_min: if threads > 1 && n >= grain {
                (n / (8 * threads)).max(grain / 16).max(1)
            } else {
                0
            },
            scan_max: SCAN_MAX,
        };
        self.scratch.active.clear();
        self.scratch.counts = WalkCounts::default();
        walk.visit(&mut self.scratch, collector, 0, n, 0, Self::root(), 0);
        self.counts.add(&self.scratch.counts);
    }
}

impl Walk<'_> {
    /// Visits the node at `level` covering `block`, whose subtree is
    /// `entries[lo..hi]`; the misfits from above that reach it are
    /// `scratch.active[active_lo..]`.
    #[allow(clippy::too_many_arguments)]
    fn visit<C: Collector>(
        &self,
        scratch: &mut Scratch,
        collector: &mut C,
        lo: usize,
        hi: usize,
        level: u32,
        block: Block,
        active_lo: usize,
    ) {
        scratch.counts.nodes += 1;
        scratch.counts.deepest = scratch.counts.deepest.max(level);
        if hi - lo <= self.leaf_size || level >= self.max_depth {
            node_pairs(scratch, collector, active_lo, &self.entries[lo..hi]);
            return;
        }

        // This node's misfits come first in its run.
        let mid = lo + self.misfits_end(lo, hi, level);
        node_pairs(scratch, collector, active_lo, &self.entries[lo..mid]);

        let bounds = self.child_runs(mid, hi, level);
        let own_hi = scratch.active.len() + (mid - lo);
        scratch
            .active
            .extend(self.entries[lo..mid].iter().map(|e| e.cells));
        let reaching = |active: &[Cells], child: &Block| -> Vec<Cells> {
            let mut reaching = active.to_vec();
            retain_from(&mut reaching, 0, |it| it.overlaps_block(child));
            reaching
        };

        if self.parallel_min > 0 && hi - mid >= self.parallel_min {
            // Each child a task with its own buffers and collector; results
            // merged back in child order.
            use rayon::prelude::*;
            let tasks: Vec<(usize, usize, Block, Vec<Cells>, C)> = (0..4)
                .filter(|&c| bounds[c] < bounds[c + 1])
                .map(|c| {
                    let child = block.child(c);
                    let active = reaching(&scratch.active[active_lo..own_hi], &child);
                    (bounds[c], bounds[c + 1], child, active, collector.fork())
                })
                .collect();
            let done: Vec<(Scratch, C)> = tasks
                .into_par_iter()
                .map(|(c_lo, c_hi, child, active, mut sub_collector)| {
                    let mut sub = Scratch {
                        active,
                        ..Scratch::default()
                    };
                    self.visit(
                        &mut sub,
                        &mut sub_collector,
                        c_lo,
                        c_hi,
                        level + 1,
                        child,
                        0,
                    );
                    (sub, sub_collector)
                })
                .collect();
            for (sub, sub_collector) in done {
                scratch.counts.add(&sub.counts);
                collector.join(sub_collector);
            }
        } else {
            for c in 0..4 {
                let (c_lo, c_hi) = (bounds[c], bounds[c + 1]);
                if c_lo == c_hi {
                    continue;
                }
                let child = block.child(c);
                let child_active = scratch.active.len();
                scratch.active.extend_from_within(active_lo..own_hi);
                retain_from(&mut scratch.active, child_active, |it| {
                    it.overlaps_block(&child)
                });
                self.visit(
                    scratch,
                    collector,
                    c_lo,
                    c_hi,
                    level + 1,
                    child,
                    child_active,
                );
                scratch.active.truncate(child_active);
            }
        }
        scratch.active.truncate(own_hi - (mid - lo));
    }

    /// How many of the entries of the node at `level` whose subtree is
    /// `entries[lo..hi]` are its own misfits.
    #[inline]
    fn misfits_end(&self, lo: usize, hi: usize, level: u32) -> usize {
        let run = &self.entries[lo..hi];
        if run.len() <= self.scan_max {
            run.iter()
                .position(|e| e.level() != level)
                .unwrap_or(run.len())
        } else {
            run.partition_point(|e| e.level() == level)
        }
    }

    /// The runs of a node's four children within `entries[mid..hi]` (the
    /// node's lines past its misfits), as five boundaries.
    fn child_runs(&self, mid: usize, hi: usize, level: u32) -> [usize; 5] {
        // The two key bits below the node's level choose the quadrant.
        let shift = LEVEL_BITS + 2 * (GRID_LEVELS - level - 1);
        let run = &self.entries[mid..hi];
        if run.len() <= self.scan_max {
            let mut count = [0; 4];
            for e in run {
                count[((e.key >> shift) & 3) as usize] += 1;
            }
            let first = mid + count[0];
            let second = first + count[1];
            return [mid, first, second, second + count[2], hi];
        }
        let split = |c: u64| mid + run.partition_point(|e| (e.key >> shift) & 3 < c);
        [mid, split(1), split(2), split(3), hi]
    }
}

/// The pairs a node owes: every pair within `own` (its misfits, or a leaf's
/// lines) and every pair between those and the active lines.
fn node_pairs<C: Collector>(
    scratch: &mut Scratch,
    collector: &mut C,
    active_lo: usize,
    own: &[Entry],
) {
    let Some(first) = own.first() else { return };
    let active = &scratch.active[active_lo..];
    let (a, n) = (active.len() as u64, own.len() as u64);
    scratch.counts.candidates += a * n + n * (n - 1) / 2;
    // Active lines reach the node's block, but most of them miss the part
    // of it that its own lines cover.
    let covered = own[1..].iter().fold(first.cells, |c, e| c.union(&e.cells));
    scratch.near.clear();
    scratch.near.extend_from_slice(active);
    retain_from(&mut scratch.near, 0, |a| a.overlaps(&covered));
    let near = &scratch.near;
    if near.len() + own.len() >= SWEEP_MIN {
        sweep_pairs(&mut scratch.sweep, collector, near, own);
        return;
    }
    for a in near {
        for b in own {
            if a.overlaps(&b.cells) {
                collector.pair(a.id, b.cells.id);
            }
        }
    }
    if let Some(pairs) = TRIANGLE.get(..own.len() * (own.len() - 1) / 2) {
        // One loop, whose end the branch predictor misses once, not once
        // per line.
        for &(k, j) in pairs {
            let (a, b) = (&own[usize::from(k)].cells, &own[usize::from(j)].cells);
            if a.overlaps(b) {
                collector.pair(a.id, b.id);
            }
        }
        return;
    }
    for (k, a) in own.iter().enumerate() {
        for b in &own[k + 1..] {
            if a.cells.overlaps(&b.cells) {
                collector.pair(a.cells.id, b.cells.id);
            }
        }
    }
}

/// Lines up to which a node's own pairs come from [`TRIANGLE`].
const TRIANGLE_LINES: usize = 24;

/// Every pair `(k, j)` with `k < j < TRIANGLE_LINES`, by `j` then `k`: the
/// first `n (n - 1) / 2` are the pairs among `n` lines.
const TRIANGLE: [(u8, u8); TRIANGLE_LINES * (TRIANGLE_LINES - 1) / 2] = {
    let mut pairs = [(0, 0); TRIANGLE_LINES * (TRIANGLE_LINES - 1) / 2];
    let (mut j, mut at) = (1, 0);
    while j < TRIANGLE_LINES {
        let mut k = 0;
        while k < j {
            pairs[at] = (k as u8, j as u8);
            at += 1;
            k += 1;
        }
        j += 1;
    }
    pairs
};

/// Keeps the cells of `cells[from..]` that `keep` accepts, in order. Each
/// is written whether kept or not, so that no branch hangs on the verdict:
/// verdicts on active lines follow no pattern a predictor could learn.
#[inline]
fn retain_from(cells: &mut Vec<Cells>, from: usize, keep: impl Fn(&Cells) -> bool) {
    let mut kept = from;
    for k in from..cells.len() {
        let it = cells[k];
        cells[kept] = it;
        kept += usize::from(keep(&it));
    }
    cells.truncate(kept);
}

/// A node's pairs by sweep and prune along whichever of the four
/// directions the lines spread least on (relative to their span), so that
/// only pairs overlapping on that direction are compared. Large pair sets
/// are misfit-heavy nodes: their lines straddle the node's centre lines and
/// lie spread along them, where a sweep prunes well.
fn sweep_pairs<C: Collector>(
    probes: &mut Vec<Probe>,
    collector: &mut C,
    active: &[Cells],
    own: &[Entry],
) {
    probes.clear();
    probes.extend(active.iter().map(|&cells| Probe {
        lo: 0,
        hi: 0,
        own: false,
        cells,
    }));
    probes.extend(own.iter().map(|e| Probe {
        lo: 0,
        hi: 0,
        own: true,
        cells: e.cells,
    }));

    let axes: [Axis; 4] = [
        |c| (c.x0, c.x1),
        |c| (c.y0, c.y1),
        |c| (c.u0, c.u1),
        |c| (c.w0, c.w1),
    ];
    let density = |axis: &Axis| {
        let (mut sum, mut least, mut most) = (0u64, u16::MAX, 0u16);
        for p in probes.iter() {
            let (l, h) = axis(&p.cells);
            sum += u64::from(h - l) + 1;
            least = least.min(l);
            most = most.max(h);
        }
        sum as f64 / (f64::from(most - least) + 1.0)
    };
    let axis = axes
        .iter()
        .min_by(|a, b| density(a).total_cmp(&density(b)))
        .expect("four axes");
    for p in probes.iter_mut() {
        (p.lo, p.hi) = axis(&p.cells);
    }
    probes.sort_unstable_by_key(|p| p.lo);

    for (i, a) in probes.iter().enumerate() {
        for b in &probes[i + 1..] {
            if b.lo > a.hi {
                break;
            }
            // Pairs of active lines belong to other nodes.
            if (a.own | b.own) & a.cells.overlaps(&b.cells) {
                collector.pair(a.cells.id, b.cells.id);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cells(x0: u16, y0: u16, x1: u16, y1: u16) -> Cells {
        Cells {
            x0,
            y0,
            x1,
            y1,
            ..Cells::default()
        }
    }

    /// An axis-aligned box with its diagonal extents.
    fn square(min_x: f64, min_y: f64, max_x: f64, max_y: f64) -> SweptBox {
        SweptBox {
            min_x,
            min_y,
            max_x,
            max_y,
            min_u: 1180.0 * min_x + 800.0 * min_y,
            max_u: 1180.0 * max_x + 800.0 * max_y,
            min_w: 1180.0 * min_x - 800.0 * max_y,
            max_w: 1180.0 * max_x - 800.0 * min_y,
        }
    }

    #[test]
    fn spread_interleaves_bits() {
        assert_eq!(spread(0b1011), 0b1_00_01_01);
        assert_eq!(spread(u16::MAX), 0x5555_5555);
    }

    #[test]
    fn a_box_lives_at_the_deepest_quadrant_holding_it() {
        // One cell: the finest level, capped by max_depth.
        let level = |k: u64| k & LEVEL_MASK;
        assert_eq!(level(key(&cells(5, 9, 5, 9), 15)), 15);
        assert_eq!(level(key(&cells(5, 9, 5, 9), 12)), 12);
        // Straddling the root's middle in x: a root misfit.
        assert_eq!(level(key(&cells(16383, 10, 16384, 10), 15)), 0);
        // Within the left half but straddling its middle: level 1.
        assert_eq!(level(key(&cells(8191, 10, 8192, 10), 15)), 1);
    }

    #[test]
    fn a_node_sorts_before_its_subtree_and_after_its_ancestors() {
        let root_misfit = key(&cells(0, 0, 20000, 10), 15);
        let node = key(&cells(0, 0, 10000, 10), 15);
        let deep = key(&cells(0, 0, 1, 1), 15);
        let sibling = key(&cells(20000, 0, 20001, 1), 15);
        assert!(root_misfit < node && node < deep && deep < sibling);
    }

    #[test]
    fn grid_cells_are_monotone_and_clamped() {
        let b = square(0.5, 0.5, 1.0, 1.0);
        let g = Grid::over(&b);
        let c = g.cells(&b, 3);
        assert_eq!(c.id, 3);
        assert!(c.x0 > 0 && c.x0 < 1024 && c.x1 > 31500 && c.x1 < CELL_MAX);
        let mid = g.cells(&square(0.75, 0.75, 0.75, 0.75), 0);
        assert_eq!((mid.x0, mid.y0), (16384, 16384));
        // The root grows to hold lines far outside the box; the middle stays.
        let far = Grid::over(&square(-3.0, 0.6, 0.9, 0.9));
        let c = far.cells(&square(-3.0, 0.75, 0.75, 0.75), 0);
        assert!(c.x0 < 2000 && c.x1 == 16384 && c.y0 == 16384);
        // Values past the edge (rounding) saturate.
        let edge = g.cells(&square(-1e9, 0.7, 1e9, 0.7), 0);
        assert_eq!((edge.x0, edge.x1), (0, CELL_MAX));
    }

    #[test]
    fn the_triangle_lists_each_pair_of_the_first_lines_once() {
        for n in 0..=TRIANGLE_LINES {
            let mut pairs: Vec<(u8, u8)> = TRIANGLE[..n * n.saturating_sub(1) / 2].to_vec();
            pairs.sort_unstable();
            let expected: Vec<(u8, u8)> = (0..n as u8)
                .flat_map(|k| (k + 1..n as u8).map(move |j| (k, j)))
                .collect();
            assert_eq!(pairs, expected, "{n} lines");
        }
    }

    #[test]
    fn retain_from_keeps_the_accepted_in_order_and_leaves_the_front() {
        let mut v: Vec<Cells> = (0..10)
            .map(|id| Cells {
                id,
                ..Cells::default()
            })
            .collect();
        retain_from(&mut v, 3, |c| c.id % 3 != 0);
        let ids: Vec<u32> = v.iter().map(|c| c.id).collect();
        assert_eq!(ids, vec![0, 1, 2, 4, 5, 7, 8]);
        retain_from(&mut v, 0, |_| false);
        assert!(v.is_empty());
    }

    #[test]
    fn blocks_split_into_quadrants_in_key_order() {
        let b = Block {
            x0: 0,
            y0: 0,
            size: 8,
        };
        let (c1, c2) = (b.child(1), b.child(2));
        assert_eq!((c1.x0, c1.y0, c1.size), (4, 0, 4));
        assert_eq!((c2.x0, c2.y0, c2.size), (0, 4, 4));
        assert!(cells(3, 0, 4, 0).overlaps_block(&c1));
        assert!(!cells(0, 0, 3, 3).overlaps_block(&c1));
    }

    #[test]
    fn nearly_sorted_and_scrambled_inputs_both_sort() {
        let mk = |k: u64| Entry {
            key: k,
            cells: Cells::default(),
        };
        let mut near: Vec<Entry> = (0..1000u64).map(|k| mk(k ^ 1)).collect();
        assert!(sort_nearly_sorted(&mut near));
        assert!(near.windows(2).all(|w| w[0].key <= w[1].key));
        // One entry in ten jumped far, both ways: 100 descents, so
        // the merge path.
        let jumped = |k: u64| match k % 20 {
            3 => mk(k * 7 % 1000),
            7 => mk(1000 - k),
            _ => mk(k),
        };
        let mut expected: Vec<u64> = (0..1000u64).map(|k| jumped(k).key).collect();
        expected.sort_unstable();
        let mut tree = Tree::new(4, 12);
        tree.entries = (0..1000u64).map(jumped).collect();
        tree.sort(false);
        assert_eq!(
            tree.entries.iter().map(|e| e.key).collect::<Vec<_>>(),
            expected
        );
        tree.entries = (0..1000u64).map(jumped).collect();
        tree.sort(true);
        assert_eq!(
            tree.entries.iter().map(|e| e.key).collect::<Vec<_>>(),
            expected
        );
        let mut reversed: Vec<Entry> = (0..1000u64).rev().map(mk).collect();
        assert!(!sort_nearly_sorted(&mut reversed));
        let mut tree = Tree::new(4, 12);
        tree.entries = reversed;
        tree.sort(false);
        assert!(tree.entries.windows(2).all(|w| w[0].key <= w[1].key));
    }

    /// A coordinate near either edge of the grid, or anywhere on it.
    fn coordinate() -> impl proptest::strategy::Strategy<Value = u16> {
        proptest::prop_oneof![0u16..8, CELL_MAX - 8..=CELL_MAX, 0..=CELL_MAX]
    }

    fn any_cells() -> impl proptest::strategy::Strategy<Value = Cells> {
        use proptest::strategy::Strategy;
        proptest::array::uniform8(coordinate()).prop_map(|c| {
            let span = |a: u16, b: u16| (a.min(b), a.max(b));
            let ((x0, x1), (y0, y1)) = (span(c[0], c[1]), span(c[2], c[3]));
            let ((u0, u1), (w0, w1)) = (span(c[4], c[5]), span(c[6], c[7]));
            Cells {
                x0,
                y0,
                u0,
                w0,
                x1,
                y1,
                u1,
                w1,
                id: 0,
            }
        })
    }

    proptest::proptest! {
        /// The four-lane overlap test agrees with eight comparisons, at the
        /// grid's edges too.
        #[test]
        fn overlaps_compares_every_direction(a in any_cells(), b in any_cells()) {
            let apart = |l0: u16, l1: u16, m0: u16, m1: u16| l1 < m0 || m1 < l0;
            let expected = !(apart(a.x0, a.x1, b.x0, b.x1)
                || apart(a.y0, a.y1, b.y0, b.y1)
                || apart(a.u0, a.u1, b.u0, b.u1)
                || apart(a.w0, a.w1, b.w0, b.w1));
            proptest::prop_assert_eq!(a.overlaps(&b), expected);
            proptest::prop_assert_eq!(b.overlaps(&a), expected);
        }
    }

    /// Sets the tree's entries to `make(0..n)` in place (in runs of
    /// `chunk` on the current rayon pool, if given), as the detector does,
    /// and sorts them.
    fn refill(
        tree: &mut Tree,
        n: usize,
        chunk: Option<usize>,
        make: impl Fn(usize) -> Entry + Sync,
    ) {
        let fill = |first: usize, mut run: Refill<'_>| {
            for k in 0..run.entries.len() {
                run.set(k, make(first + k));
            }
        };
        match chunk {
            Some(chunk) => {
                use rayon::prelude::*;
                tree.refill_in_place(n)
                    .chunks(chunk)
                    .into_par_iter()
                    .enumerate()
                    .for_each(|(c, run)| fill(c * chunk, run));
            }
            None => fill(0, tree.refill_in_place(n)),
        }
        tree.sort(chunk.is_some());
    }

    proptest::proptest! {
        /// Sorted keys, some of them changed (a few far, most a little),
        /// refilled on one thread or several: the entries come out sorted
        /// and are the same entries.
        #[test]
        fn refilling_sorts_whatever_changed(
            base in proptest::collection::vec(0u64..400, 0..3000),
            changes in proptest::collection::vec((0usize..3000, 0u64..400), 0..400),
            added in proptest::collection::vec(0u64..400, 0..200),
            threads in 1usize..4,
        ) {
            let mut keys = base;
            keys.sort_unstable();
            let mk = |k: u64, id: usize| Entry {
                key: k,
                cells: Cells { id: id as u32, ..Cells::default() },
            };
            let mut tree = Tree::new(4, 12);
            refill(&mut tree, keys.len(), None, |i| mk(keys[i], i));
            for &(at, key) in &changes {
                if at < keys.len() {
                    keys[at] = key;
                }
            }
            // Lines added since the last refill have no place to keep.
            keys.extend(&added);
            let n = keys.len();
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let chunk = (threads > 1).then_some(64);
            pool.install(|| refill(&mut tree, n, chunk, |i| mk(keys[i], i)));
            let got: Vec<u64> = tree.entries.iter().map(|e| e.key).collect();
            let mut expected = keys.clone();
            expected.sort_unstable();
            proptest::prop_assert_eq!(got, expected);
            let mut ids: Vec<u32> = tree.entries.iter().map(|e| e.cells.id).collect();
            ids.sort_unstable();
            proptest::prop_assert!(ids.iter().enumerate().all(|(i, &id)| id as usize == i));
            for e in &tree.entries {
                proptest::prop_assert_eq!(e.key, keys[e.cells.id as usize]);
            }
        }
    }
}
