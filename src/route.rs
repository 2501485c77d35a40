//! The coarse route on large maps: where the potential field pulls.
//!
//! The paper's goal attraction (eqs. 6-10) pulls every ant straight towards the goal. On a small
//! map that is what makes OHACA fast; on a large one it is the classic weakness of artificial
//! potential fields: the straight pull leads into every courtyard, dead-end street and U-shaped
//! wall that faces the goal, and a backtracking ant explores each of them before it finds the way
//! around (on a 256 x 256 city map an ant made ten times as many moves as its path has steps).
//!
//! On maps with more cells than [`crate::pheromone::BLOCKS`], the map is cut into the same
//! square blocks as the pheromone, and before any ant runs:
//!
//! 1. **Connectivity**: block `B` links to a neighbouring block `B'` when some live cell of `B`
//!    has an allowed move into a live cell of `B'` (pruned cells do not count). This
//!    over-approximates the map (a block's free cells need not be connected inside it), so a route
//!    exists on blocks whenever one exists on cells.
//! 2. **Distances**: Dijkstra from the goal's block over the links, 10 per straight and 14 per
//!    diagonal block step.
//! 3. **Sub-goals**: an ant in block `B` is pulled towards the centre of the block [`LOOKAHEAD`]
//!    links further down the route (or the goal itself once that is closer). The attraction is
//!    the paper's, unchanged (`a^(xi (d(j, T) - d(i, T)))` with the octile distance), with the
//!    sub-goal `T` in place of the goal `G`: a potential field that follows the coarse geodesic
//!    distance, so it has no local minimum larger than a block.
//!
//! The ants still walk cells, with their tabu list and backtracking, so a wrong sub-goal (a block
//! whose free cells do not connect) costs moves, never a path. Memory: one `u32` per block (the
//! links, the next block and the distance) plus scratch for the heap (two `u32` per block).

use crate::grid::{Moves, Point, DX, DY};
use crate::pheromone::Blocks;

/// Most blocks of the route: a map with more cells than this is cut into blocks of `2^k x 2^k`
/// cells (the smallest `k` that gives at most this many), a smaller one routes on cells.
pub const GUIDE_BLOCKS: usize = 4096;

/// How many blocks ahead on the route an ant's sub-goal lies.
pub const LOOKAHEAD: u32 = 2;

/// Per-block word: bits 0-7 links (bit `d`: the neighbour block in direction `d`), bits 8-11 the
/// next block's direction (`NONE`: the goal's block or no route), bits 12-31 the distance.
const NONE: u32 = 8;
const DIST_SHIFT: u32 = 12;
const UNREACHED: u32 = u32::MAX >> DIST_SHIFT;

/// The coarse route of a run: the per-block words (or their [`pack`]ed next blocks) and what
/// reads them.
#[derive(Clone, Copy, Debug)]
pub struct Route<'a> {
    blocks: Blocks,
    words: &'a [u32],
    /// `words` holds four bits a block ([`pack`]), not a word.
    packed: bool,
    goal: Point,
    width: u16,
    height: u16,
}

impl<'a> Route<'a> {
    /// A route over the per-block words [`build`] wrote.
    pub fn new(blocks: Blocks, words: &'a [u32], goal: Point, width: u16, height: u16) -> Self {
        Route {
            blocks,
            words,
            packed: false,
            goal,
            width,
            height,
        }
    }

    /// A route over the next blocks [`pack`] kept of [`build`]'s words: the same targets.
    pub fn packed(
        blocks: Blocks,
        nibbles: &'a [u32],
        goal: Point,
        width: u16,
        height: u16,
    ) -> Self {
        Route {
            packed: true,
            ..Route::new(blocks, nibbles, goal, width, height)
        }
    }

    /// The block of cell `p`.
    #[inline]
    pub fn block(&self, p: Point) -> usize {
        self.blocks.block(p)
    }

    /// The point the potential field pulls towards from cell `p`.
    #[inline]
    pub fn target(&self, p: Point) -> Point {
        if self.packed {
            // Out of line: the word-a-block form below stays as the ants' loop inlines it.
            return self.target_packed(p);
        }
        self.target_by(p, |b| self.words.get(b).map_or(NONE, |w| (w >> 8) & 15))
    }

    /// [`Route::target`] on a [`pack`]ed route.
    #[inline(never)]
    fn target_packed(&self, p: Point) -> Point {
        self.target_by(p, |b| {
            let shift = ((b & 7) as u32).wrapping_mul(4);
            self.words.get(b >> 3).map_or(NONE, |w| (w >> shift) & 15)
        })
    }

    /// [`Route::target`] with `next(b)`: block `b`'s next block's direction (`NONE`: the goal's
    /// block or no route).
    #[inline(always)]
    fn target_by(&self, p: Point, next: impl Fn(usize) -> u32) -> Point {
        let s = self.blocks.shift();
        let (mut bx, mut by) = (i32::from(p.x >> s), i32::from(p.y >> s));
        let across = self.blocks.across();
        for _ in 0..LOOKAHEAD {
            // Block coordinates are below 2^16: the index fits.
            let b = (by as usize).wrapping_mul(across).wrapping_add(bx as usize);
            let next = next(b);
            if next >= NONE {
                return self.goal;
            }
            let d = next as usize & 7;
            bx = bx.wrapping_add(DX.get(d).copied().unwrap_or(0));
            by = by.wrapping_add(DY.get(d).copied().unwrap_or(0));
        }
        // The centre of that block, on the map (the last block of a row may be cut short).
        let half = (1i32 << s) >> 1;
        let cx = (bx << s)
            .wrapping_add(half)
            .min(i32::from(self.width).wrapping_sub(1));
        let cy = (by << s)
            .wrapping_add(half)
            .min(i32::from(self.height).wrapping_sub(1));
        Point::new(cx.max(0) as u16, cy.max(0) as u16)
    }
}

