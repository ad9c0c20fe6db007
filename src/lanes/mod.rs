//! Four `f64` lanes, one type per target, for the batches written once
//! over them: the move and the walls ([`crate::motion`]), in the world's
//! pass and in the sweep's pass that also makes the next step's hulls
//! ([`crate::detect::sweep::hull`]), whose lanes are [`single`]'s. Each
//! type gathers lines' values into lanes and scatters them back, makes
//! the elementary operations, and rounds its lanes to `f32` for the
//! hulls. Each operation is the IEEE operation on every lane, and
//! rounding to `f32` is to nearest (as `as f32`), so every type gives the
//! same bits as the others and as one line moved alone.
//!
//! - [`Avx2`]: one 256-bit register (x86-64 with AVX2, chosen at start);
//! - [`Sse2`]: one 128-bit register, two lines at a time (every x86-64
//!   processor), through `safe_arch`;
//! - [`Simd128`]: two of WebAssembly's 128-bit vectors;
//! - [`Scalar`]: plain values, for the other targets (the compiler turns
//!   them into what vectors the target has).

use crate::geometry::Vec2;
use crate::line::Line;

pub(crate) mod blocks;
#[cfg(target_arch = "x86_64")]
pub(crate) mod intersect;
mod one;
pub(crate) use one::One;

/// Lines a batch of `f64` lanes takes at most.
pub(crate) const LANES: usize = 4;

/// `min` without NaN handling: one instruction. Callers rule NaN out.
#[inline(always)]
pub(crate) fn min(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// `max` without NaN handling: one instruction. Callers rule NaN out.
#[inline(always)]
pub(crate) fn max(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// `a + b`, with `a`'s NaN (quieted) where both are NaN: the sum the
/// move makes of a point and its travel, the same bits on every path.
/// Which of two NaNs an addition gives is the compiler's choice (it may
/// swap the operands), and the scalar and vector code of the move would
/// choose differently; a NaN `a` gives `a + a` instead, whichever way
/// round, as the addition with `a` first gives on x86-64.
#[inline(always)]
pub(crate) fn add_first(a: f64, b: f64) -> f64 {
    if a.is_nan() {
        a + a
    } else {
        a + b
    }
}

/// Methods `name(self, o)` of a lane type, each the operation `op` on
/// every lane, with the attributes given: of its one register, or with
/// `map2` first, of each of its registers (through the type's `map2`).
#[cfg(any(
    target_arch = "x86_64",
    all(target_arch = "wasm32", target_feature = "simd128")
))]
macro_rules! lanewise {
    (map2 $attrs:tt $($name:ident => $op:path),* $(,)?) => {
        $(lanewise!(@map2 $attrs $name $op);)*
    };
    ($attrs:tt $($name:ident => $op:path),* $(,)?) => {
        $(lanewise!(@one $attrs $name $op);)*
    };
    (@one [$($attr:meta),*] $name:ident $op:path) => {
        $(#[$attr])*
        pub fn $name(self, o: Self) -> Self {
            Self($op(self.0, o.0))
        }
    };
    (@map2 [$($attr:meta),*] $name:ident $op:path) => {
        $(#[$attr])*
        pub fn $name(self, o: Self) -> Self {
            self.map2(o, |a, b| $op(a, b))
        }
    };
}

/// Each line's `[p1.x, p1.y, p2.x, p2.y]`.
#[inline(always)]
fn row(l: &Line) -> [f64; 4] {
    [l.p1.x, l.p1.y, l.p2.x, l.p2.y]
}

/// The sign bit of an `f64`.
const SIGN: u64 = 1 << 63;

/// Sets `line`'s endpoints to `[p1.x, p1.y, p2.x, p2.y]`: its first four
/// values (a line is six `f64` in order), written as one array, so that
/// the compiler stores a register's four at once rather than in pieces.
#[inline(always)]
pub(crate) fn set_points(line: &mut Line, p: [f64; 4]) {
    let values: &mut [f64; 6] = bytemuck::cast_mut(line);
    let points: &mut [f64; 4] = (&mut values[..4]).try_into().expect("four values");
    *points = p;
}

/// A line from `[p1.x, p1.y, p2.x, p2.y]` and `[v.x, v.y]`.
#[inline(always)]
fn line_of(p: [f64; 4], v: [f64; 2]) -> Line {
    Line {
        p1: Vec2::new(p[0], p[1]),
        p2: Vec2::new(p[2], p[3]),
        v: Vec2::new(v[0], v[1]),
    }
}

/// Plain values, for targets without a lane type of their own.
#[derive(Clone, Copy)]
#[cfg_attr(
    any(
        target_arch = "x86_64",
        all(target_arch = "wasm32", target_feature = "simd128")
    ),
    allow(dead_code)
)]
pub(crate) struct Scalar([f64; LANES]);

