//! The occupancy grid: cells, the eight moves and the no-corner-cutting rule.
//!
//! A map is `width x height` cells stored row-major, one bit per cell, least significant bit
//! first (`bit i` of the buffer is cell `(i % width, i / width)`), `1` = blocked, `0` = free.
//! This is also the layout the wire protocol sends. `x` grows to the right, `y` grows downwards
//! (as in Moving AI maps: `(0, 0)` is the first character of the first row).
//!
//! Moves: the 8 neighbours ([`crate::map::dir`]). A diagonal move is allowed only when both orthogonally adjacent cells
//! are free, so a path never squeezes between two obstacles that touch at a corner.
//!
//! The grid borrows its bits, so it costs nothing to build over a `static` buffer on the device or
//! a `Vec` on the host.

use crate::error::Error;

// Cell indices are computed in `usize` from `u16` coordinates: `y * width + x` is at most
// `65535 * 65535 + 65535 < 2^32`, so with a `usize` of 32 bits or more the wrapping arithmetic
// below never actually wraps.
const _: () = assert!(
    usize::BITS >= 32,
    "cell indices need a usize of at least 32 bits"
);

/// A cell coordinate. `x` = column, `y` = row from the top. Four bytes, no padding
/// (`bytemuck::Pod`: a compact workspace carves its path cells out of an arena of words,
/// `crate::planner::arena`).
#[derive(
    Clone,
    Copy,
    Debug,
    PartialEq,
    Eq,
    Hash,
    PartialOrd,
    Ord,
    Default,
    bytemuck::Pod,
    bytemuck::Zeroable,
)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[repr(C)]
pub struct Point {
    /// Column, 0 = leftmost.
    pub x: u16,
    /// Row, 0 = top.
    pub y: u16,
}

impl Point {
    /// A point at column `x`, row `y`.
    pub const fn new(x: u16, y: u16) -> Self {
        Point { x, y }
    }
}

pub use crate::map::dir::{is_diagonal, opposite, Dir, DX, DY};

/// A borrowed occupancy grid. See the module docs for the bit layout.
#[derive(Clone, Copy, Debug)]
pub struct Grid<'a> {
    width: u16,
    height: u16,
    bits: &'a [u8],
}

/// Bytes needed to hold `cells` bits.
pub const fn bytes_for(cells: usize) -> usize {
    crate::map::bits::bytes(cells)
}

impl<'a> Grid<'a> {
    /// A grid over `bits` (see the module docs). Fails with [`Error::BadMap`] if a side is zero or
    /// `bits` holds fewer than `width * height` bits.
    pub fn new(width: u16, height: u16, bits: &'a [u8]) -> Result<Self, Error> {
        let cells = usize::from(width)
            .checked_mul(usize::from(height))
            .ok_or(Error::BadMap)?;
        if cells == 0 || bits.len() < bytes_for(cells) {
            return Err(Error::BadMap);
        }
        Ok(Grid {
            width,
            height,
            bits,
        })
    }

    /// Columns.
    #[inline]
    pub fn width(&self) -> u16 {
        self.width
    }

    /// Rows.
    #[inline]
    pub fn height(&self) -> u16 {
        self.height
    }

    /// `width * height`.
    #[inline]
    pub fn cells(&self) -> usize {
        // < 2^32: see the index note at the top of the module.
        usize::from(self.width).wrapping_mul(usize::from(self.height))
    }

