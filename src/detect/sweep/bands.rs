//! Bands: where one direction alone would meet too many boxes, the plane is
//! cut across a second direction into bands of equal width, each box goes
//! into every band it reaches, and each band is swept on its own.
//!
//! A pair of boxes that overlap lies together in every band from the one
//! holding the larger of their two least values (across the bands) to the
//! one holding the smaller of their greatest; it is reported only in the
//! first of these, so once. (The boxes themselves are laid out in
//! [`super::layout`].)

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
    /// The last band's number, as a float.
    last: f32,
}

impl Default for Bands {
    /// A single band: a plain sweep.
    fn default() -> Self {
        Self {
            across: 0,
            count: 1,
            start: 0.0,
            per_unit: 0.0,
            last: 0.0,
        }
    }
}

impl Bands {
    /// `count` bands cut across direction `across`, spread evenly over
    /// `[from, to]`; values beyond fall into the first or last band.
    pub(crate) fn spanning(across: usize, count: usize, from: f32, to: f32) -> Self {
        let count = count.max(1);
        let width = to - from;
        if count == 1 || width.is_nan() || width <= 0.0 || !width.is_finite() {
            return Self {
                across,
                ..Self::default()
            };
        }
        Self {
            across,
            count,
            start: from,
            per_unit: count as f32 / width,
            last: (count - 1) as f32,
        }
    }

    /// The band holding value `v` along `across` (`v` is not NaN).
    #[inline]
    pub(crate) fn of(&self, v: f32) -> usize {
        // Clamped to [0, last band] while still a float (NaN, from
        // `inf * 0` with one band, fails the first test and gives 0), so
        // that the conversion is a plain truncation.
        let t = (v - self.start) * self.per_unit;
        let t = if t > 0.0 { t } else { 0.0 };
        let t = if t < self.last { t } else { self.last };
        t as u32 as usize
    }

    /// The least value in band `band` (`1..count`): a value `v` is in
    /// band `band` or above exactly when `v >= self.edge(band)`, so a
    /// comparison can stand in for [`Bands::of`].
    pub(crate) fn edge(&self, band: usize) -> f32 {
        debug_assert!((1..self.count).contains(&band));
        let mut v = self.start + band as f32 / self.per_unit;
        // A few steps of one unit in the last place at most: `of` is
        // monotone, and `v` is within a rounding or two of the edge.
        while self.of(v) >= band && v > f32::MIN {
            v = v.next_down();
        }
        while self.of(v) < band {
            v = v.next_up();
        }
        v
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
    fn an_edge_is_the_least_value_of_its_band() {
        for (count, from, to) in [
            (4, 0.0, 1.0),
            (7, -3.3, 0.1),
            (1000, 0.5, 1.0),
            (3, 1e-30, 3e-30),
        ] {
            let b = Bands::spanning(1, count, from, to);
            for band in 1..count {
                let e = b.edge(band);
                assert_eq!(b.of(e), band, "{count} bands, band {band}");
                assert_eq!(b.of(e.next_down()), band - 1, "{count} bands, band {band}");
            }
        }
    }
}
