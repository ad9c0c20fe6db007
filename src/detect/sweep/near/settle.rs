//! Each box checked against its widened box ([`super`]): on the packed
//! `f32` boxes themselves, lane by lane, so that no rounding lets a box
//! out unnoticed; with AVX2 a block of eight boxes at a time.

use super::frame::{inside_moved, Shift};
use super::NOWHERE;
use crate::detect::sweep::hull::{Packed, NO_KEY};
use crate::index::Slot;
use multiversion::multiversion;

/// Sets the boxes of the lines without one (key [`NO_KEY`]) to
/// [`NOWHERE`], which overlaps no box and lies in every box; if `kept`,
/// pushes to `leavers` the slot (from `start` on) of each box that does not
/// lie in its widened box `wide`. Returns the lines without a box. The
/// lines without a box are found in a loop of their own, and the rare
/// leaver is taken by a branch: with AVX2 one a block of eight boxes,
/// compared at once ([`not_within`](crate::lanes::blocks::not_within)), and the boxes of a
/// block that may hold a leaver then checked one by one.
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2"), dispatcher = "static")
)]
pub(super) fn settle(
    boxes: &mut [Packed],
    keys: &[f32],
    (wide, kept, shift): (&[Packed], bool, &Shift),
    (start, leavers): (usize, &mut Vec<Slot>),
) -> u64 {
    let unboxed = keys.iter().map(|&k| u64::from(k == NO_KEY)).sum::<u64>();
    if unboxed > 0 {
        for (b, &key) in boxes.iter_mut().zip(keys) {
            if key == NO_KEY {
                *b = NOWHERE;
            }
        }
    }
    let shift = match (kept, shift) {
        (false, _) => return unboxed,
        (true, Shift::Still) => None,
        (true, Shift::By(s)) => Some(s),
    };
    // A line without a box lies in anything.
    let within = |k: usize, b: &Packed, w: &Packed| match shift {
        None => inside(b, w),
        Some(s) => inside_moved(b, w, s) || keys[k] == NO_KEY,
    };
    let leave = |k: usize| leavers.push(Slot((start + k) as u32));
    multiversion::target::match_target! {
        "x86_64+avx2" => {
            let mut leave = leave;
            let mut check = |from: usize, to: usize| {
                (from..to).filter(|&k| !within(k, &boxes[k], &wide[k])).for_each(&mut leave)
            };
            let whole = crate::lanes::blocks::not_within(boxes, wide, shift, &mut check);
            check(whole, boxes.len());
        }
        _ => {
            let each = boxes.iter().zip(wide).enumerate();
            let mut leave = leave;
            each.filter(|&(k, (b, w))| !within(k, b, w)).for_each(|(k, _)| leave(k));
        }
    }
    unboxed
}

/// Whether box `b` lies in box `w`: each of its lanes is at least the
/// other's (both are lower bounds). Written without branches, as
/// [`overlaps`](crate::detect::sweep::hull::overlaps) is, so that the AVX2
/// clones make it one comparison.
#[inline(always)]
pub(super) fn inside(b: &Packed, w: &Packed) -> bool {
    (0..8).fold(true, |all, l| all & (b[l] >= w[l]))
}
