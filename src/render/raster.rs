//! Drawing into a frame buffer of `0x00RRGGBB` pixels, as windows take
//! them: tiny-skia's anti-aliased strokes for scenes small enough to draw
//! that way at the display's pace, and for larger ones a line rasteriser
//! of its own (anti-aliased lines one pixel wide, Xiaolin Wu's method),
//! far cheaper a line (docs/PERFORMANCE.md, "Drawing live", measured by
//! `examples/draw_speed.rs`).

// The window's passes (`Painter`, `draw_thin`) go unused in a build
// without it.
#![cfg_attr(not(feature = "window"), allow(dead_code))]

use super::{draw_in_view, View, GRAY, RED};
use crate::line::{Color, Line};
use tiny_skia::Pixmap;

/// Scenes of up to this many lines are drawn with tiny-skia's strokes (1.5
/// pixels wide, round caps, as in pictures); larger ones with
/// [`draw_thin`]: tiny-skia's time grows with the lines, and past this
/// many a frame takes longer than a display can wait for
/// (docs/PERFORMANCE.md, "Drawing live").
pub const SMOOTH_UP_TO: usize = 5_000;

/// Pictures (`--render`) of up to this many lines are stroked by tiny-skia;
/// larger ones are drawn with [`draw_thin`], as the window draws them.
/// Strokes cost about 6 us a line (a picture of 100,000 lines 0.6 s, of a
/// million 4.2 s and 940 MB); thin lines a few dozen nanoseconds
/// (docs/PERFORMANCE.md, "Reading and writing files").
pub const PICTURE_SMOOTH_UP_TO: usize = 100_000;

/// A frame buffer: `height` rows of `width` pixels, each `0x00RRGGBB`.
///
/// ```
/// use screensaver::render::{Canvas, Size, View};
///
/// let mut pixels = vec![0u32; 118 * 80];
/// let mut canvas = Canvas::new(&mut pixels, 118, 80);
/// let view = View::new(Size { width: 118, height: 80 });
/// // A line across the box's middle, in box units.
/// canvas.draw_segment(view.point(0.6, 0.75), view.point(0.9, 0.75), 0xaa1414);
/// assert!(pixels.iter().filter(|&&p| p != 0).count() > 20);
/// ```
pub struct Canvas<'a> {
    pixels: &'a mut [u32],
    width: usize,
    height: usize,
}

impl<'a> Canvas<'a> {
    /// The canvas over `pixels`, which holds `width * height` pixels.
    ///
    /// # Panics
    /// If `pixels` is shorter than that.
    pub fn new(pixels: &'a mut [u32], width: usize, height: usize) -> Self {
        assert!(pixels.len() >= width * height, "the buffer is too small");
        Canvas {
            pixels,
            width,
            height,
        }
    }

    /// Width in pixels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The pixels, row by row.
    pub fn pixels(&self) -> &[u32] {
        &self.pixels[..self.width * self.height]
    }

    /// Paints every pixel `rgb`.
    pub fn fill(&mut self, rgb: u32) {
        self.pixels[..self.width * self.height].fill(rgb);
    }

    /// Blends `rgb` over the pixel at `(x, y)` with `coverage` (0 to 256);
    /// nothing outside the canvas.
    #[inline(always)]
    pub fn blend(&mut self, x: isize, y: isize, rgb: u32, coverage: u32) {
        if x < 0 || y < 0 || x as usize >= self.width || y as usize >= self.height {
            return;
        }
        let p = &mut self.pixels[y as usize * self.width + x as usize];
        *p = mix(*p, rgb, coverage);
    }
}

/// `over` laid over `under` with `coverage` out of 256, channel by channel.
#[inline(always)]
fn mix(under: u32, over: u32, coverage: u32) -> u32 {
    let mut out = 0;
    for shift in [0, 8, 16] {
        let (u, o) = ((under >> shift) & 0xff, (over >> shift) & 0xff);
        let c = (u * (256 - coverage) + o * coverage) >> 8;
        out |= c << shift;
    }
    out
}

