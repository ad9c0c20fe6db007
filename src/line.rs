//! Line segments, their colours, and the two coordinate systems: the box the
//! simulation runs in and the window that scene files and pictures use.

use crate::geometry::Vec2;

/// Left and bottom edge of the box.
pub const BOX_MIN: f64 = 0.5;
/// Right and top edge of the box.
pub const BOX_MAX: f64 = 1.0;
/// Width of the display window in pixels; scene files use these units.
pub const WINDOW_WIDTH: f64 = 1180.0;
/// Height of the display window in pixels.
pub const WINDOW_HEIGHT: f64 = 800.0;
/// Time step of one simulation step.
pub const DT: f64 = 0.5;

/// The colour a line is drawn in (it has no effect on the physics).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Color {
    /// Code 0 in scene files.
    Red,
    /// Code 1 in scene files.
    Gray,
}

impl Color {
    /// The colour for a scene-file code, if the code is valid.
    pub fn from_code(code: i64) -> Option<Self> {
        match code {
            0 => Some(Color::Red),
            1 => Some(Color::Gray),
            _ => None,
        }
    }

    /// The scene-file code of the colour.
    pub fn code(self) -> u8 {
        match self {
            Color::Red => 0,
            Color::Gray => 1,
        }
    }
}

/// A moving segment in box coordinates. Its id is its index in the world.
/// Laid out as six `f64` in this order, so that the move's batches can
/// write a line's endpoints as one four-value store.
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Line {
    /// First endpoint.
    pub p1: Vec2,
    /// Second endpoint.
    pub p2: Vec2,
    /// Velocity, in box units per unit of time.
    pub v: Vec2,
}

impl Line {
    /// The direction vector `p1 - p2` that the contract calls `dir(l)`.
    #[inline]
    pub fn dir(&self) -> Vec2 {
        self.p1 - self.p2
    }

    /// The line's length, which the collision response uses as its mass.
    #[inline]
    pub fn length(&self) -> f64 {
        (self.p1 - self.p2).length()
    }

    /// True when both endpoints hold a NaN coordinate. Such a line can never
    /// take part in an event again: every orientation test involving it is
    /// NaN, so every comparison the narrow phase makes is false.
    #[inline]
    pub fn is_inert(&self) -> bool {
        self.p1.has_nan() && self.p2.has_nan()
    }
}

/// Scenes of this many lines (3 MB of them) or more are larger than a
/// core's cache: the steps that read lines in no order of memory's (by the
/// ids of pairs and events) ask for them a few items ahead
/// ([`read_ahead`]), and the hulls gather theirs a block at a time.
pub(crate) const LARGE_SCENE: usize = 1 << 16;

/// Items (pairs, events) between a line's [`read_ahead`] and its use.
pub(crate) const READ_AHEAD: usize = 8;

/// Reads `line`'s first and last fields (which may lie in two cache lines)
/// and drops them, so that it is on its way from memory while the items
/// before it are worked on: the loads stay in the program
/// ([`std::hint::black_box`]) and the processor carries on past them
/// while they wait.
#[inline(always)]
pub(crate) fn read_ahead(line: &Line) {
    std::hint::black_box(line.p1.x + line.v.y);
}

/// Converts a window-coordinate point to box coordinates, in the contract's
/// order of operations.
#[inline]
pub fn window_to_box_point(p: Vec2) -> Vec2 {
    Vec2::new(
        (p.x / WINDOW_WIDTH) * (BOX_MAX - BOX_MIN) + BOX_MIN,
        (p.y / WINDOW_HEIGHT) * (BOX_MAX - BOX_MIN) + BOX_MIN,
    )
}

/// Converts a window-unit velocity to box units per unit of time.
#[inline]
pub fn window_to_box_velocity(v: Vec2) -> Vec2 {
    Vec2::new(
        (v.x / WINDOW_WIDTH) * (BOX_MAX - BOX_MIN),
        (v.y / WINDOW_HEIGHT) * (BOX_MAX - BOX_MIN),
    )
}

/// Converts a box-coordinate point back to window coordinates (not
/// guaranteed to invert the forward map exactly).
#[cfg(test)]
fn box_to_window_point(p: Vec2) -> Vec2 {
    Vec2::new(
        (p.x - BOX_MIN) / (BOX_MAX - BOX_MIN) * WINDOW_WIDTH,
        (p.y - BOX_MIN) / (BOX_MAX - BOX_MIN) * WINDOW_HEIGHT,
    )
}

/// Converts a box-unit velocity back to window units.
#[cfg(test)]
fn box_to_window_velocity(v: Vec2) -> Vec2 {
    Vec2::new(
        v.x / (BOX_MAX - BOX_MIN) * WINDOW_WIDTH,
        v.y / (BOX_MAX - BOX_MIN) * WINDOW_HEIGHT,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_corners_map_to_box_corners() {
        assert_eq!(
            window_to_box_point(Vec2::new(0.0, 0.0)),
            Vec2::new(0.5, 0.5)
        );
        assert_eq!(
            window_to_box_point(Vec2::new(1180.0, 800.0)),
            Vec2::new(1.0, 1.0)
        );
        assert_eq!(
            window_to_box_velocity(Vec2::new(1180.0, -800.0)),
            Vec2::new(0.5, -0.5)
        );
    }

    #[test]
    fn conversion_round_trips_closely() {
        let p = Vec2::new(291.469136, 540.866025);
        let back = box_to_window_point(window_to_box_point(p));
        assert!((back.x - p.x).abs() < 1e-9 && (back.y - p.y).abs() < 1e-9);
        let v = Vec2::new(-0.208073, 0.454649);
        let back = box_to_window_velocity(window_to_box_velocity(v));
        assert!((back.x - v.x).abs() < 1e-12 && (back.y - v.y).abs() < 1e-12);
    }

    #[test]
    fn colour_codes() {
        assert_eq!(Color::from_code(0), Some(Color::Red));
        assert_eq!(Color::from_code(1), Some(Color::Gray));
        assert_eq!(Color::from_code(2), None);
        assert_eq!(Color::from_code(-1), None);
        assert_eq!(Color::Gray.code(), 1);
    }

    #[test]
    fn inert_needs_nan_in_both_endpoints() {
        let nan = Vec2::new(f64::NAN, 0.0);
        let ok = Vec2::new(0.7, 0.7);
        let line = |p1, p2| Line {
            p1,
            p2,
            v: Vec2::default(),
        };
        assert!(line(nan, nan).is_inert());
        assert!(!line(nan, ok).is_inert());
        assert!(!line(ok, ok).is_inert());
    }
}
