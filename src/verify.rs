//! Checking a run step by step against the all-pairs detector
//! (`--verify`): before each step the oracle finds the events on the
//! world's lines; after it, the world's events must be the same, or differ
//! only by sliver events (the contract's documented exception), which are
//! counted.

use crate::detect::clock::now as clock;
use crate::detect::{Brute, Detector, Findings, Stored};
use crate::index::{Index, Slot};
use crate::line::{Line, DT};
use crate::narrow::Event;
use crate::World;
use std::time::Duration;

/// The first step at which a detector's events differed from the oracle's.
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Mismatch {
    /// The step (counting from 1) whose detection differed.
    pub step: u64,
    /// The oracle's events, sorted.
    pub expected: Vec<Event>,
    /// The detector's events, sorted.
    pub found: Vec<Event>,
}

impl Mismatch {
    /// The mismatch at `step` in words: the events missing and extra, then
    /// both lists whole.
    pub fn words(step: u64, expected: &[Event], found: &[Event]) -> String {
        let show = |e: &Event| format!("({}, {}, {:?})", e.first, e.second, e.kind);
        let list = |events: &mut dyn Iterator<Item = &Event>| {
            events.map(show).collect::<Vec<_>>().join(" ")
        };
        let missing = list(&mut expected.iter().filter(|e| !found.contains(e)));
        let extra = list(&mut found.iter().filter(|e| !expected.contains(e)));
        format!(
            "events differ at step {step}\n  missing (found by the oracle only): {missing}\n  \
             extra (found by the detector only): {extra}\n  oracle ({}): {}\n  detector ({}): {}",
            expected.len(),
            list(&mut expected.iter()),
            found.len(),
            list(&mut found.iter())
        )
    }
}

/// The oracle's answer for the step about to run: its events, sorted, and
/// the lines they were found on (to tell a sliver from a mismatch).
struct Expected {
    events: Vec<Event>,
    lines: Vec<Line>,
}

/// Checks steps against an oracle, counting the sliver events met.
pub(crate) struct Verifier {
    oracle: Box<dyn Detector>,
    expected: Option<Expected>,
    /// Sliver events met, and the step and event of the first.
    pub slivers: u64,
    pub first_sliver: Option<(u64, Event)>,
    /// Time spent finding the oracle's events and comparing them.
    pub time: Duration,
}

impl Verifier {
    /// A verifier against the all-pairs detector.
    pub fn new() -> Verifier {
        Verifier::against(Box::new(Brute))
    }

    /// A verifier against `oracle`.
    pub fn against(oracle: Box<dyn Detector>) -> Verifier {
        Verifier {
            oracle,
            expected: None,
            slivers: 0,
            first_sliver: None,
            time: Duration::ZERO,
        }
    }

    /// Before a step: finds the oracle's events on `world` as it is.
    /// Returns false where the oracle gave its step up on a signal: the
    /// step is not to be run.
    pub fn before_step(&mut self, world: &World) -> bool {
        let started = clock();
        let lines = world.lines().into_owned();
        let mut found = Findings::default();
        self.oracle.detect(Stored::by_id(&lines), DT, &mut found);
        if found.abandoned {
            self.time += started.map_or(Duration::ZERO, |s| s.elapsed());
            return false;
        }
        // Stored by id: slots are ids.
        let by_id = |e: &Event<Slot>| e.named(|s| s.as_id());
        let mut events: Vec<Event> = found.events.iter().map(by_id).collect();
        events.sort_unstable_by_key(Event::order_key);
        self.expected = Some(Expected { events, lines });
        self.time += started.map_or(Duration::ZERO, |s| s.elapsed());
        true
    }

    /// After the step: its events must be the oracle's, but for sliver
    /// events the detector may miss (counted).
    pub fn after_step(&mut self, world: &World) -> Result<(), Mismatch> {
        let started = clock();
        let Expected { events, lines } = (self.expected.take()).expect("before_step came first");
        let checked = self.compare(world, events, &lines);
        self.time += started.map_or(Duration::ZERO, |s| s.elapsed());
        checked
    }

