//! Where a team's groups of bands meet: the seams of the bands
//! ([`Bands::with_seams`]), moved now and then towards where each pair of
//! neighbouring groups would take as long to lay out and sweep.
//!
//! Bands of equal width hold unequal work, and a band of `koch`'s twelve
//! is about a twelfth of it: split between two threads at the band edge
//! nearest half the homes, one thread's part of the layout and sweep took
//! 15 us where the other's took 20. The threads' own speeds differ too, on
//! a shared machine by up to a third for tens of milliseconds at a time,
//! which only their times show; so the seams follow the times.
//!
//! Every box a seam passes changes band, which the kept layout pays for
//! as for any box that leaves its band; moved every step, by what one
//! step's times said, the seams cost about as much as they saved on
//! `koch`. They move once every `EVERY` steps, by what those steps' times
//! say together.

use super::bands::Bands;
use super::layout::Layout;
use std::time::Duration;

/// Steps whose times a move of the seams rests on.
const EVERY: u32 = 16;

/// The share of the way to even times that a seam moves.
const GAIN: f64 = 0.5;

/// Most a seam moves at a time, as a share of the boxes of the two groups
/// beside it: a run of slow steps on one thread may be anything.
const MOST: f64 = 0.05;

/// The seams, and the times of the steps since they last moved.
#[derive(Debug, Default)]
pub(crate) struct Seams {
    values: Vec<f32>,
    /// Per group: the time its thread took, and its boxes (homes and
    /// guests), summed over the steps since the seams last moved.
    took: Vec<f64>,
    entries: Vec<f64>,
    steps: u32,
}

impl Seams {
    /// Where the groups meet, ascending; empty until groups have been
    /// timed.
    pub(crate) fn values(&self) -> &[f32] {
        &self.values
    }

    /// Sets the seams (for tests that move them where times would not).
    #[cfg(test)]
    pub(crate) fn set(&mut self, values: Vec<f32>) {
        self.values = values;
    }

    /// Forgets the seams (for bands cut across another direction).
    pub(crate) fn clear(&mut self) {
        *self = Self::default();
    }

    /// Adds a step whose groups of `bands` were laid out and swept, as
    /// `layout` holds them: group `g` in `groups`' `g`-th time, of as many
    /// boxes as it gives; every `EVERY` steps, moves the seams.
    pub(crate) fn add_step(
        &mut self,
        bands: &Bands,
        layout: &Layout,
        groups: impl ExactSizeIterator<Item = (Duration, usize)>,
    ) {
        if self.took.len() != groups.len() {
            self.clear();
            self.took.resize(groups.len(), 0.0);
            self.entries.resize(groups.len(), 0.0);
        }
        for (g, (took, entries)) in groups.enumerate() {
            self.took[g] += took.as_secs_f64();
            self.entries[g] += entries as f64;
        }
        self.steps += 1;
        if self.steps < EVERY {
            return;
        }
        self.values = self.moved(bands, layout);
        self.steps = 0;
        self.took.fill(0.0);
        self.entries.fill(0.0);
    }

    /// The seams moved by the times summed.
    fn moved(&self, bands: &Bands, layout: &Layout) -> Vec<f32> {
        let groups = self.took.len();
        let firsts: Vec<usize> = match bands.seams().len() + 1 == groups {
            true => bands.seam_bands().collect(),
            // Not yet seamed: the groups as they were, by their homes.
            false => (layout.group_bounds(bands, groups)[1..].iter())
                .map(|g| g.start)
                .collect(),
        };
        if firsts.len() + 1 != groups {
            return Vec::new();
        }
        let band_width = 1.0 / f64::from(bands.per_unit);
        let steps = f64::from(self.steps);
        (firsts.iter().enumerate())
            .map(|(g, &first)| {
                let at = f64::from(bands.edge(first));
                let (low, high) = (self.took[g], self.took[g + 1]);
                // How much longer the group below took than the one
                // above, the boxes to hand on for that, and how many
                // boxes a unit across holds there (the two bands beside
                // the seam).
                let late = (low - high) / (low + high).max(1e-12);
                let beside = (self.entries[g] + self.entries[g + 1]) / steps;
                let boxes = (GAIN * late).clamp(-MOST, MOST) * beside / 2.0;
                let near = layout.homes(first - 1).len() + layout.homes(first).len();
                let density = (near as f64).max(1.0) / (2.0 * band_width);
                (at - boxes / density) as f32
            })
            .collect()
    }
}
