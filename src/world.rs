//! The world: every line, the two collision counters, and one step of the
//! simulation (detect, resolve, move, walls).

pub use crate::counters::Counters;
use crate::detect::{
    Detector, DetectorConfig, DetectorKind, DetectorStats, Findings, PairCounts, Setup,
    DEFAULT_GRAIN,
};
use crate::line::{window_to_box_point, window_to_box_velocity, Color, Line, DT};
use crate::narrow::{Event, Slot};
use crate::response::Resolver;
use crate::scene::Scene;
use crate::schedule::Schedule;
use crate::storage::Storage;
use crate::team::{HandOffs, Team};
use std::borrow::Cow;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Time spent in each phase of the step, summed over steps (only measured
/// when [`World::set_timing`] is on).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct PhaseTimes {
    /// Finding events.
    pub detect: Duration,
    /// Sorting and applying responses.
    pub resolve: Duration,
    /// Moving lines and bouncing them off the walls (one pass).
    pub advance: Duration,
}

/// The simulated world. Line ids are indices into [`World::lines`].
///
/// ```
/// use screensaver::{Color, DetectorConfig, DetectorKind, Line, Vec2, World};
///
/// // Two lines of your own, the second moving left onto the first.
/// let line = |x: f64, vx: f64| Line {
///     p1: Vec2::new(x, 0.70),
///     p2: Vec2::new(x, 0.80),
///     v: Vec2::new(vx, 0.0),
/// };
/// let lines = vec![line(0.60, 0.0), line(0.62, -0.4)];
/// let config = DetectorConfig::default();
/// let mut world =
///     World::from_lines(lines, vec![Color::Red; 2], DetectorKind::Sweep, &config).unwrap();
/// world.run(100);
/// assert_eq!(world.steps(), 100);
/// assert!(world.counters().line >= 1, "they met");
/// ```
pub struct World {
    lines: Vec<Line>,
    colors: Vec<Color>,
    counters: Counters,
    steps: u64,
    /// The last step was given up part way ([`World::gave_up_step`]).
    gave_up: bool,
    detector: Box<dyn Detector>,
    /// What the last step's detection found: its events by slot (sorted in
    /// the order of resolution while the lines are in id order, else in
    /// the order found).
    found: Findings,
    /// Once the lines are in the detector's order, the last step's events
    /// by id, in the order found; `named` says whether the last step
    /// named them so (else `found` holds them, slots being ids).
    events: Vec<Event>,
    named: bool,
    /// Scratch for the sort of the events in id order.
    order_keys: Vec<u64>,
    /// The pair work of every step so far, and the events found.
    pairs: PairCounts,
    events_found: u64,
    resolver: Resolver,
    /// The smallest piece of work handed to a thread, in lines or events.
    grain: usize,
    timing: Option<PhaseTimes>,
    /// The threads a step runs on, when more than one: every parallel
    /// phase, the detector's and the world's, runs on this team.
    team: Option<Arc<Team>>,
    /// The lines' ids by slot (see [`crate::storage`]): `lines` holds
    /// them by slot, in id order until the detector asks for its own.
    storage: Storage,
}

/// The system would not start the threads a world was asked to run on.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("cannot start {threads} threads: {reason}")]
pub struct ThreadsError {
    /// The threads asked for.
    pub threads: usize,
    /// What the system said.
    pub reason: String,
}

/// A scene's lines in box coordinates (converted from window coordinates
/// exactly as the reference did), and their colours.
fn box_lines(scene: &Scene) -> (Vec<Line>, Vec<Color>) {
    let lines = scene
        .lines
        .iter()
        .map(|l| Line {
            p1: window_to_box_point(l.p1),
            p2: window_to_box_point(l.p2),
            v: window_to_box_velocity(l.v),
        })
        .collect();
    let colors = scene.lines.iter().map(|l| l.color).collect();
    (lines, colors)
}

