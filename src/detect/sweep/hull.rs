//! The packed hull: a box in up to four directions as eight `f32` lower
//! bounds, so that the overlap test of two boxes is one comparison of eight
//! lanes.
//!
//! A box with least values `lo[a]` and greatest values `hi[a]` along
//! directions `a = 0..4` is packed as `[lo[0..4], -hi[0..4]]`, every lane
//! rounded to the nearest `f32`. Two boxes overlap (closed: touching
//! counts) when `lo_j[a] <= hi_i[a]` and `lo_i[a] <= hi_j[a]` for every
//! `a`, that is when every lane of `P_j` is at most the matching lane of
//! [`reach`]`(P_i)`, which is `P_i` with its halves swapped and negated.
//! An unused direction is packed as `-inf` in both halves and never rules
//! a pair out.
//!
//! Rounding to `f32` never loses an overlap: rounding is monotone (and
//! symmetric about zero), so `lo_j <= hi_i` implies
//! `f32(lo_j) <= f32(hi_i)`, even where values beyond `f32`'s range
//! become infinite. It can only add overlaps between boxes closer than
//! `f32` resolves, which the exact test behind the sweep turns down.

use crate::detect::swept::{DIAGONAL_X, DIAGONAL_Y, PAD};
use crate::line::Line;
use multiversion::multiversion;

/// The key of a box that takes no part in the sweep (a line without a
/// finite hull): it sorts after every real key, and no comparison
/// `key <= end` with a real box's end holds for it, so it also stops a
/// scan.
pub(crate) const NO_KEY: f32 = f32::INFINITY;

/// Eight `f32` lower bounds: `[lo_x, lo_y, lo_u, lo_w, -hi_x, -hi_y, -hi_u, -hi_w]`.
pub(crate) type Packed = [f32; 8];

/// Lanes per half of a packed hull: one per direction.
pub(crate) const DIRECTIONS: usize = 4;

/// Lines whose coordinates (now or one step ahead) reach beyond this are
/// treated as wild (tested against every line), which keeps every packed
/// value finite: the same bound as every detector's.
pub(crate) use crate::detect::swept::LARGEST;

/// A line's padded swept hull (see [`crate::detect::swept::swept_box`],
/// whose bounds and padding it repeats) packed; `None` when the line is not
/// finite or reaches beyond [`LARGEST`].
///
/// The pad (`2^-20` of the magnitude `m`, and `1e-12`) is far wider than
/// the rounding to `f32` (`2^-24` of a bound, which is at most about `2m`,
/// or `1980` times that on the diagonals, whose pad is as much wider), so
/// every packed bound still lies beyond the segment by at least `2^-21 m`:
/// far more than the exact test's rounding errors (near `2^-50 m`).
#[inline(always)]
pub(crate) fn of_line(line: &Line, dt: f64) -> Option<Packed> {
    let (p1, p2) = (line.p1, line.p2);
    // The corners one step ahead are the corners now moved by `d`: along
    // `x` and `y` the extremes are found before adding `d` (rounding is
    // monotone, so this is exactly the corners' extent); along the
    // diagonals the sums differ from the corners' by a rounding, which
    // the pad covers many times over. The four directions are worked as
    // one array, which the compiler turns into vector operations.
    let d = line.v * dt;
    let (a, b, d) = (project(p1.x, p1.y), project(p2.x, p2.y), project(d.x, d.y));
    let mut lo = [0.0; DIRECTIONS];
    let mut hi = [0.0; DIRECTIONS];
    for k in 0..DIRECTIONS {
        lo[k] = min(a[k], b[k]) + min(d[k], 0.0);
        hi[k] = max(a[k], b[k]) + max(d[k], 0.0);
    }
    let magnitude = max(max(-lo[0], hi[0]), max(-lo[1], hi[1]));
    // NaN anywhere makes the sum NaN; an infinite coordinate makes it
    // infinite or NaN; past this test every min and max is exact.
    let sum = p1.x + p1.y + p2.x + p2.y + line.v.x + line.v.y;
    if !(sum.is_finite() && magnitude <= LARGEST) {
        return None;
    }
    let pad = magnitude * PAD + 1e-12;
    // The diagonals reach (1180 + 800) times the magnitude; so does their pad.
    let pad_diagonal = (DIAGONAL_X + DIAGONAL_Y) * pad;
    let pads = [pad, pad, pad_diagonal, pad_diagonal];
    let mut packed = [0.0; 8];
    for k in 0..DIRECTIONS {
        packed[k] = (lo[k] - pads[k]) as f32;
        packed[k + DIRECTIONS] = -(hi[k] + pads[k]) as f32;
    }
    Some(packed)
}

