//! An exact 8-connected A*: the baseline the colony is measured against (issue 27), on the same
//! chip and counted the same way. Two variants share one search loop:
//!
//! - [`search`], **4 bits a cell**: a nibble slice holds the closed flag and the parent
//!   direction; `g` lives only in the open list, which therefore holds one entry per push (lazy
//!   deletion: an entry whose cell is already closed is dropped when it is popped).
//! - [`search_costs`], **4 bytes a cell**: a `u32` slice holds each cell's best `g` so far; a
//!   neighbour is pushed only when its `g` improves (fewer entries), a popped entry is live only
//!   if its `g` is still the cell's, and the path is read back from the costs alone (a cell's
//!   parent is a neighbour whose cost plus the step's is exactly the cell's).
//!
//! **What it owns.** One search from a start to a goal cell on a [`Grid`], with the core's own
//! moves ([`crate::map::grid::Grid::step`]: the eight king moves, a diagonal only when both
//! orthogonally adjacent cells are free, so no corner is ever cut; read from the map's bits with
//! [`Grid::mask_at`]). The map's bits are only read: neither variant copies them.
//!
//! **Costs, exact.** A straight step costs [`STRAIGHT`] units, a diagonal [`DIAGONAL`]: the
//! exact scale of [`super::cost`], on which two costs of at most [`MAX_LENGTH`] steps compare
//! exactly as the real lengths do, equality included (the proof is there). Every cost compared
//! (`g`, and `f = g + h` with `h` the octile distance, consistent for these costs) is checked on
//! every push: a cost above `MAX_LENGTH * STRAIGHT` is never stored or queued. The search is
//! therefore exact in the reals, not only up to a float's rounding: the path found is a shortest
//! 8-connected no-corner-cutting path, and [`Search::length`] is recomputed from its step counts
//! with [`steps_length`], the core's own formula, so it compares bit for bit with a core path of
//! the same steps. A goal whose optimum exceeds `MAX_LENGTH` is [`AstarError::TooFar`], never a
//! wrong path.
//!
//! **Order.** The open list is a binary min-heap of [`Entry`] (12 bytes: `f`, `g`, cell and
//! direction) in a caller slice, ordered by smaller `f`, then larger `g` (deeper first). At each
//! expansion the best new neighbour is held out of the heap: if it comes no later than the heap's
//! top (ties go to it) it is expanded next without a push or a pop, else it replaces the top
//! (one sift). Remaining ties (equal `f` and `g`) go to whichever the heap yields first. The search
//! is deterministic: the same inputs give the same path on every platform.
//!
//! **Storage, all the caller's.** [`search`]: [`nibble_bytes`]`(cells)` bytes of nibbles (row
//! major, low nibble first): [`FREE`] (not closed), [`START`] (closed, no parent), or `1..=8`
//! (closed, reached from its parent by direction `nibble - 1`, [`crate::map::dir`]); cleared at the
//! start of each search, and afterwards the parent tree [`write_path`] and [`path_back`] read.
//! [`search_costs`]: `cells` words of `g` (`u32::MAX` = not reached), filled at the start, and
//! afterwards what [`write_path_costs`] and [`path_back_costs`] read. Both: the open list.
//!
//! **Guarantees.** No allocation, no panics (every slice access is a `get`, every index sum is
//! bounded by the map's size, which is checked up front), errors are values ([`AstarError`]).

use core::fmt;

use crate::geometry::steps_length;
use crate::map::dir::{is_diagonal, opposite, Dir, DX, DY};
use crate::map::grid::{Grid, Point};

use super::cost;
use super::heap::{Full, Heap, Keyed};

/// Nibble of a cell not closed yet.
pub const FREE: u8 = 0;
/// Nibble of the start cell once closed (it has no parent).
pub const START: u8 = 9;
/// What a nibble beyond the slice reads as (never stored).
const OFF: u8 = 15;

pub use super::cost::{DIAGONAL, STRAIGHT};

/// Longest optimum (in straight-step lengths) the search decides exactly: costs up to
/// `MAX_LENGTH * STRAIGHT` units are compared exactly ([`super::cost::EXACT_STEPS`]); anything
/// beyond is dropped and, if the goal is not reached, reported as [`AstarError::TooFar`].
pub const MAX_LENGTH: u32 = cost::EXACT_STEPS;
/// The largest cost stored or queued.
const LIMIT: u32 = MAX_LENGTH * STRAIGHT;

