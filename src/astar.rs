//! An exact 8-connected A* over the grid in 4 bits a cell: the baseline the colony is measured
//! against (issue 27), on the same chip and counted the same way.
//!
//! **What it owns.** One search from a start to a goal cell on a [`Grid`], with the core's own
//! moves ([`crate::grid::Grid::step`]: the eight king moves, a diagonal only when both
//! orthogonally adjacent cells are free, so no corner is ever cut) and the core's own step costs
//! (1 straight, [`SQRT_2`] diagonal, in `f32`). The heuristic is the octile distance, which is
//! consistent for these costs, so the first time a cell is popped its `g` is final.
//!
//! **Storage, all the caller's.** A nibble slice of [`nibble_bytes`]`(cells)` bytes holds, for each
//! cell (row-major, low nibble first): [`FREE`] (free, not closed yet), [`BLOCKED`], [`START`]
//! (closed, no parent), or `1..=8` (closed, reached from its parent by direction `nibble - 1`,
//! [`crate::dir`]). The map's bits are copied into it at the start of each search (one pass);
//! after the search it still holds the map, the closed set and the parent tree. `g` is kept only
//! in the open list: a binary heap of [`Entry`] (12 bytes: `f`, `g`, cell and direction) in a
//! caller slice, with lazy deletion (a cell may be pushed more than once; at a pop, an entry whose
//! cell is already closed is dropped). Ties on `f` go to the larger `g` (deeper first), then to
//! whichever the heap holds first.
//!
//! **Guarantees.** The path found is a shortest 8-connected no-corner-cutting path (exact up to
//! `f32` rounding of the accumulated `g`: the reported [`Search::length`] is recomputed from the
//! step counts with [`steps_length`], the core's own formula, so it compares bit for bit with a
//! core path of the same steps). No allocation, no panics (every slice access is a `get`, every
//! index sum is bounded by the map's size, which is checked up front), errors are values
//! ([`AstarError`]). The search is deterministic: the same inputs give the same path on every
//! platform.

use core::fmt;

use crate::dir::{is_diagonal, opposite, Dir, DX, DY};
use crate::geometry::{steps_length, SQRT_2};
use crate::grid::{Grid, Point};

/// Nibble of a free cell not closed yet.
pub const FREE: u8 = 0;
/// Nibble of the start cell once closed (it has no parent).
pub const START: u8 = 9;
/// Nibble of a blocked cell.
pub const BLOCKED: u8 = 15;

/// Largest map the search accepts: the heap packs the cell index and a direction in 32 bits.
pub const MAX_CELLS: usize = 1 << 29;

/// Bytes of nibble storage a map of `cells` cells needs.
pub const fn nibble_bytes(cells: usize) -> usize {
    cells.div_ceil(2)
}

/// Bytes of one open-list entry.
pub const ENTRY_BYTES: usize = core::mem::size_of::<Entry>();

/// One open-list entry: the cell (index `key >> 3`), the direction it was reached by
/// (`key & 7`), its `g` and `f = g + h`. Plain old data (`bytemuck::Pod`), so a caller can carve
/// the open list out of a byte or word buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Entry {
    f: f32,
    g: f32,
    key: u32,
}

impl Entry {
    /// An entry to fill caller arrays with (`[Entry::EMPTY; N]`).
    pub const EMPTY: Entry = Entry {
        f: 0.0,
        g: 0.0,
        key: 0,
    };

    /// True if `self` must be popped before `o`: smaller `f`, then larger `g`.
    #[inline(always)]
    fn before(&self, o: &Entry) -> bool {
        self.f < o.f || (self.f == o.f && self.g > o.g)
    }
}

/// What a successful search found and what it cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Search {
    /// Path length, `straight + diagonal * SQRT_2` ([`steps_length`]).
    pub length: f32,
    /// Straight steps on the path.
    pub straight: u32,
    /// Diagonal steps on the path.
    pub diagonal: u32,
    /// Cells closed (expanded), the start and the goal included.
    pub expansions: u32,
    /// Entries pushed onto the open list.
    pub pushes: u32,
    /// Most entries the open list held at once.
    pub peak_heap: u32,
}

impl Search {
    /// Steps on the path (cells on it minus one).
    pub fn steps(&self) -> u32 {
        self.straight.saturating_add(self.diagonal)
    }