/// A colour as a `0x00RRGGBB` pixel.
pub fn pixel(rgb: [u8; 3]) -> u32 {
    (u32::from(rgb[0]) << 16) | (u32::from(rgb[1]) << 8) | u32::from(rgb[2])
}

/// Draws the scene into a canvas, keeping what it needs between frames.
#[derive(Default)]
pub struct Painter {
    /// tiny-skia's canvas, for small scenes.
    pixmap: Option<Pixmap>,
}

impl Painter {
    /// A painter with nothing kept yet.
    pub fn new() -> Self {
        Self::default()
    }

    /// Draws `lines` (coloured by `colors`) over black into `canvas` as
    /// `view` maps them: with tiny-skia for up to [`SMOOTH_UP_TO`] lines,
    /// else with [`draw_thin`].
    pub fn paint(&mut self, lines: &[Line], colors: &[Color], view: &View, canvas: &mut Canvas) {
        if lines.len() > SMOOTH_UP_TO {
            return draw_thin(lines, colors, view, canvas);
        }
        let (w, h) = (canvas.width as u32, canvas.height as u32);
        let fits = self
            .pixmap
            .as_ref()
            .is_some_and(|p| p.width() == w && p.height() == h);
        if !fits {
            self.pixmap = Pixmap::new(w, h);
        }
        let Some(pixmap) = &mut self.pixmap else {
            // An empty canvas: nothing to draw.
            return;
        };
        draw_in_view(lines, colors, pixmap, view);
        for (out, p) in canvas.pixels.iter_mut().zip(pixmap.pixels()) {
            *out = pixel([p.red(), p.green(), p.blue()]);
        }
    }
}

/// Draws `lines` over black into `canvas`, one pixel wide and
/// anti-aliased, in one pass in the order given (so where lines cross, the
/// later one shows); a line shorter than a pixel both ways is a dot, the
/// pixel under its middle. Lines whose coordinates are not finite are
/// skipped.
pub fn draw_thin(lines: &[Line], colors: &[Color], view: &View, canvas: &mut Canvas) {
    draw_thin_each(lines.iter().zip(colors.iter().copied()), view, canvas);
}

/// [`draw_thin`] of lines given with their colours, in any order: for
/// [`World::lines_as_stored`](crate::World::lines_as_stored), whose order
/// keeps nearby lines together and so draws a large scene row by row,
/// faster than in id order (docs/PERFORMANCE.md, "Drawing live").
pub fn draw_thin_each<'a>(
    lines: impl IntoIterator<Item = (&'a Line, Color)>,
    view: &View,
    canvas: &mut Canvas,
) {
    canvas.fill(0);
    let (red, gray) = (pixel(RED), pixel(GRAY));
    // Pixel centres lie at whole numbers here, at halves in the view.
    let ((ax, bx), (ay, by)) = view.affine();
    let (bx, by) = (bx - 0.5, by - 0.5);
    for (line, color) in lines {
        let rgb = if color == Color::Red { red } else { gray };
        let a = (ax * line.p1.x + bx, ay * line.p1.y + by);
        let b = (ax * line.p2.x + bx, ay * line.p2.y + by);
        segment(canvas, a, b, rgb);
    }
}

impl Canvas<'_> {
    /// Draws one line as the window draws large scenes, from `a` to `b` in
    /// the frame's pixels as [`View::point`] gives them, in colour `rgb`,
    /// over what the canvas holds: for hosts that map the lines themselves
    /// (the web page draws lines another thread stepped).
    pub fn draw_segment(&mut self, a: (f64, f64), b: (f64, f64), rgb: u32) {
        segment(self, (a.0 - 0.5, a.1 - 0.5), (b.0 - 0.5, b.1 - 0.5), rgb);
    }
}

/// One line from `a` to `b`, pixel centres at whole numbers: a dot if it is
/// shorter than a pixel both ways, nothing if it is far away, infinite or
/// NaN.
#[inline]
fn segment(canvas: &mut Canvas, (x1, y1): (f64, f64), (x2, y2): (f64, f64), rgb: u32) {
    if !(x1.abs() < 1e7 && y1.abs() < 1e7 && x2.abs() < 1e7 && y2.abs() < 1e7) {
        return;
    }
    if (x2 - x1).abs() < 1.0 && (y2 - y1).abs() < 1.0 {
        let (x, y) = ((x1 + x2) * 0.5, (y1 + y2) * 0.5);
        canvas.blend(
            x.round_ties_even() as isize,
            y.round_ties_even() as isize,
            rgb,
            256,
        );
    } else {
        wu_line(canvas, (x1, y1), (x2, y2), rgb);
    }
}

