//! A correctly rounded `atan2`, the same on every target.
//!
//! The reference's glibc `atan2` is not correctly rounded (some of its
//! results differ from the correctly rounded ones in the last bit:
//! `docs/DESIGN.md`, "Our own maths"), but the contract only compares two
//! of its results, so a correctly rounded
//! one leaves every reference state unchanged (the contract's first
//! section); a merely faithful one (musl's) does not.
//!
//! The angle is worked out in double-double arithmetic (about 2^-100
//! relative error: a 257-entry table of `atan(k / 256)` and seven terms of
//! the series about it), and rounded when the error bound cannot straddle
//! a point halfway between two doubles; otherwise (about once in 2^40
//! calls) and for arguments near the ends of the range, [`super::exact`]
//! works it out with integers to as many bits as the rounding needs.

use super::dd::Dd;
use super::table::ATAN_K_256;

const PI: Dd = Dd::new(std::f64::consts::PI, 1.2246467991473532e-16);
const HALF_PI: Dd = Dd::new(std::f64::consts::FRAC_PI_2, 6.123233995736766e-17);
const THIRD: Dd = Dd::new(0.3333333333333333, 1.850371707708594e-17);
const FIFTH: Dd = Dd::new(0.2, -1.1102230246251566e-17);

/// The nearest doubles to `pi`, `pi / 2`, `pi / 4` and `3 pi / 4`.
const PI_F: f64 = std::f64::consts::PI;
const HALF_PI_F: f64 = std::f64::consts::FRAC_PI_2;
const QUARTER_PI_F: f64 = std::f64::consts::FRAC_PI_4;
const THREE_QUARTER_PI_F: f64 = 2.356194490192345;

/// The fast path takes arguments and ratios within these powers of two,
/// where no product or remainder of double-double arithmetic underflows.
const RANGE: f64 = f64::from_bits(0x58f0_0000_0000_0000); // 2^400
/// Powers of two that bring arguments into that range, exactly.
const SCALE_DOWN: f64 = f64::from_bits(0x1a70_0000_0000_0000); // 2^-600
const SCALE_UP: f64 = f64::from_bits(0x6570_0000_0000_0000); // 2^600

/// How far the double-double angle may be from the true one, relative:
/// five bits more than the error analysis gives, so that the rounding of
/// the bound itself cannot matter.
const ERROR: f64 = f64::from_bits(0x3a00_0000_0000_0000); // 2^-95

/// The angle of the point `(x, y)` from the positive x axis, in
/// `[-pi, pi]`, correctly rounded: `y`'s sign goes with the result, zeros
/// and infinities give the values C's `atan2` gives, NaN gives NaN.
///
/// ```
/// use screensaver::maths::atan2;
/// use std::f64::consts::{FRAC_PI_4, PI};
///
/// assert_eq!(atan2(1.0, 1.0), FRAC_PI_4);
/// assert_eq!(atan2(0.0, -1.0), PI);
/// assert_eq!(atan2(-0.0, -1.0), -PI);
/// ```
pub fn atan2(y: f64, x: f64) -> f64 {
    if x.is_nan() || y.is_nan() {
        return x + y;
    }
    if y == 0.0 {
        let angle = if x.is_sign_negative() { PI_F } else { 0.0 };
        return angle.copysign(y);
    }
    if x == 0.0 {
        return HALF_PI_F.copysign(y);
    }
    if x.is_infinite() {
        let angle = match (y.is_infinite(), x > 0.0) {
            (true, true) => QUARTER_PI_F,
            (true, false) => THREE_QUARTER_PI_F,
            (false, true) => 0.0,
            (false, false) => PI_F,
        };
        return angle.copysign(y);
    }
    if y.is_infinite() {
        return HALF_PI_F.copysign(y);
    }
    let (ax, ay) = (x.abs(), y.abs());
    let swap = ay > ax;
    let (small, big) = if swap { (ax, ay) } else { (ay, ax) };
    if small / big < 1.0 / RANGE {
        // The ratio t is below 2^-400, so atan(t) = t - t^3/3 + ... lies
        // within 2^-800 of t below it: beside pi/2 or pi (whose nearest
        // doubles lie a quarter of an ulp below them) it changes nothing;
        // alone, its rounding is t's but where t lies that near a point
        // halfway between two doubles, which the exact path settles.
        let angle = match (swap, x < 0.0) {
            (true, _) => HALF_PI_F,
            (false, true) => PI_F,
            (false, false) => return super::exact::atan2_abs(ay, x).copysign(y),
        };
        return angle.copysign(y);
    }
    let fast = atan_of_ratio(small, big).and_then(|mut angle| {
        if swap {
            angle = HALF_PI - angle;
        }
        if x < 0.0 {
            angle = PI - angle;
        }
        rounded(angle)
    });
    fast.unwrap_or_else(|| super::exact::atan2_abs(ay, x))
        .copysign(y)
}

