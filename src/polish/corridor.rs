//! The last step of OHACA's default smoothing on small maps: the exact shortest path through the
//! cell centres of a corridor around the smoothed path.
//!
//! The shortest-subsequence DP ([`crate::polish::smoothing`]) keeps its waypoints on the raw path's cells,
//! and the taut pull ([`crate::polish::taut`]) moves them one cell at a time while each move shortens the
//! path; both stop in local optima. The exact any-angle optimum through cell centres (the segment
//! rule of [`crate::geometry::segment_clear`]) usually runs within a few cells of the smoothed
//! path, in the same corridor between the same obstacles. [`shortest`] finds the exact optimum over
//! every free cell centre within [`RADIUS`] cells (Chebyshev) of the smoothed path's segments: an
//! A* over their visibility graph (Euclidean heuristic, edges tested lazily and only when they
//! would improve), bounded from the start by the smoothed path's own length.
//!
//! Measured on the shared small maps (5 seeds, `quality` example), the mean smoothed length over
//! the exact any-angle optimum went from 1.0058 to about 1.002 (`docs/ALGORITHM.md`, "Smoothing");
//! radius 2 leaves 1.0027, 3 is the first that meets the 1.003 target on both random map sets.
//! What it cannot fix is a corridor on the other side of an obstacle: the any-angle optimum may go
//! around an obstacle the 8-connected optimum passes on the other side.
//!
//! Cost: for `V` corridor cells (at most the map's cells) and `E` expanded ones, each
//! expansion scans the open list and the live corridor cells. Which of those its cell sees is
//! not tested one candidate at a time (on complex-26, 10,058 candidates past the length
//! bounds, 9,706 of them hidden): one sweep from the expanded cell
//! ([`crate::polish::sweep`], shadowcasting over the corridor's bounding box, exactly
//! [`segment_clear`]'s rule) sets the bits of the corridor cells it sees in a bitmap of
//! live-list positions ([`Entry::pos`]), leaving out the rows and sectors where no cell can
//! improve (the A*'s own length test, with an eighth of a cell of slack: `reaches`,
//! [`crate::polish::sweep::Near`]). The scan walks the set bits in the list's order (the same
//! ties as a scan of every live cell) and takes the length (one `vsqrt.f32` on the device) of
//! those cells only. The bitmap, the box's free cells as words a line (for boxes of sides up
//! to [`crate::polish::sweep::LINE_SIDE`]: each sweep reads an octant's row as one word,
//! [`crate::polish::sweep::Lines`]) and the sweep's pending intervals live in the list's tail;
//! without room (or when the sweep's stack runs out), the expansion tests every live cell's
//! improving edge by one [`segment_clear`] each: the same relaxations.
//! It runs on maps of at most [`crate::colony::pheromone::BLOCKS`] cells, whose per-cell
//! pheromone increments lend the per-cell scratch (`g`, parent, flags, position).
//!
//! Guarantees: the result is never longer than the input (the input's vertices lie in the
//! corridor, and the input is replaced only by a strictly shorter path), every segment obeys the
//! segment rule, start and goal stay; deterministic (fixed candidate order, first minimum wins,
//! `f32` lengths from [`crate::geometry::distance`]); no allocation, no panic: a buffer too
//! short leaves the input as it was, and [`try_shortest`] says which one ([`Short`]).
//!
//! The per-cell scratch is typed: the lent buffer (the pheromone increments, `[f32; 4]` a cell)
//! is borrowed as `&mut [`[`Entry`]`]` by `bytemuck`'s checked cast (same size and alignment, so
//! it cannot fail; if it did, [`Short::Cells`]); the parent and the flags are integer fields,
//! not bits read out of an `f32`.

use core::fmt;

use crate::geometry::{distance, drop_collinear, polyline_length, segment_clear};
use crate::map::grid::{Grid, Point};

/// Corridor half-width in cells (Chebyshev distance from the smoothed path's segments).
pub const RADIUS: u16 = 3;

/// The least shortening that replaces the input, in cells (far above `f32` rounding).
const MIN_GAIN: f32 = 1e-4;

/// Flag bits in a cell's scratch entry.
const CANDIDATE: u16 = 1;
const CLOSED: u16 = 2;

