//! Pictures of the world: an anti-aliased rasteriser, and PNG, GIF and SVG
//! files; with the `window` feature, runs shown on screen ([`Screen`]).
//!
//! The picture is the original's: a black background, red lines in dark red
//! and gray lines in gray, the box `[0.5, 1] x [0.5, 1]` filling the frame
//! with `y` pointing down, as window coordinates do (so `mit.in` reads
//! "MIT"). Frames of any size keep the window's 1180:800
//! shape, centred, with black bars if the size has another shape.

#[cfg(feature = "window")]
mod embedded;
#[cfg(feature = "window")]
mod hud;
#[cfg(feature = "window")]
mod live;
pub(crate) mod raster;
#[cfg(feature = "window")]
mod screen;
#[cfg(feature = "window")]
mod window;

#[cfg(feature = "window")]
pub use live::{Outcome, Pace, Scenes};
pub use raster::Canvas;
#[cfg(feature = "window")]
pub use screen::{Screen, ScreenError, ShowOptions};

use crate::line::{Color, Line, BOX_MAX, BOX_MIN, WINDOW_HEIGHT, WINDOW_WIDTH};
use crate::World;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use tiny_skia::{LineCap, Paint, PathBuilder, Pixmap, Stroke, Transform};

/// How red lines are drawn (dark red, as in the original).
pub(crate) const RED: [u8; 3] = [170, 20, 20];

/// How gray lines are drawn.
pub(crate) const GRAY: [u8; 3] = [150, 150, 150];

impl Color {
    /// The colour lines of this colour are drawn in, as a [`Canvas`] pixel
    /// (`0x00RRGGBB`).
    pub fn rgb(self) -> u32 {
        raster::pixel(match self {
            Color::Red => RED,
            Color::Gray => GRAY,
        })
    }
}

/// A frame's size in pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Size {
    /// Width.
    pub width: u32,
    /// Height.
    pub height: u32,
}

impl Size {
    /// The original window's size, 1180 x 800.
    pub const WINDOW: Size = Size {
        width: WINDOW_WIDTH as u32,
        height: WINDOW_HEIGHT as u32,
    };
}

/// Maps box coordinates into a frame, `y` down: either the box filling the
/// largest centred rectangle of the window's shape ([`View::new`]), or
/// stretched over the whole frame ([`View::filling`], for screens).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    scale_x: f64,
    scale_y: f64,
    left: f64,
    top: f64,
}

impl View {
    /// The view of the box in a frame of `size`, keeping the window's
    /// 1180:800 shape (black bars fill the rest).
    pub fn new(size: Size) -> View {
        let (w, h) = (f64::from(size.width), f64::from(size.height));
        let scale = (w / WINDOW_WIDTH).min(h / WINDOW_HEIGHT);
        View {
            scale_x: scale,
            scale_y: scale,
            left: (w - WINDOW_WIDTH * scale) / 2.0,
            top: (h - WINDOW_HEIGHT * scale) / 2.0,
        }
    }

    /// The view of the box stretched over the whole frame of `size`: the
    /// box's width maps to the frame's width and its height to the
    /// frame's height, whatever their shape.
    pub fn filling(size: Size) -> View {
        View {
            scale_x: f64::from(size.width) / WINDOW_WIDTH,
            scale_y: f64::from(size.height) / WINDOW_HEIGHT,
            left: 0.0,
            top: 0.0,
        }
    }

    /// Where a box-coordinate point lands in the frame, in pixels.
    pub fn point(&self, x: f64, y: f64) -> (f64, f64) {
        let span = BOX_MAX - BOX_MIN;
        let px = self.left + (x - BOX_MIN) / span * WINDOW_WIDTH * self.scale_x;
        let py = self.top + (y - BOX_MIN) / span * WINDOW_HEIGHT * self.scale_y;
        (px, py)
    }

    /// The map as `(a_x, b_x), (a_y, b_y)`: a point `(x, y)` lands at
    /// `(a_x x + b_x, a_y y + b_y)`, as [`View::point`] has it (to a
    /// rounding), with a multiplication instead of a division.
    pub fn affine(&self) -> ((f64, f64), (f64, f64)) {
        let span = BOX_MAX - BOX_MIN;
        let ax = WINDOW_WIDTH * self.scale_x / span;
        let ay = WINDOW_HEIGHT * self.scale_y / span;
        (
            (ax, self.left - BOX_MIN * ax),
            (ay, self.top - BOX_MIN * ay),
        )
    }

