//! Decimals as the reference's files spell them: the shortest decimal that
//! reads back to the same `f64`, laid out as Rust's `{:?}` lays it out, with
//! an exponent that has a sign and at least two digits (`1e-05`, `1e+16`).
//!
//! The digits come from `zmij` (a shortest-round-trip formatter, several
//! times quicker than `{:?}`'s), but where two shortest decimals lie
//! equally near the value: there `zmij` takes the even one and `{:?}` the
//! greater, so those few values (whole numbers and short binary fractions)
//! take `{:?}`'s spelling. `zmij` lays out the rest as `{:?}` does but
//! for the exponent's spelling and the values from `1e-5` to `1e-4`, which
//! it writes without one. A state of a million lines is six million of
//! these.

use std::fmt::Write as _;

/// Appends `x` as the shortest decimal that reads back to the same bits,
/// spelled as the reference spells it (see the module's doc). NaN is
/// `NaN` or `-NaN` (its payload is not kept: the simulation only ever
/// makes the two quiet NaNs); infinities are `inf` and `-inf`.
pub(crate) fn push_decimal(out: &mut String, x: f64) {
    if x.is_nan() {
        // Rust writes every NaN as `NaN`; the sign is kept (arithmetic on
        // x86 makes negative ones), so that a state reads back to the same
        // bits.
        out.push_str(if x.is_sign_negative() { "-NaN" } else { "NaN" });
        return;
    }
    let mut buffer = zmij::Buffer::new();
    let abs = x.abs();
    let printed = match abs.is_finite() && !may_tie(abs) {
        true => buffer.format_finite(x),
        false => {
            // Whole numbers, short binary fractions, infinities: rare.
            let start = out.len();
            write!(out, "{x:?}").expect("writing to a String");
            if let Some(e) = out[start..].find('e') {
                let exponent: i32 = out[start + e + 1..].parse().expect("an exponent");
                out.truncate(start + e);
                push_exponent(out, exponent);
            }
            return;
        }
    };
    if (1e-4..1e16).contains(&abs) {
        // `zmij` lays these out as `{:?}` does: `0.000123`, `12.5`.
        out.push_str(printed);
    } else if (1e-5..1e-4).contains(&abs) {
        // `zmij` writes `0.0000123` where `{:?}` writes `1.23e-5`.
        let (sign, digits) = printed.split_at(usize::from(x < 0.0));
        let digits = &digits[6..];
        out.push_str(sign);
        out.push_str(&digits[..1]);
        if digits.len() > 1 {
            out.push('.');
            out.push_str(&digits[1..]);
        }
        push_exponent(out, -5);
    } else {
        // `1.23e-7`, `1e30`: the mantissa as it is.
        let e = printed.rfind('e').expect("an exponent");
        out.push_str(&printed[..e]);
        push_exponent(out, printed[e + 1..].parse().expect("an exponent"));
    }
}

/// Appends `e` and `exponent` with its sign and at least two digits.
fn push_exponent(out: &mut String, exponent: i32) {
    let e = exponent.unsigned_abs();
    out.push_str(if exponent < 0 { "e-" } else { "e+" });
    if e < 10 {
        out.push('0');
    }
    write!(out, "{e}").expect("writing to a String");
}

