//! Boxes as parallel arrays (keys, packed hulls, slots), which the sweep
//! reads a column at a time: views of them, a list that grows, and the
//! boxes in sorted order, kept from step to step. Lines move little in a
//! step, so boxes made in last step's order are nearly sorted and an
//! insertion sort in place finishes in about one pass; when the order has
//! changed a lot (the first step, a new sweep direction, a scene flying
//! apart) it stops after a budget of moves and a radix sort does the job.

use super::hull::{Packed, NO_KEY};
use crate::detect::sweep::tuning::MOVES_PER_BOX;
use crate::index::Slot;
use crate::lanes::blocks::BLOCK as IN_ORDER_RUN;
use crate::team::{self, Team};
use multiversion::multiversion;
use std::ops::Range;
use std::sync::atomic::{AtomicBool, Ordering};

/// The slot named by the sentinel after the last box: none.
pub(crate) const NO_SLOT: Slot = Slot(u32::MAX);

/// Boxes in parallel slices: each box's key, packed hull and slot.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxSlice<'a> {
    pub keys: &'a [f32],
    pub hulls: &'a [Packed],
    pub slots: &'a [Slot],
}

impl<'a> BoxSlice<'a> {
    pub(crate) fn new(keys: &'a [f32], hulls: &'a [Packed], slots: &'a [Slot]) -> Self {
        Self { keys, hulls, slots }
    }

    pub(crate) fn len(&self) -> usize {
        self.keys.len()
    }

    /// The boxes `r`.
    pub(crate) fn at(self, r: Range<usize>) -> Self {
        let (keys, hulls) = (&self.keys[r.clone()], &self.hulls[r.clone()]);
        Self::new(keys, hulls, &self.slots[r])
    }
}

/// A [`BoxSlice`] to write.
#[derive(Debug, Default)]
pub(crate) struct BoxSliceMut<'a> {
    pub keys: &'a mut [f32],
    pub hulls: &'a mut [Packed],
    pub slots: &'a mut [Slot],
}

impl<'a> BoxSliceMut<'a> {
    pub(crate) fn new(keys: &'a mut [f32], hulls: &'a mut [Packed], slots: &'a mut [Slot]) -> Self {
        Self { keys, hulls, slots }
    }

    pub(crate) fn len(&self) -> usize {
        self.keys.len()
    }

    /// The boxes `r`, borrowed.
    pub(crate) fn at(&mut self, r: Range<usize>) -> BoxSliceMut<'_> {
        let (keys, hulls) = (&mut self.keys[r.clone()], &mut self.hulls[r.clone()]);
        BoxSliceMut::new(keys, hulls, &mut self.slots[r])
    }

    pub(crate) fn view(&self) -> BoxSlice<'_> {
        BoxSlice::new(self.keys, self.hulls, self.slots)
    }

    /// The boxes before `mid` and from `mid` on.
    pub(crate) fn split_at(self, mid: usize) -> (Self, Self) {
        let (keys, rest_keys) = self.keys.split_at_mut(mid);
        let (hulls, rest_hulls) = self.hulls.split_at_mut(mid);
        let (slots, rest_slots) = self.slots.split_at_mut(mid);
        let rest = Self::new(rest_keys, rest_hulls, rest_slots);
        (Self::new(keys, hulls, slots), rest)
    }

    /// Splits the boxes into `parts` shares as [`team::share`] gives them,
    /// for the pieces of a job to take (see [`team::Parts`]).
    pub(crate) fn shares(self, parts: usize) -> team::Parts<Self> {
        let n = self.len();
        let mut rest = self;
        let mut cut = |k| {
            let (head, tail) = std::mem::take(&mut rest).split_at(team::share(n, parts, k).len());
            rest = tail;
            head
        };
        team::Parts::new((0..parts.max(1)).map(&mut cut))
    }

    /// Copies the boxes `src` to `dest` on, as [`slice::copy_within`].
    pub(crate) fn copy_within(&mut self, src: Range<usize>, dest: usize) {
        self.keys.copy_within(src.clone(), dest);
        self.hulls.copy_within(src.clone(), dest);
        self.slots.copy_within(src, dest);
    }

    /// Copies the boxes `from` of `src` here, from `at` on; returns where
    /// they end.
    pub(crate) fn copy_from(&mut self, at: usize, src: BoxSlice, from: Range<usize>) -> usize {
        let to = at..at + from.len();
        self.keys[to.clone()].copy_from_slice(&src.keys[from.clone()]);
        self.hulls[to.clone()].copy_from_slice(&src.hulls[from.clone()]);
        self.slots[to.clone()].copy_from_slice(&src.slots[from]);
        to.end
    }

    /// Sorts the boxes by key in `f32`'s total order, boxes with equal
    /// keys kept in their order: by radix through `order` and `spare`.
    pub(crate) fn sort_by_radix(self, order: &mut Vec<(f32, u32)>, spare: &mut BoxList) {
        radix_order(self.keys, order);
        permute(self.keys, order, &mut spare.keys);
        permute(self.hulls, order, &mut spare.hulls);
        permute(self.slots, order, &mut spare.slots);
    }
}

