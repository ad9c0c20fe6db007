//! Choosing how to sweep: along which direction, and into how many bands.
//!
//! The best direction depends on the scene (a wave of short lines laid
//! along `x` meets almost nothing sweeping along `x` and a great deal along
//! `y`), and one direction alone meets too many boxes once there are tens
//! of thousands of lines. A plan is chosen from a sample of the boxes by a
//! cost model, on the first step and every 256 steps after (less often
//! while plain sweeps along one direction keep coming out).

use super::bands::Bands;
use super::boxes::Boxes;
use super::hull::NO_KEY;
use super::hull::{hi, lo, Packed, DIRECTIONS};
use crate::detect::sweep::tuning::{LayoutCost, MAX_BANDS, SWEEP_COST};

/// How to sweep: the direction, and the bands cut across the other one.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Plan {
    /// The direction boxes are sorted and swept along (0..4: x, y, u, w).
    pub along: usize,
    /// The bands the plane is cut into.
    pub bands: Bands,
}

/// The direction bands are cut across when sweeping along `a`: the one at
/// right angles to it (`x` and `y`, `u` and `w`).
fn across(a: usize) -> usize {
    [1, 0, 3, 2][a]
}

/// What the sample says about one direction.
#[derive(Clone, Copy, Debug)]
struct Spread {
    /// Candidate pairs a sweep along it would meet, scaled to all boxes.
    candidates: f64,
    /// Mean extent of a box along it.
    extent: f64,
    /// Where the bulk of the boxes lies along it (from the first to the
    /// last percentile of their least values, plus one extent).
    from: f32,
    to: f32,
}

/// Looks at the sampled boxes' `extents` along one direction (their least
/// and greatest values, in any order), drawn evenly from `total` boxes.
fn spread(extents: Vec<(f32, f32)>, total: usize) -> Spread {
    let n = extents.len().max(1);
    let mut extents = extents;
    radsort::sort_by_key(&mut extents, |e| e.0);
    let met = met_in_sweep(&extents);
    // Summed in the order of the least values (ties in the sample's).
    let mut extent = 0.0f64;
    for &(l, h) in &extents {
        let e = f64::from(h) - f64::from(l);
        if e.is_finite() {
            extent += e;
        }
    }
    let extent = extent / n as f64;
    let scale = total as f64 / n as f64;
    let from = extents.get(n / 100).map_or(0.0, |e| e.0);
    let last = extents.get(n - 1 - n / 100).map_or(0.0, |e| e.0);
    Spread {
        candidates: met as f64 * scale * scale,
        extent,
        from,
        to: (f64::from(last) + extent) as f32,
    }
}

/// The pairs a sweep of `extents` (sorted by least value) meets: for each
/// box, the boxes after it whose least value is within its extent.
///
/// Each box's count of least values up to its greatest is found by one
/// walk over the boxes in order of their greatest values, rather than by
/// a binary search a box, whose branches go either way at random
/// (docs/DESIGN.md, "Tried and dropped").
fn met_in_sweep(extents: &[(f32, f32)]) -> u64 {
    // Each box's greatest value, with its rank among the least values. A
    // NaN meets nothing (no least value is at most it).
    let mut tops: Vec<(f32, u32)> = extents
        .iter()
        .enumerate()
        .filter(|(_, e)| !e.1.is_nan())
        .map(|(rank, e)| (e.1, rank as u32))
        .collect();
    let mut met = 0u64;
    // Least values up to the current greatest: a prefix of `extents`,
    // growing as the greatest values do.
    let mut within = 0;
    radsort::sort_by_key(&mut tops, |t| t.0);
    for (top, rank) in tops {
        while within < extents.len() && extents[within].0 <= top {
            within += 1;
        }
        met += within.saturating_sub(rank as usize + 1) as u64;
    }
    met
}

/// The model's cost of sweeping `total` boxes along a direction whose
/// sweep alone meets `candidates` pairs, in `count` bands cut across a
/// direction where a box covers `share` of a band's width when there is
/// one band (its extent over the spread). Boxes spread evenly across are
/// assumed: each box enters `1 + count * share` bands, and each band holds
/// that many over `count` of the boxes and so meets `1 / count` of the
/// candidates of a sweep of as many boxes.
/// `layout` is the cost of laying one box out in one band.
fn cost(layout: LayoutCost, total: usize, candidates: f64, share: f64, count: usize) -> f64 {
    if count == 1 {
        return SWEEP_COST * total as f64 + candidates;
    }
    let copies = 1.0 + count as f64 * share;
    let guests = total as f64 * (copies - 1.0);
    let sweep = (SWEEP_COST + layout.per_box) * (total as f64 * copies);
    sweep + candidates * copies * copies / count as f64 + layout.per_guest * guests
}

/// A plan for the first `n` of `boxes` ([`choose`], from an even sample
/// of at most `most` of them, over the first `directions` directions),
/// their keys made along its direction where it is not `last_along`.
pub(crate) fn replan(
    boxes: &mut Boxes,
    n: usize,
    (most, directions): (usize, usize),
    layout: LayoutCost,
    last_along: usize,
) -> Plan {
    let (sample, boxed) = sample(&boxes.keys[..n], &boxes.hulls[..n], most);
    let plan = choose(layout, &sample, boxed, directions);
    if plan.along != last_along {
        for (key, hull) in boxes.keys[..n].iter_mut().zip(&boxes.hulls) {
            if *key != NO_KEY {
                *key = lo(hull, plan.along);
            }
        }
    }
    plan
}

