//! A live run: the simulation on its own thread, as fast as it may (or at
//! a set pace), leaving its latest state for whatever shows it (the
//! window, or a window another program owns) to take at the display's
//! pace. Endless runs go on until told to stop; runs of generated scenes
//! start a new scene every so often, and whenever a scene has died out.

use crate::line::{Color, Line};
use crate::report::DrawStats;
use crate::run::Run;
use crate::World;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Where the scenes of a live run come from.
///
/// ```no_run
/// use screensaver::generate::{generate, SceneKind};
/// use screensaver::render::{Scenes, Screen, ShowOptions};
/// use screensaver::{DetectorKind, World};
/// use std::time::Duration;
///
/// // A screensaver: a new generated scene every thirty seconds, in a
/// // window filling the screen, until it is closed.
/// let world = |k: u64| World::with_detector(&generate(SceneKind::Ring, 2_000, k), DetectorKind::Sweep);
/// let scenes = Scenes::Generated {
///     first: Box::new(world(0)),
///     next: Box::new(world),
///     cycle: Duration::from_secs(30),
/// };
/// let screen = Screen::Window { fullscreen: true };
/// screen.check().expect("a display");
/// let outcome = screen.show(scenes, ShowOptions::default()).expect("shown");
/// println!("{} scenes, {} frames", outcome.scenes, outcome.drawn.frames);
/// ```
pub enum Scenes {
    /// One world, run until its step count reaches `until`, or until
    /// stopped if `None`.
    One {
        /// The world (boxed: a world is large beside the other variant).
        world: Box<World>,
        /// The step the run ends at, counted from the world's start (a
        /// resumed world has run some of them already).
        until: Option<u64>,
    },
    /// Generated scenes without end: `first`, then `next(k)` for the
    /// `k`-th (from 1); a new one starts after `cycle`, or as soon as the
    /// scene on show has died out (see [`World::died_out`]).
    Generated {
        /// The first scene.
        first: Box<World>,
        /// Makes the `k`-th scene.
        next: Box<dyn FnMut(u64) -> World + Send>,
        /// How long each scene is shown.
        cycle: Duration,
    },
}

/// How often a generated scene is checked for having died out.
const DEATH_CHECK_EVERY: Duration = Duration::from_millis(500);

/// How fast a live run goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pace {
    /// One step for each picture the display takes: the original `-g`'s
    /// pace, which drew after every step. The default.
    PerFrame,
    /// At most this many steps a second (at least 1).
    Rate(u64),
    /// As fast as the simulation goes.
    Max,
}

impl Pace {
    /// The pace as one word for [`Shared`]: 0 for `Max`, `u64::MAX` for
    /// `PerFrame`, else the rate.
    fn code(self) -> u64 {
        match self {
            Pace::Max => 0,
            Pace::PerFrame => u64::MAX,
            Pace::Rate(n) => n.clamp(1, u64::MAX - 1),
        }
    }

    fn from_code(code: u64) -> Pace {
        match code {
            0 => Pace::Max,
            u64::MAX => Pace::PerFrame,
            n => Pace::Rate(n),
        }
    }

    /// The pace `+` (`faster`) or `-` leads to from this one, given the
    /// steps per second measured lately: twice or half the rate; from one
    /// step a frame or from no limit, twice or half the measured rate;
    /// faster than 2^20 steps a second is no limit.
    pub fn changed(self, faster: bool, measured: f64) -> Pace {
        let rate = match self {
            Pace::Rate(n) => n as f64,
            Pace::Max if faster => return Pace::Max,
            Pace::PerFrame | Pace::Max => measured.max(1.0),
        };
        let rate = if faster { rate * 2.0 } else { rate / 2.0 };
        if rate >= f64::from(1u32 << 20) {
            Pace::Max
        } else {
            Pace::Rate((rate as u64).max(1))
        }
    }
}

impl std::fmt::Display for Pace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Pace::PerFrame => write!(f, "1 step/frame"),
            Pace::Rate(n) => write!(f, "{n} steps/s max"),
            Pace::Max => write!(f, "max speed"),
        }
    }
}