    /// Bytes of storage the search used: the nibbles plus the open list at its peak.
    pub fn ram_bytes(&self, cells: usize) -> usize {
        nibble_bytes(cells).saturating_add((self.peak_heap as usize).saturating_mul(ENTRY_BYTES))
    }
}

/// Which end of the search an [`AstarError::BadCell`] refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    /// The start cell.
    Start,
    /// The goal cell.
    Goal,
}

/// Everything that can stop a search.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AstarError {
    /// The goal is not reachable from the start.
    NoPath,
    /// The start or goal is outside the map or blocked.
    BadCell(End),
    /// The nibble slice is shorter than [`nibble_bytes`] of the map, or the map has more than
    /// [`MAX_CELLS`] cells.
    StorageTooSmall {
        /// Bytes needed.
        needed: usize,
        /// Bytes given.
        got: usize,
    },
    /// The open list outgrew its slice (`capacity` entries).
    HeapFull {
        /// Entries the slice holds.
        capacity: usize,
    },
    /// The path's cells do not fit the output slice.
    PathTooLong {
        /// Cells on the path.
        cells: usize,
        /// Cells the slice holds.
        capacity: usize,
    },
    /// The nibbles do not hold a parent tree from the start to the goal (not the storage of a
    /// successful search on this map).
    NoTree,
}

impl fmt::Display for AstarError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AstarError::NoPath => f.write_str("no path: the goal is not reachable from the start"),
            AstarError::BadCell(End::Start) => f.write_str("start is off the map or blocked"),
            AstarError::BadCell(End::Goal) => f.write_str("goal is off the map or blocked"),
            AstarError::StorageTooSmall { needed, got } => {
                write!(f, "nibble storage: {needed} bytes needed, {got} given")
            }
            AstarError::HeapFull { capacity } => {
                write!(f, "open list full at {capacity} entries")
            }
            AstarError::PathTooLong { cells, capacity } => {
                write!(f, "path has {cells} cells, the slice holds {capacity}")
            }
            AstarError::NoTree => f.write_str("no parent tree from the start to the goal"),
        }
    }
}

/// The octile distance between cells `(ax, ay)` and `(bx, by)`.
#[inline(always)]
fn octile(ax: u32, ay: u32, bx: u32, by: u32) -> f32 {
    let dx = ax.abs_diff(bx);
    let dy = ay.abs_diff(by);
    let (lo, hi) = if dx < dy { (dx, dy) } else { (dy, dx) };
    // hi >= lo: no wrap.
    hi.wrapping_sub(lo) as f32 + lo as f32 * SQRT_2
}

/// The nibble of cell `i` ([`BLOCKED`] beyond the slice).
#[inline(always)]
fn nib(nibbles: &[u8], i: usize) -> u8 {
    match nibbles.get(i >> 1) {
        Some(&b) => (b >> ((i & 1) << 2)) & 15,
        None => BLOCKED,
    }
}

/// Set the nibble of cell `i` to `v` (`v < 16`; nothing beyond the slice).
#[inline(always)]
fn set_nib(nibbles: &mut [u8], i: usize, v: u8) {
    if let Some(b) = nibbles.get_mut(i >> 1) {
        let s = (i & 1) << 2;
        *b = (*b & !(15 << s)) | ((v & 15) << s);
    }
}

/// The binary min-heap of open entries over the caller's slice.
struct Open<'h> {
    a: &'h mut [Entry],
    len: usize,
    peak: usize,
    pushes: u32,
}

