//! `hypot`, the same on every target, returning what the reference's
//! maths library (glibc 2.36 on x86-64) returned, bit for bit.
//!
//! `f64::hypot` calls the platform's libm, and libms differ in the last
//! bit (the contract's first section: any other `hypot` changes the
//! reference's states). This one follows the published algorithm that
//! glibc's follows (C. F. Borges, "An Improved Algorithm for hypot(a,b)",
//! 2019): the square root of the sum of squares, then one correction step
//! whose residual is computed exactly without fused multiply-add, with
//! scaling for very large and very small arguments. Every detail here is
//! checked against the system's `hypot` (see the tests, and
//! `docs/DESIGN.md`, "Our own maths").
//!
//! Nothing here may be fused into a multiply-add: Rust never contracts
//! `a * b + c` (only `mul_add` fuses), so each operation rounds as written
//! on every target.

/// Above this, the larger argument's square could overflow: both are
/// scaled down by [`SCALE`] first.
const LARGE: f64 = f64::from_bits(0x5fe0_0000_0000_0000); // 2^511
/// Below this, the correction's residual (about 2^-53 of the smaller
/// argument's square) could lose bits to underflow: both are scaled up
/// first. (Scaling only from 2^-511, where the square itself would, is
/// too late: the system's results differ from the unscaled ones from
/// about 2^-504 down.)
const TINY: f64 = f64::from_bits(0x2340_0000_0000_0000); // 2^-459
/// A power of two, so that scaling is exact.
const SCALE: f64 = f64::from_bits(0x1a70_0000_0000_0000); // 2^-600
/// When the smaller argument is at most this fraction of the larger, the
/// sum of the two rounds to the result (its square no longer counts).
const NEGLIGIBLE: f64 = f64::from_bits(0x3c90_0000_0000_0000); // 2^-54

/// `sqrt(x^2 + y^2)` without undue overflow or underflow, exactly as the
/// reference's libm computed it: `+inf` if either argument is infinite
/// (even with a NaN beside it), NaN for a NaN otherwise.
///
/// ```
/// use screensaver::maths::hypot;
///
/// assert_eq!(hypot(3.0, 4.0), 5.0);
/// assert_eq!(hypot(1e300, 1e300), 1.4142135623730952e300); // no overflow
/// assert_eq!(hypot(f64::NAN, f64::INFINITY), f64::INFINITY);
/// ```
#[inline]
pub fn hypot(x: f64, y: f64) -> f64 {
    if !x.is_finite() || !y.is_finite() {
        return not_finite(x, y);
    }
    let (x, y) = (x.abs(), y.abs());
    let (big, small) = if x < y { (y, x) } else { (x, y) };
    if big > LARGE {
        if small <= big * NEGLIGIBLE {
            return big + small;
        }
        return corrected(big * SCALE, small * SCALE) / SCALE;
    }
    if small < TINY {
        if big >= small / NEGLIGIBLE {
            return big + small;
        }
        return corrected(big / SCALE, small / SCALE) * SCALE;
    }
    if small <= big * NEGLIGIBLE {
        return big + small;
    }
    corrected(big, small)
}

/// `hypot` where an argument is infinite or NaN: infinity wins over a
/// quiet NaN, a signalling NaN wins over everything (quieted, as the sum
/// quiets it).
#[cold]
fn not_finite(x: f64, y: f64) -> f64 {
    if (x.is_infinite() || y.is_infinite()) && !signalling(x) && !signalling(y) {
        return f64::INFINITY;
    }
    x + y
}

/// Whether `x` is a signalling NaN (the quiet bit clear).
fn signalling(x: f64) -> bool {
    x.is_nan() && x.to_bits() & (1 << 51) == 0
}

/// The square root of `big^2 + small^2` for `big >= small`, neither so
/// large nor so small that the squares overflow or underflow, corrected
/// once: `h - (h^2 - big^2 - small^2) / (2h)`, the residual written so
/// that every product and difference in it is exact but the last few.
#[inline]
fn corrected(big: f64, small: f64) -> f64 {
    let h = (big * big + small * small).sqrt();
    // `h` lies within a factor of two of `small` or of `big`, so `delta`
    // is exact (Sterbenz); the residual is expanded around that one.
    let residual = if h <= 2.0 * small {
        let delta = h - small;
        let t1 = big * (2.0 * delta - big);
        let t2 = (delta - 2.0 * (big - small)) * delta;
        t1 + t2
    } else {
        let delta = h - big;
        let t1 = 2.0 * delta * (big - 2.0 * small);
        let t2 = (4.0 * delta - small) * small + delta * delta;
        t1 + t2
    };
    h - residual / (2.0 * h)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The system's `hypot`: the reference's libm where the tests run on
    /// glibc 2.36, x86-64.
    fn system(x: f64, y: f64) -> f64 {
        x.hypot(y)
    }

    /// Whether this is the platform whose libm the reference used.
    fn on_the_reference_libm() -> bool {
        cfg!(all(
            target_os = "linux",
            target_env = "gnu",
            target_arch = "x86_64"
        ))
    }

    fn same(a: f64, b: f64) -> bool {
        a.to_bits() == b.to_bits()
    }

    #[test]
    fn constants_are_the_powers_of_two_they_say() {
        assert_eq!(LARGE, 2f64.powi(511));
        assert_eq!(TINY, 2f64.powi(-459));
        assert_eq!(SCALE, 2f64.powi(-600));
        assert_eq!(NEGLIGIBLE, 2f64.powi(-54));
    }

    #[test]
    fn special_values() {
        assert_eq!(hypot(3.0, 4.0), 5.0);
        assert_eq!(hypot(-3.0, 4.0), 5.0);
        assert_eq!(hypot(0.0, -0.0).to_bits(), 0.0f64.to_bits());
        assert_eq!(hypot(f64::INFINITY, f64::NAN), f64::INFINITY);
        assert_eq!(hypot(f64::NAN, f64::NEG_INFINITY), f64::INFINITY);
        assert!(hypot(f64::NAN, 1.0).is_nan());
        assert_eq!(hypot(f64::MAX, f64::MAX), f64::INFINITY);
        assert_eq!(hypot(f64::MIN_POSITIVE, 0.0), f64::MIN_POSITIVE);
        let snan = f64::from_bits(0x7ff0_0000_0000_0001);
        assert!(hypot(snan, f64::INFINITY).is_nan());
    }

    /// A few million arguments of every class against the system's
    /// `hypot`, on the platform of the reference's libm (elsewhere the
    /// system's is not the reference). `examples/libm_compare.rs` runs the
    /// same classes at any scale.
    #[test]
    fn hypot_is_the_reference_libms_on_every_class() {
        if !on_the_reference_libm() {
            return;
        }
        let per_class = if cfg!(debug_assertions) {
            20_000
        } else {
            400_000
        };
        for class in super::super::classes::ALL {
            let mut differ = 0;
            let mut first = None;
            for (x, y) in class.pairs(per_class, 0x5eed) {
                if !same(hypot(x, y), system(x, y)) {
                    differ += 1;
                    first.get_or_insert((x, y));
                }
            }
            assert_eq!(differ, 0, "{}: first at {:?}", class.name(), first);
        }
    }
}
