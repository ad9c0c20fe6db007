//! What a run reports: the text the original program printed around it,
//! which every front end (the command line, the web page) prints the same
//! way (a header naming the frames and the input, and the results block),
//! and the statistics `--stats` adds, as text and as JSON.

use crate::detect::{DetectorConfig, DetectorKind, DetectorStats, SweepReport};
use crate::generate::{SceneKind, DEFAULT_LINES, DEFAULT_SEED};
use crate::team::HandOffs;
use crate::world::PhaseTimes;
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
        None => format!("(none: built-in scene, {DEFAULT_LINES} lines, seed {DEFAULT_SEED})"),
    }
}

/// The results block: the simulation's time in seconds and both counters.
///
/// ```
/// use screensaver::report::{header, input_name, results};
/// use screensaver::{generate::default_scene, DetectorKind, World};
///
/// // What `screensaver 10` prints.
/// let mut world = World::with_detector(&default_scene(), DetectorKind::Sweep);
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

/// The sweep's plan in a few words, for `--stats`: the direction it
/// sweeps along, its bands, and how it kept its pairs.
pub(crate) fn plan_words(plan: &SweepReport) -> String {
    // `u` and `w` are the diagonals.
    let name = ["x", "y", "the diagonal x+y", "the diagonal x-y"];
    let along = name[plan.along];
    let swept = match plan.bands {
        1 => format!("along {along}, one band"),
        count => format!("along {along}, {count} bands across {}", name[plan.across]),
    };
    let (keeping, sweeps) = (plan.keeping, plan.sweeps);
    match (sweeps, keeping - sweeps) {
        (0, _) => swept,
        (tries, 0) => format!("{swept}; pairs tried {tries} times, not kept"),
        (_, kept) => format!(
            "{swept}; pairs kept on {kept} of {} steps, a sweep every {:.1} and {:.1} \
             boxes mended a step while kept, {}",
            plan.steps,
            keeping as f64 / sweeps as f64,
            plan.mended as f64 / keeping as f64,
            match plan.moving {
                0 => "no sweep in a moving frame".to_string(),
                moving => format!("{moving} of its {sweeps} sweeps in a moving frame"),
            }
        ),
    }
}

/// A run's statistics: the detector's work, the time of each phase, the
/// thread team's hand-offs and the pictures drawn.
///
/// ```
/// use screensaver::report::Stats;
/// use screensaver::{generate::default_scene, DetectorConfig, DetectorKind, World};
///
/// let config = DetectorConfig::default();
/// let mut world = World::with_config(&default_scene(), DetectorKind::Sweep, &config).unwrap();
/// world.set_timing(true);
/// world.run(20);
/// let stats = Stats::of(&world, DetectorKind::Sweep, &config, None);
/// assert!(stats.text().contains("lines: 1000, steps: 20"));
/// assert!(stats.json().starts_with("{"));
/// ```
#[derive(Clone, Debug)]
pub struct Stats {
    kind: DetectorKind,
    config: DetectorConfig,
    /// How the detector is working, in a few words (the sweep's plan).
    plan: String,
    lines: usize,
    steps: u64,
    threads: usize,
    work: DetectorStats,
    times: PhaseTimes,
    detector_phases: Vec<(&'static str, Duration)>,
    hand_offs: Option<HandOffs>,
    drawn: Option<DrawStats>,
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
        Stats {
            kind,
            config: *config,
            plan: (world.detector().report().plan)
                .map(|plan| plan_words(&plan))
                .unwrap_or_default(),
            lines: world.lines().len(),
            steps: world.steps(),
            threads: world.threads_run(),
            work: world.detector_stats(),
            times: world.phase_times().unwrap_or_default(),
            detector_phases: world.detector().report().phases,
            hand_offs: world.hand_offs(),
            drawn,
        }
    }

