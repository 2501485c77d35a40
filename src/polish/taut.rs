//! Pulling a smoothed path taut over the cell centres around it: the last step of OHACA's
//! default smoothing ([`crate::polish::smoothing::SmoothingKind::Shortest`]).
//!
//! The shortest-path smoothing keeps waypoints on the raw path's cells. The exact any-angle
//! optimum (cell centres, the segment rule of [`crate::geometry::segment_clear`]) usually bends at
//! the cells right beside an obstacle's corner, which the raw path may pass one or two cells away
//! from. [`pull`] closes that gap by local moves, each of which keeps the path valid and makes it
//! strictly shorter:
//!
//! - **drop** an interior waypoint whose two neighbours see each other;
//! - **shift** an interior waypoint to one of its eight neighbouring cell centres when both new
//!   segments are clear and the two segments get shorter.
//!
//! Passes over the waypoints repeat until a pass changes nothing, at most [`MAX_PASSES`] times.
//! A pass can go a bounded amount of work at a time ([`Pass`]), with the same result.
//!
//! Guarantees: the result is never longer than the input (every move shortens it, by at least
//! [`MIN_GAIN`] cells, so a pass cannot cycle), every segment obeys the segment rule (each move
//! is checked with `segment_clear`), start and goal stay, and nothing panics or allocates. Like
//! everything in the core it is deterministic: fixed order of waypoints and neighbours, `f32`
//! lengths from [`crate::geometry::distance`] (libm's correctly rounded `sqrtf`), so the host and
//! the device pull the same path taut.

use crate::geometry::{distance, drop_collinear, segment_clear};
use crate::map::dir::{DX, DY};
use crate::map::grid::{Grid, Point};

/// Passes over the waypoints at most (measured on the shared small maps: one to three passes
/// change something, the rest find nothing).
pub const MAX_PASSES: u8 = 8;

/// The least shortening a move must bring, in cells: far above `f32` rounding of lengths below
/// a few thousand cells, far below any real gain (one cell sideways changes a length by
/// at least about `1 / (2 L)` for segments of length `L`).
pub const MIN_GAIN: f32 = 1e-4;

/// Pull `pts[..n]` taut in place (see the module docs); returns the new waypoint count. The
/// same as [`pass`] until one changes nothing (at most [`MAX_PASSES`]), then
/// [`drop_collinear`]: the planner does it a bounded piece of a pass at a time ([`Pass`]).
pub fn pull(grid: &Grid<'_>, pts: &mut [Point], n: usize) -> usize {
    let mut n = n.min(pts.len());
    for _ in 0..MAX_PASSES {
        let (m, changed) = pass(grid, pts, n);
        n = m;
        if !changed {
            break;
        }
    }
    drop_collinear(pts, n)
}

/// One pass of [`pull`] over `pts[..n]`: returns the new count and whether it changed anything.
/// The same as a [`Pass`] without a budget.
pub fn pass(grid: &Grid<'_>, pts: &mut [Point], n: usize) -> (usize, bool) {
    let mut p = Pass::new(n.min(pts.len()));
    loop {
        let mut budget = u32::MAX;
        if let Some(done) = p.resume(grid, pts, &mut budget) {
            return done;
        }
    }
}

/// Work units of a segment test from `a` to `b` ([`segment_clear`] at its worst: a walk over
/// the rows it spans, a byte of the map at a time in each): four, one a row, one for eight
/// columns. The smoothing's merge and the taut pull charge their budgets with it.
pub fn segment_units(a: Point, b: Point) -> u32 {
    let rows = u32::from(a.y.abs_diff(b.y));
    let cols = u32::from(a.x.abs_diff(b.x));
    4u32.wrapping_add(rows).wrapping_add(cols >> 3)
}

/// Work units of a waypoint of a [`Pass`] besides its segment tests (eight candidate lengths).
pub const WAYPOINT_UNITS: u32 = 8;

/// A pass of [`pull`] in progress, a bounded amount of work at a time ([`Pass::resume`]), so a
/// firmware can yield inside the pull of a long path: where it stands (the next waypoint and
/// the count) and whether it changed anything so far. However the work is cut, the pass does
/// what [`pass`] does, bit for bit; the caller passes the same points to every call.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Pass {
    /// Waypoints now.
    n: usize,
    /// The next interior waypoint to try (`1 <= i`).
    i: usize,
    /// A waypoint was dropped or shifted so far.
    changed: bool,
}

impl Pass {
    /// A pass over `pts[..n]`.
    pub fn new(n: usize) -> Self {
        Pass {
            n,
            i: 1,
            changed: false,
        }
    }

