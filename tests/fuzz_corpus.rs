//! Replays the fuzzing corpora (`fuzz/corpus/<target>/`) and the inputs
//! that once failed (`fuzz/regressions/<target>/`) through the same checks
//! the fuzz targets run, so that CI keeps them passing on stable without
//! libFuzzer.

#[path = "../fuzz/checks.rs"]
mod checks;

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

/// Every file in the target's corpus and regressions folders, sorted; a
/// folder that does not exist holds nothing.
fn inputs(target: &str) -> Vec<PathBuf> {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz");
    let mut files = Vec::new();
    for folder in ["corpus", "regressions"] {
        let Ok(entries) = std::fs::read_dir(fuzz.join(folder).join(target)) else {
            continue;
        };
        for entry in entries {
            let path = entry.expect("a readable folder entry").path();
            if path.is_file() {
                files.push(path);
            }
        }
    }
    files.sort();
    files
}

/// Runs `check` on every input of `target`; fails naming every file whose
/// check panicked (each panic's message is printed as it happens).
fn replay(target: &str, check: fn(&[u8])) {
    let files = inputs(target);
    assert!(!files.is_empty(), "no corpus for {target}");
    let failed: Vec<_> = files
        .iter()
        .filter(|path| {
            let bytes = std::fs::read(path).expect("a readable corpus file");
            catch_unwind(AssertUnwindSafe(|| check(&bytes))).is_err()
        })
        .map(|path| path.display().to_string())
        .collect();
    assert!(
        failed.is_empty(),
        "{target}: {} of {} inputs failed:\n{}",
        failed.len(),
        files.len(),
        failed.join("\n")
    );
}

#[test]
fn scene_parser_corpus() {
    replay("scene_parser", checks::scene_parser);
}

#[test]
fn step_corpus() {
    replay("step", checks::step);
}

#[test]
fn checkpoint_parser_corpus() {
    replay("checkpoint_parser", checks::checkpoint_parser);
}

#[test]
fn hypot_corpus() {
    replay("hypot", checks::hypot);
}

/// A line from its endpoints and velocity.
fn line(p1: (f64, f64), p2: (f64, f64), v: (f64, f64)) -> screensaver::Line {
    use screensaver::Vec2;
    screensaver::Line {
        p1: Vec2::new(p1.0, p1.1),
        p2: Vec2::new(p2.0, p2.1),
        v: Vec2::new(v.0, v.1),
    }
}

#[test]
fn exact_arithmetic_tells_rounding_noise_from_contact() {
    use screensaver::{intersect, IntersectionKind};
    let dt = screensaver::line::DT;
    // Two segments on one line through the origin, 0.3 of the box apart:
    // all four orientations come out near 1e-16 with signs that say
    // "crossing", but the segments never meet.
    let a = line(
        (0.28934686269672605, 0.3468574840708857),
        (-0.20250546880865056, -0.24275548304522368),
        (0.046875, -0.01666666666666667),
    );
    let b = line(
        (1.3371185213703929, 1.6028843786470577),
        (0.5674932016761594, 0.6802882268228981),
        (-0.0546875, 0.010930800335698477),
    );
    assert_eq!(
        intersect(&a, &b, dt),
        Some(IntersectionKind::AlreadyIntersected)
    );
    assert!(!checks::truly_meet(&a, &b, dt));
    // A segment at rest on the line of one that slides along itself, 0.06
    // beyond the end of its sweep: the parallelogram `intersect` builds
    // from rounded corners is a sliver whose sides cross far away, and its
    // inside test holds there in exact arithmetic too. This is the
    // contract's own answer, not noise.
    let rest = line(
        (1.0647144347264588, 0.7249015338304577),
        (1.0687037965378123, 0.7194895144692043),
        (0.0, 0.0),
    );
    let sliding = line(
        (0.9979649053873545, 0.815454800799048),
        (0.9699591478722643, 0.8534477703679866),
        (0.020813462557612464, -0.028235810052612498),
    );
    assert_eq!(
        intersect(&rest, &sliding, dt),
        Some(IntersectionKind::L1WithL2)
    );
    assert!(checks::truly_meet(&rest, &sliding, dt));
    // Ordinary crossing and ordinary apart.
    let c = line((0.6, 0.6), (0.7, 0.7), (0.0, 0.0));
    let d = line((0.6, 0.7), (0.7, 0.6), (0.0, 0.0));
    assert!(checks::truly_meet(&c, &d, dt));
    let e = line((0.8, 0.6), (0.9, 0.6), (0.0, 0.0));
    assert!(!checks::truly_meet(&c, &e, dt));
}
