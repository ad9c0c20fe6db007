//! The pair walk: every pair of lines whose cells overlap, once, at the
//! deepest node holding both. A node finds its children's runs by binary
//! search over the keys (by a scan for short runs), and the misfits from
//! above travel down as an *active list* that each child filters by its
//! cell block, so a misfit meets only the quadrants its hull reaches.

use super::entries::Entry;
use super::grid::{Block, Cells, GRID_LEVELS, LEVEL_BITS};
use crate::team::{Parts, Team, MAX_PIECES};

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

/// Below this many lines in a node's pair set, plain loops beat sorting.
const SWEEP_MIN: usize = 48;

/// In the pairs walk, runs of up to this many entries are split by reading
/// them in order, not by binary search: a scan reads ahead (and the walk
/// goes on to read every entry of the run anyway, which the scan has
/// brought into the cache), where a search waits on one cache miss after
/// another.
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
pub(super) struct Scratch {
    active: Vec<Cells>,
    /// The active lines that reach a node's own lines.
    near: Vec<Cells>,
    sweep: Vec<Probe>,
    counts: WalkCounts,
}

/// A walk's fixed settings, shared by its tasks.
pub(super) struct Walk<'t> {
    entries: &'t [Entry],
    leaf_size: usize,
    max_depth: u32,
    /// Subtrees of at least this many lines are split among threads; zero
    /// for a serial walk.
    parallel_min: usize,
    /// Runs up to this long are split by scanning (see [`SCAN_MAX`]).
    scan_max: usize,
}

impl<'t> Walk<'t> {
    /// A walk over `entries` (sorted) of a tree whose leaves hold at most
    /// `leaf_size` lines unless `max_depth` stops the splitting. With
    /// `threads` above 1 and at least `grain` lines, subtrees are walked in
    /// tasks (see [`Walk::run`]), none smaller than `grain / 16` lines.
    pub(super) fn new(
        entries: &'t [Entry],
        leaf_size: usize,
        max_depth: u32,
        threads: usize,
        grain: usize,
    ) -> Self {
        let n = entries.len();
        Walk {
            entries,
            leaf_size,
            max_depth,
            // Enough tasks to balance the threads, none too small to pay;
            // a tree of less than a grain of lines stays on one thread,
            // where waking the pool costs more than sharing the walk saves
            // (docs/DESIGN.md, "The thread team").
            parallel_min: if threads > 1 && n >= grain {
                (n / (8 * threads)).max(grain / 16).max(1)
            } else {
                0
            },
            scan_max: SCAN_MAX,
        }
    }

    /// Hands `collector` once every pair of lines whose cells overlap;
    /// returns what the walk did. Given a `team` and a tree large enough,
    /// the walk is split into tasks that the team's threads claim.
    pub(super) fn run<C: Collector>(
        &self,
        scratch: &mut Scratch,
        collector: &mut C,
        team: Option<&Team>,
    ) -> WalkCounts {
        scratch.active.clear();
        scratch.counts = WalkCounts::default();
        let n = self.entries.len();
        match team.filter(|_| self.parallel_min > 0) {
            _ if n == 0 => {}
            Some(team) => self.run_shared(team, scratch, collector),
            None => self.visit(scratch, collector, 0, n, 0, Block::root(), 0),
        }
        scratch.counts
    }

    /// The walk as tasks on `team`: the nodes too large for one task are
    /// visited here, each handing its own misfits' pairs and its children
    /// on as tasks; each task gets its own buffers and collector, merged
    /// back in the tasks' order.
    fn run_shared<C: Collector>(&self, team: &Team, scratch: &mut Scratch, collector: &mut C) {
        let mut tasks = Vec::new();
        let root = Task {
            lo: 0,
            hi: self.entries.len(),
            level: 0,
            block: Block::root(),
            active: Vec::new(),
            whole: true,
        };
        self.plan(&mut scratch.counts, &mut tasks, root);
        let mut tasks = tasks.into_iter();
        loop {
            // Each task moved out to the piece that runs it, with a fresh
            // collector.
            let batch: Vec<(Task, C)> = (tasks.by_ref().take(MAX_PIECES))
                .map(|task| (task, collector.fork()))
                .collect();
            if batch.is_empty() {
                break;
            }
            let pieces = batch.len();
            let mut done: Vec<Option<(Scratch, C)>> = (0..pieces).map(|_| None).collect();
            let outs = Parts::new(done.iter_mut());
            let work = Parts::new(batch);
            team.run_pieces(pieces, &|k| {
                let (task, mut collector) = work.take(k);
                let mut sub = Scratch {
                    active: task.active,
                    ..Scratch::default()
                };
                match task.whole {
                    true => self.visit(
                        &mut sub,
                        &mut collector,
                        task.lo,
                        task.hi,
                        task.level,
                        task.block,
                        0,
                    ),
                    false => {
                        node_pairs(&mut sub, &mut collector, 0, &self.entries[task.lo..task.hi])
                    }
                }
                *outs.take(k) = Some((sub, collector));
            });
            for (sub, sub_collector) in done.into_iter().flatten() {
                scratch.counts.add(&sub.counts);
                collector.join(sub_collector);
            }
        }
    }

    /// Splits the node `task` names into tasks: whole if it is small
    /// enough (or a leaf), else its own misfits' pairs and its children's
    /// tasks, counting the node here.
    fn plan(&self, counts: &mut WalkCounts, tasks: &mut Vec<Task>, task: Task) {
        let (lo, hi, level) = (task.lo, task.hi, task.level);
        let leaf = hi - lo <= self.leaf_size || level >= self.max_depth;
        let mid = if leaf {
            hi
        } else {
            lo + self.misfits_end(lo, hi, level)
        };
        if leaf || hi - mid < self.parallel_min {
            tasks.push(task);
            return;
        }
        counts.nodes += 1;
        counts.deepest = counts.deepest.max(level);
        let mut reaching = task.active;
        if mid > lo {
            tasks.push(Task {
                hi: mid,
                active: reaching.clone(),
                whole: false,
                ..task
            });
        }
        reaching.extend(self.entries[lo..mid].iter().map(|e| e.cells));
        let bounds = self.child_runs(mid, hi, level);
        for c in (0..4).filter(|&c| bounds[c] < bounds[c + 1]) {
            let block = task.block.child(c);
            let mut active = reaching.clone();
            retain_from(&mut active, 0, |it| it.overlaps_block(&block));
            let child = Task {
                lo: bounds[c],
                hi: bounds[c + 1],
                level: level + 1,
                block,
                active,
                whole: true,
            };
            self.plan(counts, tasks, child);
        }
    }
}

/// A piece of a shared walk: the subtree of `entries[lo..hi]` at `level`
/// covering `block` (`whole`), or a node's own misfits there, with the
/// misfits from above that reach it.
struct Task {
    lo: usize,
    hi: usize,
    level: u32,
    block: Block,
    active: Vec<Cells>,
    whole: bool,
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
}
