//! Drawing into a window another program owns: the one XScreenSaver hands
//! its display hacks (named by the environment variable
//! `XSCREENSAVER_WINDOW`), the root window (`--root`), or any window by id
//! (`--window-id`). The window is not replaced or covered: each frame is
//! put into it as an image (x11rb, the X protocol in Rust, no C library),
//! the picture stretched over the whole window, and it follows the
//! window's size as it changes. The run ends when the window goes away,
//! on SIGINT, SIGTERM or SIGHUP (the daemon ends hacks with SIGTERM), or after the
//! frames asked for.

use super::live::{FrameClock, Outcome, Scenes, Simulation};
use super::raster::{Canvas, Painter};
use super::screen::{ScreenError, ShowOptions};
use super::{hud, Size, View};
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};
use x11rb::connection::Connection;
use x11rb::protocol::xproto::{
    ChangeWindowAttributesAux, ConnectionExt as _, CreateGCAux, EventMask, ImageFormat, ImageOrder,
    VisualClass,
};
use x11rb::protocol::Event;

/// The variable through which XScreenSaver names the window to draw in.
pub(crate) const SCREENSAVER_WINDOW: &str = "XSCREENSAVER_WINDOW";

/// Which window to draw in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// The screen's root window.
    Root,
    /// A window by its X id.
    Id(u32),
}

/// Reads a window id written as XScreenSaver and `xwininfo` write them:
/// hexadecimal after `0x`, else decimal.
pub(super) fn parse_window_id(s: &str) -> Result<u32, ScreenError> {
    let t = s.trim();
    let parsed = match t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        Some(hex) => u32::from_str_radix(hex, 16),
        None => t.parse::<u32>(),
    };
    match parsed {
        Ok(0) | Err(_) => Err(ScreenError::BadWindowId {
            text: s.to_string(),
            variable: None,
        }),
        Ok(id) => Ok(id),
    }
}

/// The window XScreenSaver names in the environment, if any.
pub(super) fn screensaver_window() -> Option<Result<u32, ScreenError>> {
    let value = std::env::var(SCREENSAVER_WINDOW).ok()?;
    Some(
        parse_window_id(&value).map_err(|_| ScreenError::BadWindowId {
            text: value,
            variable: Some(SCREENSAVER_WINDOW),
        }),
    )
}

/// A connection to the display and the window to draw in, checked.
struct Opened {
    conn: x11rb::rust_connection::RustConnection,
    window: u32,
    geometry: x11rb::protocol::xproto::GetGeometryReply,
}

/// Connects to the display and checks the window `target` names: that it
/// exists and that its pixels are 24-bit true colour.
fn open(target: Target) -> Result<Opened, ScreenError> {
    super::window::display_named()?;
    let (conn, screen_number) = x11rb::connect(None)
        .map_err(|e| ScreenError::Failed(format!("cannot reach the X display: {e}")))?;
    let screen = &conn.setup().roots[screen_number];
    let window = match target {
        Target::Root => screen.root,
        Target::Id(id) => id,
    };
    let failed =
        |e: &dyn std::fmt::Display| ScreenError::Failed(format!("window 0x{window:x}: {e}"));
    let geometry = conn
        .get_geometry(window)
        .map_err(|e| failed(&e))?
        .reply()
        .map_err(|_| ScreenError::NoWindow(window))?;
    let attributes = conn
        .get_window_attributes(window)
        .map_err(|e| failed(&e))?
        .reply()
        .map_err(|e| failed(&e))?;
    let depth = geometry.depth;
    let true_colour = screen
        .allowed_depths
        .iter()
        .filter(|d| d.depth == depth)
        .flat_map(|d| &d.visuals)
        .any(|v| {
            v.visual_id == attributes.visual
                && v.class == VisualClass::TRUE_COLOR
                && (v.red_mask, v.green_mask, v.blue_mask) == (0xff_0000, 0xff00, 0xff)
        });
    let four_bytes = conn
        .setup()
        .pixmap_formats
        .iter()
        .any(|f| f.depth == depth && f.bits_per_pixel == 32);
    if !(true_colour && four_bytes && (depth == 24 || depth == 32)) {
        return Err(ScreenError::NotTrueColour { window, depth });
    }
    Ok(Opened {
        conn,
        window,
        geometry,
    })
}

/// Checks, before a run starts, that it can draw into the window `target`
/// names: the display answers, the window exists and takes 24-bit true
/// colour.
pub(super) fn check(target: Target) -> Result<(), ScreenError> {
    open(target).map(|opened| super::window::keep_open(opened.conn))
}

