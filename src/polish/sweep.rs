//! The cells a cell sees, found by one sweep (shadowcasting) instead of one segment test each:
//! exactly [`crate::geometry::segment_clear`]'s rule, for the corridor search
//! ([`crate::polish::corridor`]).
//!
//! [`sweep`] reports (by map index, through a callback) every free cell `v` of a box, within
//! depth bounds (and, with [`Near`], within an ellipse around `u` and a goal) from a free cell
//! `u` of the box, whose segment from `u`'s centre touches no blocked or off-map cell's closed
//! square; and never a cell whose segment does. Each cell may be reported more than once (the
//! octants share their borders).
//!
//! **Why it is exact.** Put `u` at the origin and take one octant: depth `r = |dx| >= |dy| = c`
//! (the other seven by reflection), slope `s = c / r` in `[0, 1]`, cell centres at integer points
//! and cell squares of side 1 around them. A square at depth `r' >= 1`, column `c' >= 0`, meets
//! the ray of slope `s` (from the origin, `x > 0`) iff some corner lies on or below the ray and
//! some on or above it, i.e. iff `s` is in the closed interval of its corner slopes
//! `[(2c' - 1) / (2r' + 1), (2c' + 1) / (2r' - 1)]` (for `c' = 0` the lower end is below 0;
//! columns `c' < 0` lie wholly below slope 0 and columns `c' > r' + 1` wholly above 1). For a
//! target at depth `r >= r' + 1` the segment covers `x` in `[0, r]`, beyond the square's
//! `[r' - 1/2, r' + 1/2]`, so the segment touches the square iff the ray does. The squares of
//! the target's own row `r` (other than its own) and of `u`'s row 0 are touched only through a
//! corner on the exact diagonal `s = 1`: cells `(r, r - 1)` and `(0, 1)` (the segment covers
//! `y` in `[c - s / 2, c]` within row `r`'s band, and `[0, s / 2]` within row 0's). So a free
//! target `(r, c)` is visible iff `c / r` lies in no closed interval of a blocked square of rows
//! `1..r`, and, when `c = r`, `(0, 1)` and `(r, r - 1)` are free. The sweep keeps that set, a
//! union of intervals, row after row: the interval `[0, 1]`, cut by each blocked square's
//! closed interval (so every end it leaves is open, except 0 and 1 uncut). In row `r` a pending
//! interval covers the columns `cmin..=cmax` whose slopes lie in it; a blocked square meets it
//! only in columns `cmin - 1 ..= cmax + 1`: the square of column `cmin - 2` or less ends at
//! `(2 cmin - 3) / (2r - 1) <= (cmin - 1) / r` (as `cmin <= r + 1`), at or below the interval's
//! open lower end, and symmetrically above. All of it in
//! integers: an end is a fraction `n / d` of the forms above, compared by cross-multiplication
//! (depths below 2^13: every product below 2^27).
//!
//! Cells outside the box count as blocked: with both `u` and `v` in the box, every cell the
//! segment touches lies in the box they span (the segment runs between their centres), so a
//! cell outside it never decides a target inside it. So the box bounds the sweep, and the
//! off-map cells of `segment_clear` are outside every box on the map.
//!
//! **Cost.** Each pending interval scans the cells of its row it covers, plus one cell each
//! side (a blocked square's interval reaches half a column beyond its own slope); a hidden
//! region costs nothing. Given the box's [`Lines`] (sides up to [`LINE_SIDE`]), a row is one
//! word: its blocked squares are taken by their bits, its visible cells by theirs. The pending intervals live on a caller's stack of
//! [`FRAME`] words each (no allocation); when it is full, [`sweep`] says so (`false`) and the
//! caller must not trust the marks (the corridor then tests its cells one by one). No panic.

use crate::geometry::sqrt;
use crate::map::grid::{Grid, Point};

/// Words a pending interval takes on [`sweep`]'s stack.
pub const FRAME: usize = 3;

/// A fraction `n / d` (`d > 0`): an end of a pending interval or of a blocked square's.
type Frac = (i32, i32);

/// Depths up to which the fractions' products fit in `i32`.
const MAX_DEPTH: i32 = 1 << 13;