impl Open<'_> {
    #[inline]
    fn push(&mut self, e: Entry) -> Result<(), AstarError> {
        let cap = self.a.len();
        if self.len >= cap {
            return Err(AstarError::HeapFull { capacity: cap });
        }
        // Sift the hole at `len` up. `len < cap`, so `len + 1` cannot wrap.
        let mut hole = self.len;
        self.len = self.len.wrapping_add(1);
        if self.len > self.peak {
            self.peak = self.len;
        }
        self.pushes = self.pushes.saturating_add(1);
        while hole > 0 {
            let parent = hole.wrapping_sub(1) >> 1;
            let Some(&p) = self.a.get(parent) else { break };
            if !e.before(&p) {
                break;
            }
            if let Some(slot) = self.a.get_mut(hole) {
                *slot = p;
            }
            hole = parent;
        }
        if let Some(slot) = self.a.get_mut(hole) {
            *slot = e;
        }
        Ok(())
    }

    #[inline]
    fn pop(&mut self) -> Option<Entry> {
        if self.len == 0 {
            return None;
        }
        let top = self.a.first().copied()?;
        self.len = self.len.wrapping_sub(1);
        let last = self.a.get(self.len).copied()?;
        // Sift `last` down from the root into the shortened heap. Children of `hole` are at most
        // `2 * len + 2 < 2 * cap + 2`, and a slice of `Entry` has far fewer than usize::MAX / 2
        // elements: no wrap.
        let len = self.len;
        let mut hole = 0usize;
        loop {
            let l = hole.wrapping_mul(2).wrapping_add(1);
            if l >= len {
                break;
            }
            let r = l.wrapping_add(1);
            let Some(&cl) = self.a.get(l) else { break };
            let (c, ce) = match self.a.get(r) {
                Some(&cr) if r < len && cr.before(&cl) => (r, cr),
                _ => (l, cl),
            };
            if !ce.before(&last) {
                break;
            }
            if let Some(slot) = self.a.get_mut(hole) {
                *slot = ce;
            }
            hole = c;
        }
        if let Some(slot) = self.a.get_mut(hole) {
            *slot = last;
        }
        Some(top)
    }
}

/// Copy the map's bits into the nibbles: [`BLOCKED`] for a blocked cell, [`FREE`] otherwise.
/// Nibbles past the map's cells (the last byte's high nibble on an odd count) get whatever the
/// bits past the map hold; nothing reads them.
fn load_map(grid: &Grid<'_>, nibbles: &mut [u8], bytes: usize) {
    const PAIR: [u8; 4] = [0x00, 0x0F, 0xF0, 0xFF];
    let out = nibbles.get_mut(..bytes).unwrap_or(&mut []);
    for (quad, &bits) in out.chunks_mut(4).zip(grid.bits()) {
        let mut b = bits;
        for o in quad {
            *o = PAIR.get(usize::from(b & 3)).copied().unwrap_or(0xFF);
            b >>= 2;
        }
    }
}

