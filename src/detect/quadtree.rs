//! The quadtree detector of the design write-up, kept as a sorted array.
//!
//! The tree is the write-up's: the root covers the swept boxes of all
//! lines; a node holding more than `leaf_size` lines, and shallower than
//! `max_depth`, splits its region into four quadrants; a line whose swept box
//! fits in one quadrant goes down to it, the others stay at the node as
//! *misfits*. A node's misfits are tested against each other and against
//! every line below the node; a leaf tests its own pairs. Each pair is
//! tested once, at the deepest node holding both lines.
//!
//! How it is built is what makes it fast:
//! - Swept boxes are quantised to a grid of `2^16 x 2^16` cells over the
//!   root, a square centred on the box that grows (by doubling) only when
//!   lines leave it, so that cells stay put from step to step. The deepest quadrant holding a box whole is where its corner
//!   cells' coordinates stop sharing leading bits, so a line's node is known
//!   without descending, and its Morton key (the node's cell interleaved,
//!   then the level) puts every node's misfits first and its subtree right
//!   after, in one sorted array.
//! - Lines hardly move in a step, so the array sorted last step is nearly
//!   sorted this step: an insertion sort fixes it in close to linear time
//!   (falling back to a full sort when lines jump far). This is the
//!   incremental tree: only the lines whose node changed move.
//! - A node finds its children's runs by binary search over the keys, and
//!   the misfits from above travel down as an *active list* that each child
//!   filters by its cell block, so a misfit meets only the quadrants its box
//!   reaches.
//! - Quantisation is monotone, so two boxes that overlap still overlap in
//!   cells: every test on cells is conservative, with no rounding questions.
//!
//! The buffers live in the detector and are reused: once they have grown to
//! the scene's size, a step allocates nothing.

use super::swept::{
    swept_box, test_pair, test_wild, Class, PairCounts, SweptBox, SweptBoxes, DIAGONAL_X,
    DIAGONAL_Y,
};
use super::{Detector, DetectorStats};
use crate::line::{Line, BOX_MAX, BOX_MIN};
use crate::narrow::Event;

/// Default for the largest number of lines a leaf holds before it splits.
pub const DEFAULT_LEAF_SIZE: usize = 16;
/// Default for the deepest level a node may split at.
pub const DEFAULT_MAX_DEPTH: u32 = 12;
/// Levels of the quantisation grid: the deepest a tree can go.
pub const GRID_LEVELS: u32 = 16;

const LEVEL_BITS: u32 = 5;
const LEVEL_MASK: u64 = (1 << LEVEL_BITS) - 1;

/// A line's swept hull in finest-level grid cells (inclusive), along the
/// axes and the diagonals, with its id.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Cells {
    x0: u16,
    y0: u16,
    x1: u16,
    y1: u16,
    u0: u16,
    w0: u16,
    u1: u16,
    w1: u16,
    id: u32,
}

impl Cells {
    /// Non-short-circuit `&`: one predictable branch on the result instead
    /// of eight unpredictable ones.
    #[inline]
    fn overlaps(&self, o: &Cells) -> bool {
        (self.x0 <= o.x1)
            & (o.x0 <= self.x1)
            & (self.y0 <= o.y1)
            & (o.y0 <= self.y1)
            & (self.u0 <= o.u1)
            & (o.u0 <= self.u1)
            & (self.w0 <= o.w1)
            & (o.w0 <= self.w1)
    }

    #[inline]
    fn overlaps_block(&self, b: &Block) -> bool {
        u32::from(self.x0) <= b.x_last()
            && b.x0 <= u32::from(self.x1)
            && u32::from(self.y0) <= b.y_last()
            && b.y0 <= u32::from(self.y1)
    }
}

const LANES: usize = 16;

/// The sorted lines' cells, one array per field, so that the candidate
/// loops compare a line with sixteen others at once (LLVM turns the
/// fixed-size inner loop into vector compares). Each array is followed by
/// `LANES` padding entries, so that a chunk may start anywhere.
#[derive(Debug, Default)]
struct Columns {
    x0: Vec<u16>,
    y0: Vec<u16>,
    x1: Vec<u16>,
    y1: Vec<u16>,
    u0: Vec<u16>,
    w0: Vec<u16>,
    u1: Vec<u16>,
    w1: Vec<u16>,
    id: Vec<u32>,
}