/// Largest map the search accepts: the heap packs the cell index and a direction in 32 bits.
pub const MAX_CELLS: usize = 1 << 29;

/// Bytes of nibble storage a map of `cells` cells needs ([`search`]).
pub const fn nibble_bytes(cells: usize) -> usize {
    cells.div_ceil(2)
}

/// Bytes of one open-list entry.
pub const ENTRY_BYTES: usize = core::mem::size_of::<Entry>();

/// One open-list entry: `!g` (so that a larger `g` ranks first), `f = g + h`, and the cell
/// (index `key >> 3`) with the direction it was reached by (`key & 7`), all in cost units. Plain
/// old data (`bytemuck::Pod`), so a caller can carve the open list out of a byte or word buffer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, bytemuck::Pod, bytemuck::Zeroable)]
#[repr(C)]
pub struct Entry {
    ng: u32,
    f: u32,
    key: u32,
}

impl Entry {
    /// An entry to fill caller arrays with (`[Entry::EMPTY; N]`).
    pub const EMPTY: Entry = Entry {
        ng: 0,
        f: 0,
        key: 0,
    };
    /// Ranks after every real entry: "no entry".
    const NONE: Entry = Entry {
        ng: u32::MAX,
        f: u32::MAX,
        key: 0,
    };

    /// The heap's order: smaller first (`f`, then larger `g`).
    #[inline(always)]
    fn rank(&self) -> u64 {
        (u64::from(self.f) << 32) | u64::from(self.ng)
    }

    /// The entry's `g`.
    #[inline(always)]
    fn g(&self) -> u32 {
        !self.ng
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
    /// Entries pushed onto the open list (the neighbours expanded straight away, without a
    /// push, not counted).
    pub pushes: u32,
    /// Most entries the open list held at once.
    pub peak_heap: u32,
    /// Bytes of per-cell storage the search used: [`nibble_bytes`]`(cells)` for [`search`],
    /// `4 * cells` for [`search_costs`].
    pub cell_bytes: usize,
}

impl Search {
    /// Steps on the path (cells on it minus one).
    pub fn steps(&self) -> u32 {
        self.straight.saturating_add(self.diagonal)
    }

    /// Bytes of storage the search used: the per-cell storage plus the open list at its peak
    /// (the map's own bits, which it only reads, not counted).
    pub fn ram_bytes(&self) -> usize {
        self.cell_bytes
            .saturating_add((self.peak_heap as usize).saturating_mul(ENTRY_BYTES))
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
    /// The goal was not reached within [`MAX_LENGTH`]; it may be reachable by a longer path.
    TooFar,
    /// The start or goal is outside the map or blocked.
    BadCell(End),
    /// The per-cell slice is shorter than the map needs, or the map has more than
    /// [`MAX_CELLS`] cells.
    StorageTooSmall {
        /// Elements needed (bytes for [`search`], words for [`search_costs`]).
        needed: usize,
        /// Elements given.
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
    /// The per-cell storage does not hold a path from the start to the goal (not the storage of
    /// a successful search on this map).
    NoTree,
}

impl fmt::Display for AstarError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AstarError::NoPath => f.write_str("no path: the goal is not reachable from the start"),
            AstarError::TooFar => write!(f, "no path of length {MAX_LENGTH} or less"),
            AstarError::BadCell(End::Start) => f.write_str("start is off the map or blocked"),
            AstarError::BadCell(End::Goal) => f.write_str("goal is off the map or blocked"),
            AstarError::StorageTooSmall { needed, got } => {
                write!(f, "per-cell storage: {needed} needed, {got} given")
            }
            AstarError::HeapFull { capacity } => {
                write!(f, "open list full at {capacity} entries")
            }
            AstarError::PathTooLong { cells, capacity } => {
                write!(f, "path has {cells} cells, the slice holds {capacity}")
            }
            AstarError::NoTree => f.write_str("no path from the start to the goal in the storage"),
        }
    }
}

