//! The project's own `hypot` and `atan2`, the same on every target, with
//! no call into the platform's maths library: the reference's results on
//! every platform (the contract's first section).
//!
//! - [`hypot`] returns exactly what the reference's libm (glibc 2.36 on
//!   x86-64) returns, for every pair of doubles.
//! - [`atan2`] is correctly rounded; the contract only compares two of its
//!   results, and a correctly rounded one keeps every reference state.

mod atan2;
// The argument classes of the maths checks: for the tests, and for
// examples/libm_compare.rs through `crate::internals`.
#[cfg(any(test, feature = "internals"))]
pub mod classes;
mod dd;
mod exact;
mod hypot;
mod table;

pub use atan2::atan2;
pub use hypot::hypot;

/// `a b - c d`, correctly signed and within a unit or two in the last place
/// (each product exact in double-double, their difference to about 2^-104
/// of itself), for values whose products and their rounding errors stay
/// normal (from about 2^-900 to 2^1000).
pub(crate) fn difference_of_products(a: f64, b: f64, c: f64, d: f64) -> f64 {
    (dd::Dd::product(a, b) - dd::Dd::product(c, d)).hi
}

#[cfg(test)]
mod tests {
    use super::difference_of_products;

    #[test]
    fn a_difference_of_products_keeps_what_rounding_the_products_loses() {
        let e = f64::EPSILON;
        // (1 + e)(1 - e) - 1 = -e^2, which each product rounded to a
        // double loses.
        assert_eq!((1.0 + e) * (1.0 - e) - 1.0, 0.0);
        assert_eq!(difference_of_products(1.0 + e, 1.0 - e, 1.0, 1.0), -e * e);
        // Equal products, in either order, give zero.
        assert_eq!(difference_of_products(0.1, 0.3, 0.3, 0.1), 0.0);
        assert_eq!(difference_of_products(3.0, 7.0, 21.0, 1.0), 0.0);
        // Against exact integers: products of 30-bit values are exact in
        // 60 bits, which i128 holds.
        let mut x = 0x2545_f491_4f6c_dd1du64;
        for _ in 0..1000 {
            let mut next = || {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                (x >> 34) as i64 - (1 << 29)
            };
            let (a, b, c, d) = (next(), next(), next(), next());
            let exact = i128::from(a) * i128::from(b) - i128::from(c) * i128::from(d);
            let got = difference_of_products(a as f64, b as f64, c as f64, d as f64);
            assert_eq!(got, exact as f64, "{a} {b} {c} {d}");
        }
    }
}
