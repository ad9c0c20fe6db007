//! Where a broad phase's pairs go: the lines as the world stores them, and
//! the sink that tests each candidate pair exactly and keeps what a step
//! finds. Every detector ends here, so the exact test, its prefilter, the
//! wild lines' test and the counting are written once.

use super::swept::{magnitude, max};
use crate::index::{LineId, Slot};
use crate::line::Line;
use crate::narrow::{intersect, may_intersect, Event, IntersectionKind};
use multiversion::multiversion;

/// The lines as the world stores them this step: the line in slot `s` is
/// `lines[s]`, with id `ids[s]`, or id `s` while they are stored by id.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Stored<'a> {
    /// The lines by slot.
    pub lines: &'a [Line],
    ids: Option<&'a [LineId]>,
}

impl<'a> Stored<'a> {
    /// Lines stored by id: slot `s` holds the line with id `s`.
    pub(crate) fn by_id(lines: &'a [Line]) -> Self {
        Stored { lines, ids: None }
    }

    /// Lines stored in any order: slot `s` holds the line with id
    /// `ids[s]`.
    pub(crate) fn by_slot(lines: &'a [Line], ids: &'a [LineId]) -> Self {
        debug_assert_eq!(lines.len(), ids.len());
        Stored {
            lines,
            ids: Some(ids),
        }
    }

    /// Whether slots are ids.
    pub(crate) fn in_id_order(self) -> bool {
        self.ids.is_none()
    }

    /// The id of the line in slot `s`.
    #[inline(always)]
    pub(crate) fn id(self, s: Slot) -> LineId {
        self.ids.map_or(LineId(s.0), |ids| ids[s.0 as usize])
    }

    /// The line in slot `s`.
    #[inline(always)]
    pub(crate) fn line(self, s: Slot) -> &'a Line {
        &self.lines[s.0 as usize]
    }

    /// `a` and `b`, each a slot with what goes with it, the one whose line
    /// has the lower id first (as events name them).
    #[inline(always)]
    fn lower_first<T>(self, a: (Slot, T), b: (Slot, T)) -> ((Slot, T), (Slot, T)) {
        match self.id(a.0) < self.id(b.0) {
            true => (a, b),
            false => (b, a),
        }
    }
}

/// Running totals of a broad phase's pair work.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PairCounts {
    /// Pairs whose boxes were compared.
    pub candidates: u64,
    /// Pairs handed to `intersect`.
    pub exact: u64,
}

impl PairCounts {
    /// Adds another tally to this one.
    pub fn add(&mut self, other: &PairCounts) {
        self.candidates += other.candidates;
        self.exact += other.exact;
    }
}

/// What a step's broad phase, or one piece of it, finds: the events by
/// slot (the line with the lower id first, in the order found) and the
/// pair work that found them. The world owns the step's; a detector that
/// splits its work gives each piece its own and appends them in order.
#[derive(Debug, Default)]
pub(crate) struct Findings {
    /// The events found.
    pub events: Vec<Event<Slot>>,
    /// The pair work done.
    pub counts: PairCounts,
    /// Set by a detector that gave up the step part way (a signal asked
    /// the program to stop during a step that takes minutes): the events
    /// are not all there, and the step must not be resolved.
    pub abandoned: bool,
}

impl Findings {
    /// Empties the events and the counts, keeping the buffer.
    pub(crate) fn clear(&mut self) {
        self.events.clear();
        self.counts = PairCounts::default();
        self.abandoned = false;
    }

    /// Counts `candidates` pairs whose boxes were compared.
    #[inline]
    pub(crate) fn met(&mut self, candidates: u64) {
        self.counts.candidates += candidates;
    }

    /// Takes in what a piece found after what is here, emptying it.
    pub(crate) fn append(&mut self, piece: &mut Findings) {
        self.events.append(&mut piece.events);
        self.counts.add(&piece.counts);
        piece.counts = PairCounts::default();
    }

    /// Tests the lines in slots `a` and `b` of `stored`, given as they are
    /// or as copies, whose hulls overlap: [`Findings::test_ordered`] with
    /// the lower id first.
    #[inline(always)]
    pub(crate) fn test_copies(
        &mut self,
        stored: Stored,
        a: (Slot, &Line),
        b: (Slot, &Line),
        dt: f64,
    ) {
        let ((a, l1), (b, l2)) = stored.lower_first(a, b);
        self.test_ordered(l1, l2, (a, b), dt);
    }

