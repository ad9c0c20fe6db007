//! A lane type of one lane: one line's values, for the move of a line
//! alone and its hull, which give the same bits as the batches' lanes.

use super::{add_first, max, min};

/// One line's value as a lane type of one lane, for
/// [`padded_hull!`](crate::detect::swept::padded_hull) and
/// [`advance_lanes!`](crate::motion::advance_lanes) (a mask is a value
/// with every bit set, or none).
#[derive(Clone, Copy)]
pub(crate) struct One(pub f64);

impl One {
    #[inline(always)]
    pub fn splat(x: f64) -> Self {
        One(x)
    }
    #[inline(always)]
    pub fn add(self, o: Self) -> Self {
        One(self.0 + o.0)
    }
    #[inline(always)]
    pub fn add_first(self, o: Self) -> Self {
        One(add_first(self.0, o.0))
    }
    #[inline(always)]
    pub fn sub(self, o: Self) -> Self {
        One(self.0 - o.0)
    }
    #[inline(always)]
    pub fn mul(self, o: Self) -> Self {
        One(self.0 * o.0)
    }
    #[inline(always)]
    pub fn min(self, o: Self) -> Self {
        One(min(self.0, o.0))
    }
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        One(max(self.0, o.0))
    }
    #[inline(always)]
    pub fn neg(self) -> Self {
        One(-self.0)
    }
    #[inline(always)]
    fn mask(holds: bool) -> Self {
        One(f64::from_bits(if holds { u64::MAX } else { 0 }))
    }
    #[inline(always)]
    pub fn gt(self, o: Self) -> Self {
        One::mask(self.0 > o.0)
    }
    #[inline(always)]
    pub fn lt(self, o: Self) -> Self {
        One::mask(self.0 < o.0)
    }
    #[inline(always)]
    pub fn and(self, o: Self) -> Self {
        One(f64::from_bits(self.0.to_bits() & o.0.to_bits()))
    }
    #[inline(always)]
    pub fn or(self, o: Self) -> Self {
        One(f64::from_bits(self.0.to_bits() | o.0.to_bits()))
    }
    /// The value with its sign flipped (exactly as `-v`) where `mask` is
    /// set.
    #[inline(always)]
    pub fn flip(self, mask: Self) -> Self {
        let sign = mask.0.to_bits() & (1 << 63);
        One(f64::from_bits(self.0.to_bits() ^ sign))
    }
    #[inline(always)]
    pub fn hits(mask: Self) -> u64 {
        u64::from(mask.0.to_bits() != 0)
    }
    /// Set where `low <= x <= high` (not for NaN).
    #[inline(always)]
    pub fn inside(self, low: Self, high: Self) -> Self {
        One::mask(low.0 <= self.0 && self.0 <= high.0)
    }
    /// Whether `mask` is set.
    #[inline(always)]
    pub fn all(mask: Self) -> bool {
        mask.0.to_bits() != 0
    }
}