/// Call `mark(i)` for every map index `i` of a free cell `v` in the box `[lo, hi]` (corners, inclusive,
/// on the map, holding `u`), `v != u`, with `segment_clear(grid, u, v)` and within the depth
/// bound of its side; and for no other index. `depth` bounds the depth `|dx|` of the cells with
/// `|dx| >= |dy|` (`depth[0]` those right of `u`, `depth[1]` left) and `|dy|` of those with
/// `|dy| >= |dx|` (`depth[2]` below, `depth[3]` above); a cell on a diagonal is marked if either
/// of its two bounds allows it. With `near`, a cell `v` whose `|v - u| + |v - goal|` is at
/// least `near.reach` may be left out too (a few thousandths of slack for `f32` roundings:
/// the caller leaves more, see [`Near`]). `stack` holds the pending intervals
/// ([`FRAME`] words each); `false` when it was too short (then some visible cells may be
/// missing) or the box is not on the map or does not hold `u`.
#[allow(clippy::too_many_arguments)]
pub fn sweep(
    grid: &Grid<'_>,
    u: Point,
    [lo, hi]: [Point; 2],
    depth: [u16; 4],
    near: Option<Near>,
    lines: Option<&Lines<'_>>,
    stack: &mut [u32],
    mut mark: impl FnMut(usize),
) -> bool {
    let (w, h) = (i32::from(grid.width()), i32::from(grid.height()));
    let (ux, uy) = (i32::from(u.x), i32::from(u.y));
    let (x0, y0, x1, y1) = (
        i32::from(lo.x),
        i32::from(lo.y),
        i32::from(hi.x),
        i32::from(hi.y),
    );
    if x0 > ux || ux > x1 || y0 > uy || uy > y1 || x1 >= w || y1 >= h {
        return false;
    }
    let [dr_, dl_, dd_, du_] = depth.map(|d| i32::from(d).min(MAX_DEPTH));
    let base = uy.wrapping_mul(w).wrapping_add(ux);
    // Room in the box beyond `u` on each side: right, left, down, up.
    let (right, left, down, up) = (
        x1.wrapping_sub(ux),
        ux.wrapping_sub(x0),
        y1.wrapping_sub(uy),
        uy.wrapping_sub(y0),
    );
    let mut ok = true;
    // The goal from `u` (x, y), and the bound (infinite: none).
    let (gx, gy, reach) = near.map_or((0.0, 0.0, f32::INFINITY), |n| {
        (
            f32::from(n.goal.x) - f32::from(u.x),
            f32::from(n.goal.y) - f32::from(u.y),
            n.reach,
        )
    });
    // The box's lines of free bits, when the caller filled them for this box: the octant's
    // rows are its columns (depth along x) or its rows (depth along y), read forward or
    // reversed ([`Lines`]), from `u`'s line, the column `u`'s bit.
    let lines = lines.filter(|l| l.corners == [lo, hi]);
    let (fx, fy) = (ux.wrapping_sub(x0), uy.wrapping_sub(y0));
    let (bx, by) = (x1.wrapping_sub(ux), y1.wrapping_sub(uy));
    for (k, (rows, cols, dr, dc, goal)) in [
        // Depth along x (columns along y), then depth along y; the goal in (depth, column).
        (right.min(dr_), down, 1, w, (gx, gy)),
        (right.min(dr_), up, 1, w.wrapping_neg(), (gx, -gy)),
        (left.min(dl_), down, -1, w, (-gx, gy)),
        (left.min(dl_), up, -1, w.wrapping_neg(), (-gx, -gy)),
        (down.min(dd_), right, w, 1, (gy, gx)),
        (down.min(dd_), left, w, -1, (gy, -gx)),
        (up.min(du_), right, w.wrapping_neg(), 1, (-gy, gx)),
        (up.min(du_), left, w.wrapping_neg(), -1, (-gy, -gx)),
    ]
    .into_iter()
    .enumerate()
    {
        // The octant's lines, from its place in the list (not a column of it: the list's
        // entries are on the stack, whose depth the device's RAM budget counts): the first
        // four go along x, the last four along y ([`OCTANT_LINES`]); odd ones have their
        // columns backwards (up, or left), and the third and fourth of each four their depth.
        let line = lines.map(|l| {
            let back = k & 1 == 1;
            let (first, shift) = if k < 4 {
                (fx, if back { by } else { fy })
            } else {
                (fy, if back { bx } else { fx })
            };
            OctantLines {
                lines: OCTANT_LINES
                    .get(k)
                    .and_then(|&kind| l.sets.get(kind))
                    .copied()
                    .unwrap_or_default(),
                first,
                // k < 8: 1 for the first two of each four, -1 for the others.
                step: 1i32.wrapping_sub(k as i32 & 2),
                shift: shift as u32,
            }
        });
        let oct = Octant {
            line,
            grid,
            base,
            dr,
            dc,
            rows,
            cols,
            goal,
            reach,
            inside: inside(goal, reach),
        };
        ok &= oct.sweep(stack, &mut mark);
    }
    ok
}