    /// Tests `l1` and `l2` (the lines in slots `first` and `second`, the
    /// lower id first; copies will do): the cheap prefilter, then the exact
    /// test, keeping the event if there is one.
    #[inline]
    pub(crate) fn test_ordered(
        &mut self,
        l1: &Line,
        l2: &Line,
        (first, second): (Slot, Slot),
        dt: f64,
    ) {
        self.keep(screen(l1, l2, dt), (first, second));
    }

    /// Tests the pair in slots `a` and `b` of `stored`, whose hulls
    /// overlap, the lower id first, with the prefilter and the exact test
    /// made by `screen` (as [`screen`] answers): from code compiled for
    /// AVX2, [`crate::lanes::intersect::screen`] (inlined where the compiler
    /// finds it pays) rather than [`screen`], which chooses the
    /// processor's code at each call.
    #[inline(always)]
    pub(crate) fn test_with(
        &mut self,
        stored: Stored,
        (a, b): (Slot, Slot),
        dt: f64,
        screen: impl Fn(&Line, &Line, f64) -> Option<Option<IntersectionKind>>,
    ) {
        let ((a, l1), (b, l2)) = stored.lower_first((a, stored.line(a)), (b, stored.line(b)));
        self.keep(screen(l1, l2, dt), (a, b));
    }

    /// Counts an exact test where the prefilter kept the pair (`screened`
    /// is `Some`), and keeps the event of the lines in slots `first` and
    /// `second`, if it found one.
    #[inline(always)]
    fn keep(&mut self, screened: Option<Option<IntersectionKind>>, (first, second): (Slot, Slot)) {
        let Some(kind) = screened else {
            return;
        };
        self.counts.exact += 1;
        if let Some(kind) = kind {
            self.events.push(Event {
                first,
                second,
                kind,
            });
        }
    }

    /// The exact test alone of `l1` and `l2` (as [`Findings::test_ordered`]
    /// takes them), as the all-pairs loop makes it.
    #[inline(always)]
    pub(crate) fn exact(&mut self, l1: &Line, l2: &Line, pair: (Slot, Slot), dt: f64) {
        self.keep(Some(intersect(l1, l2, dt)), pair);
    }

    /// Tests every wild line (a finite segment with a non-finite velocity or
    /// box) in `wild` against every line in `others` and every other wild
    /// line, each pair once, with the exact test alone. Wild lines are rare
    /// and short-lived: a line whose velocity turned NaN is inert a step
    /// later.
    pub(crate) fn test_wild(
        &mut self,
        stored: Stored,
        wild: &[Slot],
        others: impl Iterator<Item = Slot> + Clone,
        dt: f64,
    ) {
        for (k, &w) in wild.iter().enumerate() {
            for other in others.clone().chain(wild[k + 1..].iter().copied()) {
                self.counts.candidates += 1;
                let ((a, ()), (b, ())) = stored.lower_first((w, ()), (other, ()));
                self.exact(stored.line(a), stored.line(b), (a, b), dt);
            }
        }
    }
}

