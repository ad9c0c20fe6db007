//! The screensaver library for a JavaScript host, through WebAssembly: one
//! world at a time, a C-style interface of numbers and byte buffers in the
//! module's memory (no bindings generator needed). `scripts/wasm.sh` builds
//! it; `scripts/wasm-conformance.mjs` runs the reference scenes through it
//! and the page in `web/` shows it.
//!
//! Texts go in through a buffer from [`ss_alloc`] and come out as a pointer
//! ([`ss_text_ptr`]) and a length ([`ss_text_len`]) valid until the next
//! call. Lines come out mapped to a picture's pixels ([`ss_points`]) and
//! are drawn as RGBA bytes ([`ss_draw`]), as a canvas's `ImageData` holds
//! them: the page steps in one instance (a worker) and draws in another.

use screensaver::generate::{generate, SceneKind};
use screensaver::render::{Canvas, Size, View};
use screensaver::run::Run;
use screensaver::{report, Color, DetectorConfig, DetectorKind, Scene, World};
use std::cell::RefCell;

thread_local! {
    static WORLD: RefCell<Option<World>> = const { RefCell::new(None) };
    static TEXT: RefCell<String> = const { RefCell::new(String::new()) };
    /// The name of the world's input, as the command line gives it.
    static INPUT: RefCell<String> = const { RefCell::new(String::new()) };
    static POINTS: RefCell<Vec<f32>> = const { RefCell::new(Vec::new()) };
    static PIXELS: RefCell<Vec<u32>> = const { RefCell::new(Vec::new()) };
}

fn set_text(text: String) {
    TEXT.with(|t| *t.borrow_mut() = text);
}

/// The detector numbered `code`: its place in [`DetectorKind::ALL`], the
/// one list of detectors (the page numbers them the same way); the default
/// for any other number.
fn detector(code: u32) -> DetectorKind {
    let all = DetectorKind::ALL;
    all.get(code as usize).copied().unwrap_or(DetectorKind::DEFAULT)
}

fn start(scene: &Scene, code: u32, input: String) -> i32 {
    let config = DetectorConfig {
        threads: 1,
        ..DetectorConfig::default()
    };
    match World::with_config(scene, detector(code), &config) {
        Ok(world) => {
            WORLD.with(|w| *w.borrow_mut() = Some(world));
            INPUT.with(|i| *i.borrow_mut() = input);
            0
        }
        Err(e) => {
            set_text(e.to_string());
            1
        }
    }
}

/// `len` bytes for the host to fill (for [`ss_load`]'s text).
#[no_mangle]
pub extern "C" fn ss_alloc(len: usize) -> *mut u8 {
    let mut buffer = vec![0u8; len].into_boxed_slice();
    let at = buffer.as_mut_ptr();
    std::mem::forget(buffer);
    at
}

/// Gives back a buffer from [`ss_alloc`].
///
/// # Safety
/// `at` and `len` must be a buffer [`ss_alloc`] gave, not yet freed.
#[no_mangle]
pub unsafe extern "C" fn ss_free(at: *mut u8, len: usize) {
    // SAFETY: the caller passes back a buffer of `len` bytes that
    // `ss_alloc` leaked from a boxed slice of that length.
    drop(unsafe { Box::from_raw(std::ptr::slice_from_raw_parts_mut(at, len)) });
}

/// Starts a world from the scene text in `text[..len]` (named `name` in
/// errors) with detector `code` (its place in `DetectorKind::ALL`: 0 all
/// pairs, 1 quadtree, 2 sweep). 0 on
/// success; otherwise the error message is the text.
///
/// # Safety
/// `text` and `name` must point to `len` and `name_len` readable bytes.
#[no_mangle]
pub unsafe extern "C" fn ss_load(
    text: *const u8,
    len: usize,
    name: *const u8,
    name_len: usize,
    code: u32,
) -> i32 {
    // SAFETY: the caller vouches for both buffers.
    let (text, name) = unsafe {
        (
            std::slice::from_raw_parts(text, len),
            std::slice::from_raw_parts(name, name_len),
        )
    };
    let name = String::from_utf8_lossy(name);
    match Scene::parse(text, &name) {
        Ok(scene) => start(&scene, code, name.into_owned()),
        Err(e) => {
            set_text(e.to_string());
            1
        }
    }
}