/// A map cell's scratch entry, laid over one `[f32; 4]` of the lent buffer (16 bytes, 4-aligned).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Entry {
    /// The shortest length from the start found so far (`INFINITY`: not reached).
    pub g: f32,
    /// The map index of the cell it was reached from (meaningful once `g` is finite).
    pub parent: u32,
    /// The Euclidean distance to the goal (the A*'s heuristic; set for the corridor's cells).
    pub h: f32,
    /// `CANDIDATE` (in the corridor) and `CLOSED` (expanded) bits.
    pub flags: u16,
    /// Its position in the live list (set when listed, and at each compaction): its bit in
    /// the bitmap of the cells an expansion sees.
    pub pos: u16,
}

impl Entry {
    /// Not reached, not in the corridor.
    const EMPTY: Self = Self {
        g: f32::INFINITY,
        parent: 0,
        h: 0.0,
        flags: 0,
        pos: 0,
    };

    fn closed(&self) -> bool {
        self.flags & CLOSED != 0
    }
}

// The cast from the lent `[f32; 4]` cells cannot fail: same size, same alignment.
const _: () = assert!(
    core::mem::size_of::<Entry>() == core::mem::size_of::<[f32; 4]>()
        && core::mem::align_of::<Entry>() == core::mem::align_of::<[f32; 4]>()
);

/// Why [`try_shortest`] left the path as it was: a buffer too short for this map or path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Short {
    /// The cell scratch has fewer entries than the map has cells.
    Cells,
    /// The list cannot hold the corridor's cells and its open ones.
    List,
    /// The path buffer cannot hold the new path (or its parent chain is broken).
    Points,
}

impl fmt::Display for Short {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Cells => "corridor: cell scratch shorter than the map",
            Self::List => "corridor: list shorter than the corridor",
            Self::Points => "corridor: path buffer shorter than the new path",
        })
    }
}

/// Replace `pts[..n]` (a valid path from its first to its last point) by the shortest path through
/// the free cell centres within `radius` of its segments, if that is shorter; returns the new
/// point count. `pts` beyond `n` is room for a new path of more points than the input (the
/// planner's path buffer has the raw path's length); `cell` is scratch of one entry per map cell,
/// `list` scratch for the corridor's cells and its open ones (at most twice the corridor's cells;
/// beyond that, one bit a corridor cell and room for the sweep's pending intervals, 3 words
/// each: the same path faster).
/// Any of them too short leaves the path unchanged ([`try_shortest`] says which).
pub fn shortest(
    grid: &Grid<'_>,
    pts: &mut [Point],
    n: usize,
    radius: u16,
    cell: &mut [[f32; 4]],
    list: &mut [u32],
) -> usize {
    try_shortest(grid, pts, n, radius, cell, list).unwrap_or(n.min(pts.len()))
}

