//! The pheromone table `tau`: one `f32` per undirected edge between 8-connected neighbours, kept
//! at a resolution that fits a fixed budget of [`BLOCKS`] entries whatever the map's size.
//!
//! Each cell owns the four edges that leave it towards E, SE, S and SW; the other four directions
//! are the same edges seen from the neighbour, so an ant that walks an edge in either direction
//! reinforces the same entry. On a map of at most [`BLOCKS`] cells (every map up to 32 x 32) each
//! cell has its own entry: the paper's `tau_ij`, exactly. On a larger map the cells are grouped in
//! square blocks of `2^k x 2^k` cells (the smallest `k` that gives at most [`BLOCKS`] blocks) and
//! the cells of a block share its four entries: `tau_ij` is then the pheromone of "moving from this
//! block towards E (SE, S, SW, or back)", and an ant's deposit on a path through the block adds up
//! in it. This is how the colony's memory stays at `BLOCKS x 32` bytes (pheromone and its
//! increment) on a 256 x 256 map, where one entry a cell would need 2 MiB. The choice is a
//! function of the map's size only, so every platform and every workspace plans the same paths.
//!
//! Values are kept in `[tau_min, tau_max]` (max-min ant system bounds): the wolves rule subtracts
//! pheromone, and without the floor an edge could go to zero or below and never be tried again.

use crate::map::grid::{Dir, Point, DX, DY};

/// Index of the undirected edge `(p, d)` as `(cell, slot)`, or `None` if the neighbour would be
/// off the map's index range (the caller only asks about allowed moves, so this does not happen).
#[inline]
pub fn edge(width: u16, p: Point, d: Dir) -> Option<(usize, usize)> {
    let (x, y, slot) = owner(p, d);
    if x < 0 || y < 0 {
        return None;
    }
    let q = Point::new(x as u16, y as u16);
    // At most 65535 * 65535 + 65535 < 2^32: fits the (at least 32-bit) usize, see `crate::map::grid`.
    let cell = usize::from(q.y)
        .wrapping_mul(usize::from(width))
        .wrapping_add(usize::from(q.x));
    Some((cell, usize::from(slot)))
}

/// The cell that owns the undirected edge `(p, d)` (`p` itself for E, SE, S, SW, else the
/// neighbour, which may be off the map: hence `i32` coordinates) and the edge's slot in it.
#[inline]
fn owner(p: Point, d: Dir) -> (i32, i32, u8) {
    let d = d & 7;
    if d < 4 {
        (i32::from(p.x), i32::from(p.y), d)
    } else {
        let di = usize::from(d);
        // A u16 plus -1..=1: no i32 overflow.
        let x = i32::from(p.x).wrapping_add(DX.get(di).copied().unwrap_or(0));
        let y = i32::from(p.y).wrapping_add(DY.get(di).copied().unwrap_or(0));
        (x, y, d.wrapping_sub(4)) // d >= 4
    }
}

/// For each direction, the offset from `4 * cell` to the edge's slot in a flattened table: `d`
/// for the four directions a cell owns, `4 * offset(d) + (d - 4)` for the other four (the edge
/// is stored with the neighbour). `offsets` are [`crate::map::grid::Grid::offsets`].
pub fn slot_offsets(offsets: &[isize; 8]) -> [isize; 8] {
    let mut s = [0isize; 8];
    for (d, (slot, off)) in s.iter_mut().zip(offsets).enumerate() {
        *slot = if d < 4 {
            d as isize
        } else {
            // |off| <= width + 1 <= 65536: no overflow.
            off.wrapping_mul(4).wrapping_add(d as isize).wrapping_sub(4)
        };
    }
    s
}

/// Most pheromone entries a map gets (each `[f32; 4]`): maps of up to this many cells get one
/// entry per cell, larger maps one per block (see the module docs).
pub const BLOCKS: usize = 1024;

/// How a map's cells map onto pheromone entries: blocks of `2^shift x 2^shift` cells.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Blocks {
    shift: u8,
    /// Blocks per row.
    across: usize,
    count: usize,
}

impl Blocks {
    /// The block layout of a `width x height` map: the smallest blocks that give at most
    /// [`BLOCKS`] entries.
    pub fn new(width: u16, height: u16) -> Self {
        Self::with_budget(width, height, BLOCKS)
    }

