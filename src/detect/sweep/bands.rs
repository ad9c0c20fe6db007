//! Bands: where one direction alone would meet too many boxes, the plane is
//! cut across a second direction into bands of equal width, each box goes
//! into every band it reaches, and each band is swept on its own.
//!
//! A pair of boxes that overlap lies together in every band from the one
//! holding the larger of their two least values (across the bands) to the
//! one holding the smaller of their greatest; it is reported only in the
//! first of these, so once. (The boxes themselves are laid out in
//! [`super::layout`].)
//!
//! On a team, each thread lays out and sweeps a group of bands. Bands of
//! equal width hold unequal work, so the edge where two groups meet (a
//! *seam*) may be moved off the even grid by up to half a band either way
//! ([`Bands::with_seams`]): a seam moved a little from step to step evens
//! out the groups' work without more bands, and only the boxes it passes
//! change band.

use super::hull::{hi, lo, Packed};

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
    /// Where groups of bands meet, if they are set ([`Bands::with_seams`]):
    /// band `seam_bands[g]` starts at `seams[g]` instead of its even edge,
    /// for `g` in `0..seam_count`, the bands ascending.
    seams: [f32; MOST_SEAMS],
    seam_bands: [u32; MOST_SEAMS],
    seam_count: u8,
}

/// The most seams a cut may have: groups of bands beyond sixteen meet at
/// even edges.
pub(crate) const MOST_SEAMS: usize = 15;

/// How far a seam may lie from its even edge, in bands: under half, so that
/// it moves only the edge between the two bands beside it.
const SEAM_REACH: f32 = 0.45;

impl Bands {
    /// A single band: a plain sweep.
    pub(crate) fn one() -> Self {
        Self {
            across: 0,
            count: 1,
            start: 0.0,
            per_unit: 0.0,
            last: 0.0,
            seams: [0.0; MOST_SEAMS],
            seam_bands: [0; MOST_SEAMS],
            seam_count: 0,
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
            last: (count - 1) as f32,
            ..Self::one()
        }
    }

    /// The same bands with groups meeting at `seams` (ascending values
    /// across): each seam becomes the least value of the band whose even
    /// edge is nearest it, held within half a band of that edge; a seam
    /// whose band is taken by the one before it or is the first is dropped.
    /// With no seams, the even cut.
    pub(crate) fn with_seams(&self, seams: &[f32]) -> Self {
        let mut cut = Self {
            seams: [0.0; MOST_SEAMS],
            seam_bands: [0; MOST_SEAMS],
            seam_count: 0,
            ..*self
        };
        if self.count < 2 {
            return cut;
        }
        for &s in seams.iter().take(MOST_SEAMS) {
            let t = (s - self.start) * self.per_unit;
            if !t.is_finite() {
                continue;
            }
            let band = t.round().clamp(1.0, self.last) as u32;
            let taken = cut.seam_count > 0 && cut.seam_bands[cut.seam_count as usize - 1] >= band;
            if taken {
                continue;
            }
            let even = self.even_edge(band as usize);
            let reach = SEAM_REACH / self.per_unit;
            cut.seams[cut.seam_count as usize] = s.clamp(even - reach, even + reach);
            cut.seam_bands[cut.seam_count as usize] = band;
            cut.seam_count += 1;
        }
        cut
    }

