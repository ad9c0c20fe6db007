//! What a run reports: the text the original program printed around it,
//! which every front end (the command line, the web page) prints the same
//! way (a header naming the frames and the input, and the results block),
//! and the statistics as data ([`Stats`]), which the command line words.

pub use crate::detect::SweepReport;
use crate::detect::{DetectorConfig, DetectorKind, DetectorStats};
use crate::generate::SceneKind;
pub use crate::team::HandOffs;
use crate::Scene;
use crate::{Counters, World};
use std::time::Duration;

/// The header: the frames asked for (`None`: an endless run) and the
/// input's name.
pub fn header(frames: Option<u64>, input: &str) -> String {
    let frames = frames.map_or("endless".to_string(), |f| f.to_string());
    format!("Number of frames = {frames}\nInput file path is: {input}\n")
}

/// The input's name in the header for a generated scene (its kind, lines
/// and seed), or for the built-in scene (`None`).
pub fn input_name(generated: Option<(SceneKind, usize, u64)>) -> String {
    match generated {
        Some((kind, lines, seed)) => {
            let lines = crate::plural(lines as u64, "line");
            format!("(none: generated {kind} scene, {lines}, seed {seed})")
        }
        None => format!(
            "(none: built-in scene, {} lines, seed {})",
            Scene::BUILT_IN_LINES,
            Scene::BUILT_IN_SEED
        ),
    }
}

/// The results block: the simulation's time in seconds and both counters.
///
/// ```
/// use screensaver::report::{header, input_name, results};
/// use screensaver::{DetectorKind, Scene, World};
///
/// // What `screensaver 10` prints.
/// let mut world = World::with_detector(&Scene::built_in(), DetectorKind::Sweep);
/// world.run(11);
/// let text = header(Some(10), &input_name(None)) + &results(0.0123, world.counters());
/// assert!(text.starts_with("Number of frames = 10\nInput file path is: (none: built-in"));
/// assert!(text.contains("Elapsed execution time: 0.012300s\n"));
/// ```
pub fn results(seconds: f64, counters: Counters) -> String {
    format!(
        "---- RESULTS ----\nElapsed execution time: {seconds:.6}s\n{} Line-Wall Collisions\n{} Line-Line Collisions\n---- END RESULTS ----\n",
        counters.wall, counters.line
    )
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

/// A run's statistics, as data for a program to word: the detector's
/// work and plan, the time of each phase, the thread team's hand-offs and
/// the pictures drawn (the command line's `--stats` prints them).
///
/// ```
/// use screensaver::report::Stats;
/// use screensaver::{DetectorConfig, DetectorKind, Scene, World};
///
/// let config = DetectorConfig::default();
/// let mut world = World::with_config(&Scene::built_in(), DetectorKind::Sweep, &config).unwrap();
/// world.set_timing(true);
/// world.run(20);
/// let stats = Stats::of(&world, DetectorKind::Sweep, &config, None);
/// assert_eq!((stats.lines, stats.steps), (1000, 20));
/// assert!(stats.work.candidate_pairs >= stats.work.exact_tests);
/// assert!(stats.plan.is_some_and(|plan| plan.steps == 20));
/// assert!(stats.detect > std::time::Duration::ZERO);
/// ```
#[derive(Clone, Debug)]
pub struct Stats {
    /// The detector.
    pub detector: DetectorKind,
    /// Its settings.
    pub config: DetectorConfig,
    /// The sweep's plan and how it kept its pairs (the sweep alone).
    pub plan: Option<SweepReport>,
    /// Lines in the world.
    pub lines: usize,
    /// Steps run.
    pub steps: u64,
    /// Threads that ran them ([`World::threads_run`]).
    pub threads: usize,
    /// The detector's counts.
    pub work: DetectorStats,
    /// Time finding events (zero unless [`World::set_timing`] was on).
    pub detect: Duration,
    /// Time resolving them.
    pub resolve: Duration,
    /// Time moving the lines and bouncing them off the walls.
    pub advance: Duration,
    /// The detector's own phases within `detect`, by name.
    pub detector_phases: Vec<(&'static str, Duration)>,
    /// What the thread team's hand-offs cost, where a team ran.
    pub team: Option<HandOffs>,
    /// The pictures drawn, if any.
    pub drawn: Option<DrawStats>,
}

impl Stats {
    /// The statistics of `world`, whose detector is of `kind` tuned by
    /// `config`, and of the pictures `drawn`, if any.
    pub fn of(
        world: &World,
        kind: DetectorKind,
        config: &DetectorConfig,
        drawn: Option<DrawStats>,
    ) -> Stats {
        let report = world.detector().report();
        let times = world.phase_times().unwrap_or_default();
        Stats {
            detector: kind,
            config: *config,
            plan: report.plan,
            lines: world.lines().len(),
            steps: world.steps(),
            threads: world.threads_run(),
            work: world.detector_stats(),
            detect: times.detect,
            resolve: times.resolve,
            advance: times.advance,
            detector_phases: report.phases,
            team: world.hand_offs(),
            drawn,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texts_are_the_original_programs() {
        assert_eq!(
            header(Some(300), "mit.in"),
            "Number of frames = 300\nInput file path is: mit.in\n"
        );
        assert_eq!(
            input_name(Some((SceneKind::Uniform, 2000, 7))),
            "(none: generated uniform scene, 2000 lines, seed 7)"
        );
        assert_eq!(
            input_name(None),
            "(none: built-in scene, 1000 lines, seed 6172)"
        );
        assert_eq!(
            header(None, "x").lines().next(),
            Some("Number of frames = endless")
        );
        let counters = Counters {
            wall: 495,
            line: 13446,
        };
        assert_eq!(
            results(0.0302781, counters),
            "---- RESULTS ----\nElapsed execution time: 0.030278s\n495 Line-Wall Collisions\n\
             13446 Line-Line Collisions\n---- END RESULTS ----\n"
        );
    }
}