/// A point's coordinates along the four directions `x`, `y`, `u`, `w`.
#[inline(always)]
fn project(x: f64, y: f64) -> [f64; DIRECTIONS] {
    let (x_, y_) = (x * DIAGONAL_X, y * DIAGONAL_Y);
    [x, y, x_ + y_, x_ - y_]
}

/// Makes the packed hull of each line `slots[k]` into `hulls[k]`, and its
/// least value along direction `along` into `keys[k]` ([`NO_KEY`] for a
/// line without a hull).
///
/// Lines are taken [`LANES`] at a time ([`portable::make_batch`]), so that each
/// operation works on four lines at once; the rest one at a time. Compiled
/// twice, for the baseline and for AVX2 (four `f64` lanes in one register,
/// the batch written out with its intrinsics: [`avx2`]), and chosen when
/// the program starts by what the processor has. Every path performs the
/// same operations on each line in the same order, so their results are
/// the same bits.
#[multiversion(targets("x86_64+avx2"))]
pub(crate) fn make(
    lines: &[Line],
    slots: &[u32],
    hulls: &mut [Packed],
    keys: &mut [f32],
    along: usize,
    dt: f64,
) {
    let n = slots.len().min(hulls.len()).min(keys.len());
    let line = |k: usize| &lines[slots[k] as usize];
    multiversion::target::match_target! {
        "x86_64+avx2" => avx2::make_each(line, &mut hulls[..n], &mut keys[..n], along, dt),
        _ => make_each(line, &mut hulls[..n], &mut keys[..n], along, dt, portable_batch),
    }
}

/// Makes the packed hull and key of each line `line(k)` into `hulls[k]`
/// and `keys[k]`: [`LANES`] lines at a time by `batch`, the rest one at a
/// time.
#[inline(always)]
fn make_each<'a>(
    line: impl Fn(usize) -> &'a Line,
    hulls: &mut [Packed],
    keys: &mut [f32],
    along: usize,
    dt: f64,
    batch: impl Fn([&'a Line; LANES], f64, usize, &mut [Packed], &mut [f32]),
) {
    let n = hulls.len().min(keys.len());
    let whole = n - n % LANES;
    for start in (0..whole).step_by(LANES) {
        let (lines, range) = (
            std::array::from_fn(|k| line(start + k)),
            start..start + LANES,
        );
        let (hulls, keys) = (&mut hulls[range.clone()], &mut keys[range]);
        batch(lines, dt, along, hulls, keys);
    }
    for k in whole..n {
        keys[k] = make_one(line(k), dt, along, &mut hulls[k]);
    }
}

/// Lines whose hulls [`portable::make_batch`] makes at once.
pub(crate) const LANES: usize = 4;

/// The batch as the compiler vectorises it (WebAssembly with SIMD has one
/// of its own, `simd128`).
#[cfg_attr(
    all(target_arch = "wasm32", target_feature = "simd128"),
    allow(dead_code)
)]
mod portable {
    use super::{
        max, min, Line, Packed, DIAGONAL_X, DIAGONAL_Y, DIRECTIONS, LANES, LARGEST, NO_KEY, PAD,
    };

    /// One value for each line of a batch.
    type Lanes = [f64; LANES];

    /// `f` of each lane.
    #[inline(always)]
    fn lanes(f: impl FnMut(usize) -> f64) -> Lanes {
        std::array::from_fn(f)
    }

