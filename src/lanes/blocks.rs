//! Blocks of eight packed boxes at a time, for the sweep: its masks (the
//! keys within a box's end, the hulls that overlap its reach, the boxes
//! that reach the key after them), the check that boxes lie in their
//! widened boxes, and the look for keys out of order. With AVX2 each is a
//! few instructions for the block; with WebAssembly's SIMD, two 128-bit
//! vectors; other targets take a box at a time where they are called.
//! Each gives the bits the one-box-at-a-time code gives.

#[cfg(any(
    target_arch = "x86_64",
    all(target_arch = "wasm32", target_feature = "simd128")
))]
use super::single::{Packed, DIRECTIONS};

/// Boxes a block holds.
pub(crate) const BLOCK: usize = 8;

/// `x` in every lane, for [`within`].
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
pub(crate) fn splat(x: f32) -> x86::Lanes {
    std::arch::x86_64::_mm256_set1_ps(x)
}

/// A packed box's eight lanes in one register, for [`overlapping`].
#[cfg(target_arch = "x86_64")]
#[inline(always)]
pub(crate) fn packed(p: &Packed) -> x86::Lanes {
    bytemuck::cast(*p)
}

#[cfg(target_arch = "x86_64")]
pub(crate) use x86::{not_within, out_of_order_avx2, overlapping, reaching, within};

