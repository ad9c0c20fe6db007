//! The narrow phase: the exact test of one pair of lines, `intersect`.

use crate::geometry::{inside_parallelogram, segments_cross, Vec2};
pub use crate::index::{LineId, Slot};
use crate::line::Line;

/// How two lines meet during a step.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum IntersectionKind {
    /// The lines overlap already; the response pushes them apart.
    AlreadyIntersected,
    /// The lower-id line runs into the face of the higher-id one.
    L1WithL2,
    /// The higher-id line runs into the face of the lower-id one.
    L2WithL1,
}

/// A collision: the two lines, the one with the lower id first, and how
/// they meet. The lines are named by id ([`LineId`]), as every result
/// gives them (inside a step, the library names them by where it stores
/// them).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Event<I = LineId> {
    /// The line with the smaller id.
    pub first: I,
    /// The line with the larger id.
    pub second: I,
    /// How they meet.
    pub kind: IntersectionKind,
}

impl Event {
    /// The key events are resolved in: ascending `(first, second)`.
    #[inline]
    pub fn order_key(&self) -> u64 {
        (u64::from(self.first.0) << 32) | u64::from(self.second.0)
    }
}

impl IntersectionKind {
    /// The kind as a number below 3, as it is packed with its lines.
    #[inline(always)]
    fn number(self) -> u64 {
        match self {
            IntersectionKind::AlreadyIntersected => 0,
            IntersectionKind::L1WithL2 => 1,
            IntersectionKind::L2WithL1 => 2,
        }
    }

    /// The kind numbered `n & 3` ([`IntersectionKind::number`]; 3 is
    /// none's): a look-up without a branch, as the sort unpacks each event.
    #[inline(always)]
    fn from_number(n: u64) -> Self {
        const BY_NUMBER: [IntersectionKind; 4] = [
            IntersectionKind::AlreadyIntersected,
            IntersectionKind::L1WithL2,
            IntersectionKind::L2WithL1,
            IntersectionKind::L2WithL1,
        ];
        BY_NUMBER[(n & 3) as usize]
    }
}

/// Sorts `events`, whose slots are ids (the lines in id order), in the
/// contract's order of resolution (ascending `(first, second)`), using
/// `keys` for scratch. Found nearly in order (as where the sweep runs
/// along the ids), they are put in order by insertion; else each is
/// packed into one `u64` that sorts as its order key (`first`, `second`,
/// then the kind in the low bits; slots below `2^31`), so that the sort
/// compares plain integers.
pub(crate) fn sort_in_order(events: &mut [Event<Slot>], keys: &mut Vec<u64>) {
    const SLOT: u32 = (1 << 31) - 1;
    let order = |e: &Event<Slot>| (u64::from(e.first.0) << 32) | u64::from(e.second.0);
    let descents = events
        .windows(2)
        .filter(|w| order(&w[0]) > order(&w[1]))
        .count();
    if descents <= events.len() / 16 && insertion_sort(events, order) {
        return;
    }
    if events.iter().any(|e| (e.first.0 | e.second.0) > SLOT) {
        return events.sort_unstable_by_key(order);
    }
    let pack = |e: &Event<Slot>| {
        (u64::from(e.first.0) << 33) | (u64::from(e.second.0) << 2) | e.kind.number()
    };
    keys.clear();
    keys.extend(events.iter().map(pack));
    keys.sort_unstable();
    for (e, &key) in events.iter_mut().zip(keys.iter()) {
        *e = Event {
            first: Slot((key >> 33) as u32),
            second: Slot((key >> 2) as u32 & SLOT),
            kind: IntersectionKind::from_number(key),
        };
    }
}

/// Sorts `items` by `key` by insertion: each moved back past the larger
/// ones before it (cheap when few are out of place). Gives up past a
/// budget of moves a few times their number, returning false (the items
/// then in some order).
fn insertion_sort<T: Copy>(items: &mut [T], key: impl Fn(&T) -> u64) -> bool {
    let mut budget = 8 * items.len();
    for i in 1..items.len() {
        let item = items[i];
        let k = key(&item);
        let mut j = i;
        while j > 0 && key(&items[j - 1]) > k {
            if budget == 0 {
                items[j] = item;
                return false;
            }
            budget -= 1;
            items[j] = items[j - 1];
            j -= 1;
        }
        items[j] = item;
    }
    true
}