    /// The bit buffer this grid reads.
    pub fn bits(&self) -> &'a [u8] {
        self.bits
    }

    /// True if `p` lies inside the map.
    #[inline]
    pub fn contains(&self, p: Point) -> bool {
        p.x < self.width && p.y < self.height
    }

    /// Row-major index of `p` (which must be inside the map for the result to mean anything).
    #[inline]
    pub fn index(&self, p: Point) -> usize {
        // < 2^32 for any `p`: see the index note at the top of the module.
        usize::from(p.y)
            .wrapping_mul(usize::from(self.width))
            .wrapping_add(usize::from(p.x))
    }

    /// The point with row-major index `i`.
    #[inline]
    pub fn point(&self, i: usize) -> Point {
        let w = usize::from(self.width);
        // Both quotients fit in u16 for every index below `cells()`; larger ones are clamped.
        // `w > 0` (checked in `Grid::new`), so the `checked_` forms never fail.
        let clamp = |v: Option<usize>| v.and_then(|v| u16::try_from(v).ok()).unwrap_or(u16::MAX);
        Point::new(clamp(i.checked_rem(w)), clamp(i.checked_div(w)))
    }

    /// True if cell index `i` is blocked; indices outside the map count as blocked.
    #[inline]
    fn blocked_index(&self, i: usize) -> bool {
        crate::map::bits::get(self.bits, i).unwrap_or(true)
    }

    /// True if cell index `i` is blocked or beyond the map's bits.
    #[inline]
    pub fn blocked_at(&self, i: usize) -> bool {
        self.blocked_index(i)
    }

    /// True if `p` is inside the map and free.
    #[inline]
    pub fn is_free(&self, p: Point) -> bool {
        self.contains(p) && !self.blocked_index(self.index(p))
    }

    /// True if `(x, y)` is outside the map or blocked. Takes signed coordinates so callers can ask
    /// about cells one step beyond the border.
    #[inline]
    pub fn blocked_xy(&self, x: i32, y: i32) -> bool {
        if x < 0 || y < 0 || x >= i32::from(self.width) || y >= i32::from(self.height) {
            return true;
        }
        // Non-negative and inside the map, so the casts are lossless and `i < cells()`.
        let i = (y as usize)
            .wrapping_mul(usize::from(self.width))
            .wrapping_add(x as usize);
        self.blocked_index(i)
    }

    /// True if the cells `(x, y)` for `x` in `x0..=x1` are all on the map and free (also when the
    /// run is empty, `x0 > x1`, and `y` is on the map). Reads the map a byte at a time.
    pub fn run_free(&self, y: u16, x0: i32, x1: i32) -> bool {
        if y >= self.height || x0 < 0 || x1 >= i32::from(self.width) {
            return false;
        }
        if x0 > x1 {
            return true;
        }
        // On the map: both indices are below `cells` (see the index note at the top).
        let row = usize::from(y).wrapping_mul(usize::from(self.width));
        self.bits_clear(row.wrapping_add(x0 as usize), row.wrapping_add(x1 as usize))
    }

    /// True if the cells with indices `i0..=i1` (`i0 <= i1`) are all free; cells beyond the
    /// buffer count as blocked. Reads the map a byte at a time.
    #[inline]
    pub fn bits_clear(&self, i0: usize, i1: usize) -> bool {
        let (b0, b1) = (i0 >> 3, i1 >> 3);
        let first = 0xFFu8 << (i0 & 7) as u32;
        let last = 0xFFu8 >> (7u32.wrapping_sub(i1 as u32) & 7); // 7 - i1 % 8
        let byte = |k: usize| self.bits.get(k).copied().unwrap_or(0xFF);
        if b0 == b1 {
            return byte(b0) & first & last == 0;
        }
        if byte(b0) & first != 0 || byte(b1) & last != 0 {
            return false;
        }
        // The whole bytes in between.
        match self.bits.get(b0.wrapping_add(1)..b1) {
            Some(mid) => mid.iter().all(|&m| m == 0),
            None => false,
        }
    }

    /// Where move `d` from `p` leads, or `None` if the target is outside the map or blocked, or
    /// the move is a diagonal that would cut a corner.
    #[inline]
    pub fn step(&self, p: Point, d: Dir) -> Option<Point> {
        let di = usize::from(d & 7);
        let dx = DX.get(di).copied().unwrap_or(0);
        let dy = DY.get(di).copied().unwrap_or(0);
        // A u16 plus -1..=1: no i32 overflow.
        let x = i32::from(p.x).wrapping_add(dx);
        let y = i32::from(p.y).wrapping_add(dy);
        if self.blocked_xy(x, y) {
            return None;
        }
        if is_diagonal(d)
            && (self.blocked_xy(x, i32::from(p.y)) || self.blocked_xy(i32::from(p.x), y))
        {
            return None;
        }
        // Not blocked implies inside the map, so both fit in u16.
        Some(Point::new(x as u16, y as u16))
    }

    /// The allowed moves from `p` as a bit mask: bit `d` is set iff [`Grid::step`] in direction
    /// `d` succeeds. 0 for blocked or off-map cells.
    pub fn move_mask(&self, p: Point) -> u8 {
        if !self.is_free(p) {
            return 0;
        }
        (0..8u8)
            .filter(|&d| self.step(p, d).is_some())
            .fold(0, |m, d| m | (1 << d))
    }

    /// Row-major index offset of each direction on this grid (`dy * width + dx`).
    pub fn offsets(&self) -> [isize; 8] {
        // u16 -> isize is lossless on every target with a 32- or 64-bit isize.
        let w = self.width as isize;
        let mut o = [0isize; 8];
        for (d, slot) in o.iter_mut().enumerate() {
            let dx = DX.get(d).copied().unwrap_or(0) as isize;
            let dy = DY.get(d).copied().unwrap_or(0) as isize;
            // |dy|, |dx| <= 1 and w <= 65535: no overflow.
            *slot = dy.wrapping_mul(w).wrapping_add(dx);
        }
        o
    }

    /// The allowed-move mask of `p` (bit `d` set iff [`Grid::step`] allows move `d`), read from
    /// the 3 x 3 bits around `p` and a 512-entry table: the same value as [`Grid::move_mask`] at
    /// a fraction of the cost, for planners without a per-cell mask table.
    #[inline]
    pub fn mask_at(&self, p: Point) -> u8 {
        let (x, y) = (usize::from(p.x), usize::from(p.y));
        let (w, h) = (usize::from(self.width), usize::from(self.height));
        // Border cells (and cells off the map) take the slow path, which checks every side.
        if x == 0 || y == 0 || x.wrapping_add(1) >= w || y.wrapping_add(1) >= h {
            return self.move_mask(p);
        }
        // Interior: x - 1, y - 1 and the rows above and below exist. Each row's three bits start
        // at bit `(row * w + x - 1)`, which is below `cells`, so nothing here wraps.
        let top = y
            .wrapping_sub(1)
            .wrapping_mul(w)
            .wrapping_add(x)
            .wrapping_sub(1);
        self.interior_mask(top)
    }

    /// [`Grid::mask_at`] of a cell off the map's border whose 3 x 3 neighbourhood's top-left
    /// cell has index `top` (the caller has checked the border): for the loops that know it.
    #[inline(always)]
    pub(crate) fn interior_mask(&self, top: usize) -> u8 {
        let w = usize::from(self.width);
        let mid = top.wrapping_add(w);
        let bottom = mid.wrapping_add(w);
        let nb = self.three(top) | self.three(mid) << 3 | self.three(bottom) << 6;
        MASK9.get(nb & 511).copied().unwrap_or(0)
    }

    /// The blocked bits of cells `i..i + 57` (bit `k` = cell `i + k`; beyond the map's buffer:
    /// blocked; the top bits above 57 are 0), from one unaligned 8-byte read: the passes over
    /// the map's rows many cells at a time ([`Moves::fill`], [`Grid::free_window`]).
    #[inline]
    pub(crate) fn blocked_window(&self, i: usize) -> u64 {
        let b = i >> 3;
        let word = match self.bits.get(b..b.wrapping_add(8)) {
            Some(&[b0, b1, b2, b3, b4, b5, b6, b7]) => {
                u64::from_le_bytes([b0, b1, b2, b3, b4, b5, b6, b7])
            }
            _ => {
                let mut v = [0xFFu8; 8];
                for (k, slot) in v.iter_mut().enumerate() {
                    if let Some(&x) = self.bits.get(b.wrapping_add(k)) {
                        *slot = x;
                    }
                }
                u64::from_le_bytes(v)
            }
        };
        word >> (i & 7)
    }

    /// The free cells of row `y` around the run of 32 columns from `x0` as bits: bit `j` (0..=33)
    /// is column `x0 - 1 + j`; columns off the map (left of 0, right of the last) read as not
    /// free. For passes over the map 32 cells at a time ([`crate::colony::route`], [`crate::map::prune`]).
    #[inline]
    pub(crate) fn free_window(&self, y: usize, x0: usize) -> u64 {
        let w = usize::from(self.width);
        let row = y.wrapping_mul(w);
        let blocked = if x0 == 0 {
            self.blocked_window(row) << 1 | 1
        } else {
            self.blocked_window(row.wrapping_add(x0).wrapping_sub(1))
        };
        // The first bit past the row: column w, bit w - x0 + 1 (>= 2 for x0 < w).
        let end = w.wrapping_add(1).wrapping_sub(x0);
        let on_row = if end < 64 {
            !(u64::MAX << end)
        } else {
            u64::MAX
        };
        !blocked & on_row
    }

    /// The bits of a [`Grid::free_window`] from column `x0` that are cells of its run: bits
    /// `1..=n` for the `n = min(32, width - x0)` columns `x0..x0 + n` (`x0 < width`).
    #[inline]
    pub(crate) fn run_bits(&self, x0: usize) -> u64 {
        let n = usize::from(self.width).wrapping_sub(x0).min(32);
        (1u64 << n).wrapping_sub(1) << 1
    }

    /// The blocked bits of cells `i`, `i + 1`, `i + 2` (bits 0-2; beyond the map: blocked).
    #[inline]
    fn three(&self, i: usize) -> usize {
        let b = i >> 3;
        let pair = match self.bits.get(b..b.wrapping_add(2)) {
            Some(&[lo, hi]) => usize::from(hi) << 8 | usize::from(lo),
            // The last byte of the buffer (or none): what lies beyond reads as blocked.
            _ => match self.bits.get(b) {
                Some(&lo) => 0xFF00 | usize::from(lo),
                None => 0xFFFF,
            },
        };
        (pair >> (i & 7)) & 7
    }

    /// Flood fill from `start` over allowed moves: is `goal` reachable?
    ///
    /// `scratch` ([`FillScratch`]) holds the marks, a bit set of at least
    /// [`crate::map::bitmap::words`]`(cells)` words, and the queue, a ring of cell indices of any
    /// length. A breadth-first frontier longer than the ring cannot be held, and the answer is
    /// then [`Reach::Unknown`] (the planner's first backtracking ant decides instead).
    ///
    /// The fill follows the four straight moves only: a diagonal move is allowed only when both
    /// cells beside it are free, and then the two straight moves through either of them reach the
    /// same cell, so the cells reachable with the eight moves are exactly those reachable with the
    /// four. The marks start as a copy of the map's blocked bits (the same bit order), so one
    /// test-and-set per neighbour both skips obstacles and marks the cell.
    pub fn reachable(&self, start: Point, goal: Point, mut scratch: FillScratch<'_>) -> Reach {
        match self.reach_begin(start, goal, &mut scratch) {
            Err(decided) => decided,
            Ok(mut fill) => loop {
                if let Some(r) = self.reach_resume(goal, &mut scratch, &mut fill, usize::MAX) {
                    return r;
                }
            },
        }
    }

    /// [`Grid::reachable`] a piece at a time: mark the blocked cells (a pass over the marks'
    /// words) and queue the start; `Err` when that decides already (a blocked end, no room).
    /// Then [`Grid::reach_resume`] with the same buffers until it answers.
    pub fn reach_begin(
        &self,
        start: Point,
        goal: Point,
        scratch: &mut FillScratch<'_>,
    ) -> Result<Filling, Reach> {
        let FillScratch {
            marks: mark,
            ring: queue,
        } = scratch;
        let cells = self.cells();
        if !self.is_free(start) || !self.is_free(goal) {
            return Err(Reach::No);
        }
        let cap = queue.len();
        let Some(mark) = mark.get_mut(..crate::map::bitmap::words(cells)) else {
            return Err(Reach::Unknown);
        };
        if cap == 0 {
            return Err(Reach::Unknown);
        }
        // Blocked cells start marked (bytes beyond the buffer read as blocked; bits beyond the
        // map are never asked about: the fill stays on the map).
        for (k, m) in mark.iter_mut().enumerate() {
            let b = k.wrapping_mul(4); // < bytes_for(cells) + 4: no wrap
            *m = match self.bits.get(b..b.wrapping_add(4)) {
                Some(&[b0, b1, b2, b3]) => u32::from_le_bytes([b0, b1, b2, b3]),
                _ => {
                    let byte = |i: usize| self.bits.get(b.wrapping_add(i)).copied().unwrap_or(0xFF);
                    u32::from_le_bytes([byte(0), byte(1), byte(2), byte(3)])
                }
            };
        }
        let si = self.index(start);
        crate::map::bitmap::set(mark, si);
        if let Some(s) = queue.get_mut(0) {
            *s = si as u32; // < cells < 2^32
        }
        Ok(Filling { head: 0, len: 1 })
    }

    /// Go on with the fill at `fill` ([`Grid::reach_begin`]) for at most `limit` cells taken
    /// from the queue: `Some` with the answer, `None` when it paused (resume with the same
    /// buffers). The pieces answer as one [`Grid::reachable`].
    pub fn reach_resume(
        &self,
        goal: Point,
        scratch: &mut FillScratch<'_>,
        fill: &mut Filling,
        limit: usize,
    ) -> Option<Reach> {
        let FillScratch {
            marks: mark,
            ring: queue,
        } = scratch;
        if !self.is_free(goal) {
            return Some(Reach::No);
        }
        let cells = self.cells();
        let cap = queue.len();
        // Ring buffer: `head` is the next to pop, `len` how many are queued (both < cap).
        let Filling { mut head, mut len } = *fill;
        let mut left = limit;
        let gi = self.index(goal);
        let w = usize::from(self.width);
        // Cells of the first and last row: no neighbour above / below.
        let last_row = cells.wrapping_sub(w); // cells >= w
        while len > 0 {
            if left == 0 {
                *fill = Filling { head, len };
                return None;
            }
            left = left.wrapping_sub(1);
            let Some(&i) = queue.get(head) else { break };
            head = head.wrapping_add(1);
            if head == cap {
                head = 0;
            }
            len = len.wrapping_sub(1); // > 0
            let i = i as usize;
            if i == gi {
                return Some(Reach::Yes);
            }
            // `w > 0` (checked in `Grid::new`), so the remainder exists.
            let x = i.checked_rem(w).unwrap_or(0);
            // W, E, N, S; a missing side repeats the cell itself (already marked).
            let next = [
                if x > 0 { i.wrapping_sub(1) } else { i },
                if x.wrapping_add(1) < w {
                    i.wrapping_add(1)
                } else {
                    i
                },
                if i >= w { i.wrapping_sub(w) } else { i },
                if i < last_row { i.wrapping_add(w) } else { i },
            ];
            for ni in next {
                if crate::map::bitmap::insert(mark, ni) {
                    if len == cap {
                        return Some(Reach::Unknown);
                    }
                    // head < cap and len < cap: the sum is below 2 cap, one subtraction wraps it.
                    let mut t = head.wrapping_add(len);
                    if t >= cap {
                        t = t.wrapping_sub(cap);
                    }
                    if let Some(s) = queue.get_mut(t) {
                        *s = ni as u32;
                    }
                    len = len.wrapping_add(1);
                }
            }
        }
        Some(Reach::No)
    }
}

