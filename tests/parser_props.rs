//! Property tests: no text, however broken, makes the scene parser panic,
//! and every valid scene survives a write and a read unchanged.

use proptest::prelude::*;
use screensaver::{Color, Scene, SceneLine, Vec2};

fn finite() -> impl Strategy<Value = f64> {
    prop_oneof![
        -2000.0f64..2000.0,
        Just(0.0),
        Just(-0.0),
        any::<f64>().prop_filter("finite", |x| x.is_finite()),
    ]
}

fn scene_line() -> impl Strategy<Value = SceneLine> {
    (
        finite(),
        finite(),
        finite(),
        finite(),
        finite(),
        finite(),
        any::<bool>(),
    )
        .prop_map(|(a, b, c, d, e, f, gray)| SceneLine {
            p1: Vec2::new(a, b),
            p2: Vec2::new(c, d),
            v: Vec2::new(e, f),
            color: if gray { Color::Gray } else { Color::Red },
        })
}

proptest! {
    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        let _ = Scene::parse(&bytes, "random.in");
    }

    #[test]
    fn valid_scenes_round_trip(lines in proptest::collection::vec(scene_line(), 0..20)) {
        let scene = Scene { lines };
        let again = Scene::parse(scene.to_text().as_bytes(), "written.in").unwrap();
        prop_assert_eq!(scene, again);
    }

    /// Valid texts with one random edit: a deleted, inserted or replaced
    /// byte. They either parse or fail with a located error; never panic.
    #[test]
    fn near_valid_texts_never_panic(
        lines in proptest::collection::vec(scene_line(), 1..6),
        at in any::<prop::sample::Index>(),
        edit in 0u8..3,
        byte in prop_oneof![Just(b'('), Just(b')'), Just(b','), Just(b'\n'), Just(b' '), Just(b'-'),
                            Just(b'.'), Just(b'e'), Just(b'9'), any::<u8>()],
    ) {
        let mut text = Scene { lines }.to_text().into_bytes();
        let i = at.index(text.len());
        match edit {
            0 => { text.remove(i); }
            1 => text.insert(i, byte),
            _ => text[i] = byte,
        }
        if let Err(e) = Scene::parse(&text, "edited.in") {
            let lines = text.iter().filter(|&&b| b == b'\n').count() + 1;
            prop_assert!(e.line >= 1 && e.line <= lines, "line {} of {}", e.line, lines);
            prop_assert!(e.to_string().starts_with("edited.in:"));
        }
    }
}
