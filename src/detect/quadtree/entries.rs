//! The tree's entries, one a line, kept in key order from step to step:
//! lines hardly move in a step, so last step's order is nearly sorted, and
//! an insertion sort, or taking out the few that moved and merging them
//! back, fixes it in close to linear time (a full sort only when lines
//! jump far).

use super::grid::{Cells, LEVEL_MASK};
use crate::team::{self, Parts, Team};

/// A line in the tree: its key and its cells.
#[derive(Clone, Copy, Debug, Default)]
pub struct Entry {
    /// Morton key of the line's node, then its level.
    pub key: u64,
    /// The line's cells.
    pub cells: Cells,
}

impl Entry {
    #[inline]
    pub(super) fn level(&self) -> u32 {
        (self.key & LEVEL_MASK) as u32
    }
}

/// Sorts entries by key by insertion, fast when they are nearly sorted
/// already. Gives up, returning false with the entries in some order, once
/// too many have had to move far; the caller then sorts in full.
pub fn sort_nearly_sorted(entries: &mut [Entry]) -> bool {
    let mut budget = 8 * entries.len() + 64;
    for i in 1..entries.len() {
        let e = entries[i];
        let mut j = i;
        while j > 0 && entries[j - 1].key > e.key {
            entries[j] = entries[j - 1];
            j -= 1;
        }
        entries[j] = e;
        budget = budget.saturating_sub(i - j);
        if budget == 0 {
            return false;
        }
    }
    true
}

/// One task's share of a sort: the entries it keeps in place (in order),
/// and those it moves aside.
#[derive(Debug, Default)]
pub(super) struct SortRun {
    kept: Vec<Entry>,
    movers: Vec<Entry>,
}

/// Merges `kept` and `movers`, both sorted, into `out`, which is as long
/// as both. Movers are few, so the kept entries between them are copied
/// in blocks.
fn merge_into(mut kept: &[Entry], movers: &[Entry], mut out: &mut [Entry]) {
    for m in movers {
        let below = kept.iter().take_while(|e| e.key <= m.key).count();
        let (block, rest) = std::mem::take(&mut out).split_at_mut(below + 1);
        block[..below].copy_from_slice(&kept[..below]);
        block[below] = *m;
        kept = &kept[below..];
        out = rest;
    }
    out.copy_from_slice(kept);
}

/// Up to this many descents, [`Entries::sort`] tries insertion first.
const INSERTION_MAX: usize = 64;

/// A run of a tree's entries being set in place before a sort, each one
/// flagged if its key is not the one at its place before (which the sort
/// uses to keep the others where they are).
pub struct Refill<'a> {
    entries: &'a mut [Entry],
    changed: &'a mut [bool],
    /// Entries from this index on are new: they had no place before.
    old: usize,
}

impl<'a> Refill<'a> {
    /// Sets the run's `k`-th entry.
    #[inline]
    pub fn set(&mut self, k: usize, entry: Entry) {
        self.changed[k] = k >= self.old || entry.key != self.entries[k].key;
        self.entries[k] = entry;
    }

    /// Splits the run into runs of `size` entries (the last one shorter).
    pub fn chunks(self, size: usize) -> Vec<Refill<'a>> {
        let size = size.max(1);
        self.entries
            .chunks_mut(size)
            .zip(self.changed.chunks_mut(size))
            .enumerate()
            .map(|(c, (entries, changed))| Refill {
                entries,
                changed,
                old: self.old.saturating_sub(c * size),
            })
            .collect()
    }
}

/// The entries in key order, and the buffers that keep them so.
#[derive(Debug, Default)]
pub struct Entries {
    /// The lines' entries; [`Entries::sort`] puts them in key order.
    pub list: Vec<Entry>,
    /// Whether each entry's key may differ from that of the entry at its
    /// place when the entries were last sorted (see [`Refill`]).
    changed: Vec<bool>,
    /// Buffers of [`Entries::sort`].
    runs: Vec<SortRun>,
    movers: Vec<Entry>,
}

