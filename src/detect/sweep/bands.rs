//! Bands: where one direction alone would meet too many boxes, the plane is
//! cut across a second direction into bands of equal width, each box goes
//! into every band it reaches, and each band is swept on its own.
//!
//! A pair of boxes that overlap lies together in every band from the one
//! holding the larger of their two least values (across the bands) to the
//! one holding the smaller of their greatest; it is reported only in the
//! first of these, so once.

use super::hull::{hi, lo, Packed};
use super::order::{Boxes, NO_KEY};

/// How the plane is cut: across which direction, into how many bands,
/// where they start and how wide they are.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Bands {
    /// The direction the bands are cut across (0..4: x, y, u, w).
    pub across: usize,
    /// How many bands (at least 1).
    pub count: usize,
    /// Where the first band starts along `across`.
    pub start: f32,
    /// Bands per unit along `across`.
    pub per_unit: f32,
}

impl Bands {
    /// A single band: a plain sweep.
    pub(crate) fn one() -> Self {
        Self {
            across: 0,
            count: 1,
            start: 0.0,
            per_unit: 0.0,
        }
    }

    /// `count` bands cut across direction `across`, spread evenly over
    /// `[from, to]`; values beyond fall into the first or last band.
    pub(crate) fn spanning(across: usize, count: usize, from: f32, to: f32) -> Self {
        let count = count.max(1);
        let width = to - from;
        if count == 1 || width.is_nan() || width <= 0.0 || !width.is_finite() {
            return Self {
                across,
                ..Self::one()
            };
        }
        Self {
            across,
            count,
            start: from,
            per_unit: count as f32 / width,
        }
    }

    /// The band holding value `v` along `across` (`v` is not NaN).
    #[inline]
    pub(crate) fn of(&self, v: f32) -> usize {
        if self.count == 1 {
            return 0;
        }
        // The float-to-integer cast saturates: below the start (and -inf)
        // gives 0, beyond the end gives a huge index, clamped to the last.
        (((v - self.start) * self.per_unit) as usize).min(self.count - 1)
    }

    /// The first and last band a packed box reaches.
    #[inline]
    pub(crate) fn span(&self, p: &Packed) -> (usize, usize) {
        (self.of(lo(p, self.across)), self.of(hi(p, self.across)))
    }

    /// True when band `band` is the one that reports the pair of boxes `a`
    /// and `b` (which overlap, and both lie in `band`).
    #[inline]
    pub(crate) fn reports(&self, band: usize, a: &Packed, b: &Packed) -> bool {
        self.count == 1 || self.of(lo(a, self.across).max(lo(b, self.across))) == band
    }
}

/// The boxes laid out band after band, each band sorted by least value
/// along the sweep direction and closed by a sentinel whose key is
/// [`NO_KEY`] (so a scan stops there without a bounds test).
#[derive(Debug, Default)]
pub(crate) struct Layout {
    /// Least value along the sweep direction, per entry.
    pub keys: Vec<f32>,
    /// Packed hull, per entry.
    pub hulls: Vec<Packed>,
    /// Line id (or box index), per entry.
    pub ids: Vec<u32>,
    /// Where each band's entries start; band `b` ends at `starts[b + 1] - 1`,
    /// its sentinel.
    pub starts: Vec<usize>,
    /// Per sorted box, the bands it reaches.
    spans: Vec<(u32, u32)>,
    /// Per band, the next free entry while scattering.
    cursor: Vec<usize>,
}

impl Layout {
    /// Lays out the first `boxed` of `sorted` (whose keys are real and in
    /// order) in `bands`, of which there are several.
    pub(crate) fn build(&mut self, sorted: &Boxes, boxed: usize, bands: &Bands) {
        let (keys, hulls, ids) = (
            &sorted.keys[..boxed],
            &sorted.hulls[..boxed],
            &sorted.ids[..boxed],
        );
        // Count each band's entries, then scatter in sorted order, which
        // keeps every band sorted.
        self.spans.clear();
        self.cursor.clear();
        self.cursor.resize(bands.count + 1, 0);
        self.spans.extend(hulls.iter().map(|hull| {
            let (first, last) = bands.span(hull);
            (first as u32, last as u32)
        }));
        for &(first, last) in &self.spans {
            for band in first..=last {
                self.cursor[band as usize] += 1;
            }
        }
        self.starts.clear();
        let mut total = 0;
        for c in &mut self.cursor[..bands.count] {
            self.starts.push(total);
            let entries = *c;
            *c = total;
            total += entries + 1;
        }
        self.starts.push(total);
        // Every entry is written below; only the sentinels need their key.
        self.keys.resize(total, NO_KEY);
        self.hulls.resize(total, [0.0; 8]);
        self.ids.resize(total, u32::MAX);
        for &start in &self.starts[1..] {
            self.keys[start - 1] = NO_KEY;
        }
        let (out_keys, out_hulls, out_ids) = (
            &mut self.keys[..total],
            &mut self.hulls[..total],
            &mut self.ids[..total],
        );
        for (k, &(first, last)) in self.spans.iter().enumerate() {
            for band in first..=last {
                let at = self.cursor[band as usize];
                self.cursor[band as usize] = at + 1;
                out_keys[at] = keys[k];
                out_hulls[at] = hulls[k];
                out_ids[at] = ids[k];
            }
        }
    }

    /// Entries laid out, sentinels included.
    pub(crate) fn len(&self) -> usize {
        self.keys.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_fall_into_bands_and_beyond_into_the_ends() {
        let b = Bands::spanning(1, 4, 0.0, 1.0);
        assert_eq!(b.of(-5.0), 0);
        assert_eq!(b.of(f32::NEG_INFINITY), 0);
        assert_eq!(b.of(0.3), 1);
        assert_eq!(b.of(0.99), 3);
        assert_eq!(b.of(f32::MAX), 3);
        // Degenerate spreads give one band.
        assert_eq!(Bands::spanning(1, 4, 1.0, 1.0).count, 1);
        assert_eq!(Bands::spanning(1, 4, 0.0, f32::INFINITY).count, 1);
    }

    #[test]
    fn a_box_goes_into_every_band_it_reaches_in_order() {
        let hull = |lo_y: f32, hi_y: f32| -> Packed {
            let n = f32::NEG_INFINITY;
            [0.0, lo_y, n, n, -1.0, -hi_y, n, n]
        };
        let mut sorted = Boxes::default();
        sorted.reset(3);
        sorted.keys[..3].copy_from_slice(&[0.0, 0.5, 0.7]);
        sorted.hulls[..3].copy_from_slice(&[hull(0.1, 0.9), hull(0.1, 0.2), hull(0.6, 0.7)]);
        sorted.ids[..3].copy_from_slice(&[11, 10, 12]);
        let bands = Bands::spanning(1, 2, 0.0, 1.0);
        let mut layout = Layout::default();
        layout.build(&sorted, 3, &bands);
        // Band 0: ids 11, 10, sentinel; band 1: ids 11, 12, sentinel.
        assert_eq!(layout.starts, vec![0, 3, 6]);
        assert_eq!(layout.ids, vec![11, 10, u32::MAX, 11, 12, u32::MAX]);
        assert_eq!(layout.keys, vec![0.0, 0.5, NO_KEY, 0.0, 0.7, NO_KEY]);
        // 11 and 12 overlap in band 1 only; 10 and 11 in band 0 only.
        let h = &sorted.hulls;
        assert!(bands.reports(1, &h[0], &h[2]));
        assert!(!bands.reports(0, &h[0], &h[2]));
        assert!(bands.reports(0, &h[0], &h[1]));
    }
}
