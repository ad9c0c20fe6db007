//! Swept bounding boxes, the currency of every broad phase, and the pair
//! test that every broad phase ends in.
//!
//! A line's swept box holds its segment now and one step ahead. If two lines
//! collide during the step, their swept boxes overlap (the meeting point
//! lies in both), so a broad phase may skip any pair whose boxes are apart.
//! Boxes are padded by `2^-20` of their largest coordinate, which keeps them
//! conservative for the floating-point predicates of `intersect` (whose
//! errors are near `2^-50` of the coordinates).
//!
//! Lines fall into three groups:
//! - *inert* lines (NaN in both endpoints) can never collide again and are
//!   left out;
//! - lines with a finite box go through the broad phase;
//! - the rest (a finite segment with a non-finite velocity, or a box beyond
//!   `f32` range) are *wild*: each is tested against every other line.

use crate::line::Line;
use crate::narrow::{intersect, may_intersect, Event};

/// A line's padded swept box.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SweptBox {
    /// Left edge.
    pub min_x: f64,
    /// Bottom edge.
    pub min_y: f64,
    /// Right edge.
    pub max_x: f64,
    /// Top edge.
    pub max_y: f64,
}

impl SweptBox {
    /// The smallest box holding both.
    #[inline]
    pub fn union(&self, other: &SweptBox) -> SweptBox {
        SweptBox {
            min_x: self.min_x.min(other.min_x),
            min_y: self.min_y.min(other.min_y),
            max_x: self.max_x.max(other.max_x),
            max_y: self.max_y.max(other.max_y),
        }
    }
}

/// How a line takes part in this step's broad phase.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// A finite swept box: goes through the broad phase.
    Boxed,
    /// Not finite but not inert: tested against every line.
    Wild,
    /// NaN in both endpoints: can never collide again.
    Inert,
}

/// The swept boxes of one step, indexed by line id.
#[derive(Debug, Default)]
pub struct SweptBoxes {
    /// Each line's padded swept box (meaningful for boxed lines only).
    pub boxes: Vec<SweptBox>,
    /// Each line's class.
    pub class: Vec<Class>,
    /// Each line's bound on the absolute value of its coordinates now and
    /// one step ahead, for the margin of [`may_intersect`].
    pub magnitude: Vec<f64>,
    /// Ids of wild lines, in id order.
    pub wild: Vec<u32>,
    /// Number of boxed lines.
    pub boxed: usize,
    /// The union of the boxed lines' boxes (`None` when there are none).
    pub bounds: Option<SweptBox>,
}

impl SweptBoxes {
    /// Recomputes every box for `lines` and a step of `dt`, reusing the
    /// buffers.
    pub fn compute(&mut self, lines: &[Line], dt: f64) {
        self.boxes.clear();
        self.class.clear();
        self.magnitude.clear();
        self.wild.clear();
        self.boxed = 0;
        let mut bounds: Option<SweptBox> = None;
        for (id, line) in lines.iter().enumerate() {
            let (b, magnitude) = swept_box(line, dt);
            let class = match b {
                Some(b) => {
                    bounds = Some(bounds.map_or(b, |u| u.union(&b)));
                    self.boxed += 1;
                    Class::Boxed
                }
                None if line.is_inert() => Class::Inert,
                None => {
                    self.wild.push(id as u32);
                    Class::Wild
                }
            };
            self.boxes.push(b.unwrap_or_default());
            self.class.push(class);
            self.magnitude.push(magnitude);
        }
        self.bounds = bounds;
    }
}

/// The padded swept box of one line (`None` when not finite) and the
/// magnitude of its coordinates.
#[inline]
pub fn swept_box(line: &Line, dt: f64) -> (Option<SweptBox>, f64) {
    let e1 = line.p1 + line.v * dt;
    let e2 = line.p2 + line.v * dt;
    let min_x = line.p1.x.min(line.p2.x).min(e1.x.min(e2.x));
    let max_x = line.p1.x.max(line.p2.x).max(e1.x.max(e2.x));
    let min_y = line.p1.y.min(line.p2.y).min(e1.y.min(e2.y));
    let max_y = line.p1.y.max(line.p2.y).max(e1.y.max(e2.y));
    let magnitude = min_x
        .abs()
        .max(max_x.abs())
        .max(min_y.abs())
        .max(max_y.abs());
    // min/max skip NaN, so test the inputs: the sum is NaN or infinite if
    // any of them is (or, harmlessly, if it overflows: the line turns wild).
    let sum = line.p1.x + line.p1.y + line.p2.x + line.p2.y + line.v.x + line.v.y;
    let pad = magnitude * PAD + 1e-12;
    let b = SweptBox {
        min_x: min_x - pad,
        min_y: min_y - pad,
        max_x: max_x + pad,
        max_y: max_y + pad,
    };
    if sum.is_finite() && magnitude.is_finite() {
        (Some(b), magnitude)
    } else {
        (
            None,
            if sum.is_finite() {
                magnitude
            } else {
                f64::INFINITY
            },
        )
    }
}

/// Relative padding of swept boxes: far above the rounding errors of the
/// predicates (near `2^-50` of the coordinates), far below any line's size.
pub const PAD: f64 = 1.0 / 1048576.0;

/// Running totals of a broad phase's pair work.
#[derive(Clone, Copy, Debug, Default)]
pub struct PairCounts {
    /// Pairs whose boxes were compared.
    pub candidates: u64,
    /// Pairs handed to `intersect`.
    pub exact: u64,
}

