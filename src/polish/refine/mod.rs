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
//! Passes repeat until one changes nothing or `max_passes` ran, or end at once when a window
//! replaced the whole path by a shortest path on the whole map (its box the whole map, or the
//! straight line): no later window could shorten it, so the second look that would only
//! confirm it is skipped (on a small map, whose one window is the whole map, half the local
//! search). Pieces whose length already
//! equals the obstacle-free octile distance are skipped without a search, and a longer piece
//! whose ends' straight line is free takes that line without a search (it is a shortest path in
//! any box: the proof is in `line`'s docs).
//!
//! **What it cannot do.** A window only sees its piece: a detour around the wrong side of a block
//! larger than the window stays (the colony's choice of corridor), and so does a path that runs
//! one row off the optimum for longer than a window (the two diagonals that would fix it are too
//! far apart). Both are rare on the Moving AI maps; `docs/ALGORITHM.md` has the figures of the
//! `refine_large` example.
//!
//! **Exact integer costs.** A straight step costs [`STRAIGHT`] and a diagonal [`DIAGONAL`], the
//! exact scale of `search::cost` (`47321 / 33461`, a convergent of `sqrt 2`). Two step mixes
//! `(a, b)` (straight, diagonal) of different true length `a + b sqrt 2` compare the same way in
//! these units up to 36,000 steps, far beyond any window; equal integer cost means equal step
//! mix. So the search is exact, not just close. The heap orders by `f = g + h`, then larger `g`, then the
//! lower box index. The open list is an indexed binary heap (decrease-key in place); since that
//! order is total, which cell leaves next depends only on the open cells and their keys, so the
//! expansion order, the costs left in the scratch and the path read back are fixed by the rule
//! above, not by how the heap is laid out or sifted.
//!
//! **Cost.** Linear in the path length for a fixed window: about one window per half piece of
//! path per pass, each expanding at most `side * side` cells (A* expands far fewer on open
//! ground) after clearing `side * side` bytes. [`Budget`] counts the cells expanded and stops a
//! run between windows once its limit is reached (overshooting by at most one window); a stopped
//! [`Refiner`] resumes where it stopped, so a firmware can yield between calls. Scratch is
//! [`Scratch::BYTES_PER_CELL`] = 12 bytes per window cell in two word slices (`side = 52`: 2 x
//! 4,056 words, 32 KiB; `64`: 48 KiB; `128`: 192 KiB), lent for each call and free in between.
//! No direction is stored: the searched path is read back from `g` alone (see
//! `window::pred`).
//!
//! **Buffers.** The path is rewritten inside `out`, streaming: the pending input sits at the end
//! of `out` and the output grows from its front, so `out` needs `path.len()` cells. A replacement
//! with more cells than the piece it replaces (shorter paths can have more steps) needs room: it
//! is skipped when the output would overrun the pending input. A few spare cells
//! (`path.len() + side`) make that practically never happen.

use crate::error::Error;
use crate::map::grid::{direction, Grid, Point};

mod line;
mod memo;
mod scratch;
mod window;

pub use memo::{words as memo_words, Memo, RECORD_WORDS};
pub use scratch::{RefineStorage, Scratch};
use scratch::{CLOSED, UNREACHED};
use window::{place, pred, search, Box2, Shape};

/// Costs of a straight and a diagonal step in search units (the exact scale, module docs).
pub use crate::search::cost::{DIAGONAL, STRAIGHT};
/// The largest window side (box indices and heap slots are `u16`, with `0xFFFF` kept free).
pub const MAX_SIDE: usize = 255;
/// The smallest window side worth searching; with less scratch the path is returned unchanged.
pub const MIN_SIDE: usize = 8;
/// Default pass limit of [`refine`].
pub const DEFAULT_PASSES: u8 = 4;

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
    /// Windows not searched because the memo knew they would not improve ([`Memo`]).
    pub remembered: u32,
    /// Windows replaced by the straight line between their ends, without a search (`line`).
    pub lines: u32,
}