    /// The stroke width of lines: 1.5 pixels at the window's size, never
    /// under one pixel.
    pub fn stroke_width(&self) -> f32 {
        (1.5 * self.scale_x.min(self.scale_y)).max(1.0) as f32
    }
}

/// Draws `lines` (coloured by `colors`) into `pixmap`, over black, the box
/// filling the window's shape. Lines whose coordinates are not finite are
/// skipped. Up to [`raster::PICTURE_SMOOTH_UP_TO`] lines are stroked by
/// tiny-skia, more drawn thin, as the window draws large scenes.
pub(crate) fn draw(lines: &[Line], colors: &[Color], pixmap: &mut Pixmap) {
    let size = Size {
        width: pixmap.width(),
        height: pixmap.height(),
    };
    let view = View::new(size);
    if lines.len() <= raster::PICTURE_SMOOTH_UP_TO {
        return draw_in_view(lines, colors, pixmap, &view);
    }
    let (width, height) = (size.width as usize, size.height as usize);
    let mut pixels = vec![0; width * height];
    raster::draw_thin(
        lines,
        colors,
        &view,
        &mut Canvas::new(&mut pixels, width, height),
    );
    for (out, rgb) in pixmap.pixels_mut().iter_mut().zip(pixels) {
        let [_, r, g, b] = rgb.to_be_bytes();
        *out = tiny_skia::ColorU8::from_rgba(r, g, b, 255).premultiply();
    }
}

/// [`draw`] as `view` maps the box.
pub(crate) fn draw_in_view(lines: &[Line], colors: &[Color], pixmap: &mut Pixmap, view: &View) {
    pixmap.fill(tiny_skia::Color::BLACK);
    let stroke = Stroke {
        width: view.stroke_width(),
        line_cap: LineCap::Round,
        ..Stroke::default()
    };
    for (color, rgb) in [(Color::Gray, GRAY), (Color::Red, RED)] {
        let mut path = PathBuilder::new();
        for (line, _) in lines.iter().zip(colors).filter(|(_, c)| **c == color) {
            let (x1, y1) = view.point(line.p1.x, line.p1.y);
            let (x2, y2) = view.point(line.p2.x, line.p2.y);
            if [x1, y1, x2, y2]
                .iter()
                .all(|v| v.is_finite() && v.abs() < 1e7)
            {
                path.move_to(x1 as f32, y1 as f32);
                path.line_to(x2 as f32, y2 as f32);
            }
        }
        if let Some(path) = path.finish() {
            let mut paint = Paint::default();
            paint.set_color_rgba8(rgb[0], rgb[1], rgb[2], 255);
            paint.anti_alias = true;
            pixmap.stroke_path(&path, &paint, &stroke, Transform::identity(), None);
        }
    }
}

/// A new frame of `size` showing the world.
///
/// ```
/// use screensaver::render::{frame, Size};
/// use screensaver::{DetectorKind, Scene, World};
///
/// let world = World::with_detector(&Scene::built_in(), DetectorKind::Sweep);
/// let picture = frame(&world, Size { width: 295, height: 200 });
/// assert_eq!((picture.width(), picture.height()), (295, 200));
/// assert!(picture.pixels().iter().any(|p| p.red() > 0), "red lines drawn");
/// ```
pub fn frame(world: &World, size: Size) -> Pixmap {
    let mut pixmap =
        Pixmap::new(size.width, size.height).expect("sizes are checked to be non-zero");
    draw(&world.lines(), world.colors(), &mut pixmap);
    pixmap
}

/// What `--render` writes, chosen by the file's extension.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) enum Target {
    /// The last frame as a PNG.
    Png(PathBuf),
    /// Every K-th frame as numbered PNGs: `NAME-000000.png`, ...
    PngSequence(PathBuf),
    /// Every K-th frame as a looping GIF.
    Gif(PathBuf),
    /// The last frame as vectors.
    Svg(PathBuf),
}

/// Something `--render` could not do.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The file name does not end in a known extension.
    #[error("{0}: unknown picture type; use a name ending in .png, .gif or .svg")]
    UnknownType(PathBuf),
    /// A frame every K steps asked of a type that holds one picture.
    #[error(
        "{0}: an SVG holds one picture, the last frame, not a frame every so many steps; \
         name a .png (a numbered sequence) or a .gif"
    )]
    OneFrameOnly(PathBuf),
    /// Writing failed.
    #[error("{path}: cannot write: {message}")]
    Write {
        /// The file.
        path: PathBuf,
        /// Why.
        message: String,
    },
}

