//! The broad phase alone against broccoli, on the same boxes: the swept
//! boxes of generated scenes of 10^4, 10^5 and 10^6 lines (one step's
//! worth: build plus all overlapping pairs, for both).
//!
//! Both get axis-aligned boxes (the quadtree's diagonal extents are set to
//! those of the box, so they prune nothing more), and both run on one
//! thread.

use broccoli::rect;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use screensaver::detect::quadtree::count_overlapping;
use screensaver::detect::swept::{swept_box, SweptBox, DIAGONAL_X, DIAGONAL_Y};
use screensaver::generate::{generate, SceneKind};
use screensaver::{DetectorConfig, DetectorKind, World};

/// The swept boxes of a generated scene's first step, as plain boxes.
fn boxes(lines: usize) -> Vec<SweptBox> {
    let scene = generate(SceneKind::Uniform, lines, 7);
    let world = World::from_scene(&scene, DetectorKind::Brute.build());
    world
        .lines()
        .iter()
        .filter_map(|l| swept_box(l, 0.5))
        .map(|b| SweptBox {
            min_u: b.min_x * DIAGONAL_X + b.min_y * DIAGONAL_Y,
            max_u: b.max_x * DIAGONAL_X + b.max_y * DIAGONAL_Y,
            min_w: b.min_x * DIAGONAL_X - b.max_y * DIAGONAL_Y,
            max_w: b.max_x * DIAGONAL_X - b.min_y * DIAGONAL_Y,
            ..b
        })
        .collect()
}

fn broccoli_pairs(boxes: &[SweptBox]) -> u64 {
    let mut aabbs: Vec<_> = boxes
        .iter()
        .map(|b| (rect(b.min_x, b.max_x, b.min_y, b.max_y), ()))
        .collect();
    let mut tree = broccoli::Tree::new(&mut aabbs);
    let mut count = 0u64;
    tree.find_colliding_pairs(|_, _| count += 1);
    count
}

fn broad_phase(c: &mut Criterion) {
    let mut group = c.benchmark_group("broad_phase");
    group.sample_size(10);
    let config = DetectorConfig::default();
    for lines in [10_000, 100_000, 1_000_000] {
        let boxes = boxes(lines);
        eprintln!(
            "{lines} lines: quadtree {} pairs, broccoli {} pairs",
            count_overlapping(&boxes, &config),
            broccoli_pairs(&boxes)
        );
        group.bench_function(BenchmarkId::new("quadtree", lines), |b| {
            b.iter(|| count_overlapping(&boxes, &config))
        });
        group.bench_function(BenchmarkId::new("broccoli", lines), |b| {
            b.iter(|| broccoli_pairs(&boxes))
        });
    }
    group.finish();
}

criterion_group!(benches, broad_phase);
criterion_main!(benches);
