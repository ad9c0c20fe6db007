//! Pictures of a hand-made scene: the right colours at known places and
//! black elsewhere, in PNG, PNG sequences, GIF and SVG, through the command
//! line.

use std::path::{Path, PathBuf};
use std::process::Command;
use tiny_skia::Pixmap;

fn temp_dir(name: &str) -> PathBuf {
    let dir =
        std::env::temp_dir().join(format!("screensaver-render-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A red horizontal line across the upper half and a gray vertical one in
/// the right half, both still.
fn scene(dir: &Path) -> PathBuf {
    let path = dir.join("cross.in");
    std::fs::write(
        &path,
        "2\n(100, 200), (1000, 200), 0, 0, 0\n(900, 300), (900, 700), 0, 0, 1\n",
    )
    .unwrap();
    path
}

fn screensaver(args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn rgb(p: &Pixmap, x: u32, y: u32) -> [u8; 3] {
    let c = p.pixel(x, y).unwrap().demultiply();
    [c.red(), c.green(), c.blue()]
}

fn is_red(c: [u8; 3]) -> bool {
    c[0] >= 60 && c[0] > 3 * c[1] && c[1].abs_diff(c[2]) <= 4
}

fn is_gray(c: [u8; 3]) -> bool {
    c[0] >= 60 && c[0].abs_diff(c[1]) <= 4 && c[1].abs_diff(c[2]) <= 4
}

/// The red line crosses pixel `red` (or the one above it, as the line's
/// edge may fall between them) and the gray one pixel `gray` (or the one to
/// its left).
fn assert_lines_drawn(p: &Pixmap, red: (u32, u32), gray: (u32, u32)) {
    let ((rx, ry), (gx, gy)) = (red, gray);
    assert!(
        is_red(rgb(p, rx, ry)) || is_red(rgb(p, rx, ry - 1)),
        "{:?}",
        rgb(p, rx, ry)
    );
    assert!(
        is_gray(rgb(p, gx, gy)) || is_gray(rgb(p, gx - 1, gy)),
        "{:?}",
        rgb(p, gx, gy)
    );
}

#[test]
fn png_shows_the_lines_where_they_are() {
    let dir = temp_dir("png");
    let out = dir.join("cross.png");
    screensaver(&[
        "0",
        scene(&dir).to_str().unwrap(),
        "--render",
        out.to_str().unwrap(),
    ]);
    let p = Pixmap::load_png(&out).unwrap();
    assert_eq!((p.width(), p.height()), (1180, 800));
    // Window coordinates are pixel coordinates at the default size.
    assert_lines_drawn(&p, (500, 200), (900, 500));
    for (x, y) in [(5, 5), (1175, 795), (500, 400), (200, 600), (1100, 200)] {
        assert_eq!(rgb(&p, x, y), [0, 0, 0], "at {x}, {y}");
    }
    let lit = p
        .pixels()
        .iter()
        .filter(|c| c.red() > 0 || c.green() > 0)
        .count();
    // The red line is 900 pixels long, the gray 400, each 1.5 pixels wide.
    assert!(lit > 900 && lit < 900 * 3 + 400 * 3, "{lit} lit pixels");
}

#[test]
fn sizes_scale_the_picture() {
    let dir = temp_dir("small");
    let out = dir.join("small.png");
    screensaver(&[
        "0",
        scene(&dir).to_str().unwrap(),
        "--render",
        out.to_str().unwrap(),
        "--size",
        "590x400",
    ]);
    let p = Pixmap::load_png(&out).unwrap();
    assert_eq!((p.width(), p.height()), (590, 400));
    assert_lines_drawn(&p, (250, 100), (450, 250));
}

/// Renders `frames` frames of the test scene into a PNG sequence, every
/// `every` steps, in a fresh folder named after `name`; the names written.
fn render_sequence(name: &str, frames: &str, every: &str) -> (std::path::PathBuf, Vec<String>) {
    let dir = temp_dir(name);
    let out = dir.join("run.png");
    screensaver(&[
        frames,
        scene(&dir).to_str().unwrap(),
        "--render",
        out.to_str().unwrap(),
        "--render-every",
        every,
        "--size",
        "118x80",
    ]);
    let mut written: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|name| name.starts_with("run-"))
        .collect();
    written.sort();
    (dir, written)
}

#[test]
fn sequences_number_every_kth_frame() {
    let (dir, _) = render_sequence("seq", "9", "5");
    for step in [0, 5, 10] {
        let frame = dir.join(format!("run-{step:06}.png"));
        assert!(frame.is_file(), "{}", frame.display());
    }
    assert!(!dir.join("run-000001.png").exists());
    // 12 frames run 13 steps: every fifth, and the last step besides, so
    // that the sequence shows where the run got to.
    let (_, written) = render_sequence("seq-end", "12", "5");
    assert_eq!(
        written,
        [
            "run-000000.png",
            "run-000005.png",
            "run-000010.png",
            "run-000013.png"
        ]
    );
    // A K longer than the run: the first step and the last.
    let (_, written) = render_sequence("seq-long", "12", "20");
    assert_eq!(written, ["run-000000.png", "run-000013.png"]);
}

#[test]
fn gif_has_a_frame_per_kth_step_and_the_fixed_palette() {
    let dir = temp_dir("gif");
    let out = dir.join("run.gif");
    screensaver(&[
        "19",
        scene(&dir).to_str().unwrap(),
        "--render",
        out.to_str().unwrap(),
        "--render-every",
        "5",
        "--size",
        "236x160",
    ]);
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::Indexed);
    let mut decoder = options
        .read_info(std::fs::File::open(&out).unwrap())
        .unwrap();
    // Encoders pad the palette to a power of two.
    let palette = decoder.global_palette().unwrap().to_vec();
    // Black, then eight shades each of the red lines' colour (170, 20, 20)
    // and the gray lines' (150, 150, 150), from dark to full.
    let mut ours = vec![[0u8, 0, 0]];
    for rgb in [[170u16, 20, 20], [150, 150, 150]] {
        ours.extend((1..=8u16).map(|k| rgb.map(|c| (c * k / 8) as u8)));
    }
    let ours: Vec<u8> = ours.into_iter().flatten().collect();
    assert_eq!(&palette[..ours.len()], &ours[..]);
    let mut frames = 0;
    let mut seen = std::collections::BTreeSet::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert_eq!((frame.width, frame.height), (236, 160));
        seen.extend(frame.buffer.iter().copied());
        frames += 1;
    }
    // Steps 0, 5, 10, 15 and 20 (the last).
    assert_eq!(frames, 5);
    assert!(
        seen.contains(&0)
            && seen.iter().any(|&i| (1..=8).contains(&i))
            && seen.iter().any(|&i| i > 8)
    );
}

#[test]
fn svg_has_one_line_per_segment_in_each_colour() {
    let dir = temp_dir("svg");
    let out = dir.join("cross.svg");
    screensaver(&[
        "0",
        scene(&dir).to_str().unwrap(),
        "--render",
        out.to_str().unwrap(),
    ]);
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert_eq!(svg.matches("<line ").count(), 2);
    assert!(
        svg.contains(r#"stroke="rgb(170,20,20)""#) && svg.contains(r#"stroke="rgb(150,150,150)""#)
    );
    assert!(
        svg.contains(r#"x1="100.00" y1="200.00" x2="1000.00" y2="200.00""#),
        "{svg}"
    );
}

#[test]
fn unknown_picture_types_are_refused() {
    let out = Command::new(env!("CARGO_BIN_EXE_screensaver"))
        .args(["0", "--render", "x.jpg"])
        .output()
        .unwrap();
    // A bad argument, as any other: status 2.
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("x.jpg: unknown picture type"));
    assert!(out.stdout.is_empty());
}

#[test]
fn a_picture_of_more_lines_than_strokes_pay_for_is_drawn_thin_where_they_are() {
    // The cross, and 100,000 still dots in a block at the lower left: more
    // lines than pictures stroke (`PICTURE_SMOOTH_UP_TO`).
    let dir = temp_dir("thin");
    let path = dir.join("many.in");
    let mut text =
        String::from("100002\n(100, 200), (1000, 200), 0, 0, 0\n(900, 300), (900, 700), 0, 0, 1\n");
    for k in 0..100_000 {
        let (x, y) = (100 + k % 400, 450 + k / 400);
        text.push_str(&format!("({x}, {y}), ({x}.5, {y}), 0, 0, {}\n", k % 2));
    }
    std::fs::write(&path, text).unwrap();
    let out = dir.join("many.png");
    screensaver(&[
        "0",
        path.to_str().unwrap(),
        "--render",
        out.to_str().unwrap(),
    ]);
    let p = Pixmap::load_png(&out).unwrap();
    assert_lines_drawn(&p, (500, 200), (900, 500));
    for (x, y) in [(5, 5), (1175, 795), (500, 400), (700, 600), (1100, 200)] {
        assert_eq!(rgb(&p, x, y), [0, 0, 0], "at {x}, {y}");
    }
    let p = &p;
    let block = (450..700).flat_map(|y| (100..500).map(move |x| rgb(p, x, y)));
    let (red, gray) = block.fold((0, 0), |(r, g), c| {
        (r + usize::from(is_red(c)), g + usize::from(is_gray(c)))
    });
    assert!(
        red > 20_000 && gray > 20_000,
        "{red} red and {gray} gray in the block"
    );
}
