//! The raw cells a repair reads: where each waypoint lies on the raw path, and the smoothing's
//! input around the detour (the module docs of [`super`], steps 1 and 4).

use crate::geometry::segment_clear;
use crate::map::grid::{neighbour, Dir, Grid, Point};

use super::{GiveUp, PLACE_RADIUS};

/// The cell at offset `t` of the raw path from `start` by `dirs`.
pub(super) fn cell_at(start: Point, dirs: &[Dir], t: usize) -> Option<Point> {
    Some(dirs.get(..t)?.iter().fold(start, |p, &d| neighbour(p, d)))
}

/// Raw cells one step of the smoothing's input may span outside a repair's detour: from each
/// input cell the next is the farthest raw cell this many, half, a quarter ... cells on that it
/// sees (`docs/ALGORITHM.md`, "Repaired answers").
pub const STRIDE: usize = 16;

/// The smoothing's input along the raw cells after `at` by `dirs` (`at` itself is not one), the
/// last input cell so far being `p`: none when `p` sees `then` (the input cell after them, if
/// any), only the last when `p` sees it; else from `p` on, the farthest of the cells [`STRIDE`],
/// half that, a quarter ... cells on (not past the last) that `p` sees, else the next one, and
/// the last cell always. So each input cell sees
/// the one before it (the DP's assumption; where `p` is not a raw cell and sees no cell it is
/// tested with, the final check catches it), and a stretch of open floor costs the DP a cell in
/// [`STRIDE`], or none, instead of every one. Calls `emit` with each cell; returns the last input
/// cell (`p` if none).
pub(super) fn sparse(
    grid: &Grid<'_>,
    mut p: Point,
    at: Point,
    dirs: &[Dir],
    then: Option<Point>,
    emit: &mut impl FnMut(Point) -> Result<(), GiveUp>,
) -> Result<Point, GiveUp> {
    let m = dirs.len();
    if m == 0 {
        return Ok(p);
    }
    match then {
        Some(e) if segment_clear(grid, p, e) => return Ok(p),
        None => {
            let last = dirs.iter().fold(at, |q, &d| neighbour(q, d));
            if segment_clear(grid, p, last) {
                emit(last)?;
                return Ok(last);
            }
        }
        Some(_) => {}
    }
    // `ahead[k]`: the cell `k` steps after the last input cell (`ahead[0]`), at raw step `t`.
    let mut ahead = [at; STRIDE + 1];
    let mut t = 0usize;
    while t < m {
        let span = m.wrapping_sub(t).min(STRIDE); // t < m: no wrap; at least 1
        for k in 1..=span {
            let (Some(&q), Some(&d)) = (
                ahead.get(k.wrapping_sub(1)),
                dirs.get(t.wrapping_add(k).wrapping_sub(1)),
            ) else {
                return Err(GiveUp::Unplaced);
            };
            if let Some(slot) = ahead.get_mut(k) {
                *slot = neighbour(q, d);
            }
        }
        // The farthest of `span`, `span / 2`, `span / 4`, ... steps that `p` sees, else one.
        let mut k = span;
        while k > 1 && !ahead.get(k).is_some_and(|&q| segment_clear(grid, p, q)) {
            k /= 2;
        }
        let c = ahead.get(k).copied().ok_or(GiveUp::Unplaced)?;
        emit(c)?;
        p = c;
        t = t.saturating_add(k.max(1));
        if let Some(first) = ahead.first_mut() {
            *first = c;
        }
    }
    Ok(p)
}

/// Cells between two points (Chebyshev).
pub(super) fn cheb(a: Point, b: Point) -> u16 {
    a.x.abs_diff(b.x).max(a.y.abs_diff(b.y))
}

/// Squared distance between two cells within [`PLACE_RADIUS`] of each other (saturating).
pub(super) fn dist2(a: Point, b: Point) -> u32 {
    let (dx, dy) = (u32::from(a.x.abs_diff(b.x)), u32::from(a.y.abs_diff(b.y)));
    dx.saturating_mul(dx).saturating_add(dy.saturating_mul(dy))
}

/// Raw offsets of waypoints along a raw path, in order ([`Offsets::find`]).
pub(super) struct Offsets<'r> {
    dirs: &'r [Dir],
    /// The raw cell at offset `t`.
    p: Point,
    t: usize,
}

impl<'r> Offsets<'r> {
    pub(super) fn new(start: Point, dirs: &'r [Dir]) -> Self {
        Offsets {
            dirs,
            p: start,
            t: 0,
        }
    }

    /// The offset of the raw cell `w` is placed on: from the current cell on, the first visit of
    /// the raw path to within [`PLACE_RADIUS`] cells of `w` (Chebyshev), and its cell nearest to
    /// `w` (Euclidean; the first on a tie; `w` itself as soon as it is a raw cell). That cell
    /// becomes the current one: the next waypoint may be placed on it too. `None` (the current
    /// cell unchanged) when no raw cell from the current one on comes that near.
    pub(super) fn find(&mut self, w: Point) -> Option<usize> {
        let (mut p, mut t) = (self.p, self.t);
        while cheb(p, w) > PLACE_RADIUS {
            let &d = self.dirs.get(t)?;
            p = neighbour(p, d);
            t = t.wrapping_add(1);
        }
        let (mut near, mut q, mut u) = (dist2(p, w), p, t);
        while near > 0 {
            let Some(&d) = self.dirs.get(u) else { break };
            q = neighbour(q, d);
            u = u.wrapping_add(1);
            if cheb(q, w) > PLACE_RADIUS {
                break;
            }
            let e = dist2(q, w);
            if e < near {
                (near, p, t) = (e, q, u);
            }
        }
        (self.p, self.t) = (p, t);
        Some(t)
    }

    /// [`Offsets::find`] for L\[`m`\]; the first waypoint after the robot's cell (`m` 1) that the
    /// raw path from the robot on never comes near is one the robot has passed (it lies nearer
    /// the segment it ends than the next one does, [`crate::planner::reuse()`]'s entry rule):
    /// placed on the robot's cell, `true` (then smoothed again, never kept). Any other is
    /// [`GiveUp::Unplaced`].
    pub(super) fn place(&mut self, m: usize, w: Point) -> Result<(usize, bool), GiveUp> {
        match self.find(w) {
            Some(o) => Ok((o, false)),
            None if m == 1 => Ok((0, true)),
            None => Err(GiveUp::Unplaced),
        }
    }
}
