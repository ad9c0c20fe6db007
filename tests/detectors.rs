//! Every fast detector against the all-pairs oracle, step after step, on
//! random scenes of every awkward kind: lines spanning quadrants or lying on
//! their boundaries, axis-aligned, collinear, zero-length and duplicated
//! lines, very fast lines, lines outside the box, and lines that turn NaN.

use proptest::prelude::*;
use screensaver::report::Stats;
use screensaver::run::Run;
use screensaver::{Color, DetectorConfig, DetectorKind, KeepPairs, Line, Vec2, World};

/// Runs `steps` steps of `world`, each checked against the all-pairs
/// detector; the first step whose events differ is the error.
fn verified(world: &mut World, steps: u64) -> Result<(), String> {
    let run = Run {
        verify: true,
        ..Run::default()
    };
    run.run(world, steps).map(|_| ()).map_err(|e| e.to_string())
}

/// Tree shapes to try: leaves of 1, 2 and many lines, no splitting at
/// all and very deep trees; and 2, 3 and 8 threads with work split into
/// pieces of a few lines.
fn configs() -> Vec<DetectorConfig> {
    let shape = |leaf_size, max_depth| DetectorConfig {
        leaf_size,
        max_depth,
        ..DetectorConfig::default()
    };
    let threads = |threads, grain| DetectorConfig {
        threads,
        grain,
        leaf_size: 2,
        ..DetectorConfig::default()
    };
    let keep = |keep_pairs, threads| DetectorConfig {
        keep_pairs,
        threads,
        grain: 4,
        ..DetectorConfig::default()
    };
    vec![
        keep(KeepPairs::Always, 1),
        keep(KeepPairs::Always, 3),
        keep(KeepPairs::Never, 1),
        shape(1, 12),
        shape(2, 40),
        shape(1000, 12),
        shape(16, 0),
        shape(3, 2),
        shape(16, 12),
        threads(2, 1),
        threads(3, 2),
        threads(8, 4),
    ]
}

const STEPS: usize = 25;

fn fast_detectors() -> impl Iterator<Item = DetectorKind> {
    DetectorKind::ALL
        .iter()
        .copied()
        .filter(|&k| k != DetectorKind::Brute)
}

/// Runs `lines` with every fast detector and configuration, verifying each
/// step against the oracle; returns a description of the first mismatch.
fn check_all(lines: &[Line], steps: usize) -> Result<(), String> {
    for kind in fast_detectors() {
        for config in &configs() {
            let colors = vec![Color::Red; lines.len()];
            let mut world =
                World::from_lines(lines.to_vec(), colors, kind, config).expect("a thread pool");
            verified(&mut world, steps as u64).map_err(|m| format!("{kind} {config:?}: {m}"))?;
        }
    }
    Ok(())
}

/// Coordinates in the box, on likely quadrant boundaries, or outside.
fn coord() -> impl Strategy<Value = f64> + Clone {
    prop_oneof![
        4 => 0.5f64..1.0,
        3 => prop::sample::select(vec![0.5, 0.5625, 0.625, 0.6875, 0.75, 0.8125, 0.875, 1.0]),
        1 => -1.0f64..2.0,
    ]
}

/// Velocities: slow like the course scenes, very fast, or still.
fn speed() -> impl Strategy<Value = f64> + Clone {
    prop_oneof![
        4 => -0.01f64..0.01,
        1 => -0.6f64..0.6,
        1 => Just(0.0),
        1 => prop::sample::select(vec![0.004, -0.004, 0.0625, -0.0625]),
    ]
}

fn velocity() -> impl Strategy<Value = Vec2> {
    (speed(), speed()).prop_map(|(x, y)| Vec2::new(x, y))
}

