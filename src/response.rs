//! Collision response: new velocities for the two lines of one event.

use crate::geometry::crossing_point;
use crate::line::Line;
use crate::narrow::{Event, IntersectionKind};

/// Applies the response to one event. Only velocities change; positions are
/// read as they are at the start of the step.
#[inline]
pub fn resolve(lines: &mut [Line], event: &Event) {
    let (i, j) = (event.first as usize, event.second as usize);
    let (v1, v2) = respond(&lines[i], &lines[j], event.kind);
    lines[i].v = v1;
    lines[j].v = v2;
}

/// The velocities `l1` and `l2` leave a collision of `kind` with (`l1` is
/// the line with the smaller id).
pub fn respond(
    l1: &Line,
    l2: &Line,
    kind: IntersectionKind,
) -> (crate::geometry::Vec2, crate::geometry::Vec2) {
    if kind == IntersectionKind::AlreadyIntersected {
        // Push each line away from the crossing point along itself, keeping
        // its speed; both use the same point.
        let p = crossing_point(l1.p1, l1.p2, l2.p1, l2.p2);
        let away = |l: &Line| {
            if (l.p1 - p).length() < (l.p2 - p).length() {
                (l.p2 - p).normalize() * l.v.length()
            } else {
                (l.p1 - p).normalize() * l.v.length()
            }
        };
        return (away(l1), away(l2));
    }

    // Elastic collision along the normal of the struck face, mass = length.
    let face = if kind == IntersectionKind::L1WithL2 {
        l2.dir().normalize()
    } else {
        l1.dir().normalize()
    };
    let normal = face.orthogonal();
    let v1f = l1.v.dot(face);
    let v2f = l2.v.dot(face);
    let v1n = l1.v.dot(normal);
    let v2n = l2.v.dot(normal);
    let m1 = l1.length();
    let m2 = l2.length();
    let n1 = ((m1 - m2) / (m1 + m2)) * v1n + ((2.0 * m2) / (m1 + m2)) * v2n;
    let n2 = ((2.0 * m1) / (m1 + m2)) * v1n + ((m2 - m1) / (m2 + m1)) * v2n;
    (normal * n1 + face * v1f, normal * n2 + face * v2f)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Vec2;
    use crate::test_util::line;

    #[test]
    fn equal_masses_swap_normal_velocities() {
        // Two horizontal lines of equal length, one falling onto the other.
        let a = line((0.0, 0.0), (1.0, 0.0), (0.0, 0.0));
        let b = line((0.0, 1.0), (1.0, 1.0), (0.25, -2.0));
        let (va, vb) = respond(&a, &b, IntersectionKind::L1WithL2);
        assert_eq!(va, Vec2::new(0.0, -2.0));
        assert_eq!(vb, Vec2::new(0.25, 0.0));
    }

    #[test]
    fn momentum_and_energy_are_kept_along_the_normal() {
        let a = line((0.0, 0.0), (3.0, 0.0), (0.0, 1.0));
        let b = line((0.0, 1.0), (1.0, 1.0), (0.0, -2.0));
        let (va, vb) = respond(&a, &b, IntersectionKind::L2WithL1);
        let (m1, m2) = (3.0, 1.0);
        let p_before = m1 * 1.0 + m2 * -2.0;
        let p_after = m1 * va.y + m2 * vb.y;
        assert!((p_before - p_after).abs() < 1e-12);
        let e_before = m1 * 1.0 + m2 * 4.0;
        let e_after = m1 * va.y * va.y + m2 * vb.y * vb.y;
        assert!((e_before - e_after).abs() < 1e-12);
    }

    #[test]
    fn overlapping_lines_are_pushed_apart_at_their_speed() {
        let a = line((0.0, 0.0), (2.0, 2.0), (0.0, 3.0));
        let b = line((0.0, 2.0), (4.0, -2.0), (4.0, 0.0));
        let (va, vb) = respond(&a, &b, IntersectionKind::AlreadyIntersected);
        // Crossing at (1, 1): a's endpoints are equidistant, so it heads to p1.
        assert!((va.length() - 3.0).abs() < 1e-12);
        assert!(va.x < 0.0 && va.y < 0.0);
        // b's p1 is nearer, so it heads towards p2.
        assert!((vb.length() - 4.0).abs() < 1e-12);
        assert!(vb.x > 0.0 && vb.y < 0.0);
    }

    #[test]
    fn collinear_overlap_gives_nan_like_the_reference() {
        let a = line((0.0, 0.0), (2.0, 0.0), (1.0, 0.0));
        let b = line((1.0, 0.0), (3.0, 0.0), (-1.0, 0.0));
        let (va, vb) = respond(&a, &b, IntersectionKind::AlreadyIntersected);
        assert!(va.has_nan() && vb.has_nan());
    }

    #[test]
    fn zero_length_pair_gives_nan_like_the_reference() {
        let a = line((1.0, 1.0), (1.0, 1.0), (1.0, 0.0));
        let b = line((2.0, 1.0), (2.0, 1.0), (-1.0, 0.0));
        let (va, vb) = respond(&a, &b, IntersectionKind::L1WithL2);
        assert!(va.has_nan() && vb.has_nan());
    }

    #[test]
    fn resolve_writes_both_velocities() {
        let mut lines = vec![
            line((0.0, 0.0), (1.0, 0.0), (0.0, 0.0)),
            line((5.0, 5.0), (6.0, 5.0), (0.0, 0.0)),
            line((0.0, 1.0), (1.0, 1.0), (0.0, -2.0)),
        ];
        let event = Event {
            first: 0,
            second: 2,
            kind: IntersectionKind::L1WithL2,
        };
        resolve(&mut lines, &event);
        assert_eq!(lines[0].v, Vec2::new(0.0, -2.0));
        assert_eq!(lines[2].v, Vec2::new(0.0, 0.0));
        assert_eq!(lines[1].v, Vec2::new(0.0, 0.0));
    }
}