/// A flood fill's scratch over lent words: the marks (a bit a cell, the map's blocked cells and
/// the cells reached) and the ring of queued cell indices (a cell a word, any length). Two
/// buffers of the same element type, named here so that a caller cannot swap them.
#[derive(Debug)]
pub struct FillScratch<'a> {
    marks: &'a mut [u32],
    ring: &'a mut [u32],
}

impl<'a> FillScratch<'a> {
    /// The scratch over `marks` and `ring` ([`Grid::reachable`] says what each must hold).
    #[inline]
    pub fn new(marks: &'a mut [u32], ring: &'a mut [u32]) -> Self {
        Self { marks, ring }
    }
}

/// Where a flood fill ([`Grid::reach_begin`], [`Grid::reach_resume`]) stands between pieces: its
/// queue's head and length (the marks and the queue hold the rest).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Filling {
    head: usize,
    len: usize,
}

/// The cell one move `d` from `p`, without checks (callers move along allowed moves only; a move
/// off the map's edge wraps to the far end of the `u16` range, which no map contains).
#[inline]
pub fn neighbour(p: Point, d: Dir) -> Point {
    let di = usize::from(d & 7);
    // A u16 plus -1..=1: no i32 overflow.
    let x = i32::from(p.x).wrapping_add(DX.get(di).copied().unwrap_or(0));
    let y = i32::from(p.y).wrapping_add(DY.get(di).copied().unwrap_or(0));
    Point::new(x as u16, y as u16)
}

