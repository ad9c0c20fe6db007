//! How much faster `N` threads can make a run on this machine at best,
//! beside how much faster they do make it.
//!
//! ```sh
//! cargo run --release -p screensaver-bench --example ceiling -- [SCENE] [--frames F] [--threads N] [--rounds R]
//! ```
//!
//! Each round times three things, one after another: the scene on one
//! thread (`solo`); `N` copies of it at once, each on a thread of its own
//! (`copies`: nothing shared and nothing to wait for, so no split of one run
//! over `N` threads can beat it); and the scene with `--threads N`
//! (`pool`). `N` copies that take as long as one solo run would mean `N`
//! full cores; the ceiling is `N * solo / copies`. Each round starts with
//! the next of the three, so that a noisy machine weighs on them alike, and
//! the medians are printed.
//! Without SCENE it runs the built-in scene.

use screensaver::{DetectorConfig, DetectorKind, Scene, World};
use std::time::Instant;

/// Seconds to run `steps` steps of `scene` on `threads` threads (building
/// the world is not timed).
fn time_run(scene: &Scene, steps: u64, threads: usize) -> f64 {
    let config = DetectorConfig {
        threads,
        ..DetectorConfig::default()
    };
    let mut world =
        World::with_config(scene, DetectorKind::DEFAULT, &config).expect("a thread pool");
    let start = Instant::now();
    world.run(steps);
    start.elapsed().as_secs_f64()
}

/// Seconds until all of `copies` runs of `steps` steps of `scene`, each on
/// one thread of its own, are done.
fn time_copies(scene: &Scene, steps: u64, copies: usize) -> f64 {
    let config = DetectorConfig::default();
    let mut worlds: Vec<World> = (0..copies)
        .map(|_| World::with_config(scene, DetectorKind::DEFAULT, &config).expect("one thread"))
        .collect();
    let start = Instant::now();
    std::thread::scope(|s| {
        for world in &mut worlds {
            s.spawn(move || world.run(steps));
        }
    });
    start.elapsed().as_secs_f64()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let (mut path, mut frames, mut threads, mut rounds) = (None, 1000u64, 2usize, 9usize);
    while let Some(arg) = args.next() {
        let mut value = |name: &str| args.next().ok_or(format!("{name} needs a value"));
        match arg.as_str() {
            "--frames" => frames = value("--frames")?.parse()?,
            "--threads" => threads = value("--threads")?.parse()?,
            "--rounds" => rounds = value("--rounds")?.parse()?,
            other if other.starts_with("--") => {
                return Err(format!("unknown option `{other}`").into())
            }
            other => path = Some(std::path::PathBuf::from(other)),
        }
    }
    if threads < 2 || rounds == 0 {
        return Err("--threads must be at least 2 and --rounds at least 1".into());
    }
    let (scene, name) = match &path {
        Some(p) => (Scene::load(p)?, p.display().to_string()),
        None => (Scene::built_in(), "the built-in scene".into()),
    };
    // Like the program, F frames run F + 1 steps.
    let steps = frames + 1;
    let (mut solo, mut copies, mut pool) = (Vec::new(), Vec::new(), Vec::new());
    for round in 0..rounds {
        // Each round starts with another of the three, so that none always
        // follows the machine's busiest moment (the copies).
        for k in 0..3 {
            match (round + k) % 3 {
                0 => solo.push(time_run(&scene, steps, 1)),
                1 => copies.push(time_copies(&scene, steps, threads)),
                _ => pool.push(time_run(&scene, steps, threads)),
            }
        }
        eprintln!(
            "round {}: solo {:.4} s, {threads} copies {:.4} s, --threads {threads} {:.4} s",
            round + 1,
            solo[round],
            copies[round],
            pool[round]
        );
    }
    let (solo, copies, pool) = (median(solo), median(copies), median(pool));
    println!("{name}, {frames} frames, medians of {rounds} rounds:");
    println!("{:<24}{solo:.4} s", "one thread:");
    println!(
        "{:<24}{copies:.4} s (ceiling: {threads} threads do at most {:.2}x the work of one)",
        format!("{threads} copies at once:"),
        threads as f64 * solo / copies
    );
    println!(
        "{:<24}{pool:.4} s ({:.2}x one thread)",
        format!("--threads {threads}:"),
        solo / pool
    );
    Ok(())
}
