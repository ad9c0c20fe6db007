//! `f32` lanes, one type per target, for the sweep's packed hulls
//! ([`crate::detect::sweep::hull`]): each lane a line, made from the
//! move's `f64` lanes ([`super`]) rounded to nearest, as many of them as
//! the register holds, so that a register holds twice the lines an `f64`
//! register does. Each operation is the IEEE operation on every lane
//! (`min(a, b)` is `a < b ? a : b`, `max(a, b)` is `a > b ? a : b`), so
//! every type gives the same bits as the others and as one line made
//! alone ([`Scalar`] of one lane).
//!
//! - [`Avx2`]: eight lanes in one 256-bit register, of two of
//!   [`super::Avx2`]'s;
//! - [`Sse2`]: four lanes in one 128-bit register, of two of
//!   [`super::Sse2`]'s;
//! - [`Simd128`]: four lanes in one of WebAssembly's vectors, of one
//!   [`super::Simd128`]'s;
//! - [`Scalar`]: plain values, any number: four of one [`super::Scalar`]'s
//!   on other targets, one for a line alone.
//!
//! Each type writes the hulls out of its lanes: a line's eight bounds
//! (its low bounds, then its high bounds negated) and its key, the low
//! bound along the sweep's direction, or [`NO_KEY`] where the line has no
//! hull, in three parts, each small enough to be inlined where it is
//! called.

/// The key of a box that takes no part in the sweep (a line without a
/// finite hull): it sorts after every real key, and no comparison
/// `key <= end` with a real box's end holds for it, so it also stops a
/// scan.
pub(crate) const NO_KEY: f32 = f32::INFINITY;

/// Eight `f32` lower bounds: `[lo_x, lo_y, lo_u, lo_w, -hi_x, -hi_y, -hi_u, -hi_w]`.
pub(crate) type Packed = [f32; 8];

/// Lanes per half of a packed hull: one per direction.
pub(crate) const DIRECTIONS: usize = 4;

/// `N` plain values.
#[derive(Clone, Copy)]
pub(crate) struct Scalar<const N: usize>(pub [f32; N]);

impl<const N: usize> Scalar<N> {
    /// Lines a batch takes.
    pub const WIDTH: usize = N;

    #[inline(always)]
    fn map2(self, o: Self, f: impl Fn(f32, f32) -> f32) -> Self {
        Self(std::array::from_fn(|k| f(self.0[k], o.0[k])))
    }
    /// Every lane `x` rounded to `f32`.
    #[inline(always)]
    pub fn splat(x: f64) -> Self {
        Self([x as f32; N])
    }
    /// The values rounded to `f32`.
    #[inline(always)]
    pub fn round(v: [f64; N]) -> Self {
        Self(v.map(|x| x as f32))
    }
    #[inline(always)]
    pub fn add(self, o: Self) -> Self {
        self.map2(o, |a, b| a + b)
    }
    #[inline(always)]
    pub fn sub(self, o: Self) -> Self {
        self.map2(o, |a, b| a - b)
    }
    #[inline(always)]
    pub fn mul(self, o: Self) -> Self {
        self.map2(o, |a, b| a * b)
    }
    #[inline(always)]
    pub fn min(self, o: Self) -> Self {
        self.map2(o, |a, b| if a < b { a } else { b })
    }
    #[inline(always)]
    pub fn max(self, o: Self) -> Self {
        self.map2(o, |a, b| if a > b { a } else { b })
    }
    #[inline(always)]
    pub fn neg(self) -> Self {
        Self(self.0.map(|a| -a))
    }
    /// Bit `k` set where lane `k` of `sum` is finite and of `magnitude` at
    /// most `largest` (rounded to `f32`).
    #[inline(always)]
    pub fn valid(sum: Self, magnitude: Self, largest: f64) -> u32 {
        (0..N).fold(0, |bits, k| {
            let ok = sum.0[k].is_finite() && magnitude.0[k] <= largest as f32;
            bits | (u32::from(ok) << k)
        })
    }
    /// Writes the lines' least values by direction, `low[r]` of line `k`
    /// into `hulls[k][r]`.
    #[inline(always)]
    pub fn store_low(low: [Self; DIRECTIONS], hulls: &mut [Packed]) {
        for (k, hull) in hulls[..N].iter_mut().enumerate() {
            for r in 0..DIRECTIONS {
                hull[r] = low[r].0[k];
            }
        }
    }
    /// Writes the lines' greatest values by direction negated, `-high[r]`
    /// of line `k` into `hulls[k][DIRECTIONS + r]`.
    #[inline(always)]
    pub fn store_high(high: [Self; DIRECTIONS], hulls: &mut [Packed]) {
        for (k, hull) in hulls[..N].iter_mut().enumerate() {
            for r in 0..DIRECTIONS {
                hull[DIRECTIONS + r] = -high[r].0[k];
            }
        }
    }
    /// Writes the lines' keys: `key` where `valid` (bit `k` for line `k`),
    /// else [`NO_KEY`].
    #[inline(always)]
    pub fn store_keys(key: Self, valid: u32, keys: &mut [f32]) {
        for (k, out) in keys[..N].iter_mut().enumerate() {
            *out = if valid & (1 << k) != 0 {
                key.0[k]
            } else {
                NO_KEY
            };
        }
    }
}

