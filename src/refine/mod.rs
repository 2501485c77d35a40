//! Local search on a raw 8-connected path: the shortest path inside a sliding window around it
//! (the local search ACO is usually paired with).
//!
//! **What it guarantees.** Given a valid raw path (8-connected, free cells, no corner cutting, as
//! the colony produces), [`refine`] writes a path that
//!
//! - runs from the same start to the same goal and is valid by the same rule;
//! - is never longer (a piece is replaced only by a strictly shorter one);
//! - is the exact 8-connected optimum when the whole map fits one window (both sides `<=` the
//!   window side [`Scratch::side`]): the first window then spans the whole path and the whole map;
//! - is the same on every platform, bit for bit: costs are integers and every tie is broken by a
//!   fixed rule (no floating point at all).
//!
//! Loops are not removed explicitly; a loop that fits one window disappears with it.
//!
//! **Method.** A pass slides along the path. Each window takes the piece `P[s..=t]` that starts a
//! quarter side behind the last committed cell and extends forward as long as its bounding box,
//! grown by a margin of an eighth of a side on each side and to at least half a side (both
//! clipped to the map), keeps within the scratch's `side * side` cells (and [`MAX_SIDE`] a side).
//! So a piece running along an axis, as in city streets, gets a long flat box of the same area as
//! the square: this halves the excess left on the city maps against square boxes. The box grows
//! into the spare area, is centred on the piece and clipped to the map, and an exact A* (octile
//! heuristic, 8 moves, no corner cutting through [`Grid::move_mask`]) runs from `P[s]` to `P[t]`
//! inside it. A strictly shorter result replaces the piece. Either way the path is committed up
//! to the middle of the piece (the rest stays pending), so consecutive windows overlap by half.
//! Passes repeat until one changes nothing or `max_passes` ran. Pieces whose length already
//! equals the obstacle-free octile distance are skipped without a search.
//!
//! **What it cannot do.** A window only sees its piece: a detour around the wrong side of a block
//! larger than the window stays (the colony's choice of corridor), and so does a path that runs
//! one row off the optimum for longer than a window (the two diagonals that would fix it are too
//! far apart). Both are rare on the Moving AI maps; `docs/ALGORITHM.md` has the figures of the
//! `refine_large` example.
//!
//! **Exact integer costs.** A straight step costs [`STRAIGHT`] = 13860 and a diagonal
//! [`DIAGONAL`] = 19601 (a convergent of `sqrt 2`: `19601 / 13860 = 1.41421356`, off by
//! `1.8e-9`). Two step mixes `(a, b)` (straight, diagonal) of different true length
//! `a + b sqrt 2` compare the same way in these units as long as the diagonal counts differ by
//! less than about 9800, far beyond any window; equal integer cost means equal step mix. So the
//! search is exact, not just close. The heap orders by `f = g + h`, then larger `g`, then the
//! lower box index.
//!
//! **Cost.** Linear in the path length for a fixed window: about one window per half piece of
//! path per pass, each expanding at most `side * side` cells (A* expands far fewer on open
//! ground) after clearing `side * side` bytes. [`Budget`] counts the cells expanded and stops a
//! run between windows once its limit is reached (overshooting by at most one window); a stopped
//! [`Refiner`] resumes where it stopped, so a firmware can yield between calls. Scratch is
//! [`Scratch::BYTES_PER_CELL`] = 13 bytes per window cell (`side = 64`: 52 KiB; `48`: 29 KiB;
//! `128`: 208 KiB), lent for each call and free in between.
//!
//! **Buffers.** The path is rewritten inside `out`, streaming: the pending input sits at the end
//! of `out` and the output grows from its front, so `out` needs `path.len()` cells. A replacement
//! with more cells than the piece it replaces (shorter paths can have more steps) needs room: it
//! is skipped when the output would overrun the pending input. A few spare cells
//! (`path.len() + side`) make that practically never happen.

use crate::error::Error;
use crate::grid::{Grid, Point, DX, DY};

/// Cost of a straight step in search units.
pub const STRAIGHT: u32 = 13860;
/// Cost of a diagonal step in search units (`STRAIGHT * sqrt 2`, rounded, see the module docs).
pub const DIAGONAL: u32 = 19601;
/// The largest window side (box indices are `u16`).
pub const MAX_SIDE: usize = 256;
/// The smallest window side worth searching; with less scratch the path is returned unchanged.
pub const MIN_SIDE: usize = 8;
/// Default pass limit of [`refine`].
pub const DEFAULT_PASSES: u8 = 4;

/// `link` bits: the direction (0..8) the cell was reached by, and two flags.
const DIR_MASK: u8 = 0x07;
const REACHED: u8 = 0x08;
const CLOSED: u8 = 0x10;

/// Search scratch for one window, lent for each call. The window side is the largest `side` with
/// `side * side` no more than the shortest of the five slices (and at most [`MAX_SIDE`]).
#[derive(Debug)]
pub struct Scratch<'a> {
    /// Cost from the window's start, per box cell.
    pub g: &'a mut [u32],
    /// `g` plus the octile heuristic, per box cell.
    pub f: &'a mut [u32],
    /// Direction reached by and search flags, per box cell.
    pub link: &'a mut [u8],
    /// The open list: a binary heap of box cell indices.
    pub heap: &'a mut [u16],
    /// Position of each box cell in `heap`.
    pub pos: &'a mut [u16],
}