/// The block layout of the route of a `width x height` map.
pub fn blocks(width: u16, height: u16) -> Blocks {
    Blocks::with_budget(width, height, GUIDE_BLOCKS)
}

/// Build the route to `goal`: links, distances and next blocks, into `words` (one per block of
/// `blocks`). `dead` marks pruned cells (empty: none); `heap` is scratch of one word per block. Returns false
/// (and no route: every ant pulled to the goal) if a buffer is too short.
pub fn build(
    moves: &Moves<'_>,
    blocks: Blocks,
    goal: Point,
    dead: &[u32],
    words: &mut [u32],
    heap: &mut [u32],
) -> bool {
    let n = blocks.count();
    if n > usize::from(u16::MAX) {
        return false;
    }
    let (Some(words), Some(heap)) = (words.get_mut(..n), heap.get_mut(..n)) else {
        return false;
    };
    links(moves, blocks, dead, words, None);
    for w in words.iter_mut() {
        *w = (*w & 0xFF) | (NONE << 8) | (UNREACHED << DIST_SHIFT);
    }
    dijkstra(blocks, blocks.block(goal), words, Heap { w: heap, len: 0 });
    true
}
/// Rebuild the route to `goal` after the pruning marks or the map changed inside `area` only:
/// `words` hold the links of the route [`build`] (or `repair`) made before, restored with
/// [`unstash`]. The links of the blocks within one cell of `area` (`None`: no cell changed) are
/// recomputed from the map, the rest are kept, and the distances and next blocks are computed
/// again (Dijkstra over the blocks: a few thousand words, where the links read every block's
/// border cells). The result is [`build`]'s on the map and marks as they are now, bit for bit
/// (a property test compares them). Returns false (and no route) if a buffer is too short.
pub fn repair(
    moves: &Moves<'_>,
    blocks: Blocks,
    goal: Point,
    dead: &[u32],
    words: &mut [u32],
    heap: &mut [u32],
    area: Option<(Point, Point)>,
) -> bool {
    let n = blocks.count();
    if n > usize::from(u16::MAX) {
        return false;
    }
    let (Some(words), Some(heap)) = (words.get_mut(..n), heap.get_mut(..n)) else {
        return false;
    };
    let grid = *moves.grid();
    let (w, h) = (grid.width(), grid.height());
    if let (Some((lo, hi)), true) = (area, w > 0 && h > 0) {
        // A block's links read its border cells and the cells one move beyond them: the blocks
        // within one cell of `area`.
        let s = blocks.shift();
        let region = Region {
            x0: usize::from(lo.x.saturating_sub(1) >> s),
            y0: usize::from(lo.y.saturating_sub(1) >> s),
            x1: usize::from(hi.x.saturating_add(1).min(w.wrapping_sub(1)) >> s),
            y1: usize::from(hi.y.saturating_add(1).min(h.wrapping_sub(1)) >> s),
        };
        links(moves, blocks, dead, words, Some(region));
    }
    for w in words.iter_mut() {
        *w = (*w & 0xFF) | (NONE << 8) | (UNREACHED << DIST_SHIFT);
    }
    dijkstra(blocks, blocks.block(goal), words, Heap { w: heap, len: 0 });
    true
}

/// Words [`pack`] needs for a route of `count` blocks: four bits a block.
pub const fn packed_words(count: usize) -> usize {
    count.div_ceil(8)
}

/// Keep of [`build`]'s `words` only what the ants read, each block's next block (four bits a
/// block, eight a word, block `b` in bits `4 (b % 8)` of word `b / 8`), in `out`: a route
/// ([`Route::packed`]) in an eighth of the words, whose full words (and heap) were scratch
/// (the compact arena builds them in its tabu bit set, idle before the first ant). The links
/// and distances are gone: such a route is built again, never [`repair`]ed. Returns false if
/// a buffer is too short.
pub fn pack(blocks: Blocks, words: &[u32], out: &mut [u32]) -> bool {
    let n = blocks.count();
    let (Some(words), Some(out)) = (words.get(..n), out.get_mut(..packed_words(n))) else {
        return false;
    };
    for (o, eight) in out.iter_mut().zip(words.chunks(8)) {
        *o = eight.iter().enumerate().fold(0, |acc, (k, w)| {
            acc | ((w >> 8) & 15).wrapping_shl((k as u32).wrapping_mul(4))
        });
    }
    true
}

/// `f32` slots [`stash`] needs for the links of `blocks`: two blocks a slot.
pub fn stash_len(blocks: Blocks) -> usize {
    blocks.count().div_ceil(2)
}

/// Keep the links of the route in `words` in `out` (at least [`stash_len`] slots of a buffer
/// that is free until the next run: the smoothing's unused pheromone increments), two blocks'
/// link bytes a slot as an integer below `2^16`, exact in an `f32`. Returns false if `out` is
/// too short.
pub fn stash(blocks: Blocks, words: &[u32], out: &mut [f32]) -> bool {
    let n = blocks.count();
    let (Some(words), Some(out)) = (words.get(..n), out.get_mut(..stash_len(blocks))) else {
        return false;
    };
    for (slot, pair) in out.iter_mut().zip(words.chunks(2)) {
        let lo = pair.first().map_or(0, |w| w & 0xFF);
        let hi = pair.get(1).map_or(0, |w| w & 0xFF);
        // Below 2^16: exact in an f32.
        *slot = (lo | hi << 8) as f32;
    }
    true
}

