//! Which thread runs what, and when the lines are stored in the detector's
//! order: every threshold that decides it, in one place. Each is a size
//! below which a phase does better on one thread (or the lines where they
//! are) than shared; results never depend on any of them. The figures
//! behind them are in docs/DESIGN.md, "How a step is shared".

use crate::line::LARGE_SCENE;

/// Default for the smallest piece of work handed to a thread, in lines
/// or events, where a phase is cut into many pieces (`--grain`): the
/// quadtree's phases, the tied events' waves, and the move of scenes
/// beyond 256 grains.
pub const DEFAULT_GRAIN: usize = 16 * 1024;

/// The step's thresholds.
pub(crate) struct Schedule;

impl Schedule {
    /// Boxes from which the sweep shares its phases among the team: below
    /// this the hand-offs and the lines' travel between the cores' caches
    /// cost more than the shared work saves (from 384 boxes, two threads
    /// against one: `sin_wave`, 1,180 lines, 0.64x; `box` 0.71x;
    /// generated scenes of 2,000 lines 1.03x, of 4,000 1.08x).
    pub const SWEEP_FROM: usize = 2048;

    /// Lines from which a step that keeps the sweep's pairs (makes the
    /// boxes in slot order and compares the pairs kept) shares them among
    /// the team: that step does a hundred or two instructions a line, so
    /// a scene much smaller is quicker on one thread than handed out
    /// (`mit`, 809 lines, 4000 frames on two threads: 0.060 s shared
    /// against 0.046 on one), and one of a few thousand lines a little
    /// quicker shared (`koch`, 3,900 lines, on two threads 0.043 s shared
    /// against 0.044 on one; medians of 9 rounds).
    pub const KEPT_FROM: usize = 2048;

    /// Lines from which the world's move is shared among the team while
    /// they are in id order: a member's share of the move costs less than
    /// its hand-off only above this. Lines stored in the detector's order
    /// move on the team from [`Schedule::SWEEP_FROM`], each member moving
    /// the lines it reads next.
    pub const MOVE_FROM: usize = 2048;

    /// Grains of work (in lines) up to which the world moves the lines in
    /// one share per thread: 4,194,304 lines at the default grain. Past it
    /// the lines go in pieces of a grain, claimed by whichever thread is
    /// free, so that a thread held up by another program leaves its part
    /// to the others; below it a share per thread reads lines that stay in
    /// one core's cache from step to step.
    pub const TEAM_GRAINS: usize = 256;

    /// Free events (see [`crate::response::Resolver::resolve_found`]) a
    /// step must have before the team shares them: a few events a step are
    /// not worth a hand-off, while the hundreds of a large scene's step are.
    pub const RESOLVE_FROM: usize = 128;

    /// Bytes of a scene's or a checkpoint's text from which it is read on
    /// several threads (see [`crate::Scene::parse_on`] and
    /// [`crate::checkpoint::Checkpoint::parse_on`]): a megabyte of scene is
    /// about 15,000 lines, 4 ms of reading on one thread, against a few
    /// tens of microseconds to start a thread.
    pub const PARSE_SHARED_FROM: usize = 1 << 20;

    /// Lines from which the world stores them in the sweep's order even on
    /// one thread (as it does for scenes a team shares): each thread then
    /// moves and makes the boxes of the same lines, and the exact tests
    /// read lines near each other. On one thread a scene that fits the
    /// cache only pays for the copy.
    pub const STORE_FROM: usize = LARGE_SCENE;

    /// Boxes from which the sweep's kept layout, on one thread, is copied
    /// into its other arrays band by band as a team's groups copy theirs,
    /// instead of updated in place. In place, the stayers close up, the
    /// bands shift and the movers are let in: in a large scene every band
    /// shifts, and nearly every box is copied three times where the copy
    /// copies it once. One thread, copied against in place: 300,000 lines
    /// 0.89x, 600,000 lines 1.01x, a million lines 1.08x.
    pub const LAYOUT_COPIED_FROM: usize = 800_000;

    /// Steps between two times the lines are stored in the sweep's order;
    /// in between they move where they are. From step to step only the few
    /// movers leave the stored order, so reads stay near each other, and
    /// the move works in place instead of copying every line.
    pub const STORE_EVERY: u64 = 16;