impl World {
    /// A world holding `lines` (in box coordinates, ids by position) that
    /// finds collisions with `detector`.
    ///
    /// # Panics
    /// If `lines` and `colors` differ in length, or there are more lines
    /// than `u32` ids.
    pub(crate) fn new(lines: Vec<Line>, colors: Vec<Color>, detector: Box<dyn Detector>) -> Self {
        assert_eq!(lines.len(), colors.len(), "one colour per line");
        assert!(
            u32::try_from(lines.len()).is_ok(),
            "too many lines for u32 ids"
        );
        let storage = Storage::new(lines.len());
        Self {
            lines,
            colors,
            counters: Counters::default(),
            steps: 0,
            gave_up: false,
            detector,
            found: Findings::default(),
            events: Vec::new(),
            named: false,
            order_keys: Vec::new(),
            pairs: PairCounts::default(),
            events_found: 0,
            resolver: Resolver::default(),
            grain: DEFAULT_GRAIN,
            timing: None,
            team: None,
            storage,
        }
    }

    /// A world from a scene with a detector chosen by kind and tuned by
    /// `config`, running on `config.threads` threads.
    pub fn with_config(
        scene: &Scene,
        kind: DetectorKind,
        config: &DetectorConfig,
    ) -> Result<Self, ThreadsError> {
        let (lines, colors) = box_lines(scene);
        Self::from_lines(lines, colors, kind, config)
    }

    /// A world holding `lines` (in box coordinates, ids by position) of
    /// `colors`, with a detector chosen by kind and tuned by `config`,
    /// running on `config.threads` threads.
    ///
    /// # Panics
    /// If `lines` and `colors` differ in length, or there are more lines
    /// than `u32` ids.
    pub fn from_lines(
        lines: Vec<Line>,
        colors: Vec<Color>,
        kind: DetectorKind,
        config: &DetectorConfig,
    ) -> Result<Self, ThreadsError> {
        let mut world = Self::new(lines, colors, kind.build_with(config));
        world.set_threads(config.threads)?;
        world.set_grain(config.grain);
        Ok(world)
    }

    /// Runs steps on `threads` threads (1: on the calling thread alone):
    /// the world's own phases and the detector's alike, on one team.
    /// Results are the same for any number of threads.
    pub fn set_threads(&mut self, threads: usize) -> Result<(), ThreadsError> {
        let team = match threads > 1 {
            true => Some(Arc::new(Team::new(threads).map_err(|e| ThreadsError {
                threads,
                reason: e.to_string(),
            })?)),
            false => None,
        };
        if let Some(team) = &team {
            team.set_timing(self.timing.is_some());
        }
        self.team = team;
        self.detector.configure(&self.setup());
        Ok(())
    }

    /// Sets the smallest piece of work the steps' own phases (resolving
    /// events in waves, moving lines and checking walls in a large scene)
    /// hand to a thread: `grain` events, or as many lines. The detector
    /// has its own setting.
    pub fn set_grain(&mut self, grain: usize) {
        self.grain = grain.max(1);
    }

    /// Threads a step runs on.
    pub fn threads(&self) -> usize {
        self.team.as_ref().map_or(1, |t| t.threads())
    }

    /// Whether the last step was given up part way, on a signal (only the
    /// all-pairs detector, whose steps of many lines take minutes, gives
    /// up): the world is as it was before it.
    pub fn gave_up_step(&self) -> bool {
        self.gave_up
    }

    /// The threads that have stepped the world so far: its team's, once a
    /// phase has been shared among them, else one (a small scene runs on
    /// one thread whatever the team).
    pub fn threads_run(&self) -> usize {
        (self.team.as_ref()).map_or(1, |t| if t.has_shared() { t.threads() } else { 1 })
    }

    /// A world built from a scene (window coordinates converted to box
    /// coordinates exactly as the reference did).
    pub(crate) fn from_scene(scene: &Scene, detector: Box<dyn Detector>) -> Self {
        let (lines, colors) = box_lines(scene);
        Self::new(lines, colors, detector)
    }

