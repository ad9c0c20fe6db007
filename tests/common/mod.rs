//! Shared helpers for the integration tests: finding and reading the
//! reference data.

#![allow(dead_code)]

pub mod x11;

use screensaver::{Counters, DetectorConfig, DetectorKind, Line, Scene, World};
use std::path::{Path, PathBuf};

/// The reference data directory: `SCREENSAVER_REFERENCE`, or
/// `../shared/reference` beside the repository. `None` (after saying so on
/// stderr) when it is absent, so that the caller can skip.
pub fn reference_dir(test: &str) -> Option<PathBuf> {
    let dir = std::env::var_os("SCREENSAVER_REFERENCE")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/reference"));
    if dir.join("inputs").is_dir() && dir.join("expected").is_dir() {
        Some(dir)
    } else if std::env::var_os("SCREENSAVER_REQUIRE_REFERENCE").is_some_and(|v| v == "1") {
        panic!(
            "{test}: no reference data at {} and SCREENSAVER_REQUIRE_REFERENCE=1",
            dir.display()
        );
    } else {
        say_skipped(&format!(
            "{test}: skipped: no reference data at {} (set SCREENSAVER_REFERENCE)",
            dir.display()
        ));
        None
    }
}

/// The reference's counters after each step: index 0 is step 1.
pub fn expected_counts(dir: &Path, scene: &str) -> Vec<Counters> {
    let path = dir.join("expected").join(format!("{scene}.counts.csv"));
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut rows = Vec::new();
    for (i, row) in text.lines().enumerate().skip(1) {
        let fields: Vec<u64> = row
            .split(',')
            .map(|f| {
                f.trim()
                    .parse()
                    .unwrap_or_else(|e| panic!("{}:{}: {e}", path.display(), i + 1))
            })
            .collect();
        assert_eq!(fields.len(), 3, "{}:{}", path.display(), i + 1);
        assert_eq!(
            fields[0] as usize,
            rows.len() + 1,
            "{}:{}: steps in order",
            path.display(),
            i + 1
        );
        rows.push(Counters {
            wall: fields[1],
            line: fields[2],
        });
    }
    rows
}

/// The steps that have a checkpoint state file for `scene`.
pub fn checkpoints(dir: &Path, scene: &str) -> Vec<u64> {
    let mut steps: Vec<u64> = std::fs::read_dir(dir.join("expected"))
        .expect("reading the expected directory")
        .filter_map(|entry| {
            let name = entry.ok()?.file_name().into_string().ok()?;
            let rest = name.strip_prefix(scene)?.strip_prefix('.')?;
            rest.strip_suffix(".state")?.parse().ok()
        })
        .collect();
    steps.sort_unstable();
    steps
}

/// Compares the world's lines with a checkpoint file bit for bit (NaN
/// matches NaN whatever its payload). Returns a description of the first
/// difference.
pub fn compare_state(lines: &[Line], path: &Path) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let rows: Vec<&str> = text.lines().collect();
    if rows.len() != lines.len() {
        return Err(format!(
            "{}: {} rows for {} lines",
            path.display(),
            rows.len(),
            lines.len()
        ));
    }
    for (id, (row, line)) in rows.iter().zip(lines).enumerate() {
        let fields: Vec<&str> = row.split_whitespace().collect();
        let ours = [
            line.p1.x, line.p1.y, line.p2.x, line.p2.y, line.v.x, line.v.y,
        ];
        let names = ["p1.x", "p1.y", "p2.x", "p2.y", "v.x", "v.y"];
        if fields.len() != 7 || fields[0].parse::<usize>() != Ok(id) {
            return Err(format!("{}: malformed row {row:?}", path.display()));
        }
        for ((field, ours), name) in fields[1..].iter().zip(ours).zip(names) {
            let theirs: f64 = field
                .parse()
                .map_err(|e| format!("{}: {field}: {e}", path.display()))?;
            let same = ours.to_bits() == theirs.to_bits() || (ours.is_nan() && theirs.is_nan());
            if !same {
                return Err(format!(
                    "{}: line {id} {name}: expected {theirs:?}, got {ours:?}",
                    path.display()
                ));
            }
        }
    }
    Ok(())
}

/// Loads a course scene.
pub fn load_scene(dir: &Path, scene: &str) -> Scene {
    let path = dir.join("inputs").join(format!("{scene}.in"));
    Scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// Runs `scene` with `world` (already built on it) for up to `max_steps`
/// steps (or as far as the reference goes), checking the counters after
/// every step and the state at every checkpoint. Panics at the first
/// difference with the step and what differed.
pub fn check_world(dir: &Path, scene: &str, mut world: World, max_steps: Option<u64>, label: &str) {
    let expected = expected_counts(dir, scene);
    let last = max_steps.map_or(expected.len() as u64, |m| m.min(expected.len() as u64));
    let checkpoints = checkpoints(dir, scene);
    let mut checked_states = 0;
    for step in 1..=last {
        world.step();
        let want = expected[step as usize - 1];
        assert_eq!(
            world.counters(),
            want,
            "{label} {scene}: counters differ after step {step} (compare with the state at the checkpoint before it)"
        );
        if checkpoints.contains(&step) {
            let path = dir.join("expected").join(format!("{scene}.{step}.state"));
            if let Err(e) = compare_state(&world.lines(), &path) {
                panic!("{label} {scene}: state differs after step {step}: {e}");
            }
            checked_states += 1;
        }
    }
    eprintln!("{label} {scene}: counters matched for {last} steps, {checked_states} checkpoint states bit for bit");
}

/// [`check_world`] with a fresh world using `kind` with default tuning.
pub fn check_scene(scene: &str, kind: DetectorKind, max_steps: Option<u64>) {
    check_scene_with(scene, kind, &DetectorConfig::default(), max_steps);
}

/// [`check_world`] with a fresh world using `kind` tuned by `config`.
pub fn check_scene_with(
    scene: &str,
    kind: DetectorKind,
    config: &DetectorConfig,
    max_steps: Option<u64>,
) {
    let label = format!("{kind} {config:?}");
    let Some(dir) = reference_dir(&format!("{scene} ({label})")) else {
        return;
    };
    let world = World::with_config(&load_scene(&dir, scene), kind, config).expect("a thread pool");
    check_world(&dir, scene, world, max_steps, &label);
}

/// Asserts that a process ended by the signal `name` (`INT` or `TERM`)
/// itself, as a parent sees it: a death by that signal (which a shell
/// reports as 130 or 143), not an exit with a status.
pub fn assert_ended_by(status: std::process::ExitStatus, name: &str, context: &str) {
    #[cfg(unix)]
    {
        use std::os::unix::process::ExitStatusExt;
        let number = match name {
            "INT" => 2,
            "TERM" => 15,
            "HUP" => 1,
            _ => panic!("no signal {name}"),
        };
        assert_eq!(
            (status.signal(), status.code()),
            (Some(number), None),
            "ended by SIG{name}? {status:?}: {context}"
        );
    }
    #[cfg(not(unix))]
    assert!(!status.success(), "{status:?}: {context}");
}

/// Says that a test skipped, where `cargo test` shows it: straight to
/// standard error, past the test harness's capture (which shows what a
/// test prints only when it fails), so that a skip never reads as a pass.
pub fn say_skipped(message: &str) {
    use std::io::Write;
    let _ = writeln!(std::io::stderr(), "{message}");
}