    /// Go on while `budget` lasts (work units: [`segment_units`] a segment test,
    /// [`WAYPOINT_UNITS`] a waypoint), taking what it spends from it; at least one waypoint a
    /// call, so a waypoint's tests may take it below zero (then it is 0). `Some((count,
    /// changed))` once the pass is over, `None` while waypoints are left.
    pub fn resume(
        &mut self,
        grid: &Grid<'_>,
        pts: &mut [Point],
        budget: &mut u32,
    ) -> Option<(usize, bool)> {
        let mut n = self.n.min(pts.len());
        let mut i = self.i.max(1);
        let mut left = *budget;
        let mut first = true;
        // Bounds: 1 <= i and i + 1 < n <= pts.len() inside the loop.
        while i.wrapping_add(1) < n {
            if left == 0 && !first {
                (self.n, self.i) = (n, i);
                *budget = 0;
                return None;
            }
            first = false;
            let (Some(&a), Some(&b), Some(&c)) = (
                pts.get(i.wrapping_sub(1)),
                pts.get(i),
                pts.get(i.wrapping_add(1)),
            ) else {
                break;
            };
            let mut spent = WAYPOINT_UNITS.wrapping_add(segment_units(a, c));
            if segment_clear(grid, a, c) {
                // Drop b: pts[i + 1..n] moves one to the left (by hand: no bounds panic).
                for j in i..n.wrapping_sub(1) {
                    if let Some(&q) = pts.get(j.wrapping_add(1)) {
                        if let Some(slot) = pts.get_mut(j) {
                            *slot = q;
                        }
                    }
                }
                spent =
                    spent.saturating_add(u32::try_from(n.wrapping_sub(i) >> 4).unwrap_or(u32::MAX));
                n = n.wrapping_sub(1);
                self.changed = true;
                left = left.saturating_sub(spent);
                continue;
            }
            let mut clear = |p: Point, q: Point| {
                spent = spent.saturating_add(segment_units(p, q));
                segment_clear(grid, p, q)
            };
            if let Some(q) = best_shift(&mut clear, grid, a, b, c) {
                if let Some(slot) = pts.get_mut(i) {
                    *slot = q;
                }
                self.changed = true;
            }
            left = left.saturating_sub(spent);
            i = i.wrapping_add(1);
        }
        (self.n, self.i) = (n, i);
        *budget = left;
        Some((n, self.changed))
    }
}

/// The neighbour `q` of `b` (in direction order) that makes `a - q - c` the shortest, if it is at
/// least [`MIN_GAIN`] shorter than `a - b - c` and both its segments are clear (`clear`: the
/// segment test).
fn best_shift(
    clear: &mut impl FnMut(Point, Point) -> bool,
    grid: &Grid<'_>,
    a: Point,
    b: Point,
    c: Point,
) -> Option<Point> {
    let now = distance(a, b) + distance(b, c);
    let mut best: Option<(f32, Point)> = None;
    for (dx, dy) in DX.iter().zip(DY.iter()) {
        // u16 coordinates and offsets of -1..=1: no i32 wraps.
        let (x, y) = (
            i32::from(b.x).wrapping_add(*dx),
            i32::from(b.y).wrapping_add(*dy),
        );
        let (Ok(x), Ok(y)) = (u16::try_from(x), u16::try_from(y)) else {
            continue;
        };
        let q = Point::new(x, y);
        if q == a || q == c || !grid.contains(q) || !grid.is_free(q) {
            continue;
        }
        let len = distance(a, q) + distance(q, c);
        let beats = best.map_or(now - MIN_GAIN, |(l, _)| l);
        if len < beats && clear(a, q) && clear(q, c) {
            best = Some((len, q));
        }
    }
    best.map(|(_, q)| q)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polyline_length;
    use crate::testutil::bits;
    use alloc::vec::Vec;

    fn run(rows: &[&str], path: &[(u16, u16)]) -> Vec<Point> {
        let (b, w, h) = bits(rows);
        let g = Grid::new(w, h, &b).unwrap();
        let mut p: Vec<Point> = path.iter().map(|&(x, y)| Point::new(x, y)).collect();
        let n = pull(&g, &mut p, path.len());
        p.truncate(n);
        for s in p.windows(2) {
            assert!(segment_clear(&g, s[0], s[1]), "{s:?}");
        }
        p
    }

    #[test]
    fn a_corner_one_cell_off_is_pulled_onto_the_obstacle() {
        // One obstacle at (3, 2). The path bends at (2, 4), one cell further from it than
        // needed; taut, it bends at (2, 3), the centre diagonally beside the obstacle's corner
        // (by hand: 0,0 -> 2,3 -> 6,6 is sqrt 13 + 5 = 8.6056, 0,0 -> 2,4 -> 6,6 is
        // sqrt 20 + sqrt 20 = 8.9443).
        let rows = [
            ".......", //
            ".......", //
            "...#...", //
            ".......", //
            ".......", //
            ".......", //
            ".......", //
        ];
        let p = run(&rows, &[(0, 0), (2, 4), (6, 6)]);
        // By hand: the diagonal from (0,0) to (6,6) touches the obstacle's corner, so the path
        // bends once, at a centre diagonally beside that corner: (2,3) or (3,4), both
        // sqrt 13 + 5 long (the input bend at (2,4) is sqrt 20 + sqrt 20 = 8.944).
        assert_eq!(p.len(), 3, "{p:?}");
        assert!(
            p[1] == Point::new(2, 3) || p[1] == Point::new(3, 4),
            "{p:?}"
        );
        let want = libm::sqrtf(13.0) + 5.0;
        assert!((polyline_length(&p) - want).abs() < 1e-5, "{p:?}");
    }

    #[test]
    fn a_needless_waypoint_is_dropped_and_start_and_goal_stay() {
        let rows = ["......", "......", "......"];
        let p = run(&rows, &[(0, 0), (2, 2), (5, 0)]);
        assert_eq!(p, [Point::new(0, 0), Point::new(5, 0)]);
    }

    #[test]
    fn a_taut_path_is_left_alone() {
        // Around a wall: the bend at (2, 3) beside the wall's end is already optimal.
        let rows = [
            "......", //
            "..#...", //
            "..#...", //
            "......", //
        ];
        let path = [(0, 0), (1, 3), (3, 3), (5, 0)];
        let before: Vec<Point> = path.iter().map(|&(x, y)| Point::new(x, y)).collect();
        let p = run(&rows, &path);
        assert!(polyline_length(&p) <= polyline_length(&before) + 1e-6);
        let again = run(&rows, &p.iter().map(|q| (q.x, q.y)).collect::<Vec<_>>());
        assert_eq!(again, p, "pulling twice changes nothing");
    }
}
