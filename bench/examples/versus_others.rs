//! The broad phase on boxes (`screensaver::broad_phase`) against broccoli
//! and parry2d's bounding-volume hierarchy, alternating them on the same
//! boxes in one process so that a busy machine slows all alike; prints the
//! median of each and the ratios.
//!
//! ```sh
//! cargo run --release -p screensaver-bench --example versus_others -- [LINES] [ROUNDS] [uniform|clustered]
//! ```
//!
//! The boxes are the axis-aligned swept boxes of a generated scene
//! (`gen --lines LINES --seed 7`) at each of its first `ROUNDS + 1` steps,
//! so that from one round to the next every box moves a little, as a
//! program's objects do from frame to frame. Each round finds every
//! overlapping pair once with each, on one thread: `overlapping_pairs`
//! (afresh), a `BroadPhase` kept from round to round (its first call, on
//! the first step's boxes, not timed), a broccoli tree built anew, and
//! parry2d's hierarchy built anew and kept (built on the first step's
//! boxes, not timed; each round its leaves updated and the tree refitted,
//! then its pairs found). parry2d works in `f32`: its boxes are rounded
//! outwards, and its pairs, like ours, kept where the `f64` boxes overlap.
//! All must find the same number of pairs.

use broccoli::rect;
use parry2d::bounding_volume::Aabb as ParryAabb;
use parry2d::math::Vector;
use parry2d::partitioning::{Bvh, BvhBuildStrategy, BvhWorkspace};
use screensaver::broad_phase::{for_each_overlapping_pair, Aabb, BroadPhase};
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
    let mut world = World::with_detector(&scene, DetectorKind::Sweep);
    let mut frames: Vec<Vec<Aabb>> = Vec::new();
    for _ in 0..=rounds {
        // A line without a box (none here) is an empty box.
        let empty = Aabb {
            min: [f64::NAN; 2],
            max: [f64::NAN; 2],
        };
        let lines = world.lines();
        let boxes = lines.iter().map(|l| Aabb::swept(l, 0.5).unwrap_or(empty));
        frames.push(boxes.collect());
        world.step();
    }

    if frames.iter().flatten().any(Aabb::is_empty) {
        return Err("a line without a box: parry2d's leaves are every box".into());
    }
    let mut kept = BroadPhase::new();
    kept.for_each_pair(&frames[0], |_, _| {});
    let mut bvh = Bvh::from_leaves(BvhBuildStrategy::Binned, &parry_boxes(&frames[0]));
    let mut workspace = BvhWorkspace::default();
    let (mut afresh, mut carried, mut theirs) = (Vec::new(), Vec::new(), Vec::new());
    let (mut parry_built, mut parry_kept) = (Vec::new(), Vec::new());
    let mut pairs = 0u64;
    for boxes in &frames[1..] {
        let start = Instant::now();
        let mut ours = 0u64;
        for_each_overlapping_pair(boxes, |_, _| ours += 1);
        afresh.push(start.elapsed().as_secs_f64());

        let start = Instant::now();
        let mut kept_pairs = 0u64;
        kept.for_each_pair(boxes, |_, _| kept_pairs += 1);
        carried.push(start.elapsed().as_secs_f64());

        let start = Instant::now();
        let mut aabbs: Vec<_> = boxes
            .iter()
            .filter(|b| !b.is_empty())
            .map(|b| (rect(b.min[0], b.max[0], b.min[1], b.max[1]), ()))
            .collect();
        let mut tree = broccoli::Tree::new(&mut aabbs);
        let mut their_pairs = 0u64;
        tree.find_colliding_pairs(|_, _| their_pairs += 1);
        theirs.push(start.elapsed().as_secs_f64());

        let start = Instant::now();
        let mut built_pairs = 0u64;
        let built = Bvh::from_leaves(BvhBuildStrategy::Binned, &parry_boxes(boxes));
        built.traverse_bvtt_single_tree::<false>(&mut workspace, &mut |a, b| {
            built_pairs += u64::from(boxes[a as usize].overlaps(&boxes[b as usize]))
        });
        parry_built.push(start.elapsed().as_secs_f64());

        let start = Instant::now();
        let mut refit_pairs = 0u64;
        for (leaf, b) in parry_boxes(boxes).into_iter().enumerate() {
            bvh.insert_or_update_partially(b, leaf as u32, 0.0);
        }
        bvh.refit(&mut workspace);
        bvh.traverse_bvtt_single_tree::<false>(&mut workspace, &mut |a, b| {
            refit_pairs += u64::from(boxes[a as usize].overlaps(&boxes[b as usize]))
        });
        parry_kept.push(start.elapsed().as_secs_f64());

        let counts = [ours, kept_pairs, their_pairs, built_pairs, refit_pairs];
        if counts.iter().any(|&c| c != ours) {
            return Err(format!(
                "pairs differ (ours afresh, kept, broccoli, parry2d built, refitted): {counts:?}"
            )
            .into());
        }
        pairs += ours;
    }
    let median = |mut v: Vec<f64>| {
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let (afresh, carried, theirs) = (median(afresh), median(carried), median(theirs));
    let (parry_built, parry_kept) = (median(parry_built), median(parry_kept));
    println!(
        "{kind}, {} boxes, {:.0} pairs a round, medians of {rounds} (ms):",
        frames[0].len(),
        pairs as f64 / rounds as f64,
    );
    println!(
        "  afresh: overlapping_pairs {:.2}, broccoli {:.2} ({:.2}x), parry2d built {:.2} ({:.2}x)",
        afresh * 1e3,
        theirs * 1e3,
        theirs / afresh,
        parry_built * 1e3,
        parry_built / afresh,
    );
    println!(
        "  kept:   BroadPhase {:.2}, parry2d refitted {:.2} ({:.2}x)",
        carried * 1e3,
        parry_kept * 1e3,
        parry_kept / carried,
    );
    Ok(())
}

/// The boxes in parry2d's `f32`, rounded outwards.
fn parry_boxes(boxes: &[Aabb]) -> Vec<ParryAabb> {
    let down = |v: f64| {
        let f = v as f32;
        if f64::from(f) > v {
            f.next_down()
        } else {
            f
        }
    };
    let up = |v: f64| {
        let f = v as f32;
        if f64::from(f) < v {
            f.next_up()
        } else {
            f
        }
    };
    boxes
        .iter()
        .map(|b| {
            let mins = Vector::new(down(b.min[0]), down(b.min[1]));
            ParryAabb::new(mins, Vector::new(up(b.max[0]), up(b.max[1])))
        })
        .collect()
}
