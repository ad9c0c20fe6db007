//! Runs that are interrupted, outputs that cannot be written, and what a
//! new user runs into: signals stop a run cleanly, files are whole or
//! absent, checkpoints resume, and messages say what is wrong.

mod common;

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

fn screensaver(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(args)
        .output()
        .expect("running the screensaver binary")
}

fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("starting the screensaver binary")
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

fn folder(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("screensaver-int-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn signal(child: &Child, name: &str) {
    let status = Command::new("kill")
        .args([&format!("-{name}"), &child.id().to_string()])
        .status()
        .expect("running kill");
    assert!(status.success());
}

/// Waits until `path` exists (the run has got going), at most a minute.
fn wait_for(path: &Path) {
    let start = Instant::now();
    while !path.exists() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "{} never appeared",
            path.display()
        );
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn names_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn sigint_stops_at_the_end_of_a_step_with_the_results_and_a_checkpoint() {
    let dir = folder("sigint");
    let (checkpoint, state) = (dir.join("run.checkpoint"), dir.join("run.state"));
    let child = spawn(&[
        "100000000",
        "--threads",
        "1",
        "--checkpoint",
        checkpoint.to_str().unwrap(),
        "--checkpoint-every",
        "50",
        "--state-out",
        state.to_str().unwrap(),
    ]);
    wait_for(&checkpoint);
    signal(&child, "INT");
    let out = child.wait_with_output().unwrap();
    common::assert_ended_by(out.status, "INT", &text(&out.stderr));
    let stdout = text(&out.stdout);
    assert!(
        stdout.contains("---- RESULTS ----") && stdout.contains("---- END RESULTS ----"),
        "{stdout}"
    );
    assert!(
        text(&out.stderr).contains("stopped by SIGINT after step"),
        "{}",
        text(&out.stderr)
    );
    // The last checkpoint is of the step the run stopped at, and the
    // state written is that step's.
    let saved = screensaver::checkpoint::Checkpoint::load(&checkpoint).unwrap();
    let lines: Vec<&str> = stdout.lines().collect();
    let wall: u64 = lines[4].split(' ').next().unwrap().parse().unwrap();
    let line: u64 = lines[5].split(' ').next().unwrap().parse().unwrap();
    assert_eq!((saved.counters.wall, saved.counters.line), (wall, line));
    let rows = std::fs::read_to_string(&state).unwrap();
    assert_eq!(rows.lines().count(), saved.lines.len());
    assert_eq!(names_in(&dir), ["run.checkpoint", "run.state"]);
}

#[test]
fn sigterm_stops_a_json_run_marked_interrupted() {
    let dir = folder("sigterm");
    let checkpoint = dir.join("c");
    let child = spawn(&[
        "100000000",
        "--json",
        "--threads",
        "2",
        "--checkpoint",
        checkpoint.to_str().unwrap(),
        "--checkpoint-every",
        "20",
    ]);
    wait_for(&checkpoint);
    signal(&child, "TERM");
    let out = child.wait_with_output().unwrap();
    common::assert_ended_by(out.status, "TERM", &text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["interrupted"], true);
    let saved = screensaver::checkpoint::Checkpoint::load(&checkpoint).unwrap();
    assert_eq!(v["steps_run"], saved.steps);
    assert!(saved.steps < 100_000_001);
}

#[test]
fn a_second_sigint_ends_at_once_leaving_no_partial_file() {
    let dir = folder("twice");
    let (checkpoint, gif) = (dir.join("c"), dir.join("movie.gif"));
    // Large frames make every step slow, so that the second signal comes
    // while the first is still waiting for its step to end.
    let child = spawn(&[
        "100000000",
        "--threads",
        "1",
        "--size",
        "4000x4000",
        "--render",
        gif.to_str().unwrap(),
        "--checkpoint",
        checkpoint.to_str().unwrap(),
        "--checkpoint-every",
        "5",
    ]);
    wait_for(&checkpoint);
    // The second signal ends the process before the GIF is finished, so it
    // must not appear under its name.
    signal(&child, "INT");
    std::thread::sleep(Duration::from_millis(50));
    signal(&child, "INT");
    let out = child.wait_with_output().unwrap();
    common::assert_ended_by(out.status, "INT", &text(&out.stderr));
    assert!(
        !text(&out.stdout).contains("RESULTS"),
        "the run did not end at once"
    );
    assert!(!gif.exists(), "a partial GIF was left under its name");
    // Nor under a temporary name: the second signal removes it.
    assert_eq!(names_in(&dir), ["c"]);
}

#[test]
fn an_interrupted_gen_leaves_no_file_under_its_name() {
    let dir = folder("gen");
    let path = dir.join("big.in");
    let mut child = spawn(&["gen", "--lines", "20000000", "-o", path.to_str().unwrap()]);
    // Wait until the scene is being written (its temporary file grows).
    let start = Instant::now();
    while names_in(&dir).is_empty() && start.elapsed() < Duration::from_secs(60) {
        std::thread::sleep(Duration::from_millis(10));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    assert!(!path.exists(), "a partial scene was left under its name");
}

#[test]
fn resuming_from_a_checkpoint_ends_where_the_whole_run_ends() {
    let dir = folder("resume");
    let reference = std::env::var_os("SCREENSAVER_REFERENCE")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../shared/reference"));
    let input = reference.join("inputs/beaver.in");
    let input = if input.exists() {
        input.to_str().unwrap().to_string()
    } else {
        // No reference data: a generated scene does as well.
        let path = dir.join("scene.in");
        let out = screensaver(&[
            "gen",
            "--lines",
            "700",
            "--seed",
            "3",
            "-o",
            path.to_str().unwrap(),
        ]);
        assert!(out.status.success());
        path.to_str().unwrap().to_string()
    };
    let p = |name: &str| dir.join(name).to_str().unwrap().to_string();
    let whole = screensaver(&[
        "600",
        &input,
        "--state-out",
        &p("whole.state"),
        "--checkpoint",
        &p("whole.c"),
        "--threads",
        "1",
    ]);
    assert!(whole.status.success(), "{}", text(&whole.stderr));
    let part = screensaver(&[
        "230",
        &input,
        "--checkpoint",
        &p("part.c"),
        "--detector",
        "quadtree",
    ]);
    assert!(part.status.success(), "{}", text(&part.stderr));
    let rest = screensaver(&[
        "600",
        &input,
        "--resume",
        &p("part.c"),
        "--state-out",
        &p("resumed.state"),
        "--checkpoint",
        &p("resumed.c"),
        "--threads",
        "3",
        "--detector",
        "sweep",
    ]);
    assert!(rest.status.success(), "{}", text(&rest.stderr));
    let counts = |out: &Output| {
        text(&out.stdout)
            .lines()
            .skip(4)
            .take(2)
            .map(String::from)
            .collect::<Vec<_>>()
    };
    assert_eq!(counts(&rest), counts(&whole));
    let read = |name: &str| std::fs::read(dir.join(name)).unwrap();
    assert!(read("resumed.state") == read("whole.state"));
    assert!(read("resumed.c") == read("whole.c"));

    // Another scene's checkpoint is refused, naming the file and line.
    let other = screensaver(&["600", "--resume", &p("part.c")]);
    assert!(!other.status.success());
    let err = text(&other.stderr);
    assert!(
        err.contains("part.c:2: the checkpoint is of another scene"),
        "{err}"
    );
    // So is a damaged one.
    let damaged = dir.join("damaged.c");
    let good = read("part.c");
    std::fs::write(&damaged, &good[..good.len() - 30]).unwrap();
    let out = screensaver(&["600", &input, "--resume", damaged.to_str().unwrap()]);
    assert!(!out.status.success());
    let err = text(&out.stderr);
    assert!(
        err.contains("damaged.c:")
            && (err.contains("expected 8 fields")
                || err.contains("ends after")
                || err.contains("ends without its `# checksum: ` line")),
        "{err}"
    );
    // And an edited one, however plausible the edit: the step, a counter,
    // one coordinate.
    let text_of = String::from_utf8(good).unwrap();
    let steps = text_of.lines().nth(2).unwrap().to_string();
    let counter = text_of.lines().nth(4).unwrap().to_string();
    let row = text_of.lines().nth(5).unwrap().to_string();
    let last_digit = |s: &str| {
        let mut s = s.to_string();
        let d = s.pop().unwrap();
        s.push(if d == '1' { '2' } else { '1' });
        s
    };
    let mut moved: Vec<String> = row.split(' ').map(String::from).collect();
    moved[1] = last_digit(&moved[1]);
    for (from, to) in [
        (steps.clone(), last_digit(&steps)),
        (counter.clone(), last_digit(&counter)),
        (row.clone(), moved.join(" ")),
    ] {
        std::fs::write(&damaged, text_of.replacen(&from, &to, 1)).unwrap();
        let out = screensaver(&["600", &input, "--resume", damaged.to_str().unwrap()]);
        assert_eq!(out.status.code(), Some(1), "{to}");
        let err = text(&out.stderr);
        assert!(
            err.contains("damaged.c:") && err.contains("the file was changed after it was written"),
            "{err}"
        );
    }
}

#[test]
fn outputs_that_are_not_regular_files_are_written_to_not_replaced() {
    let dir = folder("special");
    // `-` is standard output: the state follows the results block, and no
    // file named `-` is made.
    let out = Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(["3", "--state-out", "-"])
        .current_dir(&dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    let stdout = text(&out.stdout);
    let rows = stdout.lines().filter(|l| l.split(' ').count() == 7).count();
    assert_eq!(rows, 1000, "{stdout}");
    assert!(names_in(&dir).is_empty(), "{:?}", names_in(&dir));
    // A device stays a device; a full one is an error, named.
    let out = screensaver(&["3", "--state-out", "/dev/null"]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let out = screensaver(&["3", "--state-out", "/dev/full"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("/dev/full: cannot write:"),
        "{}",
        text(&out.stderr)
    );
    for device in ["/dev/null", "/dev/full"] {
        let kind = std::fs::metadata(device).unwrap().file_type();
        assert!(std::os::unix::fs::FileTypeExt::is_char_device(&kind));
    }
    // A symbolic link is followed: its target gets the state, the link
    // stays a link.
    let target = dir.join("target.txt");
    std::fs::write(&target, "old").unwrap();
    let link = dir.join("link");
    std::os::unix::fs::symlink("target.txt", &link).unwrap();
    let out = screensaver(&["3", "--state-out", link.to_str().unwrap()]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(
        std::fs::read_to_string(&target).unwrap().lines().count(),
        1000
    );
    assert_eq!(names_in(&dir), ["link", "target.txt"]);
    // A folder that exists but takes no files is not called missing.
    let out = screensaver(&["3", "--checkpoint", "/proc/x.ckpt"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        text(&out.stderr).contains("the folder /proc exists but does not take new files"),
        "{}",
        text(&out.stderr)
    );
}

#[test]
fn unwritable_outputs_are_reported_before_the_run() {
    let dir = folder("unwritable");
    let missing = dir.join("no/such/folder/state.txt");
    let start = Instant::now();
    let out = screensaver(&["100000000", "--state-out", missing.to_str().unwrap()]);
    assert!(
        start.elapsed() < Duration::from_secs(30),
        "the run went ahead"
    );
    assert_eq!(out.status.code(), Some(1));
    let err = text(&out.stderr);
    assert!(
        err.contains("state.txt: cannot write: the folder") && err.contains("does not exist"),
        "{err}"
    );
    assert!(out.stdout.is_empty(), "{}", text(&out.stdout));
    // A folder is no picture's name: a bad argument.
    let out = screensaver(&["100000000", "--render", dir.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(2));
    let out = screensaver(&["100000000", "--checkpoint", dir.to_str().unwrap()]);
    assert!(
        text(&out.stderr).contains("it is a folder"),
        "{}",
        text(&out.stderr)
    );
    assert_eq!(names_in(&dir), ["no"; 0]);
}

#[test]
fn a_closed_pipe_ends_quietly() {
    for args in [&["100000"][..], &["gen", "--lines", "1000000"][..]] {
        let mut child = spawn(args);
        let mut stdout = BufReader::new(child.stdout.take().unwrap());
        let mut first = String::new();
        stdout.read_line(&mut first).unwrap();
        assert!(!first.is_empty());
        drop(stdout);
        let mut stderr = String::new();
        child
            .stderr
            .take()
            .unwrap()
            .read_to_string(&mut stderr)
            .unwrap();
        let status = child.wait().unwrap();
        assert!(status.success(), "{args:?}: {status} {stderr}");
        assert!(stderr.is_empty(), "{args:?}: {stderr}");
    }
}

#[test]
fn a_passing_verify_says_what_it_checked() {
    let out = screensaver(&["40", "--verify"]);
    assert!(out.status.success());
    let err = text(&out.stderr);
    assert!(err.contains("verified: 41 steps"), "{err}");
    let out = screensaver(&["40", "--verify", "--json"]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["verified_steps"], 41);
    assert_eq!(v["interrupted"], false);
}

#[test]
fn messages_say_what_is_wrong_in_plain_words() {
    let err = text(&screensaver(&["10", "--grain", "0"]).stderr);
    assert!(err.contains("--grain <N>': must be at least 1"), "{err}");
    let err = text(&screensaver(&["1e6"]).stderr);
    assert!(
        err.contains("`1e6` is not a whole number of frames; write it out, as 1000000"),
        "{err}"
    );
    let err = text(&screensaver(&["10", "--threads", "5000"]).stderr);
    assert!(err.contains("5000 is more than 1024 threads"), "{err}");

    let dir = folder("messages");
    let binary = dir.join("binary.in");
    std::fs::write(&binary, b"\x7fELF\x02\x01\x01\x00\x1b[31m").unwrap();
    let out = screensaver(&["10", binary.to_str().unwrap()]);
    let err = text(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("\\x7fELF\\x02\\x01\\x01\\x00\\x1b[31m"),
        "{err}"
    );
    assert!(
        !err.contains('\x1b'),
        "raw bytes reached the terminal: {err:?}"
    );

    let one = dir.join("one.in");
    std::fs::write(
        &one,
        "1\n(600, 400), (600, 420), 1, 0, 0\n(602.5, 400), (602.5, 420), -1, 0, 1\n",
    )
    .unwrap();
    let err = text(&screensaver(&["10", one.to_str().unwrap()]).stderr);
    assert!(err.contains("declares 1 line but"), "{err}");
}

#[test]
fn one_sigint_stops_gen_at_once_leaving_no_file() {
    let dir = folder("gen");
    let scene = dir.join("big.in");
    // Fifty million lines take half a minute and more to write.
    let child = spawn(&["gen", "--lines", "50000000", "-o", scene.to_str().unwrap()]);
    // Until the temporary file beside it has grown, the run has not got
    // going.
    let start = Instant::now();
    while !std::fs::read_dir(&dir)
        .unwrap()
        .any(|e| e.unwrap().metadata().is_ok_and(|m| m.len() > 1 << 20))
    {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "gen wrote nothing"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let signalled = Instant::now();
    signal(&child, "INT");
    let out = child.wait_with_output().unwrap();
    let stderr = text(&out.stderr);
    common::assert_ended_by(out.status, "INT", &stderr);
    assert!(
        signalled.elapsed() < Duration::from_secs(5),
        "gen went on for {:?} after SIGINT",
        signalled.elapsed()
    );
    assert!(stderr.contains("gen stopped by SIGINT"), "{stderr}");
    assert!(names_in(&dir).is_empty(), "left: {:?}", names_in(&dir));
}

/// A shell sees 143 for a run SIGTERM stopped: the status the program's
/// death by the signal makes, as for any program that does not catch it.
#[cfg(unix)]
#[test]
fn a_shell_sees_the_signals_status() {
    let dir = folder("shell");
    let checkpoint = dir.join("c");
    let script = format!(
        "'{}' 100000000 --checkpoint '{}' --checkpoint-every 20 >/dev/null 2>&1 & \
         while [ ! -e '{}' ]; do sleep 0.02; done; kill -TERM $!; wait $!; echo status $?",
        env!("CARGO_BIN_EXE_screensaver"),
        checkpoint.display(),
        checkpoint.display()
    );
    let out = Command::new("sh").args(["-c", &script]).output().unwrap();
    assert_eq!(
        text(&out.stdout).trim(),
        "status 143",
        "{}",
        text(&out.stderr)
    );
}

/// A closed terminal (SIGHUP) stops a run as SIGTERM does: the results of
/// the steps run, the files whole, a death by the signal.
#[cfg(unix)]
#[test]
fn sighup_stops_a_run_as_sigterm_does() {
    let dir = folder("sighup");
    let (checkpoint, state) = (dir.join("c"), dir.join("s"));
    let child = spawn(&[
        "100000000",
        "--json",
        "--checkpoint",
        checkpoint.to_str().unwrap(),
        "--checkpoint-every",
        "20",
        "--state-out",
        state.to_str().unwrap(),
    ]);
    wait_for(&checkpoint);
    signal(&child, "HUP");
    let out = child.wait_with_output().unwrap();
    common::assert_ended_by(out.status, "HUP", &text(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["interrupted"], true);
    assert!(text(&out.stderr).contains("stopped by SIGHUP"));
    assert!(state.exists());
    assert_eq!(names_in(&dir), ["c", "s"]);
}

/// One signal stops the all-pairs detector within about a second, even
/// part way through a step of 100,000 lines (minutes long): the step under
/// way is given up, the results of the steps completed are printed.
#[test]
fn one_signal_stops_a_long_all_pairs_step_at_once() {
    for extra in ["--detector=brute", "--verify"] {
        let child = spawn(&["3", "--lines", "100000", "--json", extra]);
        std::thread::sleep(Duration::from_millis(1500));
        signal(&child, "INT");
        let signalled = Instant::now();
        let out = child.wait_with_output().unwrap();
        let waited = signalled.elapsed();
        common::assert_ended_by(out.status, "INT", &text(&out.stderr));
        assert!(
            waited < Duration::from_secs(10),
            "{extra}: {waited:?} after SIGINT"
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["interrupted"], true, "{extra}");
        assert_eq!(v["steps_run"], 0, "{extra}");
    }
}

/// A signal the run was started ignoring (`nohup` ignores SIGHUP) stays
/// ignored: the run goes on when the terminal closes.
#[cfg(target_os = "linux")]
#[test]
fn a_run_started_ignoring_sighup_goes_on_after_one() {
    let dir = folder("nohup");
    let checkpoint = dir.join("c");
    let command = format!(
        "trap '' HUP; exec '{}' 100000000 --checkpoint '{}' --checkpoint-every 20",
        env!("CARGO_BIN_EXE_screensaver"),
        checkpoint.display()
    );
    let child = Command::new("sh")
        .args(["-c", &command])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_for(&checkpoint);
    signal(&child, "HUP");
    std::thread::sleep(Duration::from_millis(500));
    signal(&child, "TERM");
    let out = child.wait_with_output().unwrap();
    common::assert_ended_by(out.status, "TERM", &text(&out.stderr));
    assert!(text(&out.stderr).contains("stopped by SIGTERM"));
}

/// A scene read from a pipe (`/dev/stdin`) is read whole: nothing looks
/// at it before the loading does.
#[cfg(target_os = "linux")]
#[test]
fn a_scene_from_a_pipe_is_read_whole() {
    let bin = env!("CARGO_BIN_EXE_screensaver");
    let out = Command::new("sh")
        .args([
            "-c",
            &format!("'{bin}' gen --lines 50 | '{bin}' 5 /dev/stdin"),
        ])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(text(&out.stdout).contains("---- END RESULTS ----"));
}