impl<I> Event<I> {
    /// The same event with its lines named by `name`.
    #[inline]
    pub(crate) fn named<J>(&self, name: impl Fn(&I) -> J) -> Event<J> {
        Event {
            first: name(&self.first),
            second: name(&self.second),
            kind: self.kind,
        }
    }
}

/// The contract's `intersect(l1, l2, dt)`: whether and how `l1` and `l2`
/// meet in the next `dt`, holding `l1` still and sweeping `l2` by the
/// relative velocity. The caller passes the line with the smaller id as `l1`.
///
/// ```
/// use screensaver::{intersect, IntersectionKind, Line, Vec2};
///
/// let still = Line { p1: Vec2::new(0.6, 0.6), p2: Vec2::new(0.6, 0.7), v: Vec2::new(0.0, 0.0) };
/// let mut coming = Line { p1: Vec2::new(0.61, 0.62), p2: Vec2::new(0.63, 0.64), v: Vec2::new(-2.0, 0.0) };
/// assert_eq!(intersect(&still, &coming, 0.5e-2), Some(IntersectionKind::L2WithL1));
/// coming.v = Vec2::new(2.0, 0.0); // going away
/// assert_eq!(intersect(&still, &coming, 0.5e-2), None);
/// ```
///
/// Always inlined: the exact test of every broad phase calls it once per
/// pair that passes the prefilter, and as a call its arguments and the
/// prefilter's results go through memory.
#[inline(always)]
pub fn intersect(l1: &Line, l2: &Line, dt: f64) -> Option<IntersectionKind> {
    let rel = l2.v - l1.v;
    let q1 = l2.p1 + rel * dt;
    let q2 = l2.p2 + rel * dt;
    if segments_cross(l1.p1, l1.p2, l2.p1, l2.p2) {
        return Some(IntersectionKind::AlreadyIntersected);
    }
    let top = segments_cross(l1.p1, l1.p2, q1, l2.p1);
    let bottom = segments_cross(l1.p1, l1.p2, q2, l2.p2);
    let crossings =
        u32::from(segments_cross(l1.p1, l1.p2, q1, q2)) + u32::from(top) + u32::from(bottom);
    let inside = || {
        inside_parallelogram(l1.p1, l2.p1, l2.p2, q1, q2)
            && inside_parallelogram(l1.p2, l2.p1, l2.p2, q1, q2)
    };
    kind_of(l1, l2, (crossings, top, bottom), inside)
}

/// The rest of [`intersect`] once the lines are known not to overlap
/// already: how `l1` and the parallelogram `l2` sweeps meet, from how many
/// of the parallelogram's three other sides `l1` crosses (the far side,
/// and whether the `top` one from `l2.p1` and the `bottom` one from
/// `l2.p2` are among them) and whether both of `l1`'s endpoints lie
/// `inside` it (asked only when it decides).
#[inline(always)]
pub(crate) fn kind_of(
    l1: &Line,
    l2: &Line,
    (crossings, top, bottom): (u32, bool, bool),
    inside: impl FnOnce() -> bool,
) -> Option<IntersectionKind> {
    if crossings == 2 {
        return Some(IntersectionKind::L2WithL1);
    }
    if inside() {
        return Some(IntersectionKind::L1WithL2);
    }
    if crossings == 0 {
        return None;
    }
    // Only the sign of the difference of the two angles is used.
    let angle = l1.dir().angle_difference_sign(l2.dir());
    if top {
        return Some(if angle < 0.0 {
            IntersectionKind::L2WithL1
        } else {
            IntersectionKind::L1WithL2
        });
    }
    if bottom {
        return Some(if angle > 0.0 {
            IntersectionKind::L2WithL1
        } else {
            IntersectionKind::L1WithL2
        });
    }
    Some(IntersectionKind::L1WithL2)
}

/// The least margin [`may_intersect`] keeps: far above the rounding errors
/// of values that underflow, far below any distance that matters.
const MARGIN_FLOOR: f64 = 1e-300;

