//! The quadtree detector of the design write-up, rebuilt every step in flat
//! buffers.
//!
//! The root covers the swept boxes of all lines. A node holding more than
//! `leaf_size` lines, and shallower than `max_depth`, splits its region into
//! four quadrants: a line whose swept box fits in one quadrant goes down to
//! it, the others stay at the node as *misfits*. A node's misfits are tested
//! against each other and against every line below the node; a leaf tests
//! its own pairs. Each pair is therefore tested exactly once, at the deepest
//! node holding both lines.
//!
//! Two refinements over the write-up keep this fast:
//! - misfits from above travel down the tree as an *active list* that each
//!   child filters by its own region, so a misfit is only compared with the
//!   lines of quadrants its box reaches;
//! - the tree is never stored: each node partitions its slice of one item
//!   buffer into misfits and four quadrant runs (ping-ponging between two
//!   buffers), tests what it must, and recurses into the runs. Once the
//!   buffers have grown to the scene's size, a step allocates nothing.

use super::swept::{test_pair, test_wild, Item, PairCounts, Rect, SweptBoxes};
use super::{Detector, DetectorStats};
use crate::line::Line;
use crate::narrow::Event;

/// Default for the largest number of lines a leaf holds before it splits.
pub const DEFAULT_LEAF_SIZE: usize = 16;
/// Default for the deepest level a node may split at.
pub const DEFAULT_MAX_DEPTH: u32 = 12;

/// A quadtree broad phase, rebuilt each step.
#[derive(Debug)]
pub struct Quadtree {
    leaf_size: usize,
    max_depth: u32,
    boxes: SweptBoxes,
    /// Items in node order; `spare` receives each level's partition.
    items: Vec<Item>,
    spare: Vec<Item>,
    /// Misfits of the nodes above the current one, filtered by region.
    active: Vec<Item>,
    stats: DetectorStats,
}

impl Default for Quadtree {
    fn default() -> Self {
        Self::new(DEFAULT_LEAF_SIZE, DEFAULT_MAX_DEPTH)
    }
}

impl Quadtree {
    /// A quadtree whose leaves hold at most `leaf_size` lines (at least 1)
    /// unless `max_depth` stops the splitting first.
    pub fn new(leaf_size: usize, max_depth: u32) -> Self {
        Self {
            leaf_size: leaf_size.max(1),
            max_depth,
            boxes: SweptBoxes::default(),
            items: Vec::new(),
            spare: Vec::new(),
            active: Vec::new(),
            stats: DetectorStats::default(),
        }
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
    max_depth_seen: u32,
}

impl Pass<'_> {
    #[inline]
    fn pair(&mut self, a: &Item, b: &Item) {
        self.counts.candidates += 1;
        if a.overlaps(b) {
            test_pair(
                self.lines,
                self.magnitude,
                a.id,
                b.id,
                self.dt,
                self.events,
                &mut self.counts,
            );
        }
    }

    /// Every pair within `items`.
    fn within(&mut self, items: &[Item]) {
        for (k, a) in items.iter().enumerate() {
            for b in &items[k + 1..] {
                self.pair(a, b);
            }
        }
    }

    /// Every pair with one item from `xs` and one from `ys`.
    fn across(&mut self, xs: &[Item], ys: &[Item]) {
        for a in xs {
            for b in ys {
                self.pair(a, b);
            }
        }
    }
}

/// Which quadrant of `r` (split at `mid`) holds the box, or 4 for a misfit.
#[inline]
fn quadrant(it: &Item, mid_x: f32, mid_y: f32) -> usize {
    let x = if it.max_x < mid_x {
        0
    } else if it.min_x >= mid_x {
        1
    } else {
        return 4;
    };
    let y = if it.max_y < mid_y {
        0
    } else if it.min_y >= mid_y {
        2
    } else {
        return 4;
    };
    x + y
}

