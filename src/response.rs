//! Collision response: new velocities for the two lines of one event.

use crate::geometry::{crossing_point, Vec2};
use crate::index::{Index, Slot};
use crate::line::{read_ahead, Line, LARGE_SCENE, READ_AHEAD};
use crate::narrow::{Event, IntersectionKind};
use crate::schedule::Schedule;
use crate::team::{self, Team};
use std::mem::take;

/// Applies the response to one event. Only velocities change; positions are
/// read as they are at the start of the step.
#[inline]
pub fn resolve<I: Index>(lines: &mut [Line], event: &Event<I>) {
    let (i, j) = (event.first.at(), event.second.at());
    let (v1, v2) = respond(&lines[i], &lines[j], event.kind);
    lines[i].v = v1;
    lines[j].v = v2;
}

/// Resolves `events` one after another. In scenes larger than the cache,
/// the lines of the event [`READ_AHEAD`] places on are read ahead, as the
/// events' lines lie anywhere in memory.
fn resolve_each(lines: &mut [Line], events: &[Event<Slot>]) {
    resolve_each_in(lines, 0, lines.len(), events);
}

/// [`resolve_each`] on the lines from slot `first` on of a scene of `n`
/// lines, which `lines` holds (so that the line in slot `s` is at
/// `lines[s - first]`).
fn resolve_each_in(lines: &mut [Line], first: usize, n: usize, events: &[Event<Slot>]) {
    let ahead = n >= LARGE_SCENE;
    let first = first as u32;
    for (k, event) in events.iter().enumerate() {
        if let Some(next) = events.get(k + READ_AHEAD).filter(|_| ahead) {
            read_ahead(&lines[(next.first.0 - first) as usize]);
            read_ahead(&lines[(next.second.0 - first) as usize]);
        }
        let here = event.named(|s| Slot(s.0 - first));
        resolve(lines, &here);
    }
}

/// Events per task in a parallel wave.
const WAVE_CHUNK: usize = 256;

/// Resolves a step's events in order, on all threads when there are many.
///
/// Order matters only between events that share a line: the later one
/// must see the velocity the earlier one left. So the events are put in
/// *waves*: an event's wave is one past the last wave of any earlier event
/// on either of its lines. Events of one wave share no line, and each
/// line's events fall in ascending waves in their order, so resolving the
/// waves one after another, each in any order, leaves every line exactly
/// as resolving the events one by one would. Most events share no line
/// with any other and fall in the first wave.
#[derive(Debug, Default)]
pub struct Resolver {
    /// Per line: the last wave that touched it (zero for none; reset after
    /// each step).
    line_wave: Vec<u32>,
    /// Each event's wave.
    wave: Vec<u32>,
    /// Where each wave starts in `grouped`, by wave number.
    starts: Vec<usize>,
    /// The events grouped by wave, in order within each wave.
    grouped: Vec<Event<Slot>>,
    /// A wave's new velocities, by event.
    velocities: Vec<(Vec2, Vec2)>,
    /// Per line: how many of the step's events it takes part in, up to
    /// two (zero between steps), for [`Resolver::resolve_found`].
    shares: Vec<u8>,
    /// There, the events that share no line with another, and the others
    /// with their order key by id.
    free: Vec<Event<Slot>>,
    tied: Vec<(u64, Event<Slot>)>,
    /// There, with a team, the free events whose lines both lie in one
    /// member's share of the lines, by share; and the others.
    by_share: Vec<Vec<Event<Slot>>>,
    across: Vec<Event<Slot>>,
    /// Free events a step must have before a team shares them, if not
    /// [`Schedule::RESOLVE_FROM`] (tests share fewer).
    team_min: Option<usize>,
}

impl Resolver {
    /// Resolves `events` (sorted by [`Event::order_key`]) on `lines`. Given
    /// a `team`, a step of at least `grain` events is resolved in waves,
    /// those of at least a quarter of `grain` shared among the team.
    pub fn resolve_all(
        &mut self,
        lines: &mut [Line],
        events: &[Event<Slot>],
        grain: usize,
        team: Option<&Team>,
    ) {
        let Some(team) = team.filter(|_| events.len() >= grain.max(1)) else {
            resolve_each(lines, events);
            return;
        };
        self.group_by_wave(lines.len(), events);
        let grouped = take(&mut self.grouped);
        for w in 1..self.starts.len() - 1 {
            let wave = &grouped[self.starts[w]..self.starts[w + 1]];
            match wave.len() >= (grain / 4).max(1) {
                true => self.resolve_wave(team, lines, wave),
                false => resolve_each(lines, wave),
            }
        }
        self.grouped = grouped;
    }