impl Scratch<'_> {
    /// Bytes of scratch per window cell.
    pub const BYTES_PER_CELL: usize = 13;

    /// Box cells this scratch can hold.
    pub fn cells(&self) -> usize {
        self.g
            .len()
            .min(self.f.len())
            .min(self.link.len())
            .min(self.heap.len())
            .min(self.pos.len())
    }

    /// The window side: the largest `s <= MAX_SIDE` with `s * s <= self.cells()`.
    pub fn side(&self) -> usize {
        let cells = self.cells();
        let mut s = 0usize;
        // s <= MAX_SIDE = 256: no overflow.
        while s < MAX_SIDE && s.wrapping_add(1).wrapping_mul(s.wrapping_add(1)) <= cells {
            s = s.wrapping_add(1);
        }
        s
    }
}

/// Statically sized scratch for a `CELLS`-cell window (a firmware puts this in a `static`).
#[derive(Debug)]
pub struct RefineStorage<const CELLS: usize> {
    g: [u32; CELLS],
    f: [u32; CELLS],
    link: [u8; CELLS],
    heap: [u16; CELLS],
    pos: [u16; CELLS],
}

impl<const CELLS: usize> Default for RefineStorage<CELLS> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const CELLS: usize> RefineStorage<CELLS> {
    /// Zeroed storage.
    pub const fn new() -> Self {
        RefineStorage {
            g: [0; CELLS],
            f: [0; CELLS],
            link: [0; CELLS],
            heap: [0; CELLS],
            pos: [0; CELLS],
        }
    }

    /// Lend it as scratch.
    pub fn scratch(&mut self) -> Scratch<'_> {
        Scratch {
            g: &mut self.g,
            f: &mut self.f,
            link: &mut self.link,
            heap: &mut self.heap,
            pos: &mut self.pos,
        }
    }
}

/// Work counter and limit. The limit is checked before each window, so a run stops at most one
/// window (`side * side` expansions) past it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Budget {
    /// Stop once `expanded` reaches this.
    pub limit: u64,
    /// Cells expanded (closed) by the searches so far.
    pub expanded: u64,
    /// Windows searched.
    pub windows: u32,
    /// Windows whose piece was replaced by a shorter one.
    pub improved: u32,
}

impl Budget {
    /// A budget of `limit` expansions.
    pub const fn new(limit: u64) -> Self {
        Budget {
            limit,
            expanded: 0,
            windows: 0,
            improved: 0,
        }
    }

    /// No limit.
    pub const fn unlimited() -> Self {
        Self::new(u64::MAX)
    }

    /// True once the limit is reached.
    pub fn exhausted(&self) -> bool {
        self.expanded >= self.limit
    }
}

/// Refine `path` into `out` with at most [`DEFAULT_PASSES`] passes; returns the new path's cell
/// count (`out[..k]`). If the budget runs out, the path refined so far is returned (valid, never
/// longer); use [`Refiner`] to resume instead. With scratch for a side below [`MIN_SIDE`] the path
/// comes back unchanged.
///
/// Errors: [`Error::NoPath`] if `path` is empty or not a valid 8-connected path on `grid`;
/// [`Error::MapTooLarge`] (with `cells` = the path's and `capacity` = `out`'s length) if `out` is
/// shorter than `path`.
pub fn refine(
    grid: &Grid<'_>,
    path: &[Point],
    out: &mut [Point],
    mut scratch: Scratch<'_>,
    budget: &mut Budget,
) -> Result<usize, Error> {
    let mut r = Refiner::new(grid, path, out, DEFAULT_PASSES)?;
    r.resume(grid, out, &mut scratch, budget);
    Ok(r.finish(out))
}

/// Cost of one step between 8-neighbours.
fn step_cost(a: Point, b: Point) -> u32 {
    if a.x != b.x && a.y != b.y {
        DIAGONAL
    } else {
        STRAIGHT
    }
}

/// The obstacle-free cost between two cells.
fn octile(a: Point, b: Point) -> u32 {
    let dx = u32::from(a.x.abs_diff(b.x));
    let dy = u32::from(a.y.abs_diff(b.y));
    let (hi, lo) = (dx.max(dy), dx.min(dy));
    // Both below 2^16, costs below 2^15: the result is below 2^32.
    hi.wrapping_sub(lo)
        .wrapping_mul(STRAIGHT)
        .wrapping_add(lo.wrapping_mul(DIAGONAL))
}

/// The direction of a step between 8-neighbours, if they are neighbours.
fn dir_between(a: Point, b: Point) -> Option<u8> {
    let dx = i32::from(b.x).wrapping_sub(i32::from(a.x));
    let dy = i32::from(b.y).wrapping_sub(i32::from(a.y));
    (0..8u8).find(|&d| DX.get(usize::from(d)) == Some(&dx) && DY.get(usize::from(d)) == Some(&dy))
}