/// Runs `scenes` drawn into the window `target` until the run ends, the
/// window goes away or a signal stops it. Fails with a message when there
/// is no display, no such window, or a window whose pixels are not 24-bit
/// true colour.
pub(super) fn run(
    target: Target,
    scenes: Scenes,
    options: ShowOptions,
) -> Result<Outcome, ScreenError> {
    let Opened {
        conn,
        window,
        geometry,
    } = open(target)?;
    let failed =
        |e: &dyn std::fmt::Display| ScreenError::Failed(format!("window 0x{window:x}: {e}"));
    let depth = geometry.depth;
    let msb_first = conn.setup().image_byte_order == ImageOrder::MSB_FIRST;
    conn.change_window_attributes(
        window,
        &ChangeWindowAttributesAux::new()
            .event_mask(EventMask::STRUCTURE_NOTIFY | EventMask::EXPOSURE),
    )
    .map_err(|e| failed(&e))?;
    let gc = conn.generate_id().map_err(|e| failed(&e))?;
    conn.create_gc(gc, window, &CreateGCAux::new().graphics_exposures(0))
        .map_err(|e| failed(&e))?;
    conn.flush().map_err(|e| failed(&e))?;

    let mut size = (geometry.width, geometry.height);
    let run = Simulation::start(scenes, options.pace);
    let period = Duration::from_secs_f64(1.0 / f64::from(options.fps.max(1)));
    let mut painter = Painter::new();
    let mut pixels: Vec<u32> = Vec::new();
    let mut bytes: Vec<u8> = Vec::new();
    let mut clock = FrameClock::default();
    let mut state = None;
    let mut stale = true;
    let mut error = None;
    let mut next_frame = Instant::now();
    'frames: loop {
        loop {
            match conn.poll_for_event() {
                Ok(Some(Event::ConfigureNotify(e))) if e.window == window => {
                    if (e.width, e.height) != size {
                        size = (e.width, e.height);
                        stale = true;
                    }
                }
                Ok(Some(Event::Expose(_))) => stale = true,
                Ok(Some(Event::DestroyNotify(e))) if e.window == window => break 'frames,
                Ok(Some(_)) => {}
                Ok(None) => break,
                Err(e) => {
                    error = Some(failed(&e));
                    break 'frames;
                }
            }
        }
        if crate::stop::requested().is_some() {
            break;
        }
        let finished = run.shared.finished.load(Ordering::Acquire);
        if let Some(snapshot) = run.shared.take() {
            if let Some(old) = state.replace(snapshot) {
                run.shared.recycle(old);
            }
            stale = true;
        }
        if stale {
            if let Some(snapshot) = &state {
                let started = Instant::now();
                let (w, h) = (usize::from(size.0), usize::from(size.1));
                pixels.resize(w * h, 0);
                let view = View::filling(Size {
                    width: u32::from(size.0),
                    height: u32::from(size.1),
                });
                let mut canvas = Canvas::new(&mut pixels, w, h);
                painter.paint(&snapshot.lines, &snapshot.colors, &view, &mut canvas);
                if options.hud {
                    let text = hud::lines(snapshot, clock.recent_fps(), options.pace);
                    hud::draw(&mut canvas, &text);
                }
                let alpha = if depth == 32 { 0xff00_0000 } else { 0 };
                bytes.clear();
                bytes.extend(pixels.iter().flat_map(|&p| {
                    let p = p | alpha;
                    if msb_first {
                        p.to_be_bytes()
                    } else {
                        p.to_le_bytes()
                    }
                }));
                if let Err(e) = put_image(&conn, window, gc, size, depth, &bytes) {
                    error = Some(failed(&e));
                    break;
                }
                clock.drawn(started);
                stale = false;
            }
        }
        if finished && !run.shared.has_news() {
            break;
        }
        next_frame = (next_frame + period).max(Instant::now());
        std::thread::sleep(next_frame - Instant::now());
    }
    let outcome = run.finish()?;
    match error {
        Some(e) => Err(e),
        None => Ok(Outcome {
            drawn: clock.stats(),
            ..outcome
        }),
    }
}

/// Puts a frame of `size` (its pixels as bytes, four a pixel) into
/// `window`, in as many strips of rows as the server's request size needs.
fn put_image(
    conn: &impl Connection,
    window: u32,
    gc: u32,
    size: (u16, u16),
    depth: u8,
    bytes: &[u8],
) -> Result<(), x11rb::errors::ConnectionError> {
    let (w, h) = (usize::from(size.0), usize::from(size.1));
    if w == 0 || h == 0 {
        return Ok(());
    }
    let row = 4 * w;
    // The request's own header takes 24 bytes; leave room.
    let rows_per_strip = ((conn.maximum_request_bytes() - 64) / row).max(1);
    for (k, strip) in bytes[..row * h].chunks(row * rows_per_strip).enumerate() {
        let rows = (strip.len() / row) as u16;
        let y = (k * rows_per_strip) as i16;
        conn.put_image(
            ImageFormat::Z_PIXMAP,
            window,
            gc,
            size.0,
            rows,
            0,
            y,
            0,
            depth,
            strip,
        )?;
    }
    conn.flush()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_ids_read_as_hex_or_decimal() {
        assert_eq!(parse_window_id("0x1a00003"), Ok(0x1a0_0003));
        assert_eq!(parse_window_id("0X2A"), Ok(42));
        assert_eq!(parse_window_id(" 27262979 "), Ok(27_262_979));
        assert!(parse_window_id("0").is_err());
        assert!(parse_window_id("0xzz").is_err());
        let message = parse_window_id("root").unwrap_err().to_string();
        assert!(message.contains("`root`"), "{message}");
    }
}
