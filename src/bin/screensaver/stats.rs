//! The statistics `--stats` prints, in the command's words: as text after
//! the results, or as JSON under `"stats"`, from the library's
//! [`Stats`] (data).

use screensaver::report::{Stats, SweepReport};
use screensaver::DetectorKind;
use std::time::Duration;

/// The sweep's plan in a few words: the direction it sweeps along, its
/// bands, and how it kept its pairs.
fn plan_words(plan: &SweepReport) -> String {
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

/// The statistics as text, the block `--stats` prints.
pub(crate) fn text(stats: &Stats) -> String {
    let s = &stats.work;
    let steps = stats.steps.max(1) as f64;
    let per_step = |n: u64| n as f64 / steps;
    let total = (stats.detect + stats.resolve + stats.advance)
        .as_secs_f64()
        .max(1e-12);
    let phase = |name: &str, d: Duration| {
        format!(
            "  {name:<16}{:>12.6}s {:>6.1}%  {:>10.2} us/step\n",
            d.as_secs_f64(),
            100.0 * d.as_secs_f64() / total,
            d.as_secs_f64() * 1e6 / steps
        )
    };
    let tuning = match stats.detector {
        DetectorKind::Quadtree => format!(
            " (leaf size {}, max depth {})",
            stats.config.leaf_size, stats.config.max_depth
        ),
        _ => match &stats.plan {
            Some(plan) => format!(" ({})", plan_words(plan)),
            None => String::new(),
        },
    };
    let mut out = format!(
        "---- STATS ----\ndetector: {}{tuning}\nlines: {}, steps: {}, threads: {}\n",
        stats.detector.name(),
        stats.lines,
        stats.steps,
        stats.threads
    );
    out += &format!("{:<18}{:>16}{:>16}\n", "", "total", "per step");
    let tree = stats.detector == DetectorKind::Quadtree;
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
    out += &phase("detect", stats.detect);
    // The detector's own phases, within detect.
    for &(name, d) in &stats.detector_phases {
        if !d.is_zero() {
            out += &phase(&format!("  {name}"), d);
        }
    }
    out += &phase("resolve", stats.resolve);
    out += &phase("move and walls", stats.advance);
    if let Some(h) = stats.team.filter(|h| h.jobs > 0) {
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
    if let Some(d) = stats.drawn {
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
pub(crate) fn json(stats: &Stats) -> serde_json::Value {
    let (s, config) = (&stats.work, &stats.config);
    let mut value = serde_json::json!({
        "detector": stats.detector.name(),
        "threads": stats.threads,
        "candidate_pairs": s.candidate_pairs,
        "exact_tests": s.exact_tests,
        "events": s.events,
        "seconds": {
            "detect": stats.detect.as_secs_f64(),
            "detect_phases": stats
                .detector_phases
                .iter()
                .map(|(name, d)| (name.to_string(), serde_json::json!(d.as_secs_f64())))
                .collect::<serde_json::Map<_, _>>(),
            "resolve": stats.resolve.as_secs_f64(),
            "move_and_walls": stats.advance.as_secs_f64(),
        },
    });
    // The quadtree's tuning and its tree; the sweep's plan.
    match stats.detector {
        DetectorKind::Quadtree => {
            value["leaf_size"] = serde_json::json!(config.leaf_size);
            value["max_depth"] = serde_json::json!(config.max_depth);
            value["tree_nodes"] = serde_json::json!(s.nodes);
            value["tree_depth"] = serde_json::json!(s.max_depth);
        }
        _ => {
            if let Some(plan) = &stats.plan {
                value["plan"] = serde_json::json!(plan_words(plan));
            }
        }
    }
    if let Some(h) = stats.team {
        value["team"] = serde_json::json!({
            "hand_offs": h.jobs,
            "pieces": h.pieces,
            "member_pieces": h.member_pieces,
            "alone": h.alone,
            "wait_seconds": h.wait.as_secs_f64(),
            "parked_waits": h.parked,
        });
    }
    if let Some(d) = stats.drawn {
        value["frames_drawn"] = serde_json::json!(d.frames);
        value["drawn_fps"] = serde_json::json!(d.fps());
        value["draw_seconds_per_frame"] = serde_json::json!(d.seconds_per_frame());
    }
    value
}

#[cfg(test)]
mod tests {
    use super::*;
    use screensaver::generate::{generate, SceneKind};
    use screensaver::report::DrawStats;
    use screensaver::{DetectorConfig, World};

    #[test]
    fn statistics_read_as_text_and_as_json() {
        let scene = generate(SceneKind::Uniform, 300, 5);
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
        let text = text(&stats);
        assert!(text.starts_with("---- STATS ----\ndetector: quadtree (leaf size "));
        assert!(text.contains("lines: 300, steps: 7, threads: "), "{text}");
        assert!(text.contains("frames drawn: 3, 50.0 frames/s, 10.000 ms a frame to draw"));
        assert!(text.ends_with("---- END STATS ----\n"));
        let json = json(&stats);
        assert_eq!(json["detector"], "quadtree");
        assert_eq!(json["events"], world.detector_stats().events);
        assert_eq!(json["frames_drawn"], 3);
        assert!(json["seconds"]["detect"].as_f64().unwrap() > 0.0);
    }

    #[test]
    fn the_sweeps_plan_is_worded() {
        let scene = generate(SceneKind::Uniform, 20_000, 5);
        let config = DetectorConfig::default();
        let mut world = World::with_config(&scene, DetectorKind::Sweep, &config).unwrap();
        world.run(3);
        let text = text(&Stats::of(&world, DetectorKind::Sweep, &config, None));
        assert!(text.contains("detector: sweep (along "), "{text}");
    }
}