/// The move from `a` to `b` if they are 8-neighbours (`neighbour(a, d) == b`), else `None`.
pub fn direction(a: Point, b: Point) -> Option<Dir> {
    let dx = i32::from(b.x).wrapping_sub(i32::from(a.x));
    let dy = i32::from(b.y).wrapping_sub(i32::from(a.y));
    (0..8u8).find(|&d| DX.get(usize::from(d)) == Some(&dx) && DY.get(usize::from(d)) == Some(&dy))
}

/// Allowed-move masks, read from a per-cell table when the caller has one (one byte a cell,
/// [`Grid::move_mask`] of every cell) and computed with [`Grid::mask_at`] otherwise: the same
/// values either way, so the choice changes speed and memory, never a path.
#[derive(Clone, Copy, Debug)]
pub struct Moves<'g> {
    grid: Grid<'g>,
    table: &'g [u8],
}

impl<'g> Moves<'g> {
    /// Masks of `grid`, from `table` if it holds one entry per cell (else computed).
    pub fn new(grid: Grid<'g>, table: &'g [u8]) -> Self {
        let table = if table.len() >= grid.cells() {
            table
        } else {
            &[]
        };
        Moves { grid, table }
    }

    /// Fill `table` with the mask of every cell of `grid` (if it is long enough; returns whether
    /// it was).
    pub fn fill(grid: &Grid<'_>, table: &mut [u8]) -> bool {
        let Some(t) = table.get_mut(..grid.cells()) else {
            return false;
        };
        // Row by row: the border cells through `move_mask`, the interior sixteen cells at a
        // time from one read of each of the three rows (`Grid::blocked_window`) and `MASK9`: about
        // ten instructions a cell on the Cortex-M4 where `mask_at` per cell took about 150 (the
        // table of a 256 x 256 map cost 10 M instructions, a ninth of a plan; issue 27). The
        // values are `mask_at`'s (unit test `fill_is_mask_at`).
        let (w, h) = (usize::from(grid.width), usize::from(grid.height));
        for y in 0..h {
            let row0 = y.wrapping_mul(w); // < cells
            let Some(row) = t.get_mut(row0..row0.wrapping_add(w)) else {
                return false;
            };
            let interior = y > 0 && y.wrapping_add(1) < h && w > 2;
            if !interior {
                for (x, m) in row.iter_mut().enumerate() {
                    *m = grid.move_mask(Point::new(x as u16, y as u16));
                }
                continue;
            }
            if let Some(m) = row.first_mut() {
                *m = grid.move_mask(Point::new(0, y as u16));
            }
            let last = w.wrapping_sub(1); // w > 2
            if let Some(m) = row.get_mut(last) {
                *m = grid.move_mask(Point::new(last as u16, y as u16));
            }
            // Cells x in 1..last, sixteen at a time: bit k of each read is cell x - 1 + k.
            let mut x = 1usize;
            while x < last {
                let n = last.wrapping_sub(x).min(16);
                // Interior row: the rows above and below exist, and x - 1 >= 0.
                let i = row0.wrapping_add(x).wrapping_sub(1);
                let top = grid.blocked_window(i.wrapping_sub(w));
                let mid = grid.blocked_window(i);
                let bottom = grid.blocked_window(i.wrapping_add(w));
                if let Some(out) = row.get_mut(x..x.wrapping_add(n)) {
                    for (k, m) in out.iter_mut().enumerate() {
                        // k < 16: shifts below 32.
                        let nb =
                            ((top >> k) & 7) | ((mid >> k) & 7) << 3 | ((bottom >> k) & 7) << 6;
                        *m = MASK9.get((nb & 511) as usize).copied().unwrap_or(0);
                    }
                }
                x = x.wrapping_add(n);
            }
        }
        true
    }

