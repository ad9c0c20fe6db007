//! Seeded scene generation: the built-in default scene and scenes of any
//! size for benchmarks and stress runs.
//!
//! Generated scenes keep roughly the density and speeds of the course
//! scenes: up to a thousand lines they use course-like sizes; beyond that,
//! lengths and speeds shrink with `1/sqrt(n)` so that the fraction of the
//! window covered, and the collisions per line per step, stay about the same.
//! The same kind, count and seed always give the same scene, on every
//! platform: ChaCha8 has a fixed, documented output stream, and directions
//! take their sine and cosine from the `libm` crate (the same code
//! everywhere) rather than from the platform's maths library.

use crate::geometry::Vec2;
use crate::line::{Color, WINDOW_HEIGHT, WINDOW_WIDTH};
use crate::output::OutputError;
use crate::scene::{Scene, SceneLine};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;
use std::fmt;

/// The arrangement of a generated scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum SceneKind {
    /// Lines scattered evenly over the window in random directions.
    Uniform,
    /// Lines bunched in a few dense clusters, each drifting as a group.
    Clustered,
    /// Concentric rings of radial lines flying outward, like `explosion.in`.
    Ring,
    /// A regular lattice of short lines with random velocities.
    Grid,
}

impl SceneKind {
    /// Every kind, in the order they are listed to users.
    pub const ALL: &'static [SceneKind] = &[
        SceneKind::Uniform,
        SceneKind::Clustered,
        SceneKind::Ring,
        SceneKind::Grid,
    ];

    /// The arrangement named `name` ([`SceneKind::name`]), if one is.
    pub fn from_name(name: &str) -> Option<SceneKind> {
        Self::ALL.iter().copied().find(|k| k.name() == name)
    }

    /// The name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            SceneKind::Uniform => "uniform",
            SceneKind::Clustered => "clustered",
            SceneKind::Ring => "ring",
            SceneKind::Grid => "grid",
        }
    }
}

impl SceneKind {
    /// Writes the scene [`generate`] makes, in the `.in` format, streaming
    /// it: even huge scenes are never held in memory.
    pub fn write(
        self,
        lines: usize,
        seed: u64,
        out: &mut dyn std::io::Write,
    ) -> std::io::Result<()> {
        crate::scene::write_scene(out, lines, generate_iter(self, lines, seed))
    }

    /// [`SceneKind::write`] into the file at `path`, whole or not at all.
    pub fn save(self, lines: usize, seed: u64, path: &std::path::Path) -> Result<(), OutputError> {
        crate::output::write_with(path, |out| self.write(lines, seed, out))
    }
}

impl fmt::Display for SceneKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl Scene {
    /// Lines in the built-in scene, and in a generated scene unless asked.
    pub const BUILT_IN_LINES: usize = 1000;
    /// Seed of the built-in scene, and of a generated scene unless asked.
    pub const BUILT_IN_SEED: u64 = 6172;

    /// The built-in scene the program runs when given no input file: a
    /// thousand uniform lines in both colours, dense enough for a steady
    /// stream of collisions.
    pub fn built_in() -> Scene {
        generate(
            SceneKind::Uniform,
            Self::BUILT_IN_LINES,
            Self::BUILT_IN_SEED,
        )
    }
}

/// A scene of `lines` lines of the given kind; the same arguments always
/// give the same scene.
///
/// ```
/// use screensaver::generate::{generate, SceneKind};
///
/// let scene = generate(SceneKind::Clustered, 5_000, 42);
/// assert_eq!(scene.lines.len(), 5_000);
/// assert_eq!(scene, generate(SceneKind::Clustered, 5_000, 42));
/// ```
pub fn generate(kind: SceneKind, lines: usize, seed: u64) -> Scene {
    Scene {
        lines: generate_iter(kind, lines, seed).collect(),
    }
}

/// The lines of [`generate`] one at a time, for writing huge scenes without
/// holding them in memory.
pub(crate) fn generate_iter(
    kind: SceneKind,
    lines: usize,
    seed: u64,
) -> impl Iterator<Item = SceneLine> {
    let mut gen = Generator::new(kind, lines, seed);
    (0..lines).map(move |i| gen.line(i))
}

struct Generator {
    kind: SceneKind,
    rng: ChaCha8Rng,
    n: usize,
    /// Shrinks lengths and speeds as the scene grows past a thousand lines.
    scale: f64,
    clusters: Vec<(Vec2, Vec2, f64)>,
    grid_cols: usize,
}

impl Generator {
    fn new(kind: SceneKind, n: usize, seed: u64) -> Self {
        let mut rng =
            ChaCha8Rng::seed_from_u64(seed ^ (kind as u64).wrapping_mul(0x9e37_79b9_7f4a_7c15));
        let scale = (1000.0 / n.max(1000) as f64).sqrt();
        let clusters = if kind == SceneKind::Clustered {
            let count = (n as f64).sqrt().clamp(1.0, 64.0) as usize;
            (0..count)
                .map(|_| {
                    let centre = Vec2::new(
                        rng.random_range(0.15..0.85) * WINDOW_WIDTH,
                        rng.random_range(0.15..0.85) * WINDOW_HEIGHT,
                    );
                    let drift = random_direction(&mut rng) * rng.random_range(0.2..1.5) * scale;
                    let radius = rng.random_range(30.0..120.0) * scale.sqrt();
                    (centre, drift, radius)
                })
                .collect()
        } else {
            Vec::new()
        };
        let grid_cols = ((n as f64 * WINDOW_WIDTH / WINDOW_HEIGHT).sqrt().ceil() as usize).max(1);
        Self {
            kind,
            rng,
            n,
            scale,
            clusters,
            grid_cols,
        }
    }

