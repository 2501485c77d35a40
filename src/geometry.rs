//! Path geometry: lengths, the segment rule every path is checked against, and dropping the
//! waypoints a polyline does not need ([`drop_collinear`], shared by the smoothing, the taut
//! path and the corridor).
//!
//! **The segment rule.** Cell `(x, y)` is the closed square `[x, x+1] x [y, y+1]`; a waypoint
//! stands for its cell's centre `(x + 0.5, y + 0.5)`. A straight segment between two waypoints is
//! valid iff it touches no blocked cell's closed square. Touching counts: a segment that passes
//! exactly through the corner shared by two diagonally adjacent obstacles is invalid, and so is a
//! segment that grazes an obstacle's edge. For a single step this is exactly the
//! no-corner-cutting rule of [`crate::map::grid`], so every raw path is also valid segment by segment.
//!
//! [`segment_clear`] decides the rule exactly in integer arithmetic (doubled coordinates, so
//! centres are odd integers), with no floating point and no tolerance.

use crate::map::grid::{Grid, Point};

/// `sqrt(2)` as f32; the length of a diagonal step.
pub const SQRT_2: f32 = core::f32::consts::SQRT_2;

/// Euclidean distance between two cell centres.
#[inline]
pub fn distance(a: Point, b: Point) -> f32 {
    let dx = f32::from(a.x) - f32::from(b.x);
    let dy = f32::from(a.y) - f32::from(b.y);
    sqrt(dx * dx + dy * dy)
}

