//! The screensaver modes under a virtual X server: drawing on the root
//! window, into a window another program owns (as XScreenSaver hands one
//! over) and following its size, full screen, endless runs of generated
//! scenes, and SIGTERM ending each with the results. Skipped (with a
//! message) where `Xvfb`, `xwd` or `xwininfo` is missing, or failing where
//! `SCREENSAVER_REQUIRE_DISPLAY=1`; CI installs them and sets it.

mod common;

use common::x11::{red_and_gray, screenshot, signal, tools_found, Xvfb};
use std::path::PathBuf;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// A scene of long red and gray lines that hold still, spread over the
/// whole box.
fn still_scene() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("screensaver-saver-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut text = String::from("20\n");
    for k in 0..20 {
        let x = 30 + 58 * k;
        text += &format!("({x}, 40), ({x}, 760), 0, 0, {}\n", k % 2);
    }
    let path = dir.join("still.in");
    std::fs::write(&path, text).unwrap();
    path
}

fn start(display: &str, args: &[&str], env: &[(&str, &str)]) -> Child {
    let mut command = Command::new(env!("CARGO_BIN_EXE_screensaver"));
    command
        .args(args)
        .env("DISPLAY", display)
        .env_remove("WAYLAND_DISPLAY")
        .env_remove("XSCREENSAVER_WINDOW")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    for (name, value) in env {
        command.env(name, value);
    }
    command.spawn().expect("running screensaver")
}

/// Sends SIGTERM, waits for the program, and checks it ended as a
/// signalled run does: status 143, the results block, within a few
/// seconds (it ends at the end of the current step and frame).
fn terminate(child: Child) -> Output {
    let sent = Instant::now();
    signal(&child, "-TERM");
    let out = child.wait_with_output().expect("waiting for screensaver");
    let took = sent.elapsed();
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    eprintln!("ended {took:?} after SIGTERM");
    assert!(took < Duration::from_secs(3), "took {took:?} to end");
    common::assert_ended_by(out.status, "TERM", &stderr);
    assert!(
        stdout.contains("---- END RESULTS ----") || stdout.contains("\"interrupted\":true"),
        "{stdout}"
    );
    assert!(stderr.contains("stopped by SIGTERM"), "{stderr}");
    out
}

/// Waits until the screen shows plenty of both colours within `area`
/// (a filter on pixel positions), or 15 seconds pass; returns the counts.
fn wait_for_lines(
    display: &str,
    width: usize,
    area: impl Fn(usize, usize) -> bool,
) -> (usize, usize) {
    let start = Instant::now();
    loop {
        let pixels = screenshot(display);
        let inside: Vec<[u8; 3]> = pixels
            .iter()
            .enumerate()
            .filter(|(k, _)| area(k % width, k / width))
            .map(|(_, p)| *p)
            .collect();
        let (red, gray) = red_and_gray(&inside);
        if (red >= 500 && gray >= 500) || start.elapsed() > Duration::from_secs(15) {
            return (red, gray);
        }
        std::thread::sleep(Duration::from_millis(300));
    }
}

#[test]
fn root_draws_both_colours_over_the_whole_screen() {
    let Some(x) = Xvfb::start() else { return };
    let scene = still_scene();
    let child = start(
        &x.display,
        &["--root", "--hud", scene.to_str().unwrap()],
        &[],
    );
    // The lines run from 5% to 95% of the box's height, so they reach
    // both the top and the bottom tenth of the 900-pixel screen.
    let (red, gray) = wait_for_lines(&x.display, 1280, |_, y| y < 90);
    assert!(red >= 100 && gray >= 100, "top: red {red}, gray {gray}");
    let (red, gray) = wait_for_lines(&x.display, 1280, |_, y| y >= 810);
    assert!(red >= 100 && gray >= 100, "bottom: red {red}, gray {gray}");
    // The heads-up display's white text in the top left corner (the
    // scene has no white of its own).
    let text = screenshot(&x.display)
        .iter()
        .enumerate()
        .filter(|(k, p)| k % 1280 < 300 && k / 1280 < 60 && **p == [255, 255, 255])
        .count();
    assert!(text >= 100, "{text} white pixels in the heads-up display");
    let out = terminate(child);
    assert!(String::from_utf8_lossy(&out.stdout).contains("Number of frames = endless"));
}