/// [`shortest`], saying which buffer was too short when it leaves the path as it was. `Ok` with
/// the input's count when the input is already the shortest (or no shorter path was found).
pub fn try_shortest(
    grid: &Grid<'_>,
    pts: &mut [Point],
    n: usize,
    radius: u16,
    cell: &mut [[f32; 4]],
    list: &mut [u32],
) -> Result<usize, Short> {
    let n = n.min(pts.len());
    let cells = grid.cells();
    let cell: &mut [Entry] = bytemuck::try_cast_slice_mut(cell).map_err(|_| Short::Cells)?;
    let cell = cell.get_mut(..cells).ok_or(Short::Cells)?;
    let path = pts.get(..n).unwrap_or_default();
    let (Some(&start), Some(&goal)) = (path.first(), path.last()) else {
        return Ok(n);
    };
    if n < 3 {
        return Ok(n); // one segment: already the shortest
    }
    let bound = polyline_length(path);
    cell.fill(Entry::EMPTY);
    let v = mark(grid, path, radius, cell, list).ok_or(Short::List)?;
    // `list[..v]`: the corridor's cells; the rest holds the open ones (those with a finite `g`
    // that are not closed yet), so picking the next one scans only them.
    let (list, open) = list.split_at_mut(v.min(list.len()));
    // The corridor's bounding box: the sweeps stay in it (every segment between two of its
    // cells touches only cells of the box).
    let (mut lo, mut hi) = (start, start);
    for &c in list.iter() {
        let q = unpack(c);
        if let Some(e) = cell.get_mut(grid.index(q)) {
            e.h = distance(q, goal);
        }
        lo = Point::new(lo.x.min(q.x), lo.y.min(q.y));
        hi = Point::new(hi.x.max(q.x), hi.y.max(q.y));
    }
    let (s, t) = (grid.index(start), grid.index(goal));
    cell.get_mut(s).ok_or(Short::Cells)?.g = 0.0;
    let slot = open.first_mut().ok_or(Short::List)?;
    *slot = s as u32;
    let mut open_len = 1usize;
    // `list[..live]` holds the corridor's cells not closed yet, plus `closed` cells closed since
    // the last compaction, in their original order: the scan below skips closed cells, so
    // dropping them (in order) changes nothing but the scan's length. Compacted when a quarter
    // of the entries are closed: each cell is moved O(1) times on average.
    let mut live = list.len();
    let mut closed = 0usize;
    // In `open`'s tail beyond the `v` entries the open list can ever hold: a bit a live
    // position (the cells an expansion sees), then the sweep's pending intervals. No room for
    // the bits: every expansion tests its improving cells one by one.
    let (open, rest) = open.split_at_mut(v.min(open.len()));
    let words = v.div_ceil(32);
    let (seen, stack) = if rest.len() >= words && v <= 1 << 16 {
        rest.split_at_mut(words)
    } else {
        (&mut [][..], rest)
    };
    // The box's lines of free bits ([`crate::polish::sweep::Lines`]), from the stack's room
    // when the box is small enough and the stack keeps room for its intervals: each sweep then
    // reads an octant's row as one word. Without them, the same marks one cell at a time.
    let room = match crate::polish::sweep::line_words([lo, hi]) {
        Some(n) if stack.len() >= n.saturating_add(LINE_STACK) => n,
        _ => 0,
    };
    let (words, stack) = stack.split_at_mut(room.min(stack.len()));
    let lines = (room > 0)
        .then(|| crate::polish::sweep::Lines::fill(grid, [lo, hi], words))
        .flatten();
    let exact = grid.width() <= EXACT_SIDE && grid.height() <= EXACT_SIDE;
    // A*: expand the open cell of least g + h (the first one on ties) until the goal closes.
    while open_len > 0 {
        let shown = open.get(..open_len.min(open.len())).unwrap_or_default();
        let f_of = |c: u32| cell.get(c as usize).map_or(f32::INFINITY, |e| e.g + e.h);
        let Some((&first, others)) = shown.split_first() else {
            break;
        };
        // The first, then each later one strictly below the least so far.
        let (mut k, mut least) = (0usize, f_of(first));
        for (j, &c) in others.iter().enumerate() {
            let f = f_of(c);
            if f < least {
                (k, least) = (j.wrapping_add(1), f);
            }
        }
        // Take it out of the open list: the last open cell fills its place.
        open_len = open_len.wrapping_sub(1); // > 0: the loop's condition
        let i = open.get(k).copied().unwrap_or(0) as usize;
        if let Some(&last) = open.get(open_len) {
            if let Some(slot) = open.get_mut(k) {
                *slot = last;
            }
        }
        let Some(e) = cell.get_mut(i) else { break };
        e.flags |= CLOSED;
        let gi = e.g;
        if i == t {
            break;
        }
        closed = closed.wrapping_add(1); // <= live
        if closed.wrapping_mul(4) >= live {
            let mut k = 0usize;
            for r in 0..live {
                let Some(&c) = list.get(r) else { break };
                let Some(e) = cell.get_mut(grid.index(unpack(c))) else {
                    continue;
                };
                if !e.closed() {
                    e.pos = k as u16; // < v <= 2^16 when the bits are used
                    if let Some(slot) = list.get_mut(k) {
                        *slot = c;
                    }
                    k = k.wrapping_add(1); // <= r
                }
            }
            (live, closed) = (k, 0);
        }
        let p = grid.point(i);
        let limit = cell.get(t).map_or(bound, |e| e.g.min(bound));
        // Mark the cells `p` sees: those a relaxation may reach (below). Beyond `depth` rows
        // and outside the ellipse no cell can improve.
        let depth = reaches(gi, limit, p, goal);
        let near = crate::polish::sweep::Near {
            goal,
            reach: limit - gi + SLACK,
        };
        let nw = live.div_ceil(32);
        let marked = !seen.is_empty() && {
            seen.iter_mut().take(nw).for_each(|w| *w = 0);
            crate::polish::sweep::sweep(
                grid,
                p,
                [lo, hi],
                depth,
                Some(near),
                lines.as_ref(),
                stack,
                |k| {
                    if let Some(e) = cell.get(k) {
                        if e.flags & (CANDIDATE | CLOSED) == CANDIDATE {
                            let b = usize::from(e.pos);
                            if let Some(w) = seen.get_mut(b >> 5) {
                                *w |= 1 << (b & 31);
                            }
                        }
                    }
                },
            )
        };
        // The live cells in the list's order (the ties): the seen ones, or (not `marked`: no
        // room, or the sweep's stack was too short) all of them, each tested below.
        for wi in 0..nw {
            let mut bits = if marked {
                seen.get(wi).copied().unwrap_or(0)
            } else if wi.wrapping_add(1).wrapping_mul(32) <= live {
                u32::MAX
            } else {
                u32::MAX >> (32usize.wrapping_sub(live & 31) & 31)
            };
            while bits != 0 {
                let b = (wi << 5) | bits.trailing_zeros() as usize;
                bits &= bits.wrapping_sub(1);
                let Some(&c) = list.get(b) else { break };
                let q = unpack(c);
                let j = grid.index(q);
                let Some(e) = cell.get(j) else { continue };
                if e.closed() {
                    continue;
                }
                // On maps of sides up to `EXACT_SIDE` the length comes first: the square-root-free
                // lower bound is never above it ([`octile_low`]), so its test adds nothing, and
                // on the Cortex-M4F the square root is one instruction (`vsqrt.f32`), fewer than
                // the bound's. Beyond, the bound is tested first, as it always was.
                if !exact {
                    let low = gi + octile_low(p.x.abs_diff(q.x), p.y.abs_diff(q.y));
                    if low >= e.g || low + e.h >= limit {
                        continue;
                    }
                }
                let nd = gi + distance(p, q);
                if nd >= e.g || nd + e.h >= limit {
                    continue;
                }
                if !marked && !segment_clear(grid, p, q) {
                    continue;
                }
                let first = e.g == f32::INFINITY;
                if let Some(e) = cell.get_mut(j) {
                    e.g = nd;
                    e.parent = i as u32;
                }
                if first {
                    // A cell opens once (closed cells are never relaxed), so the open list
                    // never holds more than the corridor's cells; no room left: stop.
                    let slot = open.get_mut(open_len).ok_or(Short::List)?;
                    *slot = j as u32;
                    open_len = open_len.wrapping_add(1);
                }
            }
        }
    }
    let g = cell.get(t).ok_or(Short::Cells)?.g;
    let improves = g < bound - MIN_GAIN;
    if !improves {
        return Ok(n);
    }
    // Count the new path's points, then write them back to front.
    let mut m = 1usize;
    let mut c = t;
    while c != s {
        c = cell.get(c).ok_or(Short::Points)?.parent as usize;
        m = m.saturating_add(1);
        if m > pts.len() || m > cells {
            return Err(Short::Points); // longer than the buffer (or a broken chain)
        }
    }
    let mut c = t;
    for k in (0..m).rev() {
        if let Some(slot) = pts.get_mut(k) {
            *slot = grid.point(c);
        }
        c = cell.get(c).map_or(s, |e| e.parent as usize);
    }
    Ok(drop_collinear(pts, m))
}

