//! The broad phase alone against broccoli, on the same boxes: the swept
//! boxes of generated scenes of 10^4, 10^5 and 10^6 lines, uniform and
//! clustered (one step's worth: build plus all overlapping pairs, for
//! each; one thread).

use broccoli::rect;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use screensaver::broad_phase::{for_each_overlapping_pair, Aabb};
use screensaver::generate::{generate, SceneKind};
use screensaver::{DetectorKind, World};

/// The swept boxes of a generated scene's first step, as plain boxes.
fn boxes(kind: SceneKind, lines: usize) -> Vec<Aabb> {
    let scene = generate(kind, lines, 7);
    let world = World::with_detector(&scene, DetectorKind::Brute);
    world
        .lines()
        .iter()
        .filter_map(|l| Aabb::swept(l, 0.5))
        .collect()
}

fn sweep_pairs(boxes: &[Aabb]) -> u64 {
    let mut count = 0u64;
    for_each_overlapping_pair(boxes, |_, _| count += 1);
    count
}

fn broccoli_pairs(boxes: &[Aabb]) -> u64 {
    let mut aabbs: Vec<_> = boxes
        .iter()
        .map(|b| (rect(b.min[0], b.max[0], b.min[1], b.max[1]), ()))
        .collect();
    let mut tree = broccoli::Tree::new(&mut aabbs);
    let mut count = 0u64;
    tree.find_colliding_pairs(|_, _| count += 1);
    count
}

fn broad_phase(c: &mut Criterion) {
    let mut group = c.benchmark_group("broad_phase");
    group.sample_size(10);
    for kind in [SceneKind::Uniform, SceneKind::Clustered] {
        for lines in [10_000, 100_000, 1_000_000] {
            let boxes = boxes(kind, lines);
            let (ours, theirs) = (sweep_pairs(&boxes), broccoli_pairs(&boxes));
            eprintln!("{kind} {lines} boxes: sweep {ours} pairs, broccoli {theirs} pairs");
            assert_eq!(ours, theirs, "both find every overlapping pair");
            let id = |name| BenchmarkId::new(format!("{name}/{kind}"), lines);
            group.bench_function(id("sweep"), |b| b.iter(|| sweep_pairs(&boxes)));
            group.bench_function(id("broccoli"), |b| b.iter(|| broccoli_pairs(&boxes)));
        }
    }
    group.finish();
}

criterion_group!(benches, broad_phase);
criterion_main!(benches);