/// The prefilter ([`may_intersect`]) of `l1` and `l2` (the lower id
/// first), then, where it keeps the pair, the exact test: `None` for a pair
/// the prefilter rules out, else `Some` of what [`intersect`] finds. With
/// AVX2 both are made in lanes, the exact test's orientation tests four
/// at a time ([`crate::lanes::intersect`]), chosen when the program starts;
/// the answers are the same.
#[cfg_attr(not(screensaver_baseline), multiversion(targets("x86_64+avx2")))]
#[cfg_attr(
    screensaver_baseline,
    multiversion(targets("x86_64+avx2"), dispatcher = "static")
)]
pub(crate) fn screen(l1: &Line, l2: &Line, dt: f64) -> Option<Option<IntersectionKind>> {
    multiversion::target::match_target! {
        "x86_64+avx2" => crate::lanes::intersect::screen(l1, l2, dt),
        _ => {
            let bound = || max(magnitude(l1, dt), magnitude(l2, dt));
            may_intersect(l1, l2, dt, bound).then(|| intersect(l1, l2, dt))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::line::DT;
    use crate::narrow::IntersectionKind;
    use crate::test_util::line;
    use proptest::prelude::*;

    #[test]
    fn a_pair_is_tested_with_the_lower_id_first_whatever_its_slots() {
        // Slot 0 holds line 9, slot 1 line 4: the event names slot 1 first.
        let a = line((0.6, 0.6), (0.6, 0.7), (0.01, 0.0));
        let b = line((0.605, 0.6), (0.605, 0.7), (-0.01, 0.0));
        let (lines, ids) = ([a, b], [LineId(9), LineId(4)]);
        let stored = Stored::by_slot(&lines, &ids);
        let mut found = Findings::default();
        found.test_with(stored, (Slot(0), Slot(1)), 0.5, screen);
        assert_eq!(found.counts.exact, 1);
        assert_eq!(
            found.events,
            vec![Event {
                first: Slot(1),
                second: Slot(0),
                kind: IntersectionKind::L2WithL1,
            }]
        );
        let mut all = Findings::default();
        all.append(&mut found);
        assert_eq!((all.events.len(), found.events.len()), (1, 0));
        assert_eq!(found.counts, PairCounts::default());
    }

    #[test]
    fn wild_lines_meet_the_others_and_each_other_once() {
        let lines = [
            line((0.6, 0.6), (0.7, 0.7), (f64::NAN, f64::NAN)),
            line((0.6, 0.7), (0.7, 0.6), (0.0, 0.0)),
            line(
                (f64::NAN, f64::NAN),
                (f64::NAN, f64::NAN),
                (f64::NAN, f64::NAN),
            ),
            line((0.65, 0.6), (0.65, 0.7), (f64::NAN, 0.0)),
        ];
        assert!(crate::detect::swept_box(&lines[0], 0.5).is_none() && !lines[0].is_inert());
        assert!(lines[2].is_inert());
        let mut found = Findings::default();
        let wild = [Slot(0), Slot(3)];
        found.test_wild(Stored::by_id(&lines), &wild, [Slot(1)].into_iter(), 0.5);
        // 0-1, 0-3, 3-1: all three cross now.
        assert_eq!(found.counts.exact, 3);
        let mut pairs: Vec<_> = found
            .events
            .iter()
            .map(|e| (e.first.0, e.second.0))
            .collect();
        pairs.sort_unstable();
        assert_eq!(pairs, vec![(0, 1), (0, 3), (1, 3)]);
    }

    /// What the scalar code answers: the prefilter, then the exact test.
    fn scalar(l1: &Line, l2: &Line, dt: f64) -> Option<Option<IntersectionKind>> {
        let bound = max(magnitude(l1, dt), magnitude(l2, dt));
        may_intersect(l1, l2, dt, || bound).then(|| intersect(l1, l2, dt))
    }

    /// A coordinate: mostly on a small grid, so that points are often
    /// collinear and orientations exactly zero, with segments touching,
    /// sharing endpoints or of no length; sometimes anywhere, tiny, huge,
    /// infinite or NaN.
    fn value() -> impl Strategy<Value = f64> {
        prop_oneof![
            6 => (0..6i32).prop_map(|k| f64::from(k) * 0.25),
            2 => 0.0f64..1.5,
            1 => prop::sample::select(vec![
                -0.0, 1e-310, -1e-300, 1e-9, 1e30, -1e300, f64::MAX, f64::NAN, -f64::NAN,
                f64::INFINITY, f64::NEG_INFINITY,
            ]),
        ]
    }

    /// A velocity: still, on a grid that moves points onto the grid, or
    /// anything.
    fn speed() -> impl Strategy<Value = f64> {
        prop_oneof![
            3 => (-4..5i32).prop_map(|k| f64::from(k) * 0.5),
            2 => -2.0f64..2.0,
            1 => value(),
        ]
    }

    fn any_line() -> impl Strategy<Value = Line> {
        (value(), value(), value(), value(), speed(), speed())
            .prop_map(|(a, b, c, d, vx, vy)| line((a, b), (c, d), (vx, vy)))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        /// The prefilter and the exact test as the processor runs them
        /// (in lanes where it has AVX2) answer every pair as the scalar
        /// code does.
        #[test]
        fn the_screen_answers_every_pair_as_the_scalar_tests_do(
            l1 in any_line(),
            l2 in any_line(),
            dt in prop_oneof![3 => Just(DT), 1 => Just(0.5), 1 => Just(1.0)],
        ) {
            for (a, b) in [(&l1, &l2), (&l2, &l1)] {
                prop_assert_eq!(screen(a, b, dt), scalar(a, b, dt));
            }
        }
    }
}
