//! The grid lines are quantised to: cells along the axes and the
//! diagonals, the blocks nodes cover, and the Morton keys that place each
//! line at its node.
//!
//! Hulls are quantised to `2^15 x 2^15` cells over the root, a square
//! centred on the box that grows (by doubling) only when lines leave it, so
//! that cells stay put from step to step. The deepest quadrant holding a
//! hull whole is where its corner cells' coordinates stop sharing leading
//! bits, so a line's node is known without descending, and its key (the
//! node's cell interleaved, then the level) puts every node's misfits first
//! and its subtree right after, in one sorted array. Quantisation is
//! monotone, so hulls that overlap still overlap in cells.

use crate::detect::swept::{SweptBox, DIAGONAL_X, DIAGONAL_Y};
use crate::line::{BOX_MAX, BOX_MIN};

/// Levels of the quantisation grid: the deepest a tree can go.
pub const GRID_LEVELS: u32 = 15;
/// The last cell along any direction.
const CELL_MAX: u16 = (1 << GRID_LEVELS) - 1;

/// Bits of a key below the node's cell: its level.
pub(super) const LEVEL_BITS: u32 = 5;
pub(super) const LEVEL_MASK: u64 = (1 << LEVEL_BITS) - 1;

/// A line's swept hull in finest-level grid cells (inclusive), along the
/// axes and the diagonals, with its id. Lowest cells come first, then
/// highest, each four in the order `x`, `y`, `u`, `w`, so that each group
/// reads as one `u64` of four 16-bit lanes (see [`Cells::overlaps`]). Every
/// cell is below `2^15`, as [`Grid::cells`] makes them: the overlap test
/// relies on it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(C)]
pub struct Cells {
    pub x0: u16,
    pub y0: u16,
    pub u0: u16,
    pub w0: u16,
    pub x1: u16,
    pub y1: u16,
    pub u1: u16,
    pub w1: u16,
    /// The line's id.
    pub id: u32,
}

/// The top bit of each 16-bit lane.
const LANE_TOPS: u64 = 0x8000_8000_8000_8000;

/// Four cells packed as 16-bit lanes of one `u64`, the first lowest.
#[inline]
fn lanes(cells: [u16; 4]) -> u64 {
    cells
        .iter()
        .rev()
        .fold(0, |packed, &c| packed << 16 | u64::from(c))
}

impl Cells {
    /// The lowest cells as four 16-bit lanes, `x` lowest.
    #[inline]
    fn lows(&self) -> u64 {
        lanes([self.x0, self.y0, self.u0, self.w0])
    }

    /// The highest cells as four 16-bit lanes, `x` lowest.
    #[inline]
    fn highs(&self) -> u64 {
        lanes([self.x1, self.y1, self.u1, self.w1])
    }

    /// True when the two overlap in all four directions. All four lanes at
    /// once: cells are below `2^15`, so in each lane `high + 2^15 - low`
    /// lies in `1..2^16` (no borrow crosses lanes) and keeps its top bit
    /// exactly when `low <= high`.
    #[inline]
    pub fn overlaps(&self, o: &Cells) -> bool {
        debug_assert_eq!(
            (self.lows() | self.highs() | o.lows() | o.highs()) & LANE_TOPS,
            0
        );
        let ahead = (o.highs() | LANE_TOPS) - self.lows();
        let behind = (self.highs() | LANE_TOPS) - o.lows();
        ahead & behind & LANE_TOPS == LANE_TOPS
    }

    /// The smallest cells holding both (no id).
    #[inline]
    pub(super) fn union(&self, o: &Cells) -> Cells {
        Cells {
            x0: self.x0.min(o.x0),
            y0: self.y0.min(o.y0),
            u0: self.u0.min(o.u0),
            w0: self.w0.min(o.w0),
            x1: self.x1.max(o.x1),
            y1: self.y1.max(o.y1),
            u1: self.u1.max(o.u1),
            w1: self.w1.max(o.w1),
            id: 0,
        }
    }

    #[inline]
    pub(super) fn overlaps_block(&self, b: &Block) -> bool {
        // As in `overlaps`: one branch on the result, not four.
        (u32::from(self.x0) <= b.x_last())
            & (b.x0 <= u32::from(self.x1))
            & (u32::from(self.y0) <= b.y_last())
            & (b.y0 <= u32::from(self.y1))
    }
}

/// The finest-level cells a node covers: `size x size` from `(x0, y0)`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Block {
    x0: u32,
    y0: u32,
    size: u32,
}

impl Block {
    /// The root's block: the whole grid.
    pub(super) fn root() -> Block {
        Block {
            x0: 0,
            y0: 0,
            size: 1 << GRID_LEVELS,
        }
    }

    fn x_last(&self) -> u32 {
        self.x0 + self.size - 1
    }
    fn y_last(&self) -> u32 {
        self.y0 + self.size - 1
    }
    pub(super) fn child(&self, c: usize) -> Block {
        let half = self.size / 2;
        Block {
            x0: self.x0 + if c & 1 == 1 { half } else { 0 },
            y0: self.y0 + if c & 2 == 2 { half } else { 0 },
            size: half,
        }
    }
}

