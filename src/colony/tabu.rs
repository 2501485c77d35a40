//! The ant's tabu set: the cells a walk has entered (and the pruned cells it starts from), one
//! bit a cell in words a workspace lends ([`TabuSet`]).
//!
//! **What it owns.** A borrow of the words, nothing else: the set's operations (start a walk,
//! enter a cell, whether a cell or the eight around one are in it) are its methods, so no caller
//! does word arithmetic on the buffer, and a buffer lent as a tabu set is read as one. Two
//! layouts:
//! - **linear** (every build): [`crate::map::bitmap`]'s (bit `i % 32` of word `i / 32` is cell
//!   `i`);
//! - **rows** (feature `alloc`: the host's walk loop that reads a weight table,
//!   `Ant::walk_table`), for maps at most [`ROWS_WIDTH`] cells wide, in spare words beside the
//!   weight table ([`TabuSet::with_rows`], [`rows_words`]): word `y + 1` is map row `y`, bit
//!   `x + 1` cell `(x, y)`, with a padding row above and below and a padding bit on each side
//!   (never set), so the 3 x 3 read around a cell is three words shifted by `x`
//!   ([`TabuSet::around_at`]): one bounds test, no word straddled. The pruning marks a walk
//!   starts from are copied into the same layout once, when the set is made, so starting a walk
//!   is a copy of words in either layout.
//!
//! Every reader by cell index ([`TabuSet::contains`], [`TabuSet::insert`], [`TabuSet::around`]:
//! the general walk loop, the arrival's check, tightening) reads whichever layout the set has
//! (in the rows layout by the cell's column and row: a division, off the hot loop), so every
//! reader sees the same set; only the loops that chose a layout read it unchecked
//! ([`TabuSet::around_linear`], [`TabuSet::around_at`]).
//!
//! **Guarantees.** A cell beyond the words (or, in the rows layout, beyond the map) reads as in
//! the set (a walk never enters it) and entering one is ignored, so a short buffer never makes
//! an ant leave the map or write past its words; a set shorter than its map is refused: the
//! planner's by the workspace's capacity check (`Workspace::new`), a caller's bare words by
//! [`TabuSet::of`]; spare words too short for a map's rows leave the set linear. Every hot
//! method is `#[inline]` over slice reads: the machine code is the slice's. No panic.

use crate::map::bitmap;
#[cfg(any(feature = "alloc", test))]
use crate::map::grid::Point;

/// The widest map the rows layout holds: a row and its two padding bits in a 32-bit word.
pub const ROWS_WIDTH: usize = 30;

/// Spare words the rows layout needs for any map of at most `cells` cells (at most
/// [`ROWS_WIDTH`] wide): the live rows and the pruning marks' rows, each a word a map row (at most
/// `cells` of them) and two padding rows. Saturating.
pub const fn rows_words(cells: usize) -> usize {
    cells.saturating_add(2).saturating_mul(2)
}

/// A walk's tabu set over lent words (see the module docs).
#[derive(Debug)]
pub struct TabuSet<'a> {
    /// The linear layout's words (in the rows layout: idle, lent to the flood fill between
    /// walks).
    words: &'a mut [u32],
    /// The rows layout, when the set has it.
    #[cfg(any(feature = "alloc", test))]
    rows: Rows<'a>,
}

/// The rows layout (module docs): `width` 0 when the set is linear.
#[cfg(any(feature = "alloc", test))]
#[derive(Debug, Default)]
struct Rows<'a> {
    /// `height + 2` words of live rows, then as many of the pruning marks' rows when `marks`.
    words: &'a mut [u32],
    /// Map columns, at most [`ROWS_WIDTH`]; 0: the linear layout.
    width: usize,
    /// Map rows.
    height: usize,
    /// Whether the pruning marks' rows follow the live ones (else a walk starts empty).
    marks: bool,
}

impl<'a> TabuSet<'a> {
    /// The set over `words` (its cells: 32 a word), linear.
    #[inline]
    pub fn new(words: &'a mut [u32]) -> Self {
        Self {
            words,
            #[cfg(any(feature = "alloc", test))]
            rows: Rows::default(),
        }
    }

