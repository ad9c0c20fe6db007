//! The all-pairs detector: the original program's loop, and the oracle every
//! faster detector is checked against.

use super::{Detector, Findings, Stored};
use crate::index::Slot;

/// Tests every unordered pair of lines with the exact `intersect`. A step
/// of a hundred thousand lines takes minutes, so it looks for a signal
/// before each row and gives the step up when one came
/// ([`Findings::abandoned`]).
#[derive(Debug, Default)]
pub struct Brute;

impl Detector for Brute {
    fn detect(&mut self, stored: Stored<'_>, dt: f64, found: &mut Findings) {
        // Never reordered, so slots are ids: `i < j` puts the lower id
        // first.
        debug_assert!(stored.in_id_order());
        let lines = stored.lines;
        for (i, l1) in lines.iter().enumerate() {
            if crate::run::signalled() {
                found.abandoned = true;
                return;
            }
            for (j, l2) in lines.iter().enumerate().skip(i + 1) {
                found.exact(l1, l2, (Slot(i as u32), Slot(j as u32)), dt);
            }
        }
        let n = lines.len() as u64;
        found.met(n * n.saturating_sub(1) / 2);
    }
}