/// A resumable refinement of one path, streaming inside `out` (see the module docs).
///
/// The current path is `out[..w]` (committed) followed by `out[r..e]` (pending); the caller
/// passes the same `grid` and `out` to every call (another buffer cannot make it panic, but the
/// result is then meaningless).
#[derive(Clone, Copy, Debug)]
pub struct Refiner {
    w: usize,
    r: usize,
    e: usize,
    passes: u8,
    max_passes: u8,
    improved: bool,
    done: bool,
}

impl Refiner {
    /// Check `path` and lay it out at the end of `out`. `max_passes` 0 means no refinement.
    /// Errors as for [`refine`].
    pub fn new(
        grid: &Grid<'_>,
        path: &[Point],
        out: &mut [Point],
        max_passes: u8,
    ) -> Result<Self, Error> {
        let n = path.len();
        let first = *path.first().ok_or(Error::NoPath)?;
        if !grid.is_free(first) {
            return Err(Error::NoPath);
        }
        for pair in path.windows(2) {
            let (Some(&a), Some(&b)) = (pair.first(), pair.get(1)) else {
                return Err(Error::NoPath);
            };
            let ok = dir_between(a, b).and_then(|d| grid.step(a, d)) == Some(b);
            if !ok {
                return Err(Error::NoPath);
            }
        }
        let cap = out.len();
        let too_small = Error::MapTooLarge {
            cells: u32::try_from(n).unwrap_or(u32::MAX),
            capacity: u32::try_from(cap).unwrap_or(u32::MAX),
        };
        let start = cap.checked_sub(n).ok_or(too_small)?;
        let tail = out.get_mut(start..).ok_or(too_small)?;
        tail.copy_from_slice(path);
        let mut me = Refiner {
            w: 0,
            r: start,
            e: cap,
            passes: 0,
            max_passes,
            improved: false,
            done: max_passes == 0,
        };
        me.commit_first(out);
        Ok(me)
    }

    /// True once refinement is over (no pass left or the last pass changed nothing).
    pub fn is_done(&self) -> bool {
        self.done
    }

    /// Passes started so far.
    pub fn passes(&self) -> u8 {
        self.passes
    }

    /// Run windows until done or the budget is exhausted; returns [`Refiner::is_done`]. With
    /// scratch for a side below [`MIN_SIDE`] it ends the refinement at once.
    pub fn resume(
        &mut self,
        grid: &Grid<'_>,
        out: &mut [Point],
        scratch: &mut Scratch<'_>,
        budget: &mut Budget,
    ) -> bool {
        let side = scratch.side();
        if side < MIN_SIDE {
            self.done = true;
        }
        while !self.done {
            if budget.exhausted() {
                return false;
            }
            if self.r >= self.e {
                self.end_pass(out);
                continue;
            }
            self.window(grid, out, scratch, side, budget);
        }
        true
    }

    /// Compact the current path to the front of `out`; returns its cell count.
    pub fn finish(self, out: &mut [Point]) -> usize {
        let mut w = self.w;
        for i in self.r..self.e {
            let Some(&p) = out.get(i) else { break };
            if let Some(slot) = out.get_mut(w) {
                *slot = p;
            }
            w = w.saturating_add(1);
        }
        w
    }

    /// Move the first pending cell to the committed part.
    fn commit_first(&mut self, out: &mut [Point]) {
        if self.w == 0 && self.r < self.e {
            if let Some(&p) = out.get(self.r) {
                if let Some(slot) = out.get_mut(0) {
                    *slot = p;
                }
            }
            self.w = 1;
            self.r = self.r.saturating_add(1);
        }
    }

    /// The pass is over: start another or stop.
    fn end_pass(&mut self, out: &mut [Point]) {
        self.passes = self.passes.saturating_add(1);
        if !self.improved || self.passes >= self.max_passes {
            self.done = true;
            return;
        }
        self.improved = false;
        // Move out[..w] to the end of out (back to front: the ranges may overlap upwards).
        let cap = out.len();
        let Some(start) = cap.checked_sub(self.w) else {
            self.done = true;
            return;
        };
        for i in (0..self.w).rev() {
            let Some(&p) = out.get(i) else { break };
            // i < w <= cap, so start + i < cap.
            if let Some(slot) = out.get_mut(start.wrapping_add(i)) {
                *slot = p;
            }
        }
        self.w = 0;
        self.r = start;
        self.e = cap;
        self.commit_first(out);
    }

    /// Cell `v` of the current path (committed, then pending).
    fn at(&self, out: &[Point], v: usize) -> Option<Point> {
        if v < self.w {
            out.get(v).copied()
        } else {
            out.get(self.r.checked_add(v.wrapping_sub(self.w))?)
                .copied()
        }
    }