/// Which frames a run's pictures hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Frames {
    /// The last one only (a `.png` is one picture).
    Last,
    /// A frame every so many steps (a `.png` becomes a numbered sequence).
    Every,
}

impl Target {
    /// The target for `path`, holding `frames`.
    pub fn for_path(path: &Path, frames: Frames) -> Result<Target, RenderError> {
        let sequence = frames == Frames::Every;
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") if sequence => Ok(Target::PngSequence(path.to_path_buf())),
            Some("png") => Ok(Target::Png(path.to_path_buf())),
            Some("gif") => Ok(Target::Gif(path.to_path_buf())),
            Some("svg") if sequence => Err(RenderError::OneFrameOnly(path.to_path_buf())),
            Some("svg") => Ok(Target::Svg(path.to_path_buf())),
            _ => Err(RenderError::UnknownType(path.to_path_buf())),
        }
    }
}

fn write_error(path: &Path, e: impl std::fmt::Display) -> RenderError {
    RenderError::Write {
        path: path.to_path_buf(),
        message: e.to_string(),
    }
}

/// Writes a frame as a PNG.
pub(crate) fn save_png(pixmap: &Pixmap, path: &Path) -> Result<(), RenderError> {
    let bytes = pixmap.encode_png().map_err(|e| write_error(path, e))?;
    crate::output::write_file(path, &bytes).map_err(written)
}

/// A write that failed, as a render error (the message names the file).
fn written(e: crate::output::OutputError) -> RenderError {
    RenderError::Write {
        path: e.path.clone(),
        message: e.reason(),
    }
}

/// The name of frame `index` of a PNG sequence named after `path`.
pub(crate) fn sequence_name(path: &Path, index: u64) -> PathBuf {
    let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("frame");
    path.with_file_name(format!("{stem}-{index:06}.png"))
}

/// The world as an SVG picture of `size`.
pub(crate) fn svg(world: &World, size: Size) -> String {
    let view = View::new(size);
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}">"#,
        w = size.width,
        h = size.height
    );
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="black"/>"#);
    for (color, rgb) in [(Color::Gray, GRAY), (Color::Red, RED)] {
        let _ = writeln!(
            out,
            r#"<g stroke="rgb({},{},{})" stroke-width="{:.2}" stroke-linecap="round">"#,
            rgb[0],
            rgb[1],
            rgb[2],
            view.stroke_width()
        );
        for (line, _) in world
            .lines()
            .iter()
            .zip(world.colors())
            .filter(|(_, c)| **c == color)
        {
            let (x1, y1) = view.point(line.p1.x, line.p1.y);
            let (x2, y2) = view.point(line.p2.x, line.p2.y);
            if [x1, y1, x2, y2].iter().all(|v| v.is_finite()) {
                let _ = writeln!(
                    out,
                    r#"<line x1="{x1:.2}" y1="{y1:.2}" x2="{x2:.2}" y2="{y2:.2}"/>"#
                );
            }
        }
        let _ = writeln!(out, "</g>");
    }
    out.push_str("</svg>\n");
    out
}

/// Writes the world as an SVG file.
pub(crate) fn save_svg(world: &World, size: Size, path: &Path) -> Result<(), RenderError> {
    crate::output::write_file(path, svg(world, size).as_bytes()).map_err(written)
}

/// The GIF palette: black, then eight shades each of the two line colours
/// from dark to full (anti-aliased edges blend them with the black).
pub(crate) fn gif_palette() -> Vec<[u8; 3]> {
    let mut palette = vec![[0, 0, 0]];
    for rgb in [RED, GRAY] {
        for k in 1..=8u16 {
            palette.push(rgb.map(|c| (u16::from(c) * k / 8) as u8));
        }
    }
    palette
}

/// An animated GIF being written frame by frame.
pub(crate) struct GifWriter {
    encoder: gif::Encoder<std::io::BufWriter<crate::output::OutputFile>>,
    palette: Vec<[u8; 3]>,
    path: PathBuf,
    /// Hundredths of a second each frame shows for.
    delay: u16,
}

