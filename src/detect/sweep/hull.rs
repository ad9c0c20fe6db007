//! The packed hull: a box in up to four directions as eight `f32` lower
//! bounds, so that the overlap test of two boxes is one comparison of eight
//! lanes.
//!
//! A box with least values `lo[a]` and greatest values `hi[a]` along
//! directions `a = 0..4` is packed as `[lo[0..4], -hi[0..4]]`, every lane
//! an `f32`. Two boxes overlap (closed: touching counts) when
//! `lo_j[a] <= hi_i[a]` and `lo_i[a] <= hi_j[a]` for every `a`, that is
//! when every lane of `P_j` is at most the matching lane of
//! [`reach`]`(P_i)`, which is `P_i` with its halves swapped and negated.
//! An unused direction is packed as `-inf` in both halves and never rules
//! a pair out.
//!
//! The hulls are made in `f32` ([`crate::lanes::single`]), twice as many
//! lines to a register as in `f64`: each line's values are rounded to
//! `f32` once, after the move, and the hull is worked out from them with
//! a pad ([`PAD`]) wide enough to hold every rounding on the way
//! ([`of_line`] gives the bound). A hull is a broad phase's bound, not a
//! result: nothing the simulation computes depends on its bits, only on
//! its holding the line.

use crate::detect::swept::padded_hull;
use crate::index::Slot;
use crate::lanes::{self, single};
use crate::line::Line;
use crate::motion::advance_lanes;
use multiversion::multiversion;

/// The packed box format, which the lanes write.
pub(crate) use crate::lanes::single::{Packed, DIRECTIONS, NO_KEY};

/// Lines whose coordinates (now or one step ahead) reach beyond this are
/// treated as wild (tested against every line), which keeps every packed
/// value finite: the same bound as every detector's.
pub(crate) use crate::detect::swept::LARGEST;

/// The packed hulls' pad: `2^-18` of the magnitude (and `1e-12`).
pub(crate) const PAD: f64 = 1.0 / 262144.0;

/// A line's padded swept hull ([`padded_hull!`]) made in `f32` and
/// packed; `None` when the line is not finite or reaches beyond
/// [`LARGEST`] (as its values rounded to `f32` tell). Every batch gives
/// these bits.
///
/// The bound, with `e = 2^-24` (the relative error of a rounding to
/// `f32`), `M` the line's magnitude (at most `LARGEST`, so no value
/// overflows) and `K = 1980` (the diagonals' weights summed): a value
/// rounded is off by `e` of itself, `d = v dt` by `3e` (`v` and `dt`
/// rounded, then their product) and `|d| <= 2M`, so a least or greatest
/// value along `x` or `y` (a rounded value plus `d`, rounded) is off by at
/// most `10 e M`, and the magnitude and pad as little in proportion; one
/// along a diagonal (three products and a sum of each value, then the
/// same) by at most `20 e K M`. The pad is `64 e M` (`64 e K M` on the
/// diagonals), and taking it off rounds once more, by at most `3 e K M`:
/// every packed bound lies beyond the segment by at least `2^-21 M`, far
/// more than the exact test's rounding errors (near `2^-50 M`).
#[inline(always)]
pub(crate) fn of_line(line: &Line, dt: f64) -> Option<Packed> {
    type One = single::Scalar<1>;
    let (p1, p2, v) = (line.p1, line.p2, line.v);
    let point = [p1.x, p1.y, p2.x, p2.y].map(|x| One::round([x]));
    let (vx, vy) = (One::round([v.x]), One::round([v.y]));
    let (low, high, sum, magnitude) = padded_hull!(One, point, vx, vy, dt, PAD);
    let valid = One::valid(sum, magnitude, LARGEST) != 0;
    valid.then(|| {
        std::array::from_fn(|k| match k < DIRECTIONS {
            true => low[k].0[0],
            false => -high[k - DIRECTIONS].0[0],
        })
    })
}

