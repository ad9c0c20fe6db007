//! Lines stored in the order the detector reads them, rather than by id.
//!
//! The sweep reads lines in its own order: it makes their hulls box by box
//! in last step's layout, and each exact test reads two neighbours in that
//! layout. Stored by id, every one of those reads lands anywhere among the
//! lines; on two threads, half of them land on lines the other thread
//! wrote last. So when the detector asks ([`Detector::hand_over`]),
//! the world stores the lines in its order as it moves them: each line is
//! copied to its place in that order and moved there, in one pass split
//! into contiguous shares, one per thread, and next step each thread makes
//! the hulls of the lines it moved. The sweep asks every few steps; in
//! between, the lines move where they are, still nearly in its order.
//!
//! A line's place is its *slot*; `ids[slot]` is its id. The detector is
//! handed the lines by slot with their ids and names each event's lines by
//! slot, the one with the lower id first; the events are resolved on the
//! lines by slot, those that share a line with another in the order of
//! their ids (the contract's order of resolution) and the rest, which
//! commute with every other, as found
//! ([`crate::response::Resolver::resolve_found`]). The results are the same
//! bits in any order: moving and the wall check touch one line at a time,
//! and each line's events are resolved in the same order.
//!
//! The world always holds its lines this way: until the detector first
//! asks, each slot holds the line of that id.
//!
//! [`Detector::hand_over`]: crate::detect::Detector::hand_over

use crate::detect::Stored;
use crate::index::{Index, LineId, Slot};
use crate::line::Line;
use crate::motion::advance_and_bounce;
use crate::narrow::Event;
use crate::team::{self, Team};
use std::borrow::Cow;

/// Lines copied and moved at a time (6 KB of them).
const BLOCK: usize = 128;

/// The slots' ids and the buffers that reorder the lines.
#[derive(Debug, Default)]
pub(crate) struct Storage {
    /// The id of the line in each slot.
    ids: Vec<LineId>,
    /// The next order's lines and ids, exchanged with the current ones.
    spare: Vec<Line>,
    spare_ids: Vec<LineId>,
    /// Whether the lines have left id order (a detector's order was
    /// applied).
    reordered: bool,
}

impl Storage {
    /// Lines stored in id order: slot `k` holds line `k`, `n` in all.
    pub(crate) fn new(n: usize) -> Self {
        Storage {
            ids: (0..n as u32).map(LineId).collect(),
            ..Storage::default()
        }
    }

    /// The id of the line in each slot.
    pub(crate) fn ids(&self) -> &[LineId] {
        &self.ids
    }

    /// Whether the lines are stored in a detector's order rather than by
    /// id.
    pub(crate) fn reordered(&self) -> bool {
        self.reordered
    }

    /// What the detector is handed: `lines`, stored here, with their ids.
    pub(crate) fn stored<'a>(&'a self, lines: &'a [Line]) -> Stored<'a> {
        match self.reordered {
            true => Stored::by_slot(lines, &self.ids),
            false => Stored::by_id(lines),
        }
    }

    /// Appends `found`, events by slot, to `events`, naming the lines by
    /// id, in the order found.
    pub(crate) fn name_by_id(&self, found: &[Event<Slot>], events: &mut Vec<Event>) {
        let ids = &self.ids;
        events.extend(found.iter().map(|e| e.named(|s| ids[s.at()])));
    }

    /// Moves every line and bounces it off the walls, storing it in the
    /// order `order` gives by slot (`order[k]` is the slot of the line to
    /// store at `k`), shared among `team` if there is one. Returns the
    /// lines that hit a wall.
    ///
    /// # Panics
    /// If `order` is not as long as `lines`; a slot repeated or left out
    /// in `order` would lose a line, which a debug build checks.
    pub(crate) fn advance_in_order(
        &mut self,
        lines: &mut Vec<Line>,
        order: &[Slot],
        team: Option<&Team>,
    ) -> u64 {
        let n = lines.len();
        assert_eq!(order.len(), n, "one slot for every line");
        debug_assert!(is_permutation(order), "every slot once");
        self.spare.resize(n, Line::default());
        self.spare_ids.resize(n, LineId::default());
        let (from, from_ids) = (&lines[..], &self.ids[..]);
        // A block at a time, moved while its copies are at hand.
        let fill = |order: &[Slot], to: &mut [Line], to_ids: &mut [LineId]| {
            let mut hits = 0;
            let blocks = order.chunks(BLOCK).zip(to.chunks_mut(BLOCK));
            for ((order, to), to_ids) in blocks.zip(to_ids.chunks_mut(BLOCK)) {
                for ((&slot, line), id) in order.iter().zip(&mut *to).zip(to_ids) {
                    *line = from[slot.at()];
                    *id = from_ids[slot.at()];
                }
                hits += advance_and_bounce(to);
            }
            hits
        };
        let hits = match team {
            Some(team) => {
                let threads = team.threads();
                let to = team::split_mut(&mut self.spare, threads);
                let to_ids = team::split_mut(&mut self.spare_ids, threads);
                team.run_sum(&|k| {
                    let order = &order[team::share(n, threads, k)];
                    fill(order, to.take(k), to_ids.take(k))
                })
            }
            None => fill(order, &mut self.spare, &mut self.spare_ids),
        };
        std::mem::swap(lines, &mut self.spare);
        std::mem::swap(&mut self.ids, &mut self.spare_ids);
        self.reordered = true;
        hits
    }