fn line() -> impl Strategy<Value = Line> {
    prop_oneof![
        // Anything.
        3 => (coord(), coord(), coord(), coord(), velocity())
            .prop_map(|(a, b, c, d, v)| Line { p1: Vec2::new(a, b), p2: Vec2::new(c, d), v }),
        // Short lines near each other.
        3 => (0.6f64..0.9, 0.6f64..0.9, -0.03f64..0.03, -0.03f64..0.03, velocity())
            .prop_map(|(x, y, dx, dy, v)| Line { p1: Vec2::new(x, y), p2: Vec2::new(x + dx, y + dy), v }),
        // Horizontal and vertical.
        1 => (coord(), coord(), -0.2f64..0.2, velocity())
            .prop_map(|(x, y, len, v)| Line { p1: Vec2::new(x, y), p2: Vec2::new(x + len, y), v }),
        1 => (coord(), coord(), -0.2f64..0.2, velocity())
            .prop_map(|(x, y, len, v)| Line { p1: Vec2::new(x, y), p2: Vec2::new(x, y + len), v }),
        // On the diagonal y = x: collinear with each other (and overlapping
        // ones turn NaN when pushed apart).
        2 => (0.5f64..1.0, 0.5f64..1.0, velocity())
            .prop_map(|(s, t, v)| Line { p1: Vec2::new(s, s), p2: Vec2::new(t, t), v }),
        // Zero length.
        1 => (coord(), coord(), velocity())
            .prop_map(|(x, y, v)| Line { p1: Vec2::new(x, y), p2: Vec2::new(x, y), v }),
    ]
}

