//! The text the original program printed around a run, which every front
//! end (the command line, the web page) prints the same way: a header
//! naming the frames and the input, and the results block.

use crate::generate::{SceneKind, DEFAULT_LINES, DEFAULT_SEED};
use crate::Counters;

/// The header: the frames asked for (`None`: an endless run) and the
/// input's name.
pub fn header(frames: Option<u64>, input: &str) -> String {
    let frames = frames.map_or("endless".to_string(), |f| f.to_string());
    format!("Number of frames = {frames}\nInput file path is: {input}\n")
}

/// The input's name for a generated scene.
pub fn generated_input(kind: SceneKind, lines: usize, seed: u64) -> String {
    format!("(none: generated {kind} scene, {lines} lines, seed {seed})")
}

/// The input's name for the built-in scene.
pub fn built_in_input() -> String {
    format!("(none: built-in scene, {DEFAULT_LINES} lines, seed {DEFAULT_SEED})")
}

/// The results block: the simulation's time in seconds and both counters.
pub fn results(seconds: f64, counters: Counters) -> String {
    format!(
        "---- RESULTS ----\nElapsed execution time: {seconds:.6}s\n{} Line-Wall Collisions\n{} Line-Line Collisions\n---- END RESULTS ----\n",
        counters.wall, counters.line
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texts_are_the_original_programs() {
        assert_eq!(
            header(Some(300), "mit.in"),
            "Number of frames = 300\nInput file path is: mit.in\n"
        );
        assert_eq!(
            generated_input(SceneKind::Uniform, 2000, 7),
            "(none: generated uniform scene, 2000 lines, seed 7)"
        );
        assert_eq!(
            built_in_input(),
            "(none: built-in scene, 1000 lines, seed 6172)"
        );
        assert_eq!(
            header(None, "x").lines().next(),
            Some("Number of frames = endless")
        );
        let counters = Counters {
            wall: 495,
            line: 13446,
        };
        assert_eq!(
            results(0.0302781, counters),
            "---- RESULTS ----\nElapsed execution time: 0.030278s\n495 Line-Wall Collisions\n\
             13446 Line-Line Collisions\n---- END RESULTS ----\n"
        );
    }
}
