//! Dead-end pruning: before any ant runs, mark the free cells no shortest path needs, so ants
//! never walk into them (they are tabu from the start of every walk).
//!
//! A cell `v` (not the start or the goal) is **prunable** when every two of its remaining
//! neighbours are themselves one allowed move apart (its neighbourhood is a clique of the move
//! graph). Then any path `u -> v -> w` can be replaced by the single move `u -> w`, which costs 1
//! or `sqrt 2`, less than the two moves through `v` (at least 2). Removing `v` therefore keeps the
//! exact shortest distance between every two remaining cells, and the start and the goal stay
//! connected whenever they were. Removing a cell only shrinks its neighbours' neighbourhoods, and a
//! part of a clique is a clique, so pruning is repeated until nothing changes and the result is the
//! same whatever the order (the largest fixed point).
//!
//! What it removes: every dead-end corridor of width 1 and 2 (a perfect maze shrinks to the path
//! between start and goal), the corners of rooms and pockets. What it keeps: everything a shortest
//! path could use. Pruned cells stay free on the map, so the no-corner-cutting rule, which looks
//! at the map, is unchanged.
//!
//! This is not in the paper. The paper's ants die in dead ends and ours backtrack out of them; on a
//! 512 x 512 maze an ant would otherwise explore most of the maze's dead branches on every walk
//! (`docs/ALGORITHM.md`).
//!
//! Cost: one pass over the map plus a few checks per pruned cell; memory: the `dead` bit set and a
//! stack of any length (a full stack only means one more pass).

use crate::map::bitmap;
use crate::map::grid::{Moves, Point};

/// For each set of neighbour directions `N` (bit `d` = direction `d`, even = straight): 0 if `N`
/// is not a clique of the move graph, 1 if it is, `2 + d` if it is iff the diagonal neighbour `d`
/// is free (two straight neighbours `d - 1` and `d + 1` are one diagonal move apart only when the
/// cell between them, `d`, is free; the other cell the move passes is the centre).
#[allow(clippy::indexing_slicing, clippy::arithmetic_side_effects)]
static CLIQUE: [u8; 256] = {
    let mut t = [0u8; 256];
    let mut n = 0usize;
    while n < 256 {
        let ones = (n as u8).count_ones();
        let mut v = if ones <= 1 { 1u8 } else { 0u8 };
        let mut r = 0usize;
        while r < 8 && v != 1 {
            // The arc r, r + 1, r + 2 (mod 8).
            let arc = (1usize << r) | (1 << ((r + 1) % 8)) | (1 << ((r + 2) % 8));
            if n & !arc & 0xFF == 0 {
                let ends = (n >> r) & 1 == 1 && (n >> ((r + 2) % 8)) & 1 == 1;
                if !ends {
                    v = 1; // neighbours on the ring: always one straight move apart
                } else if r % 2 == 0 {
                    v = 2 + ((r + 1) % 8) as u8;
                }
                // Two diagonal ends are two cells apart: not a clique with this arc.
            }
            r += 1;
        }
        t[n] = v;
        n += 1;
    }
    t
};

/// Mark the prunable cells of `grid` in `dead` (a bit set of at least `words(cells)` words,
/// cleared first). `stack` is scratch of any length. Returns the number of cells marked.
pub fn prune(
    moves: &Moves<'_>,
    start: Point,
    goal: Point,
    dead: &mut [u32],
    stack: &mut [u32],
) -> u32 {
    let mut at = begin(moves, dead);
    loop {
        if let Some(n) = resume(moves, start, goal, dead, stack, &mut at, u32::MAX) {
            return n;
        }
    }
}

/// Where a pruning in pieces ([`begin`], [`resume`]) paused: 8 bytes, kept by the run between
/// its pieces. The stack is empty between two cells, so nothing else carries over.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Pruning {
    /// The next cell: the first of a 32-cell window in the first pass, the next cell in a full
    /// pass.
    next: u32,
    /// In the full passes (a full stack dropped some neighbours).
    again: bool,
    /// The stack was too short for some neighbours in the pass under way.
    full: bool,
}

/// Start a pruning in pieces: clear `dead` (as [`prune`] does).
pub fn begin(moves: &Moves<'_>, dead: &mut [u32]) -> Pruning {
    bitmap::clear(dead, moves.grid().cells());
    Pruning::default()
}