#[cfg_attr(
    any(
        target_arch = "x86_64",
        all(target_arch = "wasm32", target_feature = "simd128")
    ),
    allow(dead_code)
)]
impl Scalar<{ super::LANES }> {
    /// The lanes of one [`super::Scalar`], rounded to `f32`.
    #[inline(always)]
    pub fn narrow([v]: [super::Scalar; 1]) -> Self {
        Self(v.narrow())
    }
}

#[cfg(target_arch = "x86_64")]
pub(crate) use x86::{Avx2, Sse2};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{Packed, DIRECTIONS, NO_KEY};
    use safe_arch::{
        add_m128, bitand_m128, bitandnot_m128, bitor_m128, bitxor_m128, cmp_le_mask_m128,
        cmp_lt_mask_m128, m128, max_m128, min_m128, move_high_low_m128, move_low_high_m128,
        mul_m128, set_splat_m128, sub_m128, unpack_high_m128, unpack_low_m128,
    };
    use std::arch::x86_64::{
        __m256, _mm256_add_ps, _mm256_and_ps, _mm256_blendv_ps, _mm256_cmp_ps, _mm256_max_ps,
        _mm256_min_ps, _mm256_mul_ps, _mm256_set1_ps, _mm256_set_m128, _mm256_shuffle_ps,
        _mm256_sub_ps, _mm256_unpackhi_ps, _mm256_unpacklo_ps, _mm256_xor_ps, _CMP_LE_OQ,
        _CMP_LT_OQ,
    };

    /// `f32` with every bit but the sign: `x & ABS` is `|x|`.
    const ABS: f32 = f32::from_bits(!(1u32 << 31));

    /// Eight lanes in one AVX2 register. Its operations are compiled with
    /// AVX2 and called only from code compiled with it.
    #[derive(Clone, Copy)]
    pub struct Avx2(__m256);

    impl Avx2 {
        /// Lines a batch takes.
        pub const WIDTH: usize = 8;

        /// Every lane `x` rounded to `f32`.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn splat(x: f64) -> Self {
            Self(_mm256_set1_ps(x as f32))
        }
        /// The lanes of two [`crate::lanes::Avx2`], rounded to `f32`: the
        /// first's in the low half.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn narrow([a, b]: [crate::lanes::Avx2; 2]) -> Self {
            Self(_mm256_set_m128(b.narrow(), a.narrow()))
        }
        // `vminps` is `a < b ? a : b` in every lane, `vmaxps` `a > b ? a : b`.
        lanewise!(
            [inline, target_feature(enable = "avx2")]
            add => _mm256_add_ps, sub => _mm256_sub_ps, mul => _mm256_mul_ps,
            min => _mm256_min_ps, max => _mm256_max_ps,
        );
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn neg(self) -> Self {
            Self(_mm256_xor_ps(self.0, _mm256_set1_ps(-0.0)))
        }
        /// All ones in each lane whose `sum` is finite (NaN and infinities
        /// fail) and whose `magnitude` is at most `largest` (rounded to
        /// `f32`).
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn valid(sum: Self, magnitude: Self, largest: f64) -> __m256 {
            let abs = _mm256_and_ps(sum.0, _mm256_set1_ps(ABS));
            let finite = _mm256_cmp_ps::<_CMP_LT_OQ>(abs, _mm256_set1_ps(f32::INFINITY));
            let within = _mm256_cmp_ps::<_CMP_LE_OQ>(magnitude.0, _mm256_set1_ps(largest as f32));
            _mm256_and_ps(finite, within)
        }
        /// Writes the eight lines' least values by direction, `low[r]` of
        /// line `k` into `hulls[k][r]`: a 4 x 4 transpose in each half of
        /// the rows (pairs interleaved, then fours), which leaves line `k`'s
        /// four values beside line `k + 4`'s; each four takes one store.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn store_low(low: [Self; DIRECTIONS], hulls: &mut [Packed]) {
            Self::store_fours(low.map(|v| v.0), 0, hulls);
        }
        /// Writes the eight lines' greatest values by direction negated,
        /// `-high[r]` of line `k` into `hulls[k][DIRECTIONS + r]`, as
        /// [`Avx2::store_low`] does.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn store_high(high: [Self; DIRECTIONS], hulls: &mut [Packed]) {
            let sign = _mm256_set1_ps(-0.0);
            Self::store_fours(high.map(|v| _mm256_xor_ps(v.0, sign)), DIRECTIONS, hulls);
        }
        /// Writes `rows[r]` of line `k` into `hulls[k][at + r]`.
        #[inline]
        #[target_feature(enable = "avx2")]
        fn store_fours(rows: [__m256; DIRECTIONS], at: usize, hulls: &mut [Packed]) {
            let hulls: &mut [Packed; 8] = (&mut hulls[..8]).try_into().expect("eight hulls");
            let [r0, r1, r2, r3] = rows;
            // Lanes `[r0[0] r1[0] r0[1] r1[1] | r0[4] r1[4] r0[5] r1[5]]`
            // and so on.
            let (t0, t1) = (_mm256_unpacklo_ps(r0, r1), _mm256_unpackhi_ps(r0, r1));
            let (t2, t3) = (_mm256_unpacklo_ps(r2, r3), _mm256_unpackhi_ps(r2, r3));
            // Lanes `[r0[k] r1[k] r2[k] r3[k] | the same of line k + 4]`.
            let fours = [
                _mm256_shuffle_ps::<0x44>(t0, t2),
                _mm256_shuffle_ps::<0xEE>(t0, t2),
                _mm256_shuffle_ps::<0x44>(t1, t3),
                _mm256_shuffle_ps::<0xEE>(t1, t3),
            ];
            for (k, four) in fours.into_iter().enumerate() {
                let four: [f32; 8] = bytemuck::cast(four);
                hulls[k][at..at + DIRECTIONS].copy_from_slice(&four[..4]);
                hulls[k + 4][at..at + DIRECTIONS].copy_from_slice(&four[4..]);
            }
        }
        /// Writes the eight lines' keys: `key` where `valid`, else
        /// [`NO_KEY`], in one store.
        #[inline]
        #[target_feature(enable = "avx2")]
        pub fn store_keys(key: Self, valid: __m256, keys: &mut [f32]) {
            let key = _mm256_blendv_ps(_mm256_set1_ps(NO_KEY), key.0, valid);
            let out: &mut [f32; 8] = (&mut keys[..8]).try_into().expect("eight keys");
            *out = bytemuck::cast(key);
        }
    }

    /// Four lanes in one SSE2 register, which every x86-64 processor has
    /// (through `safe_arch`, whose operations are there without `unsafe`
    /// wherever the build's target has SSE2).
    #[derive(Clone, Copy)]
    pub struct Sse2(m128);

    impl Sse2 {
        /// Lines a batch takes.
        pub const WIDTH: usize = 4;

        /// Every lane `x` rounded to `f32`.
        #[inline(always)]
        pub fn splat(x: f64) -> Self {
            Self(set_splat_m128(x as f32))
        }
        /// The lanes of two [`crate::lanes::Sse2`], rounded to `f32`: the
        /// first's in the low half.
        #[inline(always)]
        pub fn narrow([a, b]: [crate::lanes::Sse2; 2]) -> Self {
            Self(move_low_high_m128(a.narrow(), b.narrow()))
        }
        // `minps` is `a < b ? a : b` in every lane, `maxps` `a > b ? a : b`.
        lanewise!(
            [inline(always)]
            add => add_m128, sub => sub_m128, mul => mul_m128,
            min => min_m128, max => max_m128,
        );
        #[inline(always)]
        pub fn neg(self) -> Self {
            Self(bitxor_m128(self.0, set_splat_m128(-0.0)))
        }
        /// All ones in each lane whose `sum` is finite (NaN and infinities
        /// fail) and whose `magnitude` is at most `largest` (rounded to
        /// `f32`).
        #[inline(always)]
        pub fn valid(sum: Self, magnitude: Self, largest: f64) -> m128 {
            let abs = bitand_m128(sum.0, set_splat_m128(ABS));
            let finite = cmp_lt_mask_m128(abs, set_splat_m128(f32::INFINITY));
            let within = cmp_le_mask_m128(magnitude.0, set_splat_m128(largest as f32));
            bitand_m128(finite, within)
        }
        /// Writes the four lines' least values by direction, `low[r]` of
        /// line `k` into `hulls[k][r]`, by a 4 x 4 transpose.
        #[inline(always)]
        pub fn store_low(low: [Self; DIRECTIONS], hulls: &mut [Packed]) {
            Self::store_fours(low.map(|v| v.0), 0, hulls);
        }
        /// Writes the four lines' greatest values by direction negated,
        /// `-high[r]` of line `k` into `hulls[k][DIRECTIONS + r]`.
        #[inline(always)]
        pub fn store_high(high: [Self; DIRECTIONS], hulls: &mut [Packed]) {
            let sign = set_splat_m128(-0.0);
            Self::store_fours(high.map(|v| bitxor_m128(v.0, sign)), DIRECTIONS, hulls);
        }
        /// Writes `rows[r]` of line `k` into `hulls[k][at + r]`.
        #[inline(always)]
        fn store_fours(rows: [m128; DIRECTIONS], at: usize, hulls: &mut [Packed]) {
            let [r0, r1, r2, r3] = rows;
            let (t0, t1) = (unpack_low_m128(r0, r1), unpack_high_m128(r0, r1));
            let (t2, t3) = (unpack_low_m128(r2, r3), unpack_high_m128(r2, r3));
            let lines = [
                move_low_high_m128(t0, t2),
                move_high_low_m128(t2, t0),
                move_low_high_m128(t1, t3),
                move_high_low_m128(t3, t1),
            ];
            for (hull, line) in hulls[..4].iter_mut().zip(lines) {
                let line: [f32; 4] = line.into();
                hull[at..at + DIRECTIONS].copy_from_slice(&line);
            }
        }
        /// Writes the four lines' keys: `key` where `valid`, else
        /// [`NO_KEY`].
        #[inline(always)]
        pub fn store_keys(key: Self, valid: m128, keys: &mut [f32]) {
            let key = bitor_m128(
                bitand_m128(valid, key.0),
                bitandnot_m128(valid, set_splat_m128(NO_KEY)),
            );
            let key: [f32; 4] = key.into();
            keys[..4].copy_from_slice(&key);
        }
    }
}

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub(crate) use wasm::Simd128;

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
mod wasm {
    use super::{Packed, DIRECTIONS, NO_KEY};
    use core::arch::wasm32::{
        f32x4_abs, f32x4_add, f32x4_le, f32x4_lt, f32x4_mul, f32x4_neg, f32x4_pmax, f32x4_pmin,
        f32x4_splat, f32x4_sub, i32x4_shuffle, v128, v128_and, v128_bitselect,
    };