    /// The block layout of a `width x height` map with at most `budget` blocks.
    pub fn with_budget(width: u16, height: u16, budget: usize) -> Self {
        let mut shift = 0u8;
        loop {
            // At most 65535 + 1: no overflow.
            let across = usize::from(width >> shift)
                .wrapping_add(usize::from(width & ((1u16 << shift).wrapping_sub(1)) != 0));
            let down = usize::from(height >> shift)
                .wrapping_add(usize::from(height & ((1u16 << shift).wrapping_sub(1)) != 0));
            let count = across.saturating_mul(down);
            // shift 16 leaves one block: a 65535 x 65535 map ends there at the latest.
            if count <= budget || shift >= 16 {
                return Blocks {
                    shift,
                    across,
                    count,
                };
            }
            shift = shift.wrapping_add(1);
        }
    }

    /// Entries the map needs.
    pub fn count(&self) -> usize {
        self.count
    }

    /// Blocks per row.
    pub fn across(&self) -> usize {
        self.across
    }

    /// Side of a block, as a power of two (0: one entry per cell).
    pub fn shift(&self) -> u8 {
        self.shift
    }

    /// Index of the block holding cell `p`.
    #[inline]
    pub fn block(&self, p: Point) -> usize {
        // Block coordinates are below `across` and the block rows below `count / across`, and
        // `count <= BLOCKS`: no overflow.
        usize::from(p.y >> self.shift)
            .wrapping_mul(self.across)
            .wrapping_add(usize::from(p.x >> self.shift))
    }

    /// Flat index (`4 * block + slot`) of the undirected edge `(p, d)`.
    #[inline]
    pub fn index(&self, p: Point, d: Dir) -> usize {
        let (x, y, slot) = owner(p, d);
        // Callers only ask about allowed moves, so the owner is on the map.
        let q = Point::new(x as u16, y as u16);
        self.block(q)
            .wrapping_mul(4)
            .wrapping_add(usize::from(slot))
    }

    /// The flat indices of the eight edges leaving `p`, by direction: `[index(p, 0), ...,
    /// index(p, 7)]` for every direction whose neighbour is on the map (the others are
    /// meaningless), computed once for all eight. The four edges `p` owns sit in its block; the
    /// other four in the block of the neighbour, which is `p`'s own block unless `p` lies on the
    /// block's left, top or right side.
    #[inline]
    pub fn edges(&self, p: Point) -> [usize; 8] {
        let side = (1u16 << (self.shift & 15)).wrapping_sub(1);
        let b4 = self.block(p).wrapping_mul(4);
        // Leaving the block to the left (W), to the right (E, only NE matters here) or upwards.
        let left = if p.x & side == 0 { 4 } else { 0 };
        let right = if p.x & side == side { 4 } else { 0 };
        let up = if p.y & side == 0 {
            self.across.wrapping_mul(4)
        } else {
            0
        };
        // Each is `4 * block + slot`; the block sums wrap only for neighbours off the map.
        let n4 = b4.wrapping_sub(up);
        [
            b4,
            b4.wrapping_add(1),
            b4.wrapping_add(2),
            b4.wrapping_add(3),
            b4.wrapping_sub(left),
            n4.wrapping_sub(left).wrapping_add(1),
            n4.wrapping_add(2),
            n4.wrapping_add(right).wrapping_add(3),
        ]
    }
}

/// A pheromone (or pheromone-increment) table over a map: [`Blocks::count`] entries.
#[derive(Debug)]
pub struct Table<'a> {
    blocks: Blocks,
    tau: &'a mut [[f32; 4]],
}

impl<'a> Table<'a> {
    /// Wrap a buffer (at least [`Blocks::count`] entries; a shorter one reads as 0 past its end).
    pub fn new(blocks: Blocks, tau: &'a mut [[f32; 4]]) -> Self {
        let n = blocks.count().min(tau.len());
        let (tau, _) = tau.split_at_mut(n);
        Table { blocks, tau }
    }

    /// The block layout.
    pub fn blocks(&self) -> Blocks {
        self.blocks
    }

    /// Set every entry to `value`.
    pub fn fill(&mut self, value: f32) {
        self.tau.fill([value; 4]);
    }

    /// `tau` of the edge from `p` in direction `d`.
    #[inline]
    pub fn get(&self, p: Point, d: Dir) -> f32 {
        self.flat()
            .get(self.blocks.index(p, d))
            .copied()
            .unwrap_or(0.0)
    }