/// One anti-aliased line from `a` to `b` (pixel coordinates, pixel centres
/// at whole numbers): along its longer direction one step a pixel, each
/// step shared between the two pixels across it by how near their centres
/// lie. Only the part within the canvas is walked.
fn wu_line(canvas: &mut Canvas, a: (f64, f64), b: (f64, f64), rgb: u32) {
    let steep = (b.1 - a.1).abs() > (b.0 - a.0).abs();
    // Walk along `major`; `minor` follows.
    let (mut a, mut b) = if steep {
        ((a.1, a.0), (b.1, b.0))
    } else {
        (a, b)
    };
    if a.0 > b.0 {
        std::mem::swap(&mut a, &mut b);
    }
    let (major_len, minor_len) = if steep {
        (canvas.height, canvas.width)
    } else {
        (canvas.width, canvas.height)
    };
    let dx = b.0 - a.0;
    let gradient = if dx > 0.0 { (b.1 - a.1) / dx } else { 0.0 };
    let first = a.0.round_ties_even().max(0.0);
    let last = b.0.round_ties_even().min(major_len as f64 - 1.0);
    if first > last {
        return;
    }
    let mut minor = a.1 + gradient * (first - a.0);
    let minor_limit = minor_len as f64 + 1.0;
    for major in first as isize..=last as isize {
        if minor > -2.0 && minor < minor_limit {
            let below = minor.floor();
            let near = ((minor - below) * 256.0) as u32;
            let m = below as isize;
            if steep {
                canvas.blend(m, major, rgb, 256 - near);
                canvas.blend(m + 1, major, rgb, near);
            } else {
                canvas.blend(major, m, rgb, 256 - near);
                canvas.blend(major, m + 1, rgb, near);
            }
        }
        minor += gradient;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::Size;
    use crate::test_util::line;

    fn canvas_of(pixels: &mut [u32]) -> Canvas<'_> {
        Canvas::new(pixels, 118, 80)
    }

    #[test]
    fn a_level_line_lights_the_row_it_lies_on() {
        let mut pixels = vec![0; 118 * 80];
        let mut canvas = canvas_of(&mut pixels);
        wu_line(&mut canvas, (10.0, 20.0), (50.0, 20.0), 0x00ff_ffff);
        for x in 10..=50 {
            assert_eq!(pixels[20 * 118 + x], 0x00ff_ffff, "x = {x}");
            assert_eq!(pixels[21 * 118 + x], 0, "x = {x}");
        }
        assert_eq!(pixels[20 * 118 + 9], 0);
        assert_eq!(pixels[20 * 118 + 51], 0);
    }

    #[test]
    fn a_line_between_rows_is_shared_between_them() {
        let mut pixels = vec![0; 118 * 80];
        let mut canvas = canvas_of(&mut pixels);
        wu_line(&mut canvas, (30.0, 10.0), (30.0, 40.0), 0x00ff_ffff);
        wu_line(&mut canvas, (60.0, 10.5), (90.0, 10.5), 0x00ff_ffff);
        assert_eq!(pixels[25 * 118 + 30], 0x00ff_ffff);
        // Half on row 10, half on row 11.
        assert_eq!(pixels[10 * 118 + 70], 0x007f_7f7f);
        assert_eq!(pixels[11 * 118 + 70], 0x007f_7f7f);
    }

    #[test]
    fn lines_reaching_out_of_the_canvas_are_cut_at_its_edge() {
        let mut pixels = vec![0; 118 * 80];
        let mut canvas = canvas_of(&mut pixels);
        wu_line(
            &mut canvas,
            (-1e6, 40.0 - 1e4),
            (1e6, 40.0 + 1e4),
            0x00ff_ffff,
        );
        wu_line(&mut canvas, (-5.0, -5.0), (-1.0, -1.0), 0x00ff_ffff);
        wu_line(&mut canvas, (500.0, 500.0), (900.0, 300.0), 0x00ff_ffff);
        // Only the first line crosses the canvas: about one pixel a column.
        let lit = pixels.iter().filter(|&&p| p != 0).count();
        assert!((118..=2 * 118).contains(&lit), "{lit} pixels lit");
    }

    #[test]
    fn thin_drawing_shows_both_colours_and_skips_nan() {
        let lines = [
            // Along the centres of rows 16 and 48.
            line((0.6, 0.603125), (0.9, 0.603125), (0.0, 0.0)),
            line((0.6, 0.803125), (0.9, 0.803125), (0.0, 0.0)),
            line((f64::NAN, 0.8), (0.9, f64::NAN), (0.0, 0.0)),
        ];
        let colors = [Color::Red, Color::Gray, Color::Red];
        let mut pixels = vec![7; 118 * 80];
        let mut canvas = canvas_of(&mut pixels);
        let view = View::new(Size {
            width: 118,
            height: 80,
        });
        draw_thin(&lines, &colors, &view, &mut canvas);
        assert!(pixels.contains(&pixel(RED)));
        assert!(pixels.contains(&pixel(GRAY)));
        assert!(!pixels.contains(&7), "the canvas is cleared first");
    }

    #[test]
    fn segments_mapped_by_the_view_draw_what_thin_drawing_draws() {
        let lines = [
            line((0.6, 0.61), (0.9, 0.77), (0.0, 0.0)),
            line((0.55, 0.9), (0.65, 0.6), (0.0, 0.0)),
            line((0.7, 0.7), (0.7001, 0.7001), (0.0, 0.0)),
        ];
        let colors = [Color::Red, Color::Gray, Color::Red];
        let view = View::filling(Size {
            width: 200,
            height: 90,
        });
        let mut thin = vec![0; 200 * 90];
        draw_thin(&lines, &colors, &view, &mut Canvas::new(&mut thin, 200, 90));
        let mut segments = vec![0; 200 * 90];
        let mut canvas = Canvas::new(&mut segments, 200, 90);
        for (l, c) in lines.iter().zip(colors) {
            let rgb = pixel(if c == Color::Red { RED } else { GRAY });
            canvas.draw_segment(view.point(l.p1.x, l.p1.y), view.point(l.p2.x, l.p2.y), rgb);
        }
        assert!(thin.iter().filter(|&&p| p != 0).count() > 100);
        // The view's affine map and `View::point` may round apart by an
        // ulp, which moves a blend weight by a step, or a line's end pixel
        // in or out: two pixels at most a line.
        let channel = |p: u32, k: u32| (p >> (8 * k) & 0xff) as i32;
        let apart = thin
            .iter()
            .zip(&segments)
            .filter(|(a, b)| (0..3).any(|k| (channel(**a, k) - channel(**b, k)).abs() > 2));
        assert!(apart.count() <= 2 * lines.len());
    }

    #[test]
    fn the_painter_draws_small_and_large_scenes_alike() {
        let view = View::new(Size {
            width: 118,
            height: 80,
        });
        // Along the centres of row 40.
        let one = [line((0.6, 0.753125), (0.9, 0.753125), (0.0, 0.0))];
        let many = vec![one[0]; SMOOTH_UP_TO + 1];
        let mut painter = Painter::new();
        for lines in [&one[..], &many[..]] {
            let colors = vec![Color::Gray; lines.len()];
            let mut pixels = vec![0; 118 * 80];
            painter.paint(lines, &colors, &view, &mut canvas_of(&mut pixels));
            // The middle of the line, lit with gray.
            assert_eq!(pixels[40 * 118 + 59], pixel(GRAY), "{} lines", lines.len());
        }
    }

    #[test]
    fn blending_covers_by_the_share_given() {
        assert_eq!(mix(0, 0x00ff_ffff, 256), 0x00ff_ffff);
        assert_eq!(mix(0x0012_3456, 0x00ff_ffff, 0), 0x0012_3456);
        assert_eq!(mix(0, 0x00ff_0000, 128), 0x007f_0000);
    }
}
