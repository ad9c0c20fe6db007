//! The sweep itself: every box meets the boxes after it whose least value
//! along the sweep direction lies within its own extent; of those, the
//! ones its packed hull overlaps are reported.

use super::hull::{hi, overlaps, reach, Packed};

/// Sweeps the boxes `range` of sorted `keys` and `hulls`, each against the
/// boxes after it up to the first whose key lies beyond its extent along
/// direction `along` (a sentinel after the last box guarantees one), and
/// calls `found(i, j)` for every pair whose hulls overlap. Returns the
/// pairs met (the candidates).
#[inline]
pub(crate) fn sweep(
    keys: &[f32],
    hulls: &[Packed],
    range: std::ops::Range<usize>,
    along: usize,
    mut found: impl FnMut(usize, usize),
) -> u64 {
    let mut candidates = 0;
    for i in range {
        let hull = &hulls[i];
        let end = hi(hull, along);
        let reach = reach(hull);
        let mut j = i + 1;
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
