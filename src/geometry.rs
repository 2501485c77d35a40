//! Path geometry: lengths, and the segment rule every path is checked against.
//!
//! **The segment rule.** Cell `(x, y)` is the closed square `[x, x+1] x [y, y+1]`; a waypoint
//! stands for its cell's centre `(x + 0.5, y + 0.5)`. A straight segment between two waypoints is
//! valid iff it touches no blocked cell's closed square. Touching counts: a segment that passes
//! exactly through the corner shared by two diagonally adjacent obstacles is invalid, and so is a
//! segment that grazes an obstacle's edge. For a single step this is exactly the
//! no-corner-cutting rule of [`crate::grid`], so every raw path is also valid segment by segment.
//!
//! [`segment_clear`] decides the rule exactly in integer arithmetic (doubled coordinates, so
//! centres are odd integers), with no floating point and no tolerance.

use crate::grid::{Grid, Point};

/// `sqrt(2)` as f32; the length of a diagonal step.
pub const SQRT_2: f32 = core::f32::consts::SQRT_2;

/// Euclidean distance between two cell centres.
#[inline]
pub fn distance(a: Point, b: Point) -> f32 {
    let dx = f32::from(a.x) - f32::from(b.x);
    let dy = f32::from(a.y) - f32::from(b.y);
    libm::sqrtf(dx * dx + dy * dy)
}

/// Length of a path of `straight` orthogonal and `diagonal` diagonal steps.
#[inline]
pub fn steps_length(straight: u32, diagonal: u32) -> f32 {
    straight as f32 + diagonal as f32 * SQRT_2
}

/// Floor division for a positive divisor.
#[inline]
fn floor_div(n: i64, d: i64) -> i64 {
    // 32-bit division when the operands fit (every map up to ~16k cells a side): the Cortex-M4
    // divides 32-bit integers in hardware but 64-bit ones in a library routine.
    // `checked_`: callers always pass d > 0, but this way no panic path is compiled in.
    match (i32::try_from(n), i32::try_from(d)) {
        (Ok(n), Ok(d)) => i64::from(n.checked_div_euclid(d).unwrap_or(0)),
        _ => n.checked_div_euclid(d).unwrap_or(0),
    }
}

/// Ceiling division for a positive divisor.
#[inline]
fn ceil_div(n: i64, d: i64) -> i64 {
    // Callers pass |n| < 2^36 (see `segment_clear`), far from `i64::MIN`: the negations are exact.
    floor_div(n.wrapping_neg(), d).wrapping_neg()
}

/// True iff the straight segment between the centres of `a` and `b` touches no blocked (or
/// off-map) cell's closed square. See the module docs for the rule.
///
/// Cost: one test per touched cell, about `|dx| + |dy|` cells.
pub fn segment_clear(grid: &Grid<'_>, a: Point, b: Point) -> bool {
    // Order by x so the walk goes left to right.
    let (p, q) = if a.x <= b.x { (a, b) } else { (b, a) };
    // Doubled coordinates: the centre of cell x is 2x + 1, the square of cell c spans [2c, 2c + 2].
    // Overflow: doubled coordinates and `dx`, `dy` are below 2^17 in size, so every `y * dx` value
    // below is below 2^35 in size: none of the `wrapping_` operations here can wrap in i64.
    let centre = |c: u16| i64::from(c).wrapping_mul(2).wrapping_add(1);
    let (x0, y0) = (centre(p.x), centre(p.y));
    let (x1, y1) = (centre(q.x), centre(q.y));
    let dx = x1.wrapping_sub(x0); // >= 0
    let dy = y1.wrapping_sub(y0);
    if dx == 0 {
        // Vertical: the line x = 2x0+1 lies strictly inside one column.
        let (lo, hi) = if p.y <= q.y { (p.y, q.y) } else { (q.y, p.y) };
        let x = i32::from(p.x);
        return (lo..=hi).all(|y| !grid.blocked_xy(x, i32::from(y)));
    }
    for cx in i64::from(p.x)..=i64::from(q.x) {
        let xa = x0.max(cx.wrapping_mul(2));
        let xb = x1.min(cx.wrapping_mul(2).wrapping_add(2));
        // y * dx at both ends of this column's piece of the segment (exact rationals).
        let y0dx = y0.wrapping_mul(dx);
        let ya = y0dx.wrapping_add(xa.wrapping_sub(x0).wrapping_mul(dy));
        let yb = y0dx.wrapping_add(xb.wrapping_sub(x0).wrapping_mul(dy));
        let (ylo, yhi) = if ya <= yb { (ya, yb) } else { (yb, ya) };
        // Cell cy is touched iff 2cy <= yhi/dx and 2cy + 2 >= ylo/dx.
        let dx2 = dx.wrapping_mul(2);
        let cy_lo = ceil_div(ylo.wrapping_sub(dx2), dx2);
        let cy_hi = floor_div(yhi, dx2);
        for cy in cy_lo..=cy_hi {
            // Coordinates stay within the map's u16 range, so the narrowing is lossless.
            if grid.blocked_xy(cx as i32, cy as i32) {
                return false;
            }
        }
    }
    true
}