/// Go on with the pruning [`begin`] started until it ends (`Some(cells marked)`: the same marks
/// as [`prune`], bit for bit, since the result does not depend on the order) or about `budget`
/// cells were tried (`None`: call again with the same `at`). The budget is checked between two
/// 32-cell windows of the first pass and between two cells of a full pass; the depth-first
/// settling of one pruned cell runs to its end (its stack is empty between two cells).
pub fn resume(
    moves: &Moves<'_>,
    start: Point,
    goal: Point,
    dead: &mut [u32],
    stack: &mut [u32],
    at: &mut Pruning,
    budget: u32,
) -> Option<u32> {
    let grid = *moves.grid();
    let cells = grid.cells();
    if dead.len() < bitmap::words(cells) {
        return Some(0);
    }
    let offsets = grid.offsets();
    let (si, gi) = (grid.index(start), grid.index(goal));
    let (w, h) = (usize::from(grid.width()), usize::from(grid.height()));
    // Each try: the local rule at a cell, then depth-first over the neighbours whose
    // neighbourhood just shrank (as `repair`'s re-pruning does); `touched` is not needed here.
    let mut settle = Settle {
        moves,
        offsets: &offsets,
        si,
        gi,
        stack,
        full: at.full,
        touched: None,
        tried: 0,
    };
    let mut next = at.next as usize;
    // The first pass tries only the cells that could be prunable on the map as it is, before any
    // mark: a cell with free cells on two opposite sides (west and east, or north and south) is
    // not (those two are two cells apart, so its neighbourhood is no clique). Skipping the others
    // is exact: a cell's neighbourhood changes only when a neighbour is pruned, and that pushes
    // the cell onto the stack, where it is tried with its neighbourhood as it then is. The test
    // is 32 cells at a time (`Grid::free_window`): on a city map about one free cell in ten is
    // tried (issue 27: the full scan was 5 M instructions of a 256 x 256 plan on the Cortex-M4).
    if !at.again && w > 0 {
        // One division on entering; the windows then step `x0` and `y`.
        let (mut y, mut x0) = (
            next.checked_div(w).unwrap_or(0),
            next.checked_rem(w).unwrap_or(0),
        );
        loop {
            if x0 >= w {
                (y, x0) = (y.wrapping_add(1), 0);
            }
            if y >= h {
                at.again = true;
                next = cells;
                break;
            }
            if settle.tried >= budget {
                at.next = y.wrapping_mul(w).wrapping_add(x0) as u32; // a cell index: < 2^32
                at.full = settle.full;
                return None;
            }
            let row = y.wrapping_mul(w);
            let free = grid.free_window(y, x0);
            let north = if y > 0 {
                grid.free_window(y.wrapping_sub(1), x0)
            } else {
                0
            };
            let south = if y.wrapping_add(1) < h {
                grid.free_window(y.wrapping_add(1), x0)
            } else {
                0
            };
            // Bit j is column x0 - 1 + j.
            let run = grid.run_bits(x0);
            let mut m = free & !((free << 1) & (free >> 1)) & !(north & south) & run;
            // A window's test counts as a try: the budget bounds the scan too.
            settle.tried = settle.tried.wrapping_add(1);
            while m != 0 {
                let j = m.trailing_zeros() as usize;
                m &= m.wrapping_sub(1);
                // j >= 1: column x0 - 1 + j.
                settle.at(dead, row.wrapping_add(x0).wrapping_add(j).wrapping_sub(1));
                settle.tried = settle.tried.wrapping_add(1);
            }
            x0 = x0.wrapping_add(32);
        }
    }
    // A full stack dropped some neighbours: a pass over every free cell finds what they would
    // have, as many times as it takes (`next == cells`: a pass ended). The budget is checked
    // every `FULL_CHUNK` cells (each counts as a try).
    const FULL_CHUNK: usize = 64;
    loop {
        if next >= cells {
            if !settle.full {
                break;
            }
            settle.full = false;
            next = 0;
        }
        if settle.tried >= budget {
            at.next = next as u32; // a cell index: < 2^32
            at.full = settle.full;
            return None;
        }
        let stop = next.saturating_add(FULL_CHUNK).min(cells);
        for ci in next..stop {
            // Blocked cells are never pruned: skip them before computing anything.
            if !grid.blocked_at(ci) {
                settle.at(dead, ci);
            }
        }
        settle.tried = settle.tried.wrapping_add(FULL_CHUNK as u32);
        next = stop;
    }
    *at = Pruning {
        next: cells as u32,
        again: true,
        full: false,
    };
    Some(bitmap::count(dead, cells))
}

/// A rectangle of cells, corners included: `(top-left, bottom-right)`.
pub type Rect = (Point, Point);

/// What [`repair`] changed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Repaired {
    /// Cells marked now (all of them, as [`prune`] returns).
    pub pruned: u32,
    /// A rectangle holding every cell whose mark may differ from before (`None`: none does).
    pub touched: Option<Rect>,
    /// True if the local repair ran out of stack and pruned the whole map again instead.
    pub rebuilt: bool,
}