/// An even sample of at most `most` of the boxes whose key is real
/// (`keys[k] != NO_KEY`, hull `hulls[k]`), and how many those are.
fn sample(keys: &[f32], hulls: &[Packed], most: usize) -> (Vec<Packed>, usize) {
    let boxed = keys.iter().filter(|&&k| k != NO_KEY).count();
    let hulls = keys.iter().zip(hulls).filter(|(&k, _)| k != NO_KEY);
    let stride = boxed.div_ceil(most).max(1);
    (
        hulls.step_by(stride).map(|(_, &hull)| hull).collect(),
        boxed,
    )
}

/// Chooses a plan for `total` boxes from `sample`, drawn evenly from them,
/// sweeping along one of the first `directions` directions (2: the axes
/// only, for boxes without diagonals; 4: the diagonals too), for a sweep
/// that lays boxes out in bands at `layout`
/// ([`LAYOUT_COST`](crate::detect::sweep::tuning::LAYOUT_COST)).
pub(crate) fn choose(
    layout: LayoutCost,
    sample: &[Packed],
    total: usize,
    directions: usize,
) -> Plan {
    let directions = directions.min(DIRECTIONS);
    let extents = |a| sample.iter().map(|p| (lo(p, a), hi(p, a))).collect();
    let spreads: Vec<Spread> = (0..directions).map(|a| spread(extents(a), total)).collect();
    // Each direction's partner across is among the first `directions`.
    let mut best = (f64::INFINITY, Plan::default());
    for along in 0..directions {
        let s = &spreads[along];
        let c = &spreads[across(along)];
        let width = f64::from(c.to) - f64::from(c.from);
        let share = if width > 0.0 && width.is_finite() {
            c.extent / width
        } else {
            f64::INFINITY
        };
        let mut count = 1usize;
        while count <= MAX_BANDS.min(total / 4).max(1) {
            let estimate = cost(layout, total, s.candidates, share, count);
            if estimate < best.0 {
                let bands = Bands::spanning(across(along), count, c.from, c.to);
                best = (estimate, Plan { along, bands });
            }
            if share.is_infinite() {
                break;
            }
            count = (count * 5 / 4).max(count + 1);
        }
    }
    best.1
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::detect::sweep::tuning::{LAYOUT_COST, SAMPLE};
    use proptest::prelude::*;

    /// The pairs met, counted by a binary search for every box.
    fn met_by_search(extents: &[(f32, f32)]) -> u64 {
        let mut met = 0u64;
        for (rank, &(_, h)) in extents.iter().enumerate() {
            let within = extents.partition_point(|e| e.0 <= h);
            met += within.saturating_sub(rank + 1) as u64;
        }
        met
    }

    /// Values that tie and straddle zero: small integers, both zeros, the
    /// infinities, and values far apart.
    fn awkward_value() -> impl Strategy<Value = f32> {
        prop_oneof![
            8 => (-6i8..6).prop_map(f32::from),
            1 => Just(-0.0f32),
            1 => Just(f32::INFINITY),
            1 => Just(f32::NEG_INFINITY),
            1 => -1e30f32..1e30,
        ]
    }

    proptest! {
        /// Least and greatest values that tie, greatest values below their
        /// least ones, and NaN greatest values (which meet nothing).
        #[test]
        fn one_walk_meets_what_a_search_a_box_meets(
            mut extents in proptest::collection::vec(
                (awkward_value(), prop_oneof![8 => awkward_value(), 1 => Just(f32::NAN)]),
                0..300,
            )
        ) {
            radsort::sort_by_key(&mut extents, |e| e.0);
            prop_assert_eq!(met_in_sweep(&extents), met_by_search(&extents));
        }
    }

    /// A box of size `w` by `h` at `(x, y)`, its diagonals unbounded.
    fn boxed(x: f32, y: f32, w: f32, h: f32) -> Packed {
        let n = f32::NEG_INFINITY;
        [x, y, n, n, -(x + w), -(y + h), n, n]
    }

    #[test]
    fn a_row_of_boxes_is_swept_along_the_row() {
        // Boxes strung out along x, all at the same height: along y every
        // pair meets, along x only neighbours.
        let sample: Vec<Packed> = (0..200).map(|i| boxed(i as f32, 0.0, 1.5, 1.0)).collect();
        let plan = choose(LAYOUT_COST, &sample, sample.len(), 2);
        assert_eq!(plan.along, 0);
        assert_eq!(plan.bands.count, 1);
    }

    #[test]
    fn many_small_boxes_are_cut_into_bands() {
        let sample: Vec<Packed> = (0..SAMPLE)
            .map(|i| {
                let (x, y) = ((i * 7919 % 1000) as f32, (i * 104729 % 1000) as f32);
                boxed(x, y, 1.0, 1.0)
            })
            .collect();
        let plan = choose(LAYOUT_COST, &sample, 1_000_000, 2);
        assert!(plan.bands.count > 16, "{plan:?}");
        // More bands cost more than they save past the model's optimum.
        let cost =
            |total, candidates, share, count| cost(LAYOUT_COST, total, candidates, share, count);
        assert!(cost(1000, 1e6, 0.001, 1) > cost(1000, 1e6, 0.001, 30));
        assert!(cost(1000, 1e3, 0.1, 1) < cost(1000, 1e3, 0.1, 30));
    }
}
