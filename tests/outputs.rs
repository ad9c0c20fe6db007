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

/// A numbered picture of `--render NAME.png --render-every K` is a file
/// like any other: never another output's, nor the scene's.
#[test]
fn numbered_pictures_never_overwrite_another_file() {
    let dir = folder("frames");
    let args = [
        "10",
        "two.in",
        "--render",
        "seq.png",
        "--render-every",
        "5",
        "--state-out",
        "seq-000005.png",
    ];
    assert_refused(&dir, &args, ["--render", "--state-out"]);
    std::fs::copy(dir.join("two.in"), dir.join("scene-000000.png")).unwrap();
    let args = [
        "10",
        "scene-000000.png",
        "--render",
        "scene.png",
        "--render-every",
        "1",
    ];
    assert_refused(&dir, &args, ["--render", "INPUT"]);
    // Names that are no frame of the sequence are left alone.
    let out = screensaver(
        &dir,
        &[
            "3",
            "two.in",
            "--render",
            "seq.png",
            "--render-every",
            "5",
            "--state-out",
            "seq-5.png",
        ],
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
}

/// Standard output sent into the state's file would be lost when the state
/// replaces it: refused before the run, the file as it was.
#[cfg(unix)]
#[test]
fn standard_output_into_an_output_file_is_refused() {
    let args = ["5", "two.in", "--state-out", "o.txt"];
    assert_stdout_refused("stdout", "o.txt", &args, "--state-out");
}

/// Runs `args` in a folder of the test's own with standard output sent to
/// its file `name`: refused with status 2, naming `flag` and standard
/// output, the file as it was.
#[cfg(unix)]
fn assert_stdout_refused(test: &str, name: &str, args: &[&str], flag: &str) {
    let dir = folder(test);
    let results = dir.join(name);
    std::fs::write(&results, b"kept").unwrap();
    let out = Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(args)
        .current_dir(&dir)
        .stdout(
            std::fs::OpenOptions::new()
                .append(true)
                .open(&results)
                .unwrap(),
        )
        .output()
        .unwrap();
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    let named = format!("{flag} and standard output (`>`) name the same file");
    assert!(stderr.contains(&named), "{stderr}");
    assert_eq!(std::fs::read(&results).unwrap(), b"kept");
}

/// A name ending in `/` names a folder: refused before the run (for a
/// folder that does not exist as for one that does), never after it.
#[test]
fn an_output_named_as_a_folder_is_refused_before_the_run() {
    let dir = folder("slash");
    for flag in ["--state-out", "--checkpoint"] {
        let out = screensaver(&dir, &["5", "two.in", flag, "newdir/"]);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{flag}: {stderr}");
        assert!(out.stdout.is_empty(), "{flag}: ran before failing");
        assert!(stderr.contains("newdir/: cannot write: a file's name cannot end in a separator"));
    }
    let out = screensaver(&dir, &["gen", "--lines", "5", "-o", "newdir/"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(text(&out.stderr).contains("cannot end in a separator"));
    assert!(!dir.join("newdir").exists());
}

/// A checkpoint that fails part way ends the run there: the output says
/// so and at which step, and no state file claims to be the run's end.
#[cfg(target_os = "linux")]
#[test]
fn a_failed_periodic_checkpoint_writes_no_final_state() {
    let dir = folder("full");
    let args = [
        "20",
        "two.in",
        "--checkpoint",
        "/dev/full",
        "--checkpoint-every",
        "5",
        "--state-out",
        "end.state",
        "--json",
    ];
    let out = screensaver(&dir, &args);
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let value: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(value["interrupted"], true);
    assert_eq!(value["steps_run"], 5);
    assert!(
        stderr.contains("end.state: not written: the run ended early, after step 5 of 21"),
        "{stderr}"
    );
    assert!(!dir.join("end.state").exists());
}

/// A regular file under `/dev` is replaced whole like any other file; a
/// new one there is made, not refused with a false reason.
#[cfg(target_os = "linux")]
#[test]
fn a_regular_file_under_dev_is_written_whole() {
    let shm = tempfile::tempdir_in("/dev/shm").expect("/dev/shm takes files on Linux");
    let dir = folder("dev");
    let old = shm.path().join("x");
    std::fs::write(&old, vec![b'#'; 100_000]).unwrap();
    let new = shm.path().join("new");
    for path in [&old, &new] {
        let out = screensaver(
            &dir,
            &["5", "two.in", "--state-out", path.to_str().unwrap()],
        );
        assert!(out.status.success(), "{}", text(&out.stderr));
        let state = std::fs::read_to_string(path).unwrap();
        assert_eq!(state.lines().count(), 2, "{state}");
        assert!(!state.contains('#'));
    }
    // A folder that takes no files is named without a contradiction.
    let out = screensaver(&dir, &["5", "two.in", "--render", "/proc/x.png"]);
    let stderr = text(&out.stderr);
    assert!(
        stderr.contains("the folder /proc exists but does not take new files"),
        "{stderr}"
    );
    assert!(!stderr.contains("No such file"), "{stderr}");
}

/// Another user's link in a sticky folder anyone may write (as `/tmp`) is
/// never followed by an output: refused by name, its target untouched.
#[cfg(unix)]
#[test]
fn another_users_link_in_a_shared_folder_is_not_written_through() {
    use std::os::unix::fs::{MetadataExt, PermissionsExt};
    let dir = folder("link");
    if std::fs::metadata(&dir).unwrap().uid() != 0 {
        // Only root can make a link another user's.
        assert!(std::env::var_os("CI").is_none(), "CI runs as root");
        return;
    }
    let shared = dir.join("shared");
    std::fs::create_dir_all(&shared).unwrap();
    std::fs::set_permissions(&shared, std::fs::Permissions::from_mode(0o1777)).unwrap();
    let victim = dir.join("victim");
    std::fs::write(&victim, b"precious").unwrap();
    std::fs::set_permissions(&victim, std::fs::Permissions::from_mode(0o600)).unwrap();
    for (flag, name) in [
        ("--state-out", "s"),
        ("--checkpoint", "c"),
        ("--render", "p.png"),
    ] {
        let link = shared.join(name);
        let _ = std::fs::remove_file(&link);
        std::os::unix::fs::symlink(&victim, &link).unwrap();
        std::os::unix::fs::lchown(&link, Some(65534), Some(65534)).unwrap();
        let out = screensaver(&dir, &["5", "two.in", flag, link.to_str().unwrap()]);
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{flag}: {stderr}");
        assert!(
            stderr.contains("is a symbolic link in the shared folder"),
            "{stderr}"
        );
        assert!(out.stdout.is_empty(), "{flag}: ran before refusing");
    }
    let link = shared.join("gen.in");
    std::os::unix::fs::symlink(&victim, &link).unwrap();
    std::os::unix::fs::lchown(&link, Some(65534), Some(65534)).unwrap();
    let out = screensaver(&dir, &["gen", "--lines", "5", "-o", link.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(std::fs::read(&victim).unwrap(), b"precious");
    assert_eq!(std::fs::metadata(&victim).unwrap().mode() & 0o777, 0o600);
}

/// The temporary files a killed run left are cleared by the next run
/// that writes in their folder.
#[cfg(target_os = "linux")]
#[test]
fn a_killed_runs_temporary_files_are_cleared() {
    let dir = folder("stale");
    let stale = dir.join(".screensaver-999999999-AbCdEf.part");
    std::fs::write(&stale, vec![0; 4096]).unwrap();
    // Left an hour ago by a process that no longer runs.
    let an_hour_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(3600);
    let file = std::fs::File::options().write(true).open(&stale).unwrap();
    file.set_modified(an_hour_ago).unwrap();
    let out = screensaver(&dir, &["5", "two.in", "--state-out", "s.state"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(!stale.exists());
}

/// A scene too large for the memory this process may have ends with a
/// plain message and status 1, before anything is printed.
#[cfg(target_os = "linux")]
#[test]
fn a_scene_too_large_for_the_memory_says_so() {
    let dir = folder("memory");
    let bin = env!("CARGO_BIN_EXE_screensaver");
    let made = screensaver(&dir, &["gen", "--lines", "1000000", "-o", "m.in"]);
    assert!(made.status.success());
    for (args, lines) in [("1 --lines 2000000", 2_000_000), ("1 m.in", 1_000_000)] {
        let out = Command::new("sh")
            .args(["-c", &format!("ulimit -v 300000; exec '{bin}' {args}")])
            .current_dir(&dir)
            .output()
            .unwrap();
        let stderr = text(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{args}: {stderr}");
        assert!(
            stderr.contains(&format!("a scene of {lines} lines needs about"))
                && stderr.contains("MB of memory"),
            "{args}: {stderr}"
        );
        assert!(out.stdout.is_empty(), "{args}: {}", text(&out.stdout));
    }
    std::fs::remove_file(dir.join("m.in")).unwrap();
}

/// A picture that fails after the last step leaves the run complete: the
/// state is written, the run is not called interrupted, and the error is
/// said with status 1.
#[cfg(target_os = "linux")]
#[test]
fn a_picture_failing_after_the_last_step_keeps_the_state() {
    let dir = folder("late-picture");
    std::os::unix::fs::symlink("/dev/full", dir.join("x.png")).unwrap();
    let out = screensaver(
        &dir,
        &[
            "5",
            "two.in",
            "--render",
            "x.png",
            "--state-out",
            "s.state",
            "--json",
        ],
    );
    let stderr = text(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let value: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(value["interrupted"], false);
    assert_eq!(value["steps_run"], 6);
    assert!(dir.join("s.state").exists(), "{stderr}");
    assert!(stderr.contains("x.png: cannot write"), "{stderr}");
}

/// Standard output sent to a file that a numbered picture would replace is
/// refused before the run.
#[cfg(unix)]
#[test]
fn standard_output_into_a_numbered_picture_is_refused() {
    let args = ["10", "two.in", "--render", "seq.png", "--render-every", "5"];
    assert_stdout_refused("stdout-frame", "seq-000005.png", &args, "--render");
}
