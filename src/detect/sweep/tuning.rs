//! Every tuned constant of the sweep in one list, each with what it
//! measured: how often it plans, when it keeps its pairs, how it lays out
//! and shares its work. None changes a result; each changes only how fast
//! the sweep finds the same pairs.

// The sweep's own step: how often it plans, and how it shares and scans (`mod.rs`).

/// Steps between two plans (the first step always makes one). A plan of
/// one band that comes out as the one before (one band, the same
/// direction) doubles the wait, up to [`PLAN_EVERY_MOST`]: a plan costs a
/// few hundred instructions a sampled box (two sorts of the sample in each
/// of four directions), some 2% of a scene of a thousand lines planned
/// every 256 steps.
pub(crate) const PLAN_EVERY: u64 = 256;

/// The longest wait between two plans of one band along one direction.
pub(crate) const PLAN_EVERY_MOST: u64 = 4096;

/// Boxes made at a time before the movers among them are noted (16 KB of
/// hulls, at hand in the cache).
pub(crate) const NOTE_BLOCK: usize = 512;

/// Candidates a box (last step) above which the sweep meets every box's
/// candidates a block of eight at a time, with no branch on how many it
/// has ([`scan::sweep`](super::scan::sweep)). In a dense scene the branch on a box's count
/// is mispredicted often and the blocks are mostly full; in a sparse one
/// most boxes meet one candidate or none, and a block is wasted work
/// (docs/DESIGN.md, "Sweep and prune", the sweep).
pub(crate) const DENSE: f64 = 2.0;

/// Boxes a thread of a team sweeps at a time (with one band).
pub(crate) const TEAM_SWEEP_CHUNK: usize = 256;

// The plan: the cost model that chooses a direction and bands (`plan.rs`).

/// The model's cost of sweeping one box (its own work, apart from the
/// pairs it meets), in units of one candidate pair met: a box's loop
/// ends with a branch no predictor foresees, so it costs several
/// candidates' worth (docs/DESIGN.md, "Sweep and prune", the plan).
pub(crate) const SWEEP_COST: f64 = 5.0;

/// What laying boxes out in bands costs the model, in units of one
/// candidate pair met.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct LayoutCost {
    /// Each box laid out in a band (its home or a guest).
    pub per_box: f64,
    /// Each guest, on top of that.
    pub per_guest: f64,
}

/// The layout's cost in units of one candidate: a box laid out (kept
/// from the step before and updated), and each guest on top of it, listed
/// in every band it reaches above its home and swept against that band's
/// homes. Set where the model's choices matched the measured ones: `koch`
/// is cut into bands, and `mit` (whose long lines make a third of its
/// boxes guests), `sin_wave` and `smalllines` are not.
pub(crate) const LAYOUT_COST: LayoutCost = LayoutCost {
    per_box: 3.0,
    per_guest: 20.0,
};

/// Most boxes the plan looks at; beyond this it samples evenly.
pub(crate) const SAMPLE: usize = 16 * 1024;

/// The most bands a plan cuts.
pub(crate) const MAX_BANDS: usize = 1 << 14;

// The boxes' order kept from step to step (`boxes.rs`).

/// Moves an insertion sort may make per box before it gives way to a
/// radix sort: a nearly sorted band is put right in place by a few moves,
/// while boxes far out of order cost the radix sort's fixed passes less
/// (docs/DESIGN.md, "Sweep and prune", one band, and "Tried and dropped").
pub(crate) const MOVES_PER_BOX: usize = 8;

// The scan (`scan.rs`).

/// Whether a dense scene is scanned a block at a time where the processor
/// lacks AVX2: on WebAssembly, whose SIMD makes a block's masks in a few
/// instructions, it pays as it does with AVX2; on x86-64's baseline even
/// masks made with SSE2 lost to the single loop, and other targets, whose
/// masks are made lane by lane, keep the single loop too (docs/DESIGN.md,
/// "Sweep and prune", the sweep).
pub(crate) const DENSE_WITHOUT_AVX2: bool =
    cfg!(all(target_arch = "wasm32", target_feature = "simd128"));

