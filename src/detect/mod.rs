//! Broad-phase collision detection: every detector finds exactly the events
//! the all-pairs loop finds, each by its own route.
//!
//! A detector receives the lines at the start of a step, as the world
//! stores them ([`Stored`]), and hands every pair it cannot rule out to the
//! world's sink ([`Findings`]), which tests it exactly and keeps one event
//! for every pair whose [`intersect`](crate::narrow::intersect) is not
//! `None`; the world resolves them. The all-pairs [`Brute`] detector is the
//! oracle the others are tested against.
//!
//! Adding a detector: its own folder or file here, and its line in
//! [`DetectorKind`] (name, constructor, and its place in
//! [`DetectorKind::ALL`], the one list every front end reads).

mod brute;
pub(crate) mod clock;
pub(crate) mod pairs;
mod quadtree;
pub(crate) mod sweep;
pub(crate) mod swept;

pub use crate::schedule::DEFAULT_GRAIN;
pub use brute::Brute;
pub use quadtree::{Quadtree, DEFAULT_LEAF_SIZE, DEFAULT_MAX_DEPTH};
pub use sweep::Sweep;
pub use swept::swept_box;

use crate::index::Slot;
use crate::line::Line;
use crate::team::Team;
pub(crate) use pairs::{Findings, PairCounts, Stored};
use std::fmt;
use std::time::Duration;

/// Counters of the broad phase's work, summed over all steps: the pair
/// counts the world's sink keeps, and the tree's own.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DetectorStats {
    /// Pairs the broad phase looked at (bounding boxes compared).
    pub candidate_pairs: u64,
    /// Pairs handed to the exact `intersect` test.
    pub exact_tests: u64,
    /// Events found.
    pub events: u64,
    /// Tree nodes built (zero for detectors without a tree).
    pub nodes: u64,
    /// Deepest tree level reached (zero for detectors without a tree).
    pub max_depth: u32,
}

/// A broad phase: finds every colliding pair of lines for one step.
pub(crate) trait Detector: Send {
    /// Hands `found` every pair of `stored`'s lines whose
    /// `intersect(.., dt)` may not be `None` (to its
    /// [`Findings::test`], or the exact test alone), and counts the
    /// candidate pairs it compared ([`Findings::met`]). Must not change any
    /// line, and must let through every pair the all-pairs detector finds
    /// an event for. A detector that never gives a
    /// [`Handover::order`] is only handed lines stored by id.
    fn detect(&mut self, stored: Stored<'_>, dt: f64, found: &mut Findings);

    /// The world's last phase of a step: moves every line by its velocity
    /// for a step and bounces it off the walls
    /// ([`advance_and_bounce`](crate::motion::advance_and_bounce)), on
    /// `shared`'s team in as many pieces where the world shares the
    /// phase; returns the lines that hit a wall. The world calls it where
    /// it leaves the lines in their slots ([`Detector::hand_over`] gave no
    /// order), so a detector may make its next step's boxes in the same
    /// pass, while each line is at hand.
    fn advance(&mut self, lines: &mut [Line], shared: Option<(&Team, usize)>) -> u64 {
        crate::motion::advance(lines, shared)
    }

    /// Asked once after each step's detection: what the world does with
    /// the lines this step ([`Handover`]). By default it leaves them where
    /// they are, and shares its own phases where the schedule says so.
    fn hand_over(&mut self) -> Handover {
        Handover {
            order: None,
            shares_step: true,
        }
    }

    /// What the detector says of its work so far, as data ([`Report`]).
    fn report(&self) -> Report {
        Report::default()
    }

    /// Hands the detector the world's settings: whether its own phases
    /// are timed, and the team the world steps with (`None`: one thread),
    /// to split its large phases among. Detectors without phases, or that
    /// do not split their work, ignore them.
    fn configure(&mut self, _setup: &Setup) {}
}

/// What the world does with the lines after a step's detection, as the
/// detector asks.
#[derive(Debug)]
pub(crate) struct Handover {
    /// The order to store the lines in from the next step on, when it pays
    /// for the world to store them in the order the detector reads them
    /// (`order[k]` is the slot of the line to store at slot `k`), or
    /// `None` to leave them where they are. The world stores them so as
    /// they move; a detector that gives an order has renumbered the slots
    /// it keeps to match (the line at slot `order[k]` is at slot `k`).
    pub order: Option<Vec<Slot>>,
    /// Whether the world shares its own phases of the step just detected
    /// (resolving and moving) among the team where the schedule says so:
    /// false where the detector ran the step on one thread, its work too
    /// small to hand out, when handing out the world's phases would not
    /// pay either.
    pub shares_step: bool,
}

/// What a detector says of its work so far, as data that `--stats` words.
#[derive(Clone, Debug, Default)]
pub(crate) struct Report {
    /// Its own counters (a tree's nodes and depth); the pair counts are
    /// the world's.
    pub stats: DetectorStats,
    /// The sweep's plan as it stands, and how it kept its pairs.
    pub plan: Option<SweepReport>,
    /// The time spent in each of its own phases since timing was turned
    /// on, by name, in the order they run; together they make up nearly
    /// all of its time. Empty while timing is off.
    pub phases: Vec<(&'static str, Duration)>,
}

/// The sweep's plan as it stands, and how it kept its pairs so far.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SweepReport {
    /// The direction swept along: 0 `x`, 1 `y`, 2 the diagonal `x+y`, 3
    /// the diagonal `x-y`.
    pub along: usize,
    /// Bands the boxes are cut into (1: none).
    pub bands: usize,
    /// The direction the bands are cut across (as `along`).
    pub across: usize,
    /// Steps detected.
    pub steps: u64,
    /// Steps on which pairs were kept or tried.
    pub keeping: u64,
    /// Sweeps among them.
    pub sweeps: u64,
    /// Boxes mended while pairs were kept.
    pub mended: u64,
    /// Sweeps made in a frame moving with the lines.
    pub moving: u64,
}

/// The world's settings a detector is handed ([`Detector::configure`]).
#[derive(Clone, Default)]
pub(crate) struct Setup {
    /// Whether the detector's own phases are timed (off by default: a few
    /// clock reads a step).
    pub timing: bool,
    /// The team the world steps with; `None` for one thread.
    pub team: Option<std::sync::Arc<Team>>,
}

/// The detectors the command line can choose between.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DetectorKind {
    /// Every pair, every step: the reference behaviour and the test oracle.
    Brute,
    /// The write-up's quadtree with misfit lists, rebuilt each step.
    Quadtree,
    /// Sweep and prune: boxes sorted along one direction, in bands where
    /// one direction is not enough.
    Sweep,
}