impl Entries {
    /// The `n` entries, to be set one by one in place (all of them, as the
    /// lines are filled into their slots) before [`Entries::sort`].
    pub fn refill_in_place(&mut self, n: usize) -> Refill<'_> {
        let old = self.list.len();
        self.list.resize(n, Entry::default());
        self.changed.resize(n, true);
        Refill {
            entries: &mut self.list,
            changed: &mut self.changed,
            old,
        }
    }

    /// Puts the entries in key order. Most lines keep their key from one
    /// step to the next, so the entries are mostly in order already: with
    /// few out of place they are fixed by insertion; with more, the ones out
    /// of place are taken out, sorted on their own and merged back, in time
    /// close to linear; only a scramble gets a full sort. Given a `team`,
    /// the passes over every entry are shared among it.
    pub fn sort(&mut self, team: Option<&Team>) {
        let n = self.list.len();
        let descent = |w: &[Entry]| w[1].key < w[0].key;
        let descents = match team {
            Some(team) => {
                let list = &self.list;
                let threads = team.threads();
                team.run_sum(&|k| {
                    let mine = team::share(n.saturating_sub(1), threads, k);
                    let windows = list[mine.start..(mine.end + 1).min(n)].windows(2);
                    windows.filter(|w| descent(w)).count() as u64
                }) as usize
            }
            None => self.list.windows(2).filter(|w| descent(w)).count(),
        };
        if descents == 0 {
            return;
        }
        if descents <= INSERTION_MAX && sort_nearly_sorted(&mut self.list) {
            return;
        }
        if descents <= n / 8 {
            self.merge_out_of_place(team);
            return;
        }
        // A scramble (the first step, or lines thrown far): rare enough
        // to sort on this thread.
        radsort::sort_by_key(&mut self.list, |e| e.key);
    }

    /// Takes the entries out of place out of the way, sorts them and merges
    /// them back. Each run of entries (one per task) keeps an ascending
    /// subsequence of its unchanged entries (see [`Refill`]; when the
    /// changes are not known, of those not above their successor), and
    /// moves the rest aside; then each run drops the head of its kept
    /// entries that is below the previous run's last, so that the kept
    /// entries of all runs, in turn, are in order. The entries moved aside
    /// are sorted and merged with the kept ones, each run's part on its own.
    fn merge_out_of_place(&mut self, team: Option<&Team>) {
        let n = self.list.len();
        let tasks = team.map_or(1, |team| 4 * team.threads());
        let chunk = n.div_ceil(tasks).max(1);
        let runs = n.div_ceil(chunk);
        self.runs.resize_with(runs, SortRun::default);
        let (entries, changed) = (&self.list, &self.changed);
        let known = changed.len() == n;
        let split = |first: usize, part: &[Entry], run: &mut SortRun| {
            run.kept.clear();
            run.movers.clear();
            let mut last = 0;
            for (k, e) in part.iter().enumerate() {
                let i = first + k;
                let stays = if known {
                    !changed[i]
                } else {
                    entries.get(i + 1).is_none_or(|next| e.key <= next.key)
                };
                if stays && e.key >= last {
                    run.kept.push(*e);
                    last = e.key;
                } else {
                    run.movers.push(*e);
                }
            }
        };
        let runs = &mut self.runs[..runs];
        if let Some(team) = team {
            let pieces = runs.len();
            let parts = Parts::new(runs.iter_mut());
            team.run_pieces(pieces, &|c| {
                let part = &entries[c * chunk..((c + 1) * chunk).min(n)];
                split(c * chunk, part, parts.take(c));
            });
        } else {
            for (c, (part, run)) in entries.chunks(chunk).zip(runs.iter_mut()).enumerate() {
                split(c * chunk, part, run);
            }
        }

        // Join the runs' kept entries into one ascending sequence, and
        // gather everything else.
        let movers = &mut self.movers;
        movers.clear();
        let mut last = 0;
        for run in runs.iter_mut() {
            let below = run.kept.partition_point(|e| e.key < last);
            movers.extend(run.kept.drain(..below));
            movers.extend_from_slice(&run.movers);
            if let Some(e) = run.kept.last() {
                last = e.key;
            }
        }
        radsort::sort_by_key(movers, |e| e.key);

        // Each run's part of the output: its kept entries and the movers
        // below the next run's first kept entry.
        let mut parts: Vec<(&[Entry], &[Entry], &mut [Entry])> = Vec::with_capacity(runs.len());
        let mut out: &mut [Entry] = &mut self.list;
        let mut rest: &[Entry] = movers;
        let nonempty: Vec<&SortRun> = runs.iter().filter(|r| !r.kept.is_empty()).collect();
        for (k, run) in nonempty.iter().enumerate() {
            let take = match nonempty.get(k + 1) {
                Some(next) => rest.partition_point(|m| m.key < next.kept[0].key),
                None => rest.len(),
            };
            let (mine, later) = rest.split_at(take);
            let (part, tail) = std::mem::take(&mut out).split_at_mut(run.kept.len() + take);
            parts.push((&run.kept, mine, part));
            rest = later;
            out = tail;
        }
        if nonempty.is_empty() {
            out.copy_from_slice(rest);
        }
        let merge =
            |(kept, movers, out): (&[Entry], &[Entry], &mut [Entry])| merge_into(kept, movers, out);
        match team {
            Some(team) => {
                let pieces = parts.len();
                let parts = Parts::new(parts);
                team.run_pieces(pieces, &|k| merge(parts.take(k)));
            }
            None => parts.into_iter().for_each(merge),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nearly_sorted_and_scrambled_inputs_both_sort() {
        let mk = |k: u64| Entry {
            key: k,
            cells: Cells::default(),
        };
        let mut near: Vec<Entry> = (0..1000u64).map(|k| mk(k ^ 1)).collect();
        assert!(sort_nearly_sorted(&mut near));
        assert!(near.windows(2).all(|w| w[0].key <= w[1].key));
        // One entry in ten jumped far, both ways: 100 descents, so
        // the merge path.
        let jumped = |k: u64| match k % 20 {
            3 => mk(k * 7 % 1000),
            7 => mk(1000 - k),
            _ => mk(k),
        };
        let mut expected: Vec<u64> = (0..1000u64).map(|k| jumped(k).key).collect();
        expected.sort_unstable();
        let mut entries = Entries {
            list: (0..1000u64).map(jumped).collect(),
            ..Entries::default()
        };
        entries.sort(None);
        assert_eq!(
            entries.list.iter().map(|e| e.key).collect::<Vec<_>>(),
            expected
        );
        entries.list = (0..1000u64).map(jumped).collect();
        entries.sort(Some(&Team::new(3).unwrap()));
        assert_eq!(
            entries.list.iter().map(|e| e.key).collect::<Vec<_>>(),
            expected
        );
        let mut reversed: Vec<Entry> = (0..1000u64).rev().map(mk).collect();
        assert!(!sort_nearly_sorted(&mut reversed));
        let mut entries = Entries {
            list: reversed,
            ..Entries::default()
        };
        entries.sort(None);
        assert!(entries.list.windows(2).all(|w| w[0].key <= w[1].key));
    }

    /// Sets the entries to `make(0..n)` in place (in runs of
    /// `chunk` on `team`, if given), as the detector does, and sorts them.
    fn refill(
        entries: &mut Entries,
        n: usize,
        team: Option<(&Team, usize)>,
        make: impl Fn(usize) -> Entry + Sync,
    ) {
        let fill = |first: usize, mut run: Refill<'_>| {
            for k in 0..run.entries.len() {
                run.set(k, make(first + k));
            }
        };
        match team {
            Some((team, chunk)) => {
                let runs = entries.refill_in_place(n).chunks(chunk);
                let pieces = runs.len();
                let runs = Parts::new(runs);
                team.run_pieces(pieces, &|c| fill(c * chunk, runs.take(c)));
            }
            None => fill(0, entries.refill_in_place(n)),
        }
        entries.sort(team.map(|(team, _)| team));
    }

    proptest::proptest! {
        /// Sorted keys, some of them changed (a few far, most a little),
        /// refilled on one thread or several: the entries come out sorted
        /// and are the same entries.
        #[test]
        fn refilling_sorts_whatever_changed(
            base in proptest::collection::vec(0u64..400, 0..3000),
            changes in proptest::collection::vec((0usize..3000, 0u64..400), 0..400),
            added in proptest::collection::vec(0u64..400, 0..200),
            threads in 1usize..4,
        ) {
            let mut keys = base;
            keys.sort_unstable();
            let mk = |k: u64, id: usize| Entry {
                key: k,
                cells: Cells { id: id as u32, ..Cells::default() },
            };
            let mut entries = Entries::default();
            refill(&mut entries, keys.len(), None, |i| mk(keys[i], i));
            for &(at, key) in &changes {
                if at < keys.len() {
                    keys[at] = key;
                }
            }
            // Lines added since the last refill have no place to keep.
            keys.extend(&added);
            let n = keys.len();
            let team = Team::new(threads).unwrap();
            let shared = (threads > 1).then_some((&team, 64));
            refill(&mut entries, n, shared, |i| mk(keys[i], i));
            let got: Vec<u64> = entries.list.iter().map(|e| e.key).collect();
            let mut expected = keys.clone();
            expected.sort_unstable();
            proptest::prop_assert_eq!(got, expected);
            let mut ids: Vec<u32> = entries.list.iter().map(|e| e.cells.id).collect();
            ids.sort_unstable();
            proptest::prop_assert!(ids.iter().enumerate().all(|(i, &id)| id as usize == i));
            for e in &entries.list {
                proptest::prop_assert_eq!(e.key, keys[e.cells.id as usize]);
            }
        }
    }
}