/// Search a shortest path from `start` to `goal` on `grid`, in the caller's `nibbles`
/// (at least [`nibble_bytes`]`(grid.cells())` bytes) and open list `heap`. On success the nibbles
/// hold the parent tree: [`write_path`] and [`path_back`] read the path from them.
pub fn search(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    nibbles: &mut [u8],
    heap: &mut [Entry],
) -> Result<Search, AstarError> {
    let cells = grid.cells();
    let needed = nibble_bytes(cells);
    if nibbles.len() < needed || cells > MAX_CELLS {
        return Err(AstarError::StorageTooSmall {
            needed,
            got: nibbles.len(),
        });
    }
    if !grid.is_free(start) {
        return Err(AstarError::BadCell(End::Start));
    }
    if !grid.is_free(goal) {
        return Err(AstarError::BadCell(End::Goal));
    }
    load_map(grid, nibbles, needed);

    let w = u32::from(grid.width());
    let h = u32::from(grid.height());
    let (gx, gy) = (u32::from(goal.x), u32::from(goal.y));
    let goal_i = grid.index(goal);
    // Index offset of each direction; every sum below is taken only for a neighbour inside the
    // map, so it stays in 0..cells (wrapping arithmetic on usize is exact there).
    let offs = grid.offsets();
    let mut open = Open {
        a: heap,
        len: 0,
        peak: 0,
        pushes: 0,
    };
    let mut expansions: u32 = 0;

    // The start is closed before the loop; then every pop either drops a closed cell or closes one.
    let mut cur = grid.index(start);
    let mut cur_g = 0.0f32;
    set_nib(nibbles, cur, START);
    loop {
        expansions = expansions.saturating_add(1);
        if cur == goal_i {
            break;
        }
        // Cell `cur` < cells <= MAX_CELLS < 2^32 and `w > 0`: the division is exact in u32.
        let c = u32::try_from(cur).unwrap_or(u32::MAX);
        let (Some(x), Some(y)) = (c.checked_rem(w), c.checked_div(w)) else {
            break; // w > 0 (Grid::new checks it)
        };
        // The eight neighbours' nibbles, BLOCKED off the map.
        let east = x.wrapping_add(1) < w;
        let west = x > 0;
        let south = y.wrapping_add(1) < h;
        let north = y > 0;
        let inside = [
            east,
            east && south,
            south,
            west && south,
            west,
            west && north,
            north,
            east && north,
        ];
        let mut n = [BLOCKED; 8];
        for (d, slot) in n.iter_mut().enumerate() {
            if inside.get(d).copied().unwrap_or(false) {
                let o = offs.get(d).copied().unwrap_or(0);
                *slot = nib(nibbles, cur.wrapping_add_signed(o));
            }
        }
        let blocked = |d: usize| n.get(d & 7).copied().unwrap_or(BLOCKED) == BLOCKED;
        for d in 0..8usize {
            if n.get(d).copied().unwrap_or(BLOCKED) != FREE {
                continue; // blocked, off the map or closed
            }
            let diag = d & 1 == 1;
            // A diagonal needs both orthogonal neighbours it passes between free (d - 1, d + 1).
            if diag && (blocked(d.wrapping_add(7)) || blocked(d.wrapping_add(1))) {
                continue;
            }
            let ni = cur.wrapping_add_signed(offs.get(d).copied().unwrap_or(0));
            let g = cur_g + if diag { SQRT_2 } else { 1.0 };
            let dxy = (
                DX.get(d).copied().unwrap_or(0),
                DY.get(d).copied().unwrap_or(0),
            );
            let nx = x.wrapping_add_signed(dxy.0);
            let ny = y.wrapping_add_signed(dxy.1);
            // ni < cells <= MAX_CELLS = 2^29: the shift keeps every bit.
            let key = ((ni as u32) << 3) | d as u32;
            open.push(Entry {
                f: g + octile(nx, ny, gx, gy),
                g,
                key,
            })?;
        }
        // The next cell to close.
        loop {
            let Some(e) = open.pop() else {
                return Err(AstarError::NoPath);
            };
            let i = (e.key >> 3) as usize;
            if nib(nibbles, i) != FREE {
                continue; // closed already (lazy deletion)
            }
            set_nib(nibbles, i, ((e.key & 7) as u8).wrapping_add(1));
            cur = i;
            cur_g = e.g;
            break;
        }
    }

    // Count the path's steps by walking the parents back.
    let (mut straight, mut diagonal) = (0u32, 0u32);
    for d in path_back(grid, nibbles, goal) {
        match d {
            Ok(d) if is_diagonal(d) => diagonal = diagonal.saturating_add(1),
            Ok(_) => straight = straight.saturating_add(1),
            Err(e) => return Err(e),
        }
    }
    Ok(Search {
        length: steps_length(straight, diagonal),
        straight,
        diagonal,
        expansions,
        pushes: open.pushes,
        peak_heap: u32::try_from(open.peak).unwrap_or(u32::MAX),
    })
}

/// The moves of the path found, from the goal back to the start: each item is the direction the
/// path took *into* the current cell (so the cell before it is one step in [`opposite`] of it).
/// Ends at the start; yields `Err(NoTree)` once (and then ends) if the nibbles do not lead there
/// within `cells` steps.
pub fn path_back<'n>(grid: &Grid<'_>, nibbles: &'n [u8], goal: Point) -> PathBack<'n> {
    PathBack {
        nibbles,
        offs: grid.offsets(),
        at: grid.index(goal),
        left: grid.cells(),
        done: !grid.contains(goal),
    }
}

/// The iterator of [`path_back`].
#[derive(Clone, Debug)]
pub struct PathBack<'n> {
    nibbles: &'n [u8],
    offs: [isize; 8],
    at: usize,
    left: usize,
    done: bool,
}

impl Iterator for PathBack<'_> {
    type Item = Result<Dir, AstarError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let v = nib(self.nibbles, self.at);
        if v == START {
            self.done = true;
            return None;
        }
        if !(1..=8).contains(&v) || self.left == 0 {
            self.done = true;
            return Some(Err(AstarError::NoTree));
        }
        self.left = self.left.wrapping_sub(1);
        let d: Dir = v.wrapping_sub(1);
        let o = self
            .offs
            .get(usize::from(opposite(d)))
            .copied()
            .unwrap_or(0);
        self.at = self.at.wrapping_add_signed(o);
        Some(Ok(d))
    }
}

