//! Swept bounding boxes, the currency of every broad phase, and the pair
//! test that every broad phase ends in.
//!
//! A line's swept box holds its segment now and one step ahead. If two lines
//! collide during the step, their swept boxes overlap (the meeting point
//! lies in both), so a broad phase may skip any pair whose boxes are apart.
//! Boxes are padded by `2^-20` of their largest coordinate before being
//! rounded to `f32`, which keeps them conservative for the rounding of both
//! the `f32` conversion and the floating-point predicates of `intersect`
//! (their errors are near `2^-50` of the coordinates).
//!
//! Lines fall into three groups:
//! - *inert* lines (NaN in both endpoints) can never collide again and are
//!   left out;
//! - lines with a finite box become [`Item`]s;
//! - the rest (a finite segment with a non-finite velocity, or a box beyond
//!   `f32` range) are *wild*: each is tested against every other line.

use crate::line::Line;
use crate::narrow::{intersect, may_intersect, Event};

/// A line's padded swept box in `f32`, with its id.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Item {
    /// Left edge.
    pub min_x: f32,
    /// Bottom edge.
    pub min_y: f32,
    /// Right edge.
    pub max_x: f32,
    /// Top edge.
    pub max_y: f32,
    /// The line's id.
    pub id: u32,
}

impl Item {
    /// True when the two closed boxes share a point.
    #[inline]
    pub fn overlaps(&self, other: &Item) -> bool {
        self.min_x <= other.max_x
            && other.min_x <= self.max_x
            && self.min_y <= other.max_y
            && other.min_y <= self.max_y
    }

    /// True when this box shares a point with the closed rectangle `r`.
    #[inline]
    pub fn overlaps_rect(&self, r: &Rect) -> bool {
        self.min_x <= r.max_x
            && r.min_x <= self.max_x
            && self.min_y <= r.max_y
            && r.min_y <= self.max_y
    }
}

/// An axis-aligned rectangle in `f32` (a tree node's region).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Rect {
    /// Left edge.
    pub min_x: f32,
    /// Bottom edge.
    pub min_y: f32,
    /// Right edge.
    pub max_x: f32,
    /// Top edge.
    pub max_y: f32,
}

impl Rect {
    /// The smallest rectangle holding every item, or `None` for no items.
    pub fn around(items: &[Item]) -> Option<Rect> {
        let first = items.first()?;
        let mut r = Rect {
            min_x: first.min_x,
            min_y: first.min_y,
            max_x: first.max_x,
            max_y: first.max_y,
        };
        for it in items {
            r.min_x = r.min_x.min(it.min_x);
            r.min_y = r.min_y.min(it.min_y);
            r.max_x = r.max_x.max(it.max_x);
            r.max_y = r.max_y.max(it.max_y);
        }
        Some(r)
    }
}

/// The swept boxes of one step.
#[derive(Debug, Default)]
pub struct SweptBoxes {
    /// One item per line with a finite box, in id order.
    pub items: Vec<Item>,
    /// Ids of wild lines (see the module documentation), in id order.
    pub wild: Vec<u32>,
    /// Per line id: a bound on the absolute value of its coordinates now and
    /// one step ahead, for the margin of [`may_intersect`].
    pub magnitude: Vec<f64>,
}

impl SweptBoxes {
    /// Recomputes every box for `lines` and a step of `dt`, reusing the
    /// buffers.
    pub fn compute(&mut self, lines: &[Line], dt: f64) {
        self.items.clear();
        self.wild.clear();
        self.magnitude.clear();
        self.items.reserve(lines.len());
        self.magnitude.reserve(lines.len());
        for (id, line) in lines.iter().enumerate() {
            let id = id as u32;
            let (item, magnitude) = swept_item(line, dt, id);
            self.magnitude.push(magnitude);
            match item {
                Some(item) => self.items.push(item),
                None if line.is_inert() => {}
                None => self.wild.push(id),
            }
        }
    }
}

