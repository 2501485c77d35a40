//! The iteration's move weights by cell and direction, `tau^alpha * eta^beta`, over words a
//! workspace lends ([`WeightTable`]): the pheromone does not change during an iteration (the ants
//! deposit into the increments) and the heuristic not during a plan, so a cell's eight weights,
//! once computed, hold for every ant of the iteration that stands on it.
//!
//! **What it owns.** A borrow of the words, read as a row of [`STRIDE`] words a cell, row-major:
//! the cell's eight weights (an `f32`'s bits a word, [`crate::map::grid::Dir`] order), then the
//! open-move mask of the last sum asked of the row and that sum ([`total`]: ants that stand on a
//! cell with the same open moves, most of them, skip the sum); a row whose first word is
//! [`UNFILLED`] (a signalling NaN, which no float operation returns) is not filled yet, so the
//! test is one load from the row itself. A row is filled lazily, when an ant first has a choice
//! on that cell in the iteration ([`WeightTable::row`]), by the walk loop for an entry a cell
//! ([`crate::colony::ant`]), with exactly the float operations the loop without a table does at a
//! move; so the walks are the same bit for bit with or without a table. [`WeightTable::clear`] forgets every row: the colony calls it when an iteration
//! begins (the pheromone changed at the update before it, or a run began).
//!
//! **Guarantees.** A table is refused when its words do not hold a row for every cell of its
//! map ([`WeightTable::of`], [`words`]); a cell beyond the table has no row (`None`: the
//! caller computes the weights as without a table). The words are shared through [`Cell`]s, so
//! the ant, which reads everything else by shared reference, can fill a row; nothing is
//! allocated, no `unsafe`, no panic.

use core::cell::Cell;

/// Weights a row holds: one a direction.
pub const ROW: usize = 8;

/// Words a row takes: its [`ROW`] weights, then the open-move mask whose sum it keeps and that
/// sum's bits ([`total`]).
pub const STRIDE: usize = ROW + 2;

/// Words a table for a map of `cells` cells needs: [`STRIDE`] a cell (saturating).
pub const fn words(cells: usize) -> usize {
    cells.saturating_mul(STRIDE)
}

/// A kept mask no open-move mask (a byte) equals: no sum kept.
const NO_SUM: u32 = u32::MAX;

/// The first word of a row not filled in this iteration: a signalling NaN's bits. A float
/// operation never returns one (a NaN it returns is quiet), and a weight is a product, so a
/// filled row never starts with it; were one to, the row would only be filled again with the
/// same weights.
pub const UNFILLED: u32 = 0x7F80_0001;

/// A cell's row: its eight weights by direction, then the kept mask and sum ([`total`]).
pub type Row = [Cell<u32>; STRIDE];

/// The iteration's weights over lent words (see the module docs).
#[derive(Debug)]
pub struct WeightTable<'a> {
    /// [`STRIDE`] words a cell: the weights' bits ([`UNFILLED`] first: not filled), the kept mask
    /// and sum.
    rows: &'a [Cell<u32>],
}

impl<'a> WeightTable<'a> {
    /// The table over `words` for a map of `cells` cells; `None` (refused) when the words do not
    /// hold [`words`]`(cells)`. Its rows are whatever the words held: [`WeightTable::clear`]
    /// before the first walk.
    pub fn of(words: &'a mut [u32], cells: usize) -> Option<Self> {
        let n = cells.checked_mul(STRIDE)?;
        let rows = Cell::from_mut(words).as_slice_of_cells().get(..n)?;
        Some(Self { rows })
    }

    /// Forget every row (the pheromone changed): each is filled again at its next use.
    pub fn clear(&self) {
        for row in self.rows.chunks_exact(STRIDE) {
            if let Some(first) = row.first() {
                first.set(UNFILLED);
            }
        }
    }