    /// [`super::of_line`] of [`LANES`] lines at once, each value a lane: the same
    /// operations on each line in the same order, written lane by lane so
    /// that the compiler turns each into one vector operation. Writes each
    /// line's packed hull and key (least value along `along`, or [`NO_KEY`]).
    #[inline(always)]
    pub(super) fn make_batch(
        batch: [&Line; LANES],
        dt: f64,
        along: usize,
        hulls: &mut [Packed],
        keys: &mut [f32],
    ) {
        let field = |f: fn(&Line) -> f64| lanes(|k| f(batch[k]));
        let (ax, ay) = (field(|l| l.p1.x), field(|l| l.p1.y));
        let (bx, by) = (field(|l| l.p2.x), field(|l| l.p2.y));
        let (vx, vy) = (field(|l| l.v.x), field(|l| l.v.y));
        let (dx, dy) = (lanes(|k| vx[k] * dt), lanes(|k| vy[k] * dt));
        // The four directions of each point, as `project` makes them.
        let project = |x: &Lanes, y: &Lanes| -> [Lanes; DIRECTIONS] {
            let (x_, y_) = (lanes(|k| x[k] * DIAGONAL_X), lanes(|k| y[k] * DIAGONAL_Y));
            [*x, *y, lanes(|k| x_[k] + y_[k]), lanes(|k| x_[k] - y_[k])]
        };
        let (a, b, d) = (project(&ax, &ay), project(&bx, &by), project(&dx, &dy));
        // Plain loops: `array::from_fn` over these nested closures is left as
        // a call, compiled without AVX2, the values passed through memory
        // (docs/DESIGN.md, "Tried and dropped").
        let (mut lo, mut hi) = ([[0.0; LANES]; DIRECTIONS], [[0.0; LANES]; DIRECTIONS]);
        for r in 0..DIRECTIONS {
            for k in 0..LANES {
                lo[r][k] = min(a[r][k], b[r][k]) + min(d[r][k], 0.0);
                hi[r][k] = max(a[r][k], b[r][k]) + max(d[r][k], 0.0);
            }
        }
        let magnitude = lanes(|k| max(max(-lo[0][k], hi[0][k]), max(-lo[1][k], hi[1][k])));
        let sum = lanes(|k| ax[k] + ay[k] + bx[k] + by[k] + vx[k] + vy[k]);
        let pad = lanes(|k| magnitude[k] * PAD + 1e-12);
        let pad_diagonal = lanes(|k| (DIAGONAL_X + DIAGONAL_Y) * pad[k]);
        let pads = [pad, pad, pad_diagonal, pad_diagonal];
        for k in 0..LANES {
            let hull = &mut hulls[k];
            for r in 0..DIRECTIONS {
                hull[r] = (lo[r][k] - pads[r][k]) as f32;
                hull[r + DIRECTIONS] = -(hi[r][k] + pads[r][k]) as f32;
            }
            let valid = sum[k].is_finite() && magnitude[k] <= LARGEST;
            keys[k] = if valid { hull[along] } else { NO_KEY };
        }
    }
}

/// Makes `line`'s packed hull into `hull` and returns its key (least value
/// along `along`), or [`NO_KEY`] if it has no hull.
#[inline(always)]
fn make_one(line: &Line, dt: f64, along: usize, hull: &mut Packed) -> f32 {
    match of_line(line, dt) {
        Some(packed) => {
            *hull = packed;
            lo(hull, along)
        }
        None => NO_KEY,
    }
}