/// The correctly rounded square root (IEEE 754's `squareRoot`, round to nearest even).
///
/// On a hard-float Arm target (the Cortex-M4F's FPv4-SP, the Cortex-M7F's FPv5) this is the FPU's
/// `vsqrt.f32`, one instruction of 14 cycles, where `libm::sqrtf` is a software loop of about 150
/// instructions; elsewhere (the host) it is `libm::sqrtf`. Both are correctly rounded, so they
/// return the same bits for every input, and host and device paths stay bit-identical (the unit
/// test `sqrt_is_correctly_rounded` checks the lengths the planner asks for and random inputs, and the
/// QEMU end-to-end tests compare device paths with the host's bit for bit).
#[inline]
pub fn sqrt(x: f32) -> f32 {
    #[cfg(all(target_arch = "arm", target_abi = "eabihf"))]
    {
        let r: u32;
        // SAFETY: the FPU is present and enabled: the `eabihf` ABI passes floats in its registers,
        // and cortex-m-rt enables it before `main` on hard-float targets. Rust does not expose
        // the FPU's register class to `asm!` on this target (no `vfp2` target feature), so the
        // value goes through a core register, and `s0` is saved on the stack (below the stack
        // pointer, not memory Rust code sees: `nomem` holds; `nostack` is not claimed) and
        // restored: the block touches no register or memory it does not declare or restore.
        // `vsqrt.f32` sets FPSCR's cumulative exception bits (inexact for most lengths), which
        // the reference counts among the flags, so `preserves_flags` is not claimed either.
        #[allow(unsafe_code)]
        unsafe {
            core::arch::asm!(
                "vpush {{s0}}",
                "vmov s0, {x}",
                "vsqrt.f32 s0, s0",
                "vmov {r}, s0",
                "vpop {{s0}}",
                x = in(reg) x.to_bits(),
                r = lateout(reg) r,
                options(pure, nomem)
            );
        }
        f32::from_bits(r)
    }
    #[cfg(not(all(target_arch = "arm", target_abi = "eabihf")))]
    {
        libm::sqrtf(x)
    }
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

/// True iff the straight segment between the centres of `a` and `b` touches no blocked (or
/// off-map) cell's closed square. See the module docs for the rule.
///
/// Cost: one pass over the rows the segment spans, with no division per row: in each row the
/// touched cells form one run, found by stepping the segment's crossings of the row boundaries
/// (exact integer arithmetic), and checked a byte of the map at a time
/// ([`Grid::run_free`]).
pub fn segment_clear(grid: &Grid<'_>, a: Point, b: Point) -> bool {
    // Both endpoint cells are touched; with both on the map, every touched cell lies in the
    // box they span (the segment runs between their centres), so on the map too.
    if !grid.contains(a) || !grid.contains(b) {
        return false;
    }
    // The cheapest exact rejection first: leaving a centre along its main axis (x when
    // |dx| >= |dy|, else y), the segment crosses that side of the endpoint's square at most half
    // a cell off the centre line, on the closed edge shared with the next cell on that axis:
    // that cell is touched. Likewise arriving at the other end. Two reads; in a maze most of the
    // smoothing's failing candidates fail here.
    let (dx, dy) = (
        i32::from(b.x).wrapping_sub(i32::from(a.x)),
        i32::from(b.y).wrapping_sub(i32::from(a.y)),
    );
    let (sx, sy) = if dx.abs() >= dy.abs() {
        (dx.signum(), 0)
    } else {
        (0, dy.signum())
    };
    if grid.blocked_xy(
        i32::from(a.x).wrapping_add(sx),
        i32::from(a.y).wrapping_add(sy),
    ) || grid.blocked_xy(
        i32::from(b.x).wrapping_sub(sx),
        i32::from(b.y).wrapping_sub(sy),
    ) {
        return false; // (a == b: that cell is `a` itself, blocked)
    }
    // A quick exact rejection next: the cell holding the point `k / 8` of the way from one centre
    // to the other is touched (closed squares). A long segment that crosses an obstacle (most of
    // the smoothing's tests that fail) usually has one of these points inside it: a few reads
    // instead of a walk over every row. Half-way first, then the quarters, then the eighths.
    let span = a.x.abs_diff(b.x).max(a.y.abs_diff(b.y));
    if span >= 8 {
        // With centres at c + 1/2: floor(((8 - k)(a + 1/2) + k (b + 1/2)) / 8), for k in 1..8;
        // every term is below 2^21, so nothing wraps.
        let at = |k: u32, ua: u16, ub: u16| {
            let wa = 8u32.wrapping_sub(k).wrapping_mul(2);
            wa.wrapping_mul(u32::from(ua))
                .wrapping_add(k.wrapping_mul(2).wrapping_mul(u32::from(ub)))
                .wrapping_add(8)
                >> 4
        };
        let samples: &[u32] = if span >= 24 {
            &[4, 2, 6, 1, 3, 5, 7]
        } else {
            &[4, 2, 6]
        };
        for &k in samples {
            // Between two cells on the map: on the map too.
            if grid.blocked_xy(at(k, a.x, b.x) as i32, at(k, a.y, b.y) as i32) {
                return false;
            }
        }
    }
    // Order by y so the walk goes top to bottom.
    let (p, q) = if a.y <= b.y { (a, b) } else { (b, a) };
    if p.y == q.y {
        // Horizontal: the line y = 2y0+1 lies strictly inside one row.
        let (lo, hi) = if p.x <= q.x { (p.x, q.x) } else { (q.x, p.x) };
        return grid.run_free(p.y, i32::from(lo), i32::from(hi));
    }
    // Doubled coordinates: the centre of cell c is 2c + 1, the square of cell c spans [2c, 2c + 2].
    // Along the segment, x * dy = x0 * dy + (y - y0) * dx =: v(y). Row r is touched between
    // y = max(y0, 2r) and y = min(y1, 2r + 2), and there the cells cx with
    // ceil(v_min / 2dy) - 1 <= cx <= floor(v_max / 2dy) (the square [2cx, 2cx + 2] meets the
    // x range [v_min / dy, v_max / dy]). At the centres the bounds are the cell itself.
    // Overflow: dx, dy are below 2^17 in size and x0 below 2^17, so v is below 2^35: i64 does not
    // wrap; `den`, `rem` and the step are below 2^19 and the cell bounds within -1..=65536: i32.
    let dy = i32::from(q.y).wrapping_sub(i32::from(p.y)).wrapping_mul(2); // > 0
    let dx = i32::from(q.x).wrapping_sub(i32::from(p.x)).wrapping_mul(2);
    let den = dy.wrapping_mul(2);
    // The crossing of the boundary y = 2 (p.y + 1): v = x0 dy + dx (one unit below the centre).
    let x0 = i64::from(p.x).wrapping_mul(2).wrapping_add(1);
    let v = x0.wrapping_mul(i64::from(dy)).wrapping_add(i64::from(dx));
    let (fl, rem) = floor_rem(v, i64::from(den));
    // From one boundary to the next v grows by 2 dx: whole cells and a remainder.
    let (step_fl, step_rem) = floor_rem(i64::from(dx).wrapping_mul(2), i64::from(den));
    let (mut fl, mut rem) = (fl as i32, rem as i32);
    let (step_fl, step_rem) = (step_fl as i32, step_rem as i32);
    // Floor and ceiling (of v / 2dy) where the current row starts: the centre of `p`.
    let (mut prev_fl, mut prev_ce) = (i32::from(p.x), i32::from(p.x).wrapping_add(1));
    let right = dx >= 0;
    let width = usize::from(grid.width());
    for row in p.y..=q.y {
        let (cur_fl, cur_ce) = if row == q.y {
            (i32::from(q.x), i32::from(q.x).wrapping_add(1))
        } else {
            (fl, fl.wrapping_add(i32::from(rem != 0)))
        };
        let (lo, hi) = if right {
            (prev_ce.wrapping_sub(1), cur_fl)
        } else {
            (cur_ce.wrapping_sub(1), prev_fl)
        };
        // lo <= hi within the box (see above): indices on the map.
        let base = usize::from(row).wrapping_mul(width);
        if !grid.bits_clear(
            base.wrapping_add(lo as usize),
            base.wrapping_add(hi as usize),
        ) {
            return false;
        }
        prev_fl = cur_fl;
        prev_ce = cur_ce;
        fl = fl.wrapping_add(step_fl);
        rem = rem.wrapping_add(step_rem);
        if rem >= den {
            rem = rem.wrapping_sub(den);
            fl = fl.wrapping_add(1);
        }
    }
    true
}

/// `(floor(n / d), n - d floor(n / d))` for `d > 0` (the remainder in `0..d`).
#[inline]
fn floor_rem(n: i64, d: i64) -> (i64, i64) {
    let f = floor_div(n, d);
    (f, n.wrapping_sub(f.wrapping_mul(d)))
}

/// Total Euclidean length of a polyline through cell centres. A single point (a plan from a cell
/// to itself) or none has length `+0.0` (`Iterator::sum` of no `f32` is `-0.0`, which a peer
/// would print as "-0"), and the sum runs left to right as before, so every other length is
/// unchanged bit for bit.
pub fn polyline_length(points: &[Point]) -> f32 {
    points
        .windows(2)
        .map(|w| match w {
            [a, b] => distance(*a, *b),
            _ => 0.0,
        })
        .fold(0.0, |acc, d| acc + d)
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

/// True if `b` lies on the straight line from `a` to `c`, between them.
fn collinear_between(a: Point, b: Point, c: Point) -> bool {
    let (cross, dot) = bend(a, b, c);
    cross == 0 && dot >= 0
}

/// Remove interior points of `pts[..n]` that lie straight between their neighbours; returns the
/// new length. (A point on a straight segment between two kept points adds nothing, and the
/// segment it belongs to was already checked clear, so the merged segment is clear too.)
pub fn drop_collinear(pts: &mut [Point], n: usize) -> usize {
    drop_middles(pts, n, collinear_between)
}

/// Keep `pts[0]` and the last point of `pts[..n]`; drop each interior point `b` for which
/// `needless(a, b, c)` holds, with `a` the last kept point and `c` the next one. In place; returns
/// the new length. The one filter behind [`drop_collinear`] and the smoothing's greedy merge.
pub(crate) fn drop_middles(
    pts: &mut [Point],
    n: usize,
    needless: impl Fn(Point, Point, Point) -> bool,
) -> usize {
    let n = n.min(pts.len());
    if n < 3 {
        return n;
    }
    // Bounds: 3 <= n <= pts.len() and 1 <= k <= i < n, so no `wrapping_` here wraps.
    let last_i = n.wrapping_sub(1);
    let mut k = 1usize; // pts[..k] is the output so far; pts[k-1] is the last kept point.
    for i in 1..last_i {
        let (Some(&a), Some(&b), Some(&c)) = (
            pts.get(k.wrapping_sub(1)),
            pts.get(i),
            pts.get(i.wrapping_add(1)),
        ) else {
            break;
        };
        if !needless(a, b, c) {
            if let Some(slot) = pts.get_mut(k) {
                *slot = b;
            }
            k = k.wrapping_add(1);
        }
    }
    let last = pts.get(last_i).copied();
    if let (Some(last), Some(slot)) = (last, pts.get_mut(k)) {
        *slot = last;
    }
    k.wrapping_add(1)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `sqrt` must be correctly rounded (what `vsqrt.f32` is on the device), so host and device
    /// lengths agree bit for bit: checked against the f64 root rounded once, for every squared
    /// distance between two cells of a map up to 2048 cells a side (sums of two squares, the only
    /// arguments `distance` makes) and for random bit patterns.
    #[test]
    fn sqrt_is_correctly_rounded() {
        let exact = |x: f32| f64::from(x).sqrt() as f32;
        for dx in 0u32..2048 {
            for dy in (0..=dx).step_by(7) {
                let x = (dx * dx + dy * dy) as f32;
                assert_eq!(sqrt(x).to_bits(), exact(x).to_bits(), "sqrt({x})");
            }
        }
        let mut s = 0x9E37_79B9u32;
        for _ in 0..200_000 {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            let x = f32::from_bits(s & 0x7FFF_FFFF);
            if x.is_finite() {
                assert_eq!(sqrt(x).to_bits(), exact(x).to_bits(), "sqrt({x:e})");
            }
        }
    }

    #[test]
    fn a_single_point_has_length_plus_zero() {
        let p = Point::new(3, 4);
        assert_eq!(polyline_length(&[p]).to_bits(), 0.0f32.to_bits());
        assert_eq!(polyline_length(&[]).to_bits(), 0.0f32.to_bits());
        let three = [Point::new(0, 0), Point::new(3, 4), Point::new(3, 5)];
        assert_eq!(polyline_length(&three), 6.0);
    }

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

    /// The column-by-column implementation this module had before (one division per column),
    /// kept as a second reference.
    fn segment_clear_columns(grid: &Grid<'_>, a: Point, b: Point) -> bool {
        let (p, q) = if a.x <= b.x { (a, b) } else { (b, a) };
        let centre = |c: u16| i64::from(c) * 2 + 1;
        let (x0, y0) = (centre(p.x), centre(p.y));
        let (x1, y1) = (centre(q.x), centre(q.y));
        let dx = x1 - x0;
        let dy = y1 - y0;
        if dx == 0 {
            let (lo, hi) = if p.y <= q.y { (p.y, q.y) } else { (q.y, p.y) };
            return (lo..=hi).all(|y| !grid.blocked_xy(i32::from(p.x), i32::from(y)));
        }
        for cx in i64::from(p.x)..=i64::from(q.x) {
            let xa = x0.max(cx * 2);
            let xb = x1.min(cx * 2 + 2);
            let ya = y0 * dx + (xa - x0) * dy;
            let yb = y0 * dx + (xb - x0) * dy;
            let (ylo, yhi) = if ya <= yb { (ya, yb) } else { (yb, ya) };
            let cy_lo = -((2 * dx - ylo).div_euclid(2 * dx));
            let cy_hi = yhi.div_euclid(2 * dx);
            for cy in cy_lo..=cy_hi {
                if grid.blocked_xy(cx as i32, cy as i32) {
                    return false;
                }
            }
        }
        true
    }

    #[test]
    fn rows_agree_with_columns() {
        // Every pair of cells of random maps (a few shapes, about 20 % blocked), both orders.
        let mut x = 0x9E37_79B9u32;
        for (w, h) in [(9u16, 7u16), (13, 13), (5, 17), (24, 3)] {
            for _ in 0..6 {
                let cells = usize::from(w) * usize::from(h);
                let mut b = vec![0u8; cells.div_ceil(8)];
                for i in 0..cells {
                    x ^= x << 13;
                    x ^= x >> 17;
                    x ^= x << 5;
                    if x % 5 == 0 {
                        b[i / 8] |= 1 << (i % 8);
                    }
                }
                let g = Grid::new(w, h, &b).unwrap();
                for i in 0..cells {
                    for j in 0..cells {
                        let (p, q) = (g.point(i), g.point(j));
                        assert_eq!(
                            segment_clear(&g, p, q),
                            segment_clear_columns(&g, p, q),
                            "{w}x{h} {p:?} -> {q:?}"
                        );
                    }
                }
            }
        }
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