/// Whether two shortest decimals may lie equally near `x` (positive and
/// finite), where `zmij` takes the even one and `{:?}` the greater.
///
/// A tie needs `x = (2d + 1) 10^k / 2` for some `d` of at most 17 digits.
/// For `k < 0` that is `(2d + 1) / (2^(1-k) 5^-k)`: a binary fraction only
/// if `5^-k` divides `2d + 1 < 2e17 < 5^25`, so `-k <= 24` and `x` has at
/// most 25 binary digits after the point. For `k >= 0`, `x` is a whole
/// number (zero among them, which `{:?}` spells as it must). Values of the
/// box have about 52 such digits and never go here.
fn may_tie(x: f64) -> bool {
    const TWO_TO_25: f64 = 33_554_432.0;
    const TWO_TO_52: f64 = 4_503_599_627_370_496.0;
    // Past 2^52 every value is whole (and 2^25 times it may overflow).
    x >= TWO_TO_52 || (x * TWO_TO_25).fract() == 0.0
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The spelling through `{:?}`, the definition the layout follows.
    fn through_debug(x: f64) -> String {
        if x.is_nan() {
            return if x.is_sign_negative() { "-NaN" } else { "NaN" }.to_string();
        }
        let mut out = format!("{x:?}");
        if let Some(e) = out.find('e') {
            let exponent = out[e + 1..].to_string();
            let (sign, digits) = match exponent.strip_prefix('-') {
                Some(digits) => ('-', digits.to_string()),
                None => ('+', exponent),
            };
            out.truncate(e + 1);
            out.push_str(&format!("{sign}{digits:0>2}"));
        }
        out
    }

    fn spelled(x: f64) -> String {
        let mut out = String::new();
        push_decimal(&mut out, x);
        out
    }

    #[test]
    fn spells_as_the_reference() {
        for (x, s) in [
            (1e-5, "1e-05"),
            (1e16, "1e+16"),
            (-1.25e-7, "-1.25e-07"),
            (1.5e300, "1.5e+300"),
            (5e-324, "5e-324"),
            (0.0001, "0.0001"),
            (0.00012, "0.00012"),
            (123.0, "123.0"),
            (9999999999999998.0, "9999999999999998.0"),
            (0.5856869822033898, "0.5856869822033898"),
            // Halfway between ...853.2 and ...853.3: `{:?}` takes the greater.
            (f64::from_bits(0x4302_f5a9_40e2_7caa), "667082108456853.3"),
            (0.125, "0.125"),
            (1e23, "1e+23"),
            (-0.0, "-0.0"),
            (0.0, "0.0"),
            (f64::INFINITY, "inf"),
            (f64::NEG_INFINITY, "-inf"),
            (f64::NAN, "NaN"),
            (-f64::NAN, "-NaN"),
        ] {
            assert_eq!(spelled(x), s);
        }
    }

    #[test]
    fn every_power_of_ten_and_its_neighbours_as_debug_spells_them() {
        for e in -325..=308 {
            let p: f64 = format!("1e{e}").parse().unwrap();
            let (below, above) = (
                f64::from_bits(p.to_bits().saturating_sub(1)),
                f64::from_bits(p.to_bits() + 1),
            );
            for x in [
                p,
                below,
                above,
                2.0 * p,
                5.0 * p,
                9.5 * p,
                1.25 * p,
                3.0 * p,
            ] {
                for x in [x, -x] {
                    assert_eq!(spelled(x), through_debug(x), "{:#x}", x.to_bits());
                }
            }
        }
        for x in [
            f64::MAX,
            f64::MIN_POSITIVE,
            f64::EPSILON,
            1.0 / 3.0,
            2.0 / 3.0,
            0.1,
            0.2,
            0.3,
        ] {
            assert_eq!(spelled(x), through_debug(x));
        }
    }

    #[test]
    fn many_values_as_debug_spells_them() {
        // A fixed walk over the bit patterns and over values like the
        // scenes' (a few decimals, in and near the box).
        let mut bits = 0x9e37_79b9_7f4a_7c15u64;
        for k in 0..200_000u64 {
            bits = bits
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let x = f64::from_bits(bits);
            assert_eq!(spelled(x), through_debug(x), "{bits:#x}");
            let y = (k as f64 - 100_000.0) / 1000.0 + (bits >> 40) as f64 * 1e-9;
            assert_eq!(spelled(y), through_debug(y), "{y:e}");
        }
    }

    proptest! {
        #[test]
        fn any_bits_as_debug_spells_them(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assert_eq!(spelled(x), through_debug(x));
        }

        #[test]
        fn any_value_in_the_box_as_debug_spells_them(x in -2.0f64..2.0) {
            prop_assert_eq!(spelled(x), through_debug(x));
        }
    }
}