/// Boxes as growable parallel arrays, each with the band after the last
/// it reaches (its `end`).
#[derive(Debug, Default)]
pub(crate) struct BoxList {
    pub keys: Vec<f32>,
    pub hulls: Vec<Packed>,
    pub slots: Vec<Slot>,
    pub ends: Vec<u32>,
}

impl BoxList {
    pub(crate) fn clear(&mut self) {
        self.keys.clear();
        self.hulls.clear();
        self.slots.clear();
        self.ends.clear();
    }

    pub(crate) fn len(&self) -> usize {
        self.keys.len()
    }

    #[inline]
    pub(crate) fn push(&mut self, key: f32, hull: Packed, slot: Slot, end: u32) {
        self.keys.push(key);
        self.hulls.push(hull);
        self.slots.push(slot);
        self.ends.push(end);
    }

    /// Appends box `k` of `other`.
    #[inline]
    pub(crate) fn push_from(&mut self, other: &BoxList, k: usize) {
        self.push(other.keys[k], other.hulls[k], other.slots[k], other.ends[k]);
    }

    /// Appends the boxes of `other`.
    pub(crate) fn extend(&mut self, other: &BoxList) {
        self.keys.extend_from_slice(&other.keys);
        self.hulls.extend_from_slice(&other.hulls);
        self.slots.extend_from_slice(&other.slots);
        self.ends.extend_from_slice(&other.ends);
    }

    /// Makes it `len` boxes long, any new ones zero.
    pub(crate) fn resize(&mut self, len: usize) {
        self.keys.resize(len, 0.0);
        self.hulls.resize(len, [0.0; 8]);
        self.slots.resize(len, Slot::default());
        self.ends.resize(len, 0);
    }

    /// Sets box `at` to box `k` of `other`.
    #[inline]
    pub(crate) fn set(&mut self, at: usize, other: &BoxList, k: usize) {
        self.keys[at] = other.keys[k];
        self.hulls[at] = other.hulls[k];
        self.slots[at] = other.slots[k];
        self.ends[at] = other.ends[k];
    }

    /// The boxes `r`, without their ends.
    pub(crate) fn slice(&self, r: Range<usize>) -> BoxSlice<'_> {
        let (keys, hulls) = (&self.keys[r.clone()], &self.hulls[r.clone()]);
        BoxSlice::new(keys, hulls, &self.slots[r])
    }

    /// The boxes `r`, without their ends, to write.
    pub(crate) fn slice_mut(&mut self, r: Range<usize>) -> BoxSliceMut<'_> {
        let (keys, hulls) = (&mut self.keys[r.clone()], &mut self.hulls[r.clone()]);
        BoxSliceMut::new(keys, hulls, &mut self.slots[r])
    }

    /// Sorts the boxes by key, as [`BoxSliceMut::sort_by_radix`] does.
    pub(crate) fn sort(&mut self, order: &mut Vec<(f32, u32)>, spare: &mut BoxList) {
        radix_order(&self.keys, order);
        permute(&mut self.keys, order, &mut spare.keys);
        permute(&mut self.hulls, order, &mut spare.hulls);
        permute(&mut self.slots, order, &mut spare.slots);
        permute(&mut self.ends, order, &mut spare.ends);
    }
}

