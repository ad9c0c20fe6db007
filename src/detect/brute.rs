//! The all-pairs detector: the original program's loop, and the oracle every
//! faster detector is checked against.

use super::{Detector, DetectorStats};
use crate::line::Line;
use crate::narrow::{intersect, Event};

/// Tests every unordered pair of lines with the exact `intersect`.
#[derive(Debug, Default)]
pub struct Brute {
    stats: DetectorStats,
}

impl Detector for Brute {
    fn name(&self) -> &'static str {
        "brute"
    }

    fn detect(&mut self, lines: &[Line], dt: f64, events: &mut Vec<Event>) {
        let before = events.len();
        for (i, l1) in lines.iter().enumerate() {
            for (j, l2) in lines.iter().enumerate().skip(i + 1) {
                if let Some(kind) = intersect(l1, l2, dt) {
                    events.push(Event {
                        first: i as u32,
                        second: j as u32,
                        kind,
                    });
                }
            }
        }
        let n = lines.len() as u64;
        let pairs = n * n.saturating_sub(1) / 2;
        self.stats.candidate_pairs += pairs;
        self.stats.exact_tests += pairs;
        self.stats.events += (events.len() - before) as u64;
    }

    fn stats(&self) -> DetectorStats {
        self.stats
    }
}