/// Tests one pair whose boxes overlap: the cheap prefilter, then the exact
/// test, pushing the event (lower id first) if there is one.
#[inline]
pub fn test_pair(
    lines: &[Line],
    magnitude: &[f64],
    a: u32,
    b: u32,
    dt: f64,
    events: &mut Vec<Event>,
    counts: &mut PairCounts,
) {
    let (first, second) = if a < b { (a, b) } else { (b, a) };
    let (l1, l2) = (&lines[first as usize], &lines[second as usize]);
    let m = magnitude[first as usize].max(magnitude[second as usize]);
    if !may_intersect(l1, l2, dt, m) {
        return;
    }
    counts.exact += 1;
    if let Some(kind) = intersect(l1, l2, dt) {
        events.push(Event {
            first,
            second,
            kind,
        });
    }
}

/// Tests every wild line against every other line that is not inert (each
/// pair once). Wild lines are rare and short-lived: a line whose velocity
/// turned NaN becomes inert one step later.
pub fn test_wild(
    lines: &[Line],
    boxes: &SweptBoxes,
    dt: f64,
    events: &mut Vec<Event>,
    counts: &mut PairCounts,
) {
    for &w in &boxes.wild {
        for (other, class) in boxes.class.iter().enumerate() {
            let other = other as u32;
            // Wild pairs are tested once, from their lower id.
            let wanted = match class {
                Class::Boxed => true,
                Class::Wild => other > w,
                Class::Inert => false,
            };
            if wanted {
                counts.candidates += 1;
                counts.exact += 1;
                exact_pair(lines, w, other, dt, events);
            }
        }
    }
}

#[inline]
fn exact_pair(lines: &[Line], a: u32, b: u32, dt: f64, events: &mut Vec<Event>) {
    let (first, second) = if a < b { (a, b) } else { (b, a) };
    if let Some(kind) = intersect(&lines[first as usize], &lines[second as usize], dt) {
        events.push(Event {
            first,
            second,
            kind,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec2;

    fn line(p1: (f64, f64), p2: (f64, f64), v: (f64, f64)) -> Line {
        Line {
            p1: Vec2::new(p1.0, p1.1),
            p2: Vec2::new(p2.0, p2.1),
            v: Vec2::new(v.0, v.1),
        }
    }

    #[test]
    fn the_box_holds_the_segment_now_and_one_step_ahead() {
        let (b, m) = swept_box(&line((0.6, 0.7), (0.8, 0.65), (0.1, -0.2)), 0.5);
        let b = b.unwrap();
        assert!(b.min_x < 0.6 && b.max_x > 0.85);
        assert!(b.min_y < 0.55 && b.max_y > 0.7);
        assert!((b.max_x - 0.85).abs() < 1e-5);
        assert_eq!(m, 0.8 + 0.1 * 0.5);
    }

    proptest::proptest! {
        /// The box strictly contains the segment now and one step ahead, at
        /// any scale.
        #[test]
        fn boxes_strictly_contain_their_points(
            x1 in -3.0f64..3.0, y1 in -3.0f64..3.0, x2 in -3.0f64..3.0, y2 in -3.0f64..3.0,
            vx in -1.0f64..1.0, vy in -1.0f64..1.0, scale in proptest::sample::select(vec![1e-9, 1.0, 1e5]),
        ) {
            let l = line((x1 * scale, y1 * scale), (x2 * scale, y2 * scale), (vx * scale, vy * scale));
            let b = swept_box(&l, 0.5).0.unwrap();
            for p in [l.p1, l.p2, l.p1 + l.v * 0.5, l.p2 + l.v * 0.5] {
                proptest::prop_assert!(b.min_x < p.x && p.x < b.max_x);
                proptest::prop_assert!(b.min_y < p.y && p.y < b.max_y);
            }
        }
    }

    #[test]
    fn lines_are_sorted_into_boxed_wild_and_inert() {
        let lines = [
            line((0.6, 0.6), (0.7, 0.7), (0.0, 0.0)),
            line((0.6, 0.6), (0.7, 0.7), (f64::NAN, f64::NAN)),
            line(
                (f64::NAN, f64::NAN),
                (f64::NAN, f64::NAN),
                (f64::NAN, f64::NAN),
            ),
            line((1e308, 0.6), (0.7, 0.7), (1e308, 0.0)),
            line((0.8, 0.9), (0.8, 0.95), (0.0, 0.0)),
        ];
        let mut boxes = SweptBoxes::default();
        boxes.compute(&lines, 0.5);
        use Class::*;
        assert_eq!(boxes.class, vec![Boxed, Wild, Inert, Wild, Boxed]);
        assert_eq!(boxes.wild, vec![1, 3]);
        assert_eq!(boxes.boxed, 2);
        let u = boxes.bounds.unwrap();
        assert!(u.min_x < 0.6 && u.max_x > 0.8 && u.max_y > 0.95);
    }

    #[test]
    fn wild_lines_are_tested_against_all_but_inert_ones() {
        let lines = [
            line((0.6, 0.6), (0.7, 0.7), (f64::NAN, f64::NAN)),
            line((0.6, 0.7), (0.7, 0.6), (0.0, 0.0)),
            line(
                (f64::NAN, f64::NAN),
                (f64::NAN, f64::NAN),
                (f64::NAN, f64::NAN),
            ),
            line((0.65, 0.6), (0.65, 0.7), (f64::NAN, 0.0)),
        ];
        let mut boxes = SweptBoxes::default();
        boxes.compute(&lines, 0.5);
        let (mut events, mut counts) = (Vec::new(), PairCounts::default());
        test_wild(&lines, &boxes, 0.5, &mut events, &mut counts);
        // 0-1, 0-3, 3-1: all three cross now.
        assert_eq!(counts.exact, 3);
        events.sort_unstable_by_key(Event::order_key);
        let pairs: Vec<_> = events.iter().map(|e| (e.first, e.second)).collect();
        assert_eq!(pairs, vec![(0, 1), (0, 3), (1, 3)]);
    }
}