/// Each key with its place, sorted by key in `f32`'s total order (equal
/// keys in their order).
fn radix_order(keys: &[f32], order: &mut Vec<(f32, u32)>) {
    order.clear();
    order.extend(keys.iter().zip(0u32..).map(|(&key, at)| (key, at)));
    radsort::sort_by_key(order, |k| k.0);
}

/// Puts `v` in the order of `order`'s places, through `spare`.
fn permute<T: Copy>(v: &mut [T], order: &[(f32, u32)], spare: &mut Vec<T>) {
    spare.clear();
    spare.extend(order.iter().map(|&(_, at)| v[at as usize]));
    v.copy_from_slice(spare);
}

/// Boxes as parallel arrays, followed by one sentinel box (key
/// [`NO_KEY`]) so that a scan always stops.
#[derive(Debug, Default)]
pub(crate) struct Boxes {
    /// Least value along the sweep direction, or [`NO_KEY`].
    pub keys: Vec<f32>,
    /// Packed hull (meaningless where the key is [`NO_KEY`]).
    pub hulls: Vec<Packed>,
    /// The line's slot.
    pub slots: Vec<Slot>,
    /// Keys and places, and spare arrays, for the radix sort.
    keyed: Vec<(f32, u32)>,
    spare: BoxList,
}

impl Boxes {
    /// Resets to the slots `0..n`, in that order, with room for their hulls.
    pub(crate) fn reset(&mut self, n: usize) {
        self.slots.clear();
        self.slots.extend((0..n as u32).map(Slot));
        self.slots.push(NO_SLOT);
        self.keys.clear();
        self.keys.resize(n + 1, NO_KEY);
        self.hulls.clear();
        self.hulls.resize(n + 1, [0.0; 8]);
    }

    /// Makes room for `n` boxes and the sentinel.
    pub(crate) fn set_len(&mut self, n: usize) {
        self.keys.resize(n + 1, NO_KEY);
        self.hulls.resize(n + 1, [0.0; 8]);
        self.slots.resize(n + 1, NO_SLOT);
        (self.keys[n], self.slots[n]) = (NO_KEY, NO_SLOT);
    }

    /// Boxes held, the sentinel not counted.
    pub(crate) fn len(&self) -> usize {
        self.slots.len().saturating_sub(1)
    }

    /// The first `n` boxes.
    pub(crate) fn slice(&self, n: usize) -> BoxSlice<'_> {
        BoxSlice::new(&self.keys[..n], &self.hulls[..n], &self.slots[..n])
    }

    /// The first `n` boxes, to write.
    pub(crate) fn slice_mut(&mut self, n: usize) -> BoxSliceMut<'_> {
        let (keys, hulls) = (&mut self.keys[..n], &mut self.hulls[..n]);
        BoxSliceMut::new(keys, hulls, &mut self.slots[..n])
    }

    /// Sorts the boxes by key (ties in any order: the sweep tests tied
    /// boxes both ways round), the sentinel staying last, sharing the work
    /// with `team`: each member sorts its share in place by insertion (the
    /// boxes it made the hulls of, still in its cache), then the few boxes
    /// that belong before the start of their share are moved there on this
    /// thread; by radix if that takes too many moves. Keys are never NaN.
    /// Returns the number of boxes with a real key, which now come first.
    pub(crate) fn sort(&mut self, team: &Team) -> usize {
        let (n, threads) = (self.len(), team.threads());
        let mut budget = MOVES_PER_BOX * n;
        let shares = self.slice_mut(n).shares(threads);
        let sorted = AtomicBool::new(true);
        team.run(&|k| {
            let mut share = shares.take(k);
            if insert(share.at(0..share.len()), 1, budget / threads, false).is_none() {
                sorted.store(false, Ordering::Relaxed);
            }
        });
        let mut sorted = sorted.into_inner();
        for k in 1..threads {
            let start = team::share(n, threads, k).start;
            if sorted && start > 0 && start < n {
                match insert(self.slice_mut(n), start, budget, true) {
                    Some(moves) => budget -= moves,
                    None => sorted = false,
                }
            }
        }
        if !sorted {
            let (keys, hulls) = (&mut self.keys[..n], &mut self.hulls[..n]);
            let boxes = BoxSliceMut::new(keys, hulls, &mut self.slots[..n]);
            boxes.sort_by_radix(&mut self.keyed, &mut self.spare);
        }
        self.keys[..n].partition_point(|&k| k != NO_KEY)
    }
}