impl Columns {
    /// Refills the columns from entries in order, then pads them.
    fn fill(&mut self, entries: &[Entry]) {
        let fields = [
            &mut self.x0,
            &mut self.y0,
            &mut self.x1,
            &mut self.y1,
            &mut self.u0,
            &mut self.w0,
            &mut self.u1,
            &mut self.w1,
        ];
        for (f, column) in fields.into_iter().enumerate() {
            column.clear();
            column.extend(entries.iter().map(|e| {
                let c = &e.cells;
                [c.x0, c.y0, c.x1, c.y1, c.u0, c.w0, c.u1, c.w1][f]
            }));
            column.extend([0; LANES]);
        }
        self.id.clear();
        self.id.extend(entries.iter().map(|e| e.cells.id));
        self.id.extend([u32::MAX; LANES]);
    }

    fn get(&self, i: usize) -> Cells {
        Cells {
            x0: self.x0[i],
            y0: self.y0[i],
            x1: self.x1[i],
            y1: self.y1[i],
            u0: self.u0[i],
            w0: self.w0[i],
            u1: self.u1[i],
            w1: self.w1[i],
            id: self.id[i],
        }
    }

    /// Calls `hit` with the id of every line in `lo..hi` whose cells
    /// overlap `a`'s, sixteen lines per step; lanes past `hi` are masked.
    #[inline]
    fn overlapping(&self, a: &Cells, lo: usize, hi: usize, mut hit: impl FnMut(u32)) {
        let mut i = lo;
        while i < hi {
            let lane =
                |v: &[u16]| -> [u16; LANES] { v[i..i + LANES].try_into().expect("padded columns") };
            let (x0, y0, x1, y1) = (
                lane(&self.x0),
                lane(&self.y0),
                lane(&self.x1),
                lane(&self.y1),
            );
            let (u0, w0, u1, w1) = (
                lane(&self.u0),
                lane(&self.w0),
                lane(&self.u1),
                lane(&self.w1),
            );
            let mut flags = [0u8; LANES];
            for j in 0..LANES {
                let fits = (a.x0 <= x1[j])
                    & (x0[j] <= a.x1)
                    & (a.y0 <= y1[j])
                    & (y0[j] <= a.y1)
                    & (a.u0 <= u1[j])
                    & (u0[j] <= a.u1)
                    & (a.w0 <= w1[j])
                    & (w0[j] <= a.w1);
                flags[j] = u8::from(fits);
            }
            // One byte per lane, each 0 or 1: find the set ones by bit tricks.
            let valid = hi - i;
            let mut bits = u128::from_ne_bytes(flags).to_le();
            if valid < LANES {
                bits &= (1u128 << (8 * valid)) - 1;
            }
            while bits != 0 {
                let j = bits.trailing_zeros() as usize / 8;
                hit(self.id[i + j]);
                bits &= bits - 1;
            }
            i += LANES;
        }
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    key: u64,
    cells: Cells,
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
struct Grid {
    min: f64,
    side: f64,
    scale: f64,
}

impl Grid {
    /// The grid over the smallest square of a fixed family holding
    /// `bounds`: centred on the box, a little larger than it, doubling as
    /// needed. Fixed squares keep keys stable from step to step (so last
    /// step's order is nearly sorted), whereas a root fitted to the bounds
    /// would move every cell boundary whenever any line moved.
    fn over(bounds: &SweptBox) -> Self {
        const CENTRE: f64 = (BOX_MIN + BOX_MAX) / 2.0;
        let reach = (CENTRE - bounds.min_x)
            .max(bounds.max_x - CENTRE)
            .max(CENTRE - bounds.min_y)
            .max(bounds.max_y - CENTRE);
        let mut half = (BOX_MAX - BOX_MIN) / 2.0 * (1.0 + 1.0 / 16.0);
        while half < reach {
            half *= 2.0;
        }
        Grid {
            min: CENTRE - half,
            side: 2.0 * half,
            scale: f64::from(1u32 << GRID_LEVELS) / (2.0 * half),
        }
    }

    /// True when `bounds` lies within the grid's square.
    fn holds(&self, bounds: &SweptBox) -> bool {
        let max = self.min + self.side;
        bounds.min_x >= self.min
            && bounds.min_y >= self.min
            && bounds.max_x <= max
            && bounds.max_y <= max
    }

    #[inline]
    fn cell(v: f64, min: f64, scale: f64) -> u16 {
        // Float-to-int casts saturate (and send NaN to 0): no branch needed
        // at the edges.
        ((v - min) * scale).min(f64::from(u16::MAX)) as u16
    }

    #[inline]
    fn cells(&self, b: &SweptBox, id: u32) -> Cells {
        let (wx, wy) = (DIAGONAL_X, DIAGONAL_Y);
        let min_u = self.min * (wx + wy);
        let min_w = self.min * wx - (self.min + self.side) * wy;
        let half_scale = self.scale / (wx + wy);
        Cells {
            x0: Self::cell(b.min_x, self.min, self.scale),
            y0: Self::cell(b.min_y, self.min, self.scale),
            x1: Self::cell(b.max_x, self.min, self.scale),
            y1: Self::cell(b.max_y, self.min, self.scale),
            u0: Self::cell(b.min_u, min_u, half_scale),
            w0: Self::cell(b.min_w, min_w, half_scale),
            u1: Self::cell(b.max_u, min_u, half_scale),
            w1: Self::cell(b.max_w, min_w, half_scale),
            id,
        }
    }
}

/// The sort key of a line: its node's cell (Morton order) and level.
#[inline]
fn key(c: &Cells, max_depth: u32) -> u64 {
    let differ = u32::from((c.x0 ^ c.x1) | (c.y0 ^ c.y1));
    let fits = GRID_LEVELS - (u32::BITS - differ.leading_zeros());
    let level = fits.min(max_depth);
    let keep = !((1u32 << (GRID_LEVELS - level)) - 1) as u16;
    let morton = spread(c.x0 & keep) | (spread(c.y0 & keep) << 1);
    (u64::from(morton) << LEVEL_BITS) | u64::from(level)
}

/// Sorts entries by key, fast when they are nearly sorted already; falls
/// back to a full in-place sort when too many have moved far.
fn sort_nearly_sorted(entries: &mut [Entry]) {
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
            entries.sort_unstable_by_key(|e| e.key);
            return;
        }
    }
}