/// A scene of random lines, some of them duplicated exactly.
fn scene() -> impl Strategy<Value = Vec<Line>> {
    (
        prop::collection::vec(line(), 0..48),
        prop::collection::vec(any::<prop::sample::Index>(), 0..6),
    )
        .prop_map(|(mut lines, dups)| {
            if !lines.is_empty() {
                for d in dups {
                    let copy = lines[d.index(lines.len())];
                    lines.push(copy);
                }
            }
            lines
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn fast_detectors_find_exactly_the_oracles_events(lines in scene()) {
        if let Err(e) = check_all(&lines, STEPS) {
            return Err(TestCaseError::fail(e));
        }
    }
}

#[test]
fn collinear_overlaps_turn_nan_and_detectors_cope() {
    // Overlapping collinear pairs: the response divides zero by zero.
    let mut lines = Vec::new();
    for k in 0..10 {
        let x = 0.55 + 0.04 * k as f64;
        lines.push(Line {
            p1: Vec2::new(x, x),
            p2: Vec2::new(x + 0.02, x + 0.02),
            v: Vec2::new(0.01, 0.01),
        });
        lines.push(Line {
            p1: Vec2::new(x + 0.01, x + 0.01),
            p2: Vec2::new(x + 0.03, x + 0.03),
            v: Vec2::new(-0.01, -0.01),
        });
        // A crossing line that keeps meeting the others.
        lines.push(Line {
            p1: Vec2::new(x, 0.9),
            p2: Vec2::new(x + 0.01, 0.6),
            v: Vec2::new(0.002, 0.0),
        });
    }
    let colors = vec![Color::Gray; lines.len()];
    let config = DetectorConfig::default();
    let mut probe = World::from_lines(lines.clone(), colors, DetectorKind::Brute, &config).unwrap();
    probe.run(3);
    assert!(
        probe.lines().iter().any(|l| l.v.has_nan()),
        "the scene should produce NaN"
    );
    check_all(&lines, 40).unwrap();
}

#[test]
fn identical_lines_everywhere_stop_at_the_depth_limit() {
    let line = Line {
        p1: Vec2::new(0.7, 0.7),
        p2: Vec2::new(0.71, 0.72),
        v: Vec2::new(0.001, -0.002),
    };
    check_all(&vec![line; 40], 5).unwrap();
}

#[test]
fn empty_and_single_line_scenes() {
    check_all(&[], 3).unwrap();
    let line = Line {
        p1: Vec2::new(0.7, 0.7),
        p2: Vec2::new(0.8, 0.7),
        v: Vec2::new(0.3, 0.1),
    };
    check_all(&[line], 3).unwrap();
}

/// Every fast detector against the oracle at scale: generated scenes of
/// thousands of lines (enough for the sweep to cut bands), event for event.
#[test]
fn thousands_of_lines_agree_with_the_oracle() {
    use screensaver::generate::{generate, SceneKind};
    for (kind, lines) in [(SceneKind::Uniform, 5_000), (SceneKind::Clustered, 8_000)] {
        let scene = generate(kind, lines, 11);
        for detector in fast_detectors() {
            let mut world = World::with_detector(&scene, detector);
            verified(&mut world, 2).unwrap_or_else(|m| panic!("{detector} on {kind} {lines}: {m}"));
            assert!(
                world.counters().line > 0,
                "{kind} {lines}: no events to compare"
            );
        }
    }
}

/// The sweep in bands over many steps, event for event with the oracle:
/// boxes moving between bands and the layout kept from step to step, on
/// one thread and on teams of two and three; with a grain of a few lines
/// (the world's move in pieces of a few lines, claimed by whichever
/// thread is free, and the tied events in waves) for 130 steps; and
/// sweeping every step on one thread for 60, where the move makes the
/// next step's boxes and notes those that left their band.
#[test]
fn the_sweep_in_bands_agrees_with_the_oracle_step_after_step() {
    use screensaver::generate::{generate, SceneKind};
    let scene = generate(SceneKind::Uniform, 3_000, 5);
    let default = DetectorConfig::default().grain;
    let (auto, never) = (KeepPairs::Auto, KeepPairs::Never);
    let runs = [
        (1, default, auto),
        (1, default, never),
        (3, 8, auto),
        (2, default, auto),
        (3, default, auto),
    ];
    for (threads, grain, keep_pairs) in runs {
        let config = DetectorConfig {
            threads,
            grain,
            keep_pairs,
            ..DetectorConfig::default()
        };
        let mut world =
            World::with_config(&scene, DetectorKind::Sweep, &config).expect("a pool of threads");
        let steps = match (grain == default, keep_pairs) {
            (true, KeepPairs::Auto) => 34,
            (true, _) => 60,
            (false, _) => 130,
        };
        verified(&mut world, steps)
            .unwrap_or_else(|m| panic!("{threads} threads, grain {grain}, {keep_pairs:?}: {m}"));
        let plan = Stats::of(&world, DetectorKind::Sweep, &config, None).plan;
        assert!(plan.is_some_and(|p| p.bands > 1), "{plan:?}");
    }
}

/// The sweep keeping its pairs from step to step, event for event with
/// the oracle for 120 steps: boxes leaving the room they were given one
/// by one (mended) and many at once (swept again), lines turning wild and
/// inert, and on teams of two and three the lines stored anew in the
/// sweep's order every few steps, the pairs following them; and scenes
/// whose lines mostly move alike, whose widened boxes move with them.
#[test]
fn pairs_kept_from_step_to_step_agree_with_the_oracle() {
    use screensaver::generate::{generate, SceneKind};
    for (kind, n, threads, as_one) in [
        (SceneKind::Uniform, 3_000, 1, false),
        (SceneKind::Clustered, 3_000, 2, false),
        (SceneKind::Uniform, 2_500, 3, false),
        (SceneKind::Uniform, 2_000, 1, true),
        (SceneKind::Clustered, 1_500, 3, true),
    ] {
        let mut scene = generate(kind, n, 3);
        if as_one {
            // Nine lines in ten moving alike, as a shape does: the widened
            // boxes move with them.
            let v = scene.lines[0].v;
            for line in scene
                .lines
                .iter_mut()
                .filter(|l| l.p1.x.to_bits() % 10 != 0)
            {
                line.v = v;
            }
        }
        // A few lines that turn wild: NaN velocities.
        for k in [5, 700, n - 100] {
            scene.lines[k].v = Vec2::new(f64::NAN, 0.0);
        }
        let config = DetectorConfig {
            threads,
            keep_pairs: KeepPairs::Always,
            ..DetectorConfig::default()
        };
        let mut world =
            World::with_config(&scene, DetectorKind::Sweep, &config).expect("a pool of threads");
        verified(&mut world, 120).unwrap_or_else(|m| panic!("{kind} {n}, {threads} threads: {m}"));
        let plan = Stats::of(&world, DetectorKind::Sweep, &config, None).plan;
        let plan = plan.expect("the sweep's plan");
        assert!(plan.keeping > plan.sweeps, "pairs kept: {plan:?}");
        assert_eq!(plan.moving > 0, as_one, "{plan:?}");
    }
}

/// Found by the `step` fuzz target: lines whose coordinates near 1e306 make
/// the diagonals of their hulls overflow (to infinities and NaN). A
/// detector that kept pairs from step to step missed their event at the
/// third step; such lines are now wild for every detector.
#[test]
fn lines_whose_diagonals_overflow_are_found_by_every_detector() {
    let l = |a: f64, b: f64, c: f64, d: f64, e: f64, f: f64| Line {
        p1: Vec2::new(a, b),
        p2: Vec2::new(c, d),
        v: Vec2::new(e, f),
    };
    let lines = vec![
        l(
            -2.2757887129063444e287,
            0.5377729457541771,
            0.9375,
            7.364683717114213e-222,
            7.202214981246854e201,
            0.036359960326543074,
        ),
        l(
            -2.2757887129063444e287,
            0.5377729457541771,
            0.9375,
            7.364683717114213e-222,
            7.202214981246854e201,
            0.036359960326543074,
        ),
        l(
            2.1324723575953715e186,
            0.5377729457541771,
            0.9243053330281529,
            0.5377729457541771,
            -0.01625925078202487,
            -1.977154901532549e-44,
        ),
        l(
            0.745866330968185,
            -4.456811102093262e-240,
            0.745866330968185,
            -4.456811102093262e-240,
            -0.008261997405966276,
            f64::NEG_INFINITY,
        ),
        l(
            0.9243053330281529,
            0.5377729457541771,
            0.8125,
            1.0476653696498055,
            2.3573515099325194e-248,
            0.014760814831769288,
        ),
        l(
            0.745866330968185,
            -4.456811102093262e-240,
            0.745866330968185,
            -4.456811102093262e-240,
            1e300,
            2.552899494460511e210,
        ),
        l(
            -2.2757887129063444e287,
            0.5377729457541771,
            0.9375,
            7.364683717114213e-222,
            -0.0546875,
            -1.1382478261490175e280,
        ),
        l(
            1.0,
            -5.358799606115296e-213,
            0.9516891737239643,
            0.6980659189745937,
            0.036359960326543074,
            -5.746435627732363e306,
        ),
        l(
            0.6970313572899978,
            0.9956076905470359,
            0.9375,
            0.8426665140764478,
            -0.04090104524299992,
            5e-324,
        ),
        l(
            0.745866330968185,
            -4.456811102093262e-240,
            0.745866330968185,
            -4.456811102093262e-240,
            0.03772106507972839,
            -0.0546875,
        ),
        l(
            0.6524444953078508,
            -1.977154901532549e-44,
            0.6524444953078508,
            -1.977154901532549e-44,
            3.2232247062000503e249,
            -5.746435627732363e306,
        ),
        l(
            0.6970313572899978,
            0.9956076905470359,
            0.9375,
            0.8426665140764478,
            -0.04090104524299992,
            5e-324,
        ),
        l(
            0.745866330968185,
            -4.456811102093262e-240,
            0.745866330968185,
            -4.456811102093262e-240,
            0.0330914778362707,
            0.0390625,
        ),
        l(
            4.798326081118437e-262,
            0.8785831998168918,
            4.798326081118437e-262,
            0.8785831998168918,
            3.2232247062000503e249,
            0.0,
        ),
    ];
    check_all(&lines, 6).unwrap();
}

/// Found by the `step` fuzz target: a line of subnormal length, whose
/// normal's products underflow, so that the exact test's cheap prefilter
/// rounded its margin to zero and turned down a pair that meets. The
/// margin now has a floor far above such rounding.
#[test]
fn a_line_of_subnormal_length_is_not_culled_by_the_prefilter() {
    let l = |a: f64, b: f64, c: f64, d: f64, e: f64, f: f64| Line {
        p1: Vec2::new(a, b),
        p2: Vec2::new(c, d),
        v: Vec2::new(e, f),
    };
    let lines = vec![
        l(
            -3.75397952358398e255,
            -3.078470096612901e-14,
            1.025344472419318,
            0.96875,
            0.0546875,
            0.0546875,
        ),
        l(
            0.96875,
            -3.078470096612901e-14,
            0.96875,
            -3.078470096612901e-14,
            0.0546875,
            0.0546875,
        ),
        l(
            0.0,
            -3.078470096612901e-14,
            0.0,
            -3.078470096612901e-14,
            -1.0,
            0.0,
        ),
        l(0.0, 0.0, 0.0, 5e-324, 0.75, 0.0),
        l(0.671875, 0.0, 0.921875, 0.0, 0.0, 0.0),
    ];
    // The pair meets at the second step: the all-pairs detector finds it.
    let colors = vec![Color::Red; lines.len()];
    let config = DetectorConfig::default();
    let mut oracle =
        World::from_lines(lines.clone(), colors, DetectorKind::Brute, &config).unwrap();
    oracle.run(4);
    assert!(oracle.counters().line > 0);
    check_all(&lines, 4).unwrap();
}
