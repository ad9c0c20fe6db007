//! The counts a run keeps, as the original program printed them.

/// Cumulative collision counts, as the original program printed them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Counters {
    /// Steps in which a line bounced off at least one wall, summed over lines.
    pub wall: u64,
    /// Line-line events found, including those between lines already overlapping.
    pub line: u64,
}
