//! The boxes in sorted order: by their least value along the sweep
//! direction, as parallel arrays of keys, packed hulls and ids, kept from
//! step to step.
//!
//! Lines move little in a step, so last step's order is nearly this step's:
//! hulls are made in last step's order, and an insertion sort in place
//! finishes in about one pass with a few short moves. When the order has
//! changed a lot (the first step, a new sweep direction, a scene flying
//! apart) the insertion sort stops after a budget of moves and a radix
//! sort does the whole job instead.

use super::hull::{Packed, NO_KEY};
use crate::team::{self, Team};
use std::sync::atomic::{AtomicBool, Ordering};

/// Moves an insertion sort may make per box before it gives way to a
/// radix sort of keys and slots and one gather of the boxes. (Going to
/// the radix sort at once for a while after it was needed, and from two
/// moves a box, gained nothing on `smalllines`, whose boxes overtake each
/// other most: 1.10x and 0.99x without it, two threads and one; medians
/// of 7 and 5 interleaved rounds.)
const MOVES_PER_BOX: usize = 8;

/// Boxes as parallel arrays, followed by one sentinel entry (key
/// [`NO_KEY`]) so that a scan always stops.
#[derive(Debug, Default)]
pub(crate) struct Boxes {
    /// Least value along the sweep direction, or [`NO_KEY`].
    pub keys: Vec<f32>,
    /// Packed hull (meaningless where the key is [`NO_KEY`]).
    pub hulls: Vec<Packed>,
    /// Line id.
    pub ids: Vec<u32>,
    /// Spare arrays for the gather after a radix sort.
    spare: Option<Box<Boxes>>,
    /// Keys and slots, for the radix sort.
    keyed: Vec<(f32, u32)>,
}

impl Boxes {
    /// Resets to the ids `0..n`, in that order, with room for their hulls.
    pub(crate) fn reset(&mut self, n: usize) {
        self.ids.clear();
        self.ids.extend(0..n as u32);
        self.ids.push(u32::MAX);
        self.keys.clear();
        self.keys.resize(n + 1, NO_KEY);
        self.hulls.clear();
        self.hulls.resize(n + 1, [0.0; 8]);
    }

    /// Boxes held, the sentinel not counted.
    pub(crate) fn len(&self) -> usize {
        self.ids.len().saturating_sub(1)
    }

    /// Sorts the boxes by key (ties in any order: the sweep tests tied
    /// boxes both ways round), the sentinel staying last, sharing the work
    /// with `team`. Keys are never NaN. Returns the number
    /// of boxes with a real key, which now come first.
    pub(crate) fn sort(&mut self, team: &Team) -> usize {
        let n = self.len();
        if !self.insertion_sort_shared(n, MOVES_PER_BOX * n, team) {
            self.sort_by_radix(n);
        }
        self.keys[..n].partition_point(|&k| k != NO_KEY)
    }

    /// The first `n` keys, hulls and ids.
    fn arrays(&mut self, n: usize) -> (&mut [f32], &mut [Packed], &mut [u32]) {
        (
            &mut self.keys[..n],
            &mut self.hulls[..n],
            &mut self.ids[..n],
        )
    }

    /// Insertion sort of the first `n` boxes shared with `team`: each
    /// member sorts its share of the order in place (the boxes it made the
    /// hulls of, still in its cache), then the few boxes that belong before
    /// the start of their share are moved there on this thread. Gives up
    /// after about `budget` moves (leaving the boxes permuted but
    /// unsorted); returns whether it finished.
    fn insertion_sort_shared(&mut self, n: usize, budget: usize, team: &Team) -> bool {
        let threads = team.threads();
        let (keys, hulls, ids) = self.arrays(n);
        let (keys, hulls, ids) = (
            team::shares_mut(keys, threads),
            team::shares_mut(hulls, threads),
            team::shares_mut(ids, threads),
        );
        let sorted = AtomicBool::new(true);
        team.run(&|k| {
            let (mut keys, mut hulls, mut ids) = (
                keys[k].lock().expect("a share"),
                hulls[k].lock().expect("a share"),
                ids[k].lock().expect("a share"),
            );
            if insert(
                (&mut keys, &mut hulls, &mut ids),
                1,
                budget / threads,
                false,
            )
            .is_none()
            {
                sorted.store(false, Ordering::Relaxed);
            }
        });
        if !sorted.load(Ordering::Relaxed) {
            return false;
        }
        let mut budget = budget;
        for k in 1..threads {
            let start = team::share(n, threads, k).start;
            if start == 0 || start >= n {
                continue;
            }
            match insert(self.arrays(n), start, budget, true) {
                Some(moves) => budget -= moves,
                None => return false,
            }
        }
        true
    }

