//! One window of the local search: the box shapes a window may take, the box itself, and the
//! exact A* inside it (integer costs, ties broken by a fixed rule, so the same on every platform).

use crate::map::grid::{Grid, Point, DX, DY};
use crate::search::{cost, heap};

use super::{octile, Budget, Scratch, CLOSED, MAX_SIDE, UNREACHED};

/// The cell before `p` (box index `i`) on a shortest path of the last [`search`]: its first
/// neighbour, in direction order, inside the box and reached, one allowed move away, with
/// `g(q) + cost(q, p) = g(p)`.
///
/// Why this finds a path without storing directions: `g` only ever holds the cost of a real path
/// and only decreases. Let `p` have its optimal cost, and `q` be the cell that last lowered
/// `g(p)`, with `g(q)` then. Now `opt(q) <= g(q) <= g(q) then = g(p) - cost = opt(p) - cost <=
/// opt(q)`: `q` qualifies and has its optimal cost too. Any other qualifying `q'` has
/// `opt(q') <= g(q') = opt(p) - cost' <= opt(q')` as well, so the walk from the target (optimal:
/// A* with a consistent heuristic closed it) stays on optimal costs, which fall strictly at each
/// step, and ends at the start, the only cell of cost 0.
pub(super) fn pred(
    grid: &Grid<'_>,
    bbox: &Box2,
    scratch: &Scratch<'_>,
    p: Point,
    i: usize,
) -> Option<(Point, usize)> {
    let gp = scratch.g.get(i).copied()?;
    if gp == UNREACHED || gp == 0 {
        return None;
    }
    // Moves are symmetric (no corner cutting either way), so the mask of `p` gives the moves in.
    let mask = grid.mask_at(p);
    for d in 0..8u8 {
        if mask & (1 << d) == 0 {
            continue;
        }
        let du = usize::from(d);
        let qx = i32::from(p.x).wrapping_add(DX.get(du).copied().unwrap_or(0));
        let qy = i32::from(p.y).wrapping_add(DY.get(du).copied().unwrap_or(0));
        // The move is allowed, so `q` is inside the map: both fit u16.
        let q = Point::new(qx as u16, qy as u16);
        let Some(j) = bbox.local(q) else { continue };
        let gq = scratch.g.get(j).copied().unwrap_or(UNREACHED);
        let cost = cost::step(d);
        if gq != UNREACHED && gq.checked_add(cost) == Some(gp) {
            return Some((q, j));
        }
    }
    None
}

