//! A window answered without a search: the 8-connected straight line between the piece's ends.
//!
//! **What it owns.** [`Line`], the integer (Bresenham) line from one cell to another, and
//! [`free`], whether every move along it is allowed on the map.
//!
//! **What it guarantees (the proof that a window answered by its line loses nothing).** The
//! line from `a` to `b` makes `max(dx, dy)` moves, `min(dx, dy)` of them diagonal (each move
//! advances the major axis by one and the minor axis by at most one, and the minor axis must
//! advance `min(dx, dy)` times), so its cost is exactly `octile(a, b)`, the obstacle-free cost
//! of `a` to `b` (`super::octile`). No 8-connected path from `a` to `b` costs less: write
//! `M = max(dx, dy)`, `m = min(dx, dy)`, `S` and `D` the straight and diagonal costs
//! (`S < D < 2S`). A path of `s` straight and `d` diagonal moves changes each coordinate by at
//! most one a move and only a diagonal changes both, so `s + d >= M` and `s + 2d >= M + m`; then
//! `S s + D d = (2S - D)(s + d) + (D - S)(s + 2d) >= (2S - D) M + (D - S)(M + m) = S (M - m) +
//! D m`, the octile cost (both factors positive). So when every move of the line is allowed ([`free`]: the
//! cell entered is free and, on a diagonal, so are both cells beside it, the map's no
//! corner-cutting rule, [`crate::map::grid::Grid::step`]), the line is a shortest path between
//! the ends inside any box that holds it, in particular inside the window's box, which holds the
//! piece's bounding box and so the line (a line never leaves the bounding box of its ends). The
//! window's search would find the same cost, `octile(a, b)`; the window replaces its piece in
//! exactly the same cases (`cost < old`) with a path of the same cost, and only which of the
//! equally short paths it writes differs (the line instead of the search's read-back). A line
//! that is not free decides nothing: the window is searched as before.
//!
//! The rule is pinned by `a_line_is_taken_only_when_free` in `super::tests` (a diagonal that
//! cuts a corner, or a blocked cell on the line, must send the window to its search).

use crate::map::grid::{Grid, Point};

/// The cells of the 8-connected line from `a` to `b` after `a`, `b` last: `max(dx, dy)` cells.
#[derive(Clone, Copy, Debug)]
pub(super) struct Line {
    x: i32,
    y: i32,
    dx: i32,
    dy: i32,
    sx: i32,
    sy: i32,
    err: i32,
    left: u32,
}

impl Line {
    /// The line from `a` to `b`.
    pub(super) fn new(a: Point, b: Point) -> Self {
        let (ax, ay, bx, by) = (
            i32::from(a.x),
            i32::from(a.y),
            i32::from(b.x),
            i32::from(b.y),
        );
        // Coordinates below 2^16: no overflow in i32.
        let dx = bx.wrapping_sub(ax).wrapping_abs();
        let dy = by.wrapping_sub(ay).wrapping_abs();
        Line {
            x: ax,
            y: ay,
            dx,
            dy,
            sx: if bx < ax { -1 } else { 1 },
            sy: if by < ay { -1 } else { 1 },
            err: dx.wrapping_sub(dy),
            left: dx.max(dy).unsigned_abs(),
        }
    }

    /// Moves left to the end.
    pub(super) fn len(&self) -> u32 {
        self.left
    }

    /// The next move: the cell before and the cell after it.
    fn next_move(&mut self) -> Option<((i32, i32), (i32, i32))> {
        if self.left == 0 {
            return None;
        }
        self.left = self.left.wrapping_sub(1);
        let from = (self.x, self.y);
        // |err| <= max(dx, dy) < 2^16: doubling cannot overflow.
        let e2 = self.err.wrapping_mul(2);
        if e2 > self.dy.wrapping_neg() {
            self.err = self.err.wrapping_sub(self.dy);
            self.x = self.x.wrapping_add(self.sx);
        }
        if e2 < self.dx {
            self.err = self.err.wrapping_add(self.dx);
            self.y = self.y.wrapping_add(self.sy);
        }
        Some((from, (self.x, self.y)))
    }
}

impl Iterator for Line {
    type Item = Point;

    fn next(&mut self) -> Option<Point> {
        let (_, (x, y)) = self.next_move()?;
        // The line stays inside the bounding box of two map cells: both fit u16.
        Some(Point::new(
            u16::try_from(x).unwrap_or(u16::MAX),
            u16::try_from(y).unwrap_or(u16::MAX),
        ))
    }
}

/// True if every move of the line from `a` to `b` is allowed on `grid` (`a` itself is the
/// caller's: a cell of a valid path).
pub(super) fn free(grid: &Grid<'_>, a: Point, b: Point) -> bool {
    let mut line = Line::new(a, b);
    while let Some(((x, y), (nx, ny))) = line.next_move() {
        if grid.blocked_xy(nx, ny) {
            return false;
        }
        if x != nx && y != ny && (grid.blocked_xy(nx, y) || grid.blocked_xy(x, ny)) {
            return false;
        }
    }
    true
}