    /// The statistics as text, the block `--stats` prints.
    pub fn text(&self) -> String {
        let (s, t) = (&self.work, &self.times);
        let steps = self.steps.max(1) as f64;
        let per_step = |n: u64| n as f64 / steps;
        let total = (t.detect + t.resolve + t.advance).as_secs_f64().max(1e-12);
        let phase = |name: &str, d: Duration| {
            format!(
                "  {name:<16}{:>12.6}s {:>6.1}%  {:>10.2} us/step\n",
                d.as_secs_f64(),
                100.0 * d.as_secs_f64() / total,
                d.as_secs_f64() * 1e6 / steps
            )
        };
        let tuning = match self.kind {
            DetectorKind::Quadtree => format!(
                " (leaf size {}, max depth {})",
                self.config.leaf_size, self.config.max_depth
            ),
            _ if !self.plan.is_empty() => format!(" ({})", self.plan),
            _ => String::new(),
        };
        let mut out = format!(
            "---- STATS ----\ndetector: {}{tuning}\nlines: {}, steps: {}, threads: {}\n",
            self.kind.name(),
            self.lines,
            self.steps,
            self.threads
        );
        out += &format!("{:<18}{:>16}{:>16}\n", "", "total", "per step");
        let tree = self.kind == DetectorKind::Quadtree;
        let counts = [
            ("candidate pairs", s.candidate_pairs),
            ("exact tests", s.exact_tests),
            ("events", s.events),
        ];
        let nodes = tree.then_some(("tree nodes", s.nodes));
        for (name, n) in counts.into_iter().chain(nodes) {
            out += &format!("{name:<18}{n:>16}{:>16.1}\n", per_step(n));
        }
        if tree {
            out += &format!("tree depth (max)  {:>16}\n", s.max_depth);
        }
        out += "time per phase:\n";
        out += &phase("detect", t.detect);
        // The detector's own phases, within detect.
        for &(name, d) in &self.detector_phases {
            if !d.is_zero() {
                out += &phase(&format!("  {name}"), d);
            }
        }
        out += &phase("resolve", t.resolve);
        out += &phase("move and walls", t.advance);
        if let Some(h) = self.hand_offs.filter(|h| h.jobs > 0) {
            let jobs = h.jobs as f64;
            out += &format!(
                "team: {:.1} hand-offs a step, {:.1} pieces each; the other threads ran \
                 {:.1}% of the pieces; {} of the {} hand-offs ran wholly on the stepping \
                 thread; it waited {:.2} us a step for pieces running elsewhere, and slept \
                 {} times\n",
                jobs / steps,
                h.pieces as f64 / jobs,
                100.0 * h.member_pieces as f64 / (h.pieces as f64).max(1.0),
                h.alone,
                h.jobs,
                h.wait.as_secs_f64() * 1e6 / steps,
                h.parked,
            );
        }
        if let Some(d) = self.drawn {
            // Pictures written to files have no rate of their own.
            let rate = if d.span.is_zero() {
                String::new()
            } else {
                format!(", {:.1} frames/s", d.fps())
            };
            out += &format!(
                "frames drawn: {}{rate}, {:.3} ms a frame to draw\n",
                d.frames,
                d.seconds_per_frame() * 1e3
            );
        }
        out += "---- END STATS ----\n";
        out
    }

    /// The statistics as a JSON object (keys in `snake_case`), what
    /// `--stats --json` puts under `"stats"`.
    pub fn json(&self) -> String {
        self.json_value().to_string()
    }

    /// [`Stats::json`] as a value, for the job's results to hold.
    pub(crate) fn json_value(&self) -> serde_json::Value {
        let (s, t, config) = (&self.work, &self.times, &self.config);
        let mut value = serde_json::json!({
            "detector": self.kind.name(),
            "threads": self.threads,
            "candidate_pairs": s.candidate_pairs,
            "exact_tests": s.exact_tests,
            "events": s.events,
            "seconds": {
                "detect": t.detect.as_secs_f64(),
                "detect_phases": self
                    .detector_phases
                    .iter()
                    .map(|(name, d)| (name.to_string(), serde_json::json!(d.as_secs_f64())))
                    .collect::<serde_json::Map<_, _>>(),
                "resolve": t.resolve.as_secs_f64(),
                "move_and_walls": t.advance.as_secs_f64(),
            },
        });
        // The quadtree's tuning and its tree; the sweep's plan.
        match self.kind {
            DetectorKind::Quadtree => {
                value["leaf_size"] = serde_json::json!(config.leaf_size);
                value["max_depth"] = serde_json::json!(config.max_depth);
                value["tree_nodes"] = serde_json::json!(s.nodes);
                value["tree_depth"] = serde_json::json!(s.max_depth);
            }
            _ if !self.plan.is_empty() => value["plan"] = serde_json::json!(self.plan),
            _ => {}
        }
        if let Some(h) = self.hand_offs {
            value["team"] = serde_json::json!({
                "hand_offs": h.jobs,
                "pieces": h.pieces,
                "member_pieces": h.member_pieces,
                "alone": h.alone,
                "wait_seconds": h.wait.as_secs_f64(),
                "parked_waits": h.parked,
            });
        }
        if let Some(d) = self.drawn {
            value["frames_drawn"] = serde_json::json!(d.frames);
            value["drawn_fps"] = serde_json::json!(d.fps());
            value["draw_seconds_per_frame"] = serde_json::json!(d.seconds_per_frame());
        }
        value
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_read_as_text_and_as_json() {
        let scene = crate::generate::generate(SceneKind::Uniform, 300, 5);
        let config = DetectorConfig::default();
        let mut world = World::with_config(&scene, DetectorKind::Quadtree, &config).unwrap();
        world.set_timing(true);
        world.run(7);
        let drawn = DrawStats {
            frames: 3,
            drawing: Duration::from_millis(30),
            span: Duration::from_millis(40),
        };
        let stats = Stats::of(&world, DetectorKind::Quadtree, &config, Some(drawn));
        let text = stats.text();
        assert!(text.starts_with("---- STATS ----\ndetector: quadtree (leaf size "));
        assert!(text.contains("lines: 300, steps: 7, threads: "), "{text}");
        assert!(text.contains("frames drawn: 3, 50.0 frames/s, 10.000 ms a frame to draw"));
        assert!(text.ends_with("---- END STATS ----\n"));
        let json: serde_json::Value = serde_json::from_str(&stats.json()).unwrap();
        assert_eq!(json["detector"], "quadtree");
        assert_eq!(json["events"], world.detector_stats().events);
        assert_eq!(json["frames_drawn"], 3);
        assert!(json["seconds"]["detect"].as_f64().unwrap() > 0.0);
    }

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