/// Origin of a box side of `len` cells over a piece starting at `lo` with `extent` cells, centred
/// and clipped to a map side of `map` cells (`extent <= len <= map`).
pub(super) fn place(lo: u16, extent: usize, map: usize, len: usize) -> u16 {
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
pub(super) struct Shape {
    pub(super) cells: usize,
    pub(super) margin: usize,
    pub(super) min_side: usize,
    pub(super) map_w: usize,
    pub(super) map_h: usize,
}

impl Shape {
    /// Box side for a piece extent of `e` cells on a map side of `map` cells.
    fn side(&self, e: usize, map: usize) -> usize {
        e.saturating_add(self.margin.saturating_mul(2))
            .max(self.min_side)
            .min(map)
    }

    /// True if a piece with a bounding box of `ex x ey` cells gets a box.
    pub(super) fn fits(&self, ex: usize, ey: usize) -> bool {
        let (w, h) = (self.side(ex, self.map_w), self.side(ey, self.map_h));
        w <= MAX_SIDE && h <= MAX_SIDE && w.saturating_mul(h) <= self.cells
    }

    /// The box for a piece that [`Shape::fits`]: the minimal box, its short side then its long
    /// side grown into the spare area.
    pub(super) fn dims(&self, ex: usize, ey: usize) -> (usize, usize) {
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
pub(super) struct Box2 {
    pub(super) x0: u16,
    pub(super) y0: u16,
    pub(super) w: usize,
    pub(super) h: usize,
}

impl Box2 {
    pub(super) fn cells(&self) -> usize {
        // Both <= MAX_SIDE.
        self.w.saturating_mul(self.h)
    }

    /// Whether the box is the whole `map_w x map_h` map (its A* is then the map's exact
    /// optimum).
    pub(super) fn covers(&self, map_w: usize, map_h: usize) -> bool {
        self.x0 == 0 && self.y0 == 0 && self.w >= map_w && self.h >= map_h
    }

    pub(super) fn local(&self, p: Point) -> Option<usize> {
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

/// The moves leaving a box by its west side (bit `d` set iff [`DX`]`[d] == -1`; unit test
/// `side_masks_are_the_directions`).
const WEST: u8 = 0b0011_1000;
/// The moves with [`DX`]`[d] == 1`.
const EAST: u8 = 0b1000_0011;
/// The moves with [`DY`]`[d] == -1`.
const NORTH: u8 = 0b1110_0000;
/// The moves with [`DY`]`[d] == 1`.
const SOUTH: u8 = 0b0000_1110;

/// True if box cell `a` comes before `b` in the open list's order: smaller `f`, then larger `g`,
/// then the smaller index (a total order: indices differ).
#[inline(always)]
fn before(g: &[u32], f: &[u32], a: u16, b: u16) -> bool {
    let (au, bu) = (usize::from(a), usize::from(b));
    let fa = f.get(au).copied().unwrap_or(u32::MAX);
    let fb = f.get(bu).copied().unwrap_or(u32::MAX);
    if fa != fb {
        return fa < fb;
    }
    let ga = g.get(au).copied().unwrap_or(0);
    let gb = g.get(bu).copied().unwrap_or(0);
    if ga != gb {
        return ga > gb;
    }
    a < b
}

/// The open list: the crate's binary min-heap ([`heap`]) of box indices in [`before`] order,
/// root at slot 1 of `heap` (its slot 0 unused), with each open cell's slot in `pos`. Which cell
/// leaves next depends only on the set of open cells and their keys (the order is total), not on
/// how the heap is laid out.
struct Open<'s> {
    heap: &'s mut [u16],
    pos: &'s mut [u16],
    len: usize,
}

/// The open list as the crate's heap sees it ([`heap::Slots`]): its live slots (slot `s` is
/// `heap[s + 1]`), the positions, and the keys `g` and `f`.
struct Keys<'k> {
    live: &'k mut [u16],
    pos: &'k mut [u16],
    g: &'k [u32],
    f: &'k [u32],
}

impl heap::Slots for Keys<'_> {
    type Item = u16;
    #[inline(always)]
    fn at(&self, slot: usize) -> Option<u16> {
        self.live.get(slot).copied()
    }
    #[inline(always)]
    fn put(&mut self, slot: usize, i: u16) {
        if let Some(s) = self.live.get_mut(slot) {
            *s = i;
        }
        // slot < len < cells <= MAX_SIDE^2 < 0xFFFF.
        if let Some(p) = self.pos.get_mut(usize::from(i)) {
            *p = slot.wrapping_add(1) as u16;
        }
    }
    #[inline(always)]
    fn before(&self, a: u16, b: u16) -> bool {
        before(self.g, self.f, a, b)
    }
    #[inline(always)]
    fn pair(&self, c: usize) -> Option<(u16, u16)> {
        match self.live.get(c..c.wrapping_add(2)) {
            Some(&[a, b]) => Some((a, b)),
            _ => None,
        }
    }
}

impl Open<'_> {
    /// The live slots with the keys (`None` only if `len` outgrew `heap`, which it never does).
    #[inline(always)]
    fn keys<'k>(&'k mut self, g: &'k [u32], f: &'k [u32]) -> Option<Keys<'k>> {
        Some(Keys {
            live: self.heap.get_mut(1..=self.len)?,
            pos: &mut *self.pos,
            g,
            f,
        })
    }

    /// Add the new cell `i`.
    #[inline(never)]
    fn push(&mut self, g: &[u32], f: &[u32], i: u16) {
        let hole = self.len;
        self.len = self.len.wrapping_add(1); // len < cells
        if let Some(mut k) = self.keys(g, f) {
            heap::sift_up(&mut k, hole, i);
        }
    }

    /// Cell `i`, open, got a smaller key.
    #[inline(never)]
    fn decreased(&mut self, g: &[u32], f: &[u32], i: u16) {
        let slot = usize::from(self.pos.get(usize::from(i)).copied().unwrap_or(0));
        if slot >= 1 && slot <= self.len {
            if let Some(mut k) = self.keys(g, f) {
                heap::sift_up(&mut k, slot.wrapping_sub(1), i);
            }
        }
    }

    /// Take the first cell out (the last one [`heap::settle`]s into the root's hole).
    #[inline(always)]
    fn pop(&mut self, g: &[u32], f: &[u32]) -> Option<u16> {
        if self.len == 0 {
            return None;
        }
        let top = self.heap.get(1).copied()?;
        let last = self.heap.get(self.len).copied()?;
        self.len = self.len.wrapping_sub(1);
        if self.len > 0 {
            if let Some(mut k) = self.keys(g, f) {
                heap::settle(&mut k, last);
            }
        }
        Some(top)
    }
}

