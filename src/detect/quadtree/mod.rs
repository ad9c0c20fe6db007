//! The quadtree detector: the design write-up's tree (see [`tree`]), used in
//! one of two ways, or in whichever of the two is faster at the moment.
//!
//! - **Cached** (the default): each line gets a *fat hull*, its swept hull
//!   grown by a few steps' worth of its motion. The tree is built over fat
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
//!
//! - **Auto** (the default): the cached way, except while the rebuilt way is
//!   measured to be faster. Scenes where lines change course all the time
//!   (dense collisions) wear out fat hulls faster than they pay off. Every
//!   [`PERIOD`] steps the detector runs the other way for a few steps and
//!   keeps whichever took less time per step.
//!
//! All find exactly the all-pairs detector's events, so the choice affects
//! speed only, never results. The buffers live in the detector and are
//! reused: once they have grown to the scene's size, a step allocates
//! nothing.

pub mod tree;

use super::swept::{
    test_pair, test_wild, Class, PairCounts, SweptBox, SweptBoxes, DIAGONAL_X, DIAGONAL_Y,
};
use super::{Detector, DetectorStats};
use crate::line::{Line, BOX_MAX, BOX_MIN};
use crate::narrow::Event;
use std::fmt;
use std::str::FromStr;
use std::time::Instant;
use tree::{Grid, Tree};

/// Default for the largest number of lines a leaf holds before it splits.
pub const DEFAULT_LEAF_SIZE: usize = 16;
/// Default for the deepest level a node may split at.
pub const DEFAULT_MAX_DEPTH: u32 = 12;

/// Steps of a line's motion that its fat hull has room for. (Lines moving
/// alike leave their hulls together and bring a rebuild, which is cheaper
/// than refitting them one by one.)
const FAT_STEPS: f64 = 8.0;
/// The least margin of a fat hull, in box units (about a fifth of a pixel).
const FAT_MIN: f64 = 1.0 / 4096.0;
/// The cache is rebuilt from scratch when more than this share of the lines
/// leave their fat hulls in one step.
const REBUILD_SHARE: usize = 4;

/// How the quadtree detector keeps its tree from step to step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum TreeMode {
    /// Cached, or rebuilt while that is measured to be faster.
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
        Self::ALL
            .iter()
            .copied()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                let names: Vec<_> = Self::ALL.iter().map(|m| m.name()).collect();
                format!(
                    "unknown tree mode `{s}`; expected one of: {}",
                    names.join(", ")
                )
            })
    }
}

/// Auto mode: steps between two trials of the way not in use.
pub const PERIOD: u64 = 256;
/// Auto mode: steps each trial lasts.
const TRIAL: u64 = 16;
/// Auto mode: first steps of a stint left out of its timing (a switch to
/// the cached way starts with a rebuild).
const WARM_UP: u64 = 2;

/// Auto mode's bookkeeping: which way is preferred, and the time per step
/// of each way in the current period.
#[derive(Debug, Default)]
struct Chooser {
    prefer_rebuilt: bool,
    steps: u64,
    /// Seconds and steps timed: index 0 for the trial, 1 for the rest.
    timed: [(f64, u32); 2],
}

impl Chooser {
    /// Whether this step should use the rebuilt way.
    fn rebuilt_now(&self) -> bool {
        let trial = self.steps % PERIOD < TRIAL;
        self.prefer_rebuilt != trial
    }

    /// Records this step's detection time; at the end of a period, keeps
    /// the faster way (the trial must win by 5% to take over).
    fn record(&mut self, seconds: f64) {
        let phase = self.steps % PERIOD;
        let (slot, into_stint) = if phase < TRIAL {
            (0, phase)
        } else {
            (1, phase - TRIAL)
        };
        if into_stint >= WARM_UP {
            self.timed[slot].0 += seconds;
            self.timed[slot].1 += 1;
        }
        if phase == PERIOD - 1 {
            let mean = |(t, n): (f64, u32)| (n > 0).then(|| t / f64::from(n));
            if let (Some(trial), Some(rest)) = (mean(self.timed[0]), mean(self.timed[1])) {
                if trial < 0.95 * rest {
                    self.prefer_rebuilt = !self.prefer_rebuilt;
                }
            }
            self.timed = [(0.0, 0); 2];
        }
        self.steps += 1;
    }
}

/// A quadtree broad phase.
#[derive(Debug)]
pub struct Quadtree {
    tree: Tree,
    mode: TreeMode,
    chooser: Chooser,
    boxes: SweptBoxes,
    grid: Grid,
    /// Each line's swept hull this step, by id.
    hull: Vec<SweptBox>,
    /// Rebuilt mode: ids of the boxed lines in last step's key order.
    order: Vec<u32>,
    /// Cached mode: each line's fat hull, by id.
    fat: Vec<SweptBox>,
    /// Cached mode: whether each line is in the tree and the pair cache.
    in_cache: Vec<bool>,
    /// Cached mode: whether each line left its fat hull this step.
    is_moved: Vec<bool>,
    /// Cached mode: the lines that left their fat hulls this step.
    moved: Vec<u32>,
    /// Cached mode: every pair of cached lines whose fat hulls overlap.
    pairs: Vec<(u32, u32)>,
    /// Cached mode: whether the tree and the pairs can be updated rather
    /// than rebuilt.
    valid: bool,
    stats: DetectorStats,
}