/// [`make_each`] with AVX2 written out: four lines' hulls at once, the
/// same operations in the same order on each, so the same bits.
///
/// Left to the compiler, [`portable::make_batch`] moves each line's values into the
/// lanes and each lane's results out to its hull one value at a time,
/// several times the instructions (docs/DESIGN.md, "Sweep and prune",
/// boxes). Here four lines' coordinates are loaded as rows and turned
/// into columns with a few shuffles, and the eight bounds of four hulls
/// turned back into rows the same way.
#[cfg(target_arch = "x86_64")]
mod avx2 {
    use super::{Line, Packed, DIAGONAL_X, DIAGONAL_Y, DIRECTIONS, LANES, LARGEST, NO_KEY, PAD};
    use std::arch::x86_64::{
        __m128, __m256d, _mm256_add_pd, _mm256_and_pd, _mm256_cmp_pd, _mm256_cvtpd_ps,
        _mm256_max_pd, _mm256_min_pd, _mm256_movemask_pd, _mm256_mul_pd, _mm256_permute2f128_pd,
        _mm256_set1_pd, _mm256_setzero_pd, _mm256_sub_pd, _mm256_unpackhi_pd, _mm256_unpacklo_pd,
        _mm256_xor_pd, _mm_movehl_ps, _mm_movelh_ps, _mm_set1_ps, _mm_unpackhi_ps, _mm_unpacklo_ps,
        _mm_xor_ps, _CMP_LE_OQ, _CMP_LT_OQ,
    };