    /// One window: pick the piece, search, replace or commit.
    fn window(
        &mut self,
        grid: &Grid<'_>,
        out: &mut [Point],
        scratch: &mut Scratch<'_>,
        side: usize,
        budget: &mut Budget,
    ) {
        // Virtual length; w >= 1 here (the first cell is always committed).
        let total = self.w.saturating_add(self.e.saturating_sub(self.r));
        let last_committed = self.w.saturating_sub(1);
        let back = side / 4;
        let shape = Shape {
            cells: scratch.cells(),
            margin: side / 8,
            min_side: side / 2,
            map_w: usize::from(grid.width()),
            map_h: usize::from(grid.height()),
        };
        // Grow the piece P[s..=t] forward while its bounding box fits.
        let mut s = last_committed.saturating_sub(back);
        let Some(ps) = self.at(out, s) else {
            self.done = true;
            return;
        };
        let (mut x0, mut x1, mut y0, mut y1) = (ps.x, ps.x, ps.y, ps.y);
        let mut t = s;
        let mut pt = ps;
        let mut old = 0u32;
        let mut v = s.saturating_add(1);
        while v < total {
            let Some(p) = self.at(out, v) else { break };
            let (nx0, nx1, ny0, ny1) = (x0.min(p.x), x1.max(p.x), y0.min(p.y), y1.max(p.y));
            let ex = usize::from(nx1.wrapping_sub(nx0)).saturating_add(1);
            let ey = usize::from(ny1.wrapping_sub(ny0)).saturating_add(1);
            if !shape.fits(ex, ey) {
                break;
            }
            (x0, x1, y0, y1) = (nx0, nx1, ny0, ny1);
            old = old.saturating_add(step_cost(pt, p));
            pt = p;
            t = v;
            v = v.saturating_add(1);
        }
        if t <= last_committed {
            // Cannot happen for side >= MIN_SIDE (one step past the committed end always fits);
            // fall back to the smallest piece so the pass still progresses.
            s = last_committed;
            let (Some(a), Some(b)) = (self.at(out, s), self.at(out, self.w)) else {
                self.done = true;
                return;
            };
            (x0, x1, y0, y1) = (a.x.min(b.x), a.x.max(b.x), a.y.min(b.y), a.y.max(b.y));
            old = step_cost(a, b);
            t = self.w;
            pt = b;
        }
        let Some(ps) = self.at(out, s) else {
            self.done = true;
            return;
        };
        // Search unless the piece is already as short as it can be.
        let mut replaced = false;
        if old > octile(ps, pt) {
            let ex = usize::from(x1.wrapping_sub(x0)).saturating_add(1);
            let ey = usize::from(y1.wrapping_sub(y0)).saturating_add(1);
            let (bw, bh) = shape.dims(ex, ey);
            let bbox = Box2 {
                x0: place(x0, ex, shape.map_w, bw),
                y0: place(y0, ey, shape.map_h, bh),
                w: bw,
                h: bh,
            };
            budget.windows = budget.windows.saturating_add(1);
            if let Some(cost) = search(grid, &bbox, ps, pt, scratch, budget) {
                if cost < old {
                    replaced = self.replace(out, scratch, &bbox, s, t, pt);
                }
            }
        }
        if replaced {
            budget.improved = budget.improved.saturating_add(1);
            self.improved = true;
            return;
        }
        // Commit up to the middle of the piece (at least one pending cell, everything at the end).
        let c = if t.saturating_add(1) >= total {
            t
        } else {
            s.saturating_add(t.wrapping_sub(s) / 2).max(self.w)
        };
        // Copy out[r..=r + (c - w)] to out[w..=c] (upwards-safe: w <= r).
        let count = c.saturating_add(1).saturating_sub(self.w);
        for k in 0..count {
            let from = self.r.saturating_add(k);
            let to = self.w.saturating_add(k);
            let Some(&p) = out.get(from) else { break };
            if let Some(slot) = out.get_mut(to) {
                *slot = p;
            }
        }
        self.w = self.w.saturating_add(count);
        self.r = self.r.saturating_add(count);
    }

    /// Write the searched path from `P[s]` to `P[t]` over the piece; false (nothing written) if
    /// it does not fit before the pending cells after `t`.
    fn replace(
        &mut self,
        out: &mut [Point],
        scratch: &Scratch<'_>,
        bbox: &Box2,
        s: usize,
        t: usize,
        target: Point,
    ) -> bool {
        let Some(ti) = bbox.local(target) else {
            return false;
        };
        // Count the steps back to the start (at most one per box cell).
        let Some(start) = self.at(out, s) else {
            return false;
        };
        let cells = bbox.cells();
        let mut steps = 0usize;
        let mut i = ti;
        let mut p = target;
        while p != start {
            let Some(&l) = scratch.link.get(i) else {
                return false;
            };
            if l & REACHED == 0 || steps >= cells {
                return false;
            }
            let Some(q) = back_step(p, l) else {
                return false;
            };
            let Some(qi) = bbox.local(q) else {
                return false;
            };
            p = q;
            i = qi;
            steps = steps.wrapping_add(1);
        }
        // out index of t (t >= w) is r + (t - w); the new cells go to out[s + 1..=s + steps].
        let Some(t_out) = self.r.checked_add(t.saturating_sub(self.w)) else {
            return false;
        };
        let Some(end) = s.checked_add(steps) else {
            return false;
        };
        if end > t_out || end >= out.len() {
            return false;
        }
        let mut k = end;
        let mut i = ti;
        let mut p = target;
        while k > s {
            if let Some(slot) = out.get_mut(k) {
                *slot = p;
            }
            let Some(&l) = scratch.link.get(i) else { break };
            let Some(q) = back_step(p, l) else { break };
            let Some(qi) = bbox.local(q) else { break };
            p = q;
            i = qi;
            k = k.wrapping_sub(1); // k > s >= 0
        }
        // Commit the new path up to its middle (but not less than was committed before) and hand
        // the rest back to the pending part, so the next window overlaps this one by half: move
        // out[mid + 1..=end] to just before the first pending cell (back to front: it moves up).
        let mid = s.saturating_add(steps / 2).max(self.w).min(end);
        let keep = end.wrapping_sub(mid); // mid <= end
        let r = t_out.saturating_add(1).saturating_sub(keep);
        for k in (0..keep).rev() {
            let from = mid.saturating_add(1).saturating_add(k);
            let Some(&p) = out.get(from) else { break };
            if let Some(slot) = out.get_mut(r.saturating_add(k)) {
                *slot = p;
            }
        }
        self.w = mid.saturating_add(1);
        self.r = r;
        true
    }
}