/// The octile distance between cells `(ax, ay)` and `(bx, by)` in cost units (at most
/// `65535 * DIAGONAL < 2^32` on a map of u16 sides).
#[inline(always)]
fn octile(ax: u32, ay: u32, bx: u32, by: u32) -> u32 {
    cost::EXACT.octile(ax.abs_diff(bx), ay.abs_diff(by))
}

/// The moves worth trying from a cell entered by direction `d` (`d >= 8`: the start, every
/// move), given its allowed-move mask `m`: the others lead to a neighbour its parent `p` (one
/// step in [`opposite`]`(d)`, closed before it) reaches directly by a legal move strictly cheaper
/// than the two steps through the cell, so the parent's expansion already queued that neighbour
/// with a smaller `g` (or, by the same rule one step further back, an ancestor did): the entry
/// this cell would push could only ever be stale. Entered straight (`d` even), the kept moves are
/// `d - 1`, `d`, `d + 1`, and `d +- 2` only if the diagonal `p` would take to it is not allowed,
/// i.e. (the cell's `d +- 2` neighbour being free) if cell `d +- 3` is blocked, which is move
/// `d +- 3` not being allowed; entered diagonally, `d - 2 ..= d + 2` (`d +- 3` are one straight
/// step from `p`). Pruning only entries that could never be live keeps the search, its order and
/// its result exactly as without it.
#[inline(always)]
fn forward(d: u32, m: u32) -> u32 {
    let rot = |base: u32| {
        let r = d & 7;
        (base << r | base >> (8u32.wrapping_sub(r) & 7)) & 0xFF
    };
    if d >= 8 {
        0xFF
    } else if d & 1 == 1 {
        rot(0b1100_0111) // d - 2, d - 1, d, d + 1, d + 2
    } else {
        let forced = rot(0b0010_1000) & !m; // cells d + 3 and d + 5 (= d - 3) not allowed
                                            // d + 3 -> d + 2 is a right shift by 1; d + 5 -> d + 6 a left rotation by 1.
        let forced = (forced >> 1 | forced << 7 | forced << 1 | forced >> 7) & 0xFF;
        rot(0b1000_0011) | (forced & rot(0b0100_0100))
    }
}

/// The nibble of cell `i` (`OFF` beyond the slice).
#[inline(always)]
fn nib(nibbles: &[u8], i: usize) -> u8 {
    match nibbles.get(i >> 1) {
        Some(&b) => (b >> ((i & 1) << 2)) & 15,
        None => OFF,
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

impl Keyed for Entry {
    type Key = u64;
    #[inline(always)]
    fn key(&self) -> u64 {
        self.rank()
    }
}

/// The open list: the crate's binary min-heap ([`super::heap`]) of entries over the caller's
/// slice, and what the search reports of it.
struct Open<'h> {
    heap: Heap<'h, Entry>,
    peak: usize,
    pushes: u32,
}

impl Open<'_> {
    #[inline(never)]
    fn push(&mut self, e: Entry) -> Result<(), AstarError> {
        self.heap
            .push(e)
            .map_err(|Full { capacity }| AstarError::HeapFull { capacity })?;
        if self.heap.len() > self.peak {
            self.peak = self.heap.len();
        }
        self.pushes = self.pushes.wrapping_add(1);
        Ok(())
    }

    /// The top entry ([`Entry::NONE`] if the heap is empty).
    #[inline(always)]
    fn top(&self) -> Entry {
        self.heap.top().unwrap_or(Entry::NONE)
    }

    #[inline(always)]
    fn pop(&mut self) -> Option<Entry> {
        self.heap.pop()
    }

    /// Pop the top and push `e` in one sift (the heap must not be empty).
    #[inline(always)]
    fn replace_top(&mut self, e: Entry) -> Entry {
        self.pushes = self.pushes.wrapping_add(1);
        self.heap.replace_top(e).unwrap_or(Entry::NONE)
    }
}

/// The per-cell state a search keeps: what makes the two variants differ.
trait Store {
    /// Neighbour `i` is reached with cost `g`: true if it is worth an open-list entry.
    fn offer(&mut self, i: usize, g: u32) -> bool;
    /// An entry for cell `i` with cost `g`, reached by direction `d`, leaves the open list: true
    /// if it is live (then the cell is closed).
    fn take(&mut self, i: usize, g: u32, d: u8) -> bool;
}

