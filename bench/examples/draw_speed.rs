//! Time a frame's drawing at several scene sizes, with tiny-skia's strokes
//! and with the thin-line rasteriser (lines in id order, and in the order
//! a world stepped by the sweep stores them): `cargo run --release -p screensaver-bench --example
//! draw_speed -- [WIDTHxHEIGHT] [KIND]`. Prints the median of several
//! frames for each, in milliseconds.

use screensaver::generate::{generate, SceneKind};
use screensaver::internals::{draw_in_view, draw_thin, draw_thin_each};
use screensaver::render::{Canvas, Size, View};
use screensaver::{DetectorKind, World};
use std::time::Instant;

fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let size = args.get(1).map_or(Size::WINDOW, |s| {
        let (w, h) = s.split_once('x').expect("a size like 1180x800");
        let side = |t: &str| t.parse().expect("a size like 1180x800");
        Size {
            width: side(w),
            height: side(h),
        }
    });
    let kind = args.get(2).map_or(SceneKind::Uniform, |s| {
        SceneKind::from_name(s).expect("a scene kind: uniform, clustered, ring or grid")
    });
    let view = View::new(size);
    let (w, h) = (size.width as usize, size.height as usize);
    println!("{}x{} {}: milliseconds a frame (median)", w, h, kind.name());
    println!(
        "{:>9} {:>12} {:>12} {:>12}",
        "lines", "tiny-skia", "thin", "thin stored"
    );
    for lines in [1_000, 10_000, 100_000, 1_000_000] {
        let world = World::with_detector(&generate(kind, lines, 1), DetectorKind::Brute);
        let mut pixmap = tiny_skia::Pixmap::new(size.width, size.height).expect("a size");
        let mut pixels = vec![0u32; w * h];
        let rounds = if lines >= 100_000 { 5 } else { 21 };
        let smooth = if lines <= 100_000 {
            let t: Vec<f64> = (0..rounds.min(5))
                .map(|_| {
                    let start = Instant::now();
                    draw_in_view(&world.lines(), world.colors(), &mut pixmap, &view);
                    start.elapsed().as_secs_f64() * 1e3
                })
                .collect();
            format!("{:.2}", median(t))
        } else {
            "-".to_string()
        };
        let thin: Vec<f64> = (0..rounds)
            .map(|_| {
                let start = Instant::now();
                draw_thin(
                    &world.lines(),
                    world.colors(),
                    &view,
                    &mut Canvas::new(&mut pixels, w, h),
                );
                start.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        // The same, in the order a world stepped by the sweep stores its
        // lines (nearby lines together).
        let mut stepped = World::with_detector(&generate(kind, lines, 1), DetectorKind::Sweep);
        stepped.run(1);
        let stored: Vec<f64> = (0..rounds)
            .map(|_| {
                let start = Instant::now();
                draw_thin_each(
                    stepped.lines_as_stored(),
                    &view,
                    &mut Canvas::new(&mut pixels, w, h),
                );
                start.elapsed().as_secs_f64() * 1e3
            })
            .collect();
        println!(
            "{lines:>9} {smooth:>12} {:>12.2} {:>12.2}",
            median(thin),
            median(stored)
        );
    }
}