/// A quadtree broad phase.
#[derive(Debug)]
pub struct Quadtree {
    leaf_size: usize,
    max_depth: u32,
    boxes: SweptBoxes,
    /// The grid in use; it changes only when lines leave its square.
    grid: Grid,
    /// Each line's entry for this step, by id (meaningful for boxed lines).
    by_id: Vec<Entry>,
    /// Ids of the boxed lines in last step's key order.
    order: Vec<u32>,
    entries: Vec<Entry>,
    /// The entries' cells, in key order, packed for the pair loops.
    items: Columns,
    /// Misfits of the nodes above the current one, filtered by region.
    active: Vec<Cells>,
    /// The sweep's buffer, kept between steps.
    sweep: Vec<Probe>,
    stats: DetectorStats,
}

impl Default for Quadtree {
    fn default() -> Self {
        Self::new(DEFAULT_LEAF_SIZE, DEFAULT_MAX_DEPTH)
    }
}

impl Quadtree {
    /// A quadtree whose leaves hold at most `leaf_size` lines (at least 1)
    /// unless `max_depth` (at most [`GRID_LEVELS`]) stops the splitting.
    pub fn new(leaf_size: usize, max_depth: u32) -> Self {
        Self {
            leaf_size: leaf_size.max(1),
            max_depth: max_depth.min(GRID_LEVELS),
            boxes: SweptBoxes::default(),
            grid: Grid::over(&SweptBox {
                min_x: BOX_MIN,
                min_y: BOX_MIN,
                max_x: BOX_MAX,
                max_y: BOX_MAX,
                ..SweptBox::default()
            }),
            by_id: Vec::new(),
            order: Vec::new(),
            entries: Vec::new(),
            items: Columns::default(),
            active: Vec::new(),
            sweep: Vec::new(),
            stats: DetectorStats::default(),
        }
    }