/// [`search`]'s store: the nibbles.
struct Nibbles<'n>(&'n mut [u8]);

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
struct Costs<'c>(&'c mut [u32]);

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

/// Check the storage, the map's size and the ends.
fn check(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    needed: usize,
    got: usize,
) -> Result<(), AstarError> {
    if got < needed || grid.cells() > MAX_CELLS {
        return Err(AstarError::StorageTooSmall { needed, got });
    }
    if !grid.is_free(start) {
        return Err(AstarError::BadCell(End::Start));
    }
    if !grid.is_free(goal) {
        return Err(AstarError::BadCell(End::Goal));
    }
    Ok(())
}

/// What the search loop returns: expansions, pushes, peak heap.
struct Counts {
    expansions: u32,
    pushes: u32,
    peak: u32,
}

/// The search loop shared by both variants: start and goal are free cells of `grid`, `store` is
/// fresh with the start recorded (closed, `g = 0`).
#[inline(always)]
fn run<S: Store>(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    store: &mut S,
    heap: &mut [Entry],
) -> Result<Counts, AstarError> {
    let w = u32::from(grid.width());
    let (gx, gy) = (u32::from(goal.x), u32::from(goal.y));
    let goal_i = grid.index(goal);
    // Per direction: index offset, cost, dx, dy. Every sum below is taken only for a neighbour
    // inside the map (the move mask says so), so it stays in 0..cells (wrapping arithmetic on
    // usize is exact there).
    let offs = grid.offsets();
    let mut moves = [(0isize, 0u32, 0u32, 0u32); 8];
    for (d, m) in moves.iter_mut().enumerate() {
        *m = (
            offs.get(d).copied().unwrap_or(0),
            cost::step(d as u8),
            DX.get(d).copied().unwrap_or(0) as u32,
            DY.get(d).copied().unwrap_or(0) as u32,
        );
    }
    let mut open = Open {
        heap: Heap::new(heap),
        peak: 0,
        pushes: 0,
    };
    let mut expansions: u32 = 0;
    let mut too_far = false;

    let mut cur = grid.index(start);
    let mut cur_g = 0u32;
    let (mut x, mut y) = (u32::from(start.x), u32::from(start.y));
    let mut cur_d = 8u32; // the direction `cur` was entered by; 8: the start
    loop {
        expansions = expansions.wrapping_add(1);
        if cur == goal_i {
            break;
        }
        // The allowed moves: inside the map, free, no corner cut.
        let m = u32::from(grid.mask_at(Point::new(x as u16, y as u16)));
        let mut m = m & forward(cur_d, m);
        let mut best = Entry::NONE;
        while m != 0 {
            let d = m.trailing_zeros() & 7;
            m &= m.wrapping_sub(1);
            let (o, c, dx, dy) = moves.get(d as usize).copied().unwrap_or_default();
            let ni = cur.wrapping_add_signed(o);
            // cur_g <= LIMIT < 2^31 and c < 2^16: no wrap.
            let g = cur_g.wrapping_add(c);
            if g > LIMIT {
                too_far = true;
                continue;
            }
            if !store.offer(ni, g) {
                continue; // closed, or (costs) no better than what it has
            }
            let f = g.saturating_add(octile(x.wrapping_add(dx), y.wrapping_add(dy), gx, gy));
            if f > LIMIT {
                too_far = true;
                continue;
            }
            // ni < cells <= MAX_CELLS = 2^29: the shift keeps every bit.
            let e = Entry {
                ng: !g,
                f,
                key: ((ni as u32) << 3) | d,
            };
            if e.rank() < best.rank() {
                if best != Entry::NONE {
                    open.push(best)?;
                }
                best = e;
            } else {
                open.push(e)?;
            }
        }
        // The next cell to close: the held-out neighbour if it ranks no later than the top.
        let mut next = if best == Entry::NONE {
            None
        } else if best.rank() <= open.top().rank() {
            Some(best)
        } else {
            Some(open.replace_top(best))
        };
        loop {
            let Some(e) = next.or_else(|| open.pop()) else {
                return Err(if too_far {
                    AstarError::TooFar
                } else {
                    AstarError::NoPath
                });
            };
            let i = (e.key >> 3) as usize;
            let g = e.g();
            if store.take(i, g, (e.key & 7) as u8) {
                cur = i;
                cur_g = g;
                cur_d = e.key & 7;
                // i < cells <= 2^29 and w > 0 (Grid::new checks it).
                let i = i as u32;
                x = i.checked_rem(w).unwrap_or(0);
                y = i.checked_div(w).unwrap_or(0);
                break;
            }
            next = None; // stale (lazy deletion)
        }
    }
    Ok(Counts {
        expansions,
        pushes: open.pushes,
        peak: u32::try_from(open.peak).unwrap_or(u32::MAX),
    })
}

