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
    /// Lines (or boxes) from which a step's phases go to the team: the
    /// sweep's phases, a step that keeps the sweep's pairs, and the
    /// world's move and resolution, in whatever order the lines are
    /// stored. Below it the hand-offs and the lines' travel between the
    /// cores' caches cost more than the shared work saves: from 384 boxes,
    /// two threads against one, `sin_wave` (1,180 lines) 0.64x and `box`
    /// 0.71x, generated scenes of 2,000 lines 1.03x and of 4,000 1.08x; a
    /// kept step does a hundred or two instructions a line, `mit` (809
    /// lines, 4000 frames, two threads) 0.060 s shared against 0.046 on
    /// one, `koch` (3,900 lines) 0.043 s against 0.044 (medians of 9
    /// rounds).
    pub const SHARE_FROM: usize = 2048;

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
    pub const LIVE_ALL_CORES_FROM: usize = 200_000;

    /// Whether a phase over `lines` lines (or boxes) goes to the team
    /// ([`Schedule::SHARE_FROM`]).
    pub fn shares(lines: usize) -> bool {
        lines >= Self::SHARE_FROM
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
        (threads > 1 && Self::shares(lines)) || lines >= Self::STORE_FROM
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
        assert!(!Schedule::shares(2047) && Schedule::shares(2048));
        let grain = 16_384;
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