/// Tuning shared by the detectors (each uses what applies to it).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DetectorConfig {
    /// Most lines a tree leaf holds before it splits.
    pub leaf_size: usize,
    /// Deepest level a tree node may split at.
    pub max_depth: u32,
    /// Threads the worlds made with this configuration
    /// ([`World::with_config`](crate::World::with_config)) start with; 1
    /// keeps everything on the calling thread. A world's
    /// [`World::set_threads`](crate::World::set_threads) changes them, for
    /// the detector too. Results never depend on it.
    pub threads: usize,
    /// The smallest piece of work handed to a thread, in lines (tree walks
    /// split subtrees of a sixteenth of this and up). Speed only.
    pub grain: usize,
    /// Sweep: whether the pairs a sweep finds are kept for the steps
    /// after it (docs/DESIGN.md, "Sweep and prune", near pairs). Speed only.
    pub keep_pairs: KeepPairs,
}

/// When the sweep keeps the pairs it finds for the steps after it,
/// sweeping again only when a line leaves the box it was given: where
/// that pays (the default), always, or never (a sweep every step).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum KeepPairs {
    /// Where the pairs kept are fewer than a sweep meets and hold for a
    /// few steps, judged as the run goes.
    #[default]
    Auto,
    /// Every step it can.
    Always,
    /// Never: a sweep every step.
    Never,
}

impl KeepPairs {
    /// Every choice, in the order they are listed to users.
    pub const ALL: &'static [KeepPairs] = &[KeepPairs::Auto, KeepPairs::Always, KeepPairs::Never];

    /// The choice named `name` ([`KeepPairs::name`]), if one is.
    pub fn from_name(name: &str) -> Option<KeepPairs> {
        Self::ALL.iter().copied().find(|k| k.name() == name)
    }

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            KeepPairs::Auto => "auto",
            KeepPairs::Always => "always",
            KeepPairs::Never => "never",
        }
    }
}

impl DetectorConfig {
    /// Threads to run a scene of `lines` lines on where the caller has no
    /// count of its own: every core, less one for the drawing where the
    /// run is shown `live` and the scene is small enough that a thread
    /// switched out for the drawing would hold up each step.
    pub fn threads_for(lines: usize, live: bool) -> usize {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
        crate::schedule::Schedule::default_threads(cores, live, lines)
    }
}

impl Default for DetectorConfig {
    fn default() -> Self {
        Self {
            leaf_size: DEFAULT_LEAF_SIZE,
            max_depth: DEFAULT_MAX_DEPTH,
            threads: 1,
            grain: DEFAULT_GRAIN,
            keep_pairs: KeepPairs::Auto,
        }
    }
}

impl DetectorKind {
    /// Every detector, in the order they are listed to users.
    pub const ALL: &'static [DetectorKind] = &[
        DetectorKind::Brute,
        DetectorKind::Quadtree,
        DetectorKind::Sweep,
    ];

    /// The detector named `name` ([`DetectorKind::name`]), if one is.
    pub fn from_name(name: &str) -> Option<DetectorKind> {
        Self::ALL.iter().copied().find(|k| k.name() == name)
    }

    /// The detector used when none is named.
    pub const DEFAULT: DetectorKind = DetectorKind::Sweep;

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            DetectorKind::Brute => "brute",
            DetectorKind::Quadtree => "quadtree",
            DetectorKind::Sweep => "sweep",
        }
    }

    /// A fresh detector of this kind with default tuning.
    pub(crate) fn build(self) -> Box<dyn Detector> {
        self.build_with(&DetectorConfig::default())
    }

    /// A fresh detector of this kind with the given tuning.
    pub(crate) fn build_with(self, config: &DetectorConfig) -> Box<dyn Detector> {
        match self {
            DetectorKind::Brute => Box::new(Brute),
            DetectorKind::Quadtree => Box::new(Quadtree::new(config)),
            DetectorKind::Sweep => Box::new(Sweep::new(config)),
        }
    }
}

impl fmt::Display for DetectorKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for &kind in DetectorKind::ALL {
            assert_eq!(DetectorKind::from_name(kind.name()), Some(kind));
        }
        assert_eq!(DetectorKind::from_name("nope"), None);
        for &keep in KeepPairs::ALL {
            assert_eq!(KeepPairs::from_name(keep.name()), Some(keep));
        }
    }
}