/// Makes the packed hull of each line `slots[k]` into `hulls[k]`, and its
/// least value along direction `along` into `keys[k]` ([`NO_KEY`] for a
/// line without a hull).
///
/// Lines are taken a batch at a time (eight with AVX2, else four), each
/// value of the batch's lines one lane of the target's `f32` lane type
/// ([`crate::lanes::single`]); the rest one at a time. Compiled twice on
/// x86-64, for the baseline (SSE2) and for AVX2, and chosen when the
/// program starts by what the processor has. Every
/// path performs the same operations on each line in the same order, so
/// their results are the same bits.
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2"), dispatcher = "static")
)]
pub(crate) fn make(
    lines: &[Line],
    slots: &[Slot],
    hulls: &mut [Packed],
    keys: &mut [f32],
    along: usize,
    dt: f64,
) {
    let n = slots.len().min(hulls.len()).min(keys.len());
    let (slots, hulls, keys) = (&slots[..n], &mut hulls[..n], &mut keys[..n]);
    multiversion::target::match_target! {
        "x86_64+avx2" => make_each_avx2((lines, slots), hulls, keys, along, dt),
        _ => make_each((lines, slots), hulls, keys, along, dt, batch_default),
    }
}

/// Makes the packed hull and key of the line in each slot `slots[k]` of
/// `lines` into `hulls[k]` and `keys[k]` (all three as long): `W` lines at
/// a time by `batch`, the rest one at a time.
#[inline(always)]
fn make_each<'a, const W: usize>(
    (lines, slots): (&'a [Line], &[Slot]),
    hulls: &mut [Packed],
    keys: &mut [f32],
    along: usize,
    dt: f64,
    batch: impl Fn([&'a Line; W], f64, usize, &mut [Packed], &mut [f32]),
) {
    let line = |s: &Slot| &lines[s.0 as usize];
    let whole = slots.len() - slots.len() % W;
    let (slots, rest) = slots.split_at(whole);
    let (hulls, rest_hulls) = hulls.split_at_mut(whole);
    let (keys, rest_keys) = keys.split_at_mut(whole);
    let batches = slots.chunks_exact(W).zip(hulls.chunks_exact_mut(W));
    for ((slots, hulls), keys) in batches.zip(keys.chunks_exact_mut(W)) {
        let slots: &[Slot; W] = slots.try_into().expect("a batch of slots");
        batch(slots.each_ref().map(line), dt, along, hulls, keys);
    }
    for ((slot, hull), key) in rest.iter().zip(rest_hulls).zip(rest_keys) {
        *key = make_one(line(slot), dt, along, hull);
    }
}

/// [`make_each`] with the AVX2 batch (the closure is compiled with AVX2,
/// as the function it is in).
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
fn make_each_avx2<'a>(
    lines: (&'a [Line], &[Slot]),
    hulls: &mut [Packed],
    keys: &mut [f32],
    along: usize,
    dt: f64,
) {
    let batch = |lines, dt, along, hulls: &mut [Packed], keys: &mut [f32]| {
        batch_avx2(lines, dt, along, hulls, keys)
    };
    make_each(lines, hulls, keys, along, dt, batch);
}

/// The move and wall phases of `lines` (as
/// [`advance_and_bounce`](crate::motion::advance_and_bounce) makes them),
/// and in the same pass each line's packed hull for the next step, of
/// `dt`, into `hulls` and its least value along `along` into `keys`
/// ([`NO_KEY`] for a line without a hull): the line in slot `slots[k]`
/// into `hulls[k]` (with `None`, line `k`): while each line is in
/// registers, rather than read again in the next step's first phase.
/// Every line must be named once. Returns the lines that hit a wall.
/// Compiled as [`make`] is, with the same lanes (the AVX2 clone with
/// POPCNT too, as the world's move is); every path gives the same bits
/// as the move and the walls of one line, then [`of_line`] of it.
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2+popcnt")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2+popcnt"), dispatcher = "static")
)]
pub(crate) fn advance_and_make(
    lines: &mut [Line],
    slots: Option<&[Slot]>,
    hulls: &mut [Packed],
    keys: &mut [f32],
    (along, dt): (usize, f64),
) -> u64 {
    let n = hulls.len().min(keys.len());
    let (hulls, keys) = (&mut hulls[..n], &mut keys[..n]);
    multiversion::target::match_target! {
        "x86_64+avx2+popcnt" => advance_each_avx2(lines, slots, hulls, keys, (along, dt)),
        _ => advance_each::<{ single::DefaultLanes::WIDTH }>(
            lines, slots, hulls, keys, (along, dt), advance_default, advance_at_default
        ),
    }
}