/// Whether the swept parallelogram of `l2` relative to `l1` is a sliver
/// along `l2`'s supporting line, with both of `l1`'s endpoints on that line
/// (to 1e-9 of the coordinates' magnitude): the "sliver" class of the
/// contract. Its four corners are nearly collinear when `l2` slides along
/// its own line (the relative motion parallel to it, to 1e-9) or when the
/// relative motion is itself within 1e-9 of the coordinates' magnitude
/// (rounding the corners then moves them as far as the motion does). Once
/// rounded they are not quite parallel, so [`intersect`] can report
/// [`IntersectionKind::L1WithL2`] for a segment lying on the line far
/// outside the sweep; the fast detectors, which test only pairs whose
/// swept hulls meet, do not report it. The documented exception to their
/// agreement with the all-pairs detector (`--verify` names it).
pub(crate) fn is_sliver(l1: &Line, l2: &Line, dt: f64) -> bool {
    let cross = |a: Vec2, b: Vec2| a.x * b.y - a.y * b.x;
    let (d, rel) = (l2.p2 - l2.p1, (l2.v - l1.v) * dt);
    let magnitude = [l1.p1, l1.p2, l2.p1, l2.p2]
        .iter()
        .map(|p| p.x.abs().max(p.y.abs()))
        .fold(0.0, f64::max);
    let along = cross(d, rel).abs() <= 1e-9 * d.length() * rel.length();
    let negligible = rel.length() <= 1e-9 * magnitude;
    let on_line = |p: Vec2| cross(d, p - l2.p1).abs() <= 1e-9 * magnitude * d.length();
    (along || negligible) && on_line(l1.p1) && on_line(l1.p2)
}

/// A cheap, conservative test for [`intersect`]: returns `false` only when
/// `intersect(l1, l2, dt)` is certainly `None`.
///
/// Any event needs `l1`'s segment to touch the parallelogram that `l2`
/// sweeps relative to `l1`. This projects both onto the normal of `l1`: the
/// segment lands on one value, the parallelogram on an interval, and if the
/// interval lies wholly on one side the two cannot touch. `magnitude` must
/// bound the absolute value of every coordinate of both lines, now and one
/// step ahead; the margin it buys (`1e-8` of it, against rounding errors near
/// `1e-15` of it) keeps the test conservative for the floating-point
/// predicates of `intersect` too.
///
/// An interval that holds zero keeps the pair whatever the margin (which
/// is positive, or NaN and then keeps it too), so `magnitude` is only
/// asked for where the interval lies to one side: most pairs that reach
/// this test are events, whose interval holds zero (on `sin_wave` and
/// `smalllines`, 87 to 90% of the pairs tested).
#[inline]
pub(crate) fn may_intersect(
    l1: &Line,
    l2: &Line,
    dt: f64,
    magnitude: impl FnOnce() -> f64,
) -> bool {
    let (lo, hi, scale) = projected(l1, l2, dt);
    if lo <= 0.0 && hi >= 0.0 {
        return true;
    }
    within_margin((lo, hi, scale), magnitude())
}

/// The interval the parallelogram `l2` sweeps relative to `l1` lands on,
/// projected onto the normal of `l1` with `l1` at zero, and the normal's
/// `|x| + |y|` (the margin's scale): [`may_intersect`]'s projections.
#[inline(always)]
fn projected(l1: &Line, l2: &Line, dt: f64) -> (f64, f64, f64) {
    let nx = l1.p1.y - l1.p2.y;
    let ny = l1.p2.x - l1.p1.x;
    let c = nx * l1.p1.x + ny * l1.p1.y;
    let a = nx * l2.p1.x + ny * l2.p1.y - c;
    let b = nx * l2.p2.x + ny * l2.p2.y - c;
    let w = (nx * (l2.v.x - l1.v.x) + ny * (l2.v.y - l1.v.y)) * dt;
    let (lo, hi) = if a < b { (a, b) } else { (b, a) };
    let (lo, hi) = if w < 0.0 { (lo + w, hi) } else { (lo, hi + w) };
    (lo, hi, nx.abs() + ny.abs())
}