    /// The lines, stored by slot in `lines`, by id: `lines` themselves
    /// while they are in id order.
    pub(crate) fn by_id<'a>(&self, lines: &'a [Line]) -> Cow<'a, [Line]> {
        if !self.reordered {
            return Cow::Borrowed(lines);
        }
        let mut out = vec![Line::default(); lines.len()];
        for (line, &id) in lines.iter().zip(&self.ids) {
            out[id.at()] = *line;
        }
        Cow::Owned(out)
    }
}

/// Whether `order` holds each slot of `0..order.len()` once.
fn is_permutation(order: &[Slot]) -> bool {
    let mut seen = vec![false; order.len()];
    order
        .iter()
        .all(|&k| !std::mem::replace(&mut seen[k.at()], true))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::narrow::IntersectionKind;
    use crate::test_util::line;

    fn lines(n: usize) -> Vec<Line> {
        (0..n)
            .map(|k| {
                let x = k as f64 / n as f64;
                line((x, 0.5), (x + 0.001, 0.6), (0.01, -0.02))
            })
            .collect()
    }

    #[test]
    fn lines_stored_in_any_order_move_as_by_id_and_read_back_by_id() {
        let n = 5000;
        let start = lines(n);
        let mut by_id = start.clone();
        let expected_hits = advance_and_bounce(&mut by_id);
        let teams = [
            None,
            Some(Team::new(2).unwrap()),
            Some(Team::new(3).unwrap()),
        ];
        for team in &teams {
            let mut stored = start.clone();
            let mut storage = Storage::new(n);
            // Two reorderings in a row: reversed, then odd slots first.
            assert!(!storage.reordered());
            let order: Vec<Slot> = (0..n as u32).rev().map(Slot).collect();
            let hits = storage.advance_in_order(&mut stored, &order, team.as_ref());
            assert_eq!(hits, expected_hits);
            assert!(storage.reordered());
            assert_eq!(storage.ids()[0], LineId(n as u32 - 1));
            assert_eq!(storage.by_id(&stored)[..], by_id[..]);
            let order: Vec<Slot> = (1..n as u32)
                .step_by(2)
                .chain((0..n as u32).step_by(2))
                .map(Slot)
                .collect();
            storage.advance_in_order(&mut stored, &order, team.as_ref());
            let mut twice = by_id.clone();
            advance_and_bounce(&mut twice);
            assert_eq!(storage.by_id(&stored)[..], twice[..]);
            for (slot, &id) in storage.ids().iter().enumerate() {
                assert_eq!(stored[slot], twice[id.at()]);
            }
        }
    }

    #[test]
    fn events_by_slot_are_named_by_id_and_resolved_on_their_slots() {
        let start = lines(6);
        let mut stored = start.clone();
        let mut storage = Storage::new(6);
        let reversed = [5, 4, 3, 2, 1, 0].map(Slot);
        storage.advance_in_order(&mut stored, &reversed, None);
        let mut by_id = start;
        advance_and_bounce(&mut by_id);
        // Slot k now holds line 5 - k; events name the lower id first.
        let kind = IntersectionKind::L1WithL2;
        let e = |first, second| Event {
            first,
            second,
            kind,
        };
        let found = [e(1, 0), e(4, 2), e(5, 1)].map(|e| e.named(|&s| Slot(s)));
        let mut events = Vec::new();
        storage.name_by_id(&found, &mut events);
        let want = [e(4, 5), e(1, 3), e(0, 4)].map(|e| e.named(|&id| LineId(id)));
        assert_eq!(events, want);
        // Line 4 meets 0 and then 5, in the order of their ids.
        let mut resolver = crate::response::Resolver::default();
        resolver.resolve_found(&mut stored, &found, &events, 1, None);
        let mut sorted = events.clone();
        sorted.sort_unstable_by_key(Event::order_key);
        for e in &sorted {
            crate::response::resolve(&mut by_id, e);
        }
        assert_eq!(storage.by_id(&stored)[..], by_id[..]);
    }
}
