//! The sweep itself: in each band, every box meets the boxes after it whose
//! least value along the sweep direction lies within its own extent; of
//! those, the ones its packed hull overlaps are reported.

use super::bands::{Bands, Layout};
use super::hull::{hi, overlaps, reach};

/// Sweeps band `band` of `layout` along direction `along`, calling
/// `found(i, j)` with the entry indices of every overlapping pair that the
/// band reports. Returns the pairs whose extents along `along` overlapped
/// (the candidates).
#[inline]
pub(crate) fn sweep_band(
    layout: &Layout,
    bands: &Bands,
    band: usize,
    along: usize,
    mut found: impl FnMut(usize, usize),
) -> u64 {
    let (start, sentinel) = (layout.starts[band], layout.starts[band + 1] - 1);
    sweep_range(layout, start..sentinel, sentinel, along, |i, j| {
        if bands.reports(band, &layout.hulls[i], &layout.hulls[j]) {
            found(i, j);
        }
    })
}

/// Sweeps the boxes `range` of one band, whose sentinel is at `sentinel`,
/// each against those after it in the band.
#[inline]
pub(crate) fn sweep_range(
    layout: &Layout,
    range: std::ops::Range<usize>,
    sentinel: usize,
    along: usize,
    mut found: impl FnMut(usize, usize),
) -> u64 {
    let keys = &layout.keys[..=sentinel];
    let hulls = &layout.hulls[..=sentinel];
    let mut candidates = 0;
    for i in range {
        let hull = &hulls[i];
        let end = hi(hull, along);
        let reach = reach(hull);
        let mut j = i + 1;
        // The sentinel's key is NaN: the comparison fails there.
        while keys[j] <= end {
            if overlaps(&hulls[j], &reach) {
                found(i, j);
            }
            j += 1;
        }
        candidates += (j - i - 1) as u64;
    }
    candidates
}
