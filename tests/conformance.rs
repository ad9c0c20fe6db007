//! Conformance with the reference program: counters after every step and
//! whole states at checkpoints, bit for bit, read from the reference data
//! (`SCREENSAVER_REFERENCE`, default `../shared/reference`; skipped with a
//! message when absent).
//!
//! The all-pairs detector is slow, so by default it runs as far as CI time
//! allows; `cargo test --release --test conformance -- --ignored` runs it
//! over all of the reference data.

mod common;

use common::check_scene;
use screensaver::DetectorKind::Brute;

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
    for scene in [
        "beaver",
        "box",
        "explosion",
        "koch",
        "mit",
        "sin_wave",
        "smalllines",
    ] {
        check_scene(scene, Brute, None);
    }
}