/// Repair the marks [`prune`] left in `dead` for `old_start` and `goal` after the map changed
/// inside `changed` (or nowhere) and the start moved to `start`, so that `dead` ends equal to
/// `prune(moves, start, goal, ..)` on the map as it is now, bit for bit, without a pass over
/// the map.
///
/// Pruning is the least set closed under the local rule (a cell goes when its remaining
/// neighbours are a clique; see the module docs), which only ever looks at a cell's 3 x 3
/// neighbourhood of the map and of the marks. So:
///
/// 1. **Un-prune** every marked cell within one cell of `changed` (its neighbourhood changed)
///    and the new start (now exempt), and then every marked cell 8-connected to one un-pruned:
///    a connected group of marks that touches none of these was derived from the unchanged
///    map and from marks of its own group only, so it is still derivable; any other mark may
///    not be, and is dropped.
/// 2. **Re-prune** from the local rule, as [`prune`] does, on the candidates: the un-pruned
///    cells, the cells within one cell of `changed`, the old start (no longer exempt), and the
///    neighbours of every cell pruned here. Any other cell was not prunable before with at
///    least as many marks around it and an unchanged neighbourhood, so it is not now.
///
/// Both steps are exact (a property test compares them with [`prune`] on random maps with random
/// changes). `stack` is scratch: the un-pruned cells and the re-pruning's stack. If it is too
/// short, the whole map is pruned again ([`Repaired::rebuilt`]), with the same result.
pub fn repair(
    moves: &Moves<'_>,
    (old_start, start, goal): (Point, Point, Point),
    changed: Option<Rect>,
    dead: &mut [u32],
    stack: &mut [u32],
) -> Repaired {
    let grid = *moves.grid();
    let cells = grid.cells();
    let rebuild = |dead: &mut [u32], stack: &mut [u32]| {
        let pruned = prune(moves, start, goal, dead, stack);
        let last = grid.point(cells.saturating_sub(1));
        Repaired {
            pruned,
            touched: Some((Point::new(0, 0), last)),
            rebuilt: true,
        }
    };
    if dead.len() < bitmap::words(cells) || cells == 0 {
        return rebuild(dead, stack);
    }
    let offsets = grid.offsets();
    let (si, gi) = (grid.index(start), grid.index(goal));
    // The cells within one cell of the changes, clamped to the map.
    let near = changed.map(|(lo, hi)| {
        let max = grid.point(cells.wrapping_sub(1));
        (
            Point::new(lo.x.saturating_sub(1), lo.y.saturating_sub(1)),
            Point::new(
                hi.x.saturating_add(1).min(max.x),
                hi.y.saturating_add(1).min(max.y),
            ),
        )
    });
    let mut touched = Bounds::default();
    // 1. Un-prune: `stack[..n]` lists the cells un-pruned, and is also the flood's queue.
    let mut n = 0usize;
    let mut full = false;
    let mut unprune = |dead: &mut [u32], stack: &mut [u32], n: &mut usize, ci: usize| {
        if !bitmap::get(dead, ci) {
            return;
        }
        bitmap::unset(dead, ci);
        touched.add(grid.point(ci));
        match stack.get_mut(*n) {
            Some(s) => {
                *s = ci as u32; // a cell index: < 2^32
                *n = n.wrapping_add(1);
            }
            None => full = true,
        }
    };
    if let Some((lo, hi)) = near {
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                unprune(dead, stack, &mut n, grid.index(Point::new(x, y)));
            }
        }
    }
    unprune(dead, stack, &mut n, si);
    let mut i = 0usize;
    while i < n {
        let Some(&ci) = stack.get(i) else { break };
        i = i.wrapping_add(1);
        let p = grid.point(ci as usize);
        for d in 0..8u8 {
            if let Some(q) = grid.step(p, d) {
                unprune(dead, stack, &mut n, grid.index(q));
            }
        }
    }
    if full {
        return rebuild(dead, stack);
    }
    // 2. Re-prune from the candidates, with the rest of `stack` as the cascade's stack.
    let (list, rest) = stack.split_at_mut(n.min(stack.len()));
    let mut settle = Settle {
        moves,
        offsets: &offsets,
        si,
        gi,
        stack: rest,
        full: false,
        touched: Some(&mut touched),
        tried: 0,
    };
    for &ci in list.iter() {
        settle.at(dead, ci as usize);
    }
    if let Some((lo, hi)) = near {
        for y in lo.y..=hi.y {
            for x in lo.x..=hi.x {
                settle.at(dead, grid.index(Point::new(x, y)));
            }
        }
    }
    if grid.contains(old_start) {
        settle.at(dead, grid.index(old_start));
    }
    if settle.full {
        return rebuild(dead, stack);
    }
    Repaired {
        pruned: bitmap::count(dead, cells),
        touched: touched.rect(),
        rebuilt: false,
    }
}

/// The bounding box of some cells.
#[derive(Clone, Copy, Debug, Default)]
struct Bounds(Option<Rect>);

impl Bounds {
    fn add(&mut self, p: Point) {
        self.0 = Some(match self.0 {
            None => (p, p),
            Some((lo, hi)) => (
                Point::new(lo.x.min(p.x), lo.y.min(p.y)),
                Point::new(hi.x.max(p.x), hi.y.max(p.y)),
            ),
        });
    }
    fn rect(self) -> Option<Rect> {
        self.0
    }
}

/// The pruning of [`prune`] and the re-pruning of [`repair`]: the local rule at a cell, then
/// depth-first over the neighbours of every cell it prunes.
struct Settle<'m, 's> {
    moves: &'m Moves<'m>,
    offsets: &'m [isize; 8],
    si: usize,
    gi: usize,
    stack: &'s mut [u32],
    /// The stack was too short for some neighbours.
    full: bool,
    /// The bounds of the cells pruned ([`repair`]'s; `None`: not kept).
    touched: Option<&'s mut Bounds>,
    /// Cells tried so far by the settling of pruned cells' neighbours (the callers count the
    /// cells they try: the budget of [`resume`]).
    tried: u32,
}

impl Settle<'_, '_> {
    fn at(&mut self, dead: &mut [u32], ci: usize) {
        let (m, o, si, gi) = (self.moves, self.offsets, self.si, self.gi);
        let Some(live) = try_prune(m, o, si, gi, dead, ci) else {
            return;
        };
        self.mark(ci);
        let mut top = 0usize;
        self.full |= push_neighbours(o, ci, live, self.stack, &mut top);
        while top > 0 {
            top = top.wrapping_sub(1);
            let Some(&u) = self.stack.get(top) else { break };
            let u = u as usize;
            self.tried = self.tried.wrapping_add(1);
            if let Some(live) = try_prune(m, o, si, gi, dead, u) {
                self.mark(u);
                self.full |= push_neighbours(o, u, live, self.stack, &mut top);
            }
        }
    }