/// Exact A* from `from` to `to` inside `bbox`; returns the cost to `to` (costs in `scratch`, read
/// back by [`pred`]).
///
/// Each expansion reads the cell's move mask once, drops the moves leaving the box, and visits
/// the neighbours by index offsets; a closed neighbour costs one load and a comparison (its `g`
/// is already optimal: the octile heuristic is consistent).
pub(super) fn search(
    grid: &Grid<'_>,
    bbox: &Box2,
    from: Point,
    to: Point,
    scratch: &mut Scratch<'_>,
    budget: &mut Budget,
) -> Option<u32> {
    let cells = bbox.cells();
    if cells > scratch.cells() || cells > MAX_SIDE * MAX_SIDE || bbox.w == 0 {
        return None;
    }
    let si = bbox.local(from)?;
    let ti = bbox.local(to)?;
    let g = scratch.g.get_mut(..cells)?;
    let f = scratch.f.get_mut(..cells)?;
    g.fill(UNREACHED);
    *g.get_mut(si)? = 0;
    *f.get_mut(si)? = octile(from, to);
    let mut open = Open {
        heap: &mut *scratch.heap,
        pos: &mut *scratch.pos,
        len: 0,
    };
    // Box-local offsets: w <= MAX_SIDE, so all fit isize.
    let w = bbox.w as isize;
    let mut off = [0isize; 8];
    for (d, o) in off.iter_mut().enumerate() {
        let dx = DX.get(d).copied().unwrap_or(0) as isize;
        let dy = DY.get(d).copied().unwrap_or(0) as isize;
        *o = dy.wrapping_mul(w).wrapping_add(dx);
    }
    // The target in box coordinates (for the heuristic).
    let tx = i32::from(to.x.wrapping_sub(bbox.x0));
    let ty = i32::from(to.y.wrapping_sub(bbox.y0));
    let (last_x, last_y) = (bbox.w.wrapping_sub(1), bbox.h.wrapping_sub(1));
    // si < cells <= MAX_SIDE^2 < 0xFFFF.
    open.push(g, f, si as u16);
    let mut expanded = 0u64;
    let mut result = None;
    while let Some(i) = open.pop(g, f) {
        let iu = usize::from(i);
        let gi = g.get(iu).copied().unwrap_or(UNREACHED);
        if let Some(p) = open.pos.get_mut(iu) {
            *p = CLOSED;
        }
        expanded = expanded.wrapping_add(1);
        if iu == ti {
            result = Some(gi);
            break;
        }
        let p = bbox.point(iu);
        let (lx, ly) = (
            usize::from(p.x.wrapping_sub(bbox.x0)),
            usize::from(p.y.wrapping_sub(bbox.y0)),
        );
        // The allowed moves that stay inside the box.
        let mut mask = grid.mask_at(p);
        if lx == 0 {
            mask &= !WEST;
        }
        if lx >= last_x {
            mask &= !EAST;
        }
        if ly == 0 {
            mask &= !NORTH;
        }
        if ly >= last_y {
            mask &= !SOUTH;
        }
        while mask != 0 {
            let d = mask.trailing_zeros() as usize & 7;
            mask &= mask.wrapping_sub(1);
            // The move stays inside the box: j is its box index.
            let j = iu.wrapping_add_signed(off.get(d).copied().unwrap_or(0));
            let Some(&gj) = g.get(j) else { continue };
            let ng = gi.saturating_add(cost::step(d as u8));
            if gj == UNREACHED {
                // Box coordinates below MAX_SIDE: no overflow in i32.
                let qx = (lx as i32).wrapping_add(DX.get(d).copied().unwrap_or(0));
                let qy = (ly as i32).wrapping_add(DY.get(d).copied().unwrap_or(0));
                let h = cost::EXACT.octile(qx.abs_diff(tx), qy.abs_diff(ty));
                if let (Some(gs), Some(fs)) = (g.get_mut(j), f.get_mut(j)) {
                    *gs = ng;
                    *fs = ng.saturating_add(h);
                }
                // j < cells < 0xFFFF.
                open.push(g, f, j as u16);
            } else if ng < gj && open.pos.get(j).copied() != Some(CLOSED) {
                if let (Some(gs), Some(fs)) = (g.get_mut(j), f.get_mut(j)) {
                    let h = fs.saturating_sub(*gs);
                    *gs = ng;
                    *fs = ng.saturating_add(h);
                }
                open.decreased(g, f, j as u16);
            }
        }
    }
    budget.expanded = budget.expanded.saturating_add(expanded);
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small xorshift.
    fn next(x: &mut u32) -> u32 {
        *x ^= *x << 13;
        *x ^= *x >> 17;
        *x ^= *x << 5;
        *x
    }

    #[test]
    fn side_masks_are_the_directions() {
        let along =
            |t: &[i32; 8], v: i32| (0..8).filter(|&d| t[d] == v).fold(0u8, |m, d| m | 1 << d);
        assert_eq!(WEST, along(&DX, -1));
        assert_eq!(EAST, along(&DX, 1));
        assert_eq!(NORTH, along(&DY, -1));
        assert_eq!(SOUTH, along(&DY, 1));
    }

    #[test]
    fn open_list_pops_in_key_order() {
        // Random keys with many ties in f and in g, pushes, decreases and pops interleaved: every
        // pop is the smallest open cell by (f, larger g, index), as a plain scan finds it.
        let mut x = 0x2545_F491u32;
        for round in 0..200 {
            let n = 1 + (next(&mut x) as usize % 300);
            let mut g = vec![0u32; n];
            let mut f = vec![0u32; n];
            let (mut heap, mut pos) = (vec![0u16; n + 1], vec![0u16; n]);
            let mut open = Open {
                heap: &mut heap,
                pos: &mut pos,
                len: 0,
            };
            let mut live = vec![false; n];
            let mut pushed = 0usize;
            let mut popped = 0usize;
            while popped < n {
                let r = next(&mut x) % 4;
                if r < 2 && pushed < n {
                    let i = pushed;
                    g[i] = next(&mut x) % 4;
                    f[i] = g[i] + next(&mut x) % (3 + round % 5) as u32;
                    open.push(&g, &f, i as u16);
                    live[i] = true;
                    pushed += 1;
                } else if r == 2 && popped < pushed {
                    // Lower the key of a live cell, keeping f - g (as the search does).
                    let i = next(&mut x) as usize % pushed;
                    if live[i] && g[i] > 0 {
                        let h = f[i] - g[i];
                        g[i] -= 1 + next(&mut x) % g[i];
                        f[i] = g[i] + h;
                        open.decreased(&g, &f, i as u16);
                    }
                } else if popped < pushed {
                    let want = (0..n)
                        .filter(|&i| live[i])
                        .min_by_key(|&i| (f[i], u32::MAX - g[i], i))
                        .unwrap();
                    let got = open.pop(&g, &f).expect("open cells left");
                    assert_eq!(usize::from(got), want, "round {round}");
                    live[want] = false;
                    popped += 1;
                }
            }
            assert_eq!(open.pop(&g, &f), None);
        }
    }
}