    /// Sorts the first `n` boxes' keys and slots by radix, then gathers
    /// the boxes in that order.
    fn sort_by_radix(&mut self, n: usize) {
        self.keyed.clear();
        self.keyed.extend(
            self.keys[..n]
                .iter()
                .enumerate()
                .map(|(k, &key)| (key, k as u32)),
        );
        radsort::sort_by_key(&mut self.keyed, |k| k.0);
        self.gather();
    }

    /// Puts the boxes in the order of `keyed`.
    fn gather(&mut self) {
        let mut spare = self.spare.take().unwrap_or_default();
        spare.keys.clear();
        spare.hulls.clear();
        spare.ids.clear();
        spare.keys.extend(self.keyed.iter().map(|k| k.0));
        spare
            .hulls
            .extend(self.keyed.iter().map(|k| self.hulls[k.1 as usize]));
        spare
            .ids
            .extend(self.keyed.iter().map(|k| self.ids[k.1 as usize]));
        spare.keys.push(NO_KEY);
        spare.hulls.push([0.0; 8]);
        spare.ids.push(u32::MAX);
        std::mem::swap(&mut self.keys, &mut spare.keys);
        std::mem::swap(&mut self.hulls, &mut spare.hulls);
        std::mem::swap(&mut self.ids, &mut spare.ids);
        self.spare = Some(spare);
    }
}

/// Insertion sort of the boxes from `from` on into the sorted boxes
/// before them, giving up after `budget` moves (leaving them permuted but
/// unsorted). With `until_in_place`, the boxes from `from` on are sorted
/// already and it stops at the first that needs no move. Returns the moves
/// made, if it finished.
pub(crate) fn insert(
    (keys, hulls, ids): (&mut [f32], &mut [Packed], &mut [u32]),
    from: usize,
    mut budget: usize,
    until_in_place: bool,
) -> Option<usize> {
    let mut moves = 0;
    for i in from.max(1)..keys.len() {
        let key = keys[i];
        if keys[i - 1] <= key {
            if until_in_place {
                break;
            }
            continue;
        }
        let (hull, id) = (hulls[i], ids[i]);
        let mut j = i;
        while j > 0 && keys[j - 1] > key {
            keys[j] = keys[j - 1];
            hulls[j] = hulls[j - 1];
            ids[j] = ids[j - 1];
            j -= 1;
        }
        keys[j] = key;
        hulls[j] = hull;
        ids[j] = id;
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
        assert_eq!(b.ids[n], u32::MAX);
        for k in 0..n {
            // Each box kept its hull and id together.
            assert_eq!(b.keys[k], keys[b.ids[k] as usize]);
            assert!(b.hulls[k][0] == b.keys[k] || b.keys[k] == NO_KEY);
        }
        let mut ids = b.ids[..n].to_vec();
        ids.sort_unstable();
        assert_eq!(ids, (0..n as u32).collect::<Vec<_>>());
        assert_eq!(b.keys[..n].partition_point(|&k| k != NO_KEY), boxed);
    }

    #[test]
    fn nearly_sorted_boxes_are_insertion_sorted() {
        let mut keys: Vec<f32> = (0..1000).map(|i| i as f32).collect();
        keys.swap(10, 11);
        keys.swap(500, 503);
        keys[7] = NO_KEY;
        let mut b = boxes(&keys);
        let n = keys.len();
        assert!(insert(b.arrays(n), 1, 1000, false).is_some());
        let mut b = boxes(&keys);
        assert_eq!(b.sort(&Team::solo()), 999);
        check(&b, &keys, 999);
    }

    #[test]
    fn scrambled_boxes_fall_back_to_radix() {
        let mut keys: Vec<f32> = (0..1000u32)
            .map(|i| ((i * 7919) % 1000) as f32 - 500.0)
            .collect();
        keys.extend([f32::NEG_INFINITY, -0.0, 0.0, NO_KEY]);
        let mut b = boxes(&keys);
        let n = keys.len();
        assert!(insert(b.arrays(n), 1, 8 * n, false).is_none());
        let mut b = boxes(&keys);
        assert_eq!(b.sort(&Team::solo()), keys.len() - 1);
        check(&b, &keys, keys.len() - 1);
        // Sorting again (now in order) keeps it so.
        assert_eq!(b.sort(&Team::solo()), keys.len() - 1);
        check(&b, &keys, keys.len() - 1);
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
