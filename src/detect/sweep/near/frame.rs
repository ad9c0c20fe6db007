//! The frame the widened boxes move with ([`super`]), and how far it has
//! moved since they were made.

use super::{travel, ROUNDING};
use crate::detect::sweep::hull::Packed;
use crate::detect::sweep::tuning::{FRAME_FLOOR, FRAME_PAYS, FRAME_SAMPLE};
use crate::detect::swept::{DIAGONAL_X, DIAGONAL_Y};
use crate::detect::Stored;
use crate::geometry::Vec2;
use crate::index::{LineId, Slot};

/// The frame the widened boxes move with: the lines' median velocity at
/// the last sweep, where that saves travel. Where most lines move alike
/// (a shape moving as one, as on `koch`), they stand still in it, and
/// their widened boxes need a margin only for rounding and the few lines
/// that do not; where velocities differ it is at rest.
#[derive(Debug, Default)]
pub(super) struct Frame {
    pub(super) velocity: [f64; 2],
    /// Steps since the widened boxes were made.
    pub(super) steps: u64,
}

impl Frame {
    /// Chooses the frame for boxes widened now: the median velocity of
    /// `lines` along each axis (the velocity of least travel to all), of
    /// at most [`FRAME_SAMPLE`] lines spread over them, if the lines'
    /// mean travel in it is below [`FRAME_PAYS`] of their travel at rest;
    /// else at rest. Returns the least travel a line's box is widened for
    /// ([`widened`](super::widened)).
    pub(super) fn choose(&mut self, stored: Stored, sample: &mut Vec<(LineId, Vec2)>) -> f64 {
        // The lines whose ids are a multiple of `every`, in id order: the
        // same lines and sums however the lines are stored.
        let lines = stored.lines;
        let every = (lines.len() / FRAME_SAMPLE).next_power_of_two();
        sample.clear();
        for (k, line) in lines.iter().enumerate() {
            let id = stored.id(Slot(k as u32));
            if id.0 as usize & (every - 1) == 0 && line.v.x.is_finite() && line.v.y.is_finite() {
                sample.push((id, line.v));
            }
        }
        // In id order, then each median picked in place: the same order
        // of the sample for the sums below, however the lines are stored.
        sample.sort_unstable_by_key(|&(id, _)| id);
        let mut median = |speed: fn(Vec2) -> f64| {
            if sample.is_empty() {
                return 0.0;
            }
            let by_speed =
                |a: &(LineId, Vec2), b: &(LineId, Vec2)| speed(a.1).total_cmp(&speed(b.1));
            let half = sample.len() / 2;
            let (_, &mut (_, v), _) = sample.select_nth_unstable_by(half, by_speed);
            speed(v)
        };
        let median = [median(|v| v.x), median(|v| v.y)];
        // The mean travel in the frame and at rest.
        let (mut moving, mut still) = (0.0, 0.0);
        for &(_, v) in sample.iter() {
            (moving, still) = (moving + travel(v, median), still + travel(v, [0.0; 2]));
        }
        let counted = sample.len().max(1) as f64;
        let (moving, still) = (moving / counted, still / counted);
        if moving < FRAME_PAYS * still {
            self.velocity = median;
            FRAME_FLOOR * moving
        } else {
            self.velocity = [0.0; 2];
            still
        }
    }

    /// How far the frame has moved since the widened boxes were made.
    pub(super) fn shift(&self, dt: f64) -> Shift {
        self.shift_after(self.steps, dt)
    }

    /// How far the frame moves in `steps` steps of `dt`.
    pub(super) fn shift_after(&self, steps: u64, dt: f64) -> Shift {
        let t = steps as f64 * dt;
        let (x, y) = (t * self.velocity[0], t * self.velocity[1]);
        if x == 0.0 && y == 0.0 {
            return Shift::Still;
        }
        let (u, w) = (
            x * DIAGONAL_X + y * DIAGONAL_Y,
            x * DIAGONAL_X - y * DIAGONAL_Y,
        );
        let along = [x, y, u, w];
        Shift::By(std::array::from_fn(|l| match l < 4 {
            true => up(along[l]),
            false => up(-along[l - 4]),
        }))
    }
}

/// `x` rounded up to an `f32`.
fn up(x: f64) -> f32 {
    let r = x as f32;
    match (r as f64) < x {
        true => r.next_up(),
        false => r,
    }
}

/// How far the frame has moved, lane by lane: each lane's shift rounded
/// up (a box's lanes are lower bounds, its greatest values negated), so
/// that a box found inside a widened box moved by it lies inside the
/// widened box moved by the frame's exact shift.
#[derive(Clone, Copy, Debug)]
pub(super) enum Shift {
    /// The frame is at rest, or has not moved yet.
    Still,
    By(Packed),
}

impl Shift {
    /// A widened box `wide` of `b` made now, as it was when the frame was
    /// made (every widened box is kept so), with `b` inside it moved by
    /// this shift; `None` if no widening found (rounding, huge values).
    pub(super) fn back(&self, b: &Packed, wide: &Packed) -> Option<Packed> {
        let Shift::By(s) = self else {
            return Some(*wide);
        };
        let mut back: Packed = std::array::from_fn(|l| wide[l] - s[l]);
        for _ in 0..4 {
            if inside_moved(b, &back, s) {
                return Some(back);
            }
            back = back.map(|w| w - w.abs() * ROUNDING - f32::MIN_POSITIVE);
        }
        None
    }
}