/// Put the links [`stash`] kept back into the low bytes of `words` (the rest of each word is
/// cleared). Returns false if a buffer is too short.
pub fn unstash(blocks: Blocks, kept: &[f32], words: &mut [u32]) -> bool {
    let n = blocks.count();
    let (Some(words), Some(kept)) = (words.get_mut(..n), kept.get(..stash_len(blocks))) else {
        return false;
    };
    for (pair, slot) in words.chunks_mut(2).zip(kept) {
        // An integer below 2^16 (see `stash`): the cast is exact.
        let v = *slot as u32;
        for (w, byte) in pair.iter_mut().zip([v & 0xFF, (v >> 8) & 0xFF]) {
            *w = byte;
        }
    }
    true
}

/// The links of block `(bx, by)`, cell by cell: the rule [`links`] computes 32 cells at a time,
/// kept as the tests' reference.
#[cfg(test)]
fn block_links(moves: &Moves<'_>, blocks: Blocks, dead: &[u32], bx: u16, by: u16) -> u8 {
    let grid = *moves.grid();
    let (w, h) = (grid.width(), grid.height());
    let s = blocks.shift();
    let last = (1u16 << s).wrapping_sub(1);
    let offsets = grid.offsets();
    let (x0, y0) = (u32::from(bx) << s, u32::from(by) << s);
    let x1 = (x0.wrapping_add(u32::from(last))).min(u32::from(w).wrapping_sub(1));
    let y1 = (y0.wrapping_add(u32::from(last))).min(u32::from(h).wrapping_sub(1));
    let mut out = 0u8;
    for y in y0..=y1 {
        let y = y as u16; // <= h - 1
        let border_row = y & last == 0 || y & last == last;
        let mut x = x0;
        while x <= x1 {
            let xs = x as u16; // <= w - 1
            let p = Point::new(xs, y);
            let ci = grid.index(p);
            if !crate::bitmap::marked(dead, ci) {
                let mut leaving = 0u8;
                if xs & last == 0 {
                    leaving |= 0x38;
                }
                if xs & last == last {
                    leaving |= 0x83;
                }
                if y & last == 0 {
                    leaving |= 0xE0;
                }
                if y & last == last {
                    leaving |= 0x0E;
                }
                let mut m = moves.at(ci, p) & leaving;
                while m != 0 {
                    let d = m.trailing_zeros() as usize & 7;
                    m &= m.wrapping_sub(1);
                    let ni = ci.wrapping_add_signed(offsets.get(d).copied().unwrap_or(0));
                    if crate::bitmap::marked(dead, ni) {
                        continue;
                    }
                    let q = crate::grid::neighbour(p, d as crate::grid::Dir);
                    out |= 1 << block_dir(p, q, s);
                }
            }
            // Inside a block's rows only its first and last columns can leave it.
            x = if border_row || x == x1 {
                x.wrapping_add(1)
            } else {
                x1
            };
        }
    }
    out
}

/// A rectangle of blocks, corners included (block coordinates).
#[derive(Clone, Copy, Debug)]
struct Region {
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
}

impl Region {
    #[inline]
    fn holds(&self, bx: usize, by: usize) -> bool {
        (self.x0..=self.x1).contains(&bx) && (self.y0..=self.y1).contains(&by)
    }
}

