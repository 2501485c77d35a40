//! The local search's window scratch: the word slices a window's A* works in (`g`, `f`, the open
//! list and the heap positions), how many box cells and which window side a lent buffer gives,
//! and [`RefineStorage`], the statically sized version a firmware keeps in a `static`.
//!
//! **What it guarantees.** [`Scratch::new`] never asks more than the two slices hold: a window of
//! [`Scratch::cells`] cells needs `cells + ceil(cells / 2)` words in each ([`Scratch::words`]),
//! and the contents lent do not matter (every search clears what it uses first).

use super::memo::Memo;
use super::MAX_SIDE;

/// Search scratch for one window, lent for each call: two word slices, each holding one `u32`
/// and half a `u32` per window cell (`g` and the open list in the first, `f` and the heap
/// positions in the second; see [`Scratch::new`]).
///
/// Two plain `u32` slices, so that a planner can lend buffers it no longer needs (the device's
/// coarse route and links, after the colony's last iteration) instead of setting RAM aside.
#[derive(Debug)]
pub struct Scratch<'a> {
    /// Cost from the window's start per box cell; [`UNREACHED`] for a cell not reached yet.
    pub(super) g: &'a mut [u32],
    /// `g` plus the octile heuristic, per box cell.
    pub(super) f: &'a mut [u32],
    /// The open list: a binary heap of box cell indices, root at slot 1 (the tail of the first
    /// word slice seen as `u16`s).
    pub(super) heap: &'a mut [u16],
    /// Position of each box cell in `heap` ([`CLOSED`] once expanded; the tail of the second).
    pub(super) pos: &'a mut [u16],
    /// The windows searched so far, if lent ([`Scratch::with_memo`]).
    pub(super) memo: Option<Memo<'a>>,
}

/// `g` of a cell not reached yet.
pub(super) const UNREACHED: u32 = u32::MAX;
/// `pos` of an expanded cell (heap slots are below [`MAX_SIDE`]`^2 < 0xFFFF`).
pub(super) const CLOSED: u16 = u16::MAX;

/// The words as `u16`s (two a word; empty if the cast were impossible, which it never is).
fn halves(words: &mut [u32]) -> &mut [u16] {
    bytemuck::try_cast_slice_mut(words).unwrap_or_default()
}

impl<'a> Scratch<'a> {
    /// Bytes of scratch per window cell.
    pub const BYTES_PER_CELL: usize = 12;

    /// Words each of the two slices needs for a window of `side x side` cells (saturating).
    pub const fn words(side: usize) -> usize {
        let cells = side.saturating_mul(side);
        cells.saturating_add(cells.div_ceil(2))
    }

    /// Scratch over two word slices: the window holds the largest `cells` with
    /// `cells + ceil(cells / 2)` words in the shorter one. Their contents do not matter.
    pub fn new(a: &'a mut [u32], b: &'a mut [u32]) -> Self {
        let words = a.len().min(b.len());
        // cells + ceil(cells / 2) <= words  <=>  cells <= floor(2 words / 3).
        let mut cells = words.saturating_mul(2) / 3;
        if cells.saturating_add(cells.div_ceil(2)) > words {
            cells = cells.saturating_sub(1);
        }
        let (g, a) = a.split_at_mut(cells.min(a.len()));
        let (f, b) = b.split_at_mut(cells.min(b.len()));
        let half = cells.div_ceil(2);
        Scratch {
            g,
            f,
            heap: halves(a.split_at_mut(half.min(a.len())).0),
            pos: halves(b.split_at_mut(half.min(b.len())).0),
            memo: None,
        }
    }

    /// The same scratch with a memo of the windows searched ([`Memo`]): a window whose ends and
    /// box a record holds, and that would not improve its piece, is not searched again. The
    /// refined path is the same with or without it.
    pub fn with_memo(self, memo: Memo<'a>) -> Self {
        Scratch {
            memo: Some(memo),
            ..self
        }
    }

    /// Box cells this scratch can hold.
    pub fn cells(&self) -> usize {
        self.g
            .len()
            .min(self.f.len())
            .min(self.heap.len())
            .min(self.pos.len())
    }

    /// The window side: the largest `s <= MAX_SIDE` with `s * s <= self.cells()`.
    pub fn side(&self) -> usize {
        let cells = self.cells();
        let mut s = 0usize;
        // s <= MAX_SIDE = 255: no overflow.
        while s < MAX_SIDE && s.wrapping_add(1).wrapping_mul(s.wrapping_add(1)) <= cells {
            s = s.wrapping_add(1);
        }
        s
    }
}

/// Statically sized scratch: two slices of `WORDS` words each, for a window of the largest side
/// with [`Scratch::words`]`(side) <= WORDS` (a firmware puts this in a `static`).
///
/// ```
/// use ohaca::refine::{RefineStorage, Scratch};
/// let mut s = RefineStorage::<{ Scratch::words(48) }>::new();
/// assert_eq!(s.scratch().side(), 48);
/// ```
#[derive(Debug)]
pub struct RefineStorage<const WORDS: usize> {
    a: [u32; WORDS],
    b: [u32; WORDS],
}

impl<const WORDS: usize> Default for RefineStorage<WORDS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const WORDS: usize> RefineStorage<WORDS> {
    /// Zeroed storage.
    pub const fn new() -> Self {
        RefineStorage {
            a: [0; WORDS],
            b: [0; WORDS],
        }
    }

    /// Lend it as scratch.
    pub fn scratch(&mut self) -> Scratch<'_> {
        Scratch::new(&mut self.a, &mut self.b)
    }
}