    /// Lines from which a scene shown live runs on every core all the
    /// same: its pictures come seldom enough that the team gains more than
    /// the drawing takes from it.
    #[cfg(any(test, feature = "window"))]
    pub const LIVE_ALL_CORES_FROM: usize = 200_000;

    /// Whether the sweep shares a phase of `boxes` boxes among its team.
    pub fn sweep_shares(boxes: usize) -> bool {
        boxes >= Self::SWEEP_FROM
    }

    /// Whether a step that keeps the sweep's pairs shares them, and the
    /// boxes of its `lines` lines, among the team.
    pub fn kept_shares(lines: usize) -> bool {
        lines >= Self::KEPT_FROM
    }

    /// Whether the world's phases over `lines` lines go to the team: from
    /// [`Schedule::MOVE_FROM`], or [`Schedule::SWEEP_FROM`] once they are
    /// in the detector's order.
    pub fn world_shares(lines: usize, in_detector_order: bool) -> bool {
        let least = match in_detector_order {
            true => Self::SWEEP_FROM,
            false => Self::MOVE_FROM,
        };
        lines >= least
    }

    /// The pieces the world moves `lines` lines in on a team of `threads`
    /// (see [`Schedule::TEAM_GRAINS`]).
    pub fn world_pieces(lines: usize, grain: usize, threads: usize) -> usize {
        match lines < Self::TEAM_GRAINS.saturating_mul(grain.max(1)) {
            true => threads,
            false => (lines / grain.max(1)).clamp(threads, crate::team::MAX_PIECES),
        }
    }

    /// Whether the team resolves `free` events that share no line.
    pub fn resolution_shares(free: usize, least: Option<usize>) -> bool {
        free >= least.unwrap_or(Self::RESOLVE_FROM).max(1)
    }

    /// Whether the sweep has the world store `lines` lines in its order,
    /// on `threads` threads.
    pub fn stores_in_order(lines: usize, threads: usize) -> bool {
        (threads > 1 && Self::sweep_shares(lines)) || lines >= Self::STORE_FROM
    }

    /// Whether the sweep's kept layout of `boxes` boxes, on one thread, is
    /// copied rather than updated in place (see
    /// [`Schedule::LAYOUT_COPIED_FROM`]).
    pub fn layout_copied(boxes: usize) -> bool {
        boxes >= Self::LAYOUT_COPIED_FROM
    }

    /// Threads to run on unless asked: every core, less one for the
    /// drawing where a scene of `lines` lines is shown `live` and smaller
    /// than [`Schedule::LIVE_ALL_CORES_FROM`] (the drawing takes a core a
    /// good part of the time, and a member of the team switched out for it
    /// mid-piece holds up the step).
    #[cfg(any(test, feature = "window"))]
    pub fn default_threads(cores: usize, live: bool, lines: usize) -> usize {
        match live && lines < Self::LIVE_ALL_CORES_FROM {
            true => (cores - 1).max(1),
            false => cores,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_thresholds_split_where_they_say() {
        assert!(!Schedule::sweep_shares(2047) && Schedule::sweep_shares(2048));
        let grain = 16_384;
        assert!(!Schedule::world_shares(2047, false));
        assert!(Schedule::world_shares(2048, false) && Schedule::world_shares(2048, true));
        assert!(!Schedule::world_shares(2047, true));
        assert_eq!(Schedule::world_pieces(256 * grain - 1, grain, 2), 2);
        assert_eq!(Schedule::world_pieces(256 * grain, grain, 2), 256);
        assert_eq!(
            Schedule::world_pieces(1 << 30, 1, 2),
            crate::team::MAX_PIECES
        );
        assert!(!Schedule::resolution_shares(127, None) && Schedule::resolution_shares(128, None));
        assert!(Schedule::resolution_shares(1, Some(1)));
        assert!(!Schedule::stores_in_order(3000, 1) && Schedule::stores_in_order(3000, 2));
        assert!(Schedule::stores_in_order(1 << 16, 1));
        assert!(!Schedule::layout_copied(799_999) && Schedule::layout_copied(800_000));
        assert_eq!(Schedule::default_threads(2, true, 10_000), 1);
        assert_eq!(Schedule::default_threads(2, true, 300_000), 2);
        assert_eq!(Schedule::default_threads(2, false, 10_000), 2);
        assert_eq!(Schedule::default_threads(1, true, 10), 1);
    }
}