    /// Cell `ci` was pruned now: grow the bounds of what moved, if they are kept.
    #[inline]
    fn mark(&mut self, ci: usize) {
        if let Some(t) = self.touched.as_deref_mut() {
            t.add(self.moves.grid().point(ci));
        }
    }
}

/// Prune cell `ci` if it is prunable: `Some(its live neighbours)` (a direction mask: the
/// neighbours one allowed move away that are not pruned, whose neighbourhoods shrink now) if it
/// was pruned now, `None` if not.
///
/// Inlined into the settling's loop, with one border test: a cell off the border reads its
/// allowed moves ([`crate::map::grid::Grid::interior_mask`]) and its pruned neighbours ([`bitmap::around_top`])
/// from the same 3 x 3 corner, where [`Moves::at`] and [`bitmap::around`] each tested the
/// border and worked the corner out again (a try is most of the pruning's cost: 14,800 of them
/// on Boston_0_256, `docs/bench/boston-issue36.md`).
#[inline(always)]
fn try_prune(
    moves: &Moves<'_>,
    offsets: &[isize; 8],
    si: usize,
    gi: usize,
    dead: &mut [u32],
    ci: usize,
) -> Option<u8> {
    if ci == si || ci == gi || bitmap::get(dead, ci) {
        return None;
    }
    let grid = moves.grid();
    let w = usize::from(grid.width());
    // `w > 0` (a grid's sides are): the checked forms never fail.
    let (x, y) = (
        ci.checked_rem(w).unwrap_or(0),
        ci.checked_div(w).unwrap_or(0),
    );
    let interior =
        x > 0 && y > 0 && x.wrapping_add(1) < w && y.wrapping_add(1) < usize::from(grid.height());
    let (all, live) = if interior {
        // Off the border: `ci - w - 1` does not wrap.
        let top = ci.wrapping_sub(w).wrapping_sub(1);
        let all = match moves.table_at(ci) {
            Some(m) => m,
            None => grid.interior_mask(top),
        };
        if all == 0 {
            return None; // blocked (or isolated: nothing to gain)
        }
        (all, all & !bitmap::around_top(dead, top, w))
    } else {
        let all = moves.at(ci, grid.point(ci));
        if all == 0 {
            return None;
        }
        let mut live = all;
        let mut m = all;
        while m != 0 {
            let d = m.trailing_zeros() as usize & 7;
            m &= m.wrapping_sub(1);
            let ni = ci.wrapping_add_signed(offsets.get(d).copied().unwrap_or(0));
            if bitmap::get(dead, ni) {
                live &= !(1 << d);
            }
        }
        (all, live)
    };
    let ok = match CLIQUE.get(usize::from(live)).copied().unwrap_or(0) {
        0 => false,
        1 => true,
        t => (all >> (t.wrapping_sub(2) & 7)) & 1 == 1,
    };
    if !ok {
        return None;
    }
    bitmap::set(dead, ci);
    Some(live)
}