/// `atan(small / big)` in double-double for `0 < small <= big` whose
/// ratio is at least 2^-400; `None` where it cannot be worked out exactly
/// enough in double-double.
fn atan_of_ratio(mut small: f64, mut big: f64) -> Option<Dd> {
    // Both scaled by powers of two (exactly: the ratio keeps `small` above
    // 2^-1000 once `big` is near 1) into the range where no product or
    // remainder below underflows or overflows.
    while big > RANGE {
        (small, big) = (small * SCALE_DOWN, big * SCALE_DOWN);
    }
    while big < 1.0 / RANGE {
        (small, big) = (small * SCALE_UP, big * SCALE_UP);
    }
    // t = small / big, in double-double: the quotient and its remainder.
    let th = small / big;
    if th < 1.0 / RANGE {
        return None;
    }
    let p = Dd::product(th, big);
    let tl = ((small - p.hi) - p.lo) / big;
    // About c = k / 256 nearest t: atan(t) = atan(c) + atan(u), with
    // u = (t - c) / (1 + t c) at most 2^-9.
    let k = (th * 256.0).round() as usize;
    let c = k as f64 / 256.0;
    // th - c is exact (Sterbenz: th lies within half of c either way).
    let num = Dd::sum(th - c, tl);
    let den = Dd::from(1.0) + Dd::product(th, c) + Dd::from(tl * c);
    let u = num / den;
    // atan(u) = u + u P(z), z = u^2, P(z) = -z/3 + z^2/5 - z^3/7 + ... to
    // z^6/13 (the next term is below 2^-126 of u). The terms from z^3 on
    // need only double precision.
    let z = u * u;
    let zf = z.hi;
    let rest = zf * (-1.0 / 7.0 + zf * (1.0 / 9.0 + zf * (-1.0 / 11.0 + zf / 13.0)));
    let p = z * ((FIFTH + Dd::from(rest)) * z - THIRD);
    let (hi, lo) = ATAN_K_256[k];
    Some(Dd::new(hi, lo) + (u + u * p))
}

/// The nearest double to `angle` (positive), if its error bound cannot
/// straddle a point halfway between two doubles.
fn rounded(angle: Dd) -> Option<f64> {
    let err = angle.hi * ERROR;
    let below = angle.hi + (angle.lo - err);
    let above = angle.hi + (angle.lo + err);
    (below == above).then_some(below)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn special_values_are_cs() {
        assert_eq!(atan2(0.0, 1.0).to_bits(), 0.0f64.to_bits());
        assert_eq!(atan2(-0.0, 1.0).to_bits(), (-0.0f64).to_bits());
        assert_eq!(atan2(0.0, -0.0), PI_F);
        assert_eq!(atan2(-0.0, -1.0), -PI_F);
        assert_eq!(atan2(1.0, 0.0), HALF_PI_F);
        assert_eq!(atan2(-1.0, -0.0), -HALF_PI_F);
        assert_eq!(atan2(f64::INFINITY, f64::INFINITY), QUARTER_PI_F);
        assert_eq!(atan2(-f64::INFINITY, -f64::INFINITY), -THREE_QUARTER_PI_F);
        assert_eq!(atan2(1.0, f64::NEG_INFINITY), PI_F);
        assert_eq!(atan2(1.0, f64::INFINITY), 0.0);
        assert!(atan2(f64::NAN, 1.0).is_nan());
        assert_eq!(atan2(1.0, 1.0), QUARTER_PI_F);
        assert_eq!(atan2(1.0, -1.0), THREE_QUARTER_PI_F);
    }

    #[test]
    fn the_fast_path_agrees_with_the_exact_one() {
        let mut differ = 0;
        let mut seed = 1u64;
        let mut next = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for _ in 0..20_000 {
            let (y, x) = (next(), next());
            if atan2(y, x).to_bits()
                != super::super::exact::atan2_abs(y.abs(), x)
                    .copysign(y)
                    .to_bits()
            {
                differ += 1;
            }
        }
        assert_eq!(differ, 0);
    }
}
