//! Steps per second of every detector and thread count over generated
//! scenes of 10^3 to 10^6 lines: prints a Markdown table and draws a
//! log-log plot.
//!
//! ```sh
//! cargo run --release -p screensaver-bench --example scaling -- [--max-lines N] [--out docs/scaling.png]
//! ```
//!
//! Each configuration runs the same scene (`gen --lines N --seed 7`) for
//! two warm-up steps, then for about a second (at least 10 steps) in one
//! timed run. The all-pairs detector stops at 10^4 lines. The ceiling is
//! what two threads could do at most: two copies of the one-thread sweep
//! run at once (nothing shared, nothing to wait for), their steps added up
//! (as `bench/examples/ceiling.rs` measures it on one scene). Text in the plot
//! uses DejaVu Sans from Debian's `fonts-dejavu-core`.

use plotters::prelude::*;
use screensaver::generate::{generate, SceneKind};
use screensaver::{DetectorConfig, DetectorKind, World};
use std::time::{Duration, Instant};

const FONT: &str = "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";

struct Series {
    name: String,
    kind: DetectorKind,
    config: DetectorConfig,
    max_lines: usize,
    /// Copies run at once, each on one thread (1: the configuration as
    /// it is).
    copies: usize,
    points: Vec<(usize, f64)>,
}

/// A series of `kind` on `threads` threads, `copies` worlds at once.
fn one(
    name: String,
    kind: DetectorKind,
    threads: usize,
    max_lines: usize,
    copies: usize,
) -> Series {
    Series {
        name,
        kind,
        config: DetectorConfig {
            threads,
            ..DetectorConfig::default()
        },
        max_lines,
        copies,
        points: Vec::new(),
    }
}

fn series(max_lines: usize) -> Vec<Series> {
    let threads_name = |kind: DetectorKind, threads: usize| {
        let s = if threads > 1 { "s" } else { "" };
        format!("{}, {threads} thread{s}", kind.name())
    };
    let mut all = vec![one(
        threads_name(DetectorKind::Brute, 1),
        DetectorKind::Brute,
        1,
        max_lines.min(10_000),
        1,
    )];
    for kind in [DetectorKind::Sweep, DetectorKind::Quadtree] {
        for threads in [1, 2] {
            all.push(one(
                threads_name(kind, threads),
                kind,
                threads,
                max_lines,
                1,
            ));
        }
        if kind == DetectorKind::Sweep {
            let name = "sweep, ceiling of 2 threads".to_string();
            all.push(one(name, kind, 1, max_lines, 2));
        }
    }
    all
}

/// Steps per second of `kind` with `config` on `lines` lines, summed over
/// `copies` worlds run at once, each on a thread of its own.
fn measure(lines: usize, kind: DetectorKind, config: &DetectorConfig, copies: usize) -> f64 {
    let scene = generate(SceneKind::Uniform, lines, 7);
    let mut worlds: Vec<World> = (0..copies)
        .map(|_| World::with_config(&scene, kind, config).expect("a thread pool"))
        .collect();
    // Warm up, and learn roughly how long a step takes; then time one run
    // of a second's worth (at least 10 steps) inside the thread pool.
    let start = Instant::now();
    worlds[0].run(2);
    let per_step = start.elapsed() / 2;
    let steps = (Duration::from_secs(1).as_secs_f64() / per_step.as_secs_f64().max(1e-9))
        .clamp(10.0, 1e6) as u64;
    let start = Instant::now();
    std::thread::scope(|scope| {
        for world in &mut worlds {
            scope.spawn(move || world.run(steps));
        }
    });
    (copies as u64 * steps) as f64 / start.elapsed().as_secs_f64()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (mut max_lines, mut out) = (1_000_000usize, String::from("docs/scaling.png"));
    while let Some(arg) = args.next() {
        match arg.as_str() {
            "--max-lines" => max_lines = args.next().ok_or("--max-lines needs a value")?.parse()?,
            "--out" => out = args.next().ok_or("--out needs a value")?,
            other => return Err(format!("unknown argument `{other}`").into()),
        }
    }
    let sizes: Vec<usize> = [1_000, 3_000, 10_000, 30_000, 100_000, 300_000, 1_000_000]
        .into_iter()
        .filter(|&n| n <= max_lines)
        .collect();

    let mut all = series(max_lines);
    for &n in &sizes {
        for s in all.iter_mut().filter(|s| n <= s.max_lines) {
            let rate = measure(n, s.kind, &s.config, s.copies);
            eprintln!("{n:>9} lines  {:<28} {rate:>12.1} steps/s", s.name);
            s.points.push((n, rate));
        }
    }

    print!("| configuration |");
    for n in &sizes {
        print!(" {n} |");
    }
    println!();
    println!("| --- |{}", " ---: |".repeat(sizes.len()));
    for s in &all {
        print!("| {} |", s.name);
        for n in &sizes {
            match s.points.iter().find(|p| p.0 == *n) {
                Some(p) => print!(" {:.1} |", p.1),
                None => print!(" |"),
            }
        }
        println!();
    }

    let font =
        std::fs::read(FONT).map_err(|e| format!("{FONT}: {e} (install fonts-dejavu-core)"))?;
    plotters::style::register_font(
        "sans-serif",
        FontStyle::Normal,
        Box::leak(font.into_boxed_slice()),
    )
    .map_err(|_| "cannot load the font")?;
    if let Some(dir) = std::path::Path::new(&out).parent() {
        std::fs::create_dir_all(dir)?;
    }
    let root = BitMapBackend::new(&out, (1000, 700)).into_drawing_area();
    root.fill(&WHITE)?;
    let top = all
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold(1.0, f64::max);
    let bottom = all
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.1))
        .fold(top, f64::min);
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Steps per second by scene size (generated uniform scenes)",
            ("sans-serif", 24),
        )
        .margin(20)
        .x_label_area_size(50)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (sizes[0] as f64 * 0.8..*sizes.last().expect("a size") as f64 * 1.25).log_scale(),
            (bottom * 0.5..top * 2.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("lines")
        .y_desc("steps per second")
        .label_style(("sans-serif", 16))
        .draw()?;
    for (k, s) in all.iter().enumerate() {
        let color = Palette99::pick(k).to_rgba();
        let points: Vec<(f64, f64)> = s.points.iter().map(|&(n, r)| (n as f64, r)).collect();
        chart
            .draw_series(LineSeries::new(points.clone(), color.stroke_width(2)))?
            .label(s.name.clone())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(2))
            });
        chart.draw_series(
            points
                .into_iter()
                .map(|p| Circle::new(p, 4, color.filled())),
        )?;
    }
    chart
        .configure_series_labels()
        // The curves fall from upper left to lower right.
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .label_font(("sans-serif", 16))
        .draw()?;
    root.present()?;
    eprintln!("wrote {out}");
    Ok(())
}