/// The cell a `link` entry came from.
fn back_step(p: Point, link: u8) -> Option<Point> {
    let d = usize::from(link & DIR_MASK);
    let x = i32::from(p.x).wrapping_sub(*DX.get(d)?);
    let y = i32::from(p.y).wrapping_sub(*DY.get(d)?);
    Some(Point::new(u16::try_from(x).ok()?, u16::try_from(y).ok()?))
}

/// Origin of a box side of `len` cells over a piece starting at `lo` with `extent` cells, centred
/// and clipped to a map side of `map` cells (`extent <= len <= map`).
fn place(lo: u16, extent: usize, map: usize, len: usize) -> u16 {
    let slack = len.saturating_sub(extent) / 2;
    let origin = usize::from(lo)
        .saturating_sub(slack)
        .min(map.saturating_sub(len));
    u16::try_from(origin).unwrap_or(0)
}

/// The box shapes a window may take: at most `cells` cells and [`MAX_SIDE`] a side, `margin`
/// cells around the piece's bounding box, no side below `min_side` (both clipped to the map).
/// A piece running along an axis thus gets a long flat box (same area as the square).
#[derive(Clone, Copy, Debug)]
struct Shape {
    cells: usize,
    margin: usize,
    min_side: usize,
    map_w: usize,
    map_h: usize,
}

impl Shape {
    /// Box side for a piece extent of `e` cells on a map side of `map` cells.
    fn side(&self, e: usize, map: usize) -> usize {
        e.saturating_add(self.margin.saturating_mul(2))
            .max(self.min_side)
            .min(map)
    }

    /// True if a piece with a bounding box of `ex x ey` cells gets a box.
    fn fits(&self, ex: usize, ey: usize) -> bool {
        let (w, h) = (self.side(ex, self.map_w), self.side(ey, self.map_h));
        w <= MAX_SIDE && h <= MAX_SIDE && w.saturating_mul(h) <= self.cells
    }

    /// The box for a piece that [`Shape::fits`]: the minimal box, its short side then its long
    /// side grown into the spare area.
    fn dims(&self, ex: usize, ey: usize) -> (usize, usize) {
        let (w, h) = (self.side(ex, self.map_w), self.side(ey, self.map_h));
        let grow = |other: usize, map: usize| {
            self.cells
                .checked_div(other)
                .unwrap_or(0)
                .min(map)
                .min(MAX_SIDE)
        };
        if w >= h {
            let h = grow(w, self.map_h).max(h);
            (grow(h, self.map_w).max(w), h)
        } else {
            let w = grow(h, self.map_w).max(w);
            (w, grow(w, self.map_h).max(h))
        }
    }
}

/// A search box: origin and size.
#[derive(Clone, Copy, Debug)]
struct Box2 {
    x0: u16,
    y0: u16,
    w: usize,
    h: usize,
}

impl Box2 {
    fn cells(&self) -> usize {
        // Both <= MAX_SIDE.
        self.w.saturating_mul(self.h)
    }

    fn local(&self, p: Point) -> Option<usize> {
        let lx = usize::from(p.x.checked_sub(self.x0)?);
        let ly = usize::from(p.y.checked_sub(self.y0)?);
        (lx < self.w && ly < self.h).then(|| ly.wrapping_mul(self.w).wrapping_add(lx))
    }

    fn point(&self, i: usize) -> Point {
        let (lx, ly) = (
            i.checked_rem(self.w).unwrap_or(0),
            i.checked_div(self.w).unwrap_or(0),
        );
        // lx < w, ly < h and the box lies inside the map: both fit u16.
        Point::new(
            self.x0.wrapping_add(lx as u16),
            self.y0.wrapping_add(ly as u16),
        )
    }
}

/// The open list: a binary heap of box indices ordered by `(f, larger g, index)`.
struct Heap<'s, 'a> {
    s: &'s mut Scratch<'a>,
    len: usize,
}