impl GifWriter {
    /// Starts a looping GIF of `size` at `path`, each frame shown for
    /// `delay` hundredths of a second.
    pub fn create(path: &Path, size: Size, delay: u16) -> Result<GifWriter, RenderError> {
        let too_big = |_| write_error(path, "GIFs are at most 65535 pixels on a side");
        let (w, h) = (
            u16::try_from(size.width).map_err(too_big)?,
            u16::try_from(size.height).map_err(too_big)?,
        );
        let file = crate::output::OutputFile::create(path).map_err(written)?;
        let palette = gif_palette();
        let flat: Vec<u8> = palette.iter().flatten().copied().collect();
        let mut encoder = gif::Encoder::new(std::io::BufWriter::new(file), w, h, &flat)
            .map_err(|e| write_error(path, e))?;
        encoder
            .set_repeat(gif::Repeat::Infinite)
            .map_err(|e| write_error(path, e))?;
        Ok(GifWriter {
            encoder,
            palette,
            path: path.to_path_buf(),
            delay,
        })
    }

    /// Adds a frame, each pixel mapped to the nearest palette colour.
    pub fn add(&mut self, pixmap: &Pixmap) -> Result<(), RenderError> {
        // Most pixels are the background or repeat their neighbour: the
        // palette is searched only where the colour changes.
        let mut last = None;
        let indices: Vec<u8> = pixmap
            .pixels()
            .iter()
            .map(|&p| match last {
                Some((q, index)) if q == p => index,
                _ => {
                    let c = p.demultiply();
                    let index = nearest(&self.palette, [c.red(), c.green(), c.blue()]);
                    last = Some((p, index));
                    index
                }
            })
            .collect();
        let mut frame = gif::Frame {
            width: pixmap.width() as u16,
            height: pixmap.height() as u16,
            buffer: std::borrow::Cow::Owned(indices),
            delay: self.delay,
            ..gif::Frame::default()
        };
        frame.make_lzw_pre_encoded();
        self.encoder
            .write_lzw_pre_encoded_frame(&frame)
            .map_err(|e| write_error(&self.path, e))
    }

    /// Finishes the file, which takes its name only now.
    pub fn finish(self) -> Result<(), RenderError> {
        let path = self.path.clone();
        let out = self
            .encoder
            .into_inner()
            .map_err(|e| write_error(&path, e))?;
        let file = out
            .into_inner()
            .map_err(|e| write_error(&path, e.error()))?;
        file.commit().map_err(written)
    }
}

/// Writes the frames of a run to a file: call [`Recorder::start`]
/// before the first step, [`Recorder::after_step`] after each, and
/// [`Recorder::finish`] at the end. Sequences and GIFs get the first state
/// and every `every`-th step (and the last state); PNG and SVG files get the
/// last state.
pub struct Recorder {
    target: Target,
    size: Size,
    every: u64,
    gif: Option<GifWriter>,
    /// Steps at which the last frame was written.
    last_written: Option<u64>,
    /// Frames written so far.
    written: u64,
}

impl Recorder {
    /// A recorder writing frames of `size` to `path`, by its extension: a
    /// `.png` of the last frame (with `every`, a numbered sequence
    /// `NAME-000000.png`, ... of every `every`-th step), a `.gif` of every
    /// `every`-th step (every step without it) shown at `fps` frames per
    /// second, or an `.svg` of the last frame.
    pub fn new(
        path: &Path,
        size: Size,
        every: Option<u64>,
        fps: u32,
    ) -> Result<Recorder, RenderError> {
        let frames = if every.is_some() {
            Frames::Every
        } else {
            Frames::Last
        };
        let target = Target::for_path(path, frames)?;
        let every = every.unwrap_or(1);
        let gif = match &target {
            Target::Gif(path) => {
                let delay = (100.0 / f64::from(fps.max(1))).round().clamp(2.0, 65535.0) as u16;
                Some(GifWriter::create(path, size, delay)?)
            }
            _ => None,
        };
        Ok(Recorder {
            target,
            size,
            every: every.max(1),
            gif,
            last_written: None,
            written: 0,
        })
    }

    /// Checks, before a run, that `path` names pictures a recorder can
    /// write: a known type, and one that holds a frame every so many steps
    /// where `every` asks for that.
    ///
    /// ```
    /// use screensaver::render::Recorder;
    ///
    /// assert!(Recorder::check_name("run.gif".as_ref(), true).is_ok());
    /// assert!(Recorder::check_name("run.svg".as_ref(), true).is_err());
    /// assert!(Recorder::check_name("run.jpg".as_ref(), false).is_err());
    /// ```
    pub fn check_name(path: &Path, every: bool) -> Result<(), RenderError> {
        let frames = if every { Frames::Every } else { Frames::Last };
        Target::for_path(path, frames).map(drop)
    }