    /// The set over `words` for a map of `cells` cells; `None` (refused) when the words do not
    /// hold a bit a cell.
    pub fn of(words: &'a mut [u32], cells: usize) -> Option<Self> {
        (words.len() >= bitmap::words(cells)).then(|| Self::new(words))
    }

    /// The same set in the rows layout over `spare` for a map `width` x `height` whose walks
    /// start from the pruning marks `dead` (empty: none; a walk's [`TabuSet::reset`] then copies
    /// these, whatever marks it is given): when the map is at most [`ROWS_WIDTH`] wide and
    /// `spare` holds `2 (height + 2)` words ([`rows_words`] of its cells always do); else the
    /// set stays linear. The marks' rows are written here, a pass over the map's rows.
    #[cfg(any(feature = "alloc", test))]
    pub fn with_rows(
        self,
        spare: &'a mut [u32],
        width: usize,
        height: usize,
        dead: &[u32],
    ) -> Self {
        let live = height.saturating_add(2);
        let fits = (1..=ROWS_WIDTH).contains(&width) && spare.len() / 2 >= live;
        let Some(words) = spare.get_mut(..live.wrapping_mul(2)).filter(|_| fits) else {
            return self;
        };
        let marks = !dead.is_empty();
        if marks {
            let (_, copy) = words.split_at_mut(live);
            let row_mask = (1u32 << width).wrapping_sub(1); // width <= 30
            for (y, slot) in copy.iter_mut().enumerate() {
                // Word y is map row y - 1; the padding rows are empty.
                *slot = match y.checked_sub(1).filter(|&r| r < height) {
                    Some(r) => {
                        // r * width < cells < 2^32: no overflow.
                        let bits = bitmap::window(dead, r.wrapping_mul(width)) as u32;
                        (bits & row_mask) << 1
                    }
                    None => 0,
                };
            }
        }
        Self {
            words: self.words,
            rows: Rows {
                words,
                width,
                height,
                marks,
            },
        }
    }

    /// Whether the set has the rows layout ([`TabuSet::with_rows`]).
    #[cfg(any(feature = "alloc", test))]
    #[inline]
    pub fn is_rows(&self) -> bool {
        self.rows.width != 0
    }