/// A state of the run, for showing.
pub struct Snapshot {
    /// Every line, in the order the world stores them
    /// ([`World::lines_as_stored`]: nearby lines together, which draws a
    /// large scene faster than id order).
    pub lines: Vec<Line>,
    /// Their colours, in the same order.
    pub colors: Vec<Color>,
    /// Steps run in this scene.
    pub step: u64,
    /// Line-wall collisions in this scene.
    pub wall: u64,
    /// Line-line collisions in this scene.
    pub line: u64,
    /// Steps per second, lately (kept while paused, for a change of pace).
    pub rate: f64,
    /// Whether the run is paused: no rate to show.
    pub paused: bool,
    /// Which scene (from 0).
    pub scene: u64,
}

/// What the simulation thread and the display share.
pub struct Shared {
    /// The simulation waits while set (but for single steps).
    pub paused: AtomicBool,
    /// Single steps asked for while paused.
    pub steps_requested: AtomicU64,
    /// The pace ([`Pace::code`]).
    pace: AtomicU64,
    /// Set by the display to end the run.
    pub quit: AtomicBool,
    /// Set by the simulation when it has run every step.
    pub finished: AtomicBool,
    /// The latest state, for the display to take.
    latest: Mutex<Option<Snapshot>>,
    /// Whether the display has taken the latest state (so a new one is
    /// wanted).
    taken: AtomicBool,
    /// Lines and colours of a state the display is done with, for the next
    /// snapshot to fill (a million lines are 48 MB: fresh memory each time
    /// costs its page faults, and freeing it the display's time).
    spare: Mutex<(Vec<Line>, Vec<Color>)>,
}

impl Shared {
    /// Takes the latest state, if there is one the display has not taken.
    pub fn take(&self) -> Option<Snapshot> {
        let snapshot = self
            .latest
            .lock()
            .expect("no panics while holding the lock")
            .take();
        if snapshot.is_some() {
            self.taken.store(true, Ordering::Release);
        }
        snapshot
    }

    /// Hands back a state the display no longer shows, so that its memory
    /// serves the next snapshot.
    pub fn recycle(&self, old: Snapshot) {
        *self.spare.lock().expect("no panics while holding the lock") = (old.lines, old.colors);
    }

    /// True when a state is waiting to be taken.
    pub fn has_news(&self) -> bool {
        self.latest.lock().is_ok_and(|l| l.is_some())
    }

    /// Asks for a fresh state even if nothing moves (after a pause).
    pub fn want_news(&self) {
        self.taken.store(true, Ordering::Release);
    }

    /// How fast the run goes.
    pub fn pace(&self) -> Pace {
        Pace::from_code(self.pace.load(Ordering::Relaxed))
    }

    /// Sets how fast the run goes.
    pub fn set_pace(&self, pace: Pace) {
        self.pace.store(pace.code(), Ordering::Relaxed);
    }
}

/// The outcome of a live run.
pub struct Outcome {
    /// The world on show when the run ended.
    pub world: World,
    /// The time the last scene ran (the whole run's unless generated
    /// scenes were cycled).
    pub scene_elapsed: Duration,
    /// Scenes shown (1 unless generated scenes were cycled).
    pub scenes: u64,
    /// The frames drawn, and the time they took.
    pub drawn: DrawStats,
}

/// A live run under way: the simulation on its thread.
pub struct Simulation {
    /// What the display shares with the simulation.
    pub shared: Arc<Shared>,
    thread: std::thread::JoinHandle<Outcome>,
}

impl Simulation {
    /// Starts the simulation thread, at `pace`.
    pub fn start(scenes: Scenes, pace: Pace) -> Simulation {
        let shared = Arc::new(Shared {
            paused: AtomicBool::new(false),
            steps_requested: AtomicU64::new(0),
            pace: AtomicU64::new(pace.code()),
            quit: AtomicBool::new(false),
            finished: AtomicBool::new(false),
            latest: Mutex::new(None),
            taken: AtomicBool::new(true),
            spare: Mutex::default(),
        });
        let thread = {
            let shared = Arc::clone(&shared);
            std::thread::spawn(move || simulate(scenes, &shared))
        };
        Simulation { shared, thread }
    }

    /// Tells the simulation to stop and waits for it.
    pub fn finish(self) -> Result<Outcome, super::ScreenError> {
        self.shared.quit.store(true, Ordering::Relaxed);
        (self.thread.join()).map_err(|_| super::ScreenError::Panicked)
    }
}

