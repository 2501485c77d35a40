//! The search loop both variants share ([`run`]): expand the current cell's pruned moves
//! ([`forward`]), hold the best new neighbour out of the heap, close the next live entry. Also
//! the octile heuristic on the exact scale. Every index sum stays inside the map, checked up
//! front by the entry points.

use crate::map::dir::{DX, DY};
use crate::map::grid::{Grid, Point};
use crate::search::cost;
use crate::search::heap::Heap;

use super::open::{Entry, Open};
use super::store::Store;
use super::{AstarError, LIMIT};

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

/// What the search loop returns: expansions, pushes, peak heap.
pub(super) struct Counts {
    pub(super) expansions: u32,
    pub(super) pushes: u32,
    pub(super) peak: u32,
}

/// The search loop shared by both variants: start and goal are free cells of `grid`, `store` is
/// fresh with the start recorded (closed, `g = 0`).
#[inline(always)]
pub(super) fn run<S: Store>(
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