    /// The same set, borrowed for a shorter time.
    #[inline]
    pub fn reborrow(&mut self) -> TabuSet<'_> {
        TabuSet {
            words: self.words,
            #[cfg(any(feature = "alloc", test))]
            rows: Rows {
                words: self.rows.words,
                ..self.rows
            },
        }
    }

    /// Cells its linear words can hold.
    #[inline]
    pub fn cells(&self) -> usize {
        self.words.len().saturating_mul(32)
    }

    /// Start a walk on a map of `cells` cells: the set becomes the cells of `dead` (the pruning
    /// marks; empty: none), a pass over the words. In the rows layout: the marks' rows written
    /// when the set was made ([`TabuSet::with_rows`]).
    #[inline]
    pub fn reset(&mut self, cells: usize, dead: &[u32]) {
        #[cfg(any(feature = "alloc", test))]
        if self.is_rows() {
            let live = self.rows.height.saturating_add(2);
            let (rows, marks) = self
                .rows
                .words
                .split_at_mut(live.min(self.rows.words.len()));
            match marks.get(..rows.len()).filter(|_| self.rows.marks) {
                Some(m) => rows.copy_from_slice(m),
                None => rows.fill(0),
            }
            return;
        }
        if dead.is_empty() {
            bitmap::clear(self.words, cells);
        } else {
            bitmap::copy(self.words, dead, cells);
        }
    }

    /// In the rows layout: cell `i`'s column and row (the width is not 0 there; were it, a row
    /// beyond every map).
    #[cfg(any(feature = "alloc", test))]
    #[inline]
    fn xy(&self, i: usize) -> (usize, usize) {
        let w = self.rows.width;
        (
            i.checked_rem(w).unwrap_or(0),
            i.checked_div(w).unwrap_or(usize::MAX),
        )
    }

    /// In the rows layout: cell `i`'s word and bit, `None` beyond the map.
    #[cfg(any(feature = "alloc", test))]
    #[inline]
    fn row_bit(&self, i: usize) -> Option<(usize, u32)> {
        let (x, y) = self.xy(i);
        // y < height, x < width <= 30: neither the sum nor the shift overflows.
        (y < self.rows.height).then_some((y.wrapping_add(1), 2u32 << x))
    }

    /// Whether cell `i` is in the set (a cell beyond the words, or the rows layout's map, is).
    #[inline]
    pub fn contains(&self, i: usize) -> bool {
        #[cfg(any(feature = "alloc", test))]
        if self.is_rows() {
            return match self.row_bit(i) {
                Some((k, bit)) => self.rows.words.get(k).is_none_or(|w| w & bit != 0),
                None => true,
            };
        }
        bitmap::get(self.words, i)
    }

    /// Put cell `i` in the set (ignored beyond the words, or the rows layout's map).
    #[inline]
    pub fn insert(&mut self, i: usize) {
        #[cfg(any(feature = "alloc", test))]
        if self.is_rows() {
            if let Some((k, bit)) = self.row_bit(i) {
                if let Some(w) = self.rows.words.get_mut(k) {
                    *w |= bit;
                }
            }
            return;
        }
        self.insert_linear(i);
    }

    /// [`TabuSet::insert`] in the linear layout, unchecked: for a loop that knows the set is
    /// linear.
    #[inline(always)]
    pub fn insert_linear(&mut self, i: usize) {
        bitmap::set(self.words, i);
    }

    /// The set's cells among the eight around cell `i` of a map `width` cells wide, as a
    /// direction mask ([`bitmap::around`]: on the map's border a direction off the map reads
    /// anything, the caller masks it out).
    #[inline]
    pub fn around(&self, i: usize, width: usize) -> u8 {
        #[cfg(any(feature = "alloc", test))]
        if self.is_rows() {
            let (x, y) = self.xy(i);
            return self.around_xy(x, y);
        }
        self.around_linear(i, width)
    }

    /// [`TabuSet::around`] in the linear layout, unchecked: for a loop that knows the set is
    /// linear.
    #[inline(always)]
    pub fn around_linear(&self, i: usize, width: usize) -> u8 {
        bitmap::around(self.words, i, width)
    }

    /// [`TabuSet::around`] of the cell `at` in the rows layout, unchecked: for the loop that
    /// knows the set has it (on a linear set: no panic, a meaningless mask). Three words
    /// shifted by the column: one bounds test, and the padding reads as not in the set (the
    /// caller masks the directions off the map out); beyond the words every direction reads as
    /// in the set.
    #[cfg(any(feature = "alloc", test))]
    #[inline(always)]
    pub fn around_at(&self, at: Point) -> u8 {
        self.around_xy(usize::from(at.x), usize::from(at.y))
    }

    #[cfg(any(feature = "alloc", test))]
    #[inline(always)]
    fn around_xy(&self, x: usize, y: usize) -> u8 {
        // Words y, y + 1, y + 2: map rows y - 1, y, y + 1; bits x, x + 1, x + 2 of each: columns
        // x - 1, x, x + 1 (x < width <= 30).
        let Some(&[a, b, c]) = self.rows.words.get(y..y.wrapping_add(3)) else {
            return 0xFF;
        };
        let s = x as u32;
        let nb =
            a.wrapping_shr(s) & 7 | (b.wrapping_shr(s) & 7) << 3 | (c.wrapping_shr(s) & 7) << 6;
        bitmap::ring(nb)
    }

    /// [`TabuSet::insert`] of the cell `at` in the rows layout, unchecked (as
    /// [`TabuSet::around_at`]): ignored beyond the words.
    #[cfg(any(feature = "alloc", test))]
    #[inline(always)]
    pub fn insert_at(&mut self, at: Point) {
        if let Some(w) = self.rows.words.get_mut(usize::from(at.y).wrapping_add(1)) {
            *w |= 2u32.wrapping_shl(u32::from(at.x));
        }
    }

    /// The linear words, lent between two walks as the flood fill's visited set
    /// ([`crate::map::grid::Grid::reach_begin`]): the next walk's [`TabuSet::reset`] writes
    /// every word it reads (in the rows layout they are not the set's).
    #[inline]
    pub fn lend(&mut self) -> &mut [u32] {
        self.words
    }
}