    /// The mask of cell `p`, whose index is `ci`.
    #[inline]
    pub fn at(&self, ci: usize, p: Point) -> u8 {
        match self.table.get(ci) {
            Some(&m) => m,
            None => self.grid.mask_at(p),
        }
    }

    /// The table's mask of cell `ci` (`None`: no table; [`Moves::at`] works it out).
    #[inline(always)]
    pub(crate) fn table_at(&self, ci: usize) -> Option<u8> {
        self.table.get(ci).copied()
    }

    /// The grid.
    #[inline]
    pub fn grid(&self) -> &Grid<'g> {
        &self.grid
    }
}

/// The answer of [`Grid::reachable`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reach {
    /// The goal is reachable.
    Yes,
    /// The goal is not reachable (or an endpoint is blocked).
    No,
    /// The flood fill's queue overflowed before it could decide.
    Unknown,
}

/// Allowed-move mask from the centre of a 3 x 3 neighbourhood, indexed by its blocked bits
/// (bit `3 r + c` = cell `(x - 1 + c, y - 1 + r)`): the no-corner-cutting rule as a table.
#[allow(clippy::indexing_slicing, clippy::arithmetic_side_effects)]
static MASK9: [u8; 512] = {
    let mut t = [0u8; 512];
    const fn blocked(nb: usize, c: i32, r: i32) -> bool {
        (nb >> ((r * 3 + c) as usize)) & 1 == 1
    }
    let mut nb = 0usize;
    while nb < 512 {
        let mut m = 0u8;
        if !blocked(nb, 1, 1) {
            let mut d = 0usize;
            while d < 8 {
                let (dx, dy) = (DX[d], DY[d]);
                let ok = !blocked(nb, 1 + dx, 1 + dy)
                    && (dx == 0 || dy == 0 || (!blocked(nb, 1 + dx, 1) && !blocked(nb, 1, 1 + dy)));
                if ok {
                    m |= 1 << d;
                }
                d += 1;
            }
        }
        t[nb] = m;
        nb += 1;
    }
    t
};

