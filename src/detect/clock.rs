//! Clocks: the time now, where there is one, and the time a detector
//! spends in each of its own phases, for `--stats`.

use std::time::{Duration, Instant};

/// The time now, where there is a clock to read: std's `Instant` panics in
/// WebAssembly without a host, so a run there (the web page's, which times
/// itself) reports no time.
pub(crate) fn now() -> Option<Instant> {
    (!cfg!(all(target_arch = "wasm32", target_os = "unknown"))).then(Instant::now)
}

/// Time spent in each of `N` phases, and when the phase under way began.
#[derive(Debug)]
pub(crate) struct PhaseClock<const N: usize> {
    times: [Duration; N],
    since: Instant,
}

impl<const N: usize> PhaseClock<N> {
    /// A clock with nothing timed yet.
    pub(crate) fn new() -> Self {
        Self {
            times: [Duration::ZERO; N],
            since: Instant::now(),
        }
    }

    /// Starts timing a detection at `start`.
    pub(crate) fn start(&mut self, start: Instant) {
        self.since = start;
    }

    /// Adds the time since the last lap (or the start) to phase `phase`.
    pub(crate) fn lap(&mut self, phase: usize) {
        let now = Instant::now();
        self.times[phase] += now - self.since;
        self.since = now;
    }

    /// Adds the time from the last lap (or the start) to `at` to phase
    /// `phase`, and goes on from `at` (as when a phase ended on another
    /// clock, a thread's own, before the next began).
    pub(crate) fn lap_at(&mut self, phase: usize, at: Instant) {
        let at = at.max(self.since);
        self.times[phase] += at - self.since;
        self.since = at;
    }

    /// Each phase's name, from `names`, with its time so far.
    pub(crate) fn report(&self, names: [&'static str; N]) -> Vec<(&'static str, Duration)> {
        names.into_iter().zip(self.times).collect()
    }

    /// [`PhaseClock::report`] of a detector's clock, if timing is on;
    /// nothing if it is off.
    pub(crate) fn report_of(
        clock: Option<&Self>,
        names: [&'static str; N],
    ) -> Vec<(&'static str, Duration)> {
        clock.map_or_else(Vec::new, |c| c.report(names))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn laps_add_up_in_their_phases() {
        let mut clock = PhaseClock::<2>::new();
        clock.start(Instant::now());
        std::thread::sleep(Duration::from_millis(2));
        clock.lap(1);
        clock.lap(0);
        let report = clock.report(["a", "b"]);
        assert_eq!(report[0].0, "a");
        assert!(report[1].1 >= Duration::from_millis(2));
        assert!(report[0].1 < report[1].1);
    }
}