/// Bits 0-7 of each block's word in `region` (`None`: every block): the neighbour blocks one
/// allowed move away. The words of the region's blocks are overwritten (the bits above 7
/// cleared), every other word is left as it is.
///
/// Thirty-two cells at a time: for each pair of rows `y`, `y + 1` and each run of 32 columns, the
/// live cells (free, not pruned) and the free cells of both rows as bit windows, from which one
/// AND each gives every cell with a move east, south, south-east or south-west (both ends live;
/// a diagonal also needs the two cells beside it free: the no-corner-cutting rule). Only the
/// moves that cross a block side count, and each sets the link in both blocks (moves are
/// symmetric, so the north, west and north-west/-east links are these seen from the other end),
/// when they are in the region. A move crossing a side of a region's block starts (at its north
/// or west end) in the region's cells or one cell north, west or east of them: those are the
/// cells scanned. The result is the per-cell rule of `block_links` (the tests' reference) for
/// every block of the region, bit for bit (the tests `links_match_the_per_cell_rule` and
/// `links_of_a_region_match_the_per_cell_rule` compare them on random maps, block sizes and
/// regions); on the Cortex-M4 it takes a tenth of the per-cell pass it replaced (7 M
/// instructions of a 256 x 256 plan; issue 27).
fn links(
    moves: &Moves<'_>,
    blocks: Blocks,
    dead: &[u32],
    words: &mut [u32],
    region: Option<Region>,
) {
    let grid = *moves.grid();
    let (w, h) = (usize::from(grid.width()), usize::from(grid.height()));
    let s = u32::from(blocks.shift());
    let last = (1usize << s).wrapping_sub(1);
    let across = blocks.across();
    let down = blocks.count().checked_div(across).unwrap_or(0);
    if w == 0 || h == 0 || across == 0 || down == 0 {
        return;
    }
    let whole = Region {
        x0: 0,
        y0: 0,
        x1: across.wrapping_sub(1),
        y1: down.wrapping_sub(1),
    };
    let r = match region {
        Some(r) => Region {
            x0: r.x0,
            y0: r.y0,
            x1: r.x1.min(whole.x1),
            y1: r.y1.min(whole.y1),
        },
        None => whole,
    };
    if r.x0 > r.x1 || r.y0 > r.y1 {
        return;
    }
    for by in r.y0..=r.y1 {
        let row = by.wrapping_mul(across);
        if let Some(ws) =
            words.get_mut(row.wrapping_add(r.x0)..row.wrapping_add(r.x1).wrapping_add(1))
        {
            ws.fill(0);
        }
    }
    // The cells scanned: the region's, one more column on each side and one more row north.
    let (x_lo, x_hi) = (
        (r.x0 << s).saturating_sub(1),
        (r.x1.wrapping_add(1) << s).min(w.wrapping_sub(1)),
    );
    let (y_lo, y_hi) = (
        (r.y0 << s).saturating_sub(1),
        ((r.y1.wrapping_add(1) << s).wrapping_sub(1)).min(h.wrapping_sub(1)),
    );
    // The links of the block of cell (x, y) gain `d`, and the neighbour block's `d + 4`, if
    // they are in the region.
    let mut link = |x: usize, y: usize, d: u32| {
        let (dx, dy) = match d {
            0 => (1isize, 0usize),
            1 => (1, 1),
            2 => (0, 1),
            _ => (-1, 1),
        };
        let (bx, by) = (x >> s, y >> s);
        if r.holds(bx, by) {
            if let Some(wd) = words.get_mut(by.wrapping_mul(across).wrapping_add(bx)) {
                *wd |= 1 << d;
            }
        }
        let (nx, ny) = (bx.wrapping_add_signed(dx), by.wrapping_add(dy));
        if r.holds(nx, ny) {
            if let Some(wd) = words.get_mut(ny.wrapping_mul(across).wrapping_add(nx)) {
                *wd |= 1 << (d.wrapping_add(4) & 7);
            }
        }
    };
    // Bit j of a window is cell x0 - 1 + j of its row; cells off the row read as blocked.
    let window = |y: usize, x0: usize| -> (u64, u64) {
        let free = grid.free_window(y, x0);
        let row = y.wrapping_mul(w);
        let pruned = if dead.is_empty() {
            0
        } else if x0 == 0 {
            crate::bitmap::window(dead, row) << 1
        } else {
            crate::bitmap::window(dead, row.wrapping_add(x0).wrapping_sub(1))
        };
        (free, free & !pruned)
    };
    // Blocks of at most 32 columns start at multiples of 32 in every run: the same bits in all.
    let columns = block_columns(0, last);
    for y in y_lo..=y_hi {
        let below = y.wrapping_add(1) < h;
        let y_crosses = below && y & last == last;
        // Runs start at multiples of 32 (where `columns` holds).
        let mut x0 = x_lo & !31;
        while x0 <= x_hi {
            let (free, live) = window(y, x0);
            let (free1, live1) = if below {
                window(y.wrapping_add(1), x0)
            } else {
                (0, 0)
            };
            // Bit j (1..=32) of each: the move from cell x0 - 1 + j exists.
            let east = live & (live >> 1);
            let south = live & live1;
            let south_east = live & (live1 >> 1) & (free >> 1) & free1;
            let south_west = live & (live1 << 1) & (free << 1) & free1;
            let run = grid.run_bits(x0) & span_bits(x0, x_lo, x_hi);
            // The cell of bit j: x0 - 1 + j (j >= 1).
            let cell = |j: usize| x0.wrapping_add(j).wrapping_sub(1);
            // The bits of the run's cells in a block's last column (x & last == last) and in its
            // first (x & last == 0).
            let (ends, starts) = if last < 32 {
                columns
            } else {
                block_columns(x0, last)
            };
            // Moves across a block's east side: east, and south-east from its last column when
            // they stay in the block row.
            let across_east = (east | if y_crosses { 0 } else { south_east }) & ends & run;
            for x in Ones(across_east).map(cell) {
                link(x, y, 0);
            }
            // South-west from a block's first column within the block row: the west link, i.e.
            // the east link of the block to the left, from its last column.
            if !y_crosses {
                for x in Ones(south_west & starts & run).map(cell) {
                    link(x.wrapping_sub(1), y, 0);
                }
            } else {
                // The block row's last row: south, and the diagonals that stay in the block
                // column, give the south link; one bit a block is enough, so each block's bits
                // are folded onto its first column before the loop (a first column outside
                // the cells scanned is one of a block outside the region: no link to set).
                let mut down = (south | south_east & !ends | south_west & !starts) & run;
                if last < 32 {
                    let mut k = 1usize;
                    while k <= last {
                        down |= down >> k;
                        k = k.wrapping_mul(2);
                    }
                    down &= starts;
                }
                for x in Ones(down).map(cell) {
                    link(x, y, 2);
                }
                for x in Ones(south_east & ends & run).map(cell) {
                    link(x, y, 1);
                }
                for x in Ones(south_west & starts & run).map(cell) {
                    link(x, y, 3);
                }
            }
            x0 = x0.wrapping_add(32);
        }
    }
}

/// The bits j (1..=32) of the run of cells starting at column `x0` (bit j = column x0 - 1 + j)
/// whose columns lie in `lo..=hi`.
fn span_bits(x0: usize, lo: usize, hi: usize) -> u64 {
    let first = lo.wrapping_add(1).saturating_sub(x0).max(1);
    let end = hi.wrapping_add(1).saturating_sub(x0).min(32);
    if first > end {
        return 0;
    }
    // 1 <= first <= end <= 32: shifts below 64.
    (u64::MAX >> (63usize.wrapping_sub(end.wrapping_sub(first)) & 63)) << (first & 63)
}