    /// [`super::make_each`] with [`make_batch`].
    #[inline]
    #[target_feature(enable = "avx2")]
    pub(super) fn make_each<'a>(
        line: impl Fn(usize) -> &'a Line,
        hulls: &mut [Packed],
        keys: &mut [f32],
        along: usize,
        dt: f64,
    ) {
        // The closure is compiled with AVX2, as the function it is in.
        let batch = |lines, dt, along, hulls: &mut [Packed], keys: &mut [f32]| {
            make_batch(lines, dt, along, hulls, keys)
        };
        super::make_each(line, hulls, keys, along, dt, batch);
    }

    /// The four directions of points whose coordinates are `x` and `y`,
    /// as [`super::project`] makes them.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn project(x: __m256d, y: __m256d) -> [__m256d; DIRECTIONS] {
        let x_ = _mm256_mul_pd(x, _mm256_set1_pd(DIAGONAL_X));
        let y_ = _mm256_mul_pd(y, _mm256_set1_pd(DIAGONAL_Y));
        [x, y, _mm256_add_pd(x_, y_), _mm256_sub_pd(x_, y_)]
    }

    /// Four rows of four values turned into four columns.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn columns(r: [__m128; 4]) -> [__m128; 4] {
        let (t0, t1) = (_mm_unpacklo_ps(r[0], r[1]), _mm_unpacklo_ps(r[2], r[3]));
        let (t2, t3) = (_mm_unpackhi_ps(r[0], r[1]), _mm_unpackhi_ps(r[2], r[3]));
        [
            _mm_movelh_ps(t0, t1),
            _mm_movehl_ps(t1, t0),
            _mm_movelh_ps(t2, t3),
            _mm_movehl_ps(t3, t2),
        ]
    }

    /// [`super::portable::make_batch`]: each `_mm256_min_pd(a, b)` is `a < b ? a :
    /// b` as [`super::min`] is, each `_mm256_max_pd(a, b)` `a > b ? a : b`,
    /// and each conversion rounds to nearest as `as f32` does.
    #[inline]
    #[target_feature(enable = "avx2")]
    fn make_batch(
        batch: [&Line; LANES],
        dt: f64,
        along: usize,
        hulls: &mut [Packed],
        keys: &mut [f32],
    ) {
        // Rows `p1.x p1.y p2.x p2.y`, one a line, turned into columns.
        let row = |l: &Line| -> __m256d { bytemuck::cast([l.p1.x, l.p1.y, l.p2.x, l.p2.y]) };
        let r = batch.map(row);
        let (t0, t1) = (
            _mm256_unpacklo_pd(r[0], r[1]),
            _mm256_unpackhi_pd(r[0], r[1]),
        );
        let (t2, t3) = (
            _mm256_unpacklo_pd(r[2], r[3]),
            _mm256_unpackhi_pd(r[2], r[3]),
        );
        let ax = _mm256_permute2f128_pd::<0x20>(t0, t2);
        let ay = _mm256_permute2f128_pd::<0x20>(t1, t3);
        let bx = _mm256_permute2f128_pd::<0x31>(t0, t2);
        let by = _mm256_permute2f128_pd::<0x31>(t1, t3);
        let vx: __m256d = bytemuck::cast(batch.map(|l| l.v.x));
        let vy: __m256d = bytemuck::cast(batch.map(|l| l.v.y));
        let dt = _mm256_set1_pd(dt);
        let (dx, dy) = (_mm256_mul_pd(vx, dt), _mm256_mul_pd(vy, dt));
        let (a, b, d) = (project(ax, ay), project(bx, by), project(dx, dy));
        let zero = _mm256_setzero_pd();
        let mut lo = [zero; DIRECTIONS];
        let mut hi = [zero; DIRECTIONS];
        for r in 0..DIRECTIONS {
            lo[r] = _mm256_add_pd(_mm256_min_pd(a[r], b[r]), _mm256_min_pd(d[r], zero));
            hi[r] = _mm256_add_pd(_mm256_max_pd(a[r], b[r]), _mm256_max_pd(d[r], zero));
        }
        let sign = _mm256_set1_pd(-0.0);
        let neg = |v: __m256d| _mm256_xor_pd(v, sign);
        let magnitude = _mm256_max_pd(
            _mm256_max_pd(neg(lo[0]), hi[0]),
            _mm256_max_pd(neg(lo[1]), hi[1]),
        );
        let sum = _mm256_add_pd(
            _mm256_add_pd(
                _mm256_add_pd(_mm256_add_pd(_mm256_add_pd(ax, ay), bx), by),
                vx,
            ),
            vy,
        );
        let pad = _mm256_add_pd(
            _mm256_mul_pd(magnitude, _mm256_set1_pd(PAD)),
            _mm256_set1_pd(1e-12),
        );
        let pad_diagonal = _mm256_mul_pd(_mm256_set1_pd(DIAGONAL_X + DIAGONAL_Y), pad);
        let pads = [pad, pad, pad_diagonal, pad_diagonal];
        let mut low = [bytemuck::Zeroable::zeroed(); DIRECTIONS];
        let mut high = [bytemuck::Zeroable::zeroed(); DIRECTIONS];
        let sign32 = _mm_set1_ps(-0.0);
        for r in 0..DIRECTIONS {
            low[r] = _mm256_cvtpd_ps(_mm256_sub_pd(lo[r], pads[r]));
            high[r] = _mm_xor_ps(_mm256_cvtpd_ps(_mm256_add_pd(hi[r], pads[r])), sign32);
        }
        // Finite (NaN and infinities fail) and within the largest.
        let abs = _mm256_and_pd(sum, bytemuck::cast([f64::from_bits(!(1u64 << 63)); 4]));
        let finite = _mm256_cmp_pd::<_CMP_LT_OQ>(abs, _mm256_set1_pd(f64::INFINITY));
        let within = _mm256_cmp_pd::<_CMP_LE_OQ>(magnitude, _mm256_set1_pd(LARGEST));
        let valid = _mm256_movemask_pd(_mm256_and_pd(finite, within));
        let key: [f32; LANES] = bytemuck::cast(low[along]);
        let (low, high) = (columns(low), columns(high));
        for k in 0..LANES {
            let (l, h): ([f32; 4], [f32; 4]) = (bytemuck::cast(low[k]), bytemuck::cast(high[k]));
            hulls[k] = [l[0], l[1], l[2], l[3], h[0], h[1], h[2], h[3]];
            keys[k] = if valid & (1 << k) != 0 {
                key[k]
            } else {
                NO_KEY
            };
        }
    }
}

