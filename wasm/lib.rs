//! The screensaver library for a JavaScript host, through WebAssembly: one
//! world at a time, a C-style interface of numbers and byte buffers in the
//! module's memory (no bindings generator needed). `scripts/wasm.sh` builds
//! it; `scripts/wasm-conformance.mjs` runs the reference scenes through it.
//!
//! Texts go in through a buffer from [`ss_alloc`] and come out as a pointer
//! ([`ss_text_ptr`]) and a length ([`ss_text_len`]) valid until the next
//! call.

use screensaver::generate::{generate, SceneKind};
use screensaver::{DetectorConfig, DetectorKind, Scene, World};
use std::cell::RefCell;

thread_local! {
    static WORLD: RefCell<Option<World>> = const { RefCell::new(None) };
    static TEXT: RefCell<String> = const { RefCell::new(String::new()) };
}

fn set_text(text: String) {
    TEXT.with(|t| *t.borrow_mut() = text);
}

fn detector(code: u32) -> DetectorKind {
    match code {
        0 => DetectorKind::Sweep,
        1 => DetectorKind::Quadtree,
        _ => DetectorKind::Brute,
    }
}

fn start(scene: &Scene, code: u32) -> i32 {
    let config = DetectorConfig {
        threads: 1,
        ..DetectorConfig::default()
    };
    match World::with_config(scene, detector(code), &config) {
        Ok(world) => {
            WORLD.with(|w| *w.borrow_mut() = Some(world));
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
/// errors) with detector `code` (0 sweep, 1 quadtree, 2 all pairs). 0 on
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
        Ok(scene) => start(&scene, code),
        Err(e) => {
            set_text(e.to_string());
            1
        }
    }
}

/// Starts a world from a generated scene (kind 0 uniform, 1 clustered,
/// 2 ring, 3 grid), as `screensaver gen` makes it.
#[no_mangle]
pub extern "C" fn ss_generate(kind: u32, lines: u32, seed: f64, code: u32) -> i32 {
    let kind = SceneKind::ALL[kind as usize % SceneKind::ALL.len()];
    start(&generate(kind, lines as usize, seed as u64), code)
}

fn with_world<R>(f: impl FnOnce(&mut World) -> R) -> Option<R> {
    WORLD.with(|w| w.borrow_mut().as_mut().map(f))
}

/// Runs `n` steps.
#[no_mangle]
pub extern "C" fn ss_step(n: u32) {
    with_world(|w| w.run(u64::from(n)));
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
    let state = with_world(|w| w.state_text()).unwrap_or_default();
    set_text(state);
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