/// The cells worth marking: those `v` with `|v - u| + |v - goal| < reach`, an ellipse around
/// `u` and the goal. An A* relaxation from `u` at `g` improves `v` only if
/// `g + |v - u| + |v - goal| < limit`: with `reach = limit - g + slack` ([`crate::polish::corridor`]
/// adds an eighth of a cell), every cell left out fails the A*'s own length test.
#[derive(Clone, Copy, Debug)]
pub struct Near {
    /// The goal.
    pub goal: Point,
    /// The bound on `|v - u| + |v - goal|`.
    pub reach: f32,
}

/// One octant of [`sweep`]: cell `(r, c)` (depth, column) is map index `base + r dr + c dc`;
/// rows beyond `rows` are not swept, columns beyond `cols` are outside the box (blocked).
struct Octant<'g, 'b> {
    /// The octant's rows as words of free bits ([`Lines`]), when the caller has them.
    line: Option<OctantLines<'g>>,
    grid: &'g Grid<'b>,
    base: i32,
    dr: i32,
    dc: i32,
    rows: i32,
    cols: i32,
    /// The goal in (depth, column) coordinates from `u`.
    goal: (f32, f32),
    /// [`Near::reach`] (infinite: none).
    reach: f32,
    /// Rows up to which [`Octant::far`] is not asked: about the last depth whose whole row
    /// lies inside the ellipse ([`inside`]). Only a saving: an interval kept that `far` would
    /// have dropped marks more cells, never fewer.
    inside: i32,
}

/// The longest side of a box whose lines [`Lines`] holds: a line is one word, and an octant's
/// row reads its columns `0..=r + 1` (`r` below the side) from it.
pub const LINE_SIDE: u16 = 31;

/// The set of [`Lines`] each of [`sweep`]'s eight octants reads its rows from, in its order.
const OCTANT_LINES: [usize; 8] = [
    COLS, COLS_REV, COLS, COLS_REV, ROWS, ROWS_REV, ROWS, ROWS_REV,
];

/// Which of [`Lines`]'s four sets.
const ROWS: usize = 0;
const ROWS_REV: usize = 1;
const COLS: usize = 2;
const COLS_REV: usize = 3;

/// A box's free cells as words, one a line (a row or a column of the box), for [`sweep`]: an
/// octant's row is then one word, so its blocked squares are found by their set bits and its
/// free cells marked by theirs, instead of one map read a column. Four sets: the rows read from
/// the left (bit `k` = cell `(x0 + k, y)`), the rows from the right (`(x1 - k, y)`), the columns
/// from the top (`(x, y0 + k)`) and from the bottom (`(x, y1 - k)`); a bit is set iff the cell
/// is free, so the columns beyond the box read as blocked, as [`sweep`] counts them. Filled
/// once for a box ([`Lines::fill`]) and read by every sweep over that box.
#[derive(Debug)]
pub struct Lines<'a> {
    /// The box, `[lo, hi]`: a sweep over another box does not use these lines.
    corners: [Point; 2],
    /// The four sets, by [`ROWS`], [`ROWS_REV`], [`COLS`], [`COLS_REV`].
    sets: [&'a [u32]; 4],
}

/// One octant's view of [`Lines`]: the set its rows are in, the line of depth 0, which way the
/// depth goes along the lines, and `u`'s bit in a line (its column 0).
#[derive(Clone, Copy)]
struct OctantLines<'a> {
    lines: &'a [u32],
    first: i32,
    step: i32,
    shift: u32,
}

impl OctantLines<'_> {
    /// The free bits of the octant's row `r`: bit `c` = column `c` (0 beyond the box).
    #[inline(always)]
    fn free(&self, r: i32) -> u32 {
        let k = self.first.wrapping_add(r.wrapping_mul(self.step));
        usize::try_from(k)
            .ok()
            .and_then(|k| self.lines.get(k))
            .map_or(0, |&l| l.wrapping_shr(self.shift))
    }
}

/// Columns `lo..=hi` as bits of a word, for `0 <= lo, hi <= 31` (none when `hi < lo`: the
/// two masks do not meet).
#[inline(always)]
fn span(lo: i32, hi: i32) -> u32 {
    u32::MAX.wrapping_shr(31u32.wrapping_sub(hi as u32)) & u32::MAX.wrapping_shl(lo as u32)
}

/// Words [`Lines::fill`] needs for the box `[lo, hi]`: twice its height plus twice its width;
/// `None` when a side is above [`LINE_SIDE`] (or the corners are not ordered).
pub fn line_words([lo, hi]: [Point; 2]) -> Option<usize> {
    let (w, h) = (hi.x.checked_sub(lo.x)?, hi.y.checked_sub(lo.y)?);
    // Sides at most 31: no overflow.
    (w < LINE_SIDE && h < LINE_SIDE).then(|| {
        usize::from(w)
            .wrapping_add(usize::from(h))
            .wrapping_add(2)
            .wrapping_mul(2)
    })
}