// Near pairs kept between sweeps (`near/mod.rs`).

/// Steps of its line's travel a box is widened by: the steps it stays
/// inside its widened box if nothing turns its line. Wider keeps the pairs
/// longer but keeps more of them (docs/DESIGN.md, "Sweep and prune", near pairs).
pub(crate) const MARGIN_STEPS: f64 = 8.0;

/// The most leavers mended one at a time rather than by a sweep.
pub(crate) const MEND_MOST: usize = 16;

/// Pairs kept from which their comparison is shared among the team, a
/// group a thread (fewer are compared on the stepping thread): `koch`'s
/// 4,000 or so take about 5 us a step on one thread, well over a
/// hand-off.
pub(crate) const SHARED_PAIRS_FROM: usize = 1024;

// When near pairs are kept (`near/choice.rs`).

/// Steps swept before pairs are first tried, and again after a good
/// stretch of keeping them.
pub(crate) const FIRST_WAIT: u64 = 16;

/// The most steps swept between two tries (the wait grows fourfold after
/// each try that failed).
pub(crate) const LONGEST_WAIT: u64 = 4096;

/// The part of a sweep's work a step (in candidates, [`LINE_WEIGHT`])
/// that the pairs kept must stay below: a kept pair is read at random
/// where a sweep reads its boxes in order, and on large scenes it waits on
/// memory for it.
pub(crate) const FEWER: f64 = 0.6;

/// A sweep's work on a line's box (gathered, laid out, swept), as many
/// candidates' worth: on `koch`, about 107 instructions a box and 62 a
/// candidate met, the work a kept pair takes about 16. So `koch`'s
/// 3,900 lines keep about 4,200 pairs a step against 2,900 candidates
/// and run 0.80x of the instructions sweeping; `box`'s 400 lines keep 4,700
/// against 3,500 and run 1.33x, `sin_wave`'s 1,180 lines 4,200 against
/// 380 and 1.35x (sweeps of widened boxes included).
pub(crate) const LINE_WEIGHT: f64 = 3.0;

/// The fewest steps between two sweeps of widened boxes: a scene whose
/// boxes leave sooner sweeps more than it keeps.
pub(crate) const SOONEST_SWEEP: u64 = 3;

/// Lines from which pairs are not tried where it pays: generated scenes
/// of 6,000 lines kept them (0.84x of the instructions on one thread) but
/// ran 0.98x of sweeping every step on one thread and 0.90x on two, where
/// the sweep shares its work better than a kept step; larger scenes lose
/// more (10,000 lines 0.99x and 0.86x, 30,000 0.93x and 0.72x), and each
/// try costs a few steps' worth.
pub(crate) const TRY_BELOW: usize = 4096;

/// Steps pairs are kept between two judgements of whether they pay.
pub(crate) const JUDGE_EVERY: u64 = 32;

/// Steps pairs are kept at most before the sweep runs every step again
/// for a while, to measure it anew.
pub(crate) const KEEP_MOST: u64 = 2048;

// The frame moving with the lines (`near/frame.rs`).

/// The most lines whose velocities choose a frame.
pub(crate) const FRAME_SAMPLE: usize = 64;

/// Sweeps of widened boxes between two choices of the frame (and of the
/// least travel): the lines' velocities change slowly as a whole, and
/// the choice costs a tiny scene a few per cent.
pub(crate) const FRAME_EVERY: u64 = 8;

/// The part of the lines' mean travel at rest that their mean travel in a
/// moving frame must be below for the frame to be taken.
pub(crate) const FRAME_PAYS: f64 = 0.8;

/// The part of the lines' mean travel in a moving frame that a line at
/// rest in it is widened by: most such lines stay at rest (they move with
/// the shape), so a little, against rounding and nudges, where a frame at
/// rest gives its slow lines the whole mean.
pub(crate) const FRAME_FLOOR: f64 = 0.1;
