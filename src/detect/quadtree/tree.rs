//! The quadtree as one sorted array of entries, and what it keeps between
//! steps.
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
//!
//! Its parts, in the order a step uses them: [`super::grid`] (cells and
//! keys), [`super::entries`] (the entries kept sorted), [`super::walk`]
//! (the pair walk).

use super::entries::Entries;
use super::grid::GRID_LEVELS;
use super::walk::{Collector, Scratch, Walk, WalkCounts};
use crate::team::Team;

/// The quadtree over a set of lines: their entries in key order and the
/// buffers of the walks, reused from call to call.
#[derive(Debug)]
pub struct Tree {
    pub(super) leaf_size: usize,
    pub(super) max_depth: u32,
    /// The lines' entries, kept in key order.
    pub entries: Entries,
    /// The walks' buffers.
    scratch: Scratch,
    /// What the walks have done.
    pub counts: WalkCounts,
}

impl Tree {
    /// An empty tree whose leaves hold at most `leaf_size` lines (at least
    /// 1) unless `max_depth` (at most [`GRID_LEVELS`]) stops the splitting.
    pub fn new(leaf_size: usize, max_depth: u32) -> Self {
        Self {
            leaf_size: leaf_size.max(1),
            max_depth: max_depth.min(GRID_LEVELS),
            entries: Entries::default(),
            scratch: Scratch::default(),
            counts: WalkCounts::default(),
        }
    }

    /// The depth limit in force.
    pub fn max_depth(&self) -> u32 {
        self.max_depth
    }

    /// Hands `collector` once every pair of lines whose cells overlap
    /// (entries must be sorted), shared among `team` for trees of at least
    /// `grain` lines (see [`Walk::new`]).
    pub fn pairs<C: Collector>(&mut self, collector: &mut C, team: Option<&Team>, grain: usize) {
        let entries = &self.entries.list;
        let threads = team.map_or(1, Team::threads);
        let walk = Walk::new(entries, self.leaf_size, self.max_depth, threads, grain);
        let counts = walk.run(&mut self.scratch, collector, team);
        self.counts.add(&counts);
    }
}