/// Spreads the 16 bits of `v` to the even bits of a `u32`.
#[inline]
fn spread(v: u16) -> u32 {
    let mut x = u32::from(v);
    x = (x | (x << 8)) & 0x00ff_00ff;
    x = (x | (x << 4)) & 0x0f0f_0f0f;
    x = (x | (x << 2)) & 0x3333_3333;
    x = (x | (x << 1)) & 0x5555_5555;
    x
}

/// Maps coordinates onto the grid; monotone, so overlaps are preserved.
/// The diagonals span `(1180 + 800)` times the square's side and are
/// scaled to the same number of cells.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    min: f64,
    side: f64,
    /// Where cell 0 starts along `x`, `y`, `u` and `w`.
    origin: [f64; 4],
    /// Cells per unit along `x`, `y`, `u` and `w`.
    scale: [f64; 4],
}

impl Grid {
    /// The grid over the smallest square of a fixed family holding
    /// `bounds`: centred on the box, a little larger than it, doubling as
    /// needed. Fixed squares keep keys stable from step to step (so last
    /// step's order is nearly sorted), whereas a root fitted to the bounds
    /// would move every cell boundary whenever any line moved.
    pub fn over(bounds: &SweptBox) -> Self {
        const CENTRE: f64 = (BOX_MIN + BOX_MAX) / 2.0;
        let reach = (CENTRE - bounds.min_x)
            .max(bounds.max_x - CENTRE)
            .max(CENTRE - bounds.min_y)
            .max(bounds.max_y - CENTRE);
        let mut half = (BOX_MAX - BOX_MIN) / 2.0 * (1.0 + 1.0 / 16.0);
        while half < reach {
            half *= 2.0;
        }
        let (min, side) = (CENTRE - half, 2.0 * half);
        let scale = f64::from(1u32 << GRID_LEVELS) / side;
        let (wx, wy) = (DIAGONAL_X, DIAGONAL_Y);
        // The diagonals span (wx + wy) times the square's side.
        let (min_u, min_w) = (min * (wx + wy), min * wx - (min + side) * wy);
        let diagonal_scale = scale / (wx + wy);
        Grid {
            min,
            side,
            origin: [min, min, min_u, min_w],
            scale: [scale, scale, diagonal_scale, diagonal_scale],
        }
    }

    /// True when `bounds` lies within the grid's square.
    pub fn holds(&self, bounds: &SweptBox) -> bool {
        let max = self.min + self.side;
        bounds.min_x >= self.min
            && bounds.min_y >= self.min
            && bounds.max_x <= max
            && bounds.max_y <= max
    }

    /// The cell of `v` along direction `k`: the nearest, clamped to the
    /// grid (NaN goes to 0). Any monotone rounding keeps the cells'
    /// overlaps conservative; rounding by adding `2^52`, whose last
    /// mantissa bits then hold the result, takes no saturating cast.
    #[inline]
    fn cell(&self, v: f64, k: usize) -> u16 {
        const ROUNDER: f64 = (1u64 << 52) as f64;
        let c = (v - self.origin[k]) * self.scale[k];
        let c = if c > 0.0 { c } else { 0.0 };
        let c = if c < f64::from(CELL_MAX) {
            c
        } else {
            f64::from(CELL_MAX)
        };
        (c + ROUNDER).to_bits() as u16
    }

    /// `b`'s cells, for the line `id`.
    #[inline]
    pub fn cells(&self, b: &SweptBox, id: u32) -> Cells {
        Cells {
            x0: self.cell(b.min_x, 0),
            y0: self.cell(b.min_y, 1),
            u0: self.cell(b.min_u, 2),
            w0: self.cell(b.min_w, 3),
            x1: self.cell(b.max_x, 0),
            y1: self.cell(b.max_y, 1),
            u1: self.cell(b.max_u, 2),
            w1: self.cell(b.max_w, 3),
            id,
        }
    }
}