    /// Classifies the lines and computes every boxed line's entry, growing
    /// the grid first if lines have left it.
    fn compute_entries(&mut self, lines: &[Line], dt: f64) {
        let (grid, max_depth) = (self.grid, self.max_depth);
        self.by_id.resize(lines.len(), Entry::default());
        let by_id = &mut self.by_id;
        self.boxes.compute(lines, dt, |id, b| {
            let cells = grid.cells(b, id);
            by_id[id as usize] = Entry {
                key: key(&cells, max_depth),
                cells,
            };
        });
        // Cells clamp at the grid's edge, so a stale grid would still be
        // correct, only slow: regrid (rarely) when lines get out.
        if let Some(bounds) = self.boxes.bounds {
            if !self.grid.holds(&bounds) {
                self.grid = Grid::over(&bounds);
                let grid = self.grid;
                for (id, line) in lines.iter().enumerate() {
                    if self.boxes.class[id] == Class::Boxed {
                        if let (Some(b), _) = swept_box(line, dt) {
                            let cells = grid.cells(&b, id as u32);
                            self.by_id[id] = Entry {
                                key: key(&cells, max_depth),
                                cells,
                            };
                        }
                    }
                }
            }
        }
    }

    /// Fills `entries` with this step's boxed lines in last step's order
    /// (or id order when the set of boxed lines changed) and sorts them.
    fn arrange(&mut self) {
        let (by_id, class) = (&self.by_id, &self.boxes.class);
        self.entries.clear();
        self.entries.extend(
            self.order
                .iter()
                .filter(|&&id| class.get(id as usize) == Some(&Class::Boxed))
                .map(|&id| by_id[id as usize]),
        );
        if self.entries.len() != self.boxes.boxed {
            self.entries.clear();
            self.entries.extend(
                (0..class.len())
                    .filter(|&id| class[id] == Class::Boxed)
                    .map(|id| by_id[id]),
            );
        }
        sort_nearly_sorted(&mut self.entries);
        self.order.clear();
        self.order.extend(self.entries.iter().map(|e| e.cells.id));
        self.items.fill(&self.entries);
    }

    /// Visits the node at `level` covering `block`, whose subtree is
    /// `entries[lo..hi]`; the misfits from above that reach it are
    /// `active[active_lo..]`.
    #[allow(clippy::too_many_arguments)]
    fn visit(
        &mut self,
        pass: &mut Pass,
        lo: usize,
        hi: usize,
        level: u32,
        block: Block,
        active_lo: usize,
    ) {
        pass.nodes += 1;
        pass.deepest = pass.deepest.max(level);
        if hi - lo <= self.leaf_size || level >= self.max_depth {
            pass.pairs(&self.active[active_lo..], &self.items, lo, hi);
            return;
        }

        // This node's misfits come first in its run.
        let mid = lo + self.entries[lo..hi].partition_point(|e| e.level() == level);
        pass.pairs(&self.active[active_lo..], &self.items, lo, mid);

        // Children's runs, by the two key bits that choose the quadrant.
        let shift = LEVEL_BITS + 2 * (GRID_LEVELS - level - 1);
        let child_of = |e: &Entry| ((e.key >> shift) & 3) as usize;
        let run = &self.entries[mid..hi];
        let split = |c: usize| mid + run.partition_point(|e| child_of(e) < c);
        let bounds = [mid, split(1), split(2), split(3), hi];

        let own_hi = self.active.len() + (mid - lo);
        for k in lo..mid {
            self.active.push(self.items.get(k));
        }
        for c in 0..4 {
            let (c_lo, c_hi) = (bounds[c], bounds[c + 1]);
            if c_lo == c_hi {
                continue;
            }
            let child = block.child(c);
            let child_active = self.active.len();
            for k in active_lo..own_hi {
                let it = self.active[k];
                if it.overlaps_block(&child) {
                    self.active.push(it);
                }
            }
            self.visit(pass, c_lo, c_hi, level + 1, child, child_active);
            self.active.truncate(child_active);
        }
        self.active.truncate(own_hi - (mid - lo));
    }
}

