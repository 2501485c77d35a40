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

//!
//! One concept a file:
//!
//! | file | owns |
//! | --- | --- |
//! | `mod.rs` | the limits, the result ([`Search`]) and the two entry points |
//! | `error` | [`AstarError`] and [`End`] |
//! | `open` | the open list: [`Entry`] and its order, over [`super::heap`] |
//! | `store` | the per-cell state that makes the two variants differ (nibbles, costs) |
//! | `run` | the search loop both variants share, its heuristic and its move pruning |
//! | `path` | reading the path back from the per-cell state and writing it out |

use crate::geometry::steps_length;
use crate::map::dir::{is_diagonal, Dir};
use crate::map::grid::{Grid, Point};

use super::cost;

mod error;
mod open;
mod path;
mod run;
mod store;
#[cfg(test)]
mod tests;

pub use error::{AstarError, End};
pub use open::Entry;
pub use path::{path_back, path_back_costs, write_path, write_path_costs, PathBack, PathBackCosts};
use run::{run, Counts};
use store::{set_nib, Costs, Nibbles};

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