/// Push the neighbours of `ci` in `live` (the pruned neighbours' neighbourhoods do not change,
/// and a neighbour one allowed move away is one the other way too); true if the stack was full
/// for some.
fn push_neighbours(
    offsets: &[isize; 8],
    ci: usize,
    live: u8,
    stack: &mut [u32],
    top: &mut usize,
) -> bool {
    let mut m = live;
    let mut full = false;
    while m != 0 {
        let d = m.trailing_zeros() as usize & 7;
        m &= m.wrapping_sub(1);
        let ni = ci.wrapping_add_signed(offsets.get(d).copied().unwrap_or(0));
        match stack.get_mut(*top) {
            Some(s) => {
                *s = ni as u32; // a cell index: < 2^32
                *top = top.wrapping_add(1);
            }
            None => full = true,
        }
    }
    full
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::grid::Grid;

    fn grid_from(rows: &[&str]) -> (Vec<u8>, u16, u16) {
        crate::testutil::bits(rows)
    }

    fn pruned(rows: &[&str], s: Point, g: Point, stack: usize) -> Vec<String> {
        let (b, w, h) = grid_from(rows);
        let grid = Grid::new(w, h, &b).unwrap();
        let moves = Moves::new(grid, &[]);
        let mut dead = vec![0u32; bitmap::words(grid.cells())];
        let mut st = vec![0u32; stack];
        prune(&moves, s, g, &mut dead, &mut st);
        (0..h)
            .map(|y| {
                (0..w)
                    .map(|x| {
                        let p = Point::new(x, y);
                        if !grid.is_free(p) {
                            '#'
                        } else if bitmap::get(&dead, grid.index(p)) {
                            'x'
                        } else {
                            '.'
                        }
                    })
                    .collect()
            })
            .collect()
    }

    #[test]
    fn a_perfect_maze_shrinks_to_its_path() {
        let rows = [
            "...#...", //
            ".#.#.#.", //
            ".#...#.", //
            ".######", //
            ".......", //
        ];
        // From (2,0) to (6,0) the way is (2,0) (2,1) (2,2) (3,2) (4,2) (4,1) (4,0) (5,0) (6,0);
        // the left column with the bottom row, and the stub below the goal, are dead branches.
        let out = pruned(&rows, Point::new(2, 0), Point::new(6, 0), 64);
        assert_eq!(
            out,
            [
                "xx.#...", //
                "x#.#.#x", //
                "x#...#x", //
                "x######", //
                "xxxxxxx", //
            ]
        );
    }

    #[test]
    fn an_open_room_loses_only_what_no_shortest_path_needs() {
        let rows = ["....", "....", "...."];
        let out = pruned(&rows, Point::new(0, 1), Point::new(3, 1), 64);
        // The corners go; nothing else is prunable (every other cell has two neighbours that are
        // not one move apart).
        assert_eq!(out, ["x..x", "....", "x..x"]);
    }

    #[test]
    fn a_gap_between_walls_is_kept() {
        // The middle row is the only way past the two wall cells: its middle may not go.
        let rows = ["..#..", ".....", "..#.."];
        let out = pruned(&rows, Point::new(0, 0), Point::new(4, 0), 64);
        assert_eq!(&out[1][1..4], "...");
    }

    /// Exact 8-connected distance from `s` to `g` over the cells `ok` allows (Dijkstra, f64).
    fn distance(g: &Grid<'_>, s: Point, t: Point, ok: &dyn Fn(usize) -> bool) -> Option<f64> {
        let n = g.cells();
        let mut dist = vec![f64::INFINITY; n];
        let mut done = vec![false; n];
        dist[g.index(s)] = 0.0;
        loop {
            let mut best = None;
            for i in 0..n {
                if !done[i] && dist[i].is_finite() && best.is_none_or(|b: usize| dist[i] < dist[b])
                {
                    best = Some(i);
                }
            }
            let i = best?;
            if i == g.index(t) {
                return Some(dist[i]);
            }
            done[i] = true;
            let p = g.point(i);
            for d in 0..8u8 {
                if let Some(q) = g.step(p, d) {
                    let j = g.index(q);
                    let c = if d % 2 == 1 {
                        std::f64::consts::SQRT_2
                    } else {
                        1.0
                    };
                    if ok(j) && dist[i] + c < dist[j] {
                        dist[j] = dist[i] + c;
                    }
                }
            }
        }
    }

    #[test]
    fn pruning_keeps_the_shortest_distance_on_random_maps() {
        let mut x = 0x2545_f491u32;
        let mut rnd = move || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x
        };
        let mut pruned_any = 0;
        for round in 0..300 {
            let (w, h) = (4 + rnd() % 12, 3 + rnd() % 10);
            let cells = (w * h) as usize;
            let density = [8u32, 16, 28, 40][round % 4];
            let mut b = vec![0u8; cells.div_ceil(8)];
            for i in 0..cells {
                if rnd() % 100 < density {
                    b[i / 8] |= 1 << (i % 8);
                }
            }
            let g = Grid::new(w as u16, h as u16, &b).unwrap();
            let free: Vec<usize> = (0..cells).filter(|&i| g.is_free(g.point(i))).collect();
            if free.len() < 2 {
                continue;
            }
            let s = g.point(free[rnd() as usize % free.len()]);
            let t = g.point(free[rnd() as usize % free.len()]);
            let moves = Moves::new(g, &[]);
            let mut dead = vec![0u32; bitmap::words(cells)];
            let mut st = vec![0u32; 4];
            pruned_any += prune(&moves, s, t, &mut dead, &mut st);
            let before = distance(&g, s, t, &|_| true);
            let after = distance(&g, s, t, &|j| !bitmap::get(&dead, j));
            match (before, after) {
                (None, None) => {}
                (Some(a), Some(b)) => {
                    assert!((a - b).abs() < 1e-9, "{a} vs {b} on\n{:?}", (w, h, &b))
                }
                other => panic!("connectivity changed: {other:?}"),
            }
            assert!(!bitmap::get(&dead, g.index(s)) && !bitmap::get(&dead, g.index(t)));
        }
        assert!(pruned_any > 100);
    }

    #[test]
    fn the_stack_size_does_not_change_the_result() {
        let rows = [
            "..........#.........",
            ".######.#.#.######..",
            ".#......#.#......#..",
            ".#.######.######.#.#",
            ".#..............#...",
            ".################.#.",
            "..................#.",
        ];
        let a = pruned(&rows, Point::new(0, 0), Point::new(19, 6), 1000);
        for s in [0, 1, 3, 8] {
            assert_eq!(
                pruned(&rows, Point::new(0, 0), Point::new(19, 6), s),
                a,
                "stack {s}"
            );
        }
    }

    #[test]
    fn the_first_pass_skips_no_prunable_cell_on_random_maps() {
        // With a stack too short for anything, every pruning overflows and full passes over
        // every free cell follow until nothing changes: the fixed point without the first pass's
        // filter. A long stack never overflows, so only the filtered first pass and the
        // propagation run. Both must mark the same cells (random maps of many widths, rows not
        // a multiple of 32 or 8 cells, sparse and dense obstacles).
        let mut rng = crate::rng::Xoshiro128pp::from_u64(3);
        let mut marked = 0;
        for &(w, h) in &[
            (7u16, 5u16),
            (31, 9),
            (33, 20),
            (64, 64),
            (95, 41),
            (130, 17),
        ] {
            for density in [2u32, 4, 6] {
                for _ in 0..4 {
                    let cells = usize::from(w) * usize::from(h);
                    let (b, st, go) = corner_to_corner(&mut rng, w, h, density);
                    let grid = Grid::new(w, h, &b).unwrap();
                    let moves = Moves::new(grid, &[]);
                    let words = bitmap::words(cells);
                    let (mut long, mut none) = (vec![0u32; words], vec![0u32; words]);
                    let a = prune(&moves, st, go, &mut long, &mut vec![0u32; 4 * cells]);
                    let z = prune(&moves, st, go, &mut none, &mut []);
                    assert_eq!((a, &long), (z, &none), "{w} x {h}, density {density}");
                    marked += a;
                }
            }
        }
        assert!(marked > 1000, "the maps had little to prune: {marked}");
    }

    /// The module's rule read literally, to a fixed point: a free cell (not `s` or `t`, with
    /// some allowed move) goes when every two of its remaining neighbours are one allowed move
    /// apart ([`Grid::move_mask`] and [`Grid::step`] only: no table, no 3 x 3 reads).
    fn by_the_rule(g: &Grid<'_>, s: Point, t: Point) -> Vec<bool> {
        let n = g.cells();
        let mut dead = vec![false; n];
        let apart = |a: Point, b: Point| (0..8u8).any(|d| g.step(a, d) == Some(b));
        loop {
            let mut changed = false;
            for i in 0..n {
                let p = g.point(i);
                if dead[i] || p == s || p == t || !g.is_free(p) || g.move_mask(p) == 0 {
                    continue;
                }
                let live: Vec<Point> = (0..8u8)
                    .filter_map(|d| g.step(p, d))
                    .filter(|&q| !dead[g.index(q)])
                    .collect();
                let clique = live
                    .iter()
                    .enumerate()
                    .all(|(k, &a)| live[k + 1..].iter().all(|&b| apart(a, b)));
                if clique {
                    dead[i] = true;
                    changed = true;
                }
            }
            if !changed {
                return dead;
            }
        }
    }

    #[test]
    fn pruning_marks_the_rules_fixed_point_on_random_maps() {
        // The settling's try (one 3 x 3 read of the map and one of the marks off the border,
        // the neighbours pushed only when live) against the rule applied literally until
        // nothing changes, with a move table and without, on maps of many widths and
        // densities (breaking the try's reads or its pushes fails it).
        let mut rng = crate::rng::Xoshiro128pp::from_u64(36);
        let mut marked = 0;
        for &(w, h) in &[(3u16, 3u16), (9, 4), (33, 12), (40, 37), (70, 9)] {
            for density in [2u32, 4, 6, 8] {
                for _ in 0..3 {
                    let cells = usize::from(w) * usize::from(h);
                    let (b, st, go) = corner_to_corner(&mut rng, w, h, density);
                    let grid = Grid::new(w, h, &b).unwrap();
                    let want = by_the_rule(&grid, st, go);
                    let mut table = vec![0u8; cells];
                    assert!(Moves::fill(&grid, &mut table));
                    for moves in [Moves::new(grid, &[]), Moves::new(grid, &table)] {
                        let mut dead = vec![0u32; bitmap::words(cells)];
                        marked += prune(&moves, st, go, &mut dead, &mut vec![0u32; 64]);
                        let got: Vec<bool> = (0..cells).map(|i| bitmap::get(&dead, i)).collect();
                        assert_eq!(got, want, "{w} x {h}, density {density}");
                    }
                }
            }
        }
        assert!(marked > 1000, "the maps had little to prune: {marked}");
    }

    /// A random `w` x `h` map, a cell blocked with probability `density / 16`, and its corner
    /// pair (0, 0) -> (w - 1, h - 1), both free.
    fn corner_to_corner(
        rng: &mut crate::rng::Xoshiro128pp,
        w: u16,
        h: u16,
        density: u32,
    ) -> (Vec<u8>, Point, Point) {
        let cells = usize::from(w) * usize::from(h);
        let mut b = vec![0u8; cells.div_ceil(8)];
        for i in 0..cells {
            if rng.next_word() % 16 < density {
                b[i / 8] |= 1 << (i % 8);
            }
        }
        let (st, go) = (Point::new(0, 0), Point::new(w - 1, h - 1));
        for p in [st, go] {
            let i = usize::from(p.y) * usize::from(w) + usize::from(p.x);
            b[i / 8] &= !(1 << (i % 8));
        }
        (b, st, go)
    }

    #[test]
    fn pruning_in_pieces_marks_what_one_piece_marks() {
        // `resume` with budgets of 1 to 50 tries (a pause after nearly every window and cell,
        // in the first pass and in the full passes a short stack needs) marks what `prune`
        // marks in one call, and pauses at least once a budget on maps with anything to try.
        let mut rng = crate::rng::Xoshiro128pp::from_u64(5);
        let mut paused = 0u32;
        for &(w, h) in &[(7u16, 5u16), (33, 20), (64, 64), (95, 41)] {
            for density in [2u32, 5] {
                let cells = usize::from(w) * usize::from(h);
                let (b, st, go) = corner_to_corner(&mut rng, w, h, density);
                let grid = Grid::new(w, h, &b).unwrap();
                let moves = Moves::new(grid, &[]);
                let words = bitmap::words(cells);
                for stack in [0usize, 3, 4 * cells] {
                    let mut whole = vec![0u32; words];
                    let n = prune(&moves, st, go, &mut whole, &mut vec![0u32; stack]);
                    for budget in [1u32, 2, 7, 50] {
                        let mut dead = vec![!0u32; words];
                        let mut scratch = vec![0u32; stack];
                        let mut at = begin(&moves, &mut dead);
                        let m = loop {
                            match resume(&moves, st, go, &mut dead, &mut scratch, &mut at, budget) {
                                Some(m) => break m,
                                None => paused += 1,
                            }
                        };
                        assert_eq!(
                            (m, &dead),
                            (n, &whole),
                            "{w} x {h} {density} {stack} {budget}"
                        );
                    }
                }
            }
        }
        assert!(paused > 1000, "the pruning hardly paused: {paused}");
    }

    /// Marks of `rows` pruned from scratch for `s`, `g`, as rows of `x` / `.` / `#`.
    fn show(g: &Grid<'_>, dead: &[u32]) -> Vec<String> {
        (0..g.height())
            .map(|y| {
                (0..g.width())
                    .map(|x| {
                        let p = Point::new(x, y);
                        if !g.is_free(p) {
                            '#'
                        } else if bitmap::get(dead, g.index(p)) {
                            'x'
                        } else {
                            '.'
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// Prune `before` for `(s0, goal)`, then repair for `after` (the same size) and `s1`, with
    /// the changed cells' rectangle `changed`; returns the repaired marks, the from-scratch marks
    /// on `after` and what `repair` said.
    fn repaired(
        before: &[&str],
        after: &[&str],
        (s0, s1, goal): (Point, Point, Point),
        changed: Option<Rect>,
        stack: usize,
    ) -> (Vec<String>, Vec<String>, Repaired) {
        let (b0, w, h) = grid_from(before);
        let (b1, _, _) = grid_from(after);
        let g0 = Grid::new(w, h, &b0).unwrap();
        let g1 = Grid::new(w, h, &b1).unwrap();
        let mut dead = vec![0u32; bitmap::words(g0.cells())];
        let mut st = vec![0u32; stack];
        prune(&Moves::new(g0, &[]), s0, goal, &mut dead, &mut st);
        let r = repair(
            &Moves::new(g1, &[]),
            (s0, s1, goal),
            changed,
            &mut dead,
            &mut st,
        );
        let mut fresh = vec![0u32; bitmap::words(g1.cells())];
        let n = prune(&Moves::new(g1, &[]), s1, goal, &mut fresh, &mut st);
        assert_eq!(r.pruned, n);
        (show(&g1, &dead), show(&g1, &fresh), r)
    }

    #[test]
    fn repair_revives_a_dead_end_that_a_change_opened() {
        // The corridor along the bottom is a dead end (pruned whole) until the wall at its right
        // end opens: then it is a way to the goal, and every one of its cells must come back,
        // also the ones far from the change (the un-pruning follows the connected marks).
        let before = [
            "......#", //
            ".####.#", //
            ".#....#", //
            ".######", //
            "......#", //
        ];
        let after = [
            "......#", //
            ".####.#", //
            ".#....#", //
            ".######", //
            ".......", //
        ];
        let (s, g) = (Point::new(0, 0), Point::new(6, 4));
        let changed = Some((Point::new(6, 4), Point::new(6, 4)));
        let (got, want, r) = repaired(&before, &after, (s, s, g), changed, 64);
        assert_eq!(got, want);
        assert_eq!(&got[4][..6], "......", "{got:?}");
        assert!(!r.rebuilt);
    }

    #[test]
    fn repair_prunes_the_branch_the_old_start_kept() {
        // The start at the end of a dead-end branch keeps the branch; once the robot has left
        // it, the whole branch is prunable, starting from the old start (no longer exempt).
        let rows = [
            "#########", //
            "........#", //
            "#######.#", //
            "........#", //
        ];
        let (s0, s1, g) = (Point::new(0, 1), Point::new(7, 2), Point::new(0, 3));
        let (got, want, r) = repaired(&rows, &rows, (s0, s1, g), None, 64);
        assert_eq!(got, want);
        assert_eq!(&got[1][..7], "xxxxxxx", "{got:?}");
        assert!(!r.rebuilt);
        let (lo, hi) = r.touched.unwrap();
        assert!(
            lo.x == 0 && hi.x >= 6 && lo.y <= 1 && hi.y >= 1,
            "{:?}",
            r.touched
        );
    }

    #[test]
    fn repair_revives_the_branch_of_the_new_start() {
        // The reverse: the robot is put down inside a branch that was pruned; the new start is
        // exempt, and the cells between it and the rest of the map come back with it.
        let rows = [
            "#########", //
            "........#", //
            "#######.#", //
            "........#", //
        ];
        let (s0, s1, g) = (Point::new(7, 2), Point::new(1, 1), Point::new(0, 3));
        let (got, want, r) = repaired(&rows, &rows, (s0, s1, g), None, 64);
        assert_eq!(got, want);
        assert_eq!(&got[1][1..7], "......", "{got:?}");
        assert!(!r.rebuilt);
    }

    #[test]
    fn repair_with_a_short_stack_prunes_again() {
        // The revived corridor of the first test is 6 cells: a list of 2 cannot hold them.
        let before = ["......#", ".####.#", ".#....#", ".######", "......#"];
        let after = ["......#", ".####.#", ".#....#", ".######", "......."];
        let (s, g) = (Point::new(0, 0), Point::new(6, 4));
        let changed = Some((Point::new(6, 4), Point::new(6, 4)));
        let (got, want, r) = repaired(&before, &after, (s, s, g), changed, 2);
        assert_eq!(got, want);
        assert!(r.rebuilt);
    }

    #[test]
    fn repair_equals_pruning_from_scratch_on_random_maps_with_random_changes() {
        let mut x = 0x9e37_79b9u32;
        let mut rnd = move || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x
        };
        let (mut local, mut unpruned) = (0, 0);
        for round in 0..3000 {
            let (w, h) = (3 + rnd() % 14, 3 + rnd() % 12);
            let cells = (w * h) as usize;
            let density = [8u32, 16, 28, 40][round % 4];
            let mut b = vec![0u8; cells.div_ceil(8)];
            for i in 0..cells {
                if rnd() % 100 < density {
                    b[i / 8] |= 1 << (i % 8);
                }
            }
            let free = |b: &[u8]| -> Vec<usize> {
                (0..cells)
                    .filter(|&i| b[i / 8] >> (i % 8) & 1 == 0)
                    .collect()
            };
            let f0 = free(&b);
            if f0.len() < 3 {
                continue;
            }
            let pt = |i: usize| Point::new((i % w as usize) as u16, (i / w as usize) as u16);
            let (s0, goal) = (
                pt(f0[rnd() as usize % f0.len()]),
                pt(f0[rnd() as usize % f0.len()]),
            );
            let g0 = Grid::new(w as u16, h as u16, &b).unwrap();
            let mut dead = vec![0u32; bitmap::words(cells)];
            let mut st = vec![0u32; [2usize, 9, 40, 400][round % 4]];
            prune(&Moves::new(g0, &[]), s0, goal, &mut dead, &mut st);
            let before = dead.clone();
            // Change a random rectangle (some rounds none): block or clear each of its cells at
            // random, never the goal.
            let mut after = b.clone();
            let changed = (round % 5 != 0).then(|| {
                let (cw, ch) = (1 + rnd() % 3, 1 + rnd() % 3);
                let (x0, y0) = (rnd() % w, rnd() % h);
                let (x1, y1) = ((x0 + cw - 1).min(w - 1), (y0 + ch - 1).min(h - 1));
                for y in y0..=y1 {
                    for x in x0..=x1 {
                        let i = (y * w + x) as usize;
                        if Point::new(x as u16, y as u16) != goal {
                            if rnd() % 2 == 0 {
                                after[i / 8] |= 1 << (i % 8);
                            } else {
                                after[i / 8] &= !(1 << (i % 8));
                            }
                        }
                    }
                }
                (
                    Point::new(x0 as u16, y0 as u16),
                    Point::new(x1 as u16, y1 as u16),
                )
            });
            // The robot moved somewhere free (often near where it was).
            let f1 = free(&after);
            let s1 = if round % 3 == 0 {
                s0
            } else {
                pt(f1[rnd() as usize % f1.len()])
            };
            if !f1.contains(&((s1.y as usize) * w as usize + s1.x as usize)) {
                continue;
            }
            let g1 = Grid::new(w as u16, h as u16, &after).unwrap();
            let r = repair(
                &Moves::new(g1, &[]),
                (s0, s1, goal),
                changed,
                &mut dead,
                &mut st,
            );
            let mut fresh = vec![0u32; bitmap::words(cells)];
            let n = prune(&Moves::new(g1, &[]), s1, goal, &mut fresh, &mut st);
            assert_eq!(
                show(&g1, &dead),
                show(&g1, &fresh),
                "round {round}: {s0:?} -> {s1:?}, goal {goal:?}, changed {changed:?}\nbefore\n{:#?}",
                show(&g0, &before)
            );
            assert_eq!(r.pruned, n, "round {round}");
            // Every mark that moved lies in `touched`.
            for i in 0..cells {
                if bitmap::get(&before, i) != bitmap::get(&fresh, i) {
                    let (lo, hi) = r.touched.expect("a mark moved");
                    let p = pt(i);
                    assert!(
                        (lo.x..=hi.x).contains(&p.x) && (lo.y..=hi.y).contains(&p.y),
                        "round {round}: {p:?} outside {:?}",
                        r.touched
                    );
                }
            }
            if !r.rebuilt {
                local += 1;
                unpruned += usize::from(r.touched.is_some());
            }
        }
        assert!(local > 1000 && unpruned > 500, "{local} {unpruned}");
    }

    #[test]
    fn clique_table() {
        assert_eq!(CLIQUE[0], 1);
        assert_eq!(CLIQUE[0b1], 1);
        assert_eq!(CLIQUE[0b11], 1); // E, SE
        assert_eq!(CLIQUE[0b101], 3); // E, S: iff SE free
        assert_eq!(CLIQUE[0b111], 3); // E, SE, S: iff SE free (it is, being a neighbour)
        assert_eq!(CLIQUE[0b1010], 0); // SE, SW: two apart
        assert_eq!(CLIQUE[0b1000_0001], 1); // E, NE
        assert_eq!(CLIQUE[0b0100_0001], 9); // E, N: iff NE (7) free
    }
}
