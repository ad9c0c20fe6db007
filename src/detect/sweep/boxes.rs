//! Boxes as parallel arrays (keys, packed hulls, slots), which the sweep
//! reads a column at a time: views of them, a list that grows, and their
//! sort by radix.

use super::hull::Packed;
use crate::team;
use std::ops::Range;
use std::sync::Mutex;

/// Boxes in parallel slices: each box's key, packed hull and id.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BoxSlice<'a> {
    pub keys: &'a [f32],
    pub hulls: &'a [Packed],
    pub slots: &'a [u32],
}

impl<'a> BoxSlice<'a> {
    pub(crate) fn new(keys: &'a [f32], hulls: &'a [Packed], slots: &'a [u32]) -> Self {
        Self { keys, hulls, slots }
    }

    pub(crate) fn len(&self) -> usize {
        self.keys.len()
    }

    /// The boxes `r`.
    pub(crate) fn at(self, r: Range<usize>) -> Self {
        Self::new(
            &self.keys[r.clone()],
            &self.hulls[r.clone()],
            &self.slots[r],
        )
    }
}

/// A [`BoxSlice`] to write.
#[derive(Debug, Default)]
pub(crate) struct BoxSliceMut<'a> {
    pub keys: &'a mut [f32],
    pub hulls: &'a mut [Packed],
    pub slots: &'a mut [u32],
}

impl<'a> BoxSliceMut<'a> {
    pub(crate) fn new(keys: &'a mut [f32], hulls: &'a mut [Packed], slots: &'a mut [u32]) -> Self {
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
    /// each behind its own lock (see [`team::shares_mut`]).
    pub(crate) fn shares(self, parts: usize) -> Vec<Mutex<Self>> {
        let n = self.len();
        let mut rest = self;
        let mut cut = |k| {
            let (head, tail) = std::mem::take(&mut rest).split_at(team::share(n, parts, k).len());
            rest = tail;
            Mutex::new(head)
        };
        (0..parts.max(1)).map(&mut cut).collect()
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
    pub slots: Vec<u32>,
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
    pub(crate) fn push(&mut self, key: f32, hull: Packed, id: u32, end: u32) {
        self.keys.push(key);
        self.hulls.push(hull);
        self.slots.push(id);
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
        self.slots.resize(len, 0);
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
        BoxSlice::new(
            &self.keys[r.clone()],
            &self.hulls[r.clone()],
            &self.slots[r],
        )
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
pub(crate) fn radix_order(keys: &[f32], order: &mut Vec<(f32, u32)>) {
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
