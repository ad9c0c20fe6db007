//! The heads-up display: a few lines of text in the window's top left
//! corner (step, both counters, steps and frames per second), white on a
//! dark panel so that it reads on any picture behind it. Glyphs are the
//! public-domain 8x8 font of the `font8x8` crate.

use super::live::{Pace, Snapshot};
use super::raster::Canvas;
use font8x8::legacy::BASIC_LEGACY;

/// Text colour.
const INK: u32 = 0x00ff_ffff;
/// Pixels of margin around the text, in glyph pixels.
const MARGIN: usize = 4;
/// Rows between lines of text, in glyph pixels.
const LINE_GAP: usize = 3;

/// The display's lines for a state of the run, the frames drawn per
/// second and the pace set.
pub fn lines(snapshot: &Snapshot, fps: f64, pace: Pace) -> Vec<String> {
    let mut lines = vec![
        format!("step {}", snapshot.step),
        format!("{} line-wall", snapshot.wall),
        format!("{} line-line", snapshot.line),
        match snapshot.paused {
            true => format!("paused  {fps:.0} fps"),
            false => format!("{:.0} steps/s  {fps:.0} fps", snapshot.rate),
        },
        format!("pace: {pace}"),
    ];
    if snapshot.scene > 0 {
        lines.push(format!("scene {}", snapshot.scene + 1));
    }
    lines
}

/// Draws `text` in the canvas's top left corner over a darkened panel,
/// each glyph pixel `scale` pixels wide (1 on screens under 1200 pixels
/// high, more on larger ones).
pub fn draw(canvas: &mut Canvas, text: &[String]) {
    let scale = (canvas.height() / 1200 + 1).max(1);
    let columns = text.iter().map(|l| l.chars().count()).max().unwrap_or(0);
    let width = (columns * 8 + 2 * MARGIN) * scale;
    let height = (text.len() * (8 + LINE_GAP) - LINE_GAP + 2 * MARGIN) * scale;
    // The panel: the picture behind dimmed to a quarter.
    for y in 0..height.min(canvas.height()) {
        for x in 0..width.min(canvas.width()) {
            canvas.blend(x as isize, y as isize, 0, 192);
        }
    }
    for (row, line) in text.iter().enumerate() {
        let top = (MARGIN + row * (8 + LINE_GAP)) * scale;
        for (column, c) in line.chars().enumerate() {
            let glyph = BASIC_LEGACY
                .get(c as usize)
                .copied()
                .unwrap_or(BASIC_LEGACY[b'?' as usize]);
            let left = (MARGIN + column * 8) * scale;
            for (gy, bits) in glyph.iter().enumerate() {
                for gx in 0..8 {
                    // Bit 0 is the glyph's leftmost pixel.
                    if bits >> gx & 1 == 1 {
                        for (dy, dx) in (0..scale).flat_map(|dy| (0..scale).map(move |dx| (dy, dx)))
                        {
                            let (x, y) = (left + gx * scale + dx, top + gy * scale + dy);
                            canvas.blend(x as isize, y as isize, INK, 256);
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_display_shows_the_counts_and_rates() {
        let snapshot = Snapshot {
            lines: Vec::new(),
            colors: Vec::new(),
            step: 120,
            wall: 7,
            line: 33,
            rate: 4000.4,
            paused: false,
            scene: 0,
        };
        let text = lines(&snapshot, 59.6, Pace::PerFrame);
        assert_eq!(
            text,
            [
                "step 120",
                "7 line-wall",
                "33 line-line",
                "4000 steps/s  60 fps",
                "pace: 1 step/frame"
            ]
        );
        assert_eq!(
            lines(&snapshot, 59.6, Pace::Rate(500))[4],
            "pace: 500 steps/s max"
        );
        // Paused, no rate: the run is not stepping.
        let paused = Snapshot {
            paused: true,
            ..snapshot
        };
        assert_eq!(lines(&paused, 59.6, Pace::PerFrame)[3], "paused  60 fps");
    }

    #[test]
    fn text_is_white_on_a_dimmed_panel() {
        let (w, h) = (200, 100);
        let mut pixels = vec![0x0080_8080; w * h];
        let mut canvas = Canvas::new(&mut pixels, w, h);
        draw(&mut canvas, &["1".to_string()]);
        let ink = pixels.iter().filter(|&&p| p == INK).count();
        assert!(ink > 5, "{ink} pixels of ink");
        // Inside the panel but off the glyph: dimmed.
        assert_eq!(pixels[0], 0x0020_2020);
        // Outside the panel: untouched.
        assert_eq!(pixels[w * h - 1], 0x0080_8080);
    }
}