impl Heap<'_, '_> {
    fn key(&self, i: u16) -> (u32, u32, u16) {
        let k = usize::from(i);
        let f = self.s.f.get(k).copied().unwrap_or(u32::MAX);
        let g = self.s.g.get(k).copied().unwrap_or(0);
        (f, u32::MAX.wrapping_sub(g), i)
    }

    fn at(&self, slot: usize) -> u16 {
        self.s.heap.get(slot).copied().unwrap_or(0)
    }

    fn put(&mut self, slot: usize, i: u16) {
        if let Some(h) = self.s.heap.get_mut(slot) {
            *h = i;
        }
        if let Some(p) = self.s.pos.get_mut(usize::from(i)) {
            // slot < heap length <= 65536 cells.
            *p = slot as u16;
        }
    }

    fn push(&mut self, i: u16) {
        let slot = self.len;
        self.len = self.len.saturating_add(1);
        self.put(slot, i);
        self.up(slot);
    }

    fn decreased(&mut self, i: u16) {
        let slot = usize::from(self.s.pos.get(usize::from(i)).copied().unwrap_or(0));
        self.up(slot);
    }

    fn pop(&mut self) -> Option<u16> {
        if self.len == 0 {
            return None;
        }
        let top = self.at(0);
        self.len = self.len.wrapping_sub(1);
        if self.len > 0 {
            let last = self.at(self.len);
            self.put(0, last);
            self.down(0);
        }
        Some(top)
    }

    fn up(&mut self, mut slot: usize) {
        let i = self.at(slot);
        let key = self.key(i);
        while slot > 0 {
            let parent = slot.wrapping_sub(1) / 2;
            let pi = self.at(parent);
            if self.key(pi) <= key {
                break;
            }
            self.put(slot, pi);
            slot = parent;
        }
        self.put(slot, i);
    }

    fn down(&mut self, mut slot: usize) {
        let i = self.at(slot);
        let key = self.key(i);
        loop {
            // slot < len <= 65536: no overflow.
            let l = slot.wrapping_mul(2).wrapping_add(1);
            if l >= self.len {
                break;
            }
            let r = l.wrapping_add(1);
            let mut c = l;
            if r < self.len && self.key(self.at(r)) < self.key(self.at(l)) {
                c = r;
            }
            let ci = self.at(c);
            if key <= self.key(ci) {
                break;
            }
            self.put(slot, ci);
            slot = c;
        }
        self.put(slot, i);
    }
}

