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