/// What one detection pass needs besides the tree buffers.
struct Pass<'a> {
    lines: &'a [Line],
    magnitude: &'a [f64],
    dt: f64,
    events: &'a mut Vec<Event>,
    counts: PairCounts,
    nodes: u64,
    deepest: u32,
    /// Reused buffer of the sweep.
    sweep: Vec<Probe>,
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

/// Below this many lines in a node's pair set, plain loops beat sorting.
const SWEEP_MIN: usize = 48;

impl Pass<'_> {
    /// The exact path for a pair whose boxes overlap; kept out of line so
    /// that the loops over candidates stay small.
    #[inline(never)]
    fn hit(&mut self, a: u32, b: u32) {
        test_pair(
            self.lines,
            self.magnitude,
            a,
            b,
            self.dt,
            self.events,
            &mut self.counts,
        );
    }

    /// The pairs a node owes: every pair within `items[lo..hi]` and every
    /// pair between those lines and the `active` ones.
    fn pairs(&mut self, active: &[Cells], items: &Columns, lo: usize, hi: usize) {
        let (a, n) = (active.len() as u64, (hi - lo) as u64);
        self.counts.candidates += a * n + n * n.saturating_sub(1) / 2;
        if active.len() + (hi - lo) >= SWEEP_MIN {
            self.sweep_pairs(active, items, lo, hi);
            return;
        }
        for a in active {
            items.overlapping(a, lo, hi, |b| self.hit(a.id, b));
        }
        for k in lo..hi {
            let a = items.get(k);
            items.overlapping(&a, k + 1, hi, |b| self.hit(a.id, b));
        }
    }

    /// [`Pass::pairs`] by sweep and prune along whichever of the four
    /// directions the lines spread least on (relative to their span), so
    /// that only pairs overlapping on that direction are compared. Large
    /// pair sets are misfit-heavy nodes: their lines straddle the node's
    /// centre lines and lie spread along them, where a sweep prunes well.
    fn sweep_pairs(&mut self, active: &[Cells], items: &Columns, lo: usize, hi: usize) {
        let mut probes = std::mem::take(&mut self.sweep);
        probes.clear();
        probes.extend(active.iter().map(|&cells| Probe {
            lo: 0,
            hi: 0,
            own: false,
            cells,
        }));
        probes.extend((lo..hi).map(|k| Probe {
            lo: 0,
            hi: 0,
            own: true,
            cells: items.get(k),
        }));

        let axes: [fn(&Cells) -> (u16, u16); 4] = [
            |c| (c.x0, c.x1),
            |c| (c.y0, c.y1),
            |c| (c.u0, c.u1),
            |c| (c.w0, c.w1),
        ];
        let density = |axis: &fn(&Cells) -> (u16, u16)| {
            let (mut sum, mut least, mut most) = (0u64, u16::MAX, 0u16);
            for p in &probes {
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
        for p in &mut probes {
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
                    self.hit(a.cells.id, b.cells.id);
                }
            }
        }
        self.sweep = probes;
    }
}