/// Count the straight and diagonal steps of a path read back.
fn count_steps(
    back: impl Iterator<Item = Result<Dir, AstarError>>,
) -> Result<(u32, u32), AstarError> {
    let (mut straight, mut diagonal) = (0u32, 0u32);
    for d in back {
        if is_diagonal(d?) {
            diagonal = diagonal.saturating_add(1);
        } else {
            straight = straight.saturating_add(1);
        }
    }
    Ok((straight, diagonal))
}

fn finish(c: Counts, (straight, diagonal): (u32, u32), cell_bytes: usize) -> Search {
    Search {
        length: steps_length(straight, diagonal),
        straight,
        diagonal,
        expansions: c.expansions,
        pushes: c.pushes,
        peak_heap: c.peak,
        cell_bytes,
    }
}

/// Search a shortest path from `start` to `goal` on `grid` in 4 bits a cell: the caller's
/// `nibbles` (at least [`nibble_bytes`]`(grid.cells())` bytes) and open list `heap`. On success
/// the nibbles hold the parent tree: [`write_path`] and [`path_back`] read the path from them.
pub fn search(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    nibbles: &mut [u8],
    heap: &mut [Entry],
) -> Result<Search, AstarError> {
    let needed = nibble_bytes(grid.cells());
    check(grid, start, goal, needed, nibbles.len())?;
    let nibbles = nibbles.get_mut(..needed).unwrap_or(&mut []);
    nibbles.fill(0);
    set_nib(nibbles, grid.index(start), START);
    let mut store = Nibbles(nibbles);
    let c = run(grid, start, goal, &mut store, heap)?;
    let steps = count_steps(path_back(grid, store.0, goal))?;
    Ok(finish(c, steps, needed))
}

/// Search a shortest path from `start` to `goal` on `grid` with a `g` a cell: the caller's
/// `costs` (at least `grid.cells()` words) and open list `heap`. A neighbour is queued only when
/// its cost improves. On success the costs hold every reached cell's best `g` (`u32::MAX` where
/// none): [`write_path_costs`] and [`path_back_costs`] read the path from them.
pub fn search_costs(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    costs: &mut [u32],
    heap: &mut [Entry],
) -> Result<Search, AstarError> {
    let needed = grid.cells();
    check(grid, start, goal, needed, costs.len())?;
    let costs = costs.get_mut(..needed).unwrap_or(&mut []);
    costs.fill(u32::MAX);
    if let Some(c) = costs.get_mut(grid.index(start)) {
        *c = 0;
    }
    let mut store = Costs(costs);
    let c = run(grid, start, goal, &mut store, heap)?;
    let steps = count_steps(path_back_costs(grid, store.0, goal))?;
    Ok(finish(c, steps, needed.saturating_mul(4)))
}

/// The moves of the path [`search`] found, from the goal back to the start: each item is the
/// direction the path took *into* the current cell (so the cell before it is one step in
/// [`opposite`] of it). Ends at the start; yields `Err(NoTree)` once (and then ends) if the
/// nibbles do not lead there within `cells` steps.
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

/// The moves of the path [`search_costs`] found, from the goal back to the start, as
/// [`path_back`] gives them: at each cell, the first direction `d` (in `0..8`) whose move into
/// the cell is allowed from a neighbour with exactly the cell's cost less the step's (so a
/// shortest path; among equals, the first direction). Ends at the start (cost 0); yields
/// `Err(NoTree)` once (and then ends) if no such neighbour exists.
pub fn path_back_costs<'g, 'c>(
    grid: &Grid<'g>,
    costs: &'c [u32],
    goal: Point,
) -> PathBackCosts<'g, 'c> {
    PathBackCosts {
        grid: *grid,
        costs,
        at: goal,
        done: !grid.contains(goal),
    }
}