/// The simulation thread: runs the scenes, obeying pause, single steps and
/// the speed limit, and leaves a snapshot whenever the display has taken
/// the last one.
fn simulate(scenes: Scenes, shared: &Shared) -> Outcome {
    let start = Instant::now();
    let (mut world, steps, mut next, cycle) = match scenes {
        Scenes::One { world, until } => (*world, until, None, None),
        Scenes::Generated { first, next, cycle } => (*first, None, Some(next), Some(cycle)),
    };
    let mut scene = 0;
    let mut scene_start = Instant::now();
    let mut last_check = Instant::now();
    let (mut window_start, mut window_steps) = (Instant::now(), 0u64);
    let mut rate = 0.0;
    // Whether the last pass of the loop was paused: the rate is measured
    // over running steps only, so that `+` after a pause doubles the pace
    // the run had, not the few single steps taken while paused.
    let mut was_paused = false;
    let publish = |world: &World, scene, rate, force: bool| {
        if force || shared.taken.swap(false, Ordering::AcqRel) {
            let c = world.counters();
            let (mut lines, mut colors) = std::mem::take(
                &mut *shared
                    .spare
                    .lock()
                    .expect("no panics while holding the lock"),
            );
            lines.clear();
            colors.clear();
            for (line, color) in world.lines_as_stored() {
                lines.push(*line);
                colors.push(color);
            }
            let snapshot = Snapshot {
                lines,
                colors,
                step: world.steps(),
                wall: c.wall,
                line: c.line,
                rate,
                paused: shared.paused.load(Ordering::Relaxed),
                scene,
            };
            *shared
                .latest
                .lock()
                .expect("no panics while holding the lock") = Some(snapshot);
        }
    };
    publish(&world, scene, 0.0, true);
    while steps.is_none_or(|s| world.steps() < s) && !shared.quit.load(Ordering::Relaxed) {
        if crate::stop::requested().is_some() {
            break;
        }
        if let (Some(next), Some(cycle)) = (&mut next, cycle) {
            let due = scene_start.elapsed() >= cycle;
            let dead = last_check.elapsed() >= DEATH_CHECK_EVERY && {
                last_check = Instant::now();
                world.died_out()
            };
            if due || dead {
                scene += 1;
                world = next(scene);
                scene_start = Instant::now();
                publish(&world, scene, rate, true);
            }
        }
        let paused = shared.paused.load(Ordering::Relaxed);
        if was_paused && !paused {
            (window_start, window_steps) = (Instant::now(), 0);
        }
        was_paused = paused;
        if paused && shared.steps_requested.load(Ordering::Relaxed) == 0 {
            std::thread::sleep(Duration::from_millis(5));
            continue;
        }
        let pace = shared.pace();
        // The display has not taken the last step's state yet.
        let waiting = || !paused && pace == Pace::PerFrame && !shared.taken.load(Ordering::Acquire);
        if waiting() {
            std::thread::sleep(Duration::from_micros(500));
            continue;
        }
        if paused {
            shared.steps_requested.fetch_sub(1, Ordering::Relaxed);
        }
        // Steps run until something asks the loop to look again: a single
        // step while paused, a change of pace, pause or quit, the display
        // behind at one step a picture, a scene to check.
        let burst = match steps {
            _ if paused => 1,
            Some(s) => s - world.steps(),
            None => u64::MAX,
        };
        let mut step_start = Instant::now();
        let mut after_step = |world: &World, _: Duration| {
            window_steps += u64::from(!paused);
            if !paused && window_start.elapsed() >= Duration::from_millis(250) {
                rate = window_steps as f64 / window_start.elapsed().as_secs_f64();
                (window_start, window_steps) = (Instant::now(), 0);
            }
            publish(world, scene, rate, paused);
            if let Pace::Rate(limit) = pace {
                let budget = Duration::from_secs_f64(1.0 / limit as f64);
                if let Some(rest) = budget.checked_sub(step_start.elapsed()) {
                    std::thread::sleep(rest);
                }
            }
            step_start = Instant::now();
        };
        let cycling = next.is_some();
        let look_again = |_: &World| {
            shared.quit.load(Ordering::Relaxed)
                || shared.paused.load(Ordering::Relaxed) != paused
                || shared.pace() != pace
                || waiting()
                || (cycling && last_check.elapsed() >= DEATH_CHECK_EVERY)
        };
        let run = Run {
            progress: Some(&mut after_step),
            stop: Some(&look_again),
            ..Run::default()
        };
        run.run(&mut world, burst)
            .expect("a run without pictures, checkpoints or checks cannot fail");
    }
    let elapsed = start.elapsed();
    publish(&world, scene, rate, true);
    shared.finished.store(true, Ordering::Release);
    Outcome {
        world,
        scene_elapsed: elapsed.min(scene_start.elapsed()),
        scenes: scene + 1,
        drawn: DrawStats::default(),
    }
}

