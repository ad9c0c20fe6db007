//! The files a run writes: never over the scene it reads, a checkpoint it
//! resumes from (but for a checkpoint carried on), or each other; and the
//! results printed whatever became of them.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn screensaver(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("running the screensaver binary")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

const TWO_LINES: &str =
    "2\n(600, 400), (600, 420), 1, 0, 0\n(602.5, 400), (602.5, 420), -1, 0, 1\n";

/// A folder of this test's own holding `two.in`.
fn folder(test: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("screensaver-outputs-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("two.in"), TWO_LINES).unwrap();
    dir
}

/// Refused with status 2 before any step, naming both flags, every file
/// in the folder as it was.
fn assert_refused(dir: &Path, args: &[&str], flags: [&str; 2]) {
    let before: Vec<_> = listing(dir);
    let out = screensaver(dir, args);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{args:?}: {stderr}");
    assert!(out.stdout.is_empty(), "{args:?}: {}", text(&out.stdout));
    assert!(
        stderr.contains(&format!("{} and {} name the same file", flags[0], flags[1])),
        "{args:?}: {stderr}"
    );
    assert_eq!(listing(dir), before, "{args:?} changed the folder");
}

/// Each file's name and contents.
fn listing(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let path = e.unwrap().path();
            let name = path.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(&path).unwrap_or_default())
        })
        .collect();
    files.sort();
    files
}

#[test]
fn outputs_never_overwrite_the_input_or_each_other() {
    let dir = folder("clash");
    assert_refused(
        &dir,
        &["10", "two.in", "--state-out", "two.in"],
        ["--state-out", "INPUT"],
    );
    assert_refused(
        &dir,
        &["10", "two.in", "--checkpoint", "./two.in"],
        ["--checkpoint", "INPUT"],
    );
    assert_refused(
        &dir,
        &[
            "10",
            "two.in",
            "--state-out",
            "out.state",
            "--checkpoint",
            "out.state",
        ],
        ["--checkpoint", "--state-out"],
    );
    assert_refused(
        &dir,
        &[
            "10",
            "two.in",
            "--render",
            "same.png",
            "--state-out",
            "same.png",
        ],
        ["--render", "--state-out"],
    );
    // A link and a hard link name the same file as its own name does.
    #[cfg(unix)]
    {
        std::os::unix::fs::symlink("two.in", dir.join("link.in")).unwrap();
        std::fs::hard_link(dir.join("two.in"), dir.join("hard.in")).unwrap();
        assert_refused(
            &dir,
            &["10", "two.in", "--state-out", "link.in"],
            ["--state-out", "INPUT"],
        );
        assert_refused(
            &dir,
            &["10", "two.in", "--checkpoint", "hard.in"],
            ["--checkpoint", "INPUT"],
        );
        let sub = dir.join("sub");
        std::fs::create_dir_all(&sub).unwrap();
        assert_refused(
            &dir,
            &[
                "10",
                "two.in",
                "--state-out",
                "sub/../new.state",
                "--checkpoint",
                "new.state",
            ],
            ["--checkpoint", "--state-out"],
        );
    }
    // The one overlap that is meant: a checkpoint carried on in place.
    let first = screensaver(&dir, &["5", "two.in", "--checkpoint", "run.ckpt"]);
    assert!(first.status.success(), "{}", text(&first.stderr));
    let resumed = screensaver(
        &dir,
        &[
            "10",
            "two.in",
            "--resume",
            "run.ckpt",
            "--checkpoint",
            "run.ckpt",
        ],
    );
    assert!(resumed.status.success(), "{}", text(&resumed.stderr));
    assert_refused(
        &dir,
        &[
            "10",
            "two.in",
            "--resume",
            "run.ckpt",
            "--state-out",
            "run.ckpt",
        ],
        ["--state-out", "--resume"],
    );
    // Devices are shared freely.
    let out = screensaver(
        &dir,
        &[
            "3",
            "two.in",
            "--state-out",
            "/dev/null",
            "--checkpoint",
            "/dev/null",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
}

#[cfg(target_os = "linux")]
#[test]
fn a_failed_output_keeps_the_results() {
    let dir = folder("full");
    for json in [false, true] {
        let mut args = vec![
            "3",
            "two.in",
            "--state-out",
            "/dev/full",
            "--checkpoint",
            "run.ckpt",
        ];
        if json {
            args.push("--json");
        }
        let out = screensaver(&dir, &args);
        let (stdout, stderr) = (text(&out.stdout), text(&out.stderr));
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        if json {
            let v: serde_json::Value = serde_json::from_str(&stdout).expect("the JSON results");
            assert_eq!(v["line_line_collisions"], 1, "{stdout}");
        } else {
            assert!(stdout.contains("1 Line-Line Collisions"), "{stdout}");
            assert!(stdout.contains("---- END RESULTS ----"), "{stdout}");
        }
        assert!(stderr.contains("/dev/full: cannot write"), "{stderr}");
        // The other file is written all the same.
        assert!(dir.join("run.ckpt").is_file());
        std::fs::remove_file(dir.join("run.ckpt")).unwrap();
    }
    // A checkpoint that fails during the run: the steps run so far counted.
    let out = screensaver(
        &dir,
        &[
            "30",
            "two.in",
            "--checkpoint",
            "/dev/full",
            "--checkpoint-every",
            "10",
        ],
    );
    assert_eq!(out.status.code(), Some(1), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("---- END RESULTS ----"),
        "{}",
        text(&out.stdout)
    );
}