/// A bare top-level window of the test's own, as XScreenSaver hands one
/// to a hack (no children, no window manager): black, `width` x `height`
/// at (`x`, `y`), mapped. The connection keeps it alive.
fn bare_window(
    display: &str,
    (x, y, width, height): (i16, i16, u16, u16),
) -> (x11rb::rust_connection::RustConnection, u32) {
    use x11rb::connection::Connection;
    use x11rb::protocol::xproto::{ConnectionExt, CreateWindowAux, WindowClass};
    let (conn, screen) = x11rb::connect(Some(display)).expect("connecting to the X server");
    let root = &conn.setup().roots[screen];
    let (root_window, black) = (root.root, root.black_pixel);
    let id = conn.generate_id().expect("a window id");
    conn.create_window(
        x11rb::COPY_DEPTH_FROM_PARENT,
        id,
        root_window,
        x,
        y,
        width,
        height,
        0,
        WindowClass::INPUT_OUTPUT,
        x11rb::COPY_FROM_PARENT,
        &CreateWindowAux::new().background_pixel(black),
    )
    .expect("creating a window");
    conn.map_window(id).expect("mapping the window");
    // A round trip: the window is mapped and drawn before the screenshot.
    conn.get_geometry(id)
        .expect("asking for the window's size")
        .reply()
        .expect("the window's size");
    (conn, id)
}

/// The window's children, through the X server.
fn children(conn: &x11rb::rust_connection::RustConnection, id: u32) -> Vec<u32> {
    use x11rb::protocol::xproto::ConnectionExt;
    conn.query_tree(id)
        .expect("asking for the window tree")
        .reply()
        .expect("the window tree")
        .children
}

#[test]
fn xscreensaver_window_is_drawn_into_not_replaced() {
    let Some(x) = Xvfb::start() else { return };
    let (conn, window) = bare_window(&x.display, (100, 150, 400, 300));
    let id = format!("0x{window:x}");
    let before = screenshot(&x.display);
    assert!(children(&conn, window).is_empty());
    let scene = still_scene();
    let child = start(
        &x.display,
        &[scene.to_str().unwrap()],
        &[("XSCREENSAVER_WINDOW", &id)],
    );
    let inside = |x: usize, y: usize| (100..500).contains(&x) && (150..450).contains(&y);
    let (red, gray) = wait_for_lines(&x.display, 1280, inside);
    assert!(
        red >= 500 && gray >= 500,
        "in the window: red {red}, gray {gray}"
    );
    // Nothing drawn outside it.
    let changed = screenshot(&x.display)
        .iter()
        .zip(&before)
        .enumerate()
        .filter(|(k, (now, then))| !inside(k % 1280, k / 1280) && now != then)
        .count();
    assert_eq!(changed, 0, "pixels changed outside the window");
    // The same window, with no window of ours put inside it.
    assert!(children(&conn, window).is_empty());
    // Grown to 700 x 450, the window is filled again: lines reach into the
    // part it gained on the right.
    resize(&x.display, &id, 700, 450);
    let gained = |x: usize, y: usize| (520..800).contains(&x) && (150..600).contains(&y);
    let (red, gray) = wait_for_lines(&x.display, 1280, gained);
    assert!(
        red >= 500 && gray >= 500,
        "in the part the window gained: red {red}, gray {gray}"
    );
    terminate(child);
    drop(conn);
}

/// Resizes another client's window, as a window manager or the user would.
fn resize(display: &str, id: &str, width: u16, height: u16) {
    use x11rb::protocol::xproto::{ConfigureWindowAux, ConnectionExt};
    let window = screensaver::render::Screen::parse_window_id(id).expect("a window id");
    let (conn, _) = x11rb::connect(Some(display)).expect("connecting to the X server");
    conn.configure_window(
        window,
        &ConfigureWindowAux::new()
            .width(u32::from(width))
            .height(u32::from(height)),
    )
    .expect("resizing the window");
    // A round trip, so that the server has carried the resize out before
    // this connection closes (a request still unread when a client hangs
    // up may be dropped with it).
    let geometry = conn
        .get_geometry(window)
        .expect("asking for the window's size")
        .reply()
        .expect("the window's size");
    assert_eq!((geometry.width, geometry.height), (width, height));
}

