//! Sweep and prune: boxes sorted along one direction, each meeting only
//! the boxes whose least value lies within its own extent there, tested in
//! all eight directions of the swept hull at once.
//!
//! A step runs down this folder's files in order:
//! 1. [`hull`]: every line's padded swept hull, packed as eight `f32`
//!    lower bounds, made in last step's sorted order;
//! 2. [`plan`]: now and then, the direction to sweep along and the bands
//!    to cut the plane into, chosen on a sample;
//! 3. [`order`]: the boxes sorted by their least value along that
//!    direction (nearly sorted already: an insertion sort);
//! 4. [`bands`]: the boxes laid out band by band in sorted order, the
//!    contiguous arrays the sweep reads;
//! 5. [`scan`]: each band swept; the pairs whose hulls overlap go to the
//!    exact test.
//!
//! Lines without a finite hull are tested against every line (wild) or
//! left out (inert), as for every broad phase (see [`super::swept`]).

mod bands;
mod hull;
mod order;
mod plan;
mod scan;

use super::swept::{swept_box, test_pair, test_wild, PairCounts};
use super::{Detector, DetectorConfig, DetectorStats};
use crate::line::Line;
use crate::narrow::Event;
use bands::{Bands, Layout};
use hull::{lo, Packed};
use order::Keyed;
use plan::Plan;
use std::time::{Duration, Instant};

/// Steps between two plans (the first step always makes one).
const PLAN_EVERY: u64 = 256;

/// Steps between two trials of another band count.
const TRIAL_EVERY: u64 = 16;

/// A trial's band count is kept when its work is below this share of the
/// work with the current count.
const TRIAL_GAIN: f64 = 0.97;

/// The sweep's phases, as [`Detector::phase_times`] names them.
#[derive(Clone, Copy, Debug)]
enum Phase {
    /// Making the packed hulls (and, now and then, the plan).
    Hulls,
    /// Sorting them along the sweep direction.
    Sort,
    /// Laying them out band by band.
    Layout,
    /// Sweeping the bands and testing the pairs that overlap; testing the
    /// wild lines.
    Sweep,
}

impl Phase {
    const ALL: [Phase; 4] = [Phase::Hulls, Phase::Sort, Phase::Layout, Phase::Sweep];

    fn name(self) -> &'static str {
        match self {
            Phase::Hulls => "hulls",
            Phase::Sort => "sort",
            Phase::Layout => "layout",
            Phase::Sweep => "sweep and test",
        }
    }
}

/// Time per phase, and when the phase under way began.
#[derive(Debug)]
struct PhaseClock {
    times: [Duration; Phase::ALL.len()],
    since: Instant,
}

/// The band count in use and the one on trial, with the work each did.
#[derive(Debug, Default)]
struct BandTuner {
    /// The work (entries and candidates, in the plan's cost units) of the
    /// last step with the band count in use.
    work: f64,
    /// Steps since the last trial.
    since_trial: u64,
    /// The count to try next: more (true) or fewer (false) bands.
    try_more: bool,
    /// The plan in use while a trial runs.
    kept: Option<Plan>,
}

/// The sort-based broad phase (see the [module docs](self)).
#[derive(Debug)]
pub struct Sweep {
    threads: usize,
    grain: usize,
    plan: Plan,
    /// Steps until the next plan.
    until_plan: u64,
    tuner: BandTuner,
    /// Every line's id: last step's boxed lines in sorted order first, then
    /// the others. Hulls are made in this order, so that this step's sort
    /// has little to do.
    order: Vec<u32>,
    /// Where the next `order` is built.
    next_order: Vec<u32>,
    /// Each slot's packed hull (slot `k` holds line `order[k]`).
    hulls: Vec<Packed>,
    /// Each slot's sort key and slot number; `+inf` for lines without a
    /// finite hull, which the sort puts last.
    keyed: Vec<Keyed>,
    /// Ids of this step's wild lines.
    wild: Vec<u32>,
    layout: Layout,
    stats: DetectorStats,
    clock: Option<PhaseClock>,
}