/// Sorts nearly sorted boxes by key in place: by insertion while that
/// stays short, else by radix through `order` and `spare`.
pub(crate) fn sort_nearly_sorted(
    mut b: BoxSliceMut,
    order: &mut Vec<(f32, u32)>,
    spare: &mut BoxList,
) {
    let budget = MOVES_PER_BOX * b.len() + 16;
    if insert(b.at(0..b.len()), 1, budget, false).is_none() {
        b.sort_by_radix(order, spare);
    }
}

/// Insertion sort of the boxes from `from` on into the sorted boxes
/// before them, giving up after `budget` moves (leaving them permuted but
/// unsorted). With `until_in_place`, the boxes from `from` on are sorted
/// already and it stops at the first that needs no move. Returns the moves
/// made, if it finished. Compiled for the baseline and for AVX2, chosen
/// when the program starts: with AVX2 the boxes already in order are
/// passed over a block at a time and a hull moves in one instruction.
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2+bmi1")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2+bmi1"), dispatcher = "static")
)]
pub(crate) fn insert(
    b: BoxSliceMut,
    from: usize,
    budget: usize,
    until_in_place: bool,
) -> Option<usize> {
    multiversion::target::match_target! {
        "x86_64+avx2+bmi1" => {
            let out_of_order = |run: &[f32; IN_ORDER_RUN + 1]| {
                crate::lanes::blocks::out_of_order_avx2(run)
            };
            insert_with(b, from, budget, until_in_place, Some(out_of_order))
        }
        _ => insert_with(b, from, budget, until_in_place, out_of_order_without_avx2()),
    }
}

/// Which keys of a run are below the key before them: bit `k` where
/// `run[k + 1] < run[k]`.
type OutOfOrder = fn(&[f32; IN_ORDER_RUN + 1]) -> u32;

/// [`insert`], with `out_of_order` (see [`OutOfOrder`]) to pass over the
/// boxes already in order a block at a time where the target checks a
/// block in a few instructions (else one at a time).
#[inline(always)]
fn insert_with(
    b: BoxSliceMut,
    from: usize,
    mut budget: usize,
    until_in_place: bool,
    out_of_order: Option<impl Fn(&[f32; IN_ORDER_RUN + 1]) -> u32>,
) -> Option<usize> {
    let BoxSliceMut { keys, hulls, slots } = b;
    // All three as long as the keys: no bound to check on the others.
    let n = keys.len();
    let (hulls, slots) = (&mut hulls[..n], &mut slots[..n]);
    let mut moves = 0;
    let mut i = from.max(1);
    while i < n {
        // Most boxes are in order: passed over to the next that is not.
        if let (false, Some(out_of_order)) = (until_in_place, &out_of_order) {
            while let Some(run) = keys.get(i - 1..i + IN_ORDER_RUN) {
                let bits = out_of_order(run.try_into().expect("a run"));
                if bits != 0 {
                    i += bits.trailing_zeros() as usize;
                    break;
                }
                i += IN_ORDER_RUN;
            }
            if i >= n {
                break;
            }
        }
        let key = keys[i];
        if keys[i - 1] <= key {
            if until_in_place {
                break;
            }
            i += 1;
            continue;
        }
        let (hull, slot) = (hulls[i], slots[i]);
        let mut j = i;
        while j > 0 && keys[j - 1] > key {
            keys[j] = keys[j - 1];
            hulls[j] = hulls[j - 1];
            slots[j] = slots[j - 1];
            j -= 1;
        }
        keys[j] = key;
        hulls[j] = hull;
        slots[j] = slot;
        let moved = i - j;
        if moved > budget {
            return None;
        }
        budget -= moved;
        moves += moved;
        i += 1;
    }
    Some(moves)
}