/// The larger of the two square-root-free lower bounds of the length of a vector `(dx, dy)`:
/// Chebyshev's `max(dx, dy)` and the octile diagonal's `(dx + dy) / sqrt 2`. Monotone in `dx`
/// and in `dy` (every step rounds monotonically), so the bound of a box's nearest offset is
/// at most the bound of any cell in it.
///
/// Never above [`distance`] for offsets below [`EXACT_SIDE`]: there `dx^2 + dy^2` is exact in
/// `f32` and its square root correctly rounded, `max(dx, dy)` is exact and at most the true
/// length, and `(dx + dy)` times `FRAC_1_SQRT_2` (which is below `1 / sqrt 2` as an `f32`) is
/// below it exactly; rounding is monotone. So a cell whose length passes its tests passes the
/// bound's too, and the bound is only a filter (`the_bound_is_never_above_the_length`).
#[inline(always)]
fn octile_low(dx: u16, dy: u16) -> f32 {
    let cheb = f32::from(dx.max(dy));
    let diag = (f32::from(dx) + f32::from(dy)) * core::f32::consts::FRAC_1_SQRT_2;
    // (Not `f32::max`: on the Cortex-M4F that is a call to `fmaxf`.)
    if cheb > diag {
        cheb
    } else {
        diag
    }
}