/// With AVX2.
#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::{Packed, BLOCK, DIRECTIONS};
    use std::arch::x86_64::{
        __m256, __m256i, _mm256_add_ps, _mm256_and_ps, _mm256_blend_ps, _mm256_castps_si256,
        _mm256_castsi256_ps, _mm256_cmp_ps, _mm256_cmpeq_epi32, _mm256_min_ps, _mm256_movemask_ps,
        _mm256_or_si256, _mm256_packs_epi16, _mm256_packs_epi32, _mm256_permute2x128_si256,
        _mm256_permutevar8x32_ps, _mm256_set1_epi32, _mm256_set1_ps, _mm256_setzero_si256,
        _mm256_xor_ps, _CMP_GE_OQ, _CMP_GT_OQ, _CMP_LE_OQ, _CMP_NLE_UQ,
    };

    /// Which of eight keys are at most `end8`'s: bit `k` for `keys[k]`,
    /// in one comparison.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(crate) fn within(keys: &[f32; BLOCK], end8: __m256) -> u32 {
        let k8: __m256 = bytemuck::cast(*keys);
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LE_OQ>(k8, end8)) as u32
    }

    /// Which of eight boxes `hulls` meet the key after them, `next[k]`
    /// after `hulls[k]`: bit `k` where `next[k]` is at most the box's
    /// greatest value along `along` (and at most `f32::MAX`), as the sweep
    /// asks of each box. Each hull's lane is spread to a register by one
    /// permutation and blended into its place.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(crate) fn reaching(next: &[f32; BLOCK], hulls: &[Packed; BLOCK], along: usize) -> u32 {
        let lane = _mm256_set1_epi32((DIRECTIONS + along) as i32);
        let spread = |k: usize| _mm256_permutevar8x32_ps(bytemuck::cast(hulls[k]), lane);
        // Lane k: hull k's negated greatest value.
        let mut low = spread(0);
        low = _mm256_blend_ps::<0b0000_0010>(low, spread(1));
        low = _mm256_blend_ps::<0b0000_0100>(low, spread(2));
        low = _mm256_blend_ps::<0b0000_1000>(low, spread(3));
        low = _mm256_blend_ps::<0b0001_0000>(low, spread(4));
        low = _mm256_blend_ps::<0b0010_0000>(low, spread(5));
        low = _mm256_blend_ps::<0b0100_0000>(low, spread(6));
        low = _mm256_blend_ps::<0b1000_0000>(low, spread(7));
        let end = _mm256_min_ps(
            _mm256_xor_ps(low, _mm256_set1_ps(-0.0)),
            _mm256_set1_ps(f32::MAX),
        );
        within(next, end)
    }

    /// Which of eight hulls overlap the box whose reach is `reach8`: bit
    /// `k` for `hulls[k]`. Each hull's lanes beyond reach (NaN too) come
    /// out of one comparison as all ones; packing them to bytes, two hulls
    /// at a time then four, and folding each hull's two halves together
    /// leaves four bytes a hull, which are all zero exactly when no lane
    /// is beyond. That is a few vector instructions for the whole block,
    /// rather than a mask, a test and a shift for each hull
    /// (docs/DESIGN.md, "Sweep and prune", the sweep).
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(crate) fn overlapping(hulls: &[Packed; BLOCK], reach8: __m256) -> u32 {
        let beyond = |k: usize| {
            let hull: __m256 = bytemuck::cast(hulls[k]);
            _mm256_castps_si256(_mm256_cmp_ps::<_CMP_NLE_UQ>(hull, reach8))
        };
        // Per 128-bit half, as 16-bit lanes: hull 2m's four lanes of that
        // half, then hull 2m + 1's.
        let pairs = [0, 2, 4, 6].map(|k| _mm256_packs_epi32(beyond(k), beyond(k + 1)));
        // As bytes: in the low half, lanes 0 to 3 of hulls 0..4 (a 32-bit
        // word each); in the high half, their lanes 4 to 7.
        let low: __m256i = _mm256_packs_epi16(pairs[0], pairs[1]);
        let high: __m256i = _mm256_packs_epi16(pairs[2], pairs[3]);
        // Word k: hull k's lanes 0 to 3, or'ed with word k of its lanes 4
        // to 7.
        let halves = _mm256_or_si256(
            _mm256_permute2x128_si256::<0x20>(low, high),
            _mm256_permute2x128_si256::<0x31>(low, high),
        );
        let within = _mm256_cmpeq_epi32(halves, _mm256_setzero_si256());
        _mm256_movemask_ps(_mm256_castsi256_ps(within)) as u32
    }

    /// A register of eight `f32` lanes.
    pub(crate) type Lanes = __m256;

    /// Bit `k` where `run[k] > run[k + 1]`: eight keys against the eight
    /// after them in one comparison.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(crate) fn out_of_order_avx2(run: &[f32; BLOCK + 1]) -> u32 {
        let before: __m256 =
            bytemuck::cast(<[f32; BLOCK]>::try_from(&run[..BLOCK]).expect("a run"));
        let after: __m256 = bytemuck::cast(<[f32; BLOCK]>::try_from(&run[1..]).expect("a run"));
        _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GT_OQ>(before, after)) as u32
    }

    /// Calls `check(from, to)` for each block of boxes `from..to` of
    /// `boxes` (a whole block at a time) of which one may not lie in its
    /// widened box of `wide` (moved by `shift`, if any) as
    /// `inside` or `inside_moved` of the sweep's `near` module
    /// tells (the same comparisons, lane by lane). Returns where the
    /// whole blocks end.
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(crate) fn not_within(
        boxes: &[Packed],
        wide: &[Packed],
        shift: Option<&Packed>,
        check: &mut impl FnMut(usize, usize),
    ) -> usize {
        let lanes = |p: &Packed| -> __m256 { bytemuck::cast(*p) };
        let whole = boxes.len().min(wide.len()) / BLOCK * BLOCK;
        let blocks = boxes[..whole]
            .chunks_exact(BLOCK)
            .zip(wide.chunks_exact(BLOCK));
        let all = |each: &dyn Fn(usize) -> __m256| {
            let pairs: [__m256; BLOCK / 2] =
                std::array::from_fn(|k| _mm256_and_ps(each(2 * k), each(2 * k + 1)));
            let all = _mm256_and_ps(
                _mm256_and_ps(pairs[0], pairs[1]),
                _mm256_and_ps(pairs[2], pairs[3]),
            );
            _mm256_movemask_ps(all) == 0xFF
        };
        match shift {
            None => {
                for (c, (b, w)) in blocks.enumerate() {
                    let each = |k: usize| _mm256_cmp_ps::<_CMP_GE_OQ>(lanes(&b[k]), lanes(&w[k]));
                    if !all(&each) {
                        check(c * BLOCK, (c + 1) * BLOCK);
                    }
                }
            }
            Some(s) => {
                let s = lanes(s);
                for (c, (b, w)) in blocks.enumerate() {
                    let each = |k: usize| {
                        _mm256_cmp_ps::<_CMP_GT_OQ>(lanes(&b[k]), _mm256_add_ps(lanes(&w[k]), s))
                    };
                    if !all(&each) {
                        check(c * BLOCK, (c + 1) * BLOCK);
                    }
                }
            }
        }
        whole
    }
}