/// Whether box `b` lies in box `w` moved by `s` (each lane's shift
/// rounded up): each lane of `b` is greater than the other's moved, as
/// rounded to nearest, so at least its exact value.
#[inline(always)]
pub(super) fn inside_moved(b: &Packed, w: &Packed, s: &Packed) -> bool {
    (0..8).fold(true, |all, l| all & (b[l] > w[l] + s[l]))
}

#[cfg(test)]
mod tests {
    use super::super::widened;
    use super::*;
    use crate::line::Line;

    /// How far the frame moving with `v` moves in `steps` of `dt` along
    /// `x`, `y` and the diagonals, as the exact values the shift stands
    /// for.
    fn moved(v: [f64; 2], steps: u64, dt: f64) -> [f64; 4] {
        let (x, y) = (steps as f64 * dt * v[0], steps as f64 * dt * v[1]);
        [
            x,
            y,
            x * DIAGONAL_X + y * DIAGONAL_Y,
            x * DIAGONAL_X - y * DIAGONAL_Y,
        ]
    }

    proptest::proptest! {
        /// A box found inside a widened box moved by the frame's shift
        /// lies inside it moved by the exact distance, lane by lane: its
        /// least values at least the widened box's plus the distance, its
        /// greatest at most theirs plus the distance. Boxes are drawn
        /// about the moved widened box: one lane within a few of its `f32`
        /// steps, so that both answers come up, the others well inside.
        #[test]
        fn a_box_inside_the_moved_widened_box_lies_inside_it_exactly(
            wide in proptest::array::uniform8(-2000.0f32..2000.0),
            v in proptest::array::uniform2(-1.0f64..1.0),
            steps in 1u64..64,
            (lane, nudge) in (0usize..8, -8i32..8),
        ) {
            let dt = 0.5;
            let frame = Frame { velocity: v, steps };
            let Shift::By(s) = frame.shift(dt) else {
                return Ok(());
            };
            let d = moved(v, steps, dt);
            // Each lane's distance: the least values move by `d`, the
            // greatest (negated) by `-d`.
            let exact: [f64; 8] = std::array::from_fn(|l| match l < 4 {
                true => d[l],
                false => -d[l - 4],
            });
            let b: Packed = std::array::from_fn(|l| {
                let at = (wide[l] as f64 + exact[l]) as f32;
                let nudge = if l == lane { nudge } else { 64 };
                // Steps up from `at` (its bits count down below zero).
                let bits = at.to_bits() as i64 + nudge as i64 * at.signum() as i64;
                f32::from_bits(bits as u32)
            });
            if inside_moved(&b, &wide, &s) {
                for l in 0..8 {
                    // Exact: two `f32` values of these sizes differ by an
                    // `f64` exactly.
                    let room = b[l] as f64 - wide[l] as f64;
                    proptest::prop_assert!(room >= exact[l], "lane {l}: {room} < {}", exact[l]);
                }
            }
        }

        /// A leaver's widened box, taken back to the frame's start, holds
        /// its box moved by the frame's shift.
        #[test]
        fn a_widened_box_taken_back_holds_its_box(
            b in proptest::array::uniform4(-2000.0f32..2000.0),
            size in proptest::array::uniform4(0.0f32..50.0),
            v in proptest::array::uniform2(-1.0f64..1.0),
            steps in 1u64..64,
        ) {
            let b: Packed = std::array::from_fn(|l| match l < 4 {
                true => b[l],
                false => -(b[l - 4] + size[l - 4]),
            });
            let line = Line::default();
            let frame = Frame { velocity: v, steps };
            let shift = frame.shift(0.5);
            let wide = widened(&b, &line, 0.5, (v, 0.001));
            let back = shift.back(&b, &wide).expect("a widened box");
            if let Shift::By(s) = shift {
                proptest::prop_assert!(inside_moved(&b, &back, &s));
            }
        }
    }

    #[test]
    fn most_lines_moving_alike_choose_their_frame_and_others_rest() {
        let line = |vx, vy| Line {
            v: Vec2::new(vx, vy),
            ..Line::default()
        };
        // Nine in ten alike: their velocity.
        let mut lines: Vec<Line> = (0..1000).map(|_| line(0.25, -0.5)).collect();
        for (k, l) in lines.iter_mut().enumerate().filter(|(k, _)| k % 10 == 0) {
            *l = line(k as f64 * 1e-3 - 0.5, 0.125);
        }
        let mut frame = Frame::default();
        let least = frame.choose(Stored::by_id(&lines), &mut Vec::new());
        assert_eq!(frame.velocity, [0.25, -0.5]);
        assert!(least > 0.0 && least < 0.1 * 0.75, "{least}");
        // All different: at rest, and the mean travel.
        let lines: Vec<Line> = (0..1000)
            .map(|k| {
                line(
                    (k as f64 * 0.618).fract() - 0.5,
                    (k as f64 * 0.414).fract() - 0.5,
                )
            })
            .collect();
        let least = frame.choose(Stored::by_id(&lines), &mut Vec::new());
        assert_eq!(frame.velocity, [0.0; 2]);
        assert!(least > 0.3 && least < 0.7, "{least}");
    }
}
