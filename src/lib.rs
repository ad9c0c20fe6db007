//! Line segments bouncing in a box, bit for bit as the MIT 6.172
//! "screensaver" program computed them, with fast collision detection.
//!
//! ```
//! use screensaver::{DetectorConfig, DetectorKind, Scene, World};
//!
//! let config = DetectorConfig { threads: 2, ..DetectorConfig::default() };
//! let mut world = World::with_config(&Scene::built_in(), DetectorKind::Sweep, &config)
//!     .expect("two threads");
//! world.run(1001); // 1000 frames, as `screensaver 1000` runs them
//! assert_eq!(world.counters().wall, 1352);
//! ```
//!
//! The API, in the order a program meets it:
//!
//! - A [`World`] holds lines ([`Line`], [`Color`]) moving in the box
//!   `[0.5, 1] x [0.5, 1]`, from a [`Scene`] (an `.in` file, or one of
//!   [`generate`]'s seeded scenes) or from lines of your own
//!   ([`World::from_lines`]). It finds collisions with a detector chosen by
//!   kind ([`DetectorKind`]: the sweep, the quadtree or all pairs) and
//!   tuned by a [`DetectorConfig`], threads given as a count; results are
//!   the same for any detector and any number of threads. [`World::step`]
//!   and [`World::run`] step it; [`World::counters`] counts the
//!   collisions, [`World::last_events`] lists the last step's ([`Event`]).
//! - [`run::Run`] runs steps with what may go around them: the check of
//!   every step against all pairs, pictures ([`render::Recorder`]),
//!   [`checkpoint`]s every so many steps, a progress callback and a way to
//!   stop; [`report`] words the original program's text and holds the
//!   statistics as data.
//! - [`render`] draws pictures of a world (PNG, GIF, SVG, or pixels of your
//!   own with [`render::Canvas`]) and, with the `window` feature, shows a
//!   run on screen ([`render::Screen`]).
//! - [`broad_phase`] is the sweep's broad phase on boxes of your own, with
//!   the all-pairs answer beside it.
//! - [`maths`] holds the project's own `hypot` and `atan2`, the same on
//!   every platform; [`intersect`] is the exact pair test.

#![warn(missing_docs)]

pub mod broad_phase;
pub mod checkpoint;
mod counters;
pub(crate) mod decimal;
pub(crate) mod detect;
mod fnv;
#[cfg(any(test, fuzzing))]
pub mod fuzz_checks;
pub mod generate;
pub(crate) mod geometry;
pub(crate) mod index;
pub(crate) mod lanes;
pub(crate) mod line;
pub mod maths;
pub(crate) mod motion;
pub(crate) mod narrow;
pub(crate) mod output;
#[cfg(feature = "render")]
pub mod render;
pub mod report;
pub(crate) mod response;
pub(crate) mod rows;
pub mod run;
pub mod scene;
pub(crate) mod schedule;
pub(crate) mod scoped;
#[cfg(feature = "signals")]
pub(crate) mod stop;
pub(crate) mod storage;
pub(crate) mod team;
pub(crate) mod verify;
pub(crate) mod world;

/// Parts of the library that are not its API, public only with the
/// `internals` feature, for the project's own measuring tools
/// (`bench/examples/hand_off.rs`, `libm_compare.rs`, `draw_speed.rs`): they may
/// change with any release.
#[cfg(feature = "internals")]
pub mod internals {
    pub use crate::maths::classes;
    #[cfg(feature = "render")]
    pub use crate::render::raster::{draw_thin, draw_thin_each};
    pub use crate::team::Team;

    /// Draws `lines` with tiny-skia's anti-aliased strokes, as pictures up
    /// to 5,000 lines are drawn.
    #[cfg(feature = "render")]
    pub fn draw_in_view(
        lines: &[crate::Line],
        colors: &[crate::Color],
        pixmap: &mut tiny_skia::Pixmap,
        view: &crate::render::View,
    ) {
        crate::render::draw_in_view(lines, colors, pixmap, view);
    }
}

#[cfg(test)]
mod test_util;

/// `n` things, in the singular for one.
pub(crate) fn plural(n: u64, thing: &str) -> String {
    if n == 1 {
        format!("1 {thing}")
    } else {
        format!("{n} {thing}s")
    }
}

pub use detect::{DetectorConfig, DetectorKind, DetectorStats, KeepPairs};
pub use geometry::Vec2;
pub use index::LineId;
pub use line::{Color, Line};
pub use narrow::{intersect, Event, IntersectionKind};
pub use output::{check_writable, FileIdentity, OutputError};
pub use scene::{Scene, SceneLine};
#[cfg(feature = "signals")]
pub use stop::Signal;
pub use world::{Counters, ThreadsError, World};