#[cfg(test)]
mod tests {
    use super::*;

    fn grid_from(rows: &[&str], buf: &mut [u8]) -> (u16, u16) {
        let w = rows[0].len();
        for (y, r) in rows.iter().enumerate() {
            for (x, c) in r.chars().enumerate() {
                if c == '#' {
                    let i = y * w + x;
                    buf[i / 8] |= 1 << (i % 8);
                }
            }
        }
        (w as u16, rows.len() as u16)
    }

    #[test]
    fn the_blocked_window_reads_its_cells_and_blocked_past_the_end() {
        // Every start over seven bytes of a pattern (a 56 x 1 map) and its low 32 bits, against
        // one read a cell (beyond the buffer: blocked).
        let b = [0b1011_0010u8, 0xFF, 0x00, 0b0101_0101, 0x3C, 0x81, 0x7E];
        let g = Grid::new(56, 1, &b).unwrap();
        for i in 0..64 {
            let got = g.blocked_window(i) as u32;
            for k in 0..32 {
                let want = crate::map::bits::get(&b, i + k).unwrap_or(true);
                assert_eq!(got >> k & 1 == 1, want, "blocked_window({i}) bit {k}");
            }
        }
    }

    #[test]
    fn rejects_empty_and_short_maps() {
        assert_eq!(Grid::new(0, 3, &[0; 4]).unwrap_err(), Error::BadMap);
        assert_eq!(Grid::new(5, 5, &[0; 3]).unwrap_err(), Error::BadMap);
        assert!(Grid::new(5, 5, &[0; 4]).is_ok());
    }