impl Sweep {
    /// A sweep detector tuned by `config` (threads and grain apply).
    pub fn new(config: &DetectorConfig) -> Self {
        Self {
            threads: config.threads.max(1),
            grain: config.grain.max(1),
            plan: Plan {
                along: 0,
                bands: Bands::one(),
                spread: (0.0, 0.0),
            },
            until_plan: 0,
            tuner: BandTuner::default(),
            order: Vec::new(),
            next_order: Vec::new(),
            hulls: Vec::new(),
            keyed: Vec::new(),
            wild: Vec::new(),
            layout: Layout::default(),
            stats: DetectorStats::default(),
            clock: None,
        }
    }

    /// The direction swept along (`x`, `y`, `u` or `w`) and the number of
    /// bands, as they stand.
    fn plan_text(&self) -> String {
        let name = ["x", "y", "u", "w"];
        let bands = self.plan.bands;
        if bands.count == 1 {
            format!("along {}, one band", name[self.plan.along])
        } else {
            format!(
                "along {}, {} bands across {}",
                name[self.plan.along], bands.count, name[bands.across]
            )
        }
    }

    fn lap(&mut self, phase: Phase) {
        if let Some(clock) = &mut self.clock {
            let now = Instant::now();
            clock.times[phase as usize] += now - clock.since;
            clock.since = now;
        }
    }

    /// Makes every line's packed hull in `order`, keyed for the sort.
    fn make_hulls(&mut self, lines: &[Line], dt: f64) {
        let along = self.plan.along;
        let fill = |order: &[u32], hulls: &mut [Packed], keyed: &mut [Keyed], first: usize| {
            for (k, ((&id, hull), key)) in order.iter().zip(hulls).zip(keyed).enumerate() {
                let slot = (first + k) as u32;
                *key = match swept_box(&lines[id as usize], dt) {
                    Some(b) => {
                        *hull = hull::pack(&b);
                        (lo(hull, along), slot)
                    }
                    None => (f32::INFINITY, slot),
                };
            }
        };
        let n = self.order.len();
        self.hulls.resize(n, [0.0; 8]);
        self.keyed.resize(n, (0.0, 0));
        if self.parallel(n) {
            use rayon::prelude::*;
            let chunk = self.grain;
            self.order
                .par_chunks(chunk)
                .zip(self.hulls.par_chunks_mut(chunk))
                .zip(self.keyed.par_chunks_mut(chunk))
                .enumerate()
                .for_each(|(c, ((order, hulls), keyed))| fill(order, hulls, keyed, c * chunk));
        } else {
            fill(&self.order, &mut self.hulls, &mut self.keyed, 0);
        }
    }

    fn parallel(&self, work: usize) -> bool {
        self.threads > 1 && work >= 2 * self.grain
    }

    /// Draws up a new plan from a sample of this step's boxes, and re-keys
    /// them if the direction changed.
    fn make_plan(&mut self) {
        let boxed: Vec<u32> = self
            .keyed
            .iter()
            .filter(|k| k.0 != f32::INFINITY)
            .map(|k| k.1)
            .collect();
        let stride = boxed.len().div_ceil(plan::SAMPLE).max(1);
        let sample: Vec<Packed> = boxed
            .iter()
            .step_by(stride)
            .map(|&slot| self.hulls[slot as usize])
            .collect();
        let plan = plan::choose(&sample, boxed.len());
        if plan.along != self.plan.along {
            for key in &mut self.keyed {
                if key.0 != f32::INFINITY {
                    key.0 = lo(&self.hulls[key.1 as usize], plan.along);
                }
            }
        }
        self.plan = plan;
        self.tuner = BandTuner::default();
        self.until_plan = PLAN_EVERY;
    }

    /// Picks this step's band count: now and then, one step tries a count
    /// next to the one in use.
    fn start_trial(&mut self, boxed: usize) {
        let t = &mut self.tuner;
        t.since_trial += 1;
        if t.since_trial < TRIAL_EVERY || t.work == 0.0 || boxed < 64 {
            return;
        }
        t.since_trial = 0;
        t.try_more = !t.try_more;
        let bands = self.plan.bands;
        let count = if t.try_more {
            (bands.count * 5 / 4).max(bands.count + 1)
        } else {
            bands.count * 4 / 5
        };
        if count == 0 || count == bands.count {
            return;
        }
        let (from, to) = self.plan.spread;
        let across = plan::across(self.plan.along);
        t.kept = Some(self.plan);
        self.plan.bands = Bands::spanning(across, count, from, to);
    }

