//! Keeping boxes sorted by their least value along the sweep direction.
//!
//! Lines move little in a step, so last step's order is nearly this step's:
//! an insertion sort finishes in about one pass. When the order has changed
//! a lot (the first step, a new sweep direction, a scene flying apart) the
//! insertion sort stops after a budget of moves and a radix sort does the
//! whole job instead.

/// A box's sort key (its least value along the sweep direction) and where
/// its packed hull waits.
pub(crate) type Keyed = (f32, u32);

/// Moves an insertion sort may make per element before it gives way to a
/// radix sort: a radix sort of `f32` keys costs about as much as this many
/// moves.
const MOVES_PER_ELEMENT: usize = 8;

/// Sorts `keyed` by key (ties in any order: the sweep tests tied boxes both
/// ways round). Keys are never NaN. Returns whether the radix sort was used.
pub(crate) fn sort(keyed: &mut [Keyed]) -> bool {
    if insertion_sort(keyed, MOVES_PER_ELEMENT * keyed.len() + 64) {
        return false;
    }
    radsort::sort_by_key(keyed, |k| k.0);
    true
}

/// Insertion sort that gives up after `budget` moves (leaving `keyed`
/// permuted but unsorted). Returns whether it finished.
fn insertion_sort(keyed: &mut [Keyed], mut budget: usize) -> bool {
    for i in 1..keyed.len() {
        let item = keyed[i];
        if keyed[i - 1].0 <= item.0 {
            continue;
        }
        let mut j = i;
        while j > 0 && keyed[j - 1].0 > item.0 {
            keyed[j] = keyed[j - 1];
            j -= 1;
        }
        keyed[j] = item;
        let moved = i - j;
        if moved > budget {
            return false;
        }
        budget -= moved;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sorted(keyed: &[Keyed]) -> bool {
        keyed.windows(2).all(|w| w[0].0 <= w[1].0)
    }

    #[test]
    fn nearly_sorted_input_is_insertion_sorted() {
        let mut keyed: Vec<Keyed> = (0..1000).map(|i| (i as f32, i)).collect();
        keyed.swap(10, 11);
        keyed.swap(500, 503);
        assert!(!sort(&mut keyed));
        assert!(sorted(&keyed));
        let mut slots: Vec<u32> = keyed.iter().map(|k| k.1).collect();
        slots.sort_unstable();
        assert_eq!(slots, (0..1000).collect::<Vec<_>>());
    }

    #[test]
    fn scrambled_input_falls_back_to_radix() {
        let mut keyed: Vec<Keyed> = (0..1000u32)
            .map(|i| (((i * 7919) % 1000) as f32 - 500.0, i))
            .collect();
        keyed.push((f32::NEG_INFINITY, 1000));
        keyed.push((-0.0, 1001));
        keyed.push((0.0, 1002));
        assert!(sort(&mut keyed));
        assert!(sorted(&keyed));
        assert_eq!(keyed[0].1, 1000);
    }
}
