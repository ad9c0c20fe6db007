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

/// Under `xvfb-run` as a user types it: a server with no other client,
/// which resets whenever its last client leaves. Ten runs in a row, each
/// opens its window and ends with its results.
#[test]
fn the_window_opens_under_plain_xvfb_run() {
    if !common::x11::tools_found(&["xvfb-run", "Xvfb", "xauth"]) {
        return;
    }
    let _turn = common::x11::turn();
    let scene = scene();
    for k in 0..10 {
        let out = Command::new("xvfb-run")
            .args(["-a", env!("CARGO_BIN_EXE_screensaver"), "-g", "3"])
            .arg(&scene)
            .env_remove("WAYLAND_DISPLAY")
            .env_remove("XSCREENSAVER_WINDOW")
            .output()
            .expect("running xvfb-run");
        let (stdout, stderr) = (
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr),
        );
        assert!(
            out.status.success() && stdout.contains("---- END RESULTS ----"),
            "run {k}: {:?}\nstdout: {stdout}\nstderr: {stderr}",
            out.status
        );
    }
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

/// The program's own top-level windows on the display: the children of
/// the root window whose title starts with `screensaver`.
fn our_windows(conn: &x11rb::rust_connection::RustConnection, root: u32) -> Vec<u32> {
    use x11rb::protocol::xproto::{AtomEnum, ConnectionExt};
    let children = conn.query_tree(root).unwrap().reply().unwrap().children;
    (children.into_iter())
        .filter(|&w| {
            let name = conn.get_property(false, w, AtomEnum::WM_NAME, AtomEnum::STRING, 0, 64);
            name.ok()
                .and_then(|c| c.reply().ok())
                .is_some_and(|p| p.value.starts_with(b"screensaver"))
        })
        .collect()
}

/// Another client destroys the window (as `xdotool windowclose` does): the
/// run ends as when the window is closed, with its results and status 0.
#[test]
fn a_window_destroyed_by_another_client_ends_the_run_with_its_results() {
    use x11rb::connection::Connection;
    use x11rb::protocol::xproto::ConnectionExt;
    let Some(x) = Xvfb::start() else { return };
    let scene = scene();
    let child = screensaver(&x.display, &["-g", "100000000"], &scene);
    let (conn, screen) = x11rb::connect(Some(&x.display)).expect("connecting to the X server");
    let root = conn.setup().roots[screen].root;
    let start = Instant::now();
    let window = loop {
        if let Some(&w) = our_windows(&conn, root).first() {
            break w;
        }
        assert!(
            start.elapsed() < Duration::from_secs(20),
            "no window appeared"
        );
        std::thread::sleep(Duration::from_millis(100));
    };
    // Let it draw for a while first.
    std::thread::sleep(Duration::from_millis(500));
    conn.destroy_window(window).unwrap();
    conn.flush().unwrap();
    let out = child.wait_with_output().expect("waiting for screensaver");
    let (stdout, stderr) = (
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr),
    );
    assert!(out.status.success(), "{:?}: {stderr}", out.status);
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stdout.contains("---- END RESULTS ----"), "{stdout}");
}

/// A run resumed on screen ends where the whole run would: at FRAMES + 1
/// steps from the scene's start, not that many after the checkpoint.
#[test]
fn a_resumed_run_on_screen_ends_at_the_runs_last_step() {
    let Some(x) = Xvfb::start() else { return };
    let scene = scene();
    let checkpoint = scene.with_extension("ckpt");
    let ckpt = checkpoint.to_str().unwrap();
    let saved = Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(["10", scene.to_str().unwrap(), "--checkpoint", ckpt])
        .output()
        .unwrap();
    assert!(saved.status.success());
    // From the checkpoint's step 11 to 31 and 16.
    for (frames, last) in [("30", 31), ("15", 16)] {
        let args = ["-g", frames, "--speed", "max", "--json", "--resume", ckpt];
        let out = screensaver(&x.display, &args, &scene)
            .wait_with_output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(v["steps_run"], last, "{v}");
    }
}
