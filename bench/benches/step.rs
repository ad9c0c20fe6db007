//! One simulation step per detector per scene.
//!
//! Course scenes are read from `SCREENSAVER_REFERENCE` (default
//! `../shared/reference`); when they are absent only the built-in scene is
//! measured. Each measurement steps a world that has already run a few
//! steps, so the state is a typical mid-run one.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};
use screensaver::{DetectorConfig, DetectorKind, Scene, World};
use std::path::PathBuf;

fn reference_dir() -> PathBuf {
    std::env::var_os("SCREENSAVER_REFERENCE")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/reference"))
}

fn scenes() -> Vec<(String, Scene)> {
    let mut scenes = vec![("default".to_string(), Scene::built_in())];
    for name in ["mit", "koch"] {
        let path = reference_dir().join("inputs").join(format!("{name}.in"));
        match Scene::load(&path) {
            Ok(scene) => scenes.push((name.to_string(), scene)),
            Err(e) => eprintln!("skipped {name}: {e}"),
        }
    }
    scenes
}

/// The detectors measured: the all-pairs oracle, the sweep and the
/// quadtree.
fn detectors() -> Vec<(&'static str, DetectorKind, DetectorConfig)> {
    DetectorKind::ALL
        .iter()
        .map(|&k| (k.name(), k, DetectorConfig::default()))
        .collect()
}

fn one_step(c: &mut Criterion) {
    let mut group = c.benchmark_group("step");
    group.sample_size(10);
    for (name, scene) in scenes() {
        for (label, kind, config) in detectors() {
            let mut world = World::with_config(&scene, kind, &config).expect("threads");
            world.run(3);
            group.bench_function(BenchmarkId::new(label, &name), |b| b.iter(|| world.step()));
        }
    }
    group.finish();
}

criterion_group!(benches, one_step);
criterion_main!(benches);