/// Counts frames as they are drawn.
#[derive(Debug, Default)]
pub struct FrameClock {
    first: Option<Instant>,
    stats: DrawStats,
    /// Frames since `recent_start`, and the rate they gave when last
    /// counted.
    recent: (u64, Option<Instant>, f64),
}

impl FrameClock {
    /// Notes a frame that began drawing at `started` and has just ended.
    pub fn drawn(&mut self, started: Instant) {
        let now = Instant::now();
        let first = *self.first.get_or_insert(started);
        self.stats.frames += 1;
        self.stats.drawing += now - started;
        self.stats.span = now - first;
        let (count, since, rate) = &mut self.recent;
        *count += 1;
        let since = since.get_or_insert(now);
        if now - *since >= Duration::from_secs(1) {
            *rate = *count as f64 / (now - *since).as_secs_f64();
            (*count, *since) = (0, now);
        }
    }

    /// What was counted.
    pub fn stats(&self) -> DrawStats {
        self.stats
    }

    /// Frames per second over the last second or so, for the display.
    pub fn recent_fps(&self) -> f64 {
        self.recent.2
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::Brute;
    use crate::test_util::line;

    fn world(lines: Vec<Line>) -> World {
        let colors = vec![Color::Red; lines.len()];
        World::new(lines, colors, Box::new(Brute))
    }

    /// A run of one scene of one moving line for `steps` steps, once the
    /// simulation has finished it.
    fn finished_run(steps: u64) -> Simulation {
        let run = Simulation::start(
            Scenes::One {
                world: Box::new(world(vec![line((0.6, 0.6), (0.7, 0.7), (0.01, 0.0))])),
                until: Some(steps),
            },
            Pace::Max,
        );
        while !run.shared.finished.load(Ordering::Acquire) {
            std::thread::sleep(Duration::from_millis(1));
        }
        run
    }

    #[test]
    fn a_run_of_one_scene_ends_after_its_steps() {
        let outcome = finished_run(25).finish().unwrap();
        assert_eq!(outcome.world.steps(), 25);
        assert_eq!(outcome.scenes, 1);
    }

    /// A resumed world has run some of its steps: the run ends at the
    /// same step as the whole run would, not that many steps later.
    #[test]
    fn a_resumed_world_ends_at_the_runs_last_step() {
        let mut resumed = world(vec![line((0.6, 0.6), (0.7, 0.7), (0.01, 0.0))]);
        resumed.run(10);
        let run = Simulation::start(
            Scenes::One {
                world: Box::new(resumed),
                until: Some(25),
            },
            Pace::Max,
        );
        while !run.shared.finished.load(Ordering::Acquire) {
            std::thread::sleep(Duration::from_millis(1));
        }
        assert_eq!(run.finish().unwrap().world.steps(), 25);
    }

    /// Single steps taken while paused leave the measured rate as it was
    /// running, so that `+` after a pause doubles that pace.
    #[test]
    fn steps_while_paused_keep_the_running_rate() {
        let run = Simulation::start(
            Scenes::One {
                world: Box::new(world(vec![line((0.6, 0.6), (0.7, 0.7), (0.01, 0.0))])),
                until: None,
            },
            Pace::Max,
        );
        let latest_rate = |run: &Simulation| loop {
            run.shared.want_news();
            std::thread::sleep(Duration::from_millis(20));
            if let Some(s) = run.shared.take() {
                return s.rate;
            }
        };
        let deadline = Instant::now() + Duration::from_secs(10);
        while latest_rate(&run) < 1000.0 {
            assert!(Instant::now() < deadline, "the rate was never measured");
        }
        run.shared.paused.store(true, Ordering::Relaxed);
        std::thread::sleep(Duration::from_millis(300));
        for _ in 0..3 {
            run.shared.steps_requested.fetch_add(1, Ordering::Relaxed);
            std::thread::sleep(Duration::from_millis(300));
        }
        let rate = latest_rate(&run);
        assert!(rate >= 1000.0, "a paused run's rate fell to {rate} steps/s");
        run.finish().unwrap();
    }

    #[test]
    fn dead_generated_scenes_are_replaced() {
        let made = Arc::new(AtomicU64::new(0));
        let counter = Arc::clone(&made);
        let still = || world(vec![line((0.6, 0.6), (0.7, 0.7), (0.0, 0.0))]);
        let run = Simulation::start(
            Scenes::Generated {
                first: Box::new(still()),
                next: Box::new(move |_| {
                    counter.fetch_add(1, Ordering::Relaxed);
                    still()
                }),
                cycle: Duration::from_secs(3600),
            },
            Pace::Max,
        );
        let start = Instant::now();
        while made.load(Ordering::Relaxed) < 3 && start.elapsed() < Duration::from_secs(20) {
            std::thread::sleep(Duration::from_millis(10));
        }
        let outcome = run.finish().unwrap();
        assert!(outcome.scenes >= 3, "{} scenes", outcome.scenes);
        assert!(outcome.scene_elapsed < start.elapsed());
    }

    #[test]
    fn the_latest_state_is_taken_once() {
        let run = finished_run(0);
        assert!(run.shared.take().is_some());
        assert!(run.shared.take().is_none());
        run.finish().unwrap();
    }

    #[test]
    fn at_one_step_a_frame_the_run_waits_for_each_picture() {
        let run = Simulation::start(
            Scenes::One {
                world: Box::new(world(vec![line((0.6, 0.6), (0.7, 0.7), (0.001, 0.0))])),
                until: None,
            },
            Pace::PerFrame,
        );
        let mut steps = Vec::new();
        for _ in 0..10 {
            let start = Instant::now();
            let snapshot = loop {
                if let Some(s) = run.shared.take() {
                    break s;
                }
                assert!(start.elapsed() < Duration::from_secs(20), "no picture");
                std::thread::sleep(Duration::from_millis(1));
            };
            steps.push(snapshot.step);
            // A slow display: the run must not get ahead meanwhile.
            std::thread::sleep(Duration::from_millis(20));
        }
        // The first picture is of step 0 or 1, and each after it one step on.
        assert!(steps[0] <= 1, "{steps:?}");
        assert!(steps.windows(2).all(|w| w[1] == w[0] + 1), "{steps:?}");
        // At no limit it runs on without waiting.
        run.shared.set_pace(Pace::Max);
        std::thread::sleep(Duration::from_millis(50));
        let outcome = run.finish().unwrap();
        assert!(
            outcome.world.steps() > steps[9] + 50,
            "{}",
            outcome.world.steps()
        );
    }

    #[test]
    fn paces_change_and_show() {
        // + and - double and halve; from one step a frame or from no
        // limit they start at the measured rate.
        assert_eq!(Pace::Rate(100).changed(true, 5.0), Pace::Rate(200));
        assert_eq!(Pace::Rate(100).changed(false, 5.0), Pace::Rate(50));
        assert_eq!(Pace::Rate(1).changed(false, 5.0), Pace::Rate(1));
        assert_eq!(Pace::PerFrame.changed(true, 60.0), Pace::Rate(120));
        assert_eq!(Pace::PerFrame.changed(false, 60.0), Pace::Rate(30));
        assert_eq!(Pace::Max.changed(false, 9000.0), Pace::Rate(4500));
        assert_eq!(Pace::Max.changed(true, 9000.0), Pace::Max);
        assert_eq!(Pace::Rate(1 << 20).changed(true, 0.0), Pace::Max);
        for pace in [Pace::PerFrame, Pace::Max, Pace::Rate(7)] {
            assert_eq!(Pace::from_code(pace.code()), pace);
        }
        assert_eq!(Pace::PerFrame.to_string(), "1 step/frame");
        assert_eq!(Pace::Rate(240).to_string(), "240 steps/s max");
    }

    #[test]
    fn frame_rates_count_the_spans_between_frames() {
        let stats = DrawStats {
            frames: 11,
            drawing: Duration::from_millis(55),
            span: Duration::from_secs(2),
        };
        assert!((stats.fps() - 5.0).abs() < 1e-9);
        assert!((stats.seconds_per_frame() - 0.005).abs() < 1e-9);
        assert_eq!(DrawStats::default().fps(), 0.0);
    }
}