/// The four quadrants of `r`, in the order [`quadrant`] numbers them.
fn quadrants(r: &Rect, mid_x: f32, mid_y: f32) -> [Rect; 4] {
    [
        Rect {
            max_x: mid_x,
            max_y: mid_y,
            ..*r
        },
        Rect {
            min_x: mid_x,
            max_y: mid_y,
            ..*r
        },
        Rect {
            max_x: mid_x,
            min_y: mid_y,
            ..*r
        },
        Rect {
            min_x: mid_x,
            min_y: mid_y,
            ..*r
        },
    ]
}

impl Quadtree {
    /// Visits the node whose lines are `items[lo..hi]` (in the buffer chosen
    /// by `flip`), with region `region` at `depth`; the misfits of the nodes
    /// above that reach this region are `active[active_lo..]`.
    #[allow(clippy::too_many_arguments)]
    fn visit(
        &mut self,
        pass: &mut Pass,
        flip: bool,
        lo: usize,
        hi: usize,
        region: Rect,
        depth: u32,
        active_lo: usize,
    ) {
        pass.nodes += 1;
        pass.max_depth_seen = pass.max_depth_seen.max(depth);
        let (src, dst) = if flip {
            (&mut self.spare, &mut self.items)
        } else {
            (&mut self.items, &mut self.spare)
        };

        if hi - lo <= self.leaf_size || depth >= self.max_depth {
            let here = &src[lo..hi];
            pass.across(&self.active[active_lo..], here);
            pass.within(here);
            return;
        }

        // Partition into [misfits | q0 | q1 | q2 | q3] by counting.
        let mid_x = region.min_x + (region.max_x - region.min_x) * 0.5;
        let mid_y = region.min_y + (region.max_y - region.min_y) * 0.5;
        let mut counts = [0usize; 5];
        for it in &src[lo..hi] {
            counts[quadrant(it, mid_x, mid_y)] += 1;
        }
        let mut start = [0usize; 5];
        start[4] = lo;
        start[0] = lo + counts[4];
        for q in 1..4 {
            start[q] = start[q - 1] + counts[q - 1];
        }
        let bounds = [start[0], start[1], start[2], start[3], hi];
        let mut next = start;
        for it in &src[lo..hi] {
            let q = quadrant(it, mid_x, mid_y);
            dst[next[q]] = *it;
            next[q] += 1;
        }

        let misfits = &dst[lo..start[0]];
        pass.across(&self.active[active_lo..], misfits);
        pass.within(misfits);

        // The children see this node's misfits as active too.
        let own_lo = self.active.len();
        self.active.extend_from_slice(misfits);
        let own_hi = self.active.len();
        for (q, child) in quadrants(&region, mid_x, mid_y).into_iter().enumerate() {
            let (c_lo, c_hi) = (bounds[q], bounds[q + 1]);
            if c_lo == c_hi {
                continue;
            }
            let child_active = self.active.len();
            for k in active_lo..own_hi {
                // Ancestors' misfits already passed this node's filter;
                // filter them and this node's own misfits by the quadrant.
                let it = self.active[k];
                if it.overlaps_rect(&child) {
                    self.active.push(it);
                }
            }
            self.visit(pass, !flip, c_lo, c_hi, child, depth + 1, child_active);
            self.active.truncate(child_active);
        }
        self.active.truncate(own_lo);
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

        // The fresh items become the tree's buffer; the old buffer goes back
        // to be refilled next step.
        std::mem::swap(&mut self.items, &mut self.boxes.items);
        self.spare.resize(self.items.len(), Item::default());
        self.active.clear();
        let magnitude = std::mem::take(&mut self.boxes.magnitude);
        let mut pass = Pass {
            lines,
            magnitude: &magnitude,
            dt,
            events,
            counts,
            nodes: 0,
            max_depth_seen: 0,
        };
        if let Some(root) = Rect::around(&self.items) {
            let n = self.items.len();
            self.visit(&mut pass, false, 0, n, root, 0, 0);
        }

        self.stats.candidate_pairs += pass.counts.candidates;
        self.stats.exact_tests += pass.counts.exact;
        self.stats.nodes += pass.nodes;
        self.stats.max_depth = self.stats.max_depth.max(pass.max_depth_seen);
        self.stats.events += (events.len() - before) as u64;
        self.boxes.magnitude = magnitude;
    }

    fn stats(&self) -> DetectorStats {
        self.stats
    }
}
