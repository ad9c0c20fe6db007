//! Line segments bouncing in a box, bit for bit as the MIT 6.172
//! "screensaver" program computed them, with fast collision detection.
//!
//! ```
//! use screensaver::{generate::default_scene, DetectorKind, World};
//!
//! let mut world = World::with_detector(&default_scene(), DetectorKind::Brute);
//! world.run(11);
//! let counts = world.counters();
//! println!("{} wall, {} line collisions", counts.wall, counts.line);
//! ```
//!
//! The modules follow the simulation's concepts: [`geometry`] (vectors and
//! exact predicates), [`line`](mod@line) (segments and coordinates),
//! [`scene`] (`.in` files), [`narrow`] (the exact pair test), `response`
//! (new velocities), [`world`] (one step), `storage` (lines stored in the
//! detector's order), [`detect`] (interchangeable broad
//! phases), [`render`] (pictures and the window), [`generate`] (seeded
//! scenes), [`checkpoint`] (states and resumable checkpoints), [`output`]
//! (files written whole or not at all), [`stop`] (clean stops on
//! signals) and [`team`] (the threads a step's phases are shared among).

pub mod broad_phase;
pub mod checkpoint;
mod counters;
pub mod detect;
pub mod generate;
pub mod geometry;
#[cfg(feature = "window")]
pub mod job;
pub mod line;
pub mod maths;
pub(crate) mod motion;
pub mod narrow;
pub mod output;
#[cfg(feature = "render")]
pub mod render;
pub mod report;
pub(crate) mod response;
pub mod run;
pub mod scene;
#[cfg(feature = "signals")]
pub mod stop;
pub(crate) mod storage;
pub mod team;
pub mod world;

#[cfg(test)]
mod test_util;

/// Finds the value of `all` whose `name` is `s`, for the command line's
/// named choices; the error lists the names there are.
pub(crate) fn parse_named<T: Copy>(
    all: &[T],
    name: fn(T) -> &'static str,
    what: &str,
    s: &str,
) -> Result<T, String> {
    all.iter().copied().find(|&v| name(v) == s).ok_or_else(|| {
        let names: Vec<_> = all.iter().map(|&v| name(v)).collect();
        format!(
            "unknown {what} `{s}`; expected one of: {}",
            names.join(", ")
        )
    })
}

/// `n` things, in the singular for one.
pub(crate) fn plural(n: u64, thing: &str) -> String {
    if n == 1 {
        format!("1 {thing}")
    } else {
        format!("{n} {thing}s")
    }
}

pub use detect::{Detector, DetectorConfig, DetectorKind, DetectorStats};
pub use geometry::Vec2;
pub use line::{Color, Line};
pub use narrow::{intersect, is_sliver, Event, IntersectionKind};
pub use scene::{Scene, SceneLine};
pub use world::{Counters, Mismatch, ThreadsError, World};