#[cfg(test)]
mod tests {
    use super::{rows_words, TabuSet, ROWS_WIDTH};
    use crate::map::bitmap;
    use crate::map::dir::{DX, DY};
    use crate::map::grid::Point;
    use crate::rng::Xoshiro128pp;

    #[test]
    fn the_rows_layout_reads_as_the_linear_one() {
        // Random maps up to the widest the rows hold, random pruning marks (or none) and random
        // cells entered, by index and by point: every cell's membership, and every cell's
        // neighbourhood on the map by index and (unchecked) by point, read the same in both
        // layouts; and starting a walk again gives back the marks alone.
        let mut r = Xoshiro128pp::from_u64(3636);
        for case in 0..300 {
            let w = 1 + r.next_word() as usize % ROWS_WIDTH;
            let h = 1 + r.next_word() as usize % 40;
            let cells = w * h;
            let mut dead = vec![0u32; bitmap::words(cells)];
            if case % 3 != 0 {
                for i in 0..cells {
                    if r.next_word() % 5 == 0 {
                        bitmap::set(&mut dead, i);
                    }
                }
            }
            let dead: &[u32] = if case % 3 == 0 { &[] } else { &dead };
            let mut lin_words = vec![u32::MAX; bitmap::words(cells)];
            let mut row_words = vec![0x5555_5555u32; bitmap::words(cells)];
            // Junk in the spare words: the set must write every word it reads.
            let mut spare: Vec<u32> = (0..rows_words(cells) as u32)
                .map(|i| i.wrapping_mul(0x9E37_79B9) | 1)
                .collect();
            let mut lin = TabuSet::new(&mut lin_words);
            let mut rows = TabuSet::new(&mut row_words).with_rows(&mut spare, w, h, dead);
            assert!(rows.is_rows() && !lin.is_rows());
            for round in 0..2 {
                lin.reset(cells, dead);
                rows.reset(cells, dead);
                for _ in 0..r.next_word() as usize % (cells + 1) {
                    let i = r.next_word() as usize % cells;
                    lin.insert(i);
                    if r.next_word() % 2 == 0 {
                        rows.insert(i);
                    } else {
                        let at = Point::new((i % w) as u16, (i / w) as u16);
                        rows.insert_at(at);
                    }
                }
                for i in 0..cells {
                    assert_eq!(rows.contains(i), lin.contains(i), "{w}x{h} cell {i}");
                    let (x, y) = ((i % w) as i32, (i / w) as i32);
                    let on_map = (0..8)
                        .filter(|&d| {
                            let (nx, ny) = (x + DX[d], y + DY[d]);
                            nx >= 0 && ny >= 0 && nx < w as i32 && ny < h as i32
                        })
                        .fold(0u8, |m, d| m | 1 << d);
                    let want = lin.around(i, w) & on_map;
                    assert_eq!(
                        rows.around(i, w) & on_map,
                        want,
                        "{w}x{h} cell {i}, {round}"
                    );
                    let at = Point::new(x as u16, y as u16);
                    assert_eq!(rows.around_at(at) & on_map, want, "{w}x{h} at {at:?}");
                }
                // Beyond the map: in the set, and never entered.
                assert!(rows.contains(cells) && rows.contains(usize::MAX));
                rows.insert(cells);
                assert!((0..cells).all(|i| rows.contains(i) == lin.contains(i)));
            }
        }
    }

    #[test]
    fn a_map_the_rows_do_not_hold_stays_linear() {
        // Too wide, or spare words too short: linear, and read as such.
        let (w, h) = (ROWS_WIDTH + 1, 4);
        let mut words = vec![0u32; bitmap::words(w * h)];
        let mut spare = vec![0u32; rows_words(w * h)];
        let mut t = TabuSet::new(&mut words).with_rows(&mut spare, w, h, &[]);
        assert!(!t.is_rows());
        t.insert(40);
        assert!(t.contains(40) && !t.contains(39));
        let mut short = vec![0u32; 2 * (h + 2) - 1];
        let mut words = vec![0u32; 1];
        assert!(!TabuSet::new(&mut words)
            .with_rows(&mut short, 3, h, &[])
            .is_rows());
        assert!(!TabuSet::new(&mut words)
            .with_rows(&mut short, 0, h, &[])
            .is_rows());
    }

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
