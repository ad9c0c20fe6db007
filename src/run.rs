//! A batch run: steps, and what may go around each of them (the all-pairs
//! check of `--verify`, pictures written as the run goes, checkpoints every
//! so many steps, a progress callback, a way to stop early), with the
//! simulation's own time measured apart from all of these.

use crate::detect::clock::now as clock;
use crate::output;
#[cfg(feature = "render")]
use crate::render::Recorder;
use crate::report::DrawStats;
use crate::verify::Verifier;
use crate::World;
use std::ops::ControlFlow;
use std::path::Path;
use std::time::{Duration, Instant};

/// Checkpoints of a run: written to `path` every `every` steps (if set), of
/// a scene whose digest ([`crate::Scene::digest`]) is `digest`.
#[derive(Clone, Copy, Debug)]
pub struct Checkpoints<'a> {
    /// Where.
    pub path: &'a Path,
    /// Steps between two checkpoints.
    pub every: Option<u64>,
    /// The scene's digest.
    pub digest: u64,
}

impl Checkpoints<'_> {
    /// Whether a checkpoint is due after this step.
    fn due(&self, world: &World) -> bool {
        self.every.is_some_and(|k| world.steps() % k == 0)
    }

    /// Writes the world's checkpoint, whole or not at all.
    pub fn save(&self, world: &World) -> Result<(), RunError> {
        output::write_with(self.path, |out| {
            crate::checkpoint::Checkpoint::write(world, self.digest, out)
        })
        .map_err(RunError::Checkpoint)
    }
}

/// What goes around the steps of a run; by default nothing.
///
/// ```
/// use screensaver::run::Run;
/// use screensaver::{DetectorKind, Scene, World};
///
/// let mut world = World::with_detector(&Scene::built_in(), DetectorKind::Sweep);
/// let mut seen = 0;
/// let mut progress = |_: &World, _| seen += 1;
/// let run = Run {
///     verify: true, // every step checked against all pairs
///     progress: Some(&mut progress),
///     ..Run::default()
/// };
/// let ran = run.run(&mut world, 101).expect("the sweep agrees with all pairs");
/// assert!(!ran.stopped);
/// assert_eq!((world.steps(), seen), (101, 101));
/// ```
#[derive(Default)]
pub struct Run<'a> {
    /// Checks every step against the all-pairs detector.
    pub verify: bool,
    /// Writes pictures as the run goes.
    #[cfg(feature = "render")]
    pub recorder: Option<Recorder>,
    /// Writes checkpoints as the run goes.
    pub checkpoints: Option<Checkpoints<'a>>,
    /// Called after each step with the world and the time since the run
    /// started.
    #[allow(clippy::type_complexity)] // a named alias would be one more public item
    pub progress: Option<&'a mut (dyn FnMut(&World, Duration) + Send)>,
    /// Asked after each step (after `progress`); the run ends there when
    /// it answers yes. A signal (SIGINT, SIGTERM) ends it there too.
    pub stop: Option<&'a (dyn Fn(&World) -> bool + Sync)>,
}

/// How a run went.
#[derive(Clone, Copy, Debug)]
pub struct Ran {
    /// The simulation's time: the run's, less the time spent writing
    /// pictures and checkpoints and checking steps against all pairs.
    pub elapsed: Duration,
    /// The pictures written, and the time that took.
    pub pictures: Option<DrawStats>,
    /// Whether [`Run::stop`] ended the run early.
    pub stopped: bool,
    /// With [`Run::verify`]: the sliver events met (events the all-pairs
    /// detector finds and the detector does not, every one the contract's
    /// documented exception), and the step and event of the first.
    pub slivers: Option<(u64, Option<(u64, crate::Event)>)>,
}

/// Why a run could not go on.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// A picture could not be written.
    #[cfg(feature = "render")]
    #[error(transparent)]
    Picture(#[from] crate::render::RenderError),
    /// A checkpoint could not be written.
    #[error(transparent)]
    Checkpoint(crate::output::OutputError),
    /// A step's events differed from the all-pairs detector's (by more
    /// than sliver events).
    #[error("{}", crate::verify::Mismatch::words(*step, expected, found))]
    Mismatch {
        /// The step (counting from 1) whose events differed.
        step: u64,
        /// The all-pairs detector's events, sorted.
        expected: Vec<crate::Event>,
        /// The detector's, sorted.
        found: Vec<crate::Event>,
    },
}

impl From<crate::verify::Mismatch> for RunError {
    fn from(m: crate::verify::Mismatch) -> Self {
        let crate::verify::Mismatch {
            step,
            expected,
            found,
        } = m;
        RunError::Mismatch {
            step,
            expected,
            found,
        }
    }
}

/// Whether a signal asked the program to stop.
pub(crate) fn signalled() -> bool {
    #[cfg(feature = "signals")]
    return crate::stop::requested().is_some();
    #[cfg(not(feature = "signals"))]
    return false;
}