/// [`portable::make_batch`] in WebAssembly's 128-bit vectors: two lines a vector,
/// the same operations in the same order on each line, so the same bits.
/// Left to the compiler, the batch is worked value by value, which makes
/// the hulls a large part of a step in V8 (docs/DESIGN.md, "The hulls in
/// WebAssembly").
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
mod simd128 {
    use super::{Line, Packed, DIAGONAL_X, DIAGONAL_Y, DIRECTIONS, LANES, LARGEST, NO_KEY, PAD};
    use core::arch::wasm32::{
        f32x4_demote_f64x2_zero, f32x4_extract_lane, f32x4_neg, f64x2, f64x2_add,
        f64x2_extract_lane, f64x2_mul, f64x2_neg, f64x2_pmax, f64x2_pmin, f64x2_splat, f64x2_sub,
        v128,
    };

    /// `a < b ? a : b`, as [`super::min`] (`pmin(x, y)` is `y < x ? y : x`).
    #[inline(always)]
    fn min(a: v128, b: v128) -> v128 {
        f64x2_pmin(b, a)
    }

    /// `a > b ? a : b`, as [`super::max`] (`pmax(x, y)` is `x < y ? y : x`).
    #[inline(always)]
    fn max(a: v128, b: v128) -> v128 {
        f64x2_pmax(b, a)
    }

    /// The four directions of points whose coordinates are `x` and `y`.
    #[inline(always)]
    fn project(x: v128, y: v128) -> [v128; DIRECTIONS] {
        let x_ = f64x2_mul(x, f64x2_splat(DIAGONAL_X));
        let y_ = f64x2_mul(y, f64x2_splat(DIAGONAL_Y));
        [x, y, f64x2_add(x_, y_), f64x2_sub(x_, y_)]
    }

    /// [`super::portable::make_batch`], two lines at a time.
    #[inline(always)]
    pub(super) fn make_batch(
        batch: [&Line; LANES],
        dt: f64,
        along: usize,
        hulls: &mut [Packed],
        keys: &mut [f32],
    ) {
        for pair in 0..LANES / 2 {
            let (l, m) = (batch[2 * pair], batch[2 * pair + 1]);
            let (ax, ay) = (f64x2(l.p1.x, m.p1.x), f64x2(l.p1.y, m.p1.y));
            let (bx, by) = (f64x2(l.p2.x, m.p2.x), f64x2(l.p2.y, m.p2.y));
            let (vx, vy) = (f64x2(l.v.x, m.v.x), f64x2(l.v.y, m.v.y));
            let dt = f64x2_splat(dt);
            let (dx, dy) = (f64x2_mul(vx, dt), f64x2_mul(vy, dt));
            let (a, b, d) = (project(ax, ay), project(bx, by), project(dx, dy));
            let zero = f64x2_splat(0.0);
            let (mut lo, mut hi) = ([zero; DIRECTIONS], [zero; DIRECTIONS]);
            for r in 0..DIRECTIONS {
                lo[r] = f64x2_add(min(a[r], b[r]), min(d[r], zero));
                hi[r] = f64x2_add(max(a[r], b[r]), max(d[r], zero));
            }
            let magnitude = max(max(f64x2_neg(lo[0]), hi[0]), max(f64x2_neg(lo[1]), hi[1]));
            let sum = f64x2_add(
                f64x2_add(f64x2_add(f64x2_add(f64x2_add(ax, ay), bx), by), vx),
                vy,
            );
            let pad = f64x2_add(f64x2_mul(magnitude, f64x2_splat(PAD)), f64x2_splat(1e-12));
            let pad_diagonal = f64x2_mul(f64x2_splat(DIAGONAL_X + DIAGONAL_Y), pad);
            let pads = [pad, pad, pad_diagonal, pad_diagonal];
            let mut low = [zero; DIRECTIONS];
            let mut high = [zero; DIRECTIONS];
            for r in 0..DIRECTIONS {
                low[r] = f32x4_demote_f64x2_zero(f64x2_sub(lo[r], pads[r]));
                high[r] = f32x4_neg(f32x4_demote_f64x2_zero(f64x2_add(hi[r], pads[r])));
            }
            let lanes = |v: v128| [f32x4_extract_lane::<0>(v), f32x4_extract_lane::<1>(v)];
            let (low, high) = (low.map(lanes), high.map(lanes));
            let sums = [f64x2_extract_lane::<0>(sum), f64x2_extract_lane::<1>(sum)];
            let magnitudes = [
                f64x2_extract_lane::<0>(magnitude),
                f64x2_extract_lane::<1>(magnitude),
            ];
            for k in 0..2 {
                let hull = &mut hulls[2 * pair + k];
                for r in 0..DIRECTIONS {
                    hull[r] = low[r][k];
                    hull[r + DIRECTIONS] = high[r][k];
                }
                let valid = sums[k].is_finite() && magnitudes[k] <= LARGEST;
                keys[2 * pair + k] = if valid { hull[along] } else { NO_KEY };
            }
        }
    }
}