    /// Resolves `wave`, events that share no line, in any order, on `team`:
    /// each piece works out the new velocities of a run of events, which
    /// are then set in turn.
    fn resolve_wave(&mut self, team: &Team, lines: &mut [Line], wave: &[Event<Slot>]) {
        self.velocities.resize(wave.len(), Default::default());
        let chunk = WAVE_CHUNK.max(wave.len().div_ceil(team::MAX_PIECES));
        let pieces = wave.len().div_ceil(chunk);
        let shared: &[Line] = lines;
        let outs = team::Parts::new(self.velocities[..wave.len()].chunks_mut(chunk));
        team.run_pieces(pieces, &|k| {
            let events = &wave[k * chunk..((k + 1) * chunk).min(wave.len())];
            // Copy the lines first, in a loop whose scattered reads can all
            // be in flight at once.
            let pairs: Vec<(Line, Line)> = (events.iter())
                .map(|e| (shared[e.first.at()], shared[e.second.at()]))
                .collect();
            for ((v, (l1, l2)), e) in outs.take(k).iter_mut().zip(&pairs).zip(events) {
                *v = respond(l1, l2, e.kind);
            }
        });
        for (e, &(v1, v2)) in wave.iter().zip(&self.velocities) {
            lines[e.first.at()].v = v1;
            lines[e.second.at()].v = v2;
        }
    }

    /// Resolves `events` as a detector found them, in any order, naming
    /// lines by place in `lines`; `by_id` holds the same events naming the
    /// lines by id. The tied events are resolved as
    /// [`Resolver::resolve_all`] resolves them, with `grain` and `team`.
    ///
    /// An event whose lines take part in no other event commutes with
    /// every other, so those (most) are resolved as found, at once, in the
    /// order of memory when the events come in the order the lines are
    /// stored. The others are put in the order of their ids and resolved
    /// after. Each line's events are thus applied in the contract's order,
    /// and the lines end bit for bit as resolving every event in id order
    /// would leave them, without a sort of every event or a read of the
    /// lines in the order of their ids.
    ///
    /// Given a `team`, the free events (when there are many) are resolved in place,
    /// each by the member whose share of the lines (as
    /// [`team::split_mut`] splits them) holds both its lines; the few
    /// whose lines lie in two shares after, on this thread.
    pub fn resolve_found(
        &mut self,
        lines: &mut [Line],
        events: &[Event<Slot>],
        by_id: &[Event],
        grain: usize,
        team: Option<&Team>,
    ) {
        debug_assert_eq!(events.len(), by_id.len());
        let shares = &mut self.shares;
        shares.resize(lines.len(), 0);
        for e in events {
            for line in [e.first, e.second] {
                let s = &mut shares[line.at()];
                *s = (*s + 1).min(2);
            }
        }
        let (mut free, mut tied) = (take(&mut self.free), take(&mut self.tied));
        free.clear();
        tied.clear();
        for (e, named) in events.iter().zip(by_id) {
            let (a, b) = (e.first.at(), e.second.at());
            if shares[a] == 2 || shares[b] == 2 {
                tied.push((named.order_key(), *e));
            } else {
                free.push(*e);
            }
        }
        for e in events {
            (shares[e.first.at()], shares[e.second.at()]) = (0, 0);
        }
        let shares = Schedule::resolution_shares(free.len(), self.team_min);
        match team {
            Some(team) if shares => self.resolve_by_share(team, lines, &free),
            _ => resolve_each(lines, &free),
        }
        // Pairs are unique, so an unstable sort gives the one sorted order.
        tied.sort_unstable_by_key(|t| t.0);
        // The free events' buffer, now for the tied ones in order.
        free.clear();
        free.extend(tied.iter().map(|t| t.1));
        self.resolve_all(lines, &free, grain, team);
        (self.free, self.tied) = (free, tied);
    }

    /// Resolves `free` events, which share no line, on `team`: see
    /// [`Resolver::resolve_found`].
    fn resolve_by_share(&mut self, team: &Team, lines: &mut [Line], free: &[Event<Slot>]) {
        let (n, threads) = (lines.len(), team.threads());
        let starts: Vec<usize> = (0..=threads).map(|k| n * k / threads).collect();
        debug_assert!((0..threads).all(|k| starts[k] == team::share(n, threads, k).start));
        let share_of = |line: u32| starts.partition_point(|&s| s <= line as usize) - 1;
        self.by_share.resize_with(threads, Vec::new);
        self.by_share.iter_mut().for_each(Vec::clear);
        self.across.clear();
        for e in free {
            let share = share_of(e.first.0);
            match share == share_of(e.second.0) {
                true => self.by_share[share].push(*e),
                false => self.across.push(*e),
            }
        }
        {
            let parts = team::split_mut(lines, threads);
            let by_share = &self.by_share;
            team.run(&|k| resolve_each_in(parts.take(k), starts[k], n, &by_share[k]));
        }
        resolve_each(lines, &self.across);
    }