/// Starts a world from a generated scene, as `screensaver gen` makes it:
/// kind number `kind` of the names [`ss_kinds`] gives, `lines` lines, the
/// seed `seed_hi * 2^32 + seed_lo`.
#[no_mangle]
pub extern "C" fn ss_generate(kind: u32, lines: u32, seed_lo: u32, seed_hi: u32, code: u32) -> i32 {
    let kind = SceneKind::ALL[kind as usize % SceneKind::ALL.len()];
    let seed = u64::from(seed_hi) << 32 | u64::from(seed_lo);
    let lines = lines as usize;
    let name = report::input_name(Some((kind, lines, seed)));
    start(&generate(kind, lines, seed), code, name)
}

/// Starts a world from the built-in scene.
#[no_mangle]
pub extern "C" fn ss_built_in(code: u32) -> i32 {
    start(&Scene::built_in(), code, report::input_name(None))
}

/// Makes the text the names of the generated scenes' kinds, in
/// [`ss_generate`]'s order, separated by commas.
#[no_mangle]
pub extern "C" fn ss_kinds() {
    let names: Vec<&str> = SceneKind::ALL.iter().map(|k| k.name()).collect();
    set_text(names.join(","));
}

/// Makes the text the names of the detectors, in the order their numbers
/// go (`DetectorKind::ALL`'s), separated by commas.
#[no_mangle]
pub extern "C" fn ss_detectors() {
    let names: Vec<&str> = DetectorKind::ALL.iter().map(|k| k.name()).collect();
    set_text(names.join(","));
}

fn with_world<R>(f: impl FnOnce(&mut World) -> R) -> Option<R> {
    WORLD.with(|w| w.borrow_mut().as_mut().map(f))
}

/// Runs `n` steps.
#[no_mangle]
pub extern "C" fn ss_step(n: u32) {
    with_world(|w| {
        Run::default()
            .run(w, u64::from(n))
            .expect("a run without pictures, checkpoints or checks cannot fail")
    });
}

/// Steps run so far.
#[no_mangle]
pub extern "C" fn ss_steps() -> f64 {
    with_world(|w| w.steps() as f64).unwrap_or(0.0)
}

/// The line-wall counter.
#[no_mangle]
pub extern "C" fn ss_wall() -> f64 {
    with_world(|w| w.counters().wall as f64).unwrap_or(0.0)
}

/// The line-line counter.
#[no_mangle]
pub extern "C" fn ss_line() -> f64 {
    with_world(|w| w.counters().line as f64).unwrap_or(0.0)
}

/// Makes the text the whole state in the reference's state format.
#[no_mangle]
pub extern "C" fn ss_state() {
    let state = with_world(|w| {
        let mut out = Vec::new();
        screensaver::checkpoint::write_state(w, &mut out).expect("writes to memory");
        String::from_utf8(out).expect("the state is text")
    });
    set_text(state.unwrap_or_default());
}

/// Where the text is.
#[no_mangle]
pub extern "C" fn ss_text_ptr() -> *const u8 {
    TEXT.with(|t| t.borrow().as_ptr())
}

/// The text's length in bytes.
#[no_mangle]
pub extern "C" fn ss_text_len() -> usize {
    TEXT.with(|t| t.borrow().len())
}

/// The number of lines.
#[no_mangle]
pub extern "C" fn ss_lines() -> u32 {
    with_world(|w| w.lines().len() as u32).unwrap_or(0)
}