/// For the run of cells starting at column `x0` (bit j = column x0 - 1 + j, j in 1..=32): the bits
/// of the columns that end a block (`x & last == last`) and of those that start one.
fn block_columns(x0: usize, last: usize) -> (u64, u64) {
    let (mut ends, mut starts) = (0u64, 0u64);
    for j in 1..=32usize {
        let x = x0.wrapping_add(j).wrapping_sub(1);
        ends |= u64::from(x & last == last) << j;
        starts |= u64::from(x & last == 0) << j;
    }
    (ends, starts)
}

/// The positions of the set bits of a word, lowest first.
struct Ones(u64);

impl Iterator for Ones {
    type Item = usize;
    #[inline]
    fn next(&mut self) -> Option<usize> {
        if self.0 == 0 {
            return None;
        }
        let j = self.0.trailing_zeros() as usize;
        self.0 &= self.0.wrapping_sub(1);
        Some(j)
    }
}

/// The direction from `p`'s block to `q`'s block (adjacent blocks): [`block_links`]'s.
#[cfg(test)]
fn block_dir(p: Point, q: Point, s: u8) -> u32 {
    // Block offsets are -1, 0 or 1 on each axis: index (dy + 1) * 3 + (dx + 1).
    const DIR: [u8; 9] = [5, 6, 7, 4, 0, 0, 3, 2, 1];
    // Differences of u16 values: no overflow.
    let dx = i32::from(q.x >> s).wrapping_sub(i32::from(p.x >> s));
    let dy = i32::from(q.y >> s).wrapping_sub(i32::from(p.y >> s));
    let k = dy
        .wrapping_add(1)
        .wrapping_mul(3)
        .wrapping_add(dx.wrapping_add(1));
    usize::try_from(k)
        .ok()
        .and_then(|k| DIR.get(k))
        .map_or(0, |&d| u32::from(d))
}

fn dist(w: u32) -> u32 {
    w >> DIST_SHIFT
}

/// An indexed binary min-heap of blocks by distance, in one word per block: the low half of word
/// `i` is the block in heap slot `i`, the high half of word `b` is block `b`'s slot + 1 (0: not
/// queued, `u16::MAX`: done). Blocks number at most `u16::MAX - 1`.
struct Heap<'a> {
    w: &'a mut [u32],
    len: usize,
}

impl Heap<'_> {
    fn block_at(&self, i: usize) -> usize {
        self.w.get(i).map_or(0, |&v| (v & 0xFFFF) as usize)
    }
    fn set_block_at(&mut self, i: usize, b: usize) {
        if let Some(v) = self.w.get_mut(i) {
            *v = (*v & 0xFFFF_0000) | (b as u32 & 0xFFFF);
        }
    }
    fn slot(&self, b: usize) -> u32 {
        self.w.get(b).map_or(0, |&v| v >> 16)
    }
    fn set_slot(&mut self, b: usize, s: u32) {
        if let Some(v) = self.w.get_mut(b) {
            *v = (*v & 0xFFFF) | (s << 16);
        }
    }
    /// Put the block of slot `i` there for good: record its slot.
    fn place(&mut self, i: usize, b: usize) {
        self.set_block_at(i, b);
        self.set_slot(b, (i as u32).wrapping_add(1)); // i < blocks < 2^16 - 1
    }

    /// Insert `b` or move it up after its distance dropped.
    fn push(&mut self, words: &[u32], b: usize) {
        let mut i = match self.slot(b) {
            0 => {
                let i = self.len;
                self.len = self.len.wrapping_add(1); // <= blocks
                i
            }
            0xFFFF => return, // done
            s => s.wrapping_sub(1) as usize,
        };
        let kb = key(words, b);
        // Sift up: move parents down until `b` fits.
        while i > 0 {
            let parent = i.wrapping_sub(1) >> 1;
            let pb = self.block_at(parent);
            if key(words, pb) <= kb {
                break;
            }
            self.place(i, pb);
            i = parent;
        }
        self.place(i, b);
    }

    /// Remove and return the block of least distance (`len > 0`).
    fn pop(&mut self, words: &[u32]) -> usize {
        let top = self.block_at(0);
        self.set_slot(top, 0xFFFF);
        self.len = self.len.wrapping_sub(1);
        if self.len == 0 {
            return top;
        }
        let last = self.block_at(self.len);
        let kl = key(words, last);
        // Sift down from the root with `last`.
        let mut i = 0usize;
        loop {
            let l = i.wrapping_mul(2).wrapping_add(1);
            if l >= self.len {
                break;
            }
            let r = l.wrapping_add(1);
            let mut c = l;
            if r < self.len && key(words, self.block_at(r)) < key(words, self.block_at(l)) {
                c = r;
            }
            let cb = self.block_at(c);
            if key(words, cb) >= kl {
                break;
            }
            self.place(i, cb);
            i = c;
        }
        self.place(i, last);
        top
    }
}

fn key(words: &[u32], b: usize) -> u32 {
    words.get(b).map_or(u32::MAX, |&w| dist(w))
}