    fn compare(
        &mut self,
        world: &World,
        expected: Vec<Event>,
        before: &[Line],
    ) -> Result<(), Mismatch> {
        let found = world.last_events();
        if expected[..] == found[..] {
            return Ok(());
        }
        let extra = found.iter().any(|e| !expected.contains(e));
        let missing: Vec<Event> = (expected.iter())
            .filter(|e| !found.contains(e))
            .copied()
            .collect();
        let sliver =
            |e: &Event| crate::narrow::is_sliver(&before[e.first.at()], &before[e.second.at()], DT);
        if !extra && missing.iter().all(sliver) {
            self.slivers += missing.len() as u64;
            self.first_sliver = self.first_sliver.or(Some((world.steps(), missing[0])));
            return Ok(());
        }
        Err(Mismatch {
            step: world.steps(),
            expected,
            found,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::line::Color;
    use crate::test_util::line;
    use crate::DetectorKind;

    /// A detector that never finds anything, to see a mismatch reported.
    struct Blind;
    impl Detector for Blind {
        fn detect(&mut self, _: Stored<'_>, _: f64, _: &mut Findings) {}
    }

    /// Runs `steps` steps of `world` checked by `verifier`; the first
    /// mismatch, if any.
    fn run(world: &mut World, verifier: &mut Verifier, steps: u64) -> Result<(), Mismatch> {
        for _ in 0..steps {
            assert!(verifier.before_step(world));
            world.step();
            verifier.after_step(world)?;
        }
        Ok(())
    }

    fn two_meeting() -> Vec<Line> {
        vec![
            line((0.6, 0.6), (0.6, 0.7), (0.01, 0.0)),
            line((0.605, 0.6), (0.605, 0.7), (-0.01, 0.0)),
        ]
    }

    #[test]
    fn verified_steps_agree_with_the_oracle() {
        let mut w = World::new(
            two_meeting(),
            vec![Color::Red; 2],
            DetectorKind::Sweep.build(),
        );
        run(&mut w, &mut Verifier::new(), 3).unwrap();
        assert_eq!(w.counters().line, 1);
    }

    #[test]
    fn a_wrong_detector_is_caught_with_both_event_lists() {
        let mut w = World::new(two_meeting(), vec![Color::Red; 2], Box::new(Blind));
        let mismatch = run(&mut w, &mut Verifier::new(), 3).unwrap_err();
        assert_eq!(mismatch.step, 1);
        assert_eq!(mismatch.expected.len(), 1);
        assert!(mismatch.found.is_empty());
        let text = Mismatch::words(mismatch.step, &mismatch.expected, &mismatch.found);
        assert!(
            text.contains("events differ at step 1")
                && text.contains("missing (found by the oracle only): (0, 1, L2WithL1)"),
            "{text}"
        );
    }

    /// A segment at rest on the line of one that slides along itself,
    /// beyond the end of its sweep: the contract's parallelogram, from
    /// rounded corners, reports an event the sweep (which tests only pairs
    /// whose hulls meet) does not. Verifying counts it as the documented
    /// exception rather than a mismatch.
    #[test]
    fn a_sliver_is_the_documented_exception_not_a_mismatch() {
        let (rest, sliding) = crate::test_util::sliver_pair();
        assert!(crate::narrow::is_sliver(&rest, &sliding, DT));
        let mut w = World::new(
            vec![rest, sliding],
            vec![Color::Red; 2],
            DetectorKind::Sweep.build(),
        );
        let mut verifier = Verifier::new();
        run(&mut w, &mut verifier, 1).unwrap();
        assert_eq!(verifier.slivers, 1);
        assert_eq!(
            verifier
                .first_sliver
                .map(|(step, e)| (step, e.first.0, e.second.0)),
            Some((1, 0, 1))
        );
        // A missing event that is no sliver is a mismatch all the same.
        let apart = line((0.6, 0.6), (0.6, 0.7), (0.01, 0.0));
        let toward = line((0.605, 0.6), (0.605, 0.7), (-0.01, 0.0));
        assert!(!crate::narrow::is_sliver(&apart, &toward, DT));
        let mut w = World::new(vec![apart, toward], vec![Color::Red; 2], Box::new(Blind));
        let mut verifier = Verifier::new();
        assert!(run(&mut w, &mut verifier, 1).is_err());
        assert_eq!(verifier.slivers, 0);
    }

    #[test]
    fn the_time_spent_verifying_is_kept() {
        let scene = crate::Scene::built_in();
        let mut w = World::with_detector(&scene, DetectorKind::Sweep);
        let mut verifier = Verifier::new();
        run(&mut w, &mut verifier, 1).unwrap();
        assert!(verifier.time > Duration::ZERO);
    }
}