/// Whether the interval `[lo, hi]` comes within the margin of zero that
/// `magnitude` buys at the normal's `scale` ([`may_intersect`]).
#[inline(always)]
fn within_margin((lo, hi, scale): (f64, f64, f64), magnitude: f64) -> bool {
    // The floor covers values that underflow: below `f64::MIN_POSITIVE`
    // rounding errors are absolute (up to 2^-1075 a product), not relative,
    // and the relative margin itself may round to zero.
    let margin = 1e-8 * scale * magnitude + MARGIN_FLOOR;
    // Written so that NaN anywhere keeps the pair (a NaN comparison is false).
    !(lo > margin || hi < -margin)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::line::DT;
    use crate::test_util::line;

    #[test]
    fn a_motion_within_rounding_makes_a_sliver_too() {
        // Found by the step fuzz target: a point on the extension of a
        // long segment, which moves by a few units in the last place
        // relative to it, diagonally. Rounding the swept corners makes a
        // sliver along the segment's line that takes the point in.
        let point = Line {
            p1: Vec2::new(1.2965673932653858, 1.3604056655850714),
            p2: Vec2::new(1.2965673932653858, 1.3604056655850714),
            v: Vec2::new(2.220446049250313e-16, 2.220446049250313e-16),
        };
        let segment = Line {
            p1: Vec2::new(0.711020828564889, 1.0393705653467613),
            p2: Vec2::new(1.9172849974227967e-230, 0.6495422293430991),
            v: Vec2::new(-0.0, 0.0),
        };
        assert_eq!(
            intersect(&point, &segment, DT),
            Some(IntersectionKind::L1WithL2)
        );
        assert!(is_sliver(&point, &segment, DT));
        // The same motion with the point off the line is no sliver.
        let off = Line {
            p1: Vec2::new(1.2965673932653858, 1.4),
            p2: Vec2::new(1.2965673932653858, 1.4),
            ..point
        };
        assert!(!is_sliver(&off, &segment, DT));
    }

    #[test]
    fn crossing_lines_are_already_intersected() {
        let a = line((0.0, 0.0), (1.0, 1.0), (0.0, 0.0));
        let b = line((0.0, 1.0), (1.0, 0.0), (0.0, 0.0));
        assert_eq!(
            intersect(&a, &b, 0.5),
            Some(IntersectionKind::AlreadyIntersected)
        );
    }

    #[test]
    fn far_apart_lines_do_not_meet() {
        let a = line((0.0, 0.0), (1.0, 0.0), (0.0, 0.0));
        let b = line((0.0, 5.0), (1.0, 5.0), (0.0, -1.0));
        assert_eq!(intersect(&a, &b, 0.5), None);
    }

    #[test]
    fn a_line_sweeping_fully_across_is_l2_with_l1() {
        // l2 is short and passes over l1's middle: its sweep crosses l1 with
        // both long sides of the parallelogram.
        let a = line((0.0, 0.0), (4.0, 0.0), (0.0, 0.0));
        let b = line((1.5, 1.0), (2.5, 1.0), (0.0, -4.0));
        assert_eq!(intersect(&a, &b, 0.5), Some(IntersectionKind::L2WithL1));
    }

    #[test]
    fn a_short_line_swallowed_by_the_sweep_is_l1_with_l2() {
        let a = line((1.5, 0.0), (2.5, 0.0), (0.0, 0.0));
        let b = line((0.0, 1.0), (4.0, 1.0), (0.0, -4.0));
        assert_eq!(intersect(&a, &b, 0.5), Some(IntersectionKind::L1WithL2));
    }

    #[test]
    fn only_relative_velocity_matters() {
        let a = line((0.0, 0.0), (4.0, 0.0), (3.0, 7.0));
        let b = line((1.5, 1.0), (2.5, 1.0), (3.0, 3.0));
        assert_eq!(intersect(&a, &b, 0.5), Some(IntersectionKind::L2WithL1));
        let c = line((1.5, 1.0), (2.5, 1.0), (3.0, 7.0));
        assert_eq!(intersect(&a, &c, 0.5), None);
    }

    #[test]
    fn an_endpoint_sweeping_across_uses_the_angle() {
        // Only the side swept by l2's p1 end crosses l1: one "top" crossing,
        // settled by the angle between the lines.
        let a = line((0.0, 0.0), (2.0, 0.0), (0.0, 0.0));
        let b = line((1.0, 0.5), (3.0, 0.5), (0.0, -2.0));
        let kind = intersect(&a, &b, 0.5);
        assert!(kind.is_some());
        assert_ne!(kind, Some(IntersectionKind::AlreadyIntersected));
    }

    #[test]
    fn nan_lines_never_meet() {
        let a = line((0.0, 0.0), (1.0, 1.0), (0.0, 0.0));
        let n = line((f64::NAN, 0.5), (f64::NAN, f64::NAN), (0.0, 0.0));
        assert_eq!(intersect(&a, &n, 0.5), None);
        assert_eq!(intersect(&n, &a, 0.5), None);
    }

    #[test]
    fn nan_velocity_can_still_report_an_overlap_now() {
        let a = line((0.0, 0.0), (1.0, 1.0), (0.0, 0.0));
        let b = line((0.0, 1.0), (1.0, 0.0), (f64::NAN, f64::NAN));
        assert_eq!(
            intersect(&a, &b, 0.5),
            Some(IntersectionKind::AlreadyIntersected)
        );
        let c = line((5.0, 1.0), (6.0, 0.0), (f64::NAN, f64::NAN));
        assert_eq!(intersect(&a, &c, 0.5), None);
    }

    #[test]
    fn identical_zero_length_lines_are_already_intersected() {
        let a = line((1.0, 1.0), (1.0, 1.0), (0.1, 0.0));
        let b = line((1.0, 1.0), (1.0, 1.0), (-0.1, 0.0));
        assert_eq!(
            intersect(&a, &b, 0.5),
            Some(IntersectionKind::AlreadyIntersected)
        );
    }

    #[test]
    fn the_prefilter_culls_parallel_neighbours_and_keeps_real_events() {
        let a = line((0.0, 0.0), (1.0, 1.0), (0.1, 0.0));
        let near = line((0.02, 0.0), (1.02, 1.0), (0.1, 0.0));
        assert_eq!(intersect(&a, &near, 0.5), None);
        assert!(!may_intersect(&a, &near, 0.5, || 2.0));
        let b = line((1.5, 1.0), (2.5, 1.0), (0.0, -4.0));
        let c = line((0.0, 0.0), (4.0, 0.0), (0.0, 0.0));
        assert!(intersect(&c, &b, 0.5).is_some());
        assert!(may_intersect(&c, &b, 0.5, || 4.0));
        // Zero-length and NaN lines are never culled.
        let dot = line((3.0, 3.0), (3.0, 3.0), (0.0, 0.0));
        assert!(may_intersect(&dot, &a, 0.5, || 3.0));
        let nan = line((f64::NAN, 0.0), (1.0, 1.0), (0.0, 0.0));
        assert!(may_intersect(&nan, &a, 0.5, || 3.0));
    }

    #[test]
    fn a_pair_just_off_the_line_is_decided_by_the_margin() {
        // `l2` lies 1e-12 above `l1`'s line: the interval misses zero, so
        // the margin decides, and the magnitude is asked for.
        let l1 = line((0.0, 0.0), (1.0, 0.0), (0.0, 0.0));
        let l2 = line((0.2, 1e-12), (0.4, 1e-12), (0.0, 0.0));
        for (magnitude, kept) in [(0.0, false), (1.0, true)] {
            let mut asked = false;
            let decided = may_intersect(&l1, &l2, 0.5, || {
                asked = true;
                magnitude
            });
            assert_eq!((decided, asked), (kept, true), "magnitude {magnitude}");
            assert_eq!(whole_prefilter(&l1, &l2, 0.5, magnitude), kept);
        }
    }

    fn near_line() -> impl proptest::strategy::Strategy<Value = Line> {
        use proptest::prelude::*;
        let c = prop_oneof![
            0.0f64..0.1,
            proptest::sample::select(vec![0.0, 0.025, 0.05, 0.1])
        ];
        let v = prop_oneof![-0.1f64..0.1, Just(0.0)];
        (c.clone(), c.clone(), c.clone(), c, v.clone(), v)
            .prop_map(|(a, b, c, d, vx, vy)| line((0.7 + a, 0.7 + b), (0.7 + c, 0.7 + d), (vx, vy)))
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(4096))]
        /// The prefilter never drops a pair that has an event.
        #[test]
        fn the_prefilter_is_conservative(l1 in near_line(), l2 in near_line()) {
            if intersect(&l1, &l2, 0.5).is_some() {
                proptest::prop_assert!(may_intersect(&l1, &l2, 0.5, || 1.0));
            }
        }

        /// Asking for the magnitude only where the interval misses zero
        /// answers as the whole test does, for any magnitude, zero, huge,
        /// infinite or NaN, on lines with zeros, infinities and NaN.
        #[test]
        fn the_prefilter_asks_for_the_magnitude_only_where_it_decides(
            l1 in awkward_line(),
            l2 in awkward_line(),
            magnitude in proptest::sample::select(
                vec![0.0, 1e-300, 0.5, 1.0, 3.0, 1e300, f64::INFINITY, f64::NAN],
            ),
        ) {
            let mut asked = false;
            let lazy = may_intersect(&l1, &l2, 0.5, || {
                asked = true;
                magnitude
            });
            proptest::prop_assert_eq!(lazy, whole_prefilter(&l1, &l2, 0.5, magnitude));
            if !lazy {
                proptest::prop_assert!(asked);
            }
        }
    }

    /// [`may_intersect`] without its shortcut: the margin always made and
    /// both comparisons always made.
    fn whole_prefilter(l1: &Line, l2: &Line, dt: f64, magnitude: f64) -> bool {
        within_margin(projected(l1, l2, dt), magnitude)
    }

    /// Lines near one another, often with a coordinate or a velocity that
    /// is zero, infinite or NaN.
    fn awkward_line() -> impl proptest::strategy::Strategy<Value = Line> {
        use proptest::prelude::*;
        let c = prop_oneof![
            4 => 0.0f64..0.1,
            1 => proptest::sample::select(vec![0.0, -0.0, 1e-310, f64::INFINITY, f64::NAN]),
        ];
        (c.clone(), c.clone(), c.clone(), c.clone(), c.clone(), c)
            .prop_map(|(a, b, c, d, vx, vy)| line((a, b), (c, d), (vx, vy)))
    }

    #[test]
    fn event_order_key_sorts_by_first_then_second() {
        let e = |first, second| Event {
            first: LineId(first),
            second: LineId(second),
            kind: IntersectionKind::L1WithL2,
        };
        assert!(e(1, 9).order_key() < e(2, 3).order_key());
        assert!(e(2, 3).order_key() < e(2, 4).order_key());
    }

    proptest::proptest! {
        /// Events sorted as packed keys come out as the events sorted by
        /// their order key: in any order, nearly in order (a few swapped,
        /// the largest moved to the front, which the insertion's budget
        /// hands to the full sort) or with slots too large to pack.
        #[test]
        fn events_sort_in_the_order_of_resolution(
            pairs in proptest::collection::btree_set((0u32..2000, 0u32..2000), 0..300),
            kinds in proptest::collection::vec(0u64..3, 300),
            shuffle in 0usize..4,
            huge in proptest::bool::weighted(0.1),
        ) {
            // Each pair once (events name distinct pairs).
            let pairs: std::collections::BTreeSet<(u32, u32)> =
                pairs.iter().map(|&(a, b)| (a.min(b), a.max(b))).collect();
            let mut events: Vec<Event<Slot>> = pairs
                .iter()
                .zip(&kinds)
                .map(|(&(a, b), &k)| Event {
                    first: Slot(a + if huge { u32::MAX - 2001 } else { 0 }),
                    second: Slot(b),
                    kind: IntersectionKind::from_number(k),
                })
                .collect();
            let n = events.len();
            match shuffle {
                0 => events.reverse(),
                1 => (1..n).step_by(20).for_each(|k| events.swap(k - 1, k)),
                2 => events.rotate_right(n / 16),
                _ => {}
            }
            let mut expected = events.clone();
            expected.sort_unstable_by_key(|e| e.named(|s| s.as_id()).order_key());
            sort_in_order(&mut events, &mut Vec::new());
            proptest::prop_assert_eq!(events, expected);
        }
    }
}