#[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
use portable::make_batch as portable_batch;
/// The batch of the platform's vectors where there is one written out,
/// else [`portable::make_batch`].
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
use simd128::make_batch as portable_batch;

/// `min` without NaN handling: one instruction.
#[inline(always)]
fn min(a: f64, b: f64) -> f64 {
    if a < b {
        a
    } else {
        b
    }
}

/// `max` without NaN handling: one instruction.
#[inline(always)]
fn max(a: f64, b: f64) -> f64 {
    if a > b {
        a
    } else {
        b
    }
}

/// A box with least values `lo` and greatest values `hi` along the four
/// directions, packed.
#[inline]
pub(crate) fn pack(lo: [f64; 4], hi: [f64; 4]) -> Packed {
    std::array::from_fn(|k| match k < DIRECTIONS {
        true => lo[k] as f32,
        false => -hi[k - DIRECTIONS] as f32,
    })
}

/// What a packed box reaches: the upper bounds that another box's lanes
/// must not exceed for the two to overlap.
#[inline(always)]
pub(crate) fn reach(p: &Packed) -> Packed {
    [-p[4], -p[5], -p[6], -p[7], -p[0], -p[1], -p[2], -p[3]]
}

/// True when the box packed as `p` overlaps the one whose [`reach`] is `r`.
/// Written without branches so that it compiles to one vector comparison.
#[inline(always)]
pub(crate) fn overlaps(p: &Packed, r: &Packed) -> bool {
    let mut all = true;
    for k in 0..8 {
        all &= p[k] <= r[k];
    }
    all
}

/// The least value of the box packed as `p` along direction `a`.
#[inline(always)]
pub(crate) fn lo(p: &Packed, a: usize) -> f32 {
    p[a]
}