    fn line(&mut self, i: usize) -> SceneLine {
        let s = self.scale;
        let (centre, dir, half, v) = match self.kind {
            SceneKind::Uniform => {
                let centre = Vec2::new(
                    self.rng.random_range(0.02..0.98) * WINDOW_WIDTH,
                    self.rng.random_range(0.02..0.98) * WINDOW_HEIGHT,
                );
                let dir = random_direction(&mut self.rng);
                let half = self.rng.random_range(4.0..16.0) * s;
                let v = random_direction(&mut self.rng) * self.rng.random_range(0.3..3.0) * s;
                (centre, dir, half, v)
            }
            SceneKind::Clustered => {
                let (c, drift, radius) = self.clusters[i % self.clusters.len()];
                let r = radius * self.rng.random_range(0.0f64..1.0).sqrt();
                let centre = c + random_direction(&mut self.rng) * r;
                let dir = random_direction(&mut self.rng);
                let half = self.rng.random_range(2.0..8.0) * s;
                let v =
                    drift + random_direction(&mut self.rng) * self.rng.random_range(0.0..0.5) * s;
                (centre, dir, half, v)
            }
            SceneKind::Ring => {
                let rings = ((self.n as f64).sqrt() / 4.0).ceil().max(1.0) as usize;
                let ring = i % rings;
                let angle = TAU * (i / rings) as f64 / (self.n / rings).max(1) as f64
                    + self.rng.random_range(0.0..0.01);
                let dir = Vec2::new(libm::cos(angle), libm::sin(angle));
                let radius = 20.0 + 360.0 * (ring as f64 + 0.5) / rings as f64;
                let centre = Vec2::new(WINDOW_WIDTH / 2.0, WINDOW_HEIGHT / 2.0)
                    + Vec2::new(dir.x * radius * 1.4, dir.y * radius);
                let half = 6.0 * s;
                let v = dir * self.rng.random_range(0.5..2.0) * s;
                (centre, dir, half, v)
            }
            SceneKind::Grid => {
                let cols = self.grid_cols;
                let rows = self.n.div_ceil(cols).max(1);
                let (cx, cy) = ((i % cols) as f64 + 0.5, (i / cols) as f64 + 0.5);
                let centre = Vec2::new(
                    cx / cols as f64 * WINDOW_WIDTH,
                    cy / rows as f64 * WINDOW_HEIGHT,
                );
                let cell = (WINDOW_WIDTH / cols as f64).min(WINDOW_HEIGHT / rows as f64);
                let dir = if i % 2 == 0 {
                    Vec2::new(1.0, 0.0)
                } else {
                    Vec2::new(0.0, 1.0)
                };
                let half = cell * 0.3;
                let v = random_direction(&mut self.rng) * self.rng.random_range(0.2..2.0) * s;
                (centre, dir, half, v)
            }
        };
        let color = if self.rng.random_bool(0.5) {
            Color::Red
        } else {
            Color::Gray
        };
        SceneLine {
            p1: round6(centre + dir * half),
            p2: round6(centre - dir * half),
            v: round6(v),
            color,
        }
    }
}

fn random_direction(rng: &mut ChaCha8Rng) -> Vec2 {
    let a = rng.random_range(0.0..TAU);
    Vec2::new(libm::cos(a), libm::sin(a))
}

/// Rounds to six decimals, like the course files, so written scenes stay
/// short and read back to exactly the values generated.
fn round6(p: Vec2) -> Vec2 {
    let r = |x: f64| (x * 1e6).round() / 1e6;
    Vec2::new(r(p.x), r(p.y))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generation_is_deterministic_and_seed_dependent() {
        for &kind in SceneKind::ALL {
            let a = generate(kind, 300, 7);
            assert_eq!(a, generate(kind, 300, 7), "{kind}");
            assert_ne!(a, generate(kind, 300, 8), "{kind}");
            assert_eq!(a.lines.len(), 300);
        }
    }

    #[test]
    fn generated_scenes_are_valid_and_round_trip() {
        for &kind in SceneKind::ALL {
            for n in [0, 1, 2, 17, 1000, 5000] {
                let scene = generate(kind, n, 1);
                let again = Scene::parse(scene.to_text().as_bytes(), "gen").unwrap();
                assert_eq!(scene, again, "{kind} {n}");
                for l in &scene.lines {
                    for x in [l.p1.x, l.p1.y, l.p2.x, l.p2.y, l.v.x, l.v.y] {
                        assert!(x.is_finite());
                    }
                }
            }
        }
    }

    #[test]
    fn lines_start_near_the_window() {
        for &kind in SceneKind::ALL {
            for l in generate(kind, 2000, 3).lines {
                for p in [l.p1, l.p2] {
                    assert!((-60.0..WINDOW_WIDTH + 60.0).contains(&p.x), "{kind} {p:?}");
                    assert!((-60.0..WINDOW_HEIGHT + 60.0).contains(&p.y), "{kind} {p:?}");
                }
            }
        }
    }

    #[test]
    fn both_colours_appear() {
        let s = Scene::built_in();
        assert_eq!(s.lines.len(), Scene::BUILT_IN_LINES);
        assert!(s.lines.iter().any(|l| l.color == Color::Red));
        assert!(s.lines.iter().any(|l| l.color == Color::Gray));
    }

    #[test]
    fn kind_names_round_trip() {
        for &kind in SceneKind::ALL {
            assert_eq!(SceneKind::from_name(kind.name()), Some(kind));
        }
        assert_eq!(SceneKind::from_name("spiral"), None);
    }
}