/// Exact A* from `from` to `to` inside `bbox`; returns the cost to `to` (links in `scratch`).
fn search(
    grid: &Grid<'_>,
    bbox: &Box2,
    from: Point,
    to: Point,
    scratch: &mut Scratch<'_>,
    budget: &mut Budget,
) -> Option<u32> {
    let cells = bbox.cells();
    if cells > scratch.cells() || cells > MAX_SIDE * MAX_SIDE {
        return None;
    }
    let si = bbox.local(from)?;
    let ti = bbox.local(to)?;
    scratch.link.get_mut(..cells)?.fill(0);
    *scratch.g.get_mut(si)? = 0;
    *scratch.f.get_mut(si)? = octile(from, to);
    *scratch.link.get_mut(si)? = REACHED;
    let mut heap = Heap { s: scratch, len: 0 };
    // si < cells <= 65536.
    heap.push(si as u16);
    while let Some(i) = heap.pop() {
        let iu = usize::from(i);
        let gi = heap.s.g.get(iu).copied()?;
        if let Some(l) = heap.s.link.get_mut(iu) {
            *l |= CLOSED;
        }
        budget.expanded = budget.expanded.saturating_add(1);
        if iu == ti {
            return Some(gi);
        }
        let p = bbox.point(iu);
        let mask = grid.move_mask(p);
        for d in 0..8u8 {
            if mask & (1 << d) == 0 {
                continue;
            }
            let du = usize::from(d);
            let nx = i32::from(p.x).wrapping_add(DX.get(du).copied().unwrap_or(0));
            let ny = i32::from(p.y).wrapping_add(DY.get(du).copied().unwrap_or(0));
            // The move is allowed, so the target is inside the map: both fit u16.
            let q = Point::new(nx as u16, ny as u16);
            let Some(j) = bbox.local(q) else { continue };
            let lj = heap.s.link.get(j).copied().unwrap_or(CLOSED);
            if lj & CLOSED != 0 {
                continue;
            }
            let ng = gi.saturating_add(if d & 1 == 1 { DIAGONAL } else { STRAIGHT });
            if lj & REACHED == 0 {
                if let (Some(g), Some(f), Some(l)) = (
                    heap.s.g.get_mut(j),
                    heap.s.f.get_mut(j),
                    heap.s.link.get_mut(j),
                ) {
                    *g = ng;
                    *f = ng.saturating_add(octile(q, to));
                    *l = REACHED | d;
                }
                heap.push(j as u16);
            } else if ng < heap.s.g.get(j).copied().unwrap_or(0) {
                if let (Some(g), Some(f), Some(l)) = (
                    heap.s.g.get_mut(j),
                    heap.s.f.get_mut(j),
                    heap.s.link.get_mut(j),
                ) {
                    let h = f.saturating_sub(*g);
                    *g = ng;
                    *f = ng.saturating_add(h);
                    *l = REACHED | d;
                }
                heap.decreased(j as u16);
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(rows: &[&str]) -> (Vec<u8>, u16, u16) {
        crate::testutil::bits(rows)
    }

    fn open(w: usize, h: usize) -> (Vec<u8>, u16, u16) {
        (vec![0u8; (w * h).div_ceil(8)], w as u16, h as u16)
    }

    struct Heapless {
        g: Vec<u32>,
        f: Vec<u32>,
        link: Vec<u8>,
        heap: Vec<u16>,
        pos: Vec<u16>,
    }

    impl Heapless {
        fn new(cells: usize, fill: u8) -> Self {
            Heapless {
                g: vec![u32::from(fill) * 0x0101_0101; cells],
                f: vec![u32::from(fill) * 0x0101_0101; cells],
                link: vec![fill; cells],
                heap: vec![u16::from(fill); cells],
                pos: vec![u16::from(fill); cells],
            }
        }
        fn scratch(&mut self) -> Scratch<'_> {
            Scratch {
                g: &mut self.g,
                f: &mut self.f,
                link: &mut self.link,
                heap: &mut self.heap,
                pos: &mut self.pos,
            }
        }
    }

    /// Length in search units; panics unless `p` is a valid path on `g`.
    fn cost(g: &Grid<'_>, p: &[Point]) -> u32 {
        assert!(g.is_free(p[0]));
        p.windows(2)
            .map(|s| {
                let d = dir_between(s[0], s[1]).expect("neighbours");
                assert_eq!(g.step(s[0], d), Some(s[1]), "illegal step {s:?}");
                step_cost(s[0], s[1])
            })
            .sum()
    }

    fn run(g: &Grid<'_>, path: &[Point], cells: usize) -> (Vec<Point>, Budget) {
        let mut out = vec![Point::default(); path.len() + 16];
        let mut s = Heapless::new(cells, 0xA5);
        let mut b = Budget::unlimited();
        let k = refine(g, path, &mut out, s.scratch(), &mut b).unwrap();
        out.truncate(k);
        assert_eq!(out[0], path[0]);
        assert_eq!(out[k - 1], *path.last().unwrap());
        assert!(cost(g, &out) <= cost(g, path));
        (out, b)
    }

    /// A path that walks `dirs` from `start`.
    fn walk(start: Point, dirs: &[u8]) -> Vec<Point> {
        let mut p = vec![start];
        for &d in dirs {
            let q = *p.last().unwrap();
            p.push(Point::new(
                (i32::from(q.x) + DX[d as usize]) as u16,
                (i32::from(q.y) + DY[d as usize]) as u16,
            ));
        }
        p
    }

    #[test]
    fn detour_becomes_the_optimum_inside_one_window() {
        // Around a wall: down, right along the bottom, up; the optimum hugs the wall's end.
        let rows = [
            "..........",
            "..........",
            "....#.....",
            "....#.....",
            "....#.....",
            "..........",
            "..........",
            "..........",
        ];
        let (b, w, h) = grid(&rows);
        let g = Grid::new(w, h, &b).unwrap();
        // (1,3) -> down to row 7, right to x 8, up to (8,3).
        let mut dirs = vec![2u8; 4];
        dirs.extend([0u8; 7]);
        dirs.extend([6u8; 4]);
        let path = walk(Point::new(1, 3), &dirs);
        let (out, b) = run(&g, &path, 64 * 64);
        // Optimum (over or under the wall): 4 diagonals and 3 straight steps.
        assert_eq!(cost(&g, &out), 4 * DIAGONAL + 3 * STRAIGHT, "{out:?}");
        assert!(b.improved >= 1 && b.expanded > 0);
    }

    #[test]
    fn long_zigzag_on_a_map_wider_than_the_window() {
        // 300 x 12 open map; the path zigzags between rows 2 and 8 all the way.
        let (b, w, h) = open(300, 12);
        let g = Grid::new(w, h, &b).unwrap();
        let mut dirs = vec![];
        for k in 0..50 {
            let d = if k % 2 == 0 { 1 } else { 7 }; // SE / NE
            dirs.extend([d; 5]);
        }
        dirs.extend([0; 49]);
        let path = walk(Point::new(0, 2), &dirs);
        assert_eq!(path.last().unwrap(), &Point::new(299, 2));
        let (out, b) = run(&g, &path, 32 * 32);
        // Straight along row 2 is the optimum. Windows see only local pieces: a one-row offset
        // whose two diagonals lie further apart than a window can stay (each costs
        // `DIAGONAL - STRAIGHT` extra); the zigzag itself (100 diagonals) is gone.
        let opt = 299 * STRAIGHT;
        let c = cost(&g, &out);
        let ys: Vec<(u16, u16)> = out
            .windows(2)
            .filter(|w| w[0].y != w[1].y)
            .map(|w| (w[0].x, w[0].y))
            .collect();
        assert!(
            c <= opt + 8 * (DIAGONAL - STRAIGHT),
            "{c} vs {opt} {b:?} {ys:?}"
        );
        assert!(c < cost(&g, &path) - 90 * (DIAGONAL - STRAIGHT));
        // Linear: windows are a small multiple of path / window.
        assert!(b.windows < 4 * 2 * (path.len() as u32 / 8), "{b:?}");
    }

    #[test]
    fn never_longer_and_deterministic_whatever_the_scratch_held() {
        let rows = [
            "....#.......#.....",
            "..#.#..###..#..#..",
            "..#....#.......#..",
            "..####.#.#####.#..",
            ".......#.....#....",
        ];
        let (b, w, h) = grid(&rows);
        let g = Grid::new(w, h, &b).unwrap();
        // A wandering but valid path: BFS-free hand walk along row 4 then up the right side.
        let mut dirs = vec![0u8; 6]; // (0,4) -> (6,4)
        dirs.extend([6u8; 4]); // up to (6,0)
        dirs.extend([0u8; 5]); // -> (11,0)
        dirs.extend([2u8, 2]); // (11,2)
        dirs.extend([0u8; 3]); // (14,2)
        dirs.extend([2u8, 2]); // (14,4)
        dirs.extend([0u8; 3]); // (17,4)
        let path = walk(Point::new(0, 4), &dirs);
        let (a, _) = run(&g, &path, 64 * 64);
        for fill in [0u8, 0xFF, 0x3C] {
            let mut out = vec![Point::new(7, 7); path.len() + 3];
            let mut s = Heapless::new(64 * 64, fill);
            let k = refine(&g, &path, &mut out, s.scratch(), &mut Budget::unlimited()).unwrap();
            assert_eq!(&out[..k], &a[..]);
        }
        // Whole map in one window: the exact optimum, and fewer cells.
        assert!(cost(&g, &a) < cost(&g, &path));
    }

    #[test]
    fn too_little_scratch_returns_the_input() {
        let (b, w, h) = open(20, 20);
        let g = Grid::new(w, h, &b).unwrap();
        let path = walk(Point::new(0, 0), &[0, 2, 0, 2, 0, 2, 0, 2]);
        let (out, bud) = run(&g, &path, MIN_SIDE * MIN_SIDE - 1);
        assert_eq!(out, path);
        assert_eq!(bud, Budget::unlimited());
        // One more cell side and it works.
        let (out, _) = run(&g, &path, MIN_SIDE * MIN_SIDE);
        assert_eq!(cost(&g, &out), 4 * DIAGONAL);
    }

    #[test]
    fn bad_inputs_are_errors() {
        let (b, w, h) = open(8, 8);
        let g = Grid::new(w, h, &b).unwrap();
        let mut out = vec![Point::default(); 8];
        let mut s = Heapless::new(64, 0);
        let mut bud = Budget::unlimited();
        let jump = [Point::new(0, 0), Point::new(2, 0)];
        assert_eq!(
            refine(&g, &jump, &mut out, s.scratch(), &mut bud),
            Err(Error::NoPath)
        );
        assert_eq!(
            refine(&g, &[], &mut out, s.scratch(), &mut bud),
            Err(Error::NoPath)
        );
        let off = [Point::new(8, 0)];
        assert_eq!(
            refine(&g, &off, &mut out, s.scratch(), &mut bud),
            Err(Error::NoPath)
        );
        let long = walk(Point::new(0, 0), &[0; 7]);
        assert_eq!(
            refine(&g, &long, &mut out[..7], s.scratch(), &mut bud),
            Err(Error::MapTooLarge {
                cells: 8,
                capacity: 7
            })
        );
        // A single cell is a path.
        assert_eq!(
            refine(&g, &long[..1], &mut out, s.scratch(), &mut bud),
            Ok(1)
        );
    }

    #[test]
    fn a_budget_stops_and_resumes_to_the_same_result() {
        let (b, w, h) = open(200, 30);
        let g = Grid::new(w, h, &b).unwrap();
        let mut dirs = vec![];
        for k in 0..39 {
            dirs.extend(if k % 2 == 0 {
                [1u8, 1, 0, 0, 0]
            } else {
                [7u8, 7, 0, 0, 0]
            });
        }
        let path = walk(Point::new(0, 5), &dirs);
        let (whole, total) = run(&g, &path, 24 * 24);
        let mut out = vec![Point::default(); path.len() + 16];
        let mut s = Heapless::new(24 * 24, 0);
        let mut r = Refiner::new(&g, &path, &mut out, DEFAULT_PASSES).unwrap();
        let mut calls = 0;
        let mut spent = Budget::unlimited();
        loop {
            let mut bud = Budget::new(50);
            calls += 1;
            let done = r.resume(&g, &mut out, &mut s.scratch(), &mut bud);
            // Stops at most one window past the limit.
            assert!(bud.expanded < 50 + 24 * 24);
            spent.expanded += bud.expanded;
            spent.windows += bud.windows;
            if done {
                break;
            }
        }
        let k = r.finish(&mut out);
        assert_eq!(&out[..k], &whole[..]);
        assert_eq!(spent.expanded, total.expanded);
        assert_eq!(spent.windows, total.windows);
        assert!(calls > 3, "{calls}");
    }
}