/// The greatest value of the box packed as `p` along direction `a`.
#[inline(always)]
pub(crate) fn hi(p: &Packed, a: usize) -> f32 {
    -p[a + DIRECTIONS]
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// Packing keeps every overlap, however close or far the values.
        #[test]
        fn packing_never_loses_an_overlap(
            a in -1.0f64..1.0, b in -1.0f64..1.0, e in proptest::sample::select(vec![-300, -40, -5, 0, 5, 38, 39, 300]),
            gap in proptest::sample::select(vec![0.0, 1e-30, 1e-9, 1e-7]),
        ) {
            let scale = 10f64.powi(e);
            let (lo_j, hi_i) = (a * scale, a * scale + gap * scale.abs());
            let n = f64::NEG_INFINITY;
            let (p, q) = (pack([lo_j, n, n, n], [lo_j + b.abs() * scale, -n, -n, -n]), pack([hi_i - scale, n, n, n], [hi_i, -n, -n, -n]));
            proptest::prop_assert!(overlaps(&p, &reach(&q)));
        }

        /// The packed hull of a line holds the line now and one step ahead
        /// with a margin of at least `2^-21` of its magnitude.
        #[test]
        fn line_hulls_hold_their_lines_with_a_margin(
            x1 in -3.0f64..3.0, y1 in -3.0f64..3.0, x2 in -3.0f64..3.0, y2 in -3.0f64..3.0,
            vx in -1.0f64..1.0, vy in -1.0f64..1.0, scale in proptest::sample::select(vec![1e-9, 1.0, 1e5]),
        ) {
            let l = crate::test_util::line((x1 * scale, y1 * scale), (x2 * scale, y2 * scale), (vx * scale, vy * scale));
            let p = of_line(&l, 0.5).unwrap();
            let corners = [l.p1, l.p2, l.p1 + l.v * 0.5, l.p2 + l.v * 0.5];
            let magnitude = corners.iter().map(|c| c.x.abs().max(c.y.abs())).fold(0.0, f64::max);
            let margin = magnitude / 2097152.0;
            for c in corners {
                let (u, w) = (1180.0 * c.x + 800.0 * c.y, 1180.0 * c.x - 800.0 * c.y);
                let values = [c.x, c.y, u, w];
                for (a, value) in values.into_iter().enumerate() {
                    proptest::prop_assert!(f64::from(lo(&p, a)) <= value - margin);
                    proptest::prop_assert!(f64::from(hi(&p, a)) >= value + margin);
                }
            }
        }

        /// Hulls made four at a time (with AVX2 where the processor has
        /// it) have the bits of each line's hull made alone, whatever the
        /// values: ordinary, tiny, huge, zero, NaN or infinite.
        #[test]
        fn lines_made_in_batches_get_the_bits_of_lines_made_alone(
            values in proptest::collection::vec(
                proptest::prop_oneof![
                    4 => 0.4f64..1.1,
                    1 => -1e-3f64..1e-3,
                    1 => proptest::sample::select(vec![
                        0.0, -0.0, 1e-310, -1e-310, 1e29, -3e30, 1e300,
                        f64::NAN, f64::INFINITY, f64::NEG_INFINITY,
                    ]),
                ],
                6..120,
            ),
            along in 0..DIRECTIONS,
            dt in proptest::sample::select(vec![0.5, 0.25, 3.0]),
        ) {
            let lines: Vec<Line> = values
                .chunks_exact(6)
                .map(|v| crate::test_util::line((v[0], v[1]), (v[2], v[3]), (v[4], v[5])))
                .collect();
            let slots: Vec<u32> = (0..lines.len() as u32).rev().collect();
            let mut hulls = vec![[0.0; 8]; slots.len()];
            let mut keys = vec![0.0; slots.len()];
            make(&lines, &slots, &mut hulls, &mut keys, along, dt);
            for (k, &slot) in slots.iter().enumerate() {
                match of_line(&lines[slot as usize], dt) {
                    Some(packed) => {
                        proptest::prop_assert_eq!(
                            packed.map(f32::to_bits),
                            hulls[k].map(f32::to_bits)
                        );
                        proptest::prop_assert_eq!(keys[k].to_bits(), packed[along].to_bits());
                    }
                    None => proptest::prop_assert_eq!(keys[k], NO_KEY),
                }
            }
        }
    }

    #[test]
    fn lines_beyond_the_largest_or_not_finite_have_no_hull() {
        let l = |x: f64, v: f64| crate::test_util::line((x, 0.5), (0.6, 0.6), (v, 0.0));
        assert!(of_line(&l(0.7, 0.01), 0.5).is_some());
        assert!(of_line(&l(2e30, 0.01), 0.5).is_none());
        assert!(of_line(&l(0.7, f64::NAN), 0.5).is_none());
        assert!(of_line(&l(f64::INFINITY, 0.0), 0.5).is_none());
    }

    #[test]
    fn overlap_is_closed_and_needs_every_direction() {
        let a = pack([0.0; 4], [1.0; 4]);
        let touching = pack([1.0, 0.0, 0.0, 0.0], [2.0; 4]);
        let apart_in_w = pack([0.5, 0.5, 0.5, 1.5], [2.0; 4]);
        let inside = pack([0.25; 4], [0.5; 4]);
        for (b, expected) in [(touching, true), (apart_in_w, false), (inside, true)] {
            assert_eq!(overlaps(&b, &reach(&a)), expected);
            assert_eq!(overlaps(&a, &reach(&b)), expected);
        }
        assert_eq!((lo(&a, 2), hi(&a, 2)), (0.0, 1.0));
    }
}