#[cfg_attr(
    any(
        target_arch = "x86_64",
        all(target_arch = "wasm32", target_feature = "simd128")
    ),
    allow(dead_code)
)]
impl Scalar {
    /// Lines a batch takes.
    pub const WIDTH: usize = LANES;

    #[inline(always)]
    fn map2(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
        Self(std::array::from_fn(|k| f(self.0[k], o.0[k])))
    }
    #[inline(always)]
    pub fn splat(x: f64) -> Self {
        Self([x; LANES])
    }
    #[inline(always)]
    pub fn points(batch: [&Line; LANES]) -> [Self; 4] {
        let rows = batch.map(row);
        std::array::from_fn(|c| Self(std::array::from_fn(|k| rows[k][c])))
    }
    #[inline(always)]
    pub fn add(self, o: Self) -> Self {
        self.map2(o, |a, b| a + b)
    }
    #[inline(always)]
    pub fn add_first(self, o: Self) -> Self {
        self.map2(o, add_first)
    }
    #[inline(always)]
    pub fn mul(self, o: Self) -> Self {
        self.map2(o, |a, b| a * b)
    }
    #[inline(always)]
    pub fn velocities(batch: [&Line; LANES]) -> (Self, Self) {
        (Self(batch.map(|l| l.v.x)), Self(batch.map(|l| l.v.y)))
    }
    #[inline(always)]
    pub fn lines(point: [Self; 4], vx: Self, vy: Self) -> [Line; LANES] {
        std::array::from_fn(|k| line_of(point.map(|c| c.0[k]), [vx.0[k], vy.0[k]]))
    }
    /// Each line's `[p1.x, p1.y, p2.x, p2.y]`.
    #[inline(always)]
    pub fn rows(point: [Self; 4]) -> [[f64; 4]; LANES] {
        std::array::from_fn(|k| point.map(|c| c.0[k]))
    }
    #[inline(always)]
    fn mask(self, o: Self, f: impl Fn(f64, f64) -> bool) -> Self {
        self.map2(o, |a, b| f64::from_bits(if f(a, b) { u64::MAX } else { 0 }))
    }
    #[inline(always)]
    fn bits(self, o: Self, f: impl Fn(u64, u64) -> u64) -> Self {
        self.map2(o, |a, b| f64::from_bits(f(a.to_bits(), b.to_bits())))
    }
    #[inline(always)]
    pub fn gt(self, o: Self) -> Self {
        self.mask(o, |a, b| a > b)
    }
    #[inline(always)]
    pub fn lt(self, o: Self) -> Self {
        self.mask(o, |a, b| a < b)
    }
    #[inline(always)]
    pub fn and(self, o: Self) -> Self {
        self.bits(o, |a, b| a & b)
    }
    #[inline(always)]
    pub fn or(self, o: Self) -> Self {
        self.bits(o, |a, b| a | b)
    }
    #[inline(always)]
    pub fn flip(self, mask: Self) -> Self {
        self.bits(mask, |a, m| a ^ (m & SIGN))
    }
    #[inline(always)]
    pub fn hits(mask: Self) -> u64 {
        mask.0.iter().map(|m| u64::from(m.to_bits() != 0)).sum()
    }
    /// Set where `low <= x <= high` (neither for NaN).
    #[inline(always)]
    pub fn inside(self, low: Self, high: Self) -> Self {
        self.mask(low, |x, l| l <= x)
            .and(self.mask(high, |x, h| x <= h))
    }
    /// Whether every lane of `mask` is set.
    #[inline(always)]
    pub fn all(mask: Self) -> bool {
        mask.0.iter().all(|m| m.to_bits() != 0)
    }
    /// The lanes rounded to `f32`.
    #[inline(always)]
    pub fn narrow(self) -> [f32; LANES] {
        self.0.map(|x| x as f32)
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use x86::{Avx2, Sse2};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{line_of, row, Line, LANES};
    use safe_arch::{
        add_m128d, bitand_m128d, bitandnot_m128d, bitor_m128d, bitxor_m128d, cmp_ge_mask_m128d,
        cmp_gt_mask_m128d, cmp_le_mask_m128d, cmp_lt_mask_m128d, cmp_unord_mask_m128d,
        convert_to_m128_from_m128d, m128, m128d, move_mask_m128d, mul_m128d, set_splat_m128d,
        unpack_high_m128d, unpack_low_m128d,
    };
    use std::arch::x86_64::{
        __m128, __m256d, _mm256_add_pd, _mm256_and_pd, _mm256_blendv_pd, _mm256_cmp_pd,
        _mm256_cvtpd_ps, _mm256_movemask_pd, _mm256_mul_pd, _mm256_or_pd, _mm256_permute2f128_pd,
        _mm256_set1_pd, _mm256_set_m128d, _mm256_unpackhi_pd, _mm256_unpacklo_pd, _mm256_xor_pd,
        _CMP_GE_OQ, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_LT_OQ, _CMP_UNORD_Q,
    };

    /// Four lanes in one AVX2 register. Its operations are compiled with
    /// AVX2 and called only from code compiled with it.
    #[derive(Clone, Copy)]
    pub struct Avx2(__m256d);

    impl Avx2 {
        /// Lines a batch takes.
        pub const WIDTH: usize = LANES;

        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn splat(x: f64) -> Self {
            Self(_mm256_set1_pd(x))
        }
        /// Rows `p1.x p1.y p2.x p2.y`, one a line, turned into columns.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn points(batch: [&Line; LANES]) -> [Self; 4] {
            let r: [__m256d; 4] = batch.map(|l| bytemuck::cast(row(l)));
            let (t0, t1) = (
                _mm256_unpacklo_pd(r[0], r[1]),
                _mm256_unpackhi_pd(r[0], r[1]),
            );
            let (t2, t3) = (
                _mm256_unpacklo_pd(r[2], r[3]),
                _mm256_unpackhi_pd(r[2], r[3]),
            );
            [
                Self(_mm256_permute2f128_pd::<0x20>(t0, t2)),
                Self(_mm256_permute2f128_pd::<0x20>(t1, t3)),
                Self(_mm256_permute2f128_pd::<0x31>(t0, t2)),
                Self(_mm256_permute2f128_pd::<0x31>(t1, t3)),
            ]
        }
        lanewise!(
            [inline, target_feature(enable = "avx2")]
            add => _mm256_add_pd, mul => _mm256_mul_pd,
        );
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn add_first(self, o: Self) -> Self {
            let (a, b) = (self.0, o.0);
            let nan = _mm256_cmp_pd::<_CMP_UNORD_Q>(a, a);
            Self(_mm256_blendv_pd(
                _mm256_add_pd(a, b),
                _mm256_add_pd(a, a),
                nan,
            ))
        }
        /// Each line's `[v.x, v.y]` loaded whole: lines 0 and 2 in one
        /// register, 1 and 3 in another, then interleaved.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn velocities(batch: [&Line; LANES]) -> (Self, Self) {
            let v = batch.map(|l| m128d::from([l.v.x, l.v.y]).0);
            let (a, b) = (_mm256_set_m128d(v[2], v[0]), _mm256_set_m128d(v[3], v[1]));
            (
                Self(_mm256_unpacklo_pd(a, b)),
                Self(_mm256_unpackhi_pd(a, b)),
            )
        }
        /// The four lines from their values in lanes: the points turned
        /// back into rows (the same shuffles as [`Avx2::points`]: the turn
        /// is its own inverse), the velocities interleaved by pairs.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn lines(point: [Self; 4], vx: Self, vy: Self) -> [Line; LANES] {
            let rows = Self::rows(point);
            let v02: [f64; 4] = bytemuck::cast(_mm256_unpacklo_pd(vx.0, vy.0));
            let v13: [f64; 4] = bytemuck::cast(_mm256_unpackhi_pd(vx.0, vy.0));
            let v = [
                [v02[0], v02[1]],
                [v13[0], v13[1]],
                [v02[2], v02[3]],
                [v13[2], v13[3]],
            ];
            std::array::from_fn(|k| line_of(rows[k], v[k]))
        }
        /// Each line's `[p1.x, p1.y, p2.x, p2.y]`: the points turned back
        /// into rows (the same shuffles as [`Avx2::points`]: the turn is
        /// its own inverse).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn rows(point: [Self; 4]) -> [[f64; 4]; LANES] {
            let [ax, ay, bx, by] = point.map(|c| c.0);
            let (t0, t1) = (_mm256_unpacklo_pd(ax, ay), _mm256_unpackhi_pd(ax, ay));
            let (t2, t3) = (_mm256_unpacklo_pd(bx, by), _mm256_unpackhi_pd(bx, by));
            [
                bytemuck::cast(_mm256_permute2f128_pd::<0x20>(t0, t2)),
                bytemuck::cast(_mm256_permute2f128_pd::<0x20>(t1, t3)),
                bytemuck::cast(_mm256_permute2f128_pd::<0x31>(t0, t2)),
                bytemuck::cast(_mm256_permute2f128_pd::<0x31>(t1, t3)),
            ]
        }
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn gt(self, o: Self) -> Self {
            Self(_mm256_cmp_pd::<_CMP_GT_OQ>(self.0, o.0))
        }
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn lt(self, o: Self) -> Self {
            Self(_mm256_cmp_pd::<_CMP_LT_OQ>(self.0, o.0))
        }
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn and(self, o: Self) -> Self {
            Self(_mm256_and_pd(self.0, o.0))
        }
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn or(self, o: Self) -> Self {
            Self(_mm256_or_pd(self.0, o.0))
        }
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn flip(self, mask: Self) -> Self {
            Self(_mm256_xor_pd(
                self.0,
                _mm256_and_pd(mask.0, _mm256_set1_pd(-0.0)),
            ))
        }
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn hits(mask: Self) -> u64 {
            u64::from(_mm256_movemask_pd(mask.0).count_ones())
        }
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn inside(self, low: Self, high: Self) -> Self {
            Self(_mm256_and_pd(
                _mm256_cmp_pd::<_CMP_GE_OQ>(self.0, low.0),
                _mm256_cmp_pd::<_CMP_LE_OQ>(self.0, high.0),
            ))
        }
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn all(mask: Self) -> bool {
            _mm256_movemask_pd(mask.0) == 0b1111
        }
        /// The lanes rounded to `f32`, in one 128-bit register.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn narrow(self) -> __m128 {
            _mm256_cvtpd_ps(self.0)
        }
    }

    /// Two lanes in one SSE2 register, which every x86-64 processor has
    /// (through `safe_arch`, whose operations are there without `unsafe`
    /// wherever the build's target has SSE2). Two lines at a time, so that
    /// a batch's values fit the sixteen registers.
    #[derive(Clone, Copy)]
    pub struct Sse2(m128d);

    impl Sse2 {
        /// Lines a batch takes.
        pub const WIDTH: usize = 2;

        #[inline(always)]
        pub fn splat(x: f64) -> Self {
            Self(set_splat_m128d(x))
        }
        /// Rows `p1.x p1.y` and `p2.x p2.y` of two lines turned into
        /// columns.
        #[inline(always)]
        pub fn points(batch: [&Line; 2]) -> [Self; 4] {
            let r = batch.map(|l| {
                let v = row(l);
                [m128d::from([v[0], v[1]]), m128d::from([v[2], v[3]])]
            });
            [
                Self(unpack_low_m128d(r[0][0], r[1][0])),
                Self(unpack_high_m128d(r[0][0], r[1][0])),
                Self(unpack_low_m128d(r[0][1], r[1][1])),
                Self(unpack_high_m128d(r[0][1], r[1][1])),
            ]
        }
        lanewise!(
            [inline(always)]
            add => add_m128d, mul => mul_m128d,
        );
        #[inline(always)]
        pub fn add_first(self, o: Self) -> Self {
            let (a, b) = (self.0, o.0);
            let nan = cmp_unord_mask_m128d(a, a);
            let (sum, twice) = (add_m128d(a, b), add_m128d(a, a));
            Self(bitor_m128d(
                bitand_m128d(nan, twice),
                bitandnot_m128d(nan, sum),
            ))
        }
        #[inline(always)]
        pub fn velocities(batch: [&Line; 2]) -> (Self, Self) {
            let v = batch.map(|l| m128d::from([l.v.x, l.v.y]));
            (
                Self(unpack_low_m128d(v[0], v[1])),
                Self(unpack_high_m128d(v[0], v[1])),
            )
        }
        #[inline(always)]
        pub fn lines(point: [Self; 4], vx: Self, vy: Self) -> [Line; 2] {
            let [ax, ay, bx, by] = point.map(|c| c.0);
            let p1 = [unpack_low_m128d(ax, ay), unpack_high_m128d(ax, ay)];
            let p2 = [unpack_low_m128d(bx, by), unpack_high_m128d(bx, by)];
            let v = [unpack_low_m128d(vx.0, vy.0), unpack_high_m128d(vx.0, vy.0)];
            std::array::from_fn(|k| {
                let (a, b): ([f64; 2], [f64; 2]) = (p1[k].into(), p2[k].into());
                line_of([a[0], a[1], b[0], b[1]], v[k].into())
            })
        }
        /// Each line's `[p1.x, p1.y, p2.x, p2.y]`.
        #[inline(always)]
        pub fn rows(point: [Self; 4]) -> [[f64; 4]; 2] {
            let [ax, ay, bx, by] = point.map(|c| c.0);
            let p1 = [unpack_low_m128d(ax, ay), unpack_high_m128d(ax, ay)];
            let p2 = [unpack_low_m128d(bx, by), unpack_high_m128d(bx, by)];
            std::array::from_fn(|k| {
                let (a, b): ([f64; 2], [f64; 2]) = (p1[k].into(), p2[k].into());
                [a[0], a[1], b[0], b[1]]
            })
        }
        #[inline(always)]
        pub fn gt(self, o: Self) -> Self {
            Self(cmp_gt_mask_m128d(self.0, o.0))
        }
        #[inline(always)]
        pub fn lt(self, o: Self) -> Self {
            Self(cmp_lt_mask_m128d(self.0, o.0))
        }
        #[inline(always)]
        pub fn and(self, o: Self) -> Self {
            Self(bitand_m128d(self.0, o.0))
        }
        #[inline(always)]
        pub fn or(self, o: Self) -> Self {
            Self(bitor_m128d(self.0, o.0))
        }
        #[inline(always)]
        pub fn flip(self, mask: Self) -> Self {
            Self(bitxor_m128d(
                self.0,
                bitand_m128d(mask.0, set_splat_m128d(-0.0)),
            ))
        }
        #[inline(always)]
        pub fn hits(mask: Self) -> u64 {
            u64::from(move_mask_m128d(mask.0).count_ones())
        }
        #[inline(always)]
        pub fn inside(self, low: Self, high: Self) -> Self {
            Self(bitand_m128d(
                cmp_ge_mask_m128d(self.0, low.0),
                cmp_le_mask_m128d(self.0, high.0),
            ))
        }
        #[inline(always)]
        pub fn all(mask: Self) -> bool {
            move_mask_m128d(mask.0) == 0b11
        }
        /// The lanes rounded to `f32`, in the low half of a register
        /// (the high half zero).
        #[inline(always)]
        pub fn narrow(self) -> m128 {
            convert_to_m128_from_m128d(self.0)
        }
    }
}

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub(crate) use wasm::Simd128;

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
mod wasm {
    use super::{line_of, Line, LANES};
    use core::arch::wasm32::{
        f32x4_demote_f64x2_zero, f64x2_add, f64x2_ge, f64x2_gt, f64x2_le, f64x2_lt, f64x2_mul,
        f64x2_ne, f64x2_splat, i64x2_bitmask, i64x2_shuffle, u64x2_extract_lane,
        u64x2_replace_lane, v128, v128_and, v128_bitselect, v128_or, v128_xor,
    };