    /// Add `amount` to the edge from `p` in direction `d`.
    #[inline]
    pub fn add(&mut self, p: Point, d: Dir, amount: f32) {
        let i = self.blocks.index(p, d);
        self.add_flat(i, amount);
    }

    /// `tau = clamp((1 - rho) tau + delta, lo, hi)` for every entry, then `delta = 0`.
    pub fn evaporate_and_merge(&mut self, delta: &mut Table<'_>, rho: f32, lo: f32, hi: f32) {
        let keep = 1.0 - rho;
        // Over the flat entries, one select after the other (no branch): the host's compiler
        // does four entries at a time; the same multiplication and addition per entry.
        let tau = self.tau.as_flattened_mut();
        let delta = delta.tau.as_flattened_mut();
        for (tv, dv) in tau.iter_mut().zip(delta.iter_mut()) {
            // Comparisons rather than `f32::clamp` (which has a panic path and pulls float
            // formatting into the firmware) or `max`/`min` (library calls on the M4, 6% of a
            // plan). A NaN lands on `lo`. Each select is the shape of one SSE instruction
            // (`maxps`: `a > b ? a : b`, then `minps`: `a < b ? a : b`), so the host does four
            // entries in about eight instructions. The same value as "`v >= lo`, then `v > hi`"
            // for `0 < lo <= hi` (what `Params::validate` asks of `tau_min` and `tau_max`):
            // `v == lo` gives `lo` either way (equal non-zero floats are the same bits), and
            // `above` is `v` or `lo`, so `above < hi` picks `hi` exactly when `v > hi` does
            // (test `evaporation_clamps_as_the_two_comparisons`).
            let v = keep * *tv + *dv;
            let above = if v > lo { v } else { lo };
            *tv = if above < hi { above } else { hi };
            *dv = 0.0;
        }
    }

    /// Clamp every entry into `[lo, hi]` (a NaN lands on `lo`).
    pub fn clamp(&mut self, lo: f32, hi: f32) {
        for v in self.tau.as_flattened_mut() {
            // Comparisons, as in `evaporate_and_merge`.
            *v = if *v > hi {
                hi
            } else if *v >= lo {
                *v
            } else {
                lo
            };
        }
    }

    /// Set the entries of every block that holds a cell of the rectangle `min..=max` (clipped to
    /// the map) to `value`. Returns how many entries were set.
    pub fn fill_area(&mut self, min: Point, max: Point, value: f32) -> u32 {
        let b = self.blocks;
        let across = b.across();
        // `count / across` block rows (across > 0 for every map, see `Blocks::with_budget`).
        let down = b.count().checked_div(across).unwrap_or(0);
        let x0 = usize::from(min.x >> b.shift());
        let y0 = usize::from(min.y >> b.shift());
        let x1 = usize::from(max.x >> b.shift()).min(across.saturating_sub(1));
        let y1 = usize::from(max.y >> b.shift()).min(down.saturating_sub(1));
        let mut n = 0u32;
        for by in y0..=y1 {
            // Below `count <= BLOCKS` entries: no overflow.
            let row = by.wrapping_mul(across);
            for bx in x0..=x1 {
                if let Some(e) = self.tau.get_mut(row.wrapping_add(bx)) {
                    *e = [value; 4];
                    n = n.saturating_add(1);
                }
            }
        }
        n
    }

    /// The entries as one flat slice (`4 * block + slot`).
    #[inline]
    pub fn flat(&self) -> &[f32] {
        self.tau.as_flattened()
    }

    /// The entries as one flat slice to write (`4 * block + slot`).
    #[inline]
    pub fn flat_mut(&mut self) -> &mut [f32] {
        self.tau.as_flattened_mut()
    }

    /// Add `amount` at flat index `i` (ignored if out of range).
    #[inline]
    pub fn add_flat(&mut self, i: usize, amount: f32) {
        if let Some(v) = self.tau.as_flattened_mut().get_mut(i) {
            *v += amount;
        }
    }