    /// The file of the picture after `step` in the numbered sequence a
    /// `.png` with a frame every so many steps is written as:
    /// `NAME-000005.png`.
    pub fn sequence_name(path: &Path, step: u64) -> PathBuf {
        sequence_name(path, step)
    }

    /// Writes the first frame, for sequences and GIFs.
    pub fn start(&mut self, world: &World) -> Result<(), RenderError> {
        self.write_frame(world)
    }

    /// Writes a frame if this step is one of every `every`.
    pub fn after_step(&mut self, world: &World) -> Result<(), RenderError> {
        if world.steps() % self.every == 0 {
            self.write_frame(world)?;
        }
        Ok(())
    }

    /// Closes the output: a PNG or SVG gets its one frame, the world as it
    /// ends; a sequence or GIF, which has a frame every `every` steps,
    /// also gets the last step, whether the run ended or was stopped (so
    /// that the pictures show where the run got to), unless that frame was
    /// just written. Returns the frames written in all.
    pub fn finish(mut self, world: &World) -> Result<u64, RenderError> {
        match &self.target {
            Target::Png(path) => save_png(&frame(world, self.size), path)?,
            Target::Svg(path) => save_svg(world, self.size, path)?,
            Target::PngSequence(_) | Target::Gif(_) => {
                if self.last_written != Some(world.steps()) {
                    self.write_frame(world)?;
                }
                if let Some(gif) = self.gif.take() {
                    gif.finish()?;
                }
                return Ok(self.written);
            }
        }
        Ok(1)
    }

    fn write_frame(&mut self, world: &World) -> Result<(), RenderError> {
        match &self.target {
            Target::PngSequence(path) => {
                save_png(
                    &frame(world, self.size),
                    &sequence_name(path, world.steps()),
                )?;
            }
            Target::Gif(_) => {
                let pixmap = frame(world, self.size);
                self.gif
                    .as_mut()
                    .expect("a GIF target has a writer")
                    .add(&pixmap)?;
            }
            Target::Png(_) | Target::Svg(_) => return Ok(()),
        }
        self.last_written = Some(world.steps());
        self.written += 1;
        Ok(())
    }
}

fn nearest(palette: &[[u8; 3]], c: [u8; 3]) -> u8 {
    let distance = |p: &[u8; 3]| -> i32 {
        (0..3)
            .map(|k| (i32::from(p[k]) - i32::from(c[k])).pow(2))
            .sum()
    };
    (0..palette.len())
        .min_by_key(|&k| distance(&palette[k]))
        .unwrap_or(0) as u8
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_box_fills_the_window_with_y_down() {
        let v = View::new(Size::WINDOW);
        assert_eq!(v.point(0.5, 0.5), (0.0, 0.0));
        assert_eq!(v.point(1.0, 1.0), (1180.0, 800.0));
        // A square frame gets bars above and below.
        let v = View::new(Size {
            width: 590,
            height: 590,
        });
        let (x, y) = v.point(0.5, 0.5);
        assert_eq!(x, 0.0);
        assert!((y - (590.0 - 400.0) / 2.0).abs() < 1e-9);
    }

    #[test]
    fn targets_follow_the_extension() {
        assert_eq!(
            Target::for_path(Path::new("a.PNG"), Frames::Last).unwrap(),
            Target::Png("a.PNG".into())
        );
        assert!(matches!(
            Target::for_path(Path::new("a.png"), Frames::Every).unwrap(),
            Target::PngSequence(_)
        ));
        assert!(matches!(
            Target::for_path(Path::new("a.gif"), Frames::Last).unwrap(),
            Target::Gif(_)
        ));
        assert!(matches!(
            Target::for_path(Path::new("a.svg"), Frames::Last).unwrap(),
            Target::Svg(_)
        ));
        let e = Target::for_path(Path::new("a.jpg"), Frames::Last).unwrap_err();
        assert!(e.to_string().contains("a.jpg: unknown picture type"));
        assert_eq!(
            sequence_name(Path::new("out/run.png"), 42),
            PathBuf::from("out/run-000042.png")
        );
    }

    #[test]
    fn the_palette_maps_line_colours_to_themselves() {
        let p = gif_palette();
        assert_eq!(p.len(), 17);
        assert_eq!(p[nearest(&p, RED) as usize], RED);
        assert_eq!(p[nearest(&p, GRAY) as usize], GRAY);
        assert_eq!(nearest(&p, [0, 0, 0]), 0);
    }
}