    /// Sets `grouped` to the events by wave (and in order within each) and
    /// `starts[w]` to where wave `w` begins, for waves 1 and up; `starts`
    /// ends with the total.
    fn group_by_wave(&mut self, lines: usize, events: &[Event<Slot>]) {
        self.line_wave.resize(lines, 0);
        self.wave.clear();
        // Counts per wave, at index wave + 1, turned into starts below.
        self.starts.clear();
        self.starts.resize(2, 0);
        for e in events {
            let (a, b) = (e.first.at(), e.second.at());
            let w = 1 + self.line_wave[a].max(self.line_wave[b]);
            self.line_wave[a] = w;
            self.line_wave[b] = w;
            self.wave.push(w);
            let slot = w as usize + 1;
            if slot >= self.starts.len() {
                self.starts.resize(slot + 1, 0);
            }
            self.starts[slot] += 1;
        }
        for e in events {
            self.line_wave[e.first.at()] = 0;
            self.line_wave[e.second.at()] = 0;
        }
        for w in 1..self.starts.len() {
            self.starts[w] += self.starts[w - 1];
        }
        self.grouped.resize(events.len(), events[0]);
        let mut next = self.starts.clone();
        for (e, &w) in events.iter().zip(&self.wave) {
            self.grouped[next[w as usize]] = *e;
            next[w as usize] += 1;
        }
    }
}