    /// The weights of cell `ci`, filled first by `fill` (the eight weights by direction) if this
    /// iteration has not yet; `None` beyond the table.
    #[inline(always)]
    pub fn row(&self, ci: usize, fill: impl FnOnce() -> [f32; ROW]) -> Option<&Row> {
        let start = ci.checked_mul(STRIDE)?;
        // The words from the row's first on, then its first STRIDE: two tests, no sum to check.
        let row: &Row = self.rows.get(start..)?.first_chunk()?;
        let [first, ..] = row;
        if first.get() == UNFILLED {
            for (slot, w) in row.iter().zip(fill()) {
                slot.set(w.to_bits());
            }
            if let Some(mask) = row.get(ROW) {
                mask.set(NO_SUM);
            }
        }
        Some(row)
    }

    /// Whether cell `ci`'s row is filled in this iteration.
    pub fn is_filled(&self, ci: usize) -> bool {
        self.rows
            .get(ci.saturating_mul(STRIDE))
            .is_some_and(|w| w.get() != UNFILLED)
    }
}

/// The weight in direction `d` (taken modulo 8) of a row.
#[inline(always)]
pub fn weight(row: &Row, d: usize) -> f32 {
    row.get(d & 7).map_or(0.0, |w| f32::from_bits(w.get()))
}

/// The sum of the weights of `open`'s directions in a row, lowest first: the sum the row keeps
/// for that mask, else `sum()`'s (the running sum of those weights, lowest first), then kept.
/// The same weights summed in the same order give the same bits, so a kept sum is the sum.
#[inline(always)]
pub fn total(row: &Row, open: u8, sum: impl FnOnce() -> f32) -> f32 {
    let [.., mask, kept] = row;
    if mask.get() == u32::from(open) {
        return f32::from_bits(kept.get());
    }
    let t = sum();
    mask.set(u32::from(open));
    kept.set(t.to_bits());
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_short_buffer_is_refused() {
        // 40 cells: 400 words.
        assert_eq!(words(40), 400);
        let mut buf = vec![0u32; 400];
        assert!(WeightTable::of(&mut buf, 40).is_some());
        assert!(WeightTable::of(&mut buf[..399], 40).is_none());
        assert!(WeightTable::of(&mut buf[..390], 40).is_none());
        assert!(WeightTable::of(&mut [], 0).is_some());
        assert!(WeightTable::of(&mut [], 1).is_none());
        assert_eq!(words(usize::MAX), usize::MAX);
    }

    #[test]
    fn a_row_is_filled_once_an_iteration() {
        let mut buf = vec![0u32; words(40)];
        let t = WeightTable::of(&mut buf, 40).unwrap();
        t.clear();
        let mut calls = 0;
        let mut get = |ci: usize, v: f32| {
            let row = t
                .row(ci, || {
                    calls += 1;
                    [v; ROW]
                })
                .unwrap();
            weight(row, 3)
        };
        assert_eq!(get(33, 1.5), 1.5);
        // Filled: the second call keeps the first weights.
        assert_eq!(get(33, 2.5), 1.5);
        assert_eq!(get(32, 2.5), 2.5);
        assert_eq!(calls, 2);
        assert!(t.is_filled(33) && t.is_filled(32) && !t.is_filled(34));
        assert!(t.row(40, || [0.0; ROW]).is_none());
        // The sum of a mask is kept until another mask is asked for, and forgotten at a refill.
        let row = t.row(32, || [0.0; ROW]).unwrap();
        assert_eq!(total(row, 0b11, || 5.0), 5.0);
        assert_eq!(total(row, 0b11, || 6.0), 5.0);
        assert_eq!(total(row, 0b101, || 7.0), 7.0);
        assert_eq!(total(row, 0b11, || 8.0), 8.0);
        // A new iteration fills again.
        t.clear();
        let row = t.row(32, || [1.0; ROW]).unwrap();
        assert_eq!(total(row, 0b11, || 9.0), 9.0);
        t.clear();
        assert!(!t.is_filled(33));
        assert_eq!(weight(t.row(33, || [4.0; ROW]).unwrap(), 7), 4.0);
    }
}
