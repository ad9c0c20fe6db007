//! `atan2` worked out with big integers to as many bits as its rounding
//! needs: the slow path of [`super::atan2`], taken about once in 2^40
//! calls and for arguments near the ends of the range. Slow (tens of
//! microseconds) and simple enough to check by reading.
//!
//! Every quantity is a fixed-point integer `v` standing for `v / 2^f`; each
//! operation truncates by less than one unit, and the units lost are
//! counted into the error bound the final rounding checks against. Where
//! the result lies too near a point halfway between two doubles, it is
//! worked out again with twice the bits.

use num_bigint::BigUint;

/// Bits of precision first tried beyond the result's own magnitude.
const FIRST_BITS: u64 = 160;

/// Units of the last place by which a fixed-point result may be off (a
/// generous count of the truncations below, each less than one unit, and
/// the halvings' doubling of them).
const SLACK_BITS: u64 = 24;

/// `atan2(ay, x)` for finite `ay > 0` and finite nonzero `x`, correctly
/// rounded (in `(0, pi)`).
pub(super) fn atan2_abs(ay: f64, x: f64) -> f64 {
    debug_assert!(ay > 0.0 && ay.is_finite() && x != 0.0 && x.is_finite());
    let ax = x.abs();
    let swap = ay > ax;
    let (small, big) = if swap { (ax, ay) } else { (ay, ax) };
    let (ms, es) = parts(small);
    let (mb, eb) = parts(big);
    // The ratio is at least 2^(es - eb - 53): enough bits below that.
    let tiny = u64::try_from(eb - es).unwrap_or(0);
    let mut bits = FIRST_BITS;
    loop {
        let f = bits + tiny + SLACK_BITS;
        // t = small / big in f-bit fixed point.
        let t = shifted(&BigUint::from(ms), es - eb + f as i64) / BigUint::from(mb);
        let mut angle = atan_fixed(&t, f);
        if swap {
            angle = half_pi(f) - angle;
        }
        if x < 0.0 {
            angle = (half_pi(f) << 1u8) - angle;
        }
        if let Some(r) = round_fixed(&angle, f) {
            return r;
        }
        bits *= 2;
    }
}

/// A finite nonzero double as `m * 2^e` with integer `m`.
fn parts(x: f64) -> (u64, i64) {
    let bits = x.abs().to_bits();
    let exp = (bits >> 52) as i64;
    let frac = bits & ((1 << 52) - 1);
    if exp == 0 {
        (frac, -1074)
    } else {
        (frac | (1 << 52), exp - 1075)
    }
}

/// `v * 2^by`, truncated when `by` is negative.
fn shifted(v: &BigUint, by: i64) -> BigUint {
    if by >= 0 {
        v << by as u64
    } else {
        v >> by.unsigned_abs()
    }
}

/// `atan(t)` for `0 <= t <= 1`, both in `f`-bit fixed point.
fn atan_fixed(t: &BigUint, f: u64) -> BigUint {
    let one = BigUint::from(1u8) << f;
    // Four halvings, atan(t) = 2 atan(t / (1 + sqrt(1 + t^2))), bring t
    // below tan(pi / 64) < 0.05, where the series needs a term for every
    // 8.6 bits.
    let mut t = t.clone();
    let halvings = 4u32;
    for _ in 0..halvings {
        let root = ((&one << f) + &t * &t).sqrt();
        t = (&t << f) / (&one + root);
    }
    atan_series(&t, f) << halvings
}

/// `atan(t)` by its series, for `0 <= t < 1/2`, in `f`-bit fixed point.
fn atan_series(t: &BigUint, f: u64) -> BigUint {
    let t2 = (t * t) >> f;
    let mut power = t.clone();
    let (mut plus, mut minus) = (BigUint::ZERO, BigUint::ZERO);
    let mut k = 0u64;
    while power != BigUint::ZERO {
        let term = &power / BigUint::from(2 * k + 1);
        if k % 2 == 0 {
            plus += term;
        } else {
            minus += term;
        }
        power = (&power * &t2) >> f;
        k += 1;
    }
    plus - minus
}

/// `atan(1 / n)` by its series, in `f`-bit fixed point.
fn atan_inverse(n: u64, f: u64) -> BigUint {
    let n2 = BigUint::from(n * n);
    let mut power = (BigUint::from(1u8) << f) / BigUint::from(n);
    let (mut plus, mut minus) = (BigUint::ZERO, BigUint::ZERO);
    let mut k = 0u64;
    while power != BigUint::ZERO {
        let term = &power / BigUint::from(2 * k + 1);
        if k % 2 == 0 {
            plus += term;
        } else {
            minus += term;
        }
        power /= &n2;
        k += 1;
    }
    plus - minus
}

/// `pi / 2` in `f`-bit fixed point (Machin: pi/4 = 4 atan(1/5) - atan(1/239)).
fn half_pi(f: u64) -> BigUint {
    ((atan_inverse(5, f) << 2u8) - atan_inverse(239, f)) << 1u8
}

/// The nearest double to `v / 2^f` (positive, below 4), if `v`'s error of
/// up to `2^SLACK_BITS` units cannot change it.
fn round_fixed(v: &BigUint, f: u64) -> Option<f64> {
    let len = v.bits();
    // Bits below the double's last place: 53 significant bits, or fewer
    // where the result is subnormal (its last place 2^-1074).
    let drop = len.saturating_sub(53).max(f.saturating_sub(1074));
    if drop <= SLACK_BITS + 1 {
        return None;
    }
    let kept = v >> drop;
    let rest = v - (&kept << drop);
    let half = BigUint::from(1u8) << (drop - 1);
    let slack = BigUint::from(1u8) << SLACK_BITS;
    let gap = if rest > half {
        &rest - &half
    } else {
        &half - &rest
    };
    if gap <= slack {
        return None;
    }
    let m = if rest > half { kept + 1u8 } else { kept };
    let m = u64::try_from(&m).ok()? as f64;
    // m * 2^(drop - f), exactly: m has at most 54 bits and the result is a
    // double (a power of two apart at most).
    let e = drop as i64 - f as i64;
    Some(m * pow2(e))
}

/// `2^e` for `-1074 <= e <= 1023`.
fn pow2(e: i64) -> f64 {
    if e >= -1022 {
        f64::from_bits(((e + 1023) as u64) << 52)
    } else {
        f64::from_bits(1u64 << (e + 1074))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn known_angles() {
        assert_eq!(atan2_abs(1.0, 1.0), std::f64::consts::FRAC_PI_4);
        assert_eq!(atan2_abs(1.0, -1.0), 2.356194490192345);
        assert_eq!(atan2_abs(1.0, 1e-300), std::f64::consts::FRAC_PI_2);
        assert_eq!(atan2_abs(1.0, -1e300), std::f64::consts::PI);
        // atan(t) = t - t^3/3 + ...: tiny ratios give the ratio.
        assert_eq!(atan2_abs(1e-300, 1.0), 1e-300);
        assert_eq!(atan2_abs(f64::from_bits(1), 1.0), f64::from_bits(1));
        assert_eq!(atan2_abs(f64::from_bits(1), 2.0), 0.0);
        assert_eq!(atan2_abs(f64::from_bits(3), 2.0), f64::from_bits(1));
        // sqrt(3) rounded lies below sqrt(3): just under 60 degrees
        // (checked with 300-bit arithmetic).
        assert_eq!(atan2_abs(3f64.sqrt(), 1.0), 1.0471975511965976);
        assert_eq!(pow2(-1074), f64::from_bits(1));
        assert_eq!(pow2(0), 1.0);
    }
}
