//! The live window, under a virtual X server: it opens, draws both line
//! colours, and ends by itself after the requested frames. Skipped (with a
//! message) where `Xvfb` or `xwd` is missing; CI installs both.

mod common;

use common::x11::{red_and_gray, screenshot, signal, Xvfb};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A scene of long red and gray lines that hold still in the middle.
fn scene() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("screensaver-window-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut text = String::from("20\n");
    for k in 0..20 {
        let x = 300 + 30 * k;
        text += &format!("({x}, 200), ({x}, 600), 0, 0, {}\n", k % 2);
    }
    let path = dir.join("still.in");
    std::fs::write(&path, text).unwrap();
    path
}

fn screensaver(display: &str, args: &[&str], scene: &Path) -> Child {
    Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(args)
        .arg(scene)
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("running screensaver")
}

#[test]
fn the_window_shows_both_colours() {
    let Some(x) = Xvfb::start() else { return };
    let scene = scene();
    let mut child = screensaver(&x.display, &["-g", "--hold", "5"], &scene);
    let start = Instant::now();
    let (mut red, mut gray) = (0, 0);
    while start.elapsed() < Duration::from_secs(15) && (red < 500 || gray < 500) {
        std::thread::sleep(Duration::from_millis(500));
        (red, gray) = red_and_gray(&screenshot(&x.display));
    }
    let _ = child.kill();
    let _ = child.wait();
    assert!(
        red >= 500 && gray >= 500,
        "red pixels {red}, gray pixels {gray}"
    );
}

#[test]
fn the_window_closes_after_the_frames_and_prints_the_results() {
    let Some(x) = Xvfb::start() else { return };
    let scene = scene();
    let child = screensaver(&x.display, &["-g", "30"], &scene);
    let out = child.wait_with_output().expect("waiting for screensaver");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(stdout.contains("Number of frames = 30"), "{stdout}");
    assert!(stdout.contains("0 Line-Wall Collisions"), "{stdout}");
    assert!(stdout.contains("---- END RESULTS ----"), "{stdout}");
}

#[test]
fn sigterm_closes_the_window_with_the_results() {
    let Some(x) = Xvfb::start() else { return };
    let scene = scene();
    let child = screensaver(&x.display, &["-g", "--hold", "100000000"], &scene);
    // Let the window open and the run get going.
    std::thread::sleep(Duration::from_secs(2));
    signal(&child, "-TERM");
    let out = child.wait_with_output().expect("waiting for screensaver");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    common::assert_ended_by(out.status, "TERM", &stderr);
    assert!(stdout.contains("---- END RESULTS ----"), "{stdout}");
    assert!(stderr.contains("stopped by SIGTERM"), "{stderr}");
}

/// A window test that cannot run says so in the ordinary test output, not
/// only with `--nocapture`: here a test of this file is run again with no
/// X server or tools on its PATH.
#[test]
fn a_skipped_window_test_says_so() {
    let out = Command::new(std::env::current_exe().expect("this test's binary"))
        .args([
            "--exact",
            "the_window_closes_after_the_frames_and_prints_the_results",
        ])
        .env("PATH", "/nonexistent")
        .env_remove("SCREENSAVER_REQUIRE_DISPLAY")
        .output()
        .expect("running this test binary again");
    let shown = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.status.success(), "{shown}");
    assert!(
        shown.contains("window test: skipped: Xvfb, xwd not found"),
        "{shown}"
    );
}
