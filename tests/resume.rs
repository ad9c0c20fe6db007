//! Checkpoints and resuming: a run stopped at any step and resumed from
//! its checkpoint, with any detector and thread count, ends exactly where
//! the uninterrupted run ends.

mod common;

use proptest::prelude::*;
use screensaver::checkpoint::{self, Checkpoint};
use screensaver::generate::{generate, SceneKind};
use screensaver::{DetectorConfig, DetectorKind, World};

fn config(threads: usize) -> DetectorConfig {
    DetectorConfig {
        threads,
        // A tiny grain, so that every parallel path runs.
        grain: 8,
        ..DetectorConfig::default()
    }
}

fn checkpoint_text(world: &World, digest: u64) -> Vec<u8> {
    let mut out = Vec::new();
    Checkpoint::write(world, digest, &mut out).unwrap();
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    #[test]
    fn a_resumed_run_ends_where_the_uninterrupted_one_ends(
        kind in prop::sample::select(SceneKind::ALL.to_vec()),
        lines in 2usize..400,
        seed in 0u64..1000,
        total in 1u64..120,
        stop_at in 0.0f64..1.0,
        first in prop::sample::select(DetectorKind::ALL.to_vec()),
        second in prop::sample::select(DetectorKind::ALL.to_vec()),
        threads in prop::sample::select(vec![1usize, 2, 3, 8]),
    ) {
        let scene = generate(kind, lines, seed);
        let digest = scene.digest();
        let mut whole = World::with_config(&scene, DetectorKind::Brute, &config(1)).unwrap();
        whole.run(total);

        let stop = (total as f64 * stop_at) as u64;
        let mut part = World::with_config(&scene, first, &config(threads)).unwrap();
        part.run(stop);
        let text = checkpoint_text(&part, digest);
        let saved = Checkpoint::parse(&text, "checkpoint").unwrap();
        prop_assert_eq!(saved.steps, stop);
        let mut resumed = saved.resume(second, &config(1 + threads % 3)).unwrap();
        resumed.run(total - stop);

        prop_assert_eq!(resumed.steps(), whole.steps());
        prop_assert_eq!(resumed.counters(), whole.counters());
        prop_assert_eq!(checkpoint_text(&resumed, digest), checkpoint_text(&whole, digest));
    }
}

/// The states the program writes match the reference's files byte for
/// byte, not only value for value.
#[test]
fn states_match_the_reference_files_byte_for_byte() {
    let Some(dir) = common::reference_dir("states_match_the_reference_files_byte_for_byte") else {
        return;
    };
    for scene in ["mit", "smalllines"] {
        let mut world = World::with_detector(&common::load_scene(&dir, scene), DetectorKind::Sweep);
        let mut done = 0;
        for step in common::checkpoints(&dir, scene) {
            world.run(step - done);
            done = step;
            let expected =
                std::fs::read(dir.join(format!("expected/{scene}.{step}.state"))).unwrap();
            let mut written = Vec::new();
            checkpoint::write_state(&world, &mut written).unwrap();
            assert!(
                written == expected,
                "{scene} step {step}: state differs from the reference file"
            );
        }
    }
}