/// The sweep's masks of a block with WebAssembly's 128-bit vectors: each
/// hull's lanes beyond reach (NaN too) from two comparisons, packed to
/// bytes as the AVX2 masks pack them, and a hull within reach exactly
/// when its four bytes are zero.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
pub(crate) fn masks_simd128(
    end: f32,
    reach: &Packed,
) -> impl Fn(&[f32; BLOCK], &[Packed; BLOCK]) -> (u32, u32) {
    use core::arch::wasm32::{
        f32x4, f32x4_le, f32x4_splat, i16x8_narrow_i32x4, i32x4_bitmask, i32x4_eq, i32x4_splat,
        i8x16_narrow_i16x8, v128, v128_not, v128_or,
    };
    let half = |v: &[f32], k: usize| f32x4(v[k], v[k + 1], v[k + 2], v[k + 3]);
    let end4 = f32x4_splat(end);
    let (reach_lo, reach_hi) = (half(reach, 0), half(reach, 4));
    move |keys, hulls| {
        let within = |k| u32::from(i32x4_bitmask(f32x4_le(half(keys, k), end4)));
        // Not at most (NaN too): beyond reach.
        let beyond = |k: usize| -> v128 {
            let lo = f32x4_le(half(&hulls[k], 0), reach_lo);
            let hi = f32x4_le(half(&hulls[k], 4), reach_hi);
            v128_or(v128_not(lo), v128_not(hi))
        };
        let quad = |k: usize| {
            let low = i16x8_narrow_i32x4(beyond(k), beyond(k + 1));
            let high = i16x8_narrow_i32x4(beyond(k + 2), beyond(k + 3));
            let bytes = i8x16_narrow_i16x8(low, high);
            u32::from(i32x4_bitmask(i32x4_eq(bytes, i32x4_splat(0))))
        };
        (within(0) | within(4) << 4, quad(0) | quad(4) << 4)
    }
}

/// Which of a block of boxes meet the key after them, with WebAssembly's
/// SIMD: each box's end gathered lane by lane and compared four at a time.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
pub(crate) fn reaching_simd128(next: &[f32; BLOCK], hulls: &[Packed; BLOCK], along: usize) -> u32 {
    use core::arch::wasm32::{f32x4, f32x4_le, f32x4_neg, f32x4_pmin, f32x4_splat, i32x4_bitmask};
    let lane = DIRECTIONS + along;
    {
        let within = |k: usize| {
            let low = f32x4(
                hulls[k][lane],
                hulls[k + 1][lane],
                hulls[k + 2][lane],
                hulls[k + 3][lane],
            );
            // `pmin(MAX, x)` is `x < MAX ? x : MAX`: MAX for NaN, as
            // `f32::min` gives.
            let end = f32x4_pmin(f32x4_splat(f32::MAX), f32x4_neg(low));
            let keys = f32x4(next[k], next[k + 1], next[k + 2], next[k + 3]);
            u32::from(i32x4_bitmask(f32x4_le(keys, end)))
        };
        within(0) | within(4) << 4
    }
}

/// Bit `k` where `run[k] > run[k + 1]`, with WebAssembly's SIMD: four keys
/// against the four after them at a time.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
pub(crate) fn out_of_order_simd128(run: &[f32; BLOCK + 1]) -> u32 {
    use core::arch::wasm32::{f32x4, f32x4_gt, i32x4_bitmask};
    let four = |k: usize| f32x4(run[k], run[k + 1], run[k + 2], run[k + 3]);
    let half = |k: usize| u32::from(i32x4_bitmask(f32x4_gt(four(k), four(k + 1))));
    half(0) | half(4) << 4
}
