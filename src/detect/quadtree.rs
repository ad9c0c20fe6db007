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

use super::swept::{test_pair, test_wild, Class, PairCounts, SweptBox, SweptBoxes};
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

/// A line's swept box in finest-level grid cells (inclusive), with its id.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
struct Cells {
    x0: u16,
    y0: u16,
    x1: u16,
    y1: u16,
    id: u32,
}

impl Cells {
    /// Non-short-circuit `&`: one predictable branch on the result instead
    /// of four unpredictable ones.
    #[inline]
    fn overlaps(&self, o: &Cells) -> bool {
        (self.x0 <= o.x1) & (o.x0 <= self.x1) & (self.y0 <= o.y1) & (o.y0 <= self.y1)
    }

    #[inline]
    fn overlaps_block(&self, b: &Block) -> bool {
        u32::from(self.x0) <= b.x_last()
            && b.x0 <= u32::from(self.x1)
            && u32::from(self.y0) <= b.y_last()
            && b.y0 <= u32::from(self.y1)
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
#[derive(Clone, Copy, Debug)]
struct Grid {
    min_x: f64,
    min_y: f64,
    scale_x: f64,
    scale_y: f64,
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
        let scale = f64::from(1u32 << GRID_LEVELS) / (2.0 * half);
        Grid {
            min_x: CENTRE - half,
            min_y: CENTRE - half,
            scale_x: scale,
            scale_y: scale,
        }
    }

    #[inline]
    fn cell(v: f64, min: f64, scale: f64) -> u16 {
        // Float-to-int casts saturate (and send NaN, from a zero-width
        // root, to 0): no branch needed for the edges.
        ((v - min) * scale).min(f64::from(u16::MAX)) as u16
    }

    #[inline]
    fn cells(&self, b: &SweptBox, id: u32) -> Cells {
        Cells {
            x0: Self::cell(b.min_x, self.min_x, self.scale_x),
            y0: Self::cell(b.min_y, self.min_y, self.scale_y),
            x1: Self::cell(b.max_x, self.min_x, self.scale_x),
            y1: Self::cell(b.max_y, self.min_y, self.scale_y),
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
    /// Ids of the boxed lines in last step's key order.
    order: Vec<u32>,
    entries: Vec<Entry>,
    /// The entries' cells, in key order, packed for the pair loops.
    items: Vec<Cells>,
    /// Misfits of the nodes above the current one, filtered by region.
    active: Vec<Cells>,
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
            order: Vec::new(),
            entries: Vec::new(),
            items: Vec::new(),
            active: Vec::new(),
            stats: DetectorStats::default(),
        }
    }

    /// Fills `entries` with this step's boxed lines in last step's order
    /// (or id order when the set of boxed lines changed) and sorts them.
    fn arrange(&mut self, grid: &Grid) {
        let (boxes, class) = (&self.boxes.boxes, &self.boxes.class);
        let max_depth = self.max_depth;
        let entry = |id: u32| {
            let cells = grid.cells(&boxes[id as usize], id);
            Entry {
                key: key(&cells, max_depth),
                cells,
            }
        };
        self.entries.clear();
        self.entries.extend(
            self.order
                .iter()
                .filter(|&&id| class.get(id as usize) == Some(&Class::Boxed))
                .map(|&id| entry(id)),
        );
        if self.entries.len() != self.boxes.boxed {
            self.entries.clear();
            self.entries.extend(
                (0..class.len() as u32)
                    .filter(|&id| class[id as usize] == Class::Boxed)
                    .map(entry),
            );
        }
        sort_nearly_sorted(&mut self.entries);
        self.order.clear();
        self.order.extend(self.entries.iter().map(|e| e.cells.id));
        self.items.clear();
        self.items.extend(self.entries.iter().map(|e| e.cells));
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
            let here = &self.items[lo..hi];
            pass.across(&self.active[active_lo..], here);
            pass.within(here);
            return;
        }

        // This node's misfits come first in its run.
        let mid = lo + self.entries[lo..hi].partition_point(|e| e.level() == level);
        let misfits = &self.items[lo..mid];
        pass.across(&self.active[active_lo..], misfits);
        pass.within(misfits);

        // Children's runs, by the two key bits that choose the quadrant.
        let shift = LEVEL_BITS + 2 * (GRID_LEVELS - level - 1);
        let child_of = |e: &Entry| ((e.key >> shift) & 3) as usize;
        let run = &self.entries[mid..hi];
        let split = |c: usize| mid + run.partition_point(|e| child_of(e) < c);
        let bounds = [mid, split(1), split(2), split(3), hi];

        let own_hi = self.active.len() + (mid - lo);
        self.active.extend_from_slice(&self.items[lo..mid]);
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
}

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

    /// Every pair within `items`.
    fn within(&mut self, items: &[Cells]) {
        let n = items.len() as u64;
        self.counts.candidates += n * n.saturating_sub(1) / 2;
        for (k, a) in items.iter().enumerate() {
            for b in &items[k + 1..] {
                if a.overlaps(b) {
                    self.hit(a.id, b.id);
                }
            }
        }
    }

    /// Every pair with one item from `xs` and one from `ys`.
    fn across(&mut self, xs: &[Cells], ys: &[Cells]) {
        self.counts.candidates += xs.len() as u64 * ys.len() as u64;
        for a in xs {
            for b in ys {
                if a.overlaps(b) {
                    self.hit(a.id, b.id);
                }
            }
        }
    }
}

impl Detector for Quadtree {
    fn name(&self) -> &'static str {
        "quadtree"
    }

    fn detect(&mut self, lines: &[Line], dt: f64, events: &mut Vec<Event>) {
        let before = events.len();
        self.boxes.compute(lines, dt);
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
        };
        if let Some(bounds) = self.boxes.bounds {
            self.arrange(&Grid::over(&bounds));
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
            id: 0,
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
        let b = SweptBox {
            min_x: 0.5,
            min_y: 0.5,
            max_x: 1.0,
            max_y: 1.0,
        };
        let g = Grid::over(&b);
        let c = g.cells(&b, 3);
        assert_eq!(c.id, 3);
        assert!(c.x0 > 0 && c.x0 < 2048 && c.x1 > 63000 && c.x1 < u16::MAX);
        let mid = g.cells(
            &SweptBox {
                min_x: 0.75,
                min_y: 0.75,
                max_x: 0.75,
                max_y: 0.75,
            },
            0,
        );
        assert_eq!((mid.x0, mid.y0), (32768, 32768));
        // The root grows to hold lines far outside the box; the middle stays.
        let far = Grid::over(&SweptBox {
            min_x: -3.0,
            min_y: 0.6,
            max_x: 0.9,
            max_y: 0.9,
        });
        let c = far.cells(
            &SweptBox {
                min_x: -3.0,
                min_y: 0.75,
                max_x: 0.75,
                max_y: 0.75,
            },
            0,
        );
        assert!(c.x0 < 4000 && c.x1 == 32768 && c.y0 == 32768);
        // Values past the edge (rounding) saturate.
        let edge = g.cells(
            &SweptBox {
                min_x: -1e9,
                min_y: 0.7,
                max_x: 1e9,
                max_y: 0.7,
            },
            0,
        );
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