/// Write the path's cells, start first and goal last, into `out`; returns how many (`steps + 1`,
/// with `s` the [`Search`] the nibbles hold).
pub fn write_path(
    grid: &Grid<'_>,
    nibbles: &[u8],
    goal: Point,
    s: &Search,
    out: &mut [Point],
) -> Result<usize, AstarError> {
    let n = (s.steps() as usize).saturating_add(1);
    let capacity = out.len();
    let slots = out
        .get_mut(..n)
        .ok_or(AstarError::PathTooLong { cells: n, capacity })?;
    let mut p = goal;
    let mut back = path_back(grid, nibbles, goal);
    for slot in slots.iter_mut().rev() {
        *slot = p;
        match back.next() {
            Some(Ok(d)) => {
                let o = usize::from(opposite(d));
                let dx = DX.get(o).copied().unwrap_or(0);
                let dy = DY.get(o).copied().unwrap_or(0);
                // Inside the map by the tree's construction; a bad tree is caught below.
                p = Point::new(
                    p.x.wrapping_add_signed(dx as i16),
                    p.y.wrapping_add_signed(dy as i16),
                );
            }
            Some(Err(e)) => return Err(e),
            None => {}
        }
    }
    // The walk must end exactly at the start after `steps` moves.
    match back.next() {
        None if nib(nibbles, grid.index(p)) == START => Ok(n),
        _ => Err(AstarError::NoTree),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid_of(rows: &[&str]) -> (u16, u16, alloc::vec::Vec<u8>) {
        let h = rows.len();
        let w = rows[0].len();
        let mut bits = alloc::vec![0u8; (w * h).div_ceil(8)];
        for (y, r) in rows.iter().enumerate() {
            for (x, c) in r.chars().enumerate() {
                if c == '#' {
                    let i = y * w + x;
                    bits[i / 8] |= 1 << (i % 8);
                }
            }
        }
        (w as u16, h as u16, bits)
    }

    fn run(
        rows: &[&str],
        s: (u16, u16),
        g: (u16, u16),
    ) -> Result<(Search, alloc::vec::Vec<Point>), AstarError> {
        let (w, h, bits) = grid_of(rows);
        let grid = Grid::new(w, h, &bits).unwrap();
        let mut nib = alloc::vec![0u8; nibble_bytes(grid.cells())];
        let mut heap = alloc::vec![Entry::EMPTY; 8 * grid.cells()];
        let (s, g) = (Point::new(s.0, s.1), Point::new(g.0, g.1));
        let r = search(&grid, s, g, &mut nib, &mut heap)?;
        let mut path = alloc::vec![Point::default(); r.steps() as usize + 1];
        assert_eq!(write_path(&grid, &nib, g, &r, &mut path), Ok(path.len()));
        assert_eq!(path[0], s);
        assert_eq!(*path.last().unwrap(), g);
        for p in path.windows(2) {
            assert!(
                (0..8).any(|d| grid.step(p[0], d) == Some(p[1])),
                "bad step {p:?}"
            );
        }
        Ok((r, path))
    }

    #[test]
    fn open_map_is_octile() {
        let rows = ["......", "......", "......", "......"];
        let (r, path) = run(&rows, (0, 0), (5, 3)).unwrap();
        assert_eq!((r.straight, r.diagonal), (2, 3));
        assert_eq!(r.length, steps_length(2, 3));
        assert_eq!(path.len(), 6);
    }

    #[test]
    fn no_corner_cutting() {
        // The only diagonal gap is between two blocks touching at a corner: it must go round.
        let rows = [".#", "#."];
        assert_eq!(run(&rows, (0, 0), (1, 1)).unwrap_err(), AstarError::NoPath);
        let rows = ["..#", "#..", "..."];
        let (r, _) = run(&rows, (0, 0), (2, 1)).unwrap();
        // (0,0)->(1,0)->(1,1)->(2,1): the diagonal (0,0)->(1,1) is cut by (0,1).
        assert_eq!((r.straight, r.diagonal), (3, 0));
    }

    #[test]
    fn start_is_goal() {
        let (r, path) = run(&["..."], (1, 0), (1, 0)).unwrap();
        assert_eq!((r.steps(), r.length, r.expansions), (0, 0.0, 1));
        assert_eq!(path, [Point::new(1, 0)]);
    }

    #[test]
    fn errors() {
        assert_eq!(
            run(&[".#"], (0, 0), (1, 0)).unwrap_err(),
            AstarError::BadCell(End::Goal)
        );
        assert_eq!(
            run(&[".."], (2, 0), (1, 0)).unwrap_err(),
            AstarError::BadCell(End::Start)
        );
        let (w, h, bits) = grid_of(&["....", "...."]);
        let grid = Grid::new(w, h, &bits).unwrap();
        let mut nib = [0u8; 3];
        let mut heap = [Entry::EMPTY; 1];
        assert_eq!(
            search(
                &grid,
                Point::new(0, 0),
                Point::new(3, 1),
                &mut nib,
                &mut heap
            ),
            Err(AstarError::StorageTooSmall { needed: 4, got: 3 })
        );
        let mut nib = [0u8; 4];
        assert_eq!(
            search(
                &grid,
                Point::new(0, 0),
                Point::new(3, 1),
                &mut nib,
                &mut heap
            ),
            Err(AstarError::HeapFull { capacity: 1 })
        );
        let mut heap = [Entry::EMPTY; 32];
        let r = search(
            &grid,
            Point::new(0, 0),
            Point::new(3, 1),
            &mut nib,
            &mut heap,
        )
        .unwrap();
        let mut short = [Point::default(); 2];
        assert_eq!(
            write_path(&grid, &nib, Point::new(3, 1), &r, &mut short),
            Err(AstarError::PathTooLong {
                cells: 4,
                capacity: 2
            })
        );
        // Nibbles with no tree.
        let fresh = [0u8; 4];
        let mut out = [Point::default(); 8];
        assert_eq!(
            write_path(&grid, &fresh, Point::new(3, 1), &r, &mut out),
            Err(AstarError::NoTree)
        );
        assert!(alloc::format!("{}", AstarError::NoPath).contains("no path"));
    }

    /// Bellman-Ford over `Grid::step` in f64: the optimum, or None.
    fn brute(grid: &Grid<'_>, s: Point, g: Point) -> Option<f64> {
        let n = grid.cells();
        let mut dist = alloc::vec![f64::INFINITY; n];
        dist[grid.index(s)] = 0.0;
        loop {
            let mut changed = false;
            for i in 0..n {
                let p = grid.point(i);
                if !dist[i].is_finite() {
                    continue;
                }
                for d in 0..8u8 {
                    if let Some(q) = grid.step(p, d) {
                        let c = if is_diagonal(d) {
                            core::f64::consts::SQRT_2
                        } else {
                            1.0
                        };
                        let j = grid.index(q);
                        if dist[i] + c < dist[j] - 1e-12 {
                            dist[j] = dist[i] + c;
                            changed = true;
                        }
                    }
                }
            }
            if !changed {
                break;
            }
        }
        dist[grid.index(g)].is_finite().then(|| dist[grid.index(g)])
    }

    #[test]
    fn random_maps_match_brute_force() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for _ in 0..300 {
            let w = 1 + (next() % 12) as u16;
            let h = 1 + (next() % 12) as u16;
            let n = usize::from(w) * usize::from(h);
            let density = next() % 45;
            let mut bits = alloc::vec![0u8; n.div_ceil(8)];
            for i in 0..n {
                if next() % 100 < density {
                    bits[i / 8] |= 1 << (i % 8);
                }
            }
            let (si, gi) = ((next() as usize) % n, (next() as usize) % n);
            for i in [si, gi] {
                bits[i / 8] &= !(1 << (i % 8));
            }
            let grid = Grid::new(w, h, &bits).unwrap();
            let (s, g) = (grid.point(si), grid.point(gi));
            let mut nib = alloc::vec![0u8; nibble_bytes(n)];
            let mut heap = alloc::vec![Entry::EMPTY; 8 * n];
            let got = search(&grid, s, g, &mut nib, &mut heap);
            match (brute(&grid, s, g), got) {
                (None, Err(AstarError::NoPath)) => {}
                (Some(opt), Ok(r)) => {
                    assert!((f64::from(r.length) - opt).abs() < 1e-4, "{opt} vs {r:?}");
                    let mut path = alloc::vec![Point::default(); r.steps() as usize + 1];
                    write_path(&grid, &nib, g, &r, &mut path).unwrap();
                    assert_eq!((path[0], *path.last().unwrap()), (s, g));
                    for p in path.windows(2) {
                        assert!((0..8).any(|d| grid.step(p[0], d) == Some(p[1])));
                    }
                }
                (b, a) => panic!("brute {b:?}, astar {a:?}"),
            }
        }
    }
}
