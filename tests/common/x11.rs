//! A virtual X server for the window tests, and what they look at on it:
//! the screen's pixels and the window tree. Tests skip (with a message)
//! where `Xvfb` or `xwd` is missing, or fail where
//! `SCREENSAVER_REQUIRE_DISPLAY=1` (CI installs both and sets it).

#![allow(dead_code)]

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::{Mutex, MutexGuard};

pub fn found(program: &str) -> bool {
    std::env::var_os("PATH")
        .map(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
        .unwrap_or(false)
}

/// Whether every one of `programs` is on the PATH. Where one is missing
/// the test is skipped with a message, unless `SCREENSAVER_REQUIRE_DISPLAY=1`
/// (CI sets it), which makes it fail instead.
pub fn tools_found(programs: &[&str]) -> bool {
    let missing: Vec<&str> = programs.iter().copied().filter(|p| !found(p)).collect();
    if missing.is_empty() {
        return true;
    }
    let required = std::env::var_os("SCREENSAVER_REQUIRE_DISPLAY").is_some_and(|v| v == "1");
    assert!(
        !required,
        "window test: {} not found and SCREENSAVER_REQUIRE_DISPLAY=1 \
         (apt-get install xvfb x11-apps x11-utils)",
        missing.join(", ")
    );
    super::say_skipped(&format!(
        "window test: skipped: {} not found (apt-get install xvfb x11-apps x11-utils)",
        missing.join(", ")
    ));
    false
}

/// A virtual X server on its own display, stopped when dropped.
pub struct Xvfb {
    child: Child,
    /// The display's name, `:N`.
    pub display: String,
    /// This test's turn: one X test at a time within a test binary, so
    /// that servers, clients and screenshots do not crowd two cores (with
    /// all of them at once, a window took over 10 s to appear). Released
    /// after the server is stopped.
    _turn: MutexGuard<'static, ()>,
}

/// Whose turn it is to run a server.
static TURN: Mutex<()> = Mutex::new(());

/// Waits for the turn to run an X server (one at a time), for a test that
/// starts its own (`xvfb-run`).
pub fn turn() -> MutexGuard<'static, ()> {
    TURN.lock().unwrap_or_else(|e| e.into_inner())
}

impl Xvfb {
    /// A server with a 1280 x 900 screen.
    pub fn start() -> Option<Xvfb> {
        Self::with_screen("1280x900x24")
    }

    /// A server with a screen of `screen` (`WxHxDEPTH`).
    pub fn with_screen(screen: &str) -> Option<Xvfb> {
        if !tools_found(&["Xvfb", "xwd"]) {
            return None;
        }
        // A test that failed while holding the turn leaves it poisoned:
        // the turn is still free to take.
        let turn = TURN.lock().unwrap_or_else(|e| e.into_inner());
        // Xvfb picks a display no other server holds and writes its
        // number once it accepts connections. A display whose socket an
        // earlier server left behind can still refuse clients: each server
        // is checked with a real client, and one that fails is kept
        // running while the next starts (so that it picks another number).
        let mut failed = Vec::new();
        let found = (0..5).find_map(|_| {
            let (mut child, display) = start_server(screen);
            if answers(&display) {
                Some((child, display))
            } else {
                let _ = child.kill();
                failed.push(child);
                None
            }
        });
        for mut child in failed {
            let _ = child.wait();
        }
        let (child, display) = found.expect("no Xvfb server answered in five tries");
        Some(Xvfb {
            child,
            display,
            _turn: turn,
        })
    }
}

/// Starts a server and returns it with its display's name.
fn start_server(screen: &str) -> (Child, String) {
    let mut child = Command::new("Xvfb")
        .args([
            "-displayfd",
            "1",
            "-screen",
            "0",
            screen,
            "-nolisten",
            "tcp",
            // Without it the server resets when its last client leaves
            // (the check below), and a client connecting meanwhile has
            // its connection reset.
            "-noreset",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .expect("starting Xvfb");
    let mut line = String::new();
    BufReader::new(child.stdout.take().expect("Xvfb's stdout"))
        .read_line(&mut line)
        .expect("reading Xvfb's display number");
    let number: u32 = line.trim().parse().expect("Xvfb did not start");
    (child, format!(":{number}"))
}

/// Whether a client (`xwd`, with the X library every test client uses)
/// can talk to `display`.
fn answers(display: &str) -> bool {
    Command::new("xwd")
        .args(["-root", "-silent", "-display", display])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        // SIGTERM lets the server remove its socket and lock, which a
        // SIGKILL leaves behind for the next server to trip over.
        let _ = Command::new("kill")
            .args(["-TERM", &self.child.id().to_string()])
            .status();
        let _ = self.child.wait();
    }
}

/// The root window's pixels as RGB, from `xwd`'s output (32-bit ZPixmap).
pub fn screenshot(display: &str) -> Vec<[u8; 3]> {
    let out = Command::new("xwd")
        .args(["-root", "-silent", "-display", display])
        .output()
        .expect("running xwd");
    assert!(out.status.success(), "xwd failed");
    let d = out.stdout;
    let field = |k: usize| u32::from_be_bytes(d[4 * k..4 * k + 4].try_into().unwrap()) as usize;
    let (header, width, height) = (field(0), field(4), field(5));
    let (byte_order, bits_per_pixel, bytes_per_line, ncolors) =
        (field(7), field(11), field(12), field(19));
    assert_eq!(bits_per_pixel, 32, "expected a 24-bit screen");
    let start = header + 12 * ncolors;
    let mut pixels = Vec::with_capacity(width * height);
    for y in 0..height {
        for x in 0..width {
            let p = &d[start + y * bytes_per_line + 4 * x..][..4];
            let v = if byte_order == 0 {
                u32::from_le_bytes(p.try_into().unwrap())
            } else {
                u32::from_be_bytes(p.try_into().unwrap())
            };
            pixels.push([(v >> 16) as u8, (v >> 8) as u8, v as u8]);
        }
    }
    pixels
}

/// Pixels that are plainly the red lines' colour, and plainly the gray
/// lines' (anti-aliased edges blend the colours with black: judged by
/// hue).
pub fn red_and_gray(pixels: &[[u8; 3]]) -> (usize, usize) {
    let [r, g, b] = [0, 1, 2];
    let red = pixels
        .iter()
        // Widened before the product: 3 * 255 does not fit a byte (and
        // wrapped, in a release build, so that white counted as red).
        .filter(|p| p[r] >= 60 && u16::from(p[r]) > 3 * u16::from(p[g]) && p[g].abs_diff(p[b]) <= 4)
        .count();
    let gray = pixels
        .iter()
        .filter(|p| p[r] >= 60 && p[r].abs_diff(p[g]) <= 4 && p[g].abs_diff(p[b]) <= 4)
        .count();
    (red, gray)
}

/// Sends `signal` (`-TERM`, `-INT`) to a child.
pub fn signal(child: &Child, signal: &str) {
    let sent = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .expect("running kill");
    assert!(sent.success());
}