impl Detector for Quadtree {
    fn name(&self) -> &'static str {
        "quadtree"
    }

    fn detect(&mut self, lines: &[Line], dt: f64, events: &mut Vec<Event>) {
        let before = events.len();
        self.compute_entries(lines, dt);
        let mut counts = PairCounts::default();
        test_wild(lines, &self.boxes, dt, events, &mut counts);

        let magnitude = std::mem::take(&mut self.boxes.magnitude);
        let mut pass = Pass {
            lines,
            magnitude: &magnitude,
            dt,
            events,
            counts,
            nodes: 0,
            deepest: 0,
            sweep: std::mem::take(&mut self.sweep),
        };
        if self.boxes.boxed > 0 {
            self.arrange();
            self.active.clear();
            let root = Block {
                x0: 0,
                y0: 0,
                size: 1 << GRID_LEVELS,
            };
            let n = self.entries.len();
            self.visit(&mut pass, 0, n, 0, root, 0);
        }
        let counts = pass.counts;
        let (nodes, deepest) = (pass.nodes, pass.deepest);
        self.sweep = pass.sweep;
        self.boxes.magnitude = magnitude;

        self.stats.candidate_pairs += counts.candidates;
        self.stats.exact_tests += counts.exact;
        self.stats.nodes += nodes;
        self.stats.max_depth = self.stats.max_depth.max(deepest);
        self.stats.events += (events.len() - before) as u64;
    }

    fn stats(&self) -> DetectorStats {
        self.stats
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
    fn the_lane_kernel_finds_exactly_the_overlapping_lines() {
        // Lines 0..40 each one cell wide at x = 3 * k; a probe spanning
        // x = 30..=45 meets lines 10..=15; ranges cut anywhere.
        let entries: Vec<Entry> = (0..40u16)
            .map(|k| Entry {
                key: 0,
                cells: Cells {
                    x0: 3 * k,
                    x1: 3 * k,
                    y1: 5,
                    u1: 5,
                    w1: 5,
                    id: u32::from(k),
                    ..Cells::default()
                },
            })
            .collect();
        let mut columns = Columns::default();
        columns.fill(&entries);
        let probe = Cells {
            x0: 30,
            x1: 45,
            y1: 1,
            u1: 1,
            w1: 1,
            ..Cells::default()
        };
        for (lo, hi) in [(0, 40), (0, 12), (11, 14), (12, 12), (15, 40), (13, 31)] {
            let mut found = Vec::new();
            columns.overlapping(&probe, lo, hi, |id| found.push(id));
            let expected: Vec<u32> = (lo as u32..hi as u32)
                .filter(|k| (10..=15).contains(k))
                .collect();
            assert_eq!(found, expected, "range {lo}..{hi}");
            let scalar: Vec<u32> = (lo..hi)
                .filter(|&k| probe.overlaps(&columns.get(k)))
                .map(|k| k as u32)
                .collect();
            assert_eq!(found, scalar);
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
        assert_eq!(key(&cells(5, 9, 5, 9), 16) & LEVEL_MASK, 16);
        assert_eq!(key(&cells(5, 9, 5, 9), 12) & LEVEL_MASK, 12);
        // Straddling the root's middle in x: a root misfit.
        assert_eq!(key(&cells(32767, 10, 32768, 10), 16) & LEVEL_MASK, 0);
        // Within the left half but straddling its middle: level 1.
        assert_eq!(key(&cells(16383, 10, 16384, 10), 16) & LEVEL_MASK, 1);
    }

    #[test]
    fn a_node_sorts_before_its_subtree_and_after_its_ancestors() {
        let root_misfit = key(&cells(0, 0, 40000, 10), 16);
        let node = key(&cells(0, 0, 20000, 10), 16);
        let deep = key(&cells(0, 0, 1, 1), 16);
        let sibling = key(&cells(40000, 0, 40001, 1), 16);
        assert!(root_misfit < node && node < deep && deep < sibling);
    }

    #[test]
    fn grid_cells_are_monotone_and_clamped() {
        let b = square(0.5, 0.5, 1.0, 1.0);
        let g = Grid::over(&b);
        let c = g.cells(&b, 3);
        assert_eq!(c.id, 3);
        assert!(c.x0 > 0 && c.x0 < 2048 && c.x1 > 63000 && c.x1 < u16::MAX);
        let mid = g.cells(&square(0.75, 0.75, 0.75, 0.75), 0);
        assert_eq!((mid.x0, mid.y0), (32768, 32768));
        // The root grows to hold lines far outside the box; the middle stays.
        let far = Grid::over(&square(-3.0, 0.6, 0.9, 0.9));
        let c = far.cells(&square(-3.0, 0.75, 0.75, 0.75), 0);
        assert!(c.x0 < 4000 && c.x1 == 32768 && c.y0 == 32768);
        // Values past the edge (rounding) saturate.
        let edge = g.cells(&square(-1e9, 0.7, 1e9, 0.7), 0);
        assert_eq!((edge.x0, edge.x1), (0, u16::MAX));
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
        sort_nearly_sorted(&mut near);
        assert!(near.windows(2).all(|w| w[0].key <= w[1].key));
        let mut reversed: Vec<Entry> = (0..1000u64).rev().map(mk).collect();
        sort_nearly_sorted(&mut reversed);
        assert!(reversed.windows(2).all(|w| w[0].key <= w[1].key));
    }
}