    /// The entries (`[E, SE, S, SW]` per block, row-major).
    pub fn entries(&self) -> &[[f32; 4]] {
        self.tau
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::grid::opposite;

    #[test]
    fn both_directions_share_one_entry() {
        let mut buf = [[0.0f32; 4]; 9];
        let mut t = Table::new(Blocks::new(3, 3), &mut buf);
        let p = Point::new(1, 1);
        for d in 0..8u8 {
            let q = Point::new((1 + DX[d as usize]) as u16, (1 + DY[d as usize]) as u16);
            t.add(p, d, 1.0);
            assert_eq!(t.get(q, opposite(d)), 1.0, "dir {d}");
            t.add(q, opposite(d), -1.0);
            assert_eq!(t.get(p, d), 0.0);
        }
    }

    #[test]
    fn blocks_fit_the_budget() {
        assert_eq!(Blocks::new(32, 32).shift(), 0);
        assert_eq!(Blocks::new(32, 32).count(), 1024);
        let b = Blocks::new(33, 32);
        assert_eq!((b.shift(), b.count()), (1, 17 * 16));
        let b = Blocks::new(256, 256);
        assert_eq!((b.shift(), b.count()), (3, 1024));
        let b = Blocks::new(530, 481);
        assert_eq!(b.shift(), 5);
        assert!(b.count() <= BLOCKS);
        assert_eq!(Blocks::new(65535, 65535).count(), 1024);
        // Both directions of an edge share an entry across a block border too.
        let b = Blocks::new(64, 64);
        for d in 0..8u8 {
            let p = Point::new(2, 2);
            let q = Point::new((2 + DX[d as usize]) as u16, (2 + DY[d as usize]) as u16);
            assert_eq!(b.index(p, d), b.index(q, opposite(d)));
        }
    }

    #[test]
    fn edges_are_the_eight_indices() {
        for (w, h) in [
            (7u16, 5u16),
            (32, 32),
            (33, 40),
            (64, 64),
            (100, 37),
            (256, 256),
        ] {
            let b = Blocks::new(w, h);
            for y in 0..h {
                for x in 0..w {
                    let p = Point::new(x, y);
                    let e = b.edges(p);
                    for d in 0..8u8 {
                        let (nx, ny) =
                            (i32::from(x) + DX[d as usize], i32::from(y) + DY[d as usize]);
                        if nx >= 0 && ny >= 0 && nx < i32::from(w) && ny < i32::from(h) {
                            assert_eq!(e[d as usize], b.index(p, d), "{w}x{h} {p:?} d{d}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn evaporation_clamps_and_clears_delta() {
        let mut a = [[1.0f32; 4]; 2];
        let mut b = [[0.5f32; 4]; 2];
        let bl = Blocks::new(2, 1);
        let mut ta = Table::new(bl, &mut a);
        let mut tb = Table::new(bl, &mut b);
        ta.evaporate_and_merge(&mut tb, 0.5, 0.01, 0.9);
        assert!(ta.entries().iter().flatten().all(|v| *v == 0.9));
        assert!(tb.entries().iter().flatten().all(|v| *v == 0.0));
    }

    #[test]
    fn evaporation_clamps_as_the_two_comparisons() {
        // With `tau` 0 the merged value is `delta` itself: the edges of the clamp (exactly `lo`
        // and `hi`, just inside and outside them, zeros, infinities, a NaN) against the
        // reference "`v >= lo ? v : lo`, then `v > hi ? hi : that`", bit for bit.
        let (lo, hi) = (0.01f32, 100.0f32);
        let mut values = vec![
            lo,
            hi,
            0.0,
            -0.0,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::NAN,
            -lo,
            1.0,
            50.0,
            f32::MAX,
            f32::MIN_POSITIVE,
            -f32::MAX,
        ];
        for v in [lo, hi] {
            values.push(f32::from_bits(v.to_bits() + 1));
            values.push(f32::from_bits(v.to_bits() - 1));
        }
        let mut rng = crate::rng::Xoshiro128pp::from_u64(0x9e37_79b9);
        values.extend((0..1000).map(|_| f32::from_bits(rng.next_word())));
        let mut tau = vec![[0.0f32; 4]; values.len().div_ceil(4)];
        let mut delta = tau.clone();
        for (slot, v) in delta.as_flattened_mut().iter_mut().zip(&values) {
            *slot = *v;
        }
        let bl = Blocks::new(tau.len() as u16, 1);
        Table::new(bl, &mut tau).evaporate_and_merge(&mut Table::new(bl, &mut delta), 0.5, lo, hi);
        for (got, v) in tau.as_flattened().iter().zip(&values) {
            let v = 0.0 + *v;
            let above = if v >= lo { v } else { lo };
            let want = if v > hi { hi } else { above };
            assert_eq!(got.to_bits(), want.to_bits(), "{v:e}");
        }
    }
}