impl<'a> Lines<'a> {
    /// The lines of the box `[lo, hi]` (on the map) in `words`; `None` when the box is not on
    /// the map, a side is above [`LINE_SIDE`] or `words` is shorter than [`line_words`].
    pub fn fill(grid: &Grid<'_>, [lo, hi]: [Point; 2], words: &'a mut [u32]) -> Option<Self> {
        let n = line_words([lo, hi])?;
        if !grid.contains(hi) {
            return None;
        }
        // Both sides at most `LINE_SIDE` (31): every shift below is under 32.
        let (w, h) = (
            u32::from(hi.x.wrapping_sub(lo.x)).wrapping_add(1),
            u32::from(hi.y.wrapping_sub(lo.y)).wrapping_add(1),
        );
        let (wu, hu) = (w as usize, h as usize);
        let words = words.get_mut(..n)?;
        words.fill(0);
        let (rows, rest) = words.split_at_mut(hu);
        let (rows_rev, rest) = rest.split_at_mut(hu);
        let (cols, cols_rev) = rest.split_at_mut(wu);
        let full = u32::MAX.wrapping_shr(32u32.wrapping_sub(w));
        for (k, (row, rev)) in rows.iter_mut().zip(rows_rev.iter_mut()).enumerate() {
            let y = usize::from(lo.y).wrapping_add(k);
            let i = y
                .wrapping_mul(usize::from(grid.width()))
                .wrapping_add(usize::from(lo.x));
            let free = !(grid.blocked_window(i) as u32) & full;
            *row = free;
            *rev = free.reverse_bits().wrapping_shr(32u32.wrapping_sub(w));
            // The row's free cells in the columns: bit k from the top, h - 1 - k from the bottom.
            let mut m = free;
            while m != 0 {
                let j = m.trailing_zeros() as usize;
                m &= m.wrapping_sub(1);
                if let Some(c) = cols.get_mut(j) {
                    *c |= 1u32.wrapping_shl(k as u32);
                }
                if let Some(c) = cols_rev.get_mut(j) {
                    *c |= 1u32.wrapping_shl(h.wrapping_sub(1).wrapping_sub(k as u32));
                }
            }
        }
        Some(Self {
            corners: [lo, hi],
            sets: [rows, rows_rev, cols, cols_rev],
        })
    }
}

/// A depth beyond which no cell of the octant lies inside the ellipse `|w| + |w - goal| <
/// reach` (the goal at `(ga, gc)` in (depth, column) coordinates): on the whole line at depth
/// `r`, `f(w) = |w| + |w - goal|` is least where the segment from the origin to the goal, or to
/// its mirror image `(2 r - ga, gc)` once the goal lies before the line (`ga < r`), crosses
/// it: `|goal|`, or `sqrt((2 r - ga)^2 + gc^2)`. So no row has a cell inside when `|goal| >=
/// reach`, and none beyond `(ga + sqrt(reach^2 - gc^2)) / 2` otherwise. Computed with a 32nd
/// of a cell more reach (far above the `f32` roundings): every row it cuts lies wholly outside.
/// `i32::MAX` without a reach.
#[inline(always)]
fn outside((ga, gc): (f32, f32), reach: f32) -> i32 {
    if reach == f32::INFINITY || reach.is_nan() {
        return i32::MAX;
    }
    let big = reach + 1.0 / 32.0;
    let room = big * big - gc * gc;
    if ga * ga + gc * gc >= big * big || room <= 0.0 {
        return 0;
    }
    let t = (ga + sqrt(room)) * 0.5;
    if t >= MAX_DEPTH as f32 {
        MAX_DEPTH
    } else if t > 0.0 {
        t as i32
    } else {
        0
    }
}

/// About the last depth `r` whose whole octant row (columns `0..=r`) lies inside the ellipse
/// `|w| + |w - goal| < reach`, the goal at `(ga, gc)` in (depth, column) coordinates: `f(w) =
/// |w| + |w - goal|` is convex along the row, so largest at its ends `(r, 0)` and `(r, r)`,
/// and each end's `f < reach` is, squared, linear in `r`: `2 r (reach - ga) < reach^2 -
/// |goal|^2` and `2 r (sqrt 2 reach - ga - gc) < reach^2 - |goal|^2`. Rounded in `f32`: a row
/// it takes for inside that is not only costs [`Octant::far`]'s cut there (the caller's
/// length test rejects the extra cells), so it need not be exact. 0 without a reach.
#[inline(always)]
fn inside((ga, gc): (f32, f32), reach: f32) -> i32 {
    let room = reach * reach - (ga * ga + gc * gc);
    let (a, b) = (reach - ga, reach * core::f32::consts::SQRT_2 - ga - gc);
    // (`reach` infinite: the quotients are NaN and the depth 0; `far` is never true then.)
    if !(room > 0.0 && a > 0.0 && b > 0.0) {
        return 0;
    }
    let (r0, r1) = (room / (a + a), room / (b + b));
    let r = if r0 < r1 { r0 } else { r1 };
    // Strictly below the bound (a row exactly on it is not inside), at most `MAX_DEPTH`.
    if r >= MAX_DEPTH as f32 {
        MAX_DEPTH
    } else {
        let k = r as i32;
        if k as f32 >= r {
            k.wrapping_sub(1)
        } else {
            k
        }
    }
}