/// Total Euclidean length of a polyline through cell centres.
pub fn polyline_length(points: &[Point]) -> f32 {
    points
        .windows(2)
        .map(|w| match w {
            [a, b] => distance(*a, *b),
            _ => 0.0,
        })
        .sum()
}

/// The bend at `b` of the polyline `a, b, c`: the cross and dot products of `b - a` and `c - b`.
/// Cross 0 and dot > 0: straight on; cross 0 and dot 0: a repeated point.
pub fn bend(a: Point, b: Point, c: Point) -> (i64, i64) {
    // Differences of u16 values and their products (< 2^33) cannot wrap in i64.
    let (ux, uy) = (
        i64::from(b.x).wrapping_sub(i64::from(a.x)),
        i64::from(b.y).wrapping_sub(i64::from(a.y)),
    );
    let (vx, vy) = (
        i64::from(c.x).wrapping_sub(i64::from(b.x)),
        i64::from(c.y).wrapping_sub(i64::from(b.y)),
    );
    (
        ux.wrapping_mul(vy).wrapping_sub(uy.wrapping_mul(vx)),
        ux.wrapping_mul(vx).wrapping_add(uy.wrapping_mul(vy)),
    )
}

/// Number of turns (direction changes) along a polyline: points where the incoming and outgoing
/// segments are not collinear-and-forward.
pub fn turns(points: &[Point]) -> u32 {
    let mut n = 0u32;
    for w in points.windows(3) {
        if let [a, b, c] = w {
            let (cross, dot) = bend(*a, *b, *c);
            if cross != 0 || dot <= 0 {
                n = n.saturating_add(1);
            }
        }
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(rows: &[&str]) -> (Vec<u8>, u16, u16) {
        crate::testutil::bits(rows)
    }

    #[test]
    fn diagonal_step_needs_both_sides() {
        let (b, w, h) = grid(&["..", "#."]);
        let g = Grid::new(w, h, &b).unwrap();
        assert!(!segment_clear(&g, Point::new(0, 0), Point::new(1, 1)));
        assert!(segment_clear(&g, Point::new(0, 0), Point::new(1, 0)));
    }

    #[test]
    fn corner_touch_is_blocked() {
        // Segment (0,0)->(2,2) passes through the corner points (1,1)-(2,2) of the middle cell's
        // neighbours; with the centre cell blocked it is clearly blocked.
        let (b, w, h) = grid(&["...", ".#.", "..."]);
        let g = Grid::new(w, h, &b).unwrap();
        assert!(!segment_clear(&g, Point::new(0, 0), Point::new(2, 2)));
        // A knight-like segment (0,0)->(2,1) passes the point (1.5, 1.0): touches cell (1,1)'s top edge.
        assert!(!segment_clear(&g, Point::new(0, 0), Point::new(2, 1)));
        assert!(segment_clear(&g, Point::new(0, 0), Point::new(2, 0)));
    }

    #[test]
    fn grazing_a_corner_point_is_blocked() {
        // Segment from (0,0) to (2,4): centres (0.5,0.5) -> (2.5,4.5); it passes x=1.5 at y=2.5,
        // and the point (1, 1.5)... check a case that touches exactly a corner:
        // (0,0)->(2,2) passes through (1,1) and (2,2) corners; block cell (1,0): square [1,2]x[0,1]
        // touches the point (1,1), so the segment is invalid.
        let (b, w, h) = grid(&[".#.", "...", "..."]);
        let g = Grid::new(w, h, &b).unwrap();
        assert!(!segment_clear(&g, Point::new(0, 0), Point::new(2, 2)));
        let (b, w, h) = grid(&["...", "...", "#.."]);
        let g = Grid::new(w, h, &b).unwrap();
        // Cell (0,2) is [0,1]x[2,3]; the segment (0.5,0.5)->(2.5,2.5) meets it only if it reaches
        // x<=1 while y>=2: it does not.
        assert!(segment_clear(&g, Point::new(0, 0), Point::new(2, 2)));
    }

    #[test]
    fn vertical_and_reverse() {
        let (b, w, h) = grid(&[".", "#", "."]);
        let g = Grid::new(w, h, &b).unwrap();
        assert!(!segment_clear(&g, Point::new(0, 2), Point::new(0, 0)));
        let (b, w, h) = grid(&["#..", "...", "..#"]);
        let g = Grid::new(w, h, &b).unwrap();
        assert!(segment_clear(&g, Point::new(2, 0), Point::new(0, 2)));
        assert!(segment_clear(&g, Point::new(0, 2), Point::new(2, 0)));
    }

    #[test]
    fn turns_counts_corners() {
        let p = [
            Point::new(0, 0),
            Point::new(1, 0),
            Point::new(2, 0),
            Point::new(2, 1),
            Point::new(3, 2),
        ];
        assert_eq!(turns(&p), 2);
        assert_eq!(turns(&p[..3]), 0);
    }
}