/// The velocities `l1` and `l2` leave a collision of `kind` with (`l1` is
/// the line with the smaller id).
pub fn respond(l1: &Line, l2: &Line, kind: IntersectionKind) -> (Vec2, Vec2) {
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
    use crate::index::LineId;
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
            first: LineId(0),
            second: LineId(2),
            kind: IntersectionKind::L1WithL2,
        };
        resolve(&mut lines, &event);
        assert_eq!(lines[0].v, Vec2::new(0.0, -2.0));
        assert_eq!(lines[2].v, Vec2::new(0.0, 0.0));
        assert_eq!(lines[1].v, Vec2::new(0.0, 0.0));
    }

    fn gcd(a: u32, b: u32) -> u32 {
        if b == 0 {
            a
        } else {
            gcd(b, a % b)
        }
    }

    /// Lines from generated values, and events between them from pairs of
    /// numbers (taken modulo the lines) and a kind, in resolution order,
    /// each pair once.
    #[allow(clippy::type_complexity)]
    fn lines_and_events(
        values: &[(f64, f64, f64, f64, f64, f64)],
        pairs: &[(u32, u32, u8)],
    ) -> (Vec<Line>, Vec<Event>) {
        let lines: Vec<Line> = values
            .iter()
            .map(|&(a, b, c, d, e, f)| line((a, b), (c, d), (e, f)))
            .collect();
        let n = lines.len() as u32;
        let kinds = [
            IntersectionKind::L1WithL2,
            IntersectionKind::L2WithL1,
            IntersectionKind::AlreadyIntersected,
        ];
        let mut events: Vec<Event> = pairs
            .iter()
            .map(|&(a, b, k)| (a % n, b % n, k))
            .filter(|(a, b, _)| a != b)
            .map(|(a, b, k)| Event {
                first: LineId(a.min(b)),
                second: LineId(a.max(b)),
                kind: kinds[k as usize],
            })
            .collect();
        sort_unique(&mut events);
        (lines, events)
    }

    /// Events in resolution order, each pair once.
    fn sort_unique(events: &mut Vec<Event>) {
        events.sort_unstable_by_key(Event::order_key);
        events.dedup_by_key(|e| e.order_key());
    }

    /// `events` on lines stored by id, by slot.
    fn by_slot(events: &[Event]) -> Vec<Event<Slot>> {
        events.iter().map(|e| e.named(|id| Slot(id.0))).collect()
    }

    /// `lines` after resolving `events` one by one.
    fn one_by_one(lines: &[Line], events: &[Event]) -> Vec<Line> {
        let mut out = lines.to_vec();
        for e in events {
            resolve(&mut out, e);
        }
        out
    }

    /// The bits of every line's velocity.
    fn velocity_bits(lines: &[Line]) -> Vec<u64> {
        lines
            .iter()
            .flat_map(|l| [l.v.x.to_bits(), l.v.y.to_bits()])
            .collect()
    }

    /// In a scene larger than the cache the events' lines are read ahead;
    /// the lines end exactly as resolving the events one by one leaves
    /// them, chained events included.
    #[test]
    fn events_read_ahead_resolve_like_the_plain_loop() {
        let n = LARGE_SCENE as u32 + 5;
        let lines: Vec<Line> = (0..n)
            .map(|k| {
                let x = f64::from(k % 1000) / 1000.0;
                let y = f64::from(k / 1000) / 100.0;
                line((x, y), (x + 0.01, y + 0.002), (0.1 - x / 5.0, y / 7.0))
            })
            .collect();
        let kinds = [
            IntersectionKind::L1WithL2,
            IntersectionKind::L2WithL1,
            IntersectionKind::AlreadyIntersected,
        ];
        // Pairs far apart in memory, lines shared between events, up to
        // the last line.
        let mut events: Vec<Event> = (0..3000u32)
            .map(|k| {
                let (a, b) = ((k * 7919) % n, (k * 104_729 + 13) % n);
                Event {
                    first: LineId(a.min(b)),
                    second: LineId(a.max(b)),
                    kind: kinds[k as usize % 3],
                }
            })
            .filter(|e| e.first != e.second)
            .chain([Event {
                first: LineId(0),
                second: LineId(n - 1),
                kind: IntersectionKind::L1WithL2,
            }])
            .collect();
        sort_unique(&mut events);
        let expected = one_by_one(&lines, &events);
        let mut got = lines;
        Resolver::default().resolve_all(&mut got, &by_slot(&events), 1, None);
        assert!(velocity_bits(&got) == velocity_bits(&expected));
        assert_ne!(got[0].v, Vec2::new(0.1, 0.0), "the first line was resolved");
    }

    proptest::proptest! {
        /// Events found in any order on lines stored in any order leave
        /// every line exactly as resolving them one by one in id order
        /// does, however they chain, on one thread or several (a team,
        /// sharing every step's free events, and the tied ones in waves
        /// from `grain` events).
        #[test]
        fn found_events_resolve_like_the_plain_loop(
            lines in proptest::collection::vec(
                (0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
                2..40,
            ),
            pairs in proptest::collection::vec((0u32..40, 0u32..40, 0u8..3), 0..200),
            stride in 1u32..40,
            grain in 1usize..8,
            team in proptest::option::of(2usize..5),
        ) {
            let (lines, mut by_id) = lines_and_events(&lines, &pairs);
            let n = lines.len() as u32;
            let expected = one_by_one(&lines, &by_id);
            // Slot k holds the line that a stride through the ids meets
            // k-th (a permutation when the stride and n share no factor).
            let ids: Vec<u32> = if gcd(stride, n) == 1 {
                (0..n).map(|k| (k * stride) % n).collect()
            } else {
                (0..n).rev().collect()
            };
            let mut slot = vec![0; n as usize];
            for (k, &id) in ids.iter().enumerate() {
                slot[id as usize] = k as u32;
            }
            // Found in another order: the events reversed, by slot.
            by_id.reverse();
            let found: Vec<Event<Slot>> = by_id
                .iter()
                .map(|e| e.named(|id| Slot(slot[id.0 as usize])))
                .collect();
            let mut stored: Vec<Line> = ids.iter().map(|&id| lines[id as usize]).collect();
            let team = team.map(|threads| Team::new(threads).unwrap());
            let mut resolver = Resolver {
                team_min: Some(1),
                ..Resolver::default()
            };
            resolver.resolve_found(&mut stored, &found, &by_id, grain, team.as_ref());
            let mut got = lines.clone();
            for (k, &id) in ids.iter().enumerate() {
                got[id as usize] = stored[k];
            }
            proptest::prop_assert_eq!(velocity_bits(&got), velocity_bits(&expected));
            proptest::prop_assert!(resolver.shares.iter().all(|&s| s == 0));
        }

        /// Events in waves, on several threads, leave every line exactly as
        /// resolving them one by one does, however they chain.
        #[test]
        fn waves_resolve_like_the_plain_loop(
            lines in proptest::collection::vec(
                (0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
                2..40,
            ),
            pairs in proptest::collection::vec((0u32..40, 0u32..40, 0u8..3), 0..200),
            grain in 1usize..8,
            threads in 1usize..4,
        ) {
            let (lines, events) = lines_and_events(&lines, &pairs);
            let expected = one_by_one(&lines, &events);
            let team = Team::new(threads).unwrap();
            let mut got = lines;
            let mut resolver = Resolver::default();
            resolver.resolve_all(&mut got, &by_slot(&events), grain, Some(&team));
            proptest::prop_assert_eq!(velocity_bits(&got), velocity_bits(&expected));
        }
    }
}