impl Octant<'_, '_> {
    /// Whether cell `(r, c)` (`0 <= c`) blocks: outside the box, or blocked on the map.
    #[inline(always)]
    fn blocked(&self, row: i32, c: i32) -> bool {
        // In the box: the index is on the map, non-negative.
        c > self.cols
            || self
                .grid
                .blocked_at(row.wrapping_add(c.wrapping_mul(self.dc)) as usize)
    }

    /// Whether no cell at depth `r` or beyond with slope in `[lo, hi]` is nearer than the
    /// reach: `f(w) = |w| + |w - goal|` grows along every ray from `u` (its derivative along
    /// the ray is `1 + cos >= 0`), so over that sector it is least on the row-`r` slice
    /// `(r, r s)`, `s` in `[lo, hi]`; convex along the slice, least at its minimiser over the
    /// whole line `x = r` clamped to the slice. That minimiser is where the segment from `u` to
    /// the goal (or to its mirror image across the line, when both lie on the same side)
    /// crosses the line.
    #[inline(always)]
    fn far(&self, r: i32, lo: Frac, hi: Frac) -> bool {
        if self.reach == f32::INFINITY {
            return false;
        }
        let (ga, gc) = self.goal;
        let rf = r as f32;
        let tx = if ga > rf { ga } else { rf + rf - ga };
        let (slo, shi) = (lo.0 as f32 / lo.1 as f32, hi.0 as f32 / hi.1 as f32);
        let mut s = gc / tx;
        if s < slo {
            s = slo;
        }
        if s > shi {
            s = shi;
        }
        let y = rf * s;
        let (ex, ey) = (rf - ga, y - gc);
        let f = sqrt(rf * rf + y * y) + sqrt(ex * ex + ey * ey);
        f >= self.reach
    }