impl Default for Quadtree {
    fn default() -> Self {
        Self::new(DEFAULT_LEAF_SIZE, DEFAULT_MAX_DEPTH, TreeMode::Auto)
    }
}

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

impl Quadtree {
    /// A quadtree whose leaves hold at most `leaf_size` lines (at least 1)
    /// unless `max_depth` (at most [`tree::GRID_LEVELS`]) stops the
    /// splitting, kept from step to step as `mode` says.
    pub fn new(leaf_size: usize, max_depth: u32, mode: TreeMode) -> Self {
        Self {
            tree: Tree::new(leaf_size, max_depth),
            mode,
            chooser: Chooser::default(),
            boxes: SweptBoxes::default(),
            grid: Grid::over(&SweptBox {
                min_x: BOX_MIN,
                min_y: BOX_MIN,
                max_x: BOX_MAX,
                max_y: BOX_MAX,
                ..SweptBox::default()
            }),
            hull: Vec::new(),
            order: Vec::new(),
            fat: Vec::new(),
            in_cache: Vec::new(),
            is_moved: Vec::new(),
            moved: Vec::new(),
            pairs: Vec::new(),
            valid: false,
            stats: DetectorStats::default(),
        }
    }

    /// Classifies the lines and records every boxed line's swept hull (and,
    /// in cached mode with a valid cache, which lines left their fat hulls).
    fn compute_hulls(&mut self, lines: &[Line], dt: f64, cached: bool) {
        let n = lines.len();
        self.hull.resize(n, SweptBox::default());
        self.moved.clear();
        let (hull, moved, fat) = (&mut self.hull, &mut self.moved, &self.fat);
        let check = cached && self.valid;
        self.boxes.compute(lines, dt, |id, b| {
            hull[id as usize] = *b;
            if check && !holds(&fat[id as usize], b) {
                moved.push(id);
            }
        });
    }

    /// Rebuilt mode: builds the tree over this step's swept hulls and tests
    /// its pairs.
    fn detect_rebuilt(
        &mut self,
        lines: &[Line],
        dt: f64,
        events: &mut Vec<Event>,
        counts: &mut PairCounts,
    ) {
        let Some(bounds) = self.boxes.bounds else {
            return;
        };
        if !self.grid.holds(&bounds) {
            self.grid = Grid::over(&bounds);
        }
        let (grid, hull, class) = (self.grid, &self.hull, &self.boxes.class);
        let max_depth = self.tree.max_depth();
        let entries = &mut self.tree.entries;
        entries.clear();
        let entry = |id: u32| {
            let cells = grid.cells(&hull[id as usize], id);
            tree::Entry {
                key: tree::key(&cells, max_depth),
                cells,
            }
        };
        // Last step's order is nearly sorted: start from it unless the set
        // of boxed lines changed.
        entries.extend(
            self.order
                .iter()
                .filter(|&&id| class.get(id as usize) == Some(&Class::Boxed))
                .map(|&id| entry(id)),
        );
        if entries.len() != self.boxes.boxed {
            entries.clear();
            entries.extend(
                (0..class.len() as u32)
                    .filter(|&id| class[id as usize] == Class::Boxed)
                    .map(entry),
            );
        }
        self.tree.sort();
        self.order.clear();
        self.order
            .extend(self.tree.entries.iter().map(|e| e.cells.id));
        let magnitude = &self.boxes.magnitude;
        self.tree
            .pairs(&mut |a, b| test_pair(lines, magnitude, a, b, dt, events, counts));
    }

