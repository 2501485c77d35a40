//! The ant's tabu set: the cells a walk has entered (and the pruned cells it starts from), one
//! bit a cell in words a workspace lends ([`TabuSet`]).
//!
//! **What it owns.** A borrow of the words, nothing else: the set's operations (start a walk,
//! enter a cell, whether a cell or the eight around one are in it) are its methods, so no caller
//! does word arithmetic on the buffer, and a buffer lent as a tabu set is read as one. The bit
//! layout is [`crate::map::bitmap`]'s (bit `i % 32` of word `i / 32` is cell `i`).
//!
//! **Guarantees.** A cell beyond the words reads as in the set (a walk never enters it) and
//! entering one is ignored, so a short buffer never makes an ant leave the map or write past
//! its words; a set shorter than its map is refused: the planner's by the workspace's capacity
//! check (`Workspace::new`), a caller's bare words by [`TabuSet::of`].
//! Every method is `#[inline]` over the bitmap's: the machine code is the slice's. No panic.

use crate::map::bitmap;

/// A walk's tabu set over lent words (see the module docs).
#[derive(Debug)]
pub struct TabuSet<'a> {
    words: &'a mut [u32],
}

impl<'a> TabuSet<'a> {
    /// The set over `words` (its cells: 32 a word).
    #[inline]
    pub fn new(words: &'a mut [u32]) -> Self {
        Self { words }
    }

    /// The set over `words` for a map of `cells` cells; `None` (refused) when the words do not
    /// hold a bit a cell.
    pub fn of(words: &'a mut [u32], cells: usize) -> Option<Self> {
        (words.len() >= bitmap::words(cells)).then_some(Self { words })
    }

    /// The same set, borrowed for a shorter time.
    #[inline]
    pub fn reborrow(&mut self) -> TabuSet<'_> {
        TabuSet { words: self.words }
    }

    /// Cells it can hold.
    #[inline]
    pub fn cells(&self) -> usize {
        self.words.len().saturating_mul(32)
    }

    /// Start a walk on a map of `cells` cells: the set becomes the cells of `dead` (the pruning
    /// marks; empty: none), a pass over the words.
    #[inline]
    pub fn reset(&mut self, cells: usize, dead: &[u32]) {
        if dead.is_empty() {
            bitmap::clear(self.words, cells);
        } else {
            bitmap::copy(self.words, dead, cells);
        }
    }

    /// Whether cell `i` is in the set (a cell beyond the words is).
    #[inline]
    pub fn contains(&self, i: usize) -> bool {
        bitmap::get(self.words, i)
    }

    /// Put cell `i` in the set (ignored beyond the words).
    #[inline]
    pub fn insert(&mut self, i: usize) {
        bitmap::set(self.words, i);
    }

    /// The set's cells among the eight around cell `i` of a map `width` cells wide, as a
    /// direction mask ([`bitmap::around`]: `i` off the map's border).
    #[inline]
    pub fn around(&self, i: usize, width: usize) -> u8 {
        bitmap::around(self.words, i, width)
    }

    /// The words, lent between two walks as the flood fill's visited set
    /// ([`crate::map::grid::Grid::reach_begin`]): the next walk's [`TabuSet::reset`] writes
    /// every word it reads.
    #[inline]
    pub fn lend(&mut self) -> &mut [u32] {
        self.words
    }
}

#[cfg(test)]
mod tests {
    use super::TabuSet;

    #[test]
    fn a_set_holds_its_cells_and_refuses_the_rest() {
        // A set too short for its map is refused.
        let mut short = [0u32; 2];
        assert!(TabuSet::of(&mut short, 65).is_none());
        assert!(TabuSet::of(&mut short, 64).is_some());
        let mut words = [0u32; 2];
        let mut t = TabuSet::new(&mut words);
        assert_eq!(t.cells(), 64);
        for i in [0usize, 31, 32, 63] {
            assert!(!t.contains(i));
            t.insert(i);
            assert!(t.contains(i));
        }
        // Beyond its words a cell reads as in the set (never entered) and is never written.
        assert!(t.contains(64));
        t.insert(64);
        t.insert(usize::MAX);
        assert_eq!(words, [1 | 1 << 31, 1 | 1 << 31]);
    }

    #[test]
    fn a_walk_starts_from_the_pruned_cells() {
        let mut words = [u32::MAX; 3];
        let dead = [0b100u32, 0, 0];
        let mut t = TabuSet::new(&mut words);
        t.reset(64, &dead);
        assert!(t.contains(2) && !t.contains(0) && !t.contains(40));
        t.reset(64, &[]);
        assert!(!t.contains(2));
        // Only the map's words: the third is not the map's.
        assert_eq!(words, [0, 0, u32::MAX]);
    }
}