#[test]
fn a_bad_window_id_is_refused_plainly() {
    let Some(x) = Xvfb::start() else { return };
    let out = start(&x.display, &["--window-id", "0x7fffff0"], &[])
        .wait_with_output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("there is no window 0x7fffff0"), "{stderr}");
    // With FRAMES, whose runs print a header first: nothing is printed
    // before the window is found missing.
    let scene = still_scene();
    let out = start(
        &x.display,
        &["--window-id", "0x7fffff0", "5", scene.to_str().unwrap()],
        &[],
    )
    .wait_with_output()
    .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(
        out.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let out = start(
        &x.display,
        &["-g", "5"],
        &[("XSCREENSAVER_WINDOW", "nonsense")],
    )
    .wait_with_output()
    .unwrap();
    // -g opens its own window, whatever the variable says; without -g the
    // variable must name a window.
    assert!(!String::from_utf8_lossy(&out.stderr).contains("nonsense"));
    let out = start(&x.display, &[], &[("XSCREENSAVER_WINDOW", "nonsense")])
        .wait_with_output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("XSCREENSAVER_WINDOW: `nonsense` is not a window id"),
        "{stderr}"
    );
}

#[test]
fn endless_runs_start_new_scenes() {
    let Some(x) = Xvfb::start() else { return };
    let child = start(
        &x.display,
        &["--root", "--cycle", "0.3", "--lines", "300", "--seed", "5"],
        &[],
    );
    std::thread::sleep(Duration::from_secs(3));
    let out = terminate(child);
    let stderr = String::from_utf8_lossy(&out.stderr);
    let shown: u64 = stderr
        .split("showed ")
        .nth(1)
        .and_then(|s| s.split_whitespace().next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no scene count in {stderr}"));
    assert!(shown >= 3, "{stderr}");
    assert!(stderr.contains("(seeds 5 to "), "{stderr}");
    // The results block is the last scene's, and its header names it.
    let stdout = String::from_utf8_lossy(&out.stdout);
    let last = 5 + shown - 1;
    assert!(
        stdout.contains(&format!("300 lines, seed {last})\n---- RESULTS ----")),
        "{stdout}"
    );
}

#[test]
fn fullscreen_fills_the_screen() {
    let Some(x) = Xvfb::with_screen("1920x1080x24") else {
        return;
    };
    if !tools_found(&["xwininfo"]) {
        return;
    }
    let scene = still_scene();
    let mut child = start(&x.display, &["--fullscreen", scene.to_str().unwrap()], &[]);
    let started = Instant::now();
    loop {
        if let Ok(Some(_)) = child.try_wait() {
            let out = child.wait_with_output().expect("its output");
            panic!(
                "screensaver ended before its window appeared: {:?}: {}",
                out.status,
                String::from_utf8_lossy(&out.stderr)
            );
        }
        let out = Command::new("xwininfo")
            .args(["-display", &x.display, "-root", "-tree"])
            .output()
            .expect("running xwininfo");
        let tree = String::from_utf8_lossy(&out.stdout).to_string();
        if tree
            .lines()
            .any(|l| l.contains("\"screensaver") && l.contains("1920x1080+0+0"))
        {
            break;
        }
        assert!(
            started.elapsed() < Duration::from_secs(15),
            "no full-screen window in\n{tree}"
        );
        std::thread::sleep(Duration::from_millis(200));
    }
    // The picture fills it: lines reach the screen's left and right tenths.
    let (red, gray) = wait_for_lines(&x.display, 1920, |x, _| !(192..1728).contains(&x));
    assert!(red >= 100 && gray >= 100, "edges: red {red}, gray {gray}");
    terminate(child);
}

#[test]
fn drawing_large_scenes_is_timed_in_the_stats() {
    let Some(x) = Xvfb::start() else { return };
    let child = start(
        &x.display,
        &[
            "--root", "--lines", "100000", "--seed", "1", "--stats", "--json",
        ],
        &[],
    );
    std::thread::sleep(Duration::from_secs(4));
    let out = terminate(child);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let json = stdout
        .lines()
        .find(|l| l.starts_with('{'))
        .expect("a JSON line");
    let field = |name: &str| -> f64 {
        let at = json
            .find(&format!("\"{name}\":"))
            .unwrap_or_else(|| panic!("{name} in {json}"));
        json[at + name.len() + 3..]
            .split([',', '}'])
            .next()
            .unwrap()
            .parse()
            .unwrap()
    };
    let (fps, per_frame) = (field("drawn_fps"), field("draw_seconds_per_frame"));
    // A measurement, reported; only its presence is checked.
    eprintln!(
        "100,000 lines on 1280 x 900: {fps:.1} frames/s, {:.1} ms to draw a frame",
        per_frame * 1e3
    );
    assert!(fps > 0.0 && per_frame > 0.0, "{json}");
    assert!(json.contains("\"interrupted\":true"), "{json}");
}