/// [`advance_and_make`] of `W` lines at a time, the rest one at a time:
/// in slot order a block of lines at a time (by `block`), or in the order
/// of `slots` (by `anywhere`). Each batch (the lines at `at` moved and
/// their hulls made, of `dt` and keyed along `along`, returning the lines
/// that hit a wall) is called from one place, where it is inlined.
#[inline(always)]
fn advance_each<const W: usize>(
    lines: &mut [Line],
    slots: Option<&[Slot]>,
    hulls: &mut [Packed],
    keys: &mut [f32],
    (along, dt): (usize, f64),
    block: impl Fn(&mut [Line], [usize; W], f64, usize, &mut [Packed], &mut [f32]) -> u64,
    anywhere: impl Fn(&mut [Line], [usize; W], f64, usize, &mut [Packed], &mut [f32]) -> u64,
) -> u64 {
    let place = |k: usize| slots.map_or(k, |s| s[k].0 as usize);
    let whole = hulls.len() - hulls.len() % W;
    let (hulls, rest_hulls) = hulls.split_at_mut(whole);
    let (keys, rest_keys) = keys.split_at_mut(whole);
    let batches = hulls.chunks_exact_mut(W).zip(keys.chunks_exact_mut(W));
    let mut hits = 0;
    match slots {
        None => {
            for (lines, (hulls, keys)) in lines.chunks_exact_mut(W).zip(batches) {
                let at = std::array::from_fn(|k| k);
                hits += block(lines, at, dt, along, hulls, keys);
            }
        }
        Some(slots) => {
            for (slots, (hulls, keys)) in slots.chunks_exact(W).zip(batches) {
                let at = std::array::from_fn(|k| slots[k].0 as usize);
                hits += anywhere(lines, at, dt, along, hulls, keys);
            }
        }
    }
    for (k, (hull, key)) in rest_hulls.iter_mut().zip(rest_keys).enumerate() {
        let line = &mut lines[place(whole + k)];
        hits += u64::from(crate::motion::advance_one(line));
        *key = make_one(line, dt, along, hull);
    }
    hits
}

/// [`advance_each`] with the AVX2 batches (the closures are compiled with
/// AVX2, as the function they are in).
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx2")]
fn advance_each_avx2(
    lines: &mut [Line],
    slots: Option<&[Slot]>,
    hulls: &mut [Packed],
    keys: &mut [f32],
    along_dt: (usize, f64),
) -> u64 {
    let block = |lines: &mut [Line], at, dt, along, hulls: &mut [Packed], keys: &mut [f32]| {
        advance_batch_avx2(lines, at, dt, along, hulls, keys)
    };
    let anywhere = |lines: &mut [Line], at, dt, along, hulls: &mut [Packed], keys: &mut [f32]| {
        advance_batch_at_avx2(lines, at, dt, along, hulls, keys)
    };
    advance_each::<{ single::Avx2::WIDTH }>(lines, slots, hulls, keys, along_dt, block, anywhere)
}

/// The batch: the lines' `f64` values (as many groups of them as `$single`
/// holds lanes of `$lanes`) rounded to `f32`, then [`padded_hull!`] of
/// them in `$single`'s lanes; writes each line's packed hull and key
/// (least value along `along`, or [`NO_KEY`]).
macro_rules! store_hulls {
    ($single:ty, $groups:expr, $dt:expr, $along:expr, $hulls:expr, $keys:expr) => {{
        type H = $single;
        let groups = $groups;
        let column = |c: usize| std::array::from_fn(|g| groups[g].0[c]);
        let point = [
            H::narrow(column(0)),
            H::narrow(column(1)),
            H::narrow(column(2)),
            H::narrow(column(3)),
        ];
        let vx = H::narrow(std::array::from_fn(|g| groups[g].1));
        let vy = H::narrow(std::array::from_fn(|g| groups[g].2));
        let (low, high, sum, magnitude) = padded_hull!(H, point, vx, vy, $dt, PAD);
        let valid = H::valid(sum, magnitude, LARGEST);
        let key = low[$along];
        H::store_low(low, $hulls);
        H::store_high(high, $hulls);
        H::store_keys(key, valid, $keys);
    }};
}