    #[test]
    fn diagonal_needs_both_sides_free() {
        let mut b = [0u8; 2];
        let (w, h) = grid_from(&["..", "#."], &mut b);
        let g = Grid::new(w, h, &b).unwrap();
        // (0,0) -> (1,1) is SE; (0,1) is blocked, so the move cuts a corner.
        assert_eq!(g.step(Point::new(0, 0), 1), None);
        assert_eq!(g.step(Point::new(0, 0), 0), Some(Point::new(1, 0)));
        assert_eq!(g.step(Point::new(1, 0), 2), Some(Point::new(1, 1)));
        // Off the map.
        assert_eq!(g.step(Point::new(0, 0), 4), None);
    }

    #[test]
    fn flood_fill_sees_diagonal_walls() {
        // A diagonal wall of touching obstacles separates the corners.
        let mut b = [0u8; 2];
        let (w, h) = grid_from(&["..#", ".#.", "#.."], &mut b);
        let g = Grid::new(w, h, &b).unwrap();
        let mut m = [0u32; 1];
        let mut q = [0u32; 9];
        assert_eq!(
            g.reachable(
                Point::new(0, 0),
                Point::new(2, 2),
                FillScratch::new(&mut m, &mut q)
            ),
            Reach::No
        );
        assert_eq!(
            g.reachable(
                Point::new(0, 0),
                Point::new(0, 1),
                FillScratch::new(&mut m, &mut q)
            ),
            Reach::Yes
        );
        // A ring too short for the frontier cannot decide.
        let open = Grid::new(8, 8, &[0; 8]).unwrap();
        let mut m = [0u32; 2];
        let mut q = [0u32; 2];
        assert_eq!(
            open.reachable(
                Point::new(0, 0),
                Point::new(7, 7),
                FillScratch::new(&mut m, &mut q)
            ),
            Reach::Unknown
        );
    }