/// 1 when nothing more can happen: every line is NaN or none moves.
#[no_mangle]
pub extern "C" fn ss_died_out() -> u32 {
    with_world(|w| u32::from(w.died_out())).unwrap_or(1)
}

/// Makes the text what the command line prints for the run: its header
/// (`frames` asked for, negative for an endless run) and its results
/// block, with `seconds` of simulation.
#[no_mangle]
pub extern "C" fn ss_report(frames: f64, seconds: f64) {
    let frames = (frames >= 0.0).then_some(frames as u64);
    let counters = with_world(|w| w.counters()).unwrap_or_default();
    let input = INPUT.with(|i| i.borrow().clone());
    set_text(report::header(frames, &input) + &report::results(seconds, counters));
}

/// Draws lines over black into a picture of `width` x `height` pixels
/// with the project's own rasteriser (anti-aliased lines a pixel wide):
/// `len` numbers at `points`, five a line as [`ss_points`] gives them, so
/// that one instance of the module can draw what another stepped. Gives
/// where the picture's RGBA bytes start (valid until the next call).
///
/// # Safety
/// `points` must point to `len` readable `f32`s.
#[no_mangle]
pub unsafe extern "C" fn ss_draw(
    points: *const f32,
    len: usize,
    width: u32,
    height: u32,
) -> *const u8 {
    // SAFETY: the caller vouches for the buffer.
    let points = unsafe { std::slice::from_raw_parts(points, len) };
    let (w, h) = (width as usize, height as usize);
    let (red, gray) = (Color::Red.rgb(), Color::Gray.rgb());
    PIXELS.with(|p| {
        let mut pixels = p.borrow_mut();
        pixels.resize(w * h, 0);
        let mut canvas = Canvas::new(&mut pixels, w, h);
        canvas.fill(0);
        for line in points.chunks_exact(5) {
            let (a, b) = (
                (line[0].into(), line[1].into()),
                (line[2].into(), line[3].into()),
            );
            canvas.draw_segment(a, b, if line[4] == 0.0 { red } else { gray });
        }
        // 0x00RRGGBB to the bytes R, G, B, 255 (a little-endian word).
        for p in pixels.iter_mut() {
            *p = 0xff00_0000 | (*p & 0xff) << 16 | (*p & 0xff00) | (*p >> 16 & 0xff);
        }
        pixels.as_ptr().cast()
    })
}

/// The lines' ends in a picture of `width` x `height` pixels, the box
/// stretched over it, for the host to draw: five numbers a line (x and y
/// of each end, then 0 for red or 1 for gray), in the order the world
/// stores them (nearby lines together, which draws faster), lines that are
/// not finite left out. Gives where they start; [`ss_points_len`] says how
/// many numbers there are (valid until the next call).
#[no_mangle]
pub extern "C" fn ss_points(width: u32, height: u32) -> *const f32 {
    let view = View::filling(Size { width, height });
    POINTS.with(|p| {
        let mut points = p.borrow_mut();
        points.clear();
        with_world(|world| {
            for (line, color) in world.lines_as_stored() {
                let (a, b) = (
                    view.point(line.p1.x, line.p1.y),
                    view.point(line.p2.x, line.p2.y),
                );
                if [a.0, a.1, b.0, b.1].iter().all(|v| v.is_finite()) {
                    let gray = f32::from(u8::from(color == Color::Gray));
                    points.extend([a.0 as f32, a.1 as f32, b.0 as f32, b.1 as f32, gray]);
                }
            }
        });
        points.as_ptr()
    })
}

/// How many numbers [`ss_points`] gave.
#[no_mangle]
pub extern "C" fn ss_points_len() -> usize {
    POINTS.with(|p| p.borrow().len())
}

/// Candidate pairs the detector has handed to the exact test so far (as
/// `--stats` counts them): the same on every platform where the hulls are.
#[no_mangle]
pub extern "C" fn ss_candidates() -> f64 {
    with_world(|w| w.detector_stats().candidate_pairs as f64).unwrap_or(0.0)
}