/// The iterator of [`path_back_costs`].
#[derive(Clone, Debug)]
pub struct PathBackCosts<'g, 'c> {
    grid: Grid<'g>,
    costs: &'c [u32],
    at: Point,
    done: bool,
}

impl Iterator for PathBackCosts<'_, '_> {
    type Item = Result<Dir, AstarError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.done {
            return None;
        }
        let cost = |p: Point| self.costs.get(self.grid.index(p)).copied();
        let g = match cost(self.at) {
            Some(0) => {
                self.done = true;
                return None;
            }
            Some(g) if g != u32::MAX => g,
            _ => {
                self.done = true;
                return Some(Err(AstarError::NoTree));
            }
        };
        // The costs strictly decrease along the walk, so it ends.
        for d in 0..8u8 {
            if let Some(p) = self.grid.step(self.at, opposite(d)) {
                if cost(p).and_then(|c| c.checked_add(cost::step(d))) == Some(g) {
                    self.at = p;
                    return Some(Ok(d));
                }
            }
        }
        self.done = true;
        Some(Err(AstarError::NoTree))
    }
}

/// Write the cells of the path `back` walks from `goal`, start first and goal last, into `out`;
/// `is_start` checks the cell the walk ends at.
fn write_from(
    mut back: impl Iterator<Item = Result<Dir, AstarError>>,
    is_start: impl Fn(Point) -> bool,
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
        None if is_start(p) => Ok(n),
        _ => Err(AstarError::NoTree),
    }
}

/// Write the path [`search`] found, start first and goal last, into `out`; returns how many
/// cells (`steps + 1`, with `s` the [`Search`] the nibbles hold).
pub fn write_path(
    grid: &Grid<'_>,
    nibbles: &[u8],
    goal: Point,
    s: &Search,
    out: &mut [Point],
) -> Result<usize, AstarError> {
    let back = path_back(grid, nibbles, goal);
    write_from(back, |p| nib(nibbles, grid.index(p)) == START, goal, s, out)
}

