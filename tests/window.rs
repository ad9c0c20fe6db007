//! The live window, under a virtual X server: it opens, draws both line
//! colours, and ends by itself after the requested frames. Skipped (with a
//! message) where `Xvfb` or `xwd` is missing; CI installs both.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn found(program: &str) -> bool {
    std::env::var_os("PATH")
        .map(|paths| std::env::split_paths(&paths).any(|dir| dir.join(program).is_file()))
        .unwrap_or(false)
}

/// A virtual X server on its own display, stopped when dropped.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Option<Xvfb> {
        if !found("Xvfb") || !found("xwd") {
            eprintln!(
                "window test: skipped: Xvfb or xwd not found (apt-get install xvfb x11-apps)"
            );
            return None;
        }
        // Xvfb picks a display no other server holds (a server killed
        // earlier leaves its lock and socket behind) and writes its number
        // once it accepts connections.
        let mut child = Command::new("Xvfb")
            .args([
                "-displayfd",
                "1",
                "-screen",
                "0",
                "1280x900x24",
                "-nolisten",
                "tcp",
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
        Some(Xvfb {
            child,
            display: format!(":{number}"),
        })
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

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

/// The root window's pixels as RGB, from `xwd`'s output (32-bit ZPixmap).
fn screenshot(display: &str) -> Vec<[u8; 3]> {
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
        let pixels = screenshot(&x.display);
        // Anti-aliased edges blend the colours with black: judge by hue.
        let [r, g, b] = [0, 1, 2];
        red = pixels
            .iter()
            .filter(|p| p[r] >= 60 && p[r] > 3 * p[g] && p[g].abs_diff(p[b]) <= 4)
            .count();
        gray = pixels
            .iter()
            .filter(|p| p[r] >= 60 && p[r].abs_diff(p[g]) <= 4 && p[g].abs_diff(p[b]) <= 4)
            .count();
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
    let killed = Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .expect("running kill");
    assert!(killed.success());
    let out = child.wait_with_output().expect("waiting for screensaver");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(143), "{stderr}");
    assert!(stdout.contains("---- END RESULTS ----"), "{stdout}");
    assert!(stderr.contains("stopped by SIGTERM"), "{stderr}");
}