/// Sides up to which `dx^2 + dy^2` is exact in `f32` (below 2^23), so that [`octile_low`] is
/// never above [`distance`].
const EXACT_SIDE: u16 = 2048;

/// The most rows from an expanded cell at `gi` within which a cell may still improve: the
/// largest `d` with `gi + d < limit` in `f32` (a cell at depth above it is at least that far,
/// [`distance`] being exact on integers and monotone, so `gi + distance >= limit` rejects it).
fn reach(gi: f32, limit: f32) -> u16 {
    let span = limit - gi;
    let mut d = if span >= 65_535.0 {
        u16::MAX
    } else if span > 0.0 {
        span as u16
    } else {
        0
    };
    while d > 0 && gi + f32::from(d) >= limit {
        d = d.wrapping_sub(1);
    }
    while d < u16::MAX && gi + f32::from(d.wrapping_add(1)) < limit {
        d = d.wrapping_add(1);
    }
    d
}

/// Words of the sweep's stack left for its pending intervals when the box's lines take their
/// room ([`crate::polish::sweep::FRAME`] words an interval): the lines are only a saving, a
/// stack too short for the intervals a fallback to one segment test a cell.
const LINE_STACK: usize = 96 * crate::polish::sweep::FRAME;

/// Slack, in cells, above the `f32` roundings of a candidate's `gi + distance + h` (each below
/// half a unit in the last place, a few thousandths for lengths below 2^16).
const SLACK: f32 = 0.125;

/// The depth bounds of [`crate::polish::sweep::sweep`] from `p` at `gi`, right, left, down and
/// up: [`reach`], and the goal's side. A cell `w` at depth `r` along an axis on which the goal
/// lies `ga` cells from `p` is at least `r` from `p` and `|r - ga|` from the goal, so its
/// `gi + distance + h` is at least `gi + r + |r - ga|`; rows where that reaches `limit` (plus
/// [`SLACK`] for the roundings) hold no cell that improves: the relaxation's length test would
/// reject each one. Behind `p` (`ga <= 0`) that halves the depth.
fn reaches(gi: f32, limit: f32, p: Point, goal: Point) -> [u16; 4] {
    let base = reach(gi, limit);
    let l = limit - gi + SLACK;
    let side = |ga: i32| {
        if l.is_nan() || l >= 65_535.0 {
            return base;
        }
        let ga = ga as f32;
        if ga >= l {
            return 0;
        }
        // The largest r with 2 r - ga < l (every r up to ga passes: ga < l).
        let t = (l + ga) * 0.5;
        if t <= 0.0 {
            return 0;
        }
        let mut r = t as u16;
        if f32::from(r) >= t {
            r = r.saturating_sub(1);
        }
        r.min(base)
    };
    let (dx, dy) = (
        i32::from(goal.x).wrapping_sub(i32::from(p.x)),
        i32::from(goal.y).wrapping_sub(i32::from(p.y)),
    );
    [
        side(dx),
        side(dx.wrapping_neg()),
        side(dy),
        side(dy.wrapping_neg()),
    ]
}

/// A cell as one word in the corridor's list (`x` high, `y` low): no division to get it back.
fn pack(p: Point) -> u32 {
    (u32::from(p.x) << 16) | u32::from(p.y)
}

/// [`pack`] undone.
fn unpack(c: u32) -> Point {
    Point::new((c >> 16) as u16, c as u16)
}