impl Run<'_> {
    /// Runs `steps` steps of `world` (fewer if stopped or an error ends the
    /// run).
    pub fn run(self, world: &mut World, steps: u64) -> Result<Ran, RunError> {
        let Run {
            verify,
            #[cfg(feature = "render")]
            mut recorder,
            checkpoints,
            mut progress,
            stop,
        } = self;
        let mut verifier = verify.then(Verifier::new);
        // Time spent writing pictures, and checkpoints.
        #[cfg_attr(not(feature = "render"), allow(unused_mut))]
        let mut drawing = Duration::ZERO;
        let mut saving = Duration::ZERO;
        #[cfg(feature = "render")]
        if let Some(recorder) = &mut recorder {
            let started = Instant::now();
            recorder.start(world)?;
            drawing += started.elapsed();
        }
        let mut failed = None;
        // The first picture is drawn before the loop's clock starts.
        let drawn_before = drawing;
        let start = clock();
        let since_start = || start.map_or(Duration::ZERO, |s| s.elapsed());
        // The oracle gives up its step when a signal comes: nothing runs.
        let given_up = verifier.as_mut().is_some_and(|v| !v.before_step(world));
        let mut mismatch = None;
        let mut ran = 0;
        let to_run = if given_up { 0 } else { steps };
        let stopped = world.run_with(to_run, |world| {
            ran += 1;
            if let Some(verifier) = &mut verifier {
                if let Err(m) = verifier.after_step(world) {
                    mismatch = Some(m);
                    return ControlFlow::Break(false);
                }
            }
            #[cfg(feature = "render")]
            if let Some(recorder) = &mut recorder {
                let started = Instant::now();
                let written = recorder.after_step(world);
                drawing += started.elapsed();
                if let Err(e) = written {
                    failed = Some(RunError::Picture(e));
                    return ControlFlow::Break(false);
                }
            }
            if let Some(checkpoints) = checkpoints.filter(|c| c.due(world)) {
                let started = Instant::now();
                let saved = checkpoints.save(world);
                saving += started.elapsed();
                if let Err(e) = saved {
                    failed = Some(e);
                    return ControlFlow::Break(false);
                }
            }
            if let Some(progress) = &mut progress {
                progress(world, since_start());
            }
            if stop.is_some_and(|stop| stop(world)) || signalled() {
                return ControlFlow::Break(true);
            }
            // The oracle's events for the next step, if there is one.
            if let Some(verifier) = verifier.as_mut().filter(|_| ran < steps) {
                if !verifier.before_step(world) {
                    return ControlFlow::Break(true);
                }
            }
            ControlFlow::Continue(())
        });
        // A step given up part way on a signal, the oracle's or the
        // world's, ended the run there.
        let stopped = stopped.or((given_up || world.gave_up_step()).then_some(true));
        // The simulation alone: not the pictures, the checkpoints, nor the
        // all-pairs check of --verify.
        let verifying = verifier.as_ref().map_or(Duration::ZERO, |v| v.time);
        let elapsed = since_start().saturating_sub(drawing - drawn_before + saving + verifying);
        if let Some(e) = failed {
            return Err(e);
        }
        if let Some(mismatch) = mismatch {
            return Err(mismatch.into());
        }
        #[cfg(feature = "render")]
        let pictures = match recorder {
            Some(recorder) => {
                let started = Instant::now();
                let frames = recorder.finish(world)?;
                drawing += started.elapsed();
                Some(DrawStats {
                    frames,
                    drawing,
                    span: Duration::ZERO,
                })
            }
            None => None,
        };
        #[cfg(not(feature = "render"))]
        let pictures = None;
        Ok(Ran {
            elapsed,
            pictures,
            stopped: stopped == Some(true),
            slivers: verifier.map(|v| (v.slivers, v.first_sliver)),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::generate::{generate, SceneKind};
    use crate::DetectorKind;
    use std::sync::atomic::{AtomicU64, Ordering};

    fn world() -> World {
        World::with_detector(&generate(SceneKind::Uniform, 200, 3), DetectorKind::Sweep)
    }

    #[test]
    fn a_run_reports_its_progress_and_stops_when_asked() {
        let mut world = world();
        let mut seen = Vec::new();
        let mut progress = |world: &World, _: Duration| seen.push(world.steps());
        let asked = AtomicU64::new(0);
        let stop = |_: &World| asked.fetch_add(1, Ordering::Relaxed) + 1 >= 7;
        let ran = Run {
            verify: true,
            progress: Some(&mut progress),
            stop: Some(&stop),
            ..Run::default()
        }
        .run(&mut world, 20)
        .unwrap();
        assert!(ran.stopped);
        assert_eq!(world.steps(), 7);
        assert_eq!(seen, (1..=7).collect::<Vec<_>>());
        assert!(ran.pictures.is_none());
        let mut plain = self::world();
        plain.run(7);
        assert_eq!(plain.counters(), world.counters());
    }

    #[test]
    fn checkpoints_are_written_as_the_run_goes() {
        let folder = tempfile::tempdir().unwrap();
        let path = folder.path().join("run.ckpt");
        let mut world = world();
        let ran = Run {
            checkpoints: Some(Checkpoints {
                path: &path,
                every: Some(4),
                digest: 9,
            }),
            ..Run::default()
        }
        .run(&mut world, 10)
        .unwrap();
        assert!(!ran.stopped);
        let text = std::fs::read_to_string(&path).unwrap();
        let saved = crate::checkpoint::Checkpoint::parse(text.as_bytes(), "run.ckpt").unwrap();
        assert_eq!((saved.steps, saved.scene_digest), (8, 9));
        let bad = Checkpoints {
            path: Path::new("/proc/run.ckpt"),
            every: Some(1),
            digest: 9,
        };
        let failed = Run {
            checkpoints: Some(bad),
            ..Run::default()
        }
        .run(&mut self::world(), 3);
        assert!(matches!(failed, Err(RunError::Checkpoint(_))));
    }
}
