//! A live run: the simulation on its own thread, as fast as it may (or at
//! a set pace), leaving its latest state for whatever shows it (the
//! window, or a window another program owns) to take at the display's
//! pace. Endless runs go on until told to stop; runs of generated scenes
//! start a new scene every so often, and whenever a scene has died out.

use crate::line::{Color, Line};
use crate::World;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// Where the scenes of a live run come from.
pub enum Scenes {
    /// One world, run for `steps` steps, or until stopped if `None`.
    One {
        /// The world (boxed: a world is large beside the other variant).
        world: Box<World>,
        /// Steps to run.
        steps: Option<u64>,
    },
    /// Generated scenes without end: `first`, then `next(k)` for the
    /// `k`-th (from 1); a new one starts after `cycle`, or as soon as the
    /// scene on show has died out (see [`died_out`]).
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

/// True when nothing more can happen in the world: every line is NaN, or
/// none of them moves.
pub fn died_out(lines: &[Line]) -> bool {
    lines
        .iter()
        .all(|l| l.is_inert() || (l.v.x == 0.0 && l.v.y == 0.0))
}

/// A state of the run, for showing.
pub struct Snapshot {
    /// Every line.
    pub lines: Vec<Line>,
    /// Their colours (shared until the scene changes).
    pub colors: Arc<Vec<Color>>,
    /// Steps run in this scene.
    pub step: u64,
    /// Line-wall collisions in this scene.
    pub wall: u64,
    /// Line-line collisions in this scene.
    pub line: u64,
    /// Steps per second, lately.
    pub rate: f64,
    /// Which scene (from 0).
    pub scene: u64,
}

/// What the simulation thread and the display share.
pub struct Shared {
    /// The simulation waits while set (but for single steps).
    pub paused: AtomicBool,
    /// Single steps asked for while paused.
    pub steps_requested: AtomicU64,
    /// Steps per second allowed; 0 for no limit.
    pub limit: AtomicU64,
    /// Set by the display to end the run.
    pub quit: AtomicBool,
    /// Set by the simulation when it has run every step.
    pub finished: AtomicBool,
    /// The latest state, for the display to take.
    latest: Mutex<Option<Snapshot>>,
    /// Whether the display has taken the latest state (so a new one is
    /// wanted).
    taken: AtomicBool,
    /// Lines of a state the display is done with, for the next snapshot to
    /// fill (a million lines are 48 MB: fresh memory each time costs its
    /// page faults, and freeing it the display's time).
    spare: Mutex<Vec<Line>>,
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
        *self.spare.lock().expect("no panics while holding the lock") = old.lines;
    }

    /// True when a state is waiting to be taken.
    pub fn has_news(&self) -> bool {
        self.latest.lock().is_ok_and(|l| l.is_some())
    }

    /// Asks for a fresh state even if nothing moves (after a pause).
    pub fn want_news(&self) {
        self.taken.store(true, Ordering::Release);
    }
}

/// The outcome of a live run.
pub struct Outcome {
    /// The world on show when the run ended.
    pub world: World,
    /// The time the simulation loop ran (pauses included).
    pub elapsed: Duration,
    /// Scenes shown (1 unless generated scenes were cycled).
    pub scenes: u64,
}

/// A live run under way.
pub struct Run {
    /// What the display shares with the simulation.
    pub shared: Arc<Shared>,
    thread: std::thread::JoinHandle<Outcome>,
}

impl Run {
    /// Starts the simulation thread.
    pub fn start(scenes: Scenes) -> Run {
        let shared = Arc::new(Shared {
            paused: AtomicBool::new(false),
            steps_requested: AtomicU64::new(0),
            limit: AtomicU64::new(0),
            quit: AtomicBool::new(false),
            finished: AtomicBool::new(false),
            latest: Mutex::new(None),
            taken: AtomicBool::new(true),
            spare: Mutex::new(Vec::new()),
        });
        let thread = {
            let shared = Arc::clone(&shared);
            std::thread::spawn(move || simulate(scenes, &shared))
        };
        Run { shared, thread }
    }

    /// Tells the simulation to stop and waits for it.
    pub fn finish(self) -> Result<Outcome, String> {
        self.shared.quit.store(true, Ordering::Relaxed);
        self.thread
            .join()
            .map_err(|_| "the simulation thread panicked".to_string())
    }
}