    #[test]
    fn flood_fill_agrees_with_eight_moves() {
        // Random maps (about 40 % blocked), every start and goal: the four-move fill decides
        // like a breadth-first search over the eight allowed moves.
        let mut x = 0x2545_F491u32;
        for (w, h) in [(10u16, 10u16), (7, 13), (16, 4)] {
            for _ in 0..20 {
                let cells = usize::from(w) * usize::from(h);
                let mut b = vec![0u8; cells.div_ceil(8)];
                for i in 0..cells {
                    x ^= x << 13;
                    x ^= x >> 17;
                    x ^= x << 5;
                    if x % 5 < 2 {
                        b[i / 8] |= 1 << (i % 8);
                    }
                }
                let g = Grid::new(w, h, &b).unwrap();
                let mut mark = vec![0u32; crate::map::bitmap::words(cells)];
                let mut queue = vec![0u32; cells];
                for s in 0..cells {
                    // Eight-move BFS from s.
                    let mut seen = vec![false; cells];
                    let mut todo = vec![g.point(s)];
                    seen[s] = g.is_free(g.point(s));
                    while let Some(p) = todo.pop() {
                        if !g.is_free(p) {
                            continue;
                        }
                        for d in 0..8 {
                            if let Some(q) = g.step(p, d) {
                                if !seen[g.index(q)] {
                                    seen[g.index(q)] = true;
                                    todo.push(q);
                                }
                            }
                        }
                    }
                    for (t, &seen_t) in seen.iter().enumerate().take(cells) {
                        let want = if seen_t && g.is_free(g.point(t)) {
                            Reach::Yes
                        } else {
                            Reach::No
                        };
                        let got = g.reachable(
                            g.point(s),
                            g.point(t),
                            FillScratch::new(&mut mark, &mut queue),
                        );
                        assert_eq!(got, want, "{w}x{h} {:?} -> {:?}", g.point(s), g.point(t));
                    }
                }
            }
        }
    }

    #[test]
    fn mask_at_is_move_mask() {
        // Every cell of random maps: the table agrees with the rule written out.
        let mut x = 0x1234_5678u32;
        for _ in 0..50 {
            let mut b = [0u8; 13];
            for byte in &mut b {
                x ^= x << 13;
                x ^= x >> 17;
                x ^= x << 5;
                *byte = (x & (x >> 8)) as u8; // about 25 % blocked
            }
            let g = Grid::new(10, 10, &b).unwrap();
            for i in 0..100 {
                let p = g.point(i);
                assert_eq!(g.mask_at(p), g.move_mask(p), "at {p:?}");
            }
        }
    }

    #[test]
    fn fill_is_mask_at() {
        // Every cell of random maps of many shapes (rows of 1 to 70 cells: a border only, one
        // group of sixteen and a part, several groups, rows not a whole number of bytes), with
        // and without slack bytes after the map: the fast table is the rule written out.
        let mut x = 0x9E37_79B9u32;
        for (w, h) in [
            (1, 1),
            (1, 5),
            (2, 3),
            (3, 3),
            (5, 4),
            (17, 9),
            (18, 3),
            (33, 7),
            (70, 11),
        ] {
            for slack in [0usize, 5] {
                for _ in 0..10 {
                    let cells = usize::from(w) * usize::from(h);
                    let mut b = vec![0u8; cells.div_ceil(8) + slack];
                    for byte in &mut b {
                        x ^= x << 13;
                        x ^= x >> 17;
                        x ^= x << 5;
                        *byte = (x & (x >> 8)) as u8; // about 25 % blocked
                    }
                    let g = Grid::new(w, h, &b).unwrap();
                    let mut table = vec![0xAAu8; cells];
                    assert!(Moves::fill(&g, &mut table));
                    for (i, &m) in table.iter().enumerate() {
                        let p = g.point(i);
                        assert_eq!(m, g.move_mask(p), "{w} x {h} at {p:?}");
                    }
                }
            }
        }
        // A table too short is refused, untouched.
        let g = Grid::new(4, 4, &[0; 2]).unwrap();
        let mut short = [7u8; 15];
        assert!(!Moves::fill(&g, &mut short));
        assert_eq!(short, [7; 15]);
    }

    #[test]
    fn index_and_point_round_trip() {
        let g = Grid::new(7, 3, &[0; 3]).unwrap();
        for i in 0..21 {
            assert_eq!(g.index(g.point(i)), i);
        }
    }
}
