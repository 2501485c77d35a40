//! The per-cell state of a search, what makes the two variants differ: [`Nibbles`] (closed flag
//! and parent direction in 4 bits a cell, [`super::search`]) and [`Costs`] (the best `g` a cell,
//! [`super::search_costs`]). Every access is a `get`: a cell beyond the slice reads as closed
//! (`OFF`) and is never written.

use super::{FREE, OFF};

/// The nibble of cell `i` (`OFF` beyond the slice).
#[inline(always)]
pub(super) fn nib(nibbles: &[u8], i: usize) -> u8 {
    match nibbles.get(i >> 1) {
        Some(&b) => (b >> ((i & 1) << 2)) & 15,
        None => OFF,
    }
}

/// Set the nibble of cell `i` to `v` (`v < 16`; nothing beyond the slice).
#[inline(always)]
pub(super) fn set_nib(nibbles: &mut [u8], i: usize, v: u8) {
    if let Some(b) = nibbles.get_mut(i >> 1) {
        let s = (i & 1) << 2;
        *b = (*b & !(15 << s)) | ((v & 15) << s);
    }
}

/// The per-cell state a search keeps: what makes the two variants differ.
pub(super) trait Store {
    /// Neighbour `i` is reached with cost `g`: true if it is worth an open-list entry.
    fn offer(&mut self, i: usize, g: u32) -> bool;
    /// An entry for cell `i` with cost `g`, reached by direction `d`, leaves the open list: true
    /// if it is live (then the cell is closed).
    fn take(&mut self, i: usize, g: u32, d: u8) -> bool;
}

/// [`search`]'s store: the nibbles.
pub(super) struct Nibbles<'n>(pub(super) &'n mut [u8]);

impl Store for Nibbles<'_> {
    #[inline(always)]
    fn offer(&mut self, i: usize, _g: u32) -> bool {
        nib(self.0, i) == FREE
    }
    #[inline(always)]
    fn take(&mut self, i: usize, _g: u32, d: u8) -> bool {
        if nib(self.0, i) != FREE {
            return false;
        }
        set_nib(self.0, i, d.wrapping_add(1));
        true
    }
}

/// [`search_costs`]'s store: the best `g` of every cell.
pub(super) struct Costs<'c>(pub(super) &'c mut [u32]);

impl Store for Costs<'_> {
    #[inline(always)]
    fn offer(&mut self, i: usize, g: u32) -> bool {
        match self.0.get_mut(i) {
            Some(c) if g < *c => {
                *c = g;
                true
            }
            _ => false,
        }
    }
    #[inline(always)]
    fn take(&mut self, i: usize, g: u32, _d: u8) -> bool {
        self.0.get(i) == Some(&g)
    }
}
