//! The progress bar of a long run off screen: shown on a terminal once the
//! run has taken a second, cleared when it finishes; and what a run says
//! beside its results, on stderr.

use crate::job::{Note, Progress};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::time::{Duration, Instant};

/// A progress bar on stderr, if stderr is a terminal.
pub(crate) struct Bar {
    shown: bool,
    bar: Option<ProgressBar>,
}

impl Bar {
    /// A bar drawn only if `shown`.
    pub(crate) fn new(shown: bool) -> Bar {
        Bar { shown, bar: None }
    }
}

impl Progress for Bar {
    fn step(&mut self, done: u64, steps: u64, elapsed: Duration) {
        match &self.bar {
            Some(bar) => bar.set_position(done),
            None if self.shown && elapsed > Duration::from_secs(1) => {
                self.bar = Some(progress_bar(steps, done, Instant::now() - elapsed))
            }
            None => {}
        }
    }

    fn end(&mut self, finished: bool) {
        match self.bar.take() {
            Some(bar) if finished => bar.finish_and_clear(),
            Some(bar) => bar.abandon(),
            None => {}
        }
    }

    fn note(&mut self, note: Note) {
        let line = format!("screensaver: {}", crate::words::note(&note));
        match &self.bar {
            Some(bar) => bar.suspend(|| say!("{line}")),
            None => say!("{line}"),
        }
    }
}

/// A progress bar for a run of `steps` steps that started at `start` and
/// has run `done`. Its rate and time left are the run's own, steps over
/// the time since `start`: indicatif's estimate counts the `done` steps
/// set at once as one burst, and so shows a resumed run's rate many times
/// too high.
fn progress_bar(steps: u64, done: u64, start: Instant) -> ProgressBar {
    let bar = ProgressBar::with_draw_target(Some(steps), ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} steps  {run_rate}")
            .expect("valid progress template")
            .with_key(
                "run_rate",
                move |state: &indicatif::ProgressState, w: &mut dyn std::fmt::Write| {
                    let _ = write!(w, "{}", progress_text(state.pos(), steps, start.elapsed()));
                },
            ),
    );
    bar.set_position(done);
    bar
}

/// The rate and time left of a run that has done `done` of `steps` steps
/// in `elapsed`: `384 steps/s  eta 3s`.
fn progress_text(done: u64, steps: u64, elapsed: Duration) -> String {
    let seconds = elapsed.as_secs_f64();
    if done == 0 || seconds <= 0.0 {
        return "eta -".to_string();
    }
    let rate = done as f64 / seconds;
    let left = steps.saturating_sub(done) as f64 / rate;
    format!(
        "{rate:.0} steps/s  eta {}",
        indicatif::HumanDuration(Duration::from_secs_f64(left.min(1e9)))
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_counts_the_run_since_it_started() {
        // 213 of 1501 steps in 0.555 s: 384 a second, 3 s to go.
        let text = progress_text(213, 1501, Duration::from_secs_f64(213.0 / 384.0));
        assert_eq!(text, "384 steps/s  eta 3 seconds");
        assert_eq!(progress_text(0, 10, Duration::from_secs(1)), "eta -");
    }
}
