//! Results are bit-identical for any number of threads, on a scene large
//! enough that every parallel path (filling, tree walks, moving, walls)
//! splits its work with the default grain.

use screensaver::generate::{generate, SceneKind};
use screensaver::{DetectorConfig, DetectorKind, Line, World};

/// The lines and the (wall, line) counts after `steps` steps of a
/// generated scene (`kind`, `lines` lines, `seed`) with `detector` on
/// `threads` threads.
fn run(
    detector: DetectorKind,
    (kind, lines, seed): (SceneKind, usize, u64),
    threads: usize,
    steps: u64,
) -> (Vec<Line>, (u64, u64)) {
    let config = DetectorConfig {
        threads,
        ..DetectorConfig::default()
    };
    run_with(detector, (kind, lines, seed), &config, steps)
}

/// [`run`] with the whole of `config`.
fn run_with(
    detector: DetectorKind,
    (kind, lines, seed): (SceneKind, usize, u64),
    config: &DetectorConfig,
    steps: u64,
) -> (Vec<Line>, (u64, u64)) {
    let scene = generate(kind, lines, seed);
    let mut world = World::with_config(&scene, detector, config).expect("a thread pool");
    world.run(steps);
    let c = world.counters();
    (world.lines().to_vec(), (c.wall, c.line))
}

fn same_bits(a: &[Line], b: &[Line]) -> bool {
    let bits = |l: &Line| [l.p1.x, l.p1.y, l.p2.x, l.p2.y, l.v.x, l.v.y].map(f64::to_bits);
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| bits(x) == bits(y))
}

#[test]
fn any_thread_count_gives_the_same_bits() {
    for kind in [SceneKind::Uniform, SceneKind::Clustered] {
        let scene = (kind, 100_000, 7);
        let (lines, counts) = run(DetectorKind::Quadtree, scene, 1, 6);
        assert!(counts.1 > 0, "the scene should have collisions");
        for threads in [2, 3, 8] {
            let (other, other_counts) = run(DetectorKind::Quadtree, scene, threads, 6);
            assert_eq!(counts, other_counts, "{kind} on {threads} threads");
            assert!(same_bits(&lines, &other), "{kind} on {threads} threads");
        }
    }
}

/// The sweep shares its phases among the team at this size with the
/// default grain, and moves the lines in pieces of a few hundred lines
/// (claimed by whichever thread is free) with a grain of that size.
#[test]
fn the_sweep_gives_the_same_bits_on_any_thread_count() {
    let run = |threads, grain| {
        let scene = (SceneKind::Clustered, 100_000, 7);
        let config = DetectorConfig {
            threads,
            grain,
            ..DetectorConfig::default()
        };
        run_with(DetectorKind::Sweep, scene, &config, 4)
    };
    let default = DetectorConfig::default().grain;
    let (lines, counts) = run(1, default);
    for (threads, grain) in [(2, default), (3, default), (8, default), (2, 256)] {
        let (other, other_counts) = run(threads, grain);
        let on = format!("sweep on {threads} threads, grain {grain}");
        assert_eq!(counts, other_counts, "{on}");
        assert!(same_bits(&lines, &other), "{on}");
    }
}

/// A scene larger than the cache (where the sweep gathers its lines and
/// reads the lines of pairs and events ahead) ends as the quadtree leaves
/// it, bit for bit.
#[test]
fn the_sweep_gives_the_quadtrees_bits_beyond_the_cache() {
    let scene = (SceneKind::Uniform, 100_000, 3);
    let (sweep, sweep_counts) = run(DetectorKind::Sweep, scene, 1, 4);
    let (tree, tree_counts) = run(DetectorKind::Quadtree, scene, 1, 4);
    assert!(sweep_counts.1 > 1000, "{sweep_counts:?}");
    assert_eq!(sweep_counts, tree_counts);
    assert!(same_bits(&sweep, &tree));
}

/// Scenes of thousands of lines share their phases among the world's team
/// of threads: the same bits on any number of threads, over enough steps
/// for events and wall bounces.
#[test]
fn the_team_gives_the_same_bits_on_any_thread_count() {
    for (kind, lines, steps) in [
        (SceneKind::Uniform, 3000, 200),
        (SceneKind::Clustered, 5000, 100),
        (SceneKind::Ring, 4000, 150),
    ] {
        let run = |threads| run(DetectorKind::Sweep, (kind, lines, 11), threads, steps);
        let (one, counts) = run(1);
        assert!(counts.1 > 0, "{kind}: {counts:?}");
        for threads in [2, 3, 8] {
            let (other, other_counts) = run(threads);
            assert_eq!(counts, other_counts, "{kind} on {threads} threads");
            assert!(same_bits(&one, &other), "{kind} on {threads} threads");
        }
    }
}

/// The sweep's counts (exact tests, events, and candidates met) are the
/// same on any number of threads, also with more threads than the scene
/// has bands, across the steps where the plan changes between one band
/// and several. On two threads the seams between the team's groups of
/// bands move with the threads' times, and the bands' edges with them, so
/// the candidates met differ a little (exact tests and events do not).
#[test]
fn the_sweeps_counts_are_the_same_on_any_thread_count() {
    let stats = |kind, threads| {
        let scene = generate(kind, 3000, 3);
        let config = DetectorConfig {
            threads,
            ..DetectorConfig::default()
        };
        let mut world =
            World::with_config(&scene, DetectorKind::Sweep, &config).expect("a thread pool");
        world.run(600);
        world.detector_stats()
    };
    for kind in [SceneKind::Uniform, SceneKind::Grid] {
        let one = stats(kind, 1);
        assert!(one.candidate_pairs > 0, "{kind}");
        // More threads than bands: no seams.
        assert_eq!(stats(kind, 16), one, "{kind} on 16 threads");
        let two = stats(kind, 2);
        assert_eq!(
            (two.exact_tests, two.events),
            (one.exact_tests, one.events),
            "{kind} on 2 threads"
        );
        let off = two.candidate_pairs.abs_diff(one.candidate_pairs) as f64;
        assert!(
            off <= 0.05 * one.candidate_pairs as f64,
            "{kind} on 2 threads: {} candidates against {}",
            two.candidate_pairs,
            one.candidate_pairs
        );
    }
}