impl Budget {
    /// A budget of `limit` expansions.
    pub const fn new(limit: u64) -> Self {
        Budget {
            limit,
            expanded: 0,
            windows: 0,
            improved: 0,
            remembered: 0,
            lines: 0,
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
    // Both below 2^16: the result is below 65535 * DIAGONAL < 2^32.
    crate::search::cost::EXACT.octile(u32::from(a.x.abs_diff(b.x)), u32::from(a.y.abs_diff(b.y)))
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
        let start = Self::tail(n, out.len())?;
        let tail = out.get_mut(start..).ok_or(Error::NoPath)?;
        tail.copy_from_slice(path);
        Self::laid_out(grid, out, start, max_passes)
    }

    /// [`Refiner::new`] for a path already in `out[..n]` (moved to the end of `out`).
    pub fn in_place(
        grid: &Grid<'_>,
        out: &mut [Point],
        n: usize,
        max_passes: u8,
    ) -> Result<Self, Error> {
        let start = Self::tail(n, out.len())?;
        out.copy_within(..n, start);
        Self::laid_out(grid, out, start, max_passes)
    }

    /// Where a path of `n` cells starts when laid out at the end of `cap` cells.
    fn tail(n: usize, cap: usize) -> Result<usize, Error> {
        cap.checked_sub(n).ok_or(Error::MapTooLarge {
            cells: u32::try_from(n).unwrap_or(u32::MAX),
            capacity: u32::try_from(cap).unwrap_or(u32::MAX),
        })
    }

    /// Check the path in `out[start..]` and start refining it.
    fn laid_out(
        grid: &Grid<'_>,
        out: &mut [Point],
        start: usize,
        max_passes: u8,
    ) -> Result<Self, Error> {
        let path = out.get(start..).ok_or(Error::NoPath)?;
        let first = *path.first().ok_or(Error::NoPath)?;
        if !grid.is_free(first) {
            return Err(Error::NoPath);
        }
        for pair in path.windows(2) {
            let (Some(&a), Some(&b)) = (pair.first(), pair.get(1)) else {
                return Err(Error::NoPath);
            };
            let ok = direction(a, b).and_then(|d| grid.step(a, d)) == Some(b);
            if !ok {
                return Err(Error::NoPath);
            }
        }
        let mut me = Refiner {
            w: 0,
            r: start,
            e: out.len(),
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
        // Whether the piece is the whole path (start to goal) and its replacement a shortest
        // path on the whole map: then no later window can shorten any piece of it (a piece of
        // a shortest path is a shortest path between its ends, and a window replaces a piece
        // only by a strictly shorter one), so the refinement ends there with the path every
        // further window and pass would have left as it is.
        let whole_path = s == 0 && t.saturating_add(1) >= total;
        let mut optimal = false;
        if old > octile(ps, pt) && line::free(grid, ps, pt) {
            // The straight line is a shortest path between the ends (`line`'s proof): the
            // window's search would find its cost; write the line instead of searching.
            budget.lines = budget.lines.saturating_add(1);
            replaced = self.replace_line(out, s, t, ps, pt);
            optimal = whole_path;
        } else if old > octile(ps, pt) {
            let ex = usize::from(x1.wrapping_sub(x0)).saturating_add(1);
            let ey = usize::from(y1.wrapping_sub(y0)).saturating_add(1);
            let (bw, bh) = shape.dims(ex, ey);
            let bbox = Box2 {
                x0: place(x0, ex, shape.map_w, bw),
                y0: place(y0, ey, shape.map_h, bh),
                w: bw,
                h: bh,
            };
            // A window asked before that would not improve its piece needs no search (the
            // proof is in `memo`'s docs).
            let key = memo::Key::new(ps, pt, &bbox);
            let known = scratch.memo.as_ref().and_then(|m| m.find(key));
            if known.is_none_or(|cost| cost < old) {
                budget.windows = budget.windows.saturating_add(1);
                if let Some(cost) = search(grid, &bbox, ps, pt, scratch, budget) {
                    if let Some(m) = scratch.memo.as_mut() {
                        m.put(key, cost);
                    }
                    if cost < old {
                        replaced = self.replace(grid, out, scratch, &bbox, s, t, pt);
                        // The window's box is the whole map: its A* is the exact optimum on
                        // the map (the module docs).
                        optimal = whole_path && bbox.covers(shape.map_w, shape.map_h);
                    }
                }
            } else {
                budget.remembered = budget.remembered.saturating_add(1);
            }
        }
        if replaced {
            budget.improved = budget.improved.saturating_add(1);
            self.improved = true;
            // (See `whole_path` above: `finish` compacts the path as it stands.)
            self.done = optimal;
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
    #[allow(clippy::too_many_arguments)] // one call site; the window's whole state
    fn replace(
        &mut self,
        grid: &Grid<'_>,
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
            if steps >= cells {
                return false;
            }
            let Some((q, qi)) = pred(grid, bbox, scratch, p, i) else {
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
            let Some((q, qi)) = pred(grid, bbox, scratch, p, i) else {
                break;
            };
            p = q;
            i = qi;
            k = k.wrapping_sub(1); // k > s >= 0
        }
        self.settle(out, s, steps, t_out);
        true
    }

    /// Write the line from `P[s]` = `from` to `P[t]` = `to` over the piece (it always fits: the
    /// line has `max(dx, dy)` steps, no more than any path between the ends); false if not.
    fn replace_line(
        &mut self,
        out: &mut [Point],
        s: usize,
        t: usize,
        from: Point,
        to: Point,
    ) -> bool {
        let line = line::Line::new(from, to);
        let steps = line.len() as usize;
        let Some(t_out) = self.r.checked_add(t.saturating_sub(self.w)) else {
            return false;
        };
        let Some(end) = s.checked_add(steps) else {
            return false;
        };
        if end > t_out || end >= out.len() {
            return false;
        }
        let slots = out.get_mut(s.saturating_add(1)..=end).unwrap_or_default();
        for (slot, p) in slots.iter_mut().zip(line) {
            *slot = p;
        }
        self.settle(out, s, steps, t_out);
        true
    }

    /// After a replacement written to `out[s + 1..=s + steps]` (the piece's last cell, virtual
    /// index `t`, was at `out[t_out]`): commit the new path up to its middle (but not less than
    /// was committed before) and hand the rest back to the pending part, so the next window
    /// overlaps this one by half: move `out[mid + 1..=end]` to just before the first pending cell
    /// (back to front: it moves up).
    fn settle(&mut self, out: &mut [Point], s: usize, steps: usize, t_out: usize) {
        let end = s.saturating_add(steps);
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
    }
}

/// The exact shortest 8-connected path from `from` to `to` inside the box of cells `lo..=hi`
/// (`lo` its top-left, `hi` its bottom-right corner, both on the map, `from` and `to` inside;
/// at most [`MAX_SIDE`] a side and [`Scratch::cells`] cells). Writes its cells, `from` first and
/// `to` last, to `out` and returns how many; `None` when the box is not such a box, no path inside
/// it exists, or `out` is too short (then `out` is left as it was). The box is the caller's: a
/// reused answer's repair sizes it by what blocks the answer ([`crate::planner`]'s `repair`).
pub(crate) fn detour(
    grid: &Grid<'_>,
    from: Point,
    to: Point,
    (lo, hi): (Point, Point),
    scratch: &mut Scratch<'_>,
    out: &mut [Point],
) -> Option<usize> {
    if hi.x >= grid.width() || hi.y >= grid.height() {
        return None;
    }
    let bbox = Box2 {
        x0: lo.x,
        y0: lo.y,
        w: usize::from(hi.x.checked_sub(lo.x)?).saturating_add(1),
        h: usize::from(hi.y.checked_sub(lo.y)?).saturating_add(1),
    };
    if bbox.w > MAX_SIDE || bbox.h > MAX_SIDE {
        return None;
    }
    search(grid, &bbox, from, to, scratch, &mut Budget::unlimited())?;
    let ti = bbox.local(to)?;
    // Count the steps back to `from` (at most one per box cell), then write them back to front.
    let cells = bbox.cells();
    let (mut steps, mut i, mut p) = (0usize, ti, to);
    while p != from {
        if steps >= cells {
            return None;
        }
        (p, i) = pred(grid, &bbox, scratch, p, i)?;
        steps = steps.wrapping_add(1);
    }
    let n = steps.checked_add(1)?;
    let cells_out = out.get_mut(..n)?;
    let (mut i, mut p) = (ti, to);
    for slot in cells_out.iter_mut().rev() {
        *slot = p;
        if p != from {
            (p, i) = pred(grid, &bbox, scratch, p, i)?;
        }
    }
    Some(n)
}

#[cfg(test)]
mod tests;
