//! One window of the local search: the box shapes a window may take, the box itself, and the
//! exact A* inside it (integer costs, ties broken by a fixed rule, so the same on every platform).

use crate::grid::{Grid, Point, DX, DY};

use super::{
    half, octile, set_half, Budget, Scratch, CLOSED, DIAGONAL, MAX_SIDE, STRAIGHT, UNREACHED,
};

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
        let cost = if d & 1 == 1 { DIAGONAL } else { STRAIGHT };
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
        half(self.s.heap, slot)
    }

    fn put(&mut self, slot: usize, i: u16) {
        set_half(self.s.heap, slot, i);
        // slot < heap length <= MAX_SIDE^2 < 0xFFFF.
        set_half(self.s.pos, usize::from(i), slot as u16);
    }

    fn push(&mut self, i: u16) {
        let slot = self.len;
        self.len = self.len.saturating_add(1);
        self.put(slot, i);
        self.up(slot);
    }

    fn decreased(&mut self, i: u16) {
        let slot = usize::from(half(self.s.pos, usize::from(i)));
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

/// Exact A* from `from` to `to` inside `bbox`; returns the cost to `to` (costs in `scratch`, read
/// back by [`pred`]).
pub(super) fn search(
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
    scratch.g.get_mut(..cells)?.fill(UNREACHED);
    *scratch.g.get_mut(si)? = 0;
    *scratch.f.get_mut(si)? = octile(from, to);
    let mut heap = Heap { s: scratch, len: 0 };
    // si < cells <= MAX_SIDE^2 < 0xFFFF.
    heap.push(si as u16);
    while let Some(i) = heap.pop() {
        let iu = usize::from(i);
        let gi = heap.s.g.get(iu).copied()?;
        set_half(heap.s.pos, iu, CLOSED);
        budget.expanded = budget.expanded.saturating_add(1);
        if iu == ti {
            return Some(gi);
        }
        let p = bbox.point(iu);
        let mask = grid.mask_at(p);
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
            let gj = heap.s.g.get(j).copied().unwrap_or(0);
            let ng = gi.saturating_add(if d & 1 == 1 { DIAGONAL } else { STRAIGHT });
            if gj == UNREACHED {
                if let (Some(g), Some(f)) = (heap.s.g.get_mut(j), heap.s.f.get_mut(j)) {
                    *g = ng;
                    *f = ng.saturating_add(octile(q, to));
                }
                // j < cells < 0xFFFF.
                heap.push(j as u16);
            } else if ng < gj && half(heap.s.pos, j) != CLOSED {
                if let (Some(g), Some(f)) = (heap.s.g.get_mut(j), heap.s.f.get_mut(j)) {
                    let h = f.saturating_sub(*g);
                    *g = ng;
                    *f = ng.saturating_add(h);
                }
                heap.decreased(j as u16);
            }
        }
    }
    None
}