/// The sort key of a line: its node's cell (Morton order), then its
/// level.
#[inline]
pub fn key(c: &Cells, max_depth: u32) -> u64 {
    let differ = u32::from((c.x0 ^ c.x1) | (c.y0 ^ c.y1));
    let fits = GRID_LEVELS - (u32::BITS - differ.leading_zeros());
    let level = fits.min(max_depth);
    let keep = !((1u32 << (GRID_LEVELS - level)) - 1) as u16;
    let morton = spread(c.x0 & keep) | (spread(c.y0 & keep) << 1);
    (u64::from(morton) << LEVEL_BITS) | u64::from(level)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cells(x0: u16, y0: u16, x1: u16, y1: u16) -> Cells {
        Cells {
            x0,
            y0,
            x1,
            y1,
            ..Cells::default()
        }
    }

    /// An axis-aligned box with its diagonal extents.
    fn square(min_x: f64, min_y: f64, max_x: f64, max_y: f64) -> SweptBox {
        SweptBox {
            min_x,
            min_y,
            max_x,
            max_y,
            min_u: 1180.0 * min_x + 800.0 * min_y,
            max_u: 1180.0 * max_x + 800.0 * max_y,
            min_w: 1180.0 * min_x - 800.0 * max_y,
            max_w: 1180.0 * max_x - 800.0 * min_y,
        }
    }

    #[test]
    fn spread_interleaves_bits() {
        assert_eq!(spread(0b1011), 0b1_00_01_01);
        assert_eq!(spread(u16::MAX), 0x5555_5555);
    }

    #[test]
    fn a_box_lives_at_the_deepest_quadrant_holding_it() {
        // One cell: the finest level, capped by max_depth.
        let level = |k: u64| k & LEVEL_MASK;
        assert_eq!(level(key(&cells(5, 9, 5, 9), 15)), 15);
        assert_eq!(level(key(&cells(5, 9, 5, 9), 12)), 12);
        // Straddling the root's middle in x: a root misfit.
        assert_eq!(level(key(&cells(16383, 10, 16384, 10), 15)), 0);
        // Within the left half but straddling its middle: level 1.
        assert_eq!(level(key(&cells(8191, 10, 8192, 10), 15)), 1);
    }

    #[test]
    fn a_node_sorts_before_its_subtree_and_after_its_ancestors() {
        let root_misfit = key(&cells(0, 0, 20000, 10), 15);
        let node = key(&cells(0, 0, 10000, 10), 15);
        let deep = key(&cells(0, 0, 1, 1), 15);
        let sibling = key(&cells(20000, 0, 20001, 1), 15);
        assert!(root_misfit < node && node < deep && deep < sibling);
    }

    #[test]
    fn grid_cells_are_monotone_and_clamped() {
        let b = square(0.5, 0.5, 1.0, 1.0);
        let g = Grid::over(&b);
        let c = g.cells(&b, 3);
        assert_eq!(c.id, 3);
        assert!(c.x0 > 0 && c.x0 < 1024 && c.x1 > 31500 && c.x1 < CELL_MAX);
        let mid = g.cells(&square(0.75, 0.75, 0.75, 0.75), 0);
        assert_eq!((mid.x0, mid.y0), (16384, 16384));
        // The root grows to hold lines far outside the box; the middle stays.
        let far = Grid::over(&square(-3.0, 0.6, 0.9, 0.9));
        let c = far.cells(&square(-3.0, 0.75, 0.75, 0.75), 0);
        assert!(c.x0 < 2000 && c.x1 == 16384 && c.y0 == 16384);
        // Values past the edge (rounding) saturate.
        let edge = g.cells(&square(-1e9, 0.7, 1e9, 0.7), 0);
        assert_eq!((edge.x0, edge.x1), (0, CELL_MAX));
    }

    #[test]
    fn blocks_split_into_quadrants_in_key_order() {
        let b = Block {
            x0: 0,
            y0: 0,
            size: 8,
        };
        let (c1, c2) = (b.child(1), b.child(2));
        assert_eq!((c1.x0, c1.y0, c1.size), (4, 0, 4));
        assert_eq!((c2.x0, c2.y0, c2.size), (0, 4, 4));
        assert!(cells(3, 0, 4, 0).overlaps_block(&c1));
        assert!(!cells(0, 0, 3, 3).overlaps_block(&c1));
    }

    /// A coordinate near either edge of the grid, or anywhere on it.
    fn coordinate() -> impl proptest::strategy::Strategy<Value = u16> {
        proptest::prop_oneof![0u16..8, CELL_MAX - 8..=CELL_MAX, 0..=CELL_MAX]
    }

    fn any_cells() -> impl proptest::strategy::Strategy<Value = Cells> {
        use proptest::strategy::Strategy;
        proptest::array::uniform8(coordinate()).prop_map(|c| {
            let span = |a: u16, b: u16| (a.min(b), a.max(b));
            let ((x0, x1), (y0, y1)) = (span(c[0], c[1]), span(c[2], c[3]));
            let ((u0, u1), (w0, w1)) = (span(c[4], c[5]), span(c[6], c[7]));
            Cells {
                x0,
                y0,
                u0,
                w0,
                x1,
                y1,
                u1,
                w1,
                id: 0,
            }
        })
    }

    proptest::proptest! {
        /// The four-lane overlap test agrees with eight comparisons, at the
        /// grid's edges too.
        #[test]
        fn overlaps_compares_every_direction(a in any_cells(), b in any_cells()) {
            let apart = |l0: u16, l1: u16, m0: u16, m1: u16| l1 < m0 || m1 < l0;
            let expected = !(apart(a.x0, a.x1, b.x0, b.x1)
                || apart(a.y0, a.y1, b.y0, b.y1)
                || apart(a.u0, a.u1, b.u0, b.u1)
                || apart(a.w0, a.w1, b.w0, b.w1));
            proptest::prop_assert_eq!(a.overlaps(&b), expected);
            proptest::prop_assert_eq!(b.overlaps(&a), expected);
        }
    }
}