    /// Four lanes in one of WebAssembly's 128-bit vectors.
    #[derive(Clone, Copy)]
    pub struct Simd128(v128);

    impl Simd128 {
        /// Lines a batch takes.
        pub const WIDTH: usize = 4;

        /// Every lane `x` rounded to `f32`.
        #[inline(always)]
        pub fn splat(x: f64) -> Self {
            Self(f32x4_splat(x as f32))
        }
        /// The lanes of one [`crate::lanes::Simd128`], rounded to `f32`.
        #[inline(always)]
        pub fn narrow([v]: [crate::lanes::Simd128; 1]) -> Self {
            Self(v.narrow())
        }
        lanewise!(
            [inline(always)]
            add => f32x4_add, sub => f32x4_sub, mul => f32x4_mul,
        );
        /// `a < b ? a : b` (`pmin(x, y)` is `y < x ? y : x`).
        #[inline(always)]
        pub fn min(self, o: Self) -> Self {
            Self(f32x4_pmin(o.0, self.0))
        }
        /// `a > b ? a : b` (`pmax(x, y)` is `x < y ? y : x`).
        #[inline(always)]
        pub fn max(self, o: Self) -> Self {
            Self(f32x4_pmax(o.0, self.0))
        }
        #[inline(always)]
        pub fn neg(self) -> Self {
            Self(f32x4_neg(self.0))
        }
        /// All ones in each lane whose `sum` is finite (NaN and infinities
        /// fail) and whose `magnitude` is at most `largest` (rounded to
        /// `f32`).
        #[inline(always)]
        pub fn valid(sum: Self, magnitude: Self, largest: f64) -> v128 {
            let finite = f32x4_lt(f32x4_abs(sum.0), f32x4_splat(f32::INFINITY));
            v128_and(finite, f32x4_le(magnitude.0, f32x4_splat(largest as f32)))
        }
        /// Writes the four lines' least values by direction, `low[r]` of
        /// line `k` into `hulls[k][r]`, by a 4 x 4 transpose.
        #[inline(always)]
        pub fn store_low(low: [Self; DIRECTIONS], hulls: &mut [Packed]) {
            Self::store_fours(low.map(|v| v.0), 0, hulls);
        }
        /// Writes the four lines' greatest values by direction negated,
        /// `-high[r]` of line `k` into `hulls[k][DIRECTIONS + r]`.
        #[inline(always)]
        pub fn store_high(high: [Self; DIRECTIONS], hulls: &mut [Packed]) {
            Self::store_fours(high.map(|v| f32x4_neg(v.0)), DIRECTIONS, hulls);
        }
        /// Writes `rows[r]` of line `k` into `hulls[k][at + r]`.
        #[inline(always)]
        fn store_fours(rows: [v128; DIRECTIONS], at: usize, hulls: &mut [Packed]) {
            let [r0, r1, r2, r3] = rows;
            // `[r0[0] r1[0] r0[1] r1[1]]` and so on.
            let (t0, t1) = (
                i32x4_shuffle::<0, 4, 1, 5>(r0, r1),
                i32x4_shuffle::<2, 6, 3, 7>(r0, r1),
            );
            let (t2, t3) = (
                i32x4_shuffle::<0, 4, 1, 5>(r2, r3),
                i32x4_shuffle::<2, 6, 3, 7>(r2, r3),
            );
            let lines = [
                i32x4_shuffle::<0, 1, 4, 5>(t0, t2),
                i32x4_shuffle::<2, 3, 6, 7>(t0, t2),
                i32x4_shuffle::<0, 1, 4, 5>(t1, t3),
                i32x4_shuffle::<2, 3, 6, 7>(t1, t3),
            ];
            for (hull, line) in hulls[..4].iter_mut().zip(lines) {
                let line: [f32; 4] = bytemuck::cast(line);
                hull[at..at + DIRECTIONS].copy_from_slice(&line);
            }
        }
        /// Writes the four lines' keys: `key` where `valid`, else
        /// [`NO_KEY`].
        #[inline(always)]
        pub fn store_keys(key: Self, valid: v128, keys: &mut [f32]) {
            let key = v128_bitselect(key.0, f32x4_splat(NO_KEY), valid);
            let key: [f32; 4] = bytemuck::cast(key);
            keys[..4].copy_from_slice(&key);
        }
    }
}

/// The lane type of the baseline's hulls: the target's own where it has
/// one, else plain values, four lines at a time.
#[cfg(target_arch = "x86_64")]
pub(crate) type DefaultLanes = Sse2;
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub(crate) type DefaultLanes = Simd128;
#[cfg(not(any(
    target_arch = "x86_64",
    all(target_arch = "wasm32", target_feature = "simd128")
)))]
pub(crate) type DefaultLanes = Scalar<{ super::LANES }>;
