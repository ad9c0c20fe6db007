//! The boxes in sorted order: by their key, as parallel arrays kept from
//! step to step. Lines move little in a step, so boxes made in last step's
//! order are nearly sorted and an insertion sort in place finishes in about
//! one pass; when the order has changed a lot (the first step, a new sweep
//! direction, a scene flying apart) it stops after a budget of moves and a
//! radix sort does the job instead.

use super::boxes::{BoxList, BoxSlice, BoxSliceMut};
use super::hull::{Packed, NO_KEY};
use crate::team::{self, Team};
use std::sync::atomic::{AtomicBool, Ordering};

/// Moves an insertion sort may make per box before it gives way to a
/// radix sort. (Going to the radix sort at once for a while after it was
/// needed, and from two moves a box, gained nothing on `smalllines`, whose
/// boxes overtake each other most.)
pub(crate) const MOVES_PER_BOX: usize = 8;

/// Boxes as parallel arrays, followed by one sentinel entry (key
/// [`NO_KEY`]) so that a scan always stops.
#[derive(Debug, Default)]
pub(crate) struct Boxes {
    /// Least value along the sweep direction, or [`NO_KEY`].
    pub keys: Vec<f32>,
    /// Packed hull (meaningless where the key is [`NO_KEY`]).
    pub hulls: Vec<Packed>,
    /// Line id.
    pub slots: Vec<u32>,
    /// Keys and places, and spare arrays, for the radix sort.
    keyed: Vec<(f32, u32)>,
    spare: BoxList,
}

impl Boxes {
    /// Resets to the slots `0..n`, in that order, with room for their hulls.
    pub(crate) fn reset(&mut self, n: usize) {
        self.slots.clear();
        self.slots.extend(0..n as u32);
        self.slots.push(u32::MAX);
        self.keys.clear();
        self.keys.resize(n + 1, NO_KEY);
        self.hulls.clear();
        self.hulls.resize(n + 1, [0.0; 8]);
    }

    /// Makes room for `n` boxes and the sentinel.
    pub(crate) fn set_len(&mut self, n: usize) {
        self.keys.resize(n + 1, NO_KEY);
        self.hulls.resize(n + 1, [0.0; 8]);
        self.slots.resize(n + 1, u32::MAX);
        (self.keys[n], self.slots[n]) = (NO_KEY, u32::MAX);
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
            let share = &mut *shares[k].lock().expect("a share");
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
/// made, if it finished.
pub(crate) fn insert(
    b: BoxSliceMut,
    from: usize,
    mut budget: usize,
    until_in_place: bool,
) -> Option<usize> {
    let BoxSliceMut { keys, hulls, slots } = b;
    let mut moves = 0;
    for i in from.max(1)..keys.len() {
        let key = keys[i];
        if keys[i - 1] <= key {
            if until_in_place {
                break;
            }
            continue;
        }
        let (hull, id) = (hulls[i], slots[i]);
        let mut j = i;
        while j > 0 && keys[j - 1] > key {
            keys[j] = keys[j - 1];
            hulls[j] = hulls[j - 1];
            slots[j] = slots[j - 1];
            j -= 1;
        }
        keys[j] = key;
        hulls[j] = hull;
        slots[j] = id;
        let moved = i - j;
        if moved > budget {
            return None;
        }
        budget -= moved;
        moves += moved;
    }
    Some(moves)
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
        assert_eq!(b.slots[n], u32::MAX);
        for k in 0..n {
            // Each box kept its hull and id together.
            assert_eq!(b.keys[k], keys[b.slots[k] as usize]);
            assert!(b.hulls[k][0] == b.keys[k] || b.keys[k] == NO_KEY);
        }
        let mut slots = b.slots[..n].to_vec();
        slots.sort_unstable();
        assert_eq!(slots, (0..n as u32).collect::<Vec<_>>());
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