/// The batches, stamped out for each pair of lane types (`f64` lanes for
/// the move, `f32` lanes for the hulls) with the attributes their target
/// needs (a macro rather than a generic function, so that the AVX2 copy
/// is compiled with AVX2 and calls the lane types' AVX2 operations
/// without `unsafe`). A batch takes as many lines as the `f32` type has
/// lanes, in groups of the `f64` type's (numbered after the types).
macro_rules! batch {
    // The hulls of the lines, which stay where they are.
    ($(#[$attr:meta])* fn $name:ident($lanes:ty => $single:ty; $($g:literal),+)) => {
        $(#[$attr])*
        fn $name(
            batch: [&Line; <$single>::WIDTH],
            dt: f64,
            along: usize,
            hulls: &mut [Packed],
            keys: &mut [f32],
        ) {
            type L = $lanes;
            const { assert!([$($g),+].len() * <$lanes>::WIDTH == <$single>::WIDTH) };
            let groups = [$({
                let lines: [&Line; <$lanes>::WIDTH] =
                    std::array::from_fn(|k| batch[$g * <$lanes>::WIDTH + k]);
                let (point, (vx, vy)) = (L::points(lines), L::velocities(lines));
                (point, vx, vy)
            }),+];
            store_hulls!($single, groups, dt, along, hulls, keys);
        }
    };
    // The move, the walls and the next step's hull of the lines at
    // places `at`, in one pass: two copies, one for blocks of lines in
    // slot order and one for lines anywhere, so that each is called from
    // one place and inlined there.
    (advance: $(#[$attr:meta])* fn $block:ident, $at:ident($($types:tt)*)) => {
        batch!(advance_one: $(#[$attr])* fn $block($($types)*));
        batch!(advance_one: $(#[$attr])* fn $at($($types)*));
    };
    (advance_one: $(#[$attr:meta])* fn $name:ident($lanes:ty => $single:ty; $($g:literal),+)) => {
        $(#[$attr])*
        fn $name(
            lines: &mut [Line],
            at: [usize; <$single>::WIDTH],
            dt: f64,
            along: usize,
            hulls: &mut [Packed],
            keys: &mut [f32],
        ) -> u64 {
            type L = $lanes;
            const { assert!([$($g),+].len() * <$lanes>::WIDTH == <$single>::WIDTH) };
            let mut hits = 0;
            let groups = [$({
                let at: [usize; <$lanes>::WIDTH] =
                    std::array::from_fn(|k| at[$g * <$lanes>::WIDTH + k]);
                let batch = at.map(|k| &lines[k]);
                let (point, (vx, vy)) = (L::points(batch), L::velocities(batch));
                let (point, vx, vy, hit) = advance_lanes!($lanes, point, vx, vy);
                let group_hits = L::hits(hit);
                // Without a hit the velocities are as they were: only the
                // points are written.
                match group_hits {
                    0 => at.into_iter().zip(L::rows(point)).for_each(|(k, p)| {
                        lanes::set_points(&mut lines[k], p)
                    }),
                    _ => at.into_iter().zip(L::lines(point, vx, vy)).for_each(|(k, l)| lines[k] = l),
                }
                hits += group_hits;
                (point, vx, vy)
            }),+];
            store_hulls!($single, groups, dt, along, hulls, keys);
            hits
        }
    };
}

#[cfg(target_arch = "x86_64")]
batch!(
    #[inline]
    #[target_feature(enable = "avx2")]
    fn batch_avx2(lanes::Avx2 => single::Avx2; 0, 1)
);

#[cfg(target_arch = "x86_64")]
batch!(
    #[inline(always)]
    fn batch_sse2(lanes::Sse2 => single::Sse2; 0, 1)
);

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
batch!(
    #[inline(always)]
    fn batch_simd128(lanes::Simd128 => single::Simd128; 0)
);

batch!(
    #[inline(always)]
    #[cfg_attr(
        any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128")),
        allow(dead_code)
    )]
    fn batch_scalar(lanes::Scalar => single::Scalar<{ lanes::LANES }>; 0)
);

#[cfg(target_arch = "x86_64")]
batch!(advance:
    #[inline]
    #[target_feature(enable = "avx2")]
    fn advance_batch_avx2, advance_batch_at_avx2(lanes::Avx2 => single::Avx2; 0, 1)
);

#[cfg(target_arch = "x86_64")]
batch!(advance:
    #[inline(always)]
    fn advance_batch_sse2, advance_batch_at_sse2(lanes::Sse2 => single::Sse2; 0, 1)
);

#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
batch!(advance:
    #[inline(always)]
    fn advance_batch_simd128, advance_batch_at_simd128(lanes::Simd128 => single::Simd128; 0)
);

batch!(advance:
    #[inline(always)]
    #[cfg_attr(
        any(target_arch = "x86_64", all(target_arch = "wasm32", target_feature = "simd128")),
        allow(dead_code)
    )]
    fn advance_batch_scalar, advance_batch_at_scalar(lanes::Scalar => single::Scalar<{ lanes::LANES }>; 0)
);

#[cfg(not(any(
    target_arch = "x86_64",
    all(target_arch = "wasm32", target_feature = "simd128")
)))]
use {
    advance_batch_at_scalar as advance_at_default, advance_batch_scalar as advance_default,
    batch_scalar as batch_default,
};
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
use {
    advance_batch_at_simd128 as advance_at_default, advance_batch_simd128 as advance_default,
    batch_simd128 as batch_default,
};
/// The batch of the baseline: the target's lane type where it has one
/// (every x86-64 processor has SSE2; WebAssembly with SIMD), else plain
/// values.
#[cfg(target_arch = "x86_64")]
use {
    advance_batch_at_sse2 as advance_at_default, advance_batch_sse2 as advance_default,
    batch_sse2 as batch_default,
};

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

/// A box with least values `lo` and greatest values `hi` along the four
/// directions, packed (the broad phase's boxes of your own). Rounding to
/// `f32` never loses an overlap: rounding is monotone (and symmetric about
/// zero), so `lo_j <= hi_i` implies `f32(lo_j) <= f32(hi_i)`, even where
/// values beyond `f32`'s range become infinite. It can only add overlaps
/// between boxes closer than `f32` resolves, which an exact test behind
/// turns down.
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
            vx in -1.0f64..1.0, vy in -1.0f64..1.0,
            scale in proptest::sample::select(vec![1e-30, 1e-9, 1.0, 1e5, 1e29]),
            dt in proptest::sample::select(vec![0.5, 0.1, 3.0]),
        ) {
            let l = crate::test_util::line((x1 * scale, y1 * scale), (x2 * scale, y2 * scale), (vx * scale, vy * scale));
            let p = of_line(&l, dt).unwrap();
            let corners = [l.p1, l.p2, l.p1 + l.v * dt, l.p2 + l.v * dt];
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
            let slots: Vec<Slot> = (0..lines.len() as u32).rev().map(Slot).collect();
            let n = slots.len();
            let line = (&lines[..], &slots[..]);
            // What the processor runs (the AVX2 batches where it has
            // AVX2), and every lane type this target has.
            let mut made = Vec::new();
            let (mut hulls, mut keys) = (vec![[0.0; 8]; n], vec![0.0; n]);
            make(&lines, &slots, &mut hulls, &mut keys, along, dt);
            made.push(("make", hulls, keys));
            let (mut hulls, mut keys) = (vec![[0.0; 8]; n], vec![0.0; n]);
            make_each(line, &mut hulls, &mut keys, along, dt, batch_scalar);
            made.push(("scalar", hulls, keys));
            let (mut hulls, mut keys) = (vec![[0.0; 8]; n], vec![0.0; n]);
            make_each(line, &mut hulls, &mut keys, along, dt, batch_default);
            made.push(("default", hulls, keys));
            for (name, hulls, keys) in &made {
                for (k, &slot) in slots.iter().enumerate() {
                    match of_line(&lines[slot.0 as usize], dt) {
                        Some(packed) => {
                            proptest::prop_assert_eq!(
                                packed.map(f32::to_bits),
                                hulls[k].map(f32::to_bits),
                                "{}", name
                            );
                            proptest::prop_assert_eq!(keys[k].to_bits(), packed[along].to_bits(), "{}", name);
                        }
                        None => proptest::prop_assert_eq!(keys[k], NO_KEY, "{}", name),
                    }
                }
            }
        }
    }

    proptest::proptest! {
        /// Lines moved, bounced and boxed in one pass, four at a time
        /// (with AVX2 where the processor has it), in slot order or in
        /// any order, have the bits of each line moved and bounced alone,
        /// then its hull made alone, and hit as many walls: whatever the
        /// values, on either side of a wall, tiny, huge, NaN or infinite.
        #[test]
        fn lines_moved_and_boxed_at_once_get_the_bits_of_each_alone(
            values in proptest::collection::vec(
                proptest::prop_oneof![
                    4 => 0.4f64..1.1,
                    1 => -1e-3f64..1e-3,
                    1 => proptest::sample::select(vec![
                        0.0, -0.0, 0.5, 1.0, 1e-310, -1e-310, 1e29, -3e30, 1e300,
                        f64::NAN, -f64::NAN, f64::from_bits(0x7ff0_0000_0000_0001),
                        f64::from_bits(0xfff8_0000_dead_beef), f64::INFINITY, f64::NEG_INFINITY,
                    ]),
                ],
                6..120,
            ),
            along in 0..DIRECTIONS,
            in_order in proptest::bool::ANY,
        ) {
            let lines: Vec<Line> = values
                .chunks_exact(6)
                .map(|v| crate::test_util::line((v[0], v[1]), (v[2], v[3]), (v[4], v[5])))
                .collect();
            let n = lines.len();
            let reversed: Vec<Slot> = (0..n as u32).rev().map(Slot).collect();
            let slots = (!in_order).then_some(&reversed[..]);
            let place = |k: usize| slots.map_or(k, |s| s[k].0 as usize);
            let dt = crate::line::DT;
            // Each alone.
            let mut alone = lines.clone();
            let hits: u64 = alone.iter_mut().map(|l| u64::from(crate::motion::advance_one(l))).sum();
            // What the processor runs (the AVX2 batches where it has
            // AVX2), and every lane type this target has.
            let mut made = Vec::new();
            type Pass<'a> = &'a dyn Fn(&mut [Line], &mut [Packed], &mut [f32]) -> u64;
            let run = |f: Pass| {
                let (mut moved, mut hulls, mut keys) = (lines.clone(), vec![[0.0; 8]; n], vec![0.0; n]);
                let hits = f(&mut moved, &mut hulls, &mut keys);
                (moved, hulls, keys, hits)
            };
            made.push(("dispatched", run(&|l, h, k| advance_and_make(l, slots, h, k, (along, dt)))));
            made.push(("scalar", run(&|l, h, k| {
                advance_each::<{ lanes::LANES }>(l, slots, h, k, (along, dt), advance_batch_scalar, advance_batch_at_scalar)
            })));
            made.push(("default", run(&|l, h, k| {
                advance_each::<{ single::DefaultLanes::WIDTH }>(l, slots, h, k, (along, dt), advance_default, advance_at_default)
            })));
            for (name, (moved, hulls, keys, made_hits)) in &made {
                proptest::prop_assert_eq!(*made_hits, hits, "{}", name);
                // NaNs by sign and payload too (the move's sums take the
                // point's NaN, `lanes::add_first`).
                let bits = |l: &Line| [l.p1.x, l.p1.y, l.p2.x, l.p2.y, l.v.x, l.v.y].map(f64::to_bits);
                for (a, b) in moved.iter().zip(&alone) {
                    proptest::prop_assert_eq!(bits(a), bits(b), "{}", name);
                }
                for k in 0..n {
                    match of_line(&alone[place(k)], dt) {
                        Some(packed) => {
                            proptest::prop_assert_eq!(packed.map(f32::to_bits), hulls[k].map(f32::to_bits), "{}", name);
                            proptest::prop_assert_eq!(keys[k].to_bits(), packed[along].to_bits(), "{}", name);
                        }
                        None => proptest::prop_assert_eq!(keys[k], NO_KEY, "{}", name),
                    }
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
