//! The iteration's move weights by cell and direction, `tau^alpha * eta^beta`, over words a
//! workspace lends ([`WeightTable`]): the pheromone does not change during an iteration (the ants
//! deposit into the increments) and the heuristic not during a plan, so a cell's eight weights,
//! once computed, hold for every ant of the iteration that stands on it.
//!
//! **What it owns.** A borrow of the words, read as eight weights a cell (an `f32`'s bits a
//! word, row-major by cell, [`crate::map::grid::Dir`] order in a row); a row whose first word is
//! [`UNFILLED`] (a signalling NaN, which no float operation returns) is not filled yet, so the
//! test is one load from the row itself. A row is filled lazily,
//! when an ant first has a choice on that cell in the iteration ([`WeightTable::row`]), by the
//! walk loop for an entry a cell ([`crate::colony::ant`]), with exactly the float operations the
//! loop without a table does at a move; so the walks are the same bit for bit with or without
//! a table. [`WeightTable::clear`] forgets every row: the colony calls it when an iteration
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

/// Words a table for a map of `cells` cells needs: [`ROW`] weights a cell (saturating).
pub const fn words(cells: usize) -> usize {
    cells.saturating_mul(ROW)
}

/// The first word of a row not filled in this iteration: a signalling NaN's bits. A float
/// operation never returns one (a NaN it returns is quiet), and a weight is a product, so a
/// filled row never starts with it; were one to, the row would only be filled again with the
/// same weights.
pub const UNFILLED: u32 = 0x7F80_0001;

/// A cell's eight weights, by direction.
pub type Row = [Cell<u32>; ROW];

/// The iteration's weights over lent words (see the module docs).
#[derive(Debug)]
pub struct WeightTable<'a> {
    /// [`ROW`] words a cell: the weights' bits ([`UNFILLED`] first: not filled).
    rows: &'a [Cell<u32>],
}

impl<'a> WeightTable<'a> {
    /// The table over `words` for a map of `cells` cells; `None` (refused) when the words do not
    /// hold [`words`]`(cells)`. Its rows are whatever the words held: [`WeightTable::clear`]
    /// before the first walk.
    pub fn of(words: &'a mut [u32], cells: usize) -> Option<Self> {
        let n = cells.checked_mul(ROW)?;
        let rows = Cell::from_mut(words).as_slice_of_cells().get(..n)?;
        Some(Self { rows })
    }

    /// Forget every row (the pheromone changed): each is filled again at its next use.
    pub fn clear(&self) {
        for first in self.rows.iter().step_by(ROW) {
            first.set(UNFILLED);
        }
    }

    /// The weights of cell `ci`, filled first by `fill` (the eight weights by direction) if this
    /// iteration has not yet; `None` beyond the table.
    #[inline(always)]
    pub fn row(&self, ci: usize, fill: impl FnOnce() -> [f32; ROW]) -> Option<&Row> {
        let start = ci.checked_mul(ROW)?;
        let row: &Row = self
            .rows
            .get(start..start.checked_add(ROW)?)?
            .try_into()
            .ok()?;
        let [first, ..] = row;
        if first.get() == UNFILLED {
            for (slot, w) in row.iter().zip(fill()) {
                slot.set(w.to_bits());
            }
        }
        Some(row)
    }

    /// Whether cell `ci`'s row is filled in this iteration.
    pub fn is_filled(&self, ci: usize) -> bool {
        self.rows
            .get(ci.saturating_mul(ROW))
            .is_some_and(|w| w.get() != UNFILLED)
    }
}

/// The weight in direction `d` (taken modulo 8) of a row.
#[inline(always)]
pub fn weight(row: &Row, d: usize) -> f32 {
    row.get(d & 7).map_or(0.0, |w| f32::from_bits(w.get()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_short_buffer_is_refused() {
        // 40 cells: 320 weights.
        assert_eq!(words(40), 320);
        let mut buf = vec![0u32; 320];
        assert!(WeightTable::of(&mut buf, 40).is_some());
        assert!(WeightTable::of(&mut buf[..319], 40).is_none());
        assert!(WeightTable::of(&mut buf[..312], 40).is_none());
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
        // A new iteration fills again.
        t.clear();
        assert!(!t.is_filled(33));
        assert_eq!(weight(t.row(33, || [4.0; ROW]).unwrap(), 7), 4.0);
    }
}
