//! Whether the sweep keeps its pairs for the steps after it
//! ([`super`]): chosen as the run goes, from the work each way meets.

use crate::detect::sweep::tuning::{
    FEWER, FIRST_WAIT, JUDGE_EVERY, KEEP_MOST, LINE_WEIGHT, LONGEST_WAIT, SOONEST_SWEEP, TRY_BELOW,
};
use crate::detect::KeepPairs;

/// Whether pairs are kept, chosen by what each way meets: keeping pays
/// where the pairs kept, compared every step, are well under a sweep's
/// work every step (the candidates it meets and its lines' boxes,
/// [`FEWER`], [`LINE_WEIGHT`]), and the boxes stay inside their widened
/// boxes for a few steps ([`SOONEST_SWEEP`]).
/// Crowded scenes (many pairs close by, many events turning lines) fail
/// their tries and are swept every step, large ones ([`TRY_BELOW`]) are
/// not tried; scenes whose sweeps meet many boxes that do not overlap keep
/// their pairs. The counts are the same on every run, so the choices are
/// too; the events are the same either way.
#[derive(Debug)]
pub(crate) struct Choice {
    /// Always, never, or where it pays.
    mode: KeepPairs,
    /// Whether pairs are kept this step.
    keeping: bool,
    /// Steps until the next try (sweeping) or judgement (keeping).
    left: u64,
    /// The wait before the next try after a failed one.
    wait: u64,
    /// Candidates met and steps, in this stretch of sweeping every step.
    swept: (u64, u64),
    /// A step's work sweeping every step, as last measured, in
    /// candidates: those met, and [`LINE_WEIGHT`] a line.
    sweeping_rate: f64,
    /// Candidates met and steps since the last judgement, and steps in
    /// this stretch of keeping.
    kept: (u64, u64),
    kept_for: u64,
    /// Steps since the last sweep of widened boxes, this one included.
    since_sweep: u64,
}

impl Default for Choice {
    fn default() -> Self {
        Self::new(KeepPairs::Auto)
    }
}

impl Choice {
    /// Keeping pairs as `mode` says; where it pays, first tried after
    /// [`FIRST_WAIT`] steps.
    pub(crate) fn new(mode: KeepPairs) -> Self {
        Self {
            mode,
            keeping: mode == KeepPairs::Always,
            left: FIRST_WAIT,
            wait: FIRST_WAIT,
            swept: (0, 0),
            sweeping_rate: 0.0,
            kept: (0, 0),
            kept_for: 0,
            since_sweep: 0,
        }
    }

    /// Whether pairs are kept this step.
    pub(crate) fn keeping(&self) -> bool {
        self.keeping
    }

    /// Takes in a step of `lines` lines: the candidates it met, whether it
    /// swept, and the pairs kept (when keeping). Returns true when keeping
    /// begins with the next step (the pairs held are stale and must be
    /// forgotten).
    pub(crate) fn after(
        &mut self,
        candidates: u64,
        swept: bool,
        pairs: usize,
        lines: usize,
    ) -> bool {
        if self.mode != KeepPairs::Auto || (!self.keeping && lines >= TRY_BELOW) {
            return false;
        }
        self.left = self.left.saturating_sub(1);
        if !self.keeping {
            self.swept.0 += candidates;
            self.swept.1 += 1;
            if self.left > 0 {
                return false;
            }
            let met = self.swept.0 as f64 / self.swept.1 as f64;
            self.sweeping_rate = met + LINE_WEIGHT * lines as f64;
            self.swept = (0, 0);
            (self.keeping, self.left, self.kept) = (true, JUDGE_EVERY, (0, 0));
            (self.kept_for, self.since_sweep) = (0, 0);
            return true;
        }
        self.kept.0 += candidates;
        self.kept.1 += 1;
        let (met, steps) = self.kept;
        // A sweep of widened boxes that keeps more than a part of the
        // candidates a sweep meets, or that comes within a few steps of
        // the last, fails the stretch at once.
        let too_many = swept && pairs as f64 >= FEWER * self.sweeping_rate;
        let too_soon = swept && self.kept_for > 0 && self.since_sweep < SOONEST_SWEEP;
        self.kept_for += 1;
        self.since_sweep = if swept { 1 } else { self.since_sweep + 1 };
        if !(too_many || too_soon) && self.left > 0 {
            return false;
        }
        let pays = !(too_many || too_soon)
            && (met as f64 / steps as f64) < FEWER * self.sweeping_rate
            && self.kept_for < KEEP_MOST;
        if pays {
            (self.left, self.kept, self.wait) = (JUDGE_EVERY, (0, 0), FIRST_WAIT);
            return false;
        }
        // Back to sweeping every step: soon after a good stretch, later
        // and later after tries that failed.
        if self.kept_for > JUDGE_EVERY {
            self.wait = FIRST_WAIT;
        } else {
            self.wait = (4 * self.wait).min(LONGEST_WAIT);
        }
        (self.keeping, self.left) = (false, self.wait);
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Feeds `choice` steps of `candidates` each while sweeping every
    /// step, and of `kept` pairs (a sweep every `every` steps) while
    /// keeping; returns the steps kept.
    fn run(choice: &mut Choice, steps: u64, candidates: u64, kept: u64, every: u64) -> u64 {
        run_lines(choice, steps, (candidates, kept, every), 1000)
    }

    /// [`run`] on a scene of `lines` lines.
    fn run_lines(
        choice: &mut Choice,
        steps: u64,
        (candidates, kept, every): (u64, u64, u64),
        lines: usize,
    ) -> u64 {
        let (mut kept_steps, mut since) = (0, 0);
        for _ in 0..steps {
            if choice.keeping() {
                // Keeping begins with a sweep of the widened boxes.
                let swept = since % every == 0;
                (kept_steps, since) = (kept_steps + 1, since + 1);
                choice.after(kept, swept, kept as usize, lines);
            } else {
                since = 0;
                choice.after(candidates, true, 0, lines);
            }
        }
        kept_steps
    }

    #[test]
    fn pairs_are_kept_where_they_are_fewer_and_hold_for_a_few_steps() {
        // Fewer pairs than candidates, a sweep every 8 steps: kept nearly
        // throughout (swept every step for a short while now and then).
        let mut choice = Choice::new(KeepPairs::Auto);
        let kept = run(&mut choice, 4000, 9000, 2500, 8);
        assert!(kept > 3800, "{kept}");
        // More pairs than candidates: a try now and then, each one step.
        let mut choice = Choice::new(KeepPairs::Auto);
        assert!(run(&mut choice, 4000, 3000, 10_000, 8) <= 5);
        // Fewer, but a sweep every step: tried, and given up.
        let mut choice = Choice::new(KeepPairs::Auto);
        let kept = run(&mut choice, 4000, 9000, 2500, 1);
        assert!(kept <= 5 * JUDGE_EVERY, "{kept}");
        // A large scene is not tried, however it would fare.
        let mut choice = Choice::new(KeepPairs::Auto);
        assert_eq!(run_lines(&mut choice, 4000, (9000, 100, 8), TRY_BELOW), 0);
        // Always and never.
        assert_eq!(
            run(&mut Choice::new(KeepPairs::Always), 100, 1, 100, 1),
            100
        );
        assert_eq!(run(&mut Choice::new(KeepPairs::Never), 100, 100, 1, 100), 0);
    }
}