/// The simulation thread: runs the scenes, obeying pause, single steps and
/// the speed limit, and leaves a snapshot whenever the display has taken
/// the last one.
fn simulate(scenes: Scenes, shared: &Shared) -> Outcome {
    let start = Instant::now();
    let (mut world, steps, mut next, cycle) = match scenes {
        Scenes::One { world, steps } => (*world, steps, None, None),
        Scenes::Generated { first, next, cycle } => (*first, None, Some(next), Some(cycle)),
    };
    let mut scene = 0;
    let mut colors = Arc::new(world.colors().to_vec());
    let mut scene_start = Instant::now();
    let mut last_check = Instant::now();
    let (mut window_start, mut window_steps) = (Instant::now(), 0u64);
    let mut rate = 0.0;
    let publish = |world: &World, colors: &Arc<Vec<Color>>, scene, rate, force: bool| {
        if force || shared.taken.swap(false, Ordering::AcqRel) {
            let c = world.counters();
            let mut lines = std::mem::take(
                &mut *shared
                    .spare
                    .lock()
                    .expect("no panics while holding the lock"),
            );
            lines.clear();
            lines.extend_from_slice(&world.lines());
            let snapshot = Snapshot {
                lines,
                colors: Arc::clone(colors),
                step: world.steps(),
                wall: c.wall,
                line: c.line,
                rate,
                scene,
            };
            *shared
                .latest
                .lock()
                .expect("no panics while holding the lock") = Some(snapshot);
        }
    };
    publish(&world, &colors, scene, 0.0, true);
    while steps.is_none_or(|s| world.steps() < s) && !shared.quit.load(Ordering::Relaxed) {
        if crate::stop::requested().is_some() {
            break;
        }
        if let (Some(next), Some(cycle)) = (&mut next, cycle) {
            let due = scene_start.elapsed() >= cycle;
            let dead = last_check.elapsed() >= DEATH_CHECK_EVERY && {
                last_check = Instant::now();
                died_out(&world.lines())
            };
            if due || dead {
                scene += 1;
                world = next(scene);
                colors = Arc::new(world.colors().to_vec());
                scene_start = Instant::now();
                publish(&world, &colors, scene, rate, true);
            }
        }
        let paused = shared.paused.load(Ordering::Relaxed);
        if paused && shared.steps_requested.load(Ordering::Relaxed) == 0 {
            std::thread::sleep(Duration::from_millis(5));
            continue;
        }
        if paused {
            shared.steps_requested.fetch_sub(1, Ordering::Relaxed);
        }
        let step_start = Instant::now();
        world.step();
        window_steps += 1;
        if window_start.elapsed() >= Duration::from_millis(250) {
            rate = window_steps as f64 / window_start.elapsed().as_secs_f64();
            (window_start, window_steps) = (Instant::now(), 0);
        }
        publish(&world, &colors, scene, rate, paused);
        let limit = shared.limit.load(Ordering::Relaxed);
        if limit > 0 {
            let budget = Duration::from_secs_f64(1.0 / limit as f64);
            if let Some(rest) = budget.checked_sub(step_start.elapsed()) {
                std::thread::sleep(rest);
            }
        }
    }
    let elapsed = start.elapsed();
    publish(&world, &colors, scene, rate, true);
    shared.finished.store(true, Ordering::Release);
    Outcome {
        world,
        elapsed,
        scenes: scene + 1,
    }
}

/// Frames drawn and the time drawing them took.
#[derive(Clone, Copy, Debug, Default)]
pub struct DrawStats {
    /// Frames drawn.
    pub frames: u64,
    /// Time spent drawing them (painting and handing them to the display).
    pub drawing: Duration,
    /// Time from the first frame to the last.
    pub span: Duration,
}

impl DrawStats {
    /// Frames drawn per second over the run.
    pub fn fps(&self) -> f64 {
        if self.frames < 2 || self.span.is_zero() {
            return 0.0;
        }
        (self.frames - 1) as f64 / self.span.as_secs_f64()
    }

    /// The mean time a frame took to draw.
    pub fn seconds_per_frame(&self) -> f64 {
        if self.frames == 0 {
            return 0.0;
        }
        self.drawing.as_secs_f64() / self.frames as f64
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
        World::new(lines, colors, Box::new(Brute::default()))
    }

    /// A run of one scene of one moving line for `steps` steps, once the
    /// simulation has finished it.
    fn finished_run(steps: u64) -> Run {
        let run = Run::start(Scenes::One {
            world: Box::new(world(vec![line((0.6, 0.6), (0.7, 0.7), (0.01, 0.0))])),
            steps: Some(steps),
        });
        while !run.shared.finished.load(Ordering::Acquire) {
            std::thread::sleep(Duration::from_millis(1));
        }
        run
    }

    #[test]
    fn a_scene_dies_out_when_nothing_moves_or_all_is_nan() {
        let moving = line((0.6, 0.6), (0.7, 0.7), (0.01, 0.0));
        let still = line((0.6, 0.6), (0.7, 0.7), (0.0, 0.0));
        let nan = line((f64::NAN, f64::NAN), (f64::NAN, f64::NAN), (0.01, 0.0));
        assert!(!died_out(&[moving, still]));
        assert!(died_out(&[still, still]));
        assert!(died_out(&[nan, still]));
        assert!(died_out(&[]));
    }

    #[test]
    fn a_run_of_one_scene_ends_after_its_steps() {
        let outcome = finished_run(25).finish().unwrap();
        assert_eq!(outcome.world.steps(), 25);
        assert_eq!(outcome.scenes, 1);
    }

    #[test]
    fn dead_generated_scenes_are_replaced() {
        let made = Arc::new(AtomicU64::new(0));
        let counter = Arc::clone(&made);
        let still = || world(vec![line((0.6, 0.6), (0.7, 0.7), (0.0, 0.0))]);
        let run = Run::start(Scenes::Generated {
            first: Box::new(still()),
            next: Box::new(move |_| {
                counter.fetch_add(1, Ordering::Relaxed);
                still()
            }),
            cycle: Duration::from_secs(3600),
        });
        let start = Instant::now();
        while made.load(Ordering::Relaxed) < 3 && start.elapsed() < Duration::from_secs(20) {
            std::thread::sleep(Duration::from_millis(10));
        }
        let outcome = run.finish().unwrap();
        assert!(outcome.scenes >= 3, "{} scenes", outcome.scenes);
    }

    #[test]
    fn the_latest_state_is_taken_once() {
        let run = finished_run(0);
        assert!(run.shared.take().is_some());
        assert!(run.shared.take().is_none());
        run.finish().unwrap();
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