/// The padded swept box of one line and its coordinate magnitude; `None`
/// for the box when it is not finite in `f32`.
#[inline]
pub fn swept_item(line: &Line, dt: f64, id: u32) -> (Option<Item>, f64) {
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
    // f64::min/max skip NaN, so check every input, not just the results.
    let finite = [line.p1, line.p2, e1, e2]
        .iter()
        .all(|p| p.x.is_finite() && p.y.is_finite());
    let pad = magnitude * (1.0 / 1048576.0) + 1e-12;
    let item = Item {
        min_x: (min_x - pad) as f32,
        min_y: (min_y - pad) as f32,
        max_x: (max_x + pad) as f32,
        max_y: (max_y + pad) as f32,
        id,
    };
    let in_range = [item.min_x, item.min_y, item.max_x, item.max_y]
        .iter()
        .all(|v| v.is_finite());
    if finite && in_range {
        (Some(item), magnitude)
    } else {
        (None, if finite { magnitude } else { f64::INFINITY })
    }
}

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
    for (k, &w) in boxes.wild.iter().enumerate() {
        for &other in &boxes.wild[k + 1..] {
            counts.candidates += 1;
            counts.exact += 1;
            exact_pair(lines, w, other, dt, events);
        }
        for item in &boxes.items {
            counts.candidates += 1;
            counts.exact += 1;
            exact_pair(lines, w, item.id, dt, events);
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
        let (item, m) = swept_item(&line((0.6, 0.7), (0.8, 0.65), (0.1, -0.2)), 0.5, 3);
        let item = item.unwrap();
        assert_eq!(item.id, 3);
        assert!(item.min_x <= 0.6 && item.max_x >= 0.85);
        assert!(item.min_y <= 0.55 && item.max_y >= 0.7);
        assert!((item.max_x - 0.85).abs() < 1e-5);
        assert_eq!(m, 0.8 + 0.1 * 0.5);
    }

    #[test]
    fn padding_survives_f32_rounding() {
        // Coordinates exactly representable in f32 must still be padded.
        let l = line((0.5, 0.5), (0.75, 0.75), (0.0, 0.0));
        let item = swept_item(&l, 0.5, 0).0.unwrap();
        assert!(f64::from(item.min_x) < 0.5 && f64::from(item.max_x) > 0.75);
        // And far from the box too.
        let l = line((1e6 + 0.1, -3e5), (1e6 + 0.2, -3e5), (0.0, 0.0));
        let item = swept_item(&l, 0.5, 0).0.unwrap();
        assert!(f64::from(item.min_x) < 1e6 + 0.1 && f64::from(item.max_x) > 1e6 + 0.2);
        assert!(f64::from(item.min_y) < -3e5 && f64::from(item.max_y) > -3e5);
    }

    #[test]
    fn lines_are_sorted_into_items_wild_and_inert() {
        let lines = [
            line((0.6, 0.6), (0.7, 0.7), (0.0, 0.0)),
            line((0.6, 0.6), (0.7, 0.7), (f64::NAN, f64::NAN)),
            line(
                (f64::NAN, f64::NAN),
                (f64::NAN, f64::NAN),
                (f64::NAN, f64::NAN),
            ),
            line((1e300, 0.6), (0.7, 0.7), (0.0, 0.0)),
        ];
        let mut boxes = SweptBoxes::default();
        boxes.compute(&lines, 0.5);
        assert_eq!(
            boxes.items.iter().map(|i| i.id).collect::<Vec<_>>(),
            vec![0]
        );
        assert_eq!(boxes.wild, vec![1, 3]);
        assert_eq!(boxes.magnitude.len(), 4);
    }

    proptest::proptest! {
        /// The f32 box strictly contains the segment now and one step ahead,
        /// whatever the rounding of the conversion.
        #[test]
        fn boxes_strictly_contain_their_points(
            x1 in -3.0f64..3.0, y1 in -3.0f64..3.0, x2 in -3.0f64..3.0, y2 in -3.0f64..3.0,
            vx in -1.0f64..1.0, vy in -1.0f64..1.0, scale in proptest::sample::select(vec![1e-9, 1.0, 1e5]),
        ) {
            let l = line((x1 * scale, y1 * scale), (x2 * scale, y2 * scale), (vx * scale, vy * scale));
            let item = swept_item(&l, 0.5, 0).0.unwrap();
            for p in [l.p1, l.p2, l.p1 + l.v * 0.5, l.p2 + l.v * 0.5] {
                proptest::prop_assert!(f64::from(item.min_x) < p.x && p.x < f64::from(item.max_x));
                proptest::prop_assert!(f64::from(item.min_y) < p.y && p.y < f64::from(item.max_y));
            }
        }
    }

    #[test]
    fn overlap_is_closed() {
        let a = Item {
            min_x: 0.0,
            min_y: 0.0,
            max_x: 1.0,
            max_y: 1.0,
            id: 0,
        };
        let b = Item {
            min_x: 1.0,
            min_y: 1.0,
            max_x: 2.0,
            max_y: 2.0,
            id: 1,
        };
        let c = Item {
            min_x: 1.5,
            min_y: 0.0,
            max_x: 2.0,
            max_y: 1.0,
            id: 2,
        };
        assert!(a.overlaps(&b) && b.overlaps(&a));
        assert!(!a.overlaps(&c) && !c.overlaps(&a));
        let r = Rect::around(&[a, c]).unwrap();
        assert_eq!((r.min_x, r.max_x, r.min_y, r.max_y), (0.0, 2.0, 0.0, 1.0));
        assert!(b.overlaps_rect(&r));
        assert!(Rect::around(&[]).is_none());
    }
}