/// Dijkstra over blocks from `goal_block`.
fn dijkstra(blocks: Blocks, goal_block: usize, words: &mut [u32], mut heap: Heap<'_>) {
    heap.w.fill(0);
    let across = blocks.across().max(1);
    let n = words.len();
    if let Some(w) = words.get_mut(goal_block) {
        *w &= !(UNREACHED << DIST_SHIFT);
    }
    heap.push(words, goal_block);
    while heap.len > 0 {
        let b = heap.pop(words);
        let Some(&wb) = words.get(b) else { break };
        let db = dist(wb);
        // `across >= 1`: the checked forms never fail.
        let bx = b.checked_rem(across).unwrap_or(0) as i32;
        let by = b.checked_div(across).unwrap_or(0) as i32;
        for d in 0..8usize {
            let nx = bx.wrapping_add(DX.get(d).copied().unwrap_or(0));
            let ny = by.wrapping_add(DY.get(d).copied().unwrap_or(0));
            if nx < 0 || ny < 0 || nx as usize >= across {
                continue;
            }
            let nb = (ny as usize).wrapping_mul(across).wrapping_add(nx as usize);
            if nb >= n {
                continue;
            }
            let Some(&wn) = words.get(nb) else { continue };
            // The neighbour reaches `b` in the opposite direction of `d` (links are per
            // direction of travel).
            let back = (d as u32).wrapping_add(4) & 7;
            if (wn >> back) & 1 == 0 {
                continue;
            }
            let nd = db.saturating_add(if d % 2 == 1 { 14 } else { 10 });
            if nd < dist(wn) {
                if let Some(w) = words.get_mut(nb) {
                    *w = (wn & 0xFF) | (back << 8) | (nd << DIST_SHIFT);
                }
                heap.push(words, nb);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::Grid;

    /// A 64 x 64 map (2 x 2 blocks would be 1024: the route uses single cells up to 4096 cells, so
    /// take 128 x 64 = 8192 cells: 2 x 2 blocks) with a wall between start and goal that has one
    /// gap at the bottom.
    fn walled() -> (Vec<u8>, u16, u16) {
        let (w, h) = (128u16, 64u16);
        let mut b = vec![0u8; (usize::from(w) * usize::from(h)).div_ceil(8)];
        for y in 0..h - 4 {
            let i = usize::from(y) * usize::from(w) + 64;
            b[i / 8] |= 1 << (i % 8);
        }
        (b, w, h)
    }

    #[test]
    fn links_match_the_per_cell_rule() {
        // Random maps of many shapes (rows not a multiple of 32 or 8, narrower than a block,
        // one row), random pruning marks or none, every block size from one cell to 16 x 16:
        // the word-parallel pass gives every block the links the per-cell rule does.
        let mut rng = crate::rng::Xoshiro128pp::from_u64(7);
        let shapes = [
            (1u16, 1u16),
            (1, 9),
            (9, 1),
            (5, 7),
            (31, 3),
            (33, 17),
            (64, 5),
            (70, 40),
            (97, 66),
            (200, 70),
        ];
        for &(w, h) in &shapes {
            for s in 0..=6u8 {
                for pruned in [false, true] {
                    let cells = usize::from(w) * usize::from(h);
                    let mut b = vec![0u8; cells.div_ceil(8)];
                    for byte in &mut b {
                        let r = rng.next_word();
                        *byte = (r & (r >> 8)) as u8; // about 25 % blocked
                    }
                    let g = Grid::new(w, h, &b).unwrap();
                    let moves = Moves::new(g, &[]);
                    let dead: Vec<u32> = if pruned {
                        (0..crate::bitmap::words(cells))
                            .map(|_| rng.next_word() & rng.next_word() & rng.next_word())
                            .collect()
                    } else {
                        Vec::new()
                    };
                    // The smallest blocks within this budget: shift s, or less on small maps.
                    let budget = usize::from(w).div_ceil(1 << s) * usize::from(h).div_ceil(1 << s);
                    let blocks = Blocks::with_budget(w, h, budget);
                    assert!(blocks.shift() <= s);
                    let across = blocks.across();
                    let down = blocks.count() / across;
                    let mut words = vec![0xDEADu32; across * down];
                    // Marks cut short (a caller's bug, not a workspace's): the per-cell rule's
                    // answer too, cells beyond them pruned.
                    let short = if pruned && dead.len() > 1 {
                        &dead[..dead.len() / 2]
                    } else {
                        &dead[..]
                    };
                    links(&moves, blocks, short, &mut words, None);
                    for by in 0..down {
                        for bx in 0..across {
                            let want = block_links(&moves, blocks, short, bx as u16, by as u16);
                            assert_eq!(words[by * across + bx], u32::from(want), "short marks");
                        }
                    }
                    links(&moves, blocks, &dead, &mut words, None);
                    for by in 0..down {
                        for bx in 0..across {
                            let want = block_links(&moves, blocks, &dead, bx as u16, by as u16);
                            assert_eq!(
                                words[by * across + bx],
                                u32::from(want),
                                "{w} x {h}, shift {s}, pruned {pruned}, block ({bx}, {by})"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn links_of_a_region_match_the_per_cell_rule() {
        // Random maps (some wider than two runs of 32 columns), block sizes from one cell to
        // 64 x 64, pruning marks (none, random, cut short) and rectangles of blocks (at the map's
        // edges, one block, the whole map, wider than 32 columns or not aligned to 32): `links`
        // on the region gives each of its blocks the per-cell rule's links and leaves every
        // other word as it was.
        let mut rng = crate::rng::Xoshiro128pp::from_u64(29);
        let mut pick = |n: u32| rng.next_word() % n.max(1);
        let mut seen = [0u32; 4];
        for round in 0..600 {
            let (w, h) = (1 + pick(300) as u16, 1 + pick(120) as u16);
            let cells = usize::from(w) * usize::from(h);
            let density = [5u32, 20, 40][round % 3];
            let mut b = vec![0u8; cells.div_ceil(8)];
            for i in 0..cells {
                if pick(100) < density {
                    b[i / 8] |= 1 << (i % 8);
                }
            }
            let g = Grid::new(w, h, &b).unwrap();
            let moves = Moves::new(g, &[]);
            let mut dead: Vec<u32> = match round % 4 {
                0 => Vec::new(),
                _ => (0..crate::bitmap::words(cells))
                    .map(|_| pick(u32::MAX) & pick(u32::MAX) & pick(u32::MAX))
                    .collect(),
            };
            if round % 4 == 3 {
                // Cut short: the cells beyond read as pruned.
                dead.truncate(dead.len() / 2);
            }
            let s = pick(7);
            let budget = usize::from(w).div_ceil(1 << s) * usize::from(h).div_ceil(1 << s);
            let blocks = Blocks::with_budget(w, h, budget);
            let across = blocks.across();
            let down = blocks.count() / across;
            let (a, d) = (across as u32, down as u32);
            // A corner, then the other one at or beyond it (sometimes past the map: clamped).
            let edge = |v: u32, n: u32, r: u32| match r % 4 {
                0 => 0,
                1 => n - 1,
                _ => v,
            };
            let x0 = edge(pick(a), a, pick(8)) as usize;
            let y0 = edge(pick(d), d, pick(8)) as usize;
            let x1 = match pick(4) {
                0 => across - 1,
                1 => across + 3,
                _ => x0 + pick(a - x0 as u32) as usize,
            };
            let y1 = match pick(4) {
                0 => down - 1,
                _ => y0 + pick(d - y0 as u32) as usize,
            };
            let region = Region { x0, y0, x1, y1 };
            let cols = (x1.min(across - 1) + 1 - x0) << blocks.shift();
            seen[0] += u32::from(x0 == 0 || y0 == 0 || x1 >= across - 1 || y1 == down - 1);
            seen[1] += u32::from(cols > 32);
            seen[2] += u32::from((x0 << blocks.shift()) % 32 != 0);
            seen[3] += u32::from(blocks.shift() >= 6);
            let before: Vec<u32> = (0..blocks.count()).map(|_| pick(u32::MAX)).collect();
            let mut words = before.clone();
            links(&moves, blocks, &dead, &mut words, Some(region));
            for by in 0..down {
                for bx in 0..across {
                    let i = by * across + bx;
                    let want = if region.holds(bx, by) {
                        u32::from(block_links(&moves, blocks, &dead, bx as u16, by as u16))
                    } else {
                        before[i]
                    };
                    assert_eq!(
                        words[i],
                        want,
                        "round {round}: {w} x {h}, shift {}, {region:?}, block ({bx}, {by})",
                        blocks.shift()
                    );
                }
            }
        }
        assert!(seen.iter().all(|&n| n > 30), "{seen:?}");
    }

    #[test]
    fn sub_goals_lead_around_the_wall() {
        let (b, w, h) = walled();
        let g = Grid::new(w, h, &b).unwrap();
        let blocks = blocks(w, h);
        assert_eq!(blocks.shift(), 1);
        let moves = Moves::new(g, &[]);
        let dead = vec![0u32; crate::bitmap::words(g.cells())];
        let mut words = vec![0u32; GUIDE_BLOCKS];
        let mut heap = vec![0u32; GUIDE_BLOCKS];
        let goal = Point::new(100, 2);
        assert!(build(&moves, blocks, goal, &dead, &mut words, &mut heap));
        let route = Route::new(blocks, &words, goal, w, h);
        // From the top left the straight pull would hit the wall; the sub-goal leads down.
        let t = route.target(Point::new(20, 2));
        assert!(t.y > 2, "{t:?}");
        // Follow the sub-goals: they reach the goal through the gap.
        let mut p = Point::new(20, 2);
        for _ in 0..400 {
            let t = route.target(p);
            if t == goal {
                break;
            }
            assert!(t.x != 64 || t.y >= h - 4, "a sub-goal in the wall: {t:?}");
            p = t;
        }
        assert_eq!(route.target(p), goal);
        // Next to the goal, the goal itself.
        assert_eq!(route.target(Point::new(101, 3)), goal);
    }

    #[test]
    fn a_packed_route_pulls_where_its_words_do() {
        // Random maps and goals: every cell's target is the same from the packed next blocks
        // as from the words they were packed from, and a buffer one word short packs nothing.
        let mut rng = crate::rng::Xoshiro128pp::from_u64(5);
        let mut routed = 0;
        for (w, h) in [(300u16, 200u16), (512, 64), (97, 131)] {
            for _ in 0..3 {
                let mut b = vec![0u8; (usize::from(w) * usize::from(h)).div_ceil(8)];
                for byte in b.iter_mut() {
                    for bit in 0..8 {
                        if rng.next_unit() < 0.3 {
                            *byte |= 1 << bit;
                        }
                    }
                }
                let g = Grid::new(w, h, &b).unwrap();
                let blocks = blocks(w, h);
                let moves = Moves::new(g, &[]);
                let goal = Point::new(
                    (rng.next_unit() * f32::from(w - 1)) as u16,
                    (rng.next_unit() * f32::from(h - 1)) as u16,
                );
                let mut words = vec![0u32; GUIDE_BLOCKS];
                let mut heap = vec![0u32; GUIDE_BLOCKS];
                assert!(build(&moves, blocks, goal, &[], &mut words, &mut heap));
                let mut nibbles = vec![0u32; packed_words(blocks.count())];
                assert!(!pack(blocks, &words, &mut nibbles[1..]));
                assert!(pack(blocks, &words, &mut nibbles));
                let full = Route::new(blocks, &words, goal, w, h);
                let packed = Route::packed(blocks, &nibbles, goal, w, h);
                for y in 0..h {
                    for x in 0..w {
                        let p = Point::new(x, y);
                        assert_eq!(packed.target(p), full.target(p), "{w}x{h} {p:?}");
                        routed += usize::from(full.target(p) != goal);
                    }
                }
            }
        }
        assert!(routed > 100_000, "{routed}");
    }

    #[test]
    fn distances_are_exact_on_blocks() {
        // An empty map: the distance of a block is the octile-like 10/14 distance to the goal's.
        let g = Grid::new(128, 64, &[0u8; 1024]).unwrap();
        let blocks = blocks(128, 64);
        let moves = Moves::new(g, &[]);
        let dead = vec![0u32; crate::bitmap::words(g.cells())];
        let mut words = vec![0u32; GUIDE_BLOCKS];
        let mut heap = vec![0u32; GUIDE_BLOCKS];
        assert!(build(
            &moves,
            blocks,
            Point::new(0, 0),
            &dead,
            &mut words,
            &mut heap
        ));
        for (b, w) in words.iter().take(blocks.count()).enumerate() {
            let (bx, by) = ((b % blocks.across()) as u32, (b / blocks.across()) as u32);
            let (hi, lo) = (bx.max(by), bx.min(by));
            assert_eq!(dist(*w), 10 * (hi - lo) + 14 * lo, "block {b}");
        }
        // Too short a heap: no route.
        let mut short = vec![0u32; 10];
        assert!(!build(
            &moves,
            blocks,
            Point::new(0, 0),
            &dead,
            &mut words,
            &mut short
        ));
    }

    #[test]
    fn repair_equals_build_on_random_maps_with_random_changes() {
        let mut x = 0x1234_5679u32;
        let mut rnd = move || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x
        };
        let mut shifts = [0u32; 4];
        for round in 0..300 {
            let (w, h) = (20 + rnd() % 200, 20 + rnd() % 150);
            let cells = (w * h) as usize;
            let density = [5u32, 20, 35][round % 3];
            let mut b = vec![0u8; cells.div_ceil(8)];
            let mut dead = vec![0u32; crate::bitmap::words(cells)];
            for i in 0..cells {
                if rnd() % 100 < density {
                    b[i / 8] |= 1 << (i % 8);
                } else if rnd() % 100 < 15 {
                    crate::bitmap::set(&mut dead, i);
                }
            }
            let blocks = blocks(w as u16, h as u16);
            shifts[usize::from(blocks.shift()).min(3)] += 1;
            let goal = Point::new((rnd() % w) as u16, (rnd() % h) as u16);
            let g0 = Grid::new(w as u16, h as u16, &b).unwrap();
            let mut words = vec![0u32; GUIDE_BLOCKS];
            let mut heap = vec![0u32; GUIDE_BLOCKS];
            assert!(build(
                &Moves::new(g0, &[]),
                blocks,
                goal,
                &dead,
                &mut words,
                &mut heap
            ));
            let mut kept = vec![0f32; stash_len(blocks)];
            assert!(stash(blocks, &words, &mut kept));
            // Scribble over the words, as the local search does with its scratch.
            words.fill(0xDEAD_BEEF);
            // Change the map and the marks inside a random rectangle (or nowhere).
            let area = (round % 7 != 0).then(|| {
                let (cw, ch) = (1 + rnd() % 9, 1 + rnd() % 9);
                let (x0, y0) = (rnd() % w, rnd() % h);
                let (x1, y1) = ((x0 + cw - 1).min(w - 1), (y0 + ch - 1).min(h - 1));
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let i = (y * w + x) as usize;
                        match rnd() % 4 {
                            0 => b[i / 8] |= 1 << (i % 8),
                            1 => b[i / 8] &= !(1 << (i % 8)),
                            2 => crate::bitmap::set(&mut dead, i),
                            _ => crate::bitmap::unset(&mut dead, i),
                        }
                    }
                }
                (
                    Point::new(x0 as u16, y0 as u16),
                    Point::new(x1 as u16, y1 as u16),
                )
            });
            let g1 = Grid::new(w as u16, h as u16, &b).unwrap();
            assert!(unstash(blocks, &kept, &mut words));
            let m1 = Moves::new(g1, &[]);
            assert!(repair(
                &m1, blocks, goal, &dead, &mut words, &mut heap, area
            ));
            let mut fresh = vec![0u32; GUIDE_BLOCKS];
            assert!(build(&m1, blocks, goal, &dead, &mut fresh, &mut heap));
            let n = blocks.count();
            assert_eq!(words[..n], fresh[..n], "round {round}: {w} x {h}, {area:?}");
        }
        assert!(
            shifts[0] > 20 && shifts[1] > 20 && shifts[2] > 10,
            "{shifts:?}"
        );
    }

    #[test]
    fn stash_keeps_the_links_only() {
        let blocks = blocks(256, 256);
        let words: Vec<u32> = (0..GUIDE_BLOCKS as u32)
            .map(|i| i.wrapping_mul(2654435761))
            .collect();
        let mut kept = vec![0f32; stash_len(blocks)];
        assert_eq!(kept.len(), 2048);
        assert!(stash(blocks, &words, &mut kept));
        assert!(!stash(blocks, &words, &mut kept[..2047]));
        let mut back = vec![u32::MAX; GUIDE_BLOCKS];
        assert!(unstash(blocks, &kept, &mut back));
        for (a, b) in words.iter().zip(&back) {
            assert_eq!(a & 0xFF, *b);
        }
    }
}