    /// Cached mode: brings the tree and the pairs up to date, then tests the
    /// pairs whose swept hulls overlap.
    fn detect_cached(
        &mut self,
        lines: &[Line],
        dt: f64,
        events: &mut Vec<Event>,
        counts: &mut PairCounts,
    ) {
        let n = lines.len();
        self.fat.resize(n, SweptBox::default());
        self.in_cache.resize(n, false);
        self.is_moved.resize(n, false);

        if self.valid {
            let class = &self.boxes.class;
            let same_lines = self
                .in_cache
                .iter()
                .zip(class)
                .all(|(&cached, &c)| cached == (c == Class::Boxed));
            self.valid = same_lines && self.moved.len() <= n / REBUILD_SHARE;
        }
        if self.valid {
            for &m in &self.moved {
                self.fat[m as usize] = fatten(&self.hull[m as usize], &lines[m as usize], dt);
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
        } else {
            self.stats.rebuilds += 1;
            self.rebuild_cache(lines, dt);
        }

        let (hull, magnitude) = (&self.hull, &self.boxes.magnitude);
        counts.candidates += self.pairs.len() as u64;
        for &(a, b) in &self.pairs {
            if hull[a as usize].overlaps(&hull[b as usize]) {
                test_pair(lines, magnitude, a, b, dt, events, counts);
            }
        }
    }

    /// Rebuilds the tree over fresh fat hulls of every boxed line, and the
    /// pairs from it.
    fn rebuild_cache(&mut self, lines: &[Line], dt: f64) {
        self.pairs.clear();
        let class = &self.boxes.class;
        // The tree's entries are last step's lines in key order: keep that
        // order (nearly sorted still) unless the set of lines changed.
        let same_lines = self.tree.entries.len() == self.boxes.boxed
            && self
                .tree
                .entries
                .iter()
                .all(|e| class[e.cells.id as usize] == Class::Boxed);
        for (id, cached) in self.in_cache.iter_mut().enumerate() {
            *cached = class[id] == Class::Boxed;
        }
        let Some(mut bounds) = self.boxes.bounds else {
            self.tree.entries.clear();
            self.valid = true;
            return;
        };
        for id in (0..class.len()).filter(|&id| class[id] == Class::Boxed) {
            self.fat[id] = fatten(&self.hull[id], &lines[id], dt);
            bounds = bounds.union(&self.fat[id]);
        }
        if !self.grid.holds(&bounds) {
            self.grid = Grid::over(&bounds);
        }
        let (grid, fat) = (self.grid, &self.fat);
        let max_depth = self.tree.max_depth();
        if same_lines {
            for e in &mut self.tree.entries {
                e.cells = grid.cells(&fat[e.cells.id as usize], e.cells.id);
                e.key = tree::key(&e.cells, max_depth);
            }
        } else {
            self.tree.entries.clear();
            for id in (0..class.len()).filter(|&id| class[id] == Class::Boxed) {
                let cells = grid.cells(&fat[id], id as u32);
                let key = tree::key(&cells, max_depth);
                self.tree.entries.push(tree::Entry { key, cells });
            }
        }
        self.tree.sort();
        let pairs = &mut self.pairs;
        self.tree
            .pairs(&mut |a, b| pairs.push(if a < b { (a, b) } else { (b, a) }));
        self.valid = true;
    }

    /// Moves the lines that left their fat hulls (their new fat hulls are
    /// set): new cells and keys, their old pairs out, their new pairs in.
    fn update_cache(&mut self) {
        if self.moved.is_empty() {
            return;
        }
        for &m in &self.moved {
            self.is_moved[m as usize] = true;
        }
        let (grid, fat, is_moved) = (self.grid, &self.fat, &self.is_moved);
        let max_depth = self.tree.max_depth();
        for e in &mut self.tree.entries {
            let id = e.cells.id;
            if is_moved[id as usize] {
                e.cells = grid.cells(&fat[id as usize], id);
                e.key = tree::key(&e.cells, max_depth);
            }
        }
        self.tree.sort();
        self.pairs
            .retain(|&(a, b)| !is_moved[a as usize] && !is_moved[b as usize]);
        for &m in &self.moved {
            let probe = grid.cells(&fat[m as usize], m);
            let pairs = &mut self.pairs;
            // A pair of two moved lines is taken from the lower id's query.
            self.tree.query(&probe, |j| {
                if j != m && (!is_moved[j as usize] || j > m) {
                    pairs.push(if m < j { (m, j) } else { (j, m) });
                }
            });
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
        self.compute_hulls(lines, dt, !rebuilt);
        let mut counts = PairCounts::default();
        test_wild(lines, &self.boxes, dt, events, &mut counts);
        self.tree.counts = tree::WalkCounts::default();
        if rebuilt {
            // The tree now holds swept hulls: the cache must be rebuilt
            // before it is used again.
            self.valid = false;
            self.detect_rebuilt(lines, dt, events, &mut counts);
        } else {
            self.detect_cached(lines, dt, events, &mut counts);
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
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chooser_tries_the_other_way_then_keeps_the_faster() {
        let mut c = Chooser::default();
        let mut rebuilt_steps = 0;
        for _ in 0..PERIOD {
            let rebuilt = c.rebuilt_now();
            rebuilt_steps += u64::from(rebuilt);
            // Rebuilding is twice as fast here.
            c.record(if rebuilt { 1.0 } else { 2.0 });
        }
        assert_eq!(rebuilt_steps, TRIAL);
        assert!(c.prefer_rebuilt);
        // Now the cached way is the trial, and it stays slower.
        for _ in 0..PERIOD {
            let rebuilt = c.rebuilt_now();
            c.record(if rebuilt { 1.0 } else { 2.0 });
        }
        assert!(c.prefer_rebuilt);
        // A near tie does not switch.
        for _ in 0..PERIOD {
            let rebuilt = c.rebuilt_now();
            c.record(if rebuilt { 1.0 } else { 0.98 });
        }
        assert!(c.prefer_rebuilt);
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
