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