    /// Four lanes in two of WebAssembly's 128-bit vectors.
    #[derive(Clone, Copy)]
    pub struct Simd128([v128; 2]);

    impl Simd128 {
        /// Lines a batch takes.
        pub const WIDTH: usize = LANES;

        #[inline(always)]
        fn map2(self, o: Self, f: impl Fn(v128, v128) -> v128) -> Self {
            Self([f(self.0[0], o.0[0]), f(self.0[1], o.0[1])])
        }
        #[inline(always)]
        pub fn splat(x: f64) -> Self {
            Self([f64x2_splat(x); 2])
        }
        /// Rows `p1.x p1.y` and `p2.x p2.y` of four lines, each loaded
        /// whole, turned into columns two lines at a time.
        #[inline(always)]
        pub fn points(batch: [&Line; LANES]) -> [Self; 4] {
            let p1 = batch.map(|l| bytemuck::cast::<_, v128>(l.p1));
            let p2 = batch.map(|l| bytemuck::cast::<_, v128>(l.p2));
            [
                Self::columns::<0, 2>(p1),
                Self::columns::<1, 3>(p1),
                Self::columns::<0, 2>(p2),
                Self::columns::<1, 3>(p2),
            ]
        }
        /// Lane `A` (then `B`, the same lane of the next) of each of four
        /// pairs, as four lanes: `[r0[A], r1[A] | r2[A], r3[A]]` for `A =
        /// 0, B = 2`.
        #[inline(always)]
        fn columns<const A: usize, const B: usize>(r: [v128; 4]) -> Self {
            Self([
                i64x2_shuffle::<A, B>(r[0], r[1]),
                i64x2_shuffle::<A, B>(r[2], r[3]),
            ])
        }
        lanewise!(
            map2 [inline(always)]
            add => f64x2_add, mul => f64x2_mul,
            gt => f64x2_gt, lt => f64x2_lt, and => v128_and, or => v128_or,
        );
        #[inline(always)]
        pub fn add_first(self, o: Self) -> Self {
            self.map2(o, |a, b| {
                let nan = f64x2_ne(a, a);
                v128_bitselect(f64x2_add(a, a), f64x2_add(a, b), nan)
            })
        }
        /// Each line's `[v.x, v.y]` loaded whole, turned into columns.
        #[inline(always)]
        pub fn velocities(batch: [&Line; LANES]) -> (Self, Self) {
            let v = batch.map(|l| bytemuck::cast::<_, v128>(l.v));
            (Self::columns::<0, 2>(v), Self::columns::<1, 3>(v))
        }
        /// The lines from their values in lanes: [`Simd128::rows`] and
        /// the velocities turned back as the points are.
        #[inline(always)]
        pub fn lines(point: [Self; 4], vx: Self, vy: Self) -> [Line; LANES] {
            let rows = Self::rows(point);
            let v = Self::pairs(vx, vy).map(bytemuck::cast::<v128, [f64; 2]>);
            std::array::from_fn(|k| line_of(rows[k], v[k]))
        }
        /// Each line's `[p1.x, p1.y, p2.x, p2.y]`: the columns turned back
        /// into rows two lines at a time.
        #[inline(always)]
        pub fn rows(point: [Self; 4]) -> [[f64; 4]; LANES] {
            let [ax, ay, bx, by] = point;
            let (p1, p2) = (Self::pairs(ax, ay), Self::pairs(bx, by));
            std::array::from_fn(|k| bytemuck::cast([p1[k], p2[k]]))
        }
        /// Each line's `[x, y]` from its `x` and `y` in lanes.
        #[inline(always)]
        fn pairs(x: Self, y: Self) -> [v128; LANES] {
            let ([x01, x23], [y01, y23]) = (x.0, y.0);
            [
                i64x2_shuffle::<0, 2>(x01, y01),
                i64x2_shuffle::<1, 3>(x01, y01),
                i64x2_shuffle::<0, 2>(x23, y23),
                i64x2_shuffle::<1, 3>(x23, y23),
            ]
        }
        #[inline(always)]
        pub fn flip(self, mask: Self) -> Self {
            self.map2(mask, |a, m| v128_xor(a, v128_and(m, f64x2_splat(-0.0))))
        }
        #[inline(always)]
        pub fn hits(mask: Self) -> u64 {
            let [a, b] = mask.0.map(|m| i64x2_bitmask(m).count_ones());
            u64::from(a + b)
        }
        #[inline(always)]
        pub fn inside(self, low: Self, high: Self) -> Self {
            let ge = self.map2(low, |x, l| f64x2_ge(x, l));
            ge.map2(self.map2(high, |x, h| f64x2_le(x, h)), |a, b| {
                v128_and(a, b)
            })
        }
        #[inline(always)]
        pub fn all(mask: Self) -> bool {
            i64x2_bitmask(mask.0[0]) & i64x2_bitmask(mask.0[1]) == 0b11
        }
        /// The lanes rounded to `f32`, in one vector. Each half is rounded
        /// apart and passed through `black_box`: where the compiler sees
        /// both roundings joined, it rounds the four values one by one
        /// (eight scalar instructions for each, rather than one vector
        /// instruction and a copy through memory; `koch` 0.068 s against
        /// 0.061 under Node).
        #[inline(always)]
        pub fn narrow(self) -> v128 {
            let [a, b] = self
                .0
                .map(|x| core::hint::black_box(f32x4_demote_f64x2_zero(x)));
            u64x2_replace_lane::<1>(a, u64x2_extract_lane::<0>(b))
        }
    }
}

/// The lane type of the baseline's batches: the target's own where it has
/// one (every x86-64 processor has SSE2; WebAssembly with SIMD), else
/// plain values.
#[cfg(target_arch = "x86_64")]
pub(crate) type DefaultLanes = Sse2;
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub(crate) type DefaultLanes = Simd128;
#[cfg(not(any(
    target_arch = "x86_64",
    all(target_arch = "wasm32", target_feature = "simd128")
)))]
pub(crate) type DefaultLanes = Scalar;

pub(crate) mod single;
