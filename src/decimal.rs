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
//!
//! Reading goes the other way: [`read_decimal`] reads the plain decimals
//! the scene files hold (`-00.208073`) at a few instructions a digit, and
//! leaves every other spelling to Rust's own reader.

use std::fmt::Write as _;

/// The powers of ten a plain decimal of at most 19 digits, one of them
/// before its point, divides by: each exact in a `f64`.
const POWERS: [f64; 19] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18,
];

/// The `f64` that `word`, a decimal, reads as, exactly as
/// `str::parse::<f64>` reads it; `None` where it is not one.
///
/// A plain decimal (`[+-]digits[.digits]`, at most 19 digits, at most
/// 2^53 as a whole number) is its digits as a whole number `m` divided by
/// `10^k`: both are exact in a `f64`, and the division rounds once, so the
/// quotient is the decimal correctly rounded, which is what Rust's reader
/// gives (Clinger's fast path). Every other spelling (an exponent, more
/// digits, `.5`, `inf`, text) goes to Rust's reader ([`read_any`]).
/// Reading a million-line scene file takes 1.65 G instructions this way,
/// 4.0 G through `str::parse`.
pub(crate) fn read_decimal(word: &[u8]) -> Option<f64> {
    match read_plain(word) {
        Some((x, len)) if len == word.len() => Some(x),
        _ => read_any(word),
    }
}

/// `word` read by Rust's own reader, whatever its spelling.
pub(crate) fn read_any(word: &[u8]) -> Option<f64> {
    std::str::from_utf8(word).ok()?.parse().ok()
}

/// [`read_decimal`] of the plain decimal at the start of `text`, within
/// the fast path's bounds: its value and its length, in one pass over its
/// bytes; `None` where `text` starts otherwise (the caller checks that
/// the decimal ends where its word does).
pub(crate) fn read_plain(text: &[u8]) -> Option<(f64, usize)> {
    let (negative, signed) = match text.first() {
        Some(b'-') => (true, 1),
        Some(b'+') => (false, 1),
        _ => (false, 0),
    };
    let (mut m, mut k, mut point) = (0u64, signed, None);
    while let Some(&b) = text.get(k) {
        let digit = b.wrapping_sub(b'0');
        if digit <= 9 {
            m = m.wrapping_mul(10).wrapping_add(u64::from(digit));
        } else if b == b'.' && point.is_none() {
            point = Some(k);
        } else {
            break;
        }
        k += 1;
    }
    // At least one digit on each side of a point; at most 19 digits, so
    // that the whole number has not wrapped.
    let digits = k - signed - usize::from(point.is_some());
    let after = match point {
        Some(p) if p == signed || p + 1 == k => return None,
        Some(p) => k - p - 1,
        None => 0,
    };
    // (So `after` is at most 18.)
    if digits == 0 || digits > 19 || m > 1 << 53 {
        return None;
    }
    let x = m as f64 / POWERS[after];
    Some((if negative { -x } else { x }, k))
}

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

    /// Rust's reader, the definition [`read_decimal`] follows.
    fn by_rust(word: &str) -> Option<u64> {
        word.parse::<f64>().ok().map(f64::to_bits)
    }

    #[test]
    fn plain_decimals_read_as_rust_reads_them() {
        let words = [
            "0",
            "-0",
            "-0.000000",
            "+1",
            "291.000000",
            "-00.208073",
            "000.454649",
            "1.",
            ".5",
            "-.5",
            ".",
            "-",
            "+",
            "",
            "1e5",
            "1.5e-3",
            "inf",
            "NaN",
            "0x10",
            "1,5",
            "1..2",
            "12a",
            "9007199254740992",
            "9007199254740993",
            "0.9007199254740993",
            "1.0000000000000000000001",
            "123456789.0123456789",
            "0.0000000000000000000001",
            "0.00000000000000000000001",
            "18446744073709551615",
            "99999999999999999999",
            "4.9406564584124654e-324",
            "1.7976931348623157e308",
        ];
        for word in words {
            let read = read_decimal(word.as_bytes()).map(f64::to_bits);
            assert_eq!(read, by_rust(word), "{word:?}");
        }
    }

    proptest! {
        #[test]
        fn generated_decimals_read_as_rust_reads_them(
            sign in prop::sample::select(vec!["", "-", "+"]),
            whole in "[0-9]{1,12}",
            fraction in prop::option::of("[0-9]{0,12}"),
        ) {
            let word = match fraction {
                Some(f) => format!("{sign}{whole}.{f}"),
                None => format!("{sign}{whole}"),
            };
            let read = read_decimal(word.as_bytes()).map(f64::to_bits);
            prop_assert_eq!(read, by_rust(&word), "{}", word);
        }

        #[test]
        fn shortest_decimals_read_back(bits in any::<u64>()) {
            let x = f64::from_bits(bits);
            prop_assume!(x.is_finite());
            let mut out = String::new();
            push_decimal(&mut out, x);
            prop_assert_eq!(read_decimal(out.as_bytes()).map(f64::to_bits), Some(bits));
        }
    }

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