    /// A world continuing a run at `steps` steps with `counters` (as a
    /// checkpoint recorded it: [`crate::checkpoint::Checkpoint::resume`]).
    pub(crate) fn continuing(
        lines: Vec<Line>,
        colors: Vec<Color>,
        (steps, counters): (u64, Counters),
        kind: DetectorKind,
        config: &DetectorConfig,
    ) -> Result<Self, ThreadsError> {
        let mut world = Self::from_lines(lines, colors, kind, config)?;
        world.steps = steps;
        world.counters = counters;
        Ok(world)
    }

    /// Convenience: a world from a scene with a detector chosen by kind.
    pub fn with_detector(scene: &Scene, kind: DetectorKind) -> Self {
        Self::from_scene(scene, kind.build())
    }

    /// The lines, indexed by id: borrowed while they are stored by id, a
    /// copy in id order once the detector has had them stored in its own.
    pub fn lines(&self) -> Cow<'_, [Line]> {
        self.storage.by_id(&self.lines)
    }

    /// True when nothing more can happen in the world: every line is NaN,
    /// or none of them moves (a screensaver then starts another scene).
    pub fn died_out(&self) -> bool {
        (self.lines.iter()).all(|l| l.is_inert() || (l.v.x == 0.0 && l.v.y == 0.0))
    }

    /// Each line with its colour, in the order the world stores them: the
    /// detector's, which keeps lines near each other together (by id until
    /// the detector has stored them). For drawing, where the order shows
    /// only where lines cross: a large scene drawn in this order touches
    /// the frame row by row, so nearby pixels are drawn together
    /// (docs/DESIGN.md, "Drawing fast enough").
    pub fn lines_as_stored(&self) -> impl Iterator<Item = (&Line, Color)> + '_ {
        let ids = self.storage.ids();
        (self.lines.iter())
            .zip(ids)
            .map(move |(line, &id)| (line, self.colors[id.0 as usize]))
    }

    /// The colour of each line, indexed by id.
    pub fn colors(&self) -> &[Color] {
        &self.colors
    }

    /// The collision counters so far.
    pub fn counters(&self) -> Counters {
        self.counters
    }

    /// Steps run so far.
    pub fn steps(&self) -> u64 {
        self.steps
    }

    /// The detector in use.
    pub(crate) fn detector(&self) -> &dyn Detector {
        self.detector.as_ref()
    }

    /// The broad phase's counters: the pairs its detector handed on and
    /// the events found, with the detector's own.
    pub fn detector_stats(&self) -> DetectorStats {
        DetectorStats {
            candidate_pairs: self.pairs.candidates,
            exact_tests: self.pairs.exact,
            events: self.events_found,
            ..self.detector.report().stats
        }
    }

    /// Events of the last step, sorted in the contract's order of
    /// resolution (ascending ids).
    pub fn last_events(&self) -> Vec<Event> {
        if !self.named {
            // Slots were ids, and the events are sorted already.
            let by_id = |e: &Event<Slot>| e.named(|s| s.as_id());
            return self.found.events.iter().map(by_id).collect();
        }
        // Kept in the order found (see `crate::storage`).
        let mut events = self.events.clone();
        events.sort_unstable_by_key(Event::order_key);
        events
    }

    /// Turns per-phase timing on or off, the detector's own phases included
    /// (off by default: it costs a few clock reads per step).
    pub fn set_timing(&mut self, on: bool) {
        self.timing = if on {
            Some(PhaseTimes::default())
        } else {
            None
        };
        // The detector's clock starts anew too, as the world's does.
        let stopped = Setup {
            timing: false,
            ..self.setup()
        };
        self.detector.configure(&stopped);
        self.detector.configure(&self.setup());
        if let Some(team) = &self.team {
            team.set_timing(on);
        }
    }

    /// Per-phase times so far, if timing is on.
    pub(crate) fn phase_times(&self) -> Option<PhaseTimes> {
        self.timing
    }

    /// What handing the phases to the thread team has cost so far, if
    /// timing is on and the world has a team (more than one thread).
    pub(crate) fn hand_offs(&self) -> Option<HandOffs> {
        self.timing?;
        self.team.as_deref().map(Team::hand_offs)
    }

    /// Runs one step, in the contract's stages: find the pairs that meet,
    /// name their events in the contract's order, resolve them, then
    /// integrate (move, walls, and the lines stored in the detector's
    /// order where it asks).
    pub fn step(&mut self) {
        let t0 = self.timing.map(|_| Instant::now());
        if !self.find_pairs() {
            // Given up on a signal: the world is as it was before the step.
            return;
        }
        let t1 = self.lap(t0, |t, d| t.detect += d);
        self.name_events();
        let t1 = self.lap(t1, |t, d| t.resolve += d);
        // What the detector asks of the rest of the step (its storage
        // order is the move's work, and timed with it).
        let handover = self.detector.hand_over();
        let t1 = self.lap(t1, |t, d| t.advance += d);
        // The team (a handle of its own: `self` is borrowed mutably below),
        // and whether the schedule shares the world's phases among it.
        let team = self.team.clone();
        let shares = self.shares_step(handover.shares_step);
        let shared = team.as_deref().filter(|_| shares);
        self.resolve(shared, team.as_deref());
        let t2 = self.lap(t1, |t, d| t.resolve += d);
        let hits = self.integrate(handover.order, shared);
        self.counters.wall += hits;
        self.lap(t2, |t, d| t.advance += d);
        self.steps += 1;
    }

    /// Finds the pairs that meet, their events by slot in `found`; false
    /// where the detector gave the step up on a signal (only the all-pairs
    /// detector, whose steps of many lines take minutes, does).
    fn find_pairs(&mut self) -> bool {
        self.found.clear();
        let stored = self.storage.stored(&self.lines);
        self.detector.detect(stored, DT, &mut self.found);
        self.gave_up = self.found.abandoned;
        if self.gave_up {
            self.found.clear();
            self.events.clear();
        }
        !self.gave_up
    }

    /// Puts the events in the contract's order of resolution. While the
    /// lines are in id order, slots are ids: the events are sorted; once
    /// the lines are in the detector's order, its events by slot are named
    /// by id and resolved as found, without a sort (see `crate::storage`).
    fn name_events(&mut self) {
        let reordered = self.storage.reordered();
        let found = &mut self.found;
        self.events.clear();
        self.named = reordered;
        if reordered {
            self.storage.name_by_id(&found.events, &mut self.events);
        } else {
            // Pairs are unique, so an unstable sort gives the one order.
            crate::narrow::sort_in_order(&mut found.events, &mut self.order_keys);
        }
        self.pairs.add(&found.counts);
        self.events_found += found.events.len() as u64;
        self.counters.line += found.events.len() as u64;
    }

    /// Whether the world's own phases of this step (resolving and moving)
    /// are shared among the team: where the schedule says so for its size,
    /// and the detector did not run the step on one thread
    /// (`detector_shares`).
    fn shares_step(&self, detector_shares: bool) -> bool {
        Schedule::shares(self.lines.len()) && detector_shares
    }

    /// The settings the detector is handed.
    fn setup(&self) -> Setup {
        Setup {
            timing: self.timing.is_some(),
            team: self.team.clone(),
        }
    }

    /// Resolves the events: as found, a share a thread where `shared`, on
    /// lines in the detector's order; else in waves of events on `team`.
    fn resolve(&mut self, shared: Option<&Team>, team: Option<&Team>) {
        let (lines, found) = (&mut self.lines, &self.found.events);
        match self.named {
            true => (self.resolver).resolve_found(lines, found, &self.events, self.grain, shared),
            false => (self.resolver).resolve_all(lines, found, self.grain, team),
        }
    }

    /// Moves every line and bounces it off the walls in one pass (each
    /// line moved, then checked, as the contract orders: the wall check
    /// reads only the line's own new position); returns the lines that hit
    /// a wall, a sum the same in any order. Where the detector asks, the
    /// lines are stored in its order as they move (see `crate::storage`),
    /// a share per member of the team; else they move in their slots, in as
    /// many pieces as the schedule says, by the detector, which may make
    /// its next boxes as they go.
    fn integrate(&mut self, order: Option<Vec<Slot>>, shared: Option<&Team>) -> u64 {
        if let Some(order) = order {
            return (self.storage).advance_in_order(&mut self.lines, &order, shared);
        }
        let n = self.lines.len();
        let pieces = |team: &Team| Schedule::world_pieces(n, self.grain, team.threads());
        let shared = shared.map(|team| (team, pieces(team)));
        self.detector.advance(&mut self.lines, shared)
    }

    /// Runs `n` steps.
    pub fn run(&mut self, n: u64) {
        self.run_with(n, |_| std::ops::ControlFlow::<()>::Continue(()));
    }

    /// Runs up to `n` steps, calling `after_step` after each; it may stop
    /// the run early. The team is woken first, so that its members are
    /// spinning when the first step hands them work.
    pub fn run_with<B>(
        &mut self,
        n: u64,
        mut after_step: impl FnMut(&mut World) -> std::ops::ControlFlow<B>,
    ) -> Option<B> {
        if let Some(team) = &self.team {
            team.wake();
        }
        for _ in 0..n {
            self.step();
            if self.gave_up {
                return None;
            }
            if let std::ops::ControlFlow::Break(b) = after_step(self) {
                return Some(b);
            }
        }
        None
    }

    fn lap(
        &mut self,
        since: Option<Instant>,
        add: impl FnOnce(&mut PhaseTimes, Duration),
    ) -> Option<Instant> {
        let (times, since) = (self.timing.as_mut()?, since?);
        let now = Instant::now();
        add(times, now - since);
        Some(now)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::Brute;
    use crate::geometry::Vec2;
    use crate::index::LineId;
    use crate::test_util::line;

    #[test]
    fn a_scene_dies_out_when_nothing_moves_or_all_is_nan() {
        let moving = line((0.6, 0.6), (0.7, 0.7), (0.01, 0.0));
        let still = line((0.6, 0.6), (0.7, 0.7), (0.0, 0.0));
        let nan = line((f64::NAN, f64::NAN), (f64::NAN, f64::NAN), (0.01, 0.0));
        let died_out = |lines: &[Line]| {
            World::new(
                lines.to_vec(),
                vec![Color::Red; lines.len()],
                Box::new(Brute),
            )
            .died_out()
        };
        assert!(!died_out(&[moving, still]));
        assert!(died_out(&[still, still]));
        assert!(died_out(&[nan, still]));
        assert!(died_out(&[]));
    }

    fn world(lines: Vec<Line>) -> World {
        let colors = vec![Color::Red; lines.len()];
        World::new(lines, colors, Box::new(Brute))
    }

    #[test]
    fn a_free_line_moves_by_v_dt() {
        let mut w = world(vec![line((0.6, 0.6), (0.7, 0.6), (0.01, -0.02))]);
        w.step();
        let l = w.lines()[0];
        assert_eq!(l.p1, Vec2::new(0.6 + 0.01 * 0.5, 0.6 + -0.02 * 0.5));
        assert_eq!(w.counters(), Counters::default());
        assert_eq!(w.steps(), 1);
    }

    #[test]
    fn walls_are_checked_after_moving() {
        let mut w = world(vec![line((0.9, 0.7), (0.99, 0.7), (0.04, 0.0))]);
        w.step();
        assert_eq!(w.counters().wall, 1);
        assert_eq!(w.lines()[0].v.x, -0.04);
    }

    #[test]
    fn events_are_counted_and_resolved_in_id_order() {
        // Two lines about to meet head on, and a third far away.
        let mut w = world(vec![
            line((0.6, 0.6), (0.6, 0.7), (0.01, 0.0)),
            line((0.9, 0.9), (0.91, 0.9), (0.0, 0.0)),
            line((0.605, 0.6), (0.605, 0.7), (-0.01, 0.0)),
        ]);
        w.step();
        assert_eq!(w.counters().line, 1);
        assert_eq!(w.last_events().len(), 1);
        assert_eq!(
            (w.last_events()[0].first, w.last_events()[0].second),
            (LineId(0), LineId(2))
        );
        assert_eq!(w.lines()[0].v.x, -0.01);
        assert_eq!(w.lines()[2].v.x, 0.01);
    }

    /// The step after which the lines are first stored in the sweep's
    /// order still reports its events by id, as every step does, found
    /// while the lines were stored by id or after.
    #[test]
    fn events_read_by_id_before_during_and_after_the_lines_are_reordered() {
        use crate::generate::{generate, SceneKind};
        let scene = generate(SceneKind::Uniform, 3_000, 5);
        let config = DetectorConfig {
            threads: 2,
            ..DetectorConfig::default()
        };
        let mut sweep = World::with_config(&scene, DetectorKind::Sweep, &config).unwrap();
        let mut oracle = World::with_detector(&scene, DetectorKind::Brute);
        let mut found = 0;
        for step in 1..=3 {
            sweep.step();
            oracle.step();
            assert!(
                sweep.storage.reordered(),
                "stored in the sweep's order from step 1"
            );
            assert_eq!(sweep.last_events(), oracle.last_events(), "step {step}");
            found += sweep.last_events().len();
        }
        assert!(found > 0, "no events to compare");
    }

    #[test]
    fn timing_adds_up_when_on() {
        let mut w = world(vec![line((0.6, 0.6), (0.7, 0.6), (0.01, 0.0))]);
        assert!(w.phase_times().is_none());
        w.set_timing(true);
        w.run(3);
        assert!(w.phase_times().is_some());
        assert_eq!(w.steps(), 3);
    }

    /// Members held back at random (up to 300 us a job, sleeping or
    /// spinning) and threads outnumbering the cores, with two more threads
    /// spinning beside them: every piece still runs once, on whichever
    /// thread, and the results are one thread's, bit for bit.
    #[test]
    fn late_and_switched_out_members_leave_the_results_unchanged() {
        use crate::generate::{generate, SceneKind};
        use std::sync::atomic::{AtomicBool, Ordering};
        /// Stops the spinning threads when dropped: also when an assertion
        /// fails, or the scope would wait for them for ever.
        struct Stop<'a>(&'a AtomicBool);
        impl Drop for Stop<'_> {
            fn drop(&mut self) {
                self.0.store(true, Ordering::Relaxed);
            }
        }
        let stop = AtomicBool::new(false);
        std::thread::scope(|scope| {
            let _stop = Stop(&stop);
            for _ in 0..2 {
                scope.spawn(|| {
                    while !stop.load(Ordering::Relaxed) {
                        std::hint::spin_loop();
                    }
                });
            }
            // Scenes the team shares (from `Schedule::SHARE_FROM` lines).
            for (kind, n, steps) in [
                (SceneKind::Uniform, 2_500, 80),
                (SceneKind::Clustered, 3_000, 60),
                (SceneKind::Uniform, 12_000, 20),
            ] {
                let scene = generate(kind, n, 11);
                let run = |threads: usize| {
                    let config = DetectorConfig {
                        threads,
                        ..DetectorConfig::default()
                    };
                    let mut w = World::with_config(&scene, DetectorKind::Sweep, &config).unwrap();
                    if let Some(team) = &w.team {
                        team.delay_members(Duration::from_micros(300));
                    }
                    w.set_timing(true);
                    w.run(steps);
                    let jobs = w.hand_offs().map_or(0, |h| h.jobs);
                    assert_eq!(jobs > 0, threads > 1, "{kind} {n}: the team's jobs");
                    let bits: Vec<[u64; 6]> = (w.lines().iter())
                        .map(|l| [l.p1.x, l.p1.y, l.p2.x, l.p2.y, l.v.x, l.v.y].map(f64::to_bits))
                        .collect();
                    (w.counters(), bits)
                };
                let one = run(1);
                assert!(one.0.line > 0, "{kind} {n}: no collisions to check");
                for threads in [2, 3, 8] {
                    assert!(run(threads) == one, "{kind} {n} on {threads} threads");
                }
            }
        });
    }
}
