//! Conformance with the reference program: counters after every step and
//! whole states at checkpoints, bit for bit, read from the reference data
//! (`SCREENSAVER_REFERENCE`, default `../shared/reference`; skipped with a
//! message when absent, or failed if `SCREENSAVER_REQUIRE_REFERENCE=1`).
//!
//! The all-pairs detector is slow, so by default it runs as far as CI time
//! allows; `cargo test --release --test conformance -- --ignored` runs it
//! over all of the reference data.

mod common;

use common::{check_scene, check_scene_with};
use screensaver::DetectorConfig;
use screensaver::DetectorKind::{Brute, Quadtree, Sweep};

const SCENES: [&str; 7] = [
    "beaver",
    "box",
    "explosion",
    "koch",
    "mit",
    "sin_wave",
    "smalllines",
];

#[test]
fn brute_beaver() {
    check_scene("beaver", Brute, None);
}

#[test]
fn brute_box() {
    check_scene("box", Brute, None);
}

#[test]
fn brute_smalllines() {
    check_scene("smalllines", Brute, None);
}

#[test]
fn brute_explosion() {
    check_scene("explosion", Brute, None);
}

#[test]
fn brute_mit_to_step_1001() {
    check_scene("mit", Brute, Some(1001));
}

#[test]
fn brute_sin_wave_to_step_1001() {
    check_scene("sin_wave", Brute, Some(1001));
}

#[test]
fn brute_koch_to_step_101() {
    check_scene("koch", Brute, Some(101));
}

#[test]
#[ignore = "minutes of all-pairs work; run with --ignored"]
fn brute_every_scene_to_the_end() {
    for scene in SCENES {
        check_scene(scene, Brute, None);
    }
}

#[test]
fn quadtree_every_scene_to_the_end() {
    for scene in SCENES {
        check_scene(scene, Quadtree, None);
    }
}

/// Results must not depend on the number of threads. A grain of a few
/// lines makes even these small scenes split their work.
#[test]
fn quadtree_on_2_3_and_8_threads_every_scene_to_step_1001() {
    for threads in [2, 3, 8] {
        let config = DetectorConfig {
            threads,
            grain: 8,
            ..DetectorConfig::default()
        };
        for scene in SCENES {
            check_scene_with(scene, Quadtree, &config, Some(1001));
        }
    }
}

#[test]
fn quadtree_odd_shapes_every_scene_to_step_1001() {
    for config in [
        DetectorConfig {
            leaf_size: 1,
            max_depth: 16,
            ..DetectorConfig::default()
        },
        DetectorConfig {
            leaf_size: 64,
            max_depth: 3,
            ..DetectorConfig::default()
        },
        DetectorConfig {
            leaf_size: 2,
            max_depth: 8,
            ..DetectorConfig::default()
        },
    ] {
        for scene in SCENES {
            check_scene_with(scene, Quadtree, &config, Some(1001));
        }
    }
}

#[test]
fn sweep_every_scene_to_the_end() {
    for scene in SCENES {
        check_scene(scene, Sweep, None);
    }
}

/// A grain of a few lines makes the sweep's parallel paths (hulls, bands)
/// run on these small scenes.
#[test]
fn sweep_on_2_3_and_8_threads_every_scene_to_step_1001() {
    for threads in [2, 3, 8] {
        let config = DetectorConfig {
            threads,
            grain: 8,
            ..DetectorConfig::default()
        };
        for scene in SCENES {
            check_scene_with(scene, Sweep, &config, Some(1001));
        }
    }
}
