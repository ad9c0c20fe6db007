//! The broad phase on boxes (`screensaver::broad_phase`) against broccoli,
//! alternating the two on the same boxes in one process so that a busy
//! machine slows both alike; prints the median of each and their ratio.
//!
//! ```sh
//! cargo run --release -p screensaver-bench --example versus_broccoli -- [LINES] [ROUNDS] [uniform|clustered]
//! ```
//!
//! The boxes are the axis-aligned swept boxes of a generated scene's first
//! step (`gen --lines LINES --seed 7`); each round builds and finds every
//! overlapping pair once with each, on one thread. Both must find the same
//! number of pairs.

use broccoli::rect;
use screensaver::broad_phase::{for_each_overlapping_pair, Aabb};
use screensaver::generate::{generate, SceneKind};
use screensaver::{DetectorKind, World};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let lines: usize = args.next().map_or(Ok(100_000), |a| a.parse())?;
    let rounds: usize = args.next().map_or(Ok(15), |a| a.parse())?;
    let kind = match args.next() {
        Some(name) => {
            SceneKind::from_name(&name).ok_or("a scene kind: uniform, clustered, ring or grid")?
        }
        None => SceneKind::Uniform,
    };
    let rounds = rounds.max(1);

    let scene = generate(kind, lines, 7);
    let world = World::with_detector(&scene, DetectorKind::Brute);
    let boxes: Vec<Aabb> = world
        .lines()
        .iter()
        .filter_map(|l| Aabb::swept(l, 0.5))
        .collect();

    let (mut ours, mut theirs) = (Vec::new(), Vec::new());
    let (mut our_pairs, mut their_pairs) = (0u64, 0u64);
    for _ in 0..rounds {
        let start = Instant::now();
        our_pairs = 0;
        for_each_overlapping_pair(&boxes, |_, _| our_pairs += 1);
        ours.push(start.elapsed().as_secs_f64());

        let start = Instant::now();
        let mut aabbs: Vec<_> = boxes
            .iter()
            .map(|b| (rect(b.min[0], b.max[0], b.min[1], b.max[1]), ()))
            .collect();
        let mut tree = broccoli::Tree::new(&mut aabbs);
        their_pairs = 0;
        tree.find_colliding_pairs(|_, _| their_pairs += 1);
        theirs.push(start.elapsed().as_secs_f64());
    }
    if our_pairs != their_pairs {
        return Err(format!("pairs differ: {our_pairs} against broccoli's {their_pairs}").into());
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (ours, theirs) = (median(ours), median(theirs));
    println!(
        "{kind}, {} boxes, {our_pairs} pairs, medians of {rounds}: broad_phase {:.2} ms, broccoli {:.2} ms, {:.2}x",
        boxes.len(),
        ours * 1e3,
        theirs * 1e3,
        theirs / ours
    );
    Ok(())
}