/// [`OutOfOrder`] where the processor lacks AVX2: with WebAssembly's
/// SIMD, four keys against the four before them at a time.
#[cfg(all(target_arch = "wasm32", target_feature = "simd128"))]
#[inline(always)]
fn out_of_order_without_avx2() -> Option<OutOfOrder> {
    Some(crate::lanes::blocks::out_of_order_simd128)
}

/// Other targets: one box at a time (see the WebAssembly version).
#[cfg(not(all(target_arch = "wasm32", target_feature = "simd128")))]
#[inline(always)]
fn out_of_order_without_avx2() -> Option<OutOfOrder> {
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn boxes(keys: &[f32]) -> Boxes {
        let mut b = Boxes::default();
        b.reset(keys.len());
        b.keys[..keys.len()].copy_from_slice(keys);
        for (k, &key) in keys.iter().enumerate() {
            b.hulls[k] = [key; 8];
        }
        b
    }

    fn check(b: &Boxes, keys: &[f32], boxed: usize) {
        let n = keys.len();
        assert!(b.keys[..n].windows(2).all(|w| w[0] <= w[1]));
        assert_eq!(b.keys[n], NO_KEY);
        assert_eq!(b.slots[n], NO_SLOT);
        for k in 0..n {
            // Each box kept its hull and slot together.
            assert_eq!(b.keys[k], keys[b.slots[k].0 as usize]);
            assert!(b.hulls[k][0] == b.keys[k] || b.keys[k] == NO_KEY);
        }
        let mut slots = b.slots[..n].to_vec();
        slots.sort_unstable();
        assert_eq!(slots, (0..n as u32).map(Slot).collect::<Vec<_>>());
        assert_eq!(b.keys[..n].partition_point(|&k| k != NO_KEY), boxed);
    }

    /// Nearly sorted boxes are sorted by insertion, scrambled ones by
    /// radix, both by the sweep's sort and by a layout's.
    #[test]
    fn boxes_are_sorted_by_insertion_or_else_by_radix() {
        let mut nearly: Vec<f32> = (0..1000).map(|i| i as f32).collect();
        nearly.swap(10, 11);
        nearly.swap(500, 503);
        nearly[7] = NO_KEY;
        let mut scrambled: Vec<f32> = (0..1000u32)
            .map(|i| ((i * 7919) % 1000) as f32 - 500.0)
            .collect();
        scrambled.extend([f32::NEG_INFINITY, -0.0, 0.0, NO_KEY]);
        for (keys, by_insertion) in [(nearly, true), (scrambled, false)] {
            let n = keys.len();
            let mut b = boxes(&keys);
            let moves = insert(b.slice_mut(n), 1, MOVES_PER_BOX * n, false);
            assert_eq!(moves.is_some(), by_insertion);
            let mut b = boxes(&keys);
            assert_eq!(b.sort(&Team::solo()), n - 1);
            check(&b, &keys, n - 1);
            // Sorting again (now in order) keeps it so.
            assert_eq!(b.sort(&Team::solo()), n - 1);
            check(&b, &keys, n - 1);
            let mut b = boxes(&keys);
            sort_nearly_sorted(b.slice_mut(n), &mut Vec::new(), &mut BoxList::default());
            check(&b, &keys, n - 1);
        }
    }

    #[test]
    fn a_team_sorts_its_shares_and_mends_the_seams() {
        for threads in [2, 3, 8] {
            let team = Team::new(threads).unwrap();
            // Nearly sorted, with boxes that belong in another share.
            let mut keys: Vec<f32> = (0..1000).map(|i| i as f32).collect();
            keys.swap(10, 11);
            keys.swap(499, 503);
            keys[600] = 3.5;
            keys[7] = NO_KEY;
            let mut b = boxes(&keys);
            assert_eq!(b.sort(&team), 999);
            check(&b, &keys, 999);
            // Scrambled: the team gives up and the radix sort takes over.
            let keys: Vec<f32> = (0..1000u32).map(|i| ((i * 7919) % 1000) as f32).collect();
            let mut b = boxes(&keys);
            assert_eq!(b.sort(&team), 1000);
            check(&b, &keys, 1000);
            // Fewer boxes than members.
            let keys = [2.0, 1.0];
            let mut b = boxes(&keys);
            assert_eq!(b.sort(&team), 2);
            check(&b, &keys, 2);
        }
    }
}
