//! The links of the coarse route's blocks: which neighbouring blocks one allowed move reaches.
//!
//! Block `B` links to a neighbouring block `B'` when some live cell of `B` (free, not pruned) has
//! an allowed move into a live cell of `B'`. Moves are symmetric, so the links are too (`B` links
//! to `B'` in direction `d` exactly when `B'` links to `B` in direction `d + 4`). [`links`]
//! computes them for a rectangle of blocks, 32 cells at a time from the map's bit windows; the
//! route's search ([`super::search`]) asks for one block at a time, when it closes the block, so
//! a plan reads the border cells of the blocks its corridor needs and no others.

use crate::colony::pheromone::Blocks;
use crate::map::grid::Moves;
#[cfg(test)]
use crate::map::grid::Point;

/// The links of block `(bx, by)`, cell by cell: the rule [`links`] computes 32 cells at a time,
/// kept as the tests' reference.
#[cfg(test)]
pub(super) fn block_links(moves: &Moves<'_>, blocks: Blocks, dead: &[u32], bx: u16, by: u16) -> u8 {
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
            if !crate::map::bitmap::marked(dead, ci) {
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
                    if crate::map::bitmap::marked(dead, ni) {
                        continue;
                    }
                    let q = crate::map::grid::neighbour(p, d as crate::map::grid::Dir);
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
pub(super) struct Region {
    pub(super) x0: usize,
    pub(super) y0: usize,
    pub(super) x1: usize,
    pub(super) y1: usize,
}

impl Region {
    /// One block.
    pub(super) fn block(bx: usize, by: usize) -> Self {
        Region {
            x0: bx,
            y0: by,
            x1: bx,
            y1: by,
        }
    }

    #[inline]
    pub(super) fn holds(&self, bx: usize, by: usize) -> bool {
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
pub(super) fn links(
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
    // they are in the region. On the whole map both are: a move's two ends are cells of the
    // map (the windows read cells off it as blocked), so their blocks are on it too.
    let all = r.x0 == 0 && r.y0 == 0 && r.x1 == whole.x1 && r.y1 == whole.y1;
    let mut link = |x: usize, y: usize, d: u32| {
        let (dx, dy) = match d {
            0 => (1isize, 0usize),
            1 => (1, 1),
            2 => (0, 1),
            _ => (-1, 1),
        };
        let (bx, by) = (x >> s, y >> s);
        if all || r.holds(bx, by) {
            if let Some(wd) = words.get_mut(by.wrapping_mul(across).wrapping_add(bx)) {
                *wd |= 1 << d;
            }
        }
        let (nx, ny) = (bx.wrapping_add_signed(dx), by.wrapping_add(dy));
        if all || r.holds(nx, ny) {
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
            crate::map::bitmap::window(dead, row) << 1
        } else {
            crate::map::bitmap::window(dead, row.wrapping_add(x0).wrapping_sub(1))
        };
        (free, free & !pruned)
    };
    // Blocks of at most 32 columns start at multiples of 32 in every run: the same bits in all
    // (a table, not worked out at each call: the route's search asks for one block at a time).
    let columns = COLUMNS
        .get(s as usize)
        .copied()
        .unwrap_or_else(|| block_columns(0, last));
    // Block row by block row (the first may be the one row north of the region: the last row
    // of the block row above), and in each, run by run, its rows top to bottom: each row's
    // windows are read once (row `y + 1`'s serve as row `y`'s next), and a block's east and
    // west links, one bit a block in `ends` and `starts`, are gathered over the block row's
    // rows and set once (a move across a block's side sets the same link from any of them).
    let mut ya = y_lo;
    while ya <= y_hi {
        // The block row's last row (`ya | last`), within the cells scanned.
        let yb = (ya | last).min(y_hi);
        // Runs start at multiples of 32 (where `columns` holds).
        let mut x0 = x_lo & !31;
        while x0 <= x_hi {
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
            let (mut east_side, mut west_side) = (0u64, 0u64);
            let mut here = window(ya, x0);
            let mut y = ya;
            while y <= yb {
                let below = y.wrapping_add(1) < h;
                let y_crosses = below && y & last == last;
                let (free, live) = here;
                let (free1, live1) = if below {
                    window(y.wrapping_add(1), x0)
                } else {
                    (0, 0)
                };
                here = (free1, live1);
                // Bit j (1..=32) of each: the move from cell x0 - 1 + j exists.
                let east = live & (live >> 1);
                let south_east = live & (live1 >> 1) & (free >> 1) & free1;
                let south_west = live & (live1 << 1) & (free << 1) & free1;
                // Moves across a block's east side: east, and south-east from its last column
                // when they stay in the block row.
                east_side |= east | if y_crosses { 0 } else { south_east };
                if !y_crosses {
                    // South-west from a block's first column within the block row: the west
                    // link, i.e. the east link of the block to the left, from its last column.
                    west_side |= south_west;
                } else {
                    // The block row's last row: south, and the diagonals that stay in the block
                    // column, give the south link; one bit a block is enough, so each block's
                    // bits are folded onto its first column before the loop (a first column
                    // outside the cells scanned is one of a block outside the region: no link
                    // to set).
                    let south = live & live1;
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
                y = y.wrapping_add(1);
            }
            for x in Ones(east_side & ends & run).map(cell) {
                link(x, ya, 0);
            }
            for x in Ones(west_side & starts & run).map(cell) {
                link(x.wrapping_sub(1), ya, 0);
            }
            x0 = x0.wrapping_add(32);
        }
        ya = yb.wrapping_add(1);
    }
}

/// The links of the one block `(bx, by)`: what [`links`] gives it, read from the `n + 2` rows
/// of `n + 2` cells around it only (`n = 2^s` cells a side), as the route's search asks when it
/// closes a block.
///
/// Each row is one bit window of its free cells and one of its live cells (free, not pruned),
/// bit `k` = column `x0 - 1 + k`; the block's first and last columns and the columns beyond
/// them are gathered as column vectors on the way (bit `r` = row `y0 - 1 + r`). Each link is
/// then a few ANDs: a move across the block's side whose far end stays in the block's row (for
/// east and west) or column (for north and south) of blocks, or the one diagonal move across a
/// corner. Blocks wider than 32 cells (maps of more than 16 M cells) take [`links`] on a
/// one-block region. The per-cell rule's answer, bit for bit
/// (`one_blocks_links_match_the_per_cell_rule`).
pub(super) fn block(
    moves: &Moves<'_>,
    blocks: Blocks,
    dead: &[u32],
    words: &mut [u32],
    (bx, by): (usize, usize),
) -> u32 {
    let grid = *moves.grid();
    let (w, h) = (usize::from(grid.width()), usize::from(grid.height()));
    let s = usize::from(blocks.shift());
    if s > 5 {
        // `links` writes the block's word: keep what else it holds.
        let b = by.wrapping_mul(blocks.across()).wrapping_add(bx);
        let kept = words.get(b).copied().unwrap_or(0);
        links(moves, blocks, dead, words, Some(Region::block(bx, by)));
        let Some(word) = words.get_mut(b) else {
            return 0;
        };
        let out = *word & 0xFF;
        *word = kept;
        return out;
    }
    let n = 1usize << s;
    let (x0, y0) = (bx << s, by << s);
    if x0 >= w || y0 >= h {
        return 0;
    }
    // Bits 0..=n + 1 of a row: columns x0 - 1 ..= x0 + n (n <= 32: at most 34 bits).
    let row_bits = (1u64 << n.wrapping_add(2)).wrapping_sub(1);
    let window = |y: usize| -> (u64, u64) {
        let free = grid.free_window(y, x0) & row_bits;
        let i = y.wrapping_mul(w);
        let pruned = if dead.is_empty() {
            0
        } else if x0 == 0 {
            crate::map::bitmap::window(dead, i) << 1
        } else {
            crate::map::bitmap::window(dead, i.wrapping_add(x0).wrapping_sub(1))
        };
        (free, free & !pruned)
    };
    let bit = |v: u64, k: usize| (v >> (k & 63)) & 1;
    let (last, east) = (n, n.wrapping_add(1));
    // Row r = 0 ..= n + 1 is y0 - 1 ..= y0 + n (off the map: no cell).
    let row = |r: usize| -> (u64, u64) {
        let y = y0.wrapping_add(r).wrapping_sub(1);
        if y >= h {
            (0, 0) // y0 - 1 above the top row wraps round
        } else {
            window(y)
        }
    };
    // The four rows the north and south links and the corners read.
    let (north, top) = (row(0), row(1));
    let bottom = if n == 1 { top } else { row(n) };
    let south = row(n.wrapping_add(1));
    // The east and west links (bits 0 and 1 here): a move from the block's last (first) column
    // to the column beyond it whose both ends lie in the block's rows 1..=n: straight within a
    // row, or diagonal between two consecutive rows (both ends live, the two cells beside it
    // free: the no-corner-cutting rule). Rows are read top to bottom only while a side link is
    // still missing: on open ground the first row finds both.
    let straight = |(_, l): (u64, u64)| -> u8 {
        (bit(l, last) & bit(l, east)) as u8 | ((bit(l, 1) & bit(l, 0)) as u8) << 1
    };
    let diagonal = |(fa, la): (u64, u64), (fb, lb): (u64, u64), edge: usize, out: usize| -> u64 {
        (bit(la, edge) & bit(lb, out) & bit(fa, out) & bit(fb, edge))
            | (bit(lb, edge) & bit(la, out) & bit(fb, out) & bit(fa, edge))
    };
    let mut sides = straight(top);
    let mut prev = top;
    let mut r = 2usize;
    while sides != 3 && r <= n {
        let cur = if r == n { bottom } else { row(r) };
        sides |= straight(cur)
            | diagonal(prev, cur, last, east) as u8
            | (diagonal(prev, cur, 1, 0) as u8) << 1;
        prev = cur;
        r = r.wrapping_add(1);
    }
    // A move from the block's edge row `a` to the row `b` beyond it, straight or diagonal, whose
    // far end stays within the block's columns: both ends live, and a diagonal's two side cells
    // free (the no-corner-cutting rule).
    let inner = row_bits & !1 & !(1u64 << east);
    let side = |(fa, la): (u64, u64), (fb, lb): (u64, u64)| -> bool {
        let straight = la & lb;
        let up = la & (lb >> 1) & fb & (fa >> 1) & (inner >> 1);
        let down = la & (lb << 1) & fb & (fa << 1) & (inner << 1);
        (straight | up | down) & inner != 0
    };
    // The diagonal move from bit `ka` of row `a` to bit `kb` of row `b`.
    let corner = |(fa, la): (u64, u64), ka: usize, (fb, lb): (u64, u64), kb: usize| -> bool {
        bit(la, ka) & bit(lb, kb) & bit(fa, kb) & bit(fb, ka) == 1
    };
    let links = [
        sides & 1 != 0,                    // 0: east
        corner(bottom, last, south, east), // 1: south-east
        side(bottom, south),               // 2: south
        corner(bottom, 1, south, 0),       // 3: south-west
        sides & 2 != 0,                    // 4: west
        corner(top, 1, north, 0),          // 5: north-west
        side(top, north),                  // 6: north
        corner(top, last, north, east),    // 7: north-east
    ];
    links
        .iter()
        .enumerate()
        .fold(0, |acc, (d, &l)| acc | u32::from(l) << d)
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

/// [`block_columns`]`(0, 2^s - 1)` for blocks of `2^s` columns, `s` in `0..=5`.
#[allow(clippy::indexing_slicing, clippy::arithmetic_side_effects)]
const COLUMNS: [(u64, u64); 6] = {
    let mut t = [(0u64, 0u64); 6];
    let mut s = 0usize;
    while s < 6 {
        let last = (1usize << s) - 1;
        let mut j = 1usize;
        while j <= 32 {
            let x = j - 1;
            if x & last == last {
                t[s].0 |= 1 << j;
            }
            if x & last == 0 {
                t[s].1 |= 1 << j;
            }
            j += 1;
        }
        s += 1;
    }
    t
};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::grid::Grid;

    #[test]
    fn one_blocks_links_match_the_per_cell_rule() {
        // Random maps of many shapes (narrower than a block, one row, rows not a multiple of 8
        // or 32), random pruning marks (none, random, cut short), every block size from one cell
        // to 128 x 128 (past 32: `links` on the block): `block` gives every block the per-cell
        // rule's links, and leaves the words as they were.
        let mut rng = crate::rng::Xoshiro128pp::from_u64(37);
        let mut pick = |n: u32| rng.next_word() % n.max(1);
        for round in 0..300 {
            let (w, h) = (1 + pick(260) as u16, 1 + pick(150) as u16);
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
                _ => (0..crate::map::bitmap::words(cells))
                    .map(|_| pick(u32::MAX) & pick(u32::MAX) & pick(u32::MAX))
                    .collect(),
            };
            if round % 4 == 3 {
                dead.truncate(dead.len() / 2);
            }
            let s = pick(8);
            let budget = usize::from(w).div_ceil(1 << s) * usize::from(h).div_ceil(1 << s);
            let blocks = Blocks::with_budget(w, h, budget);
            let across = blocks.across();
            let down = blocks.count() / across;
            let before: Vec<u32> = (0..blocks.count()).map(|_| pick(u32::MAX)).collect();
            let mut words = before.clone();
            for by in 0..down {
                for bx in 0..across {
                    let want = block_links(&moves, blocks, &dead, bx as u16, by as u16);
                    let got = block(&moves, blocks, &dead, &mut words, (bx, by));
                    assert_eq!(
                        got,
                        u32::from(want),
                        "round {round}: {w} x {h}, shift {}, block ({bx}, {by})",
                        blocks.shift()
                    );
                }
            }
            assert_eq!(words, before);
        }
    }

    #[test]
    fn the_column_table_is_block_columns() {
        for (s, &c) in COLUMNS.iter().enumerate() {
            assert_eq!(c, block_columns(0, (1 << s) - 1), "shift {s}");
        }
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
                        (0..crate::map::bitmap::words(cells))
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
                _ => (0..crate::map::bitmap::words(cells))
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
}