    /// Records this step's work; a trial that did less than the count in
    /// use becomes the count in use.
    fn end_step(&mut self, entries: usize, candidates: u64) {
        let work = plan::ENTRY_COST * entries as f64 + candidates as f64;
        let t = &mut self.tuner;
        match t.kept.take() {
            Some(kept) if work >= TRIAL_GAIN * t.work => self.plan = kept,
            _ => t.work = work,
        }
    }
}

impl Default for Sweep {
    fn default() -> Self {
        Self::new(&DetectorConfig::default())
    }
}

impl Detector for Sweep {
    fn name(&self) -> &'static str {
        "sweep"
    }

    fn detect(&mut self, lines: &[Line], dt: f64, events: &mut Vec<Event>) {
        let before = events.len();
        if let Some(clock) = &mut self.clock {
            clock.since = Instant::now();
        }
        if self.order.len() != lines.len() {
            self.order = (0..lines.len() as u32).collect();
            self.until_plan = 0;
        }

        self.make_hulls(lines, dt);
        if self.until_plan == 0 {
            self.make_plan();
        }
        self.until_plan -= 1;
        self.lap(Phase::Hulls);

        order::sort(&mut self.keyed);
        let boxed = self.keyed.partition_point(|k| k.0 != f32::INFINITY);
        self.next_order.clear();
        self.next_order
            .extend(self.keyed.iter().map(|k| self.order[k.1 as usize]));
        self.wild.clear();
        self.wild.extend(
            self.next_order[boxed..]
                .iter()
                .copied()
                .filter(|&id| !lines[id as usize].is_inert()),
        );
        self.lap(Phase::Sort);

        self.start_trial(boxed);
        let bands = self.plan.bands;
        self.layout
            .build(&self.keyed[..boxed], &self.hulls, &self.order, &bands);
        std::mem::swap(&mut self.order, &mut self.next_order);
        self.lap(Phase::Layout);

        let mut counts = PairCounts::default();
        let along = self.plan.along;
        let layout = &self.layout;
        let sweep_bands = |range: std::ops::Range<usize>, events: &mut Vec<Event>| {
            let mut counts = PairCounts::default();
            for band in range {
                counts.candidates += scan::sweep_band(layout, &bands, band, along, |i, j| {
                    let (a, b) = (layout.ids[i], layout.ids[j]);
                    test_pair(
                        (&lines[a as usize], a),
                        (&lines[b as usize], b),
                        dt,
                        events,
                        &mut counts,
                    );
                });
            }
            counts
        };
        if self.parallel(layout.len()) && bands.count > 1 {
            use rayon::prelude::*;
            let per_task = bands.count.div_ceil(4 * self.threads).max(1);
            let found: Vec<(Vec<Event>, PairCounts)> = (0..bands.count)
                .step_by(per_task)
                .collect::<Vec<_>>()
                .into_par_iter()
                .map(|first| {
                    let mut found = Vec::new();
                    let c = sweep_bands(first..(first + per_task).min(bands.count), &mut found);
                    (found, c)
                })
                .collect();
            for (found, c) in found {
                events.extend(found);
                counts.add(&c);
            }
        } else {
            counts.add(&sweep_bands(0..bands.count, events));
        }
        test_wild(
            lines,
            &self.wild,
            self.order[..boxed].iter().copied(),
            dt,
            events,
            &mut counts,
        );
        self.end_step(self.layout.len() - bands.count, counts.candidates);
        self.lap(Phase::Sweep);

        self.stats.candidate_pairs += counts.candidates;
        self.stats.exact_tests += counts.exact;
        self.stats.events += (events.len() - before) as u64;
    }

    fn stats(&self) -> DetectorStats {
        self.stats
    }

    fn describe(&self) -> String {
        self.plan_text()
    }

    fn set_timing(&mut self, on: bool) {
        self.clock = on.then(|| PhaseClock {
            times: Default::default(),
            since: Instant::now(),
        });
    }

    fn phase_times(&self) -> Vec<(&'static str, Duration)> {
        match &self.clock {
            Some(clock) => Phase::ALL
                .iter()
                .map(|&p| (p.name(), clock.times[p as usize]))
                .collect(),
            None => Vec::new(),
        }
    }
}