    /// The bands that start at a seam, ascending.
    pub(crate) fn seam_bands(&self) -> impl Iterator<Item = usize> + '_ {
        self.seam_bands[..self.seam_count as usize]
            .iter()
            .map(|&b| b as usize)
    }

    /// The seams' values, ascending.
    pub(crate) fn seams(&self) -> &[f32] {
        &self.seams[..self.seam_count as usize]
    }

    /// Whether `other` cuts the plane into the same bands but for where the
    /// seams lie.
    pub(crate) fn same_but_seams(&self, other: &Bands) -> bool {
        self.with_seams(&[]) == other.with_seams(&[])
    }

    /// Where band `band` starts on the even grid.
    fn even_edge(&self, band: usize) -> f32 {
        self.start + band as f32 / self.per_unit
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
        let band = t as u32 as usize;
        if self.seam_count == 0 {
            return band;
        }
        self.seamed(v, band)
    }

    /// The band holding `v` where seams are set, `band` on the even grid: a
    /// seam moves only the edge between its band and the one before. (Kept
    /// out of line, so that [`Bands::of`] stays small enough to inline
    /// where there are none: one thread ran 3% more instructions on `koch`
    /// with it inlined.)
    #[inline(never)]
    fn seamed(&self, v: f32, band: usize) -> usize {
        for (&s, &b) in self.seams().iter().zip(&self.seam_bands) {
            let b = b as usize;
            if band + 1 == b && v >= s {
                return b;
            }
            if band == b && v < s {
                return b - 1;
            }
        }
        band
    }

    /// The least value in band `band` (`1..count`): a value `v` is in
    /// band `band` or above exactly when `v >= self.edge(band)`, so a
    /// comparison can stand in for [`Bands::of`].
    pub(crate) fn edge(&self, band: usize) -> f32 {
        debug_assert!((1..self.count).contains(&band));
        let seam = self.seam_bands().position(|b| b == band);
        let mut v = match seam {
            Some(g) => self.seams[g],
            None => self.even_edge(band),
        };
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

    /// The first and last band a packed box reaches.
    #[inline]
    pub(crate) fn span(&self, p: &Packed) -> (usize, usize) {
        (self.of(lo(p, self.across)), self.of(hi(p, self.across)))
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
    fn a_seam_moves_only_the_edge_it_replaces() {
        let even = Bands::spanning(1, 10, 0.0, 1.0);
        // Near the edges of bands 3 and 7 (0.3 and 0.7), and one asking
        // for band 7 again, which is dropped.
        let cut = even.with_seams(&[0.33, 0.68, 0.69]);
        assert_eq!(cut.seam_bands().collect::<Vec<_>>(), [3, 7]);
        assert_eq!(cut.seams(), [0.33, 0.68]);
        assert!(cut.same_but_seams(&even) && cut != even);
        assert_eq!(cut.with_seams(&[]), even);
        assert_eq!((cut.of(0.32), cut.of(0.33), cut.of(0.29)), (2, 3, 2));
        assert_eq!((cut.of(0.679), cut.of(0.68), cut.of(0.75)), (6, 7, 7));
        for v in [0.05, 0.15, 0.45, 0.55, 0.85, 0.95] {
            assert_eq!(cut.of(v), even.of(v));
        }
        // Held within half a band of the even edge; outside the bands'
        // range or not finite, none.
        assert!((even.with_seams(&[0.2501]).seams()[0] - 0.255).abs() < 1e-6);
        assert_eq!(even.with_seams(&[0.01]).seam_bands().next(), Some(1));
        assert!(even.with_seams(&[f32::NAN]).seams().is_empty());
        assert!(Bands::one().with_seams(&[0.5]).seams().is_empty());
    }

    #[test]
    fn with_seams_bands_stay_in_order() {
        let even = Bands::spanning(0, 12, -2.0, 3.0);
        let cut = even.with_seams(&[-1.37, -1.0, 0.61, 2.2]);
        let mut last = 0;
        let mut v = -2.5f32;
        while v < 3.5 {
            let band = cut.of(v);
            assert!(band >= last && band - last <= 1, "{v}: {band} after {last}");
            last = band;
            v += 1e-4;
        }
        assert_eq!(last, 11);
    }

    #[test]
    fn an_edge_is_the_least_value_of_its_band() {
        for (count, from, to) in [
            (4, 0.0, 1.0),
            (7, -3.3, 0.1),
            (1000, 0.5, 1.0),
            (3, 1e-30, 3e-30),
        ] {
            let even = Bands::spanning(1, count, from, to);
            // Seams a third and two fifths of a band off two even edges.
            let w = (to - from) / count as f32;
            let seams = [from + w * 1.33, to - w * 1.4];
            for b in [even, even.with_seams(&seams)] {
                for band in 1..count {
                    let e = b.edge(band);
                    assert_eq!(b.of(e), band, "{count} bands, band {band}");
                    assert_eq!(b.of(e.next_down()), band - 1, "{count} bands, band {band}");
                }
            }
        }
    }
}