/// Write the path [`search_costs`] found, start first and goal last, into `out`; returns how
/// many cells (`steps + 1`, with `s` the [`Search`] the costs hold).
pub fn write_path_costs(
    grid: &Grid<'_>,
    costs: &[u32],
    goal: Point,
    s: &Search,
    out: &mut [Point],
) -> Result<usize, AstarError> {
    let back = path_back_costs(grid, costs, goal);
    write_from(back, |p| costs.get(grid.index(p)) == Some(&0), goal, s, out)
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

    /// Which variant a test runs.
    #[derive(Clone, Copy, Debug)]
    enum V {
        Nibbles,
        Costs,
    }
    const BOTH: [V; 2] = [V::Nibbles, V::Costs];

    /// Search with variant `v` and write the path (checked move by move).
    fn solve(
        v: V,
        grid: &Grid<'_>,
        s: Point,
        g: Point,
        heap_len: usize,
    ) -> Result<(Search, alloc::vec::Vec<Point>), AstarError> {
        let n = grid.cells();
        let mut heap = alloc::vec![Entry::EMPTY; heap_len];
        let mut nib = alloc::vec![0u8; nibble_bytes(n)];
        let mut costs = alloc::vec![0u32; n];
        let r = match v {
            V::Nibbles => search(grid, s, g, &mut nib, &mut heap)?,
            V::Costs => search_costs(grid, s, g, &mut costs, &mut heap)?,
        };
        let mut path = alloc::vec![Point::default(); r.steps() as usize + 1];
        let written = match v {
            V::Nibbles => write_path(grid, &nib, g, &r, &mut path),
            V::Costs => write_path_costs(grid, &costs, g, &r, &mut path),
        };
        assert_eq!(written, Ok(path.len()));
        assert_eq!((path[0], *path.last().unwrap()), (s, g));
        let (mut st, mut di) = (0, 0);
        for p in path.windows(2) {
            let d = (0..8).find(|&d| grid.step(p[0], d) == Some(p[1]));
            match d {
                Some(d) if is_diagonal(d) => di += 1,
                Some(_) => st += 1,
                None => panic!("bad step {p:?}"),
            }
        }
        assert_eq!((st, di), (r.straight, r.diagonal));
        assert!(r.peak_heap <= r.pushes);
        Ok((r, path))
    }

    fn run(
        v: V,
        rows: &[&str],
        s: (u16, u16),
        g: (u16, u16),
    ) -> Result<(Search, alloc::vec::Vec<Point>), AstarError> {
        let (w, h, bits) = grid_of(rows);
        let grid = Grid::new(w, h, &bits).unwrap();
        let (s, g) = (Point::new(s.0, s.1), Point::new(g.0, g.1));
        solve(v, &grid, s, g, 8 * grid.cells())
    }

    #[test]
    fn costs_stay_below_2_31() {
        // The largest sums stay below 2^32 (f = g + h saturates above LIMIT).
        assert!(u64::from(LIMIT) + u64::from(DIAGONAL) < 1 << 31);
    }

    #[test]
    fn open_map_is_octile() {
        let rows = ["......", "......", "......", "......"];
        for v in BOTH {
            let (r, path) = run(v, &rows, (0, 0), (5, 3)).unwrap();
            assert_eq!((r.straight, r.diagonal), (2, 3));
            assert_eq!(r.length, steps_length(2, 3));
            assert_eq!(path.len(), 6);
            // Deeper first and the held-out neighbour: straight down the optimal corridor.
            assert_eq!(r.expansions, 6, "{v:?}");
        }
    }

    #[test]
    fn no_corner_cutting() {
        for v in BOTH {
            // The only diagonal gap is between two blocks touching at a corner: it must go round.
            let rows = [".#", "#."];
            assert_eq!(
                run(v, &rows, (0, 0), (1, 1)).unwrap_err(),
                AstarError::NoPath
            );
            let rows = ["..#", "#..", "..."];
            let (r, _) = run(v, &rows, (0, 0), (2, 1)).unwrap();
            // (0,0)->(1,0)->(1,1)->(2,1): the diagonal (0,0)->(1,1) is cut by (0,1).
            assert_eq!((r.straight, r.diagonal), (3, 0));
        }
    }

    #[test]
    fn start_is_goal() {
        for v in BOTH {
            let (r, path) = run(v, &["..."], (1, 0), (1, 0)).unwrap();
            assert_eq!((r.steps(), r.length, r.expansions), (0, 0.0, 1));
            assert_eq!(path, [Point::new(1, 0)]);
        }
    }

    #[test]
    fn errors() {
        for v in BOTH {
            assert_eq!(
                run(v, &[".#"], (0, 0), (1, 0)).unwrap_err(),
                AstarError::BadCell(End::Goal)
            );
            assert_eq!(
                run(v, &[".."], (2, 0), (1, 0)).unwrap_err(),
                AstarError::BadCell(End::Start)
            );
        }
        let (w, h, bits) = grid_of(&["....", "...."]);
        let grid = Grid::new(w, h, &bits).unwrap();
        let (s, g) = (Point::new(0, 0), Point::new(3, 1));
        let mut heap = [Entry::EMPTY; 1];
        let mut nib = [0u8; 3];
        let mut costs = [0u32; 7];
        assert_eq!(
            search(&grid, s, g, &mut nib, &mut heap),
            Err(AstarError::StorageTooSmall { needed: 4, got: 3 })
        );
        assert_eq!(
            search_costs(&grid, s, g, &mut costs, &mut heap),
            Err(AstarError::StorageTooSmall { needed: 8, got: 7 })
        );
        // The first expansion holds one of its three neighbours out and pushes two.
        let mut nib = [0u8; 4];
        let mut costs = [0u32; 8];
        assert_eq!(
            search(&grid, s, g, &mut nib, &mut heap),
            Err(AstarError::HeapFull { capacity: 1 })
        );
        assert_eq!(
            search_costs(&grid, s, g, &mut costs, &mut heap),
            Err(AstarError::HeapFull { capacity: 1 })
        );
        let mut heap = [Entry::EMPTY; 32];
        let r = search(&grid, s, g, &mut nib, &mut heap).unwrap();
        assert_eq!(r.ram_bytes(), 4 + 12 * r.peak_heap as usize);
        let mut short = [Point::default(); 2];
        let too_long = Err(AstarError::PathTooLong {
            cells: 4,
            capacity: 2,
        });
        assert_eq!(write_path(&grid, &nib, g, &r, &mut short), too_long);
        let rc = search_costs(&grid, s, g, &mut costs, &mut heap).unwrap();
        assert_eq!(rc.ram_bytes(), 32 + 12 * rc.peak_heap as usize);
        assert_eq!(
            write_path_costs(&grid, &costs, g, &rc, &mut short),
            too_long
        );
        // Storage with no tree.
        let mut out = [Point::default(); 8];
        assert_eq!(
            write_path(&grid, &[0u8; 4], g, &r, &mut out),
            Err(AstarError::NoTree)
        );
        assert_eq!(
            write_path_costs(&grid, &[u32::MAX; 8], g, &rc, &mut out),
            Err(AstarError::NoTree)
        );
        // Costs that lead nowhere: the goal's cost has no neighbour one step cheaper.
        let mut bad = [u32::MAX; 8];
        bad[grid.index(g)] = 3 * STRAIGHT;
        bad[grid.index(s)] = 0;
        assert_eq!(
            write_path_costs(&grid, &bad, g, &rc, &mut out),
            Err(AstarError::NoTree)
        );
        assert!(alloc::format!("{}", AstarError::NoPath).contains("no path"));
        assert!(alloc::format!("{}", AstarError::TooFar).contains("36000"));
    }

    /// A serpentine of 1-wide rows `w` long joined at alternate ends: its only path, from the
    /// top-left corner to the end of the last row, is `rows (w - 1) + 2 (rows - 1)` straight
    /// steps.
    fn serpentine(w: usize, rows: usize) -> (u16, u16, alloc::vec::Vec<u8>) {
        let h = 2 * rows - 1;
        let mut bits = alloc::vec![0u8; (w * h).div_ceil(8)];
        for y in (1..h).step_by(2) {
            let gap = if y % 4 == 1 { w - 1 } else { 0 };
            for x in (0..w).filter(|&x| x != gap) {
                let i = y * w + x;
                bits[i / 8] |= 1 << (i % 8);
            }
        }
        (w as u16, h as u16, bits)
    }

    #[test]
    fn long_paths_exact_up_to_max_length_then_too_far() {
        let w = 300usize;
        for (rows, fits) in [(101usize, true), (123, false)] {
            let (gw, gh, bits) = serpentine(w, rows);
            let grid = Grid::new(gw, gh, &bits).unwrap();
            let goal_x = if rows % 2 == 1 { w - 1 } else { 0 };
            let (s, g) = (Point::new(0, 0), Point::new(goal_x as u16, gh - 1));
            let steps = (rows * (w - 1) + 2 * (rows - 1)) as u32;
            for v in BOTH {
                let got = solve(v, &grid, s, g, 64);
                if fits {
                    let (r, _) = got.unwrap();
                    assert_eq!((r.straight, r.diagonal), (steps, 0), "{v:?}");
                } else {
                    assert!(steps > MAX_LENGTH);
                    assert_eq!(got.unwrap_err(), AstarError::TooFar, "{v:?}");
                }
            }
        }
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
        for _ in 0..400 {
            let w = 1 + (next() % 14) as u16;
            let h = 1 + (next() % 14) as u16;
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
            for v in BOTH {
                match (brute(&grid, s, g), solve(v, &grid, s, g, 8 * n)) {
                    (None, Err(AstarError::NoPath)) => {}
                    (Some(opt), Ok((r, _))) => {
                        let exact = f64::from(r.straight)
                            + f64::from(r.diagonal) * core::f64::consts::SQRT_2;
                        assert!((exact - opt).abs() < 1e-9, "{v:?}: {opt} vs {r:?}");
                    }
                    (b, a) => panic!("{v:?}: brute {b:?}, astar {a:?}"),
                }
            }
        }
    }
}