/// Mark every free cell within `radius` of `path`'s segments as a candidate and list it; returns
/// how many, or `None` if `list` is too short.
fn mark(
    grid: &Grid<'_>,
    path: &[Point],
    radius: u16,
    cell: &mut [Entry],
    list: &mut [u32],
) -> Option<usize> {
    let mut v = 0usize;
    // The last square visited (columns, then rows, inclusive): consecutive points of the
    // walk along the segments are at most a cell apart, so their squares mostly overlap.
    let mut seen: Option<(i64, i64, i64, i64)> = None;
    let r = i64::from(radius);
    let (w, h) = (i64::from(grid.width()), i64::from(grid.height()));
    // Coordinates and offsets are below 2^17 in magnitude, so no i64 operation below wraps.
    for pair in path.windows(2) {
        let (Some(&a), Some(&b)) = (pair.first(), pair.get(1)) else {
            continue;
        };
        let (ax, ay) = (i64::from(a.x), i64::from(a.y));
        let (dx, dy) = (
            i64::from(b.x).wrapping_sub(ax),
            i64::from(b.y).wrapping_sub(ay),
        );
        let steps = dx.abs().max(dy.abs()).max(1);
        // The cell nearest the segment at each of its `steps + 1` columns (or rows).
        let at = |d: i64, k: i64| {
            let num = d.wrapping_mul(2).wrapping_mul(k).wrapping_add(steps);
            num.checked_div_euclid(steps.wrapping_mul(2)).unwrap_or(0)
        };
        for k in 0..=steps {
            let x = ax.wrapping_add(at(dx, k));
            let y = ay.wrapping_add(at(dy, k));
            let square = (
                x.wrapping_sub(r).max(0),
                x.wrapping_add(r).min(w.wrapping_sub(1)),
                y.wrapping_sub(r).max(0),
                y.wrapping_add(r).min(h.wrapping_sub(1)),
            );
            let (x0, x1, y0, y1) = square;
            // The previous square's cells are all candidates already (its free ones were
            // listed): only the rest of this one is visited, in the same order (row by row,
            // left to right), so the cells are listed in the order of a visit of every cell.
            let (px0, px1, py0, py1) = seen.unwrap_or((1, 0, 1, 0));
            seen = Some(square);
            for cy in y0..=y1 {
                // The row's columns outside the previous square: left of it, then right of it
                // (all of them when the row is not the previous square's).
                let (left, right) = if cy >= py0 && cy <= py1 {
                    (x1.min(px0.wrapping_sub(1)), x0.max(px1.wrapping_add(1)))
                } else {
                    (x1, x1.wrapping_add(1))
                };
                for cx in (x0..=left).chain(right..=x1) {
                    // In range: 0 <= cx < w and 0 <= cy < h, both below 2^16.
                    let q = Point::new(cx as u16, cy as u16);
                    if !grid.is_free(q) {
                        continue;
                    }
                    let c = grid.index(q);
                    let Some(e) = cell.get_mut(c) else { continue };
                    if e.flags & CANDIDATE != 0 {
                        continue;
                    }
                    e.flags = CANDIDATE;
                    e.pos = v as u16; // < v <= 2^16 when the bits are used
                    *list.get_mut(v)? = pack(q);
                    v = v.wrapping_add(1); // < list.len(): the slot existed
                }
            }
        }
    }
    Some(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::bits;

    fn run(rows: &[&str], path: &[(u16, u16)], radius: u16) -> (Vec<Point>, f32, f32) {
        let (b, w, h) = bits(rows);
        let g = Grid::new(w, h, &b).unwrap();
        let mut pts: Vec<Point> = path.iter().map(|&(x, y)| Point::new(x, y)).collect();
        let before = polyline_length(&pts);
        let mut cell = vec![[0.0f32; 4]; g.cells()];
        let mut list = vec![0u32; 2 * g.cells()];
        let n = shortest(&g, &mut pts, path.len(), radius, &mut cell, &mut list);
        pts.truncate(n);
        for s in pts.windows(2) {
            assert!(
                segment_clear(&g, s[0], s[1]),
                "{:?} -> {:?} not clear",
                s[0],
                s[1]
            );
        }
        let after = polyline_length(&pts);
        (pts, before, after)
    }

    /// A wall (column 4, rows 2-4) between the start (0, 4) and the goal (8, 0). By hand, under
    /// the segment rule (blocked squares are closed, `[3.5, 4.5] x [1.5, 4.5]` here): the straight
    /// segment crosses the wall at y = 2; bending at (4, 1), just above the wall's end, clears it
    /// (at x = 3.5 the first leg is at y = 1.375, above the square's top edge 1.5), for
    /// 5 + sqrt(17) = 9.123; the other centres beside the end are longer ((3, 1): 9.342) or do
    /// not see the start past the wall ((5, 1), (5, 2), (3, 2) and below).
    #[test]
    fn a_detour_around_a_wall_end_becomes_the_taut_string() {
        let rows = [
            ".........", //
            ".........", //
            "....#....", //
            "....#....", //
            "....#....", //
        ];
        // A valid, bad path: along the bottom row's free cells, then up past the wall.
        let (b, w, h) = bits(&rows);
        let g = Grid::new(w, h, &b).unwrap();
        let input = [(0, 4), (3, 4), (3, 1), (5, 1), (8, 0)];
        for s in input.windows(2) {
            let (a, c) = (Point::new(s[0].0, s[0].1), Point::new(s[1].0, s[1].1));
            assert!(segment_clear(&g, a, c), "input {a:?} -> {c:?}");
        }
        let (pts, before, after) = run(&rows, &input, RADIUS);
        assert!(after < before);
        assert_eq!(
            pts,
            vec![Point::new(0, 4), Point::new(4, 1), Point::new(8, 0)],
            "{after} from {before}"
        );
        assert!((after - (5.0 + 17f32.sqrt())).abs() < 1e-5);
    }

    /// The rule that lets the length come before the square-root-free bound: on offsets below
    /// [`EXACT_SIDE`] the bound is never above the length, so testing it first or not at all
    /// rejects the same cells. Every offset is tried (a constant for `1 / sqrt 2` rounded up
    /// fails it on the diagonal).
    #[test]
    fn the_bound_is_never_above_the_length() {
        let o = Point::new(0, 0);
        for dx in 0..EXACT_SIDE {
            for dy in 0..=dx {
                let d = distance(o, Point::new(dx, dy));
                assert!(octile_low(dx, dy) <= d, "({dx}, {dy})");
                assert!(octile_low(dy, dx) <= d, "({dy}, {dx})");
            }
        }
    }

    /// The same path whatever room the list leaves beyond the corridor: the bitmap and the
    /// sweep's stack, only the stack short (the sweep gives up, every cell is tested), or no
    /// bitmap (every cell tested by `segment_clear`). A fallback that skipped a visible cell,
    /// or let a hidden one through, would change the path.
    /// The corridor's list is every free cell within the radius of the path's points, in the
    /// order a visit of each point's whole square finds them first (the order the A*'s ties
    /// follow): `mark`, which visits only the part of each square its predecessor's does not
    /// cover, lists the same cells in the same order, on random maps and paths.
    #[test]
    fn the_corridor_lists_its_cells_in_the_order_of_whole_squares() {
        let mut rng = crate::rng::Xoshiro128pp::from_u64(41);
        for round in 0..300 {
            let (w, h) = (
                1 + (rng.next_word() % 40) as u16,
                1 + (rng.next_word() % 40) as u16,
            );
            let b = crate::testutil::random_bits(&mut rng, w, h, (round % 5) as f32 * 0.1);
            let g = Grid::new(w, h, &b).unwrap();
            let n = 2 + (rng.next_word() % 6) as usize;
            let path: Vec<Point> = (0..n)
                .map(|_| {
                    Point::new(
                        (rng.next_word() % u32::from(w)) as u16,
                        (rng.next_word() % u32::from(h)) as u16,
                    )
                })
                .collect();
            let radius = (round % 4) as u16;
            // Every square whole, in order.
            let mut want: Vec<u32> = Vec::new();
            for pair in path.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                let (dx, dy) = (
                    i64::from(b.x) - i64::from(a.x),
                    i64::from(b.y) - i64::from(a.y),
                );
                let steps = dx.abs().max(dy.abs()).max(1);
                for k in 0..=steps {
                    let at = |d: i64| (2 * d * k + steps).div_euclid(2 * steps);
                    let (x, y) = (i64::from(a.x) + at(dx), i64::from(a.y) + at(dy));
                    let r = i64::from(radius);
                    for cy in (y - r).max(0)..=(y + r).min(i64::from(h) - 1) {
                        for cx in (x - r).max(0)..=(x + r).min(i64::from(w) - 1) {
                            let q = Point::new(cx as u16, cy as u16);
                            if g.is_free(q) && !want.contains(&pack(q)) {
                                want.push(pack(q));
                            }
                        }
                    }
                }
            }
            let mut cell = vec![Entry::EMPTY; g.cells()];
            let mut list = vec![0u32; g.cells()];
            let v = mark(&g, &path, radius, &mut cell, &mut list).unwrap();
            assert_eq!(&list[..v], &want[..], "round {round}");
            for (k, &c) in want.iter().enumerate() {
                let e = cell[g.index(unpack(c))];
                assert_eq!((e.flags, e.pos), (CANDIDATE, k as u16));
            }
        }
    }

    #[test]
    fn the_path_does_not_depend_on_the_room_for_the_sweep() {
        let rows = [
            "............", //
            "..#....#....", //
            "..#..#.#..#.", //
            ".....#....#.", //
            "..##.#..#...", //
            "........#.#.", //
        ];
        let (b, w, h) = bits(&rows);
        let g = Grid::new(w, h, &b).unwrap();
        // A valid, bad path up the left edge, along the top row, down the right edge.
        let input = [
            Point::new(0, 5),
            Point::new(0, 0),
            Point::new(11, 0),
            Point::new(11, 5),
        ];
        for s in input.windows(2) {
            assert!(segment_clear(&g, s[0], s[1]), "input {s:?}");
        }
        let mut results = Vec::new();
        for len in 0..=2 * g.cells() + 64 {
            let mut pts = input.to_vec();
            pts.resize(32, Point::new(0, 0)); // room for a path of more points
            let mut cell = vec![[0.0f32; 4]; g.cells()];
            let mut list = vec![0u32; len];
            if let Ok(n) = try_shortest(&g, &mut pts, input.len(), RADIUS, &mut cell, &mut list) {
                pts.truncate(n);
                for s in pts.windows(2) {
                    assert!(segment_clear(&g, s[0], s[1]), "list {len}: {s:?}");
                }
                results.push(pts);
            }
        }
        assert!(results.len() > 10, "{}", results.len());
        assert!(polyline_length(&results[0]) < polyline_length(&input) - 1.0);
        for r in &results {
            assert_eq!(r, &results[0]);
        }
    }

    #[test]
    fn a_straight_path_and_a_single_segment_stay_as_they_are() {
        let rows = [".....", ".....", "....."];
        let (pts, before, after) = run(&rows, &[(0, 0), (4, 2)], RADIUS);
        assert_eq!(pts, vec![Point::new(0, 0), Point::new(4, 2)]);
        assert_eq!(before, after);
        // Three points on a free map: the middle one goes.
        let (pts, _, _) = run(&rows, &[(0, 0), (2, 2), (4, 0)], RADIUS);
        assert_eq!(pts, vec![Point::new(0, 0), Point::new(4, 0)]);
    }

    #[test]
    fn too_little_scratch_leaves_the_path_unchanged() {
        let rows = [".....", ".....", "....."];
        let (b, w, h) = bits(&rows);
        let g = Grid::new(w, h, &b).unwrap();
        let input = [Point::new(0, 0), Point::new(2, 2), Point::new(4, 0)];
        for (cells, list, why) in [
            (g.cells() - 1, g.cells(), Short::Cells),
            (g.cells(), 3, Short::List),
        ] {
            let mut pts = input.to_vec();
            let mut cell = vec![[0.0f32; 4]; cells];
            let mut l = vec![0u32; list];
            assert_eq!(shortest(&g, &mut pts, 3, RADIUS, &mut cell, &mut l), 3);
            assert_eq!(pts, input);
            let r = try_shortest(&g, &mut pts, 3, RADIUS, &mut cell, &mut l);
            assert_eq!(r, Err(why), "{why}");
            assert_eq!(pts, input);
        }
    }
}