    fn sweep(&self, stack: &mut [u32], mark: &mut impl FnMut(usize)) -> bool {
        // Rows beyond the ellipse hold no cell to mark.
        let rows = self.rows.min(outside(self.goal, self.reach));
        if rows < 1 {
            return true;
        }
        // The diagonal also needs `(0, 1)` free (it passes its corner).
        let diag = !self.blocked(self.base, 1);
        // A pending interval: its row, its lower end `ln / ld` (closed iff `ln == 0`: the
        // uncut 0) and its upper end `hn / hd` (closed iff `hd == 1`: the uncut 1); ends are
        // non-negative and below 2^16.
        // The interval next swept is kept out of the stack: the last piece a row leaves is
        // the one the stack would give back first (it is pushed last), so it goes on without
        // a push and a pop; the others wait on the stack, in the same order as ever.
        let mut top = 0usize;
        let mut held = Some((1, (0, 1), (1, 1)));
        while let Some((r, (ln, ld), (hn, hd))) = held.take().or_else(|| pop(stack, &mut top)) {
            if r > self.inside && self.far(r, (ln, ld), (hn, hd)) {
                continue;
            }
            // Columns whose slope lies in the interval: `c ld > ln r` (or any `c >= 0` when
            // closed at 0) and `c hd < hn r` (or `c <= r` when closed at 1).
            let cmin = if ln == 0 {
                0
            } else {
                ln.wrapping_mul(r)
                    .checked_div(ld)
                    .unwrap_or(0)
                    .wrapping_add(1)
            };
            let cmax = if hd == 1 {
                r
            } else {
                hn.wrapping_mul(r)
                    .wrapping_sub(1)
                    .checked_div(hd)
                    .unwrap_or(0)
            };
            let row = self.base.wrapping_add(r.wrapping_mul(self.dr));
            // Blocked squares of this row whose closed interval meets the pending one lie in
            // columns `cmin - 1 ..= cmax + 1` (see the module doc: a square's interval reaches
            // less than a column beyond its own), and at most `r + 1`.
            let (a, b) = (
                cmin.wrapping_sub(1).max(0),
                cmax.wrapping_add(1).min(r.wrapping_add(1)),
            );
            let (d_lo, d_hi) = (
                r.wrapping_mul(2).wrapping_add(1),
                r.wrapping_mul(2).wrapping_sub(1),
            );
            let next = r.wrapping_add(1);
            let deeper = next <= rows;
            // The part of the interval not cut yet starts at `cur` (open unless 0).
            let mut cur = (ln, ld);
            // A blocked square at column `c` hides `[(2c - 1) / (2r + 1), (2c + 1) / (2r - 1)]`:
            // the piece before it (its upper end open: the square's lower end, or the
            // interval's own upper end if that comes first) goes deeper, `cur` moves past it.
            // `false`: the stack is full.
            let mut cut = |c: i32, cur: &mut Frac, top: &mut usize| {
                let (sn, sd) = (c.wrapping_mul(2).wrapping_sub(1), d_lo);
                let (en, ed) = (c.wrapping_mul(2).wrapping_add(1), d_hi);
                let upper = if less_eq((sn, sd), (hn, hd)) {
                    (sn, sd)
                } else {
                    (hn, hd)
                };
                if deeper && less(*cur, upper) && !push(stack, top, next, *cur, upper) {
                    return false;
                }
                if less(*cur, (en, ed)) {
                    *cur = (en, ed);
                }
                true
            };
            if let Some(line) = self.line {
                // The row as a word (the box's sides are at most `LINE_SIDE`: `r + 1 <= 31`):
                // the blocked squares in order, then the free cells, the same cuts and marks
                // as the loop below (the marks' order is not the loop's; they only set bits).
                let free = line.free(r);
                let mut blocked = !free & span(a, b);
                // The diagonal cell `(r, r)` also needs the square before it free (it passes
                // that square's corner), when that square is in the row's columns.
                let before_diag = r > a && blocked.wrapping_shr(r.wrapping_sub(1) as u32) & 1 == 1;
                while blocked != 0 {
                    let c = blocked.trailing_zeros() as i32;
                    blocked &= blocked.wrapping_sub(1);
                    if !cut(c, &mut cur, &mut top) {
                        return false;
                    }
                }
                let mut seen = free & span(cmin, cmax);
                if !diag || before_diag {
                    seen &= !1u32.wrapping_shl(r as u32);
                }
                while seen != 0 {
                    let c = seen.trailing_zeros() as i32;
                    seen &= seen.wrapping_sub(1);
                    // Free, so on the map and in the box: the index is valid.
                    mark(row.wrapping_add(c.wrapping_mul(self.dc)) as usize);
                }
            } else {
                let mut prev_blocked = false;
                for c in a..=b {
                    if self.blocked(row, c) {
                        if !cut(c, &mut cur, &mut top) {
                            return false;
                        }
                        prev_blocked = true;
                    } else {
                        if c >= cmin && c <= cmax && (c < r || (diag && !prev_blocked)) {
                            // On the map and in the box (not blocked), so the index is valid.
                            mark(row.wrapping_add(c.wrapping_mul(self.dc)) as usize);
                        }
                        prev_blocked = false;
                    }
                }
            }
            if deeper && less(cur, (hn, hd)) {
                held = Some((next, cur, (hn, hd)));
            }
        }
        true
    }
}

/// `a < b` for fractions with positive denominators.
#[inline(always)]
fn less(a: Frac, b: Frac) -> bool {
    a.0.wrapping_mul(b.1) < b.0.wrapping_mul(a.1)
}

/// `a <= b` for fractions with positive denominators.
#[inline(always)]
fn less_eq(a: Frac, b: Frac) -> bool {
    a.0.wrapping_mul(b.1) <= b.0.wrapping_mul(a.1)
}

/// Push a pending interval (ends non-negative and below 2^16); `false` when `stack` is full.
#[inline(always)]
fn push(stack: &mut [u32], top: &mut usize, r: i32, lo: Frac, hi: Frac) -> bool {
    let Some(slot) = stack.get_mut(*top..top.wrapping_add(FRAME)) else {
        return false;
    };
    if let [a, b, c] = slot {
        *a = r as u32;
        *b = ((lo.0 as u32) << 16) | (lo.1 as u32 & 0xFFFF);
        *c = ((hi.0 as u32) << 16) | (hi.1 as u32 & 0xFFFF);
    }
    *top = top.wrapping_add(FRAME);
    true
}

/// The last pending interval pushed, taken off `stack`.
#[inline(always)]
fn pop(stack: &[u32], top: &mut usize) -> Option<(i32, Frac, Frac)> {
    let from = top.checked_sub(FRAME)?;
    let [a, b, c] = *stack.get(from..*top)? else {
        return None;
    };
    *top = from;
    Some((
        a as i32,
        ((b >> 16) as i32, (b & 0xFFFF) as i32),
        ((c >> 16) as i32, (c & 0xFFFF) as i32),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::segment_clear;

    /// The swept set against `segment_clear` on every target of random maps, boxes, depth
    /// bounds and origins (diagonals, borders, grazed corners included).
    #[test]
    fn the_swept_set_is_exactly_the_segment_rule() {
        let mut rng = crate::rng::Xoshiro128pp::from_u64(36);
        let mut stack = vec![0u32; 3 * 256];
        let (mut seen, mut hidden, mut with_lines) = (0usize, 0usize, 0usize);
        for round in 0..600 {
            let w = 1 + (rng.next_word() % 40) as u16;
            let h = 1 + (rng.next_word() % 40) as u16;
            let density = (round % 7) as f32 * 0.1;
            let b = crate::testutil::random_bits(&mut rng, w, h, density);
            let g = Grid::new(w, h, &b).unwrap();
            let pick = |rng: &mut crate::rng::Xoshiro128pp, n: u16| {
                (rng.next_word() % u32::from(n)) as u16
            };
            let u = Point::new(pick(&mut rng, w), pick(&mut rng, h));
            if !g.is_free(u) {
                continue; // (the corridor sweeps from free cells only)
            }
            let (lo, hi) = if round % 3 == 0 {
                (Point::new(0, 0), Point::new(w - 1, h - 1))
            } else {
                (
                    Point::new(pick(&mut rng, u.x + 1), pick(&mut rng, u.y + 1)),
                    Point::new(u.x + pick(&mut rng, w - u.x), u.y + pick(&mut rng, h - u.y)),
                )
            };
            let depth = if round % 2 == 0 {
                [u16::MAX; 4]
            } else {
                [0; 4].map(|_| pick(&mut rng, 45))
            };
            // Every third round, a goal and a reach: cells beyond it may be left out.
            let reach = (round % 3 == 1).then(|| Near {
                goal: Point::new(pick(&mut rng, w), pick(&mut rng, h)),
                reach: (rng.next_word() % 60) as f32 + 0.5,
            });
            let mut got = vec![false; g.cells()];
            assert!(sweep(
                &g,
                u,
                [lo, hi],
                depth,
                reach,
                None,
                &mut stack,
                |i| got[i] = true
            ));
            // The same marks from the box's lines, where its sides allow them.
            let mut words = vec![0u32; line_words([lo, hi]).unwrap_or(0)];
            if let Some(lines) = Lines::fill(&g, [lo, hi], &mut words) {
                let mut by_lines = vec![false; g.cells()];
                assert!(sweep(
                    &g,
                    u,
                    [lo, hi],
                    depth,
                    reach,
                    Some(&lines),
                    &mut stack,
                    |i| by_lines[i] = true
                ));
                assert_eq!(by_lines, got, "{w}x{h} {u:?} box {lo:?}..{hi:?} by lines");
                with_lines += 1;
            }
            for (i, &got) in got.iter().enumerate() {
                let v = g.point(i);
                let inside = v.x >= lo.x && v.x <= hi.x && v.y >= lo.y && v.y <= hi.y;
                let (dx, dy) = (v.x.abs_diff(u.x), v.y.abs_diff(u.y));
                let near = (dx >= dy && dx <= depth[usize::from(v.x < u.x)])
                    || (dy >= dx && dy <= depth[2 + usize::from(v.y < u.y)]);
                let want = inside && v != u && near && g.is_free(v) && segment_clear(&g, u, v);
                // Within the reach (with a thousandth's slack), a visible cell must be marked;
                // beyond it, it may be.
                let within = reach.is_none_or(|n| {
                    let f = |a: Point, b: Point| {
                        (f64::from(a.x) - f64::from(b.x)).hypot(f64::from(a.y) - f64::from(b.y))
                    };
                    f(v, u) + f(v, n.goal) < f64::from(n.reach) - 1e-3
                });
                if want && !within {
                    assert!(!got || want, "{u:?} -> {v:?}: marked, hidden");
                    continue;
                }
                assert_eq!(
                    got, want,
                    "{w}x{h} {u:?} -> {v:?} box {lo:?}..{hi:?} depth {depth:?}"
                );
                if inside && v != u && near && g.is_free(v) {
                    if want {
                        seen += 1;
                    } else {
                        hidden += 1;
                    }
                }
            }
        }
        assert!(seen > 10_000 && hidden > 10_000, "{seen} {hidden}");
        assert!(with_lines > 300, "{with_lines}");
    }

    /// The rows [`inside`] lets skip [`Octant::far`] lie inside the ellipse (both ends of each,
    /// so the whole row), and the next row does not (up to `f32` rounding, and the depth cap):
    /// a depth too large would only lose `far`'s cut, too small its saving, so the rule pinned is
    /// the depth itself, against `f64` on random goals and reaches.
    /// A random goal (depth and column in `-60..=60`) and reach (`0..125` in 16ths of a cell)
    /// for the ellipse depth tests below.
    fn random_ellipse(rng: &mut crate::rng::Xoshiro128pp) -> ((f32, f32), f32) {
        let mut pick = || (rng.next_word() % 121) as f32 - 60.0;
        let goal = (pick(), pick());
        (goal, (rng.next_word() % 2000) as f32 / 16.0)
    }

    /// `|w| + |w - goal|` for the cell `w` at depth `r`, column `c`, in `f64`.
    fn ellipse_f(r: f64, c: f64, ga: f64, gc: f64) -> f64 {
        r.hypot(c) + (r - ga).hypot(c - gc)
    }

    #[test]
    fn the_inside_rows_are_inside_the_ellipse() {
        let mut rng = crate::rng::Xoshiro128pp::from_u64(37);
        let f = ellipse_f;
        let (mut some, mut none) = (0, 0);
        for _ in 0..20_000 {
            let ((ga, gc), reach) = random_ellipse(&mut rng);
            let k = inside((ga, gc), reach);
            let (ga, gc, reach) = (f64::from(ga), f64::from(gc), f64::from(reach));
            let end = |r: i32| {
                let r = f64::from(r);
                f(r, 0.0, ga, gc).max(f(r, r, ga, gc))
            };
            if k > 0 {
                some += 1;
                assert!(end(k) < reach + 1e-3, "({ga}, {gc}) {reach}: {k}");
            } else {
                none += 1;
            }
            assert!(
                end(k + 1) >= reach - 1e-3 || k == MAX_DEPTH,
                "({ga}, {gc}) {reach}: {k} + 1"
            );
        }
        assert!(some > 1000 && none > 1000, "{some} {none}");
        assert_eq!(inside((3.0, 4.0), f32::INFINITY), 0);
    }

    /// The rows [`outside`] cuts hold no cell inside the ellipse (every column of the first
    /// row cut, against `f64`), and the cut is no more than a 16th of a cell of reach early: on
    /// the line at the last depth kept, the least `f` is below `reach + 1/16`.
    #[test]
    fn the_rows_cut_outside_hold_no_cell_inside() {
        let mut rng = crate::rng::Xoshiro128pp::from_u64(38);
        let f = ellipse_f;
        let (mut cut, mut all) = (0, 0);
        for _ in 0..20_000 {
            let ((ga, gc), reach) = random_ellipse(&mut rng);
            let k = outside((ga, gc), reach);
            let (ga, gc, reach) = (f64::from(ga), f64::from(gc), f64::from(reach));
            let next = f64::from(k + 1);
            for c in 0..=k + 1 {
                let c = f64::from(c);
                assert!(
                    f(next, c, ga, gc) >= reach,
                    "({ga}, {gc}) {reach}: row {k} + 1 column {c}"
                );
            }
            if k == 0 {
                all += 1;
                continue;
            }
            cut += 1;
            let kf = f64::from(k);
            let least = if ga >= kf {
                ga.hypot(gc)
            } else {
                (2.0 * kf - ga).hypot(gc)
            };
            assert!(least < reach + 1.0 / 16.0, "({ga}, {gc}) {reach}: {k}");
        }
        assert!(cut > 1000 && all > 1000, "{cut} {all}");
        assert_eq!(outside((3.0, 4.0), f32::INFINITY), i32::MAX);
    }

    /// A stack too short says so: one blocked cell splits an octant's interval in two (the
    /// square at depth 3, column 1 hides `[1/7, 3/5]`), so the second piece has no room.
    #[test]
    fn a_short_stack_says_so() {
        let rows = [".......", ".......", ".......", "...#...", "......."];
        let (b, w, h) = crate::testutil::bits(&rows);
        let g = Grid::new(w, h, &b).unwrap();
        let (u, lo, hi) = (Point::new(0, 2), Point::new(0, 0), Point::new(w - 1, h - 1));
        let mut stack = [0u32; FRAME];
        assert!(!sweep(
            &g,
            u,
            [lo, hi],
            [u16::MAX; 4],
            None,
            None,
            &mut stack,
            |_| ()
        ));
        let mut stack = [0u32; 2 * FRAME];
        assert!(sweep(
            &g,
            u,
            [lo, hi],
            [u16::MAX; 4],
            None,
            None,
            &mut stack,
            |_| ()
        ));
    }
}
