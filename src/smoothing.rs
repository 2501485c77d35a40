//! Line-of-sight smoothing of the raw ant path (paper section 4.3): drop waypoints that a
//! straight, collision-free segment makes needless.
//!
//! Segments are checked with [`crate::geometry::segment_clear`] (the closed-square rule), so the
//! smoothed path never touches an obstacle, not even at a corner.
//!
//! Three kinds:
//!
//! - [`SmoothingKind::Shortest`] (default for OHACA): the shortest path that visits a subsequence
//!   of the raw path's cells, found by dynamic programming over all pairs that see each other
//!   (`O(n^2)` segment tests at worst for `n` raw cells, pruned by length). This is the reading
//!   that works: on the shared maps it lands on average within 1% of the any-angle optimum through
//!   cell centres, where the paper's greedy rule is up to 5% above it, because greedy keeps the
//!   first cell it cannot see past rather than the best one.
//! - [`SmoothingKind::Greedy`]: the paper's steps 1-5 literally: from the anchor `S`, extend `N`
//!   along the path while `S` sees `N`; when it does not, the node before `N` becomes the next
//!   anchor and a waypoint. Kept for faithful comparisons.
//! - [`SmoothingKind::None`]: no smoothing; the waypoints are the raw path's corners (used by ACA,
//!   PACA and HACA, which the paper reports without post-processing).
//!
//! All three work in place on the caller's buffers and keep collinear points out of the output.

use crate::geometry::{distance, segment_clear};
use crate::grid::{Grid, Point};

/// How to post-process the raw path.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[cfg_attr(
    feature = "serde",
    derive(serde::Serialize, serde::Deserialize),
    serde(rename_all = "lowercase")
)]
pub enum SmoothingKind {
    /// Keep the raw path; waypoints are its corners.
    None,
    /// The paper's greedy line-of-sight rule.
    Greedy,
    /// Shortest subsequence path (dynamic programming). Default.
    #[default]
    Shortest,
}

impl SmoothingKind {
    /// All three, default first.
    pub const ALL: [SmoothingKind; 3] = [
        SmoothingKind::Shortest,
        SmoothingKind::Greedy,
        SmoothingKind::None,
    ];

    /// Lower-case name (`"shortest"`, `"greedy"`, `"none"`).
    pub const fn name(self) -> &'static str {
        match self {
            SmoothingKind::None => "none",
            SmoothingKind::Greedy => "greedy",
            SmoothingKind::Shortest => "shortest",
        }
    }

    /// Parse a name (case-insensitive).
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s))
    }
}

impl core::fmt::Display for SmoothingKind {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// True if `b` lies on the straight line from `a` to `c`, between them.
fn collinear_between(a: Point, b: Point, c: Point) -> bool {
    // Differences of u16 values and their products (< 2^33) cannot wrap in i64.
    let (ux, uy) = (
        i64::from(b.x).wrapping_sub(i64::from(a.x)),
        i64::from(b.y).wrapping_sub(i64::from(a.y)),
    );
    let (vx, vy) = (
        i64::from(c.x).wrapping_sub(i64::from(b.x)),
        i64::from(c.y).wrapping_sub(i64::from(b.y)),
    );
    ux.wrapping_mul(vy) == uy.wrapping_mul(vx)
        && ux.wrapping_mul(vx).wrapping_add(uy.wrapping_mul(vy)) >= 0
}

/// Remove interior points of `pts[..n]` that lie straight between their neighbours; returns the
/// new length. (A point on a straight segment between two kept points adds nothing, and the
/// segment it belongs to was already checked clear, so the merged segment is clear too.)
pub fn drop_collinear(pts: &mut [Point], n: usize) -> usize {
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
        if !collinear_between(a, b, c) {
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

/// Smooth the path `pts[..n]` in place; returns the number of waypoints now in `pts`.
/// `dist` and `prev` are scratch of at least `n` entries (only [`SmoothingKind::Shortest`] uses
/// them; if they are too short it falls back to [`SmoothingKind::Greedy`]).
pub fn smooth(
    grid: &Grid<'_>,
    kind: SmoothingKind,
    pts: &mut [Point],
    n: usize,
    dist: &mut [f32],
    prev: &mut [u32],
) -> usize {
    let n = n.min(pts.len());
    if n < 3 {
        return n;
    }
    let k = match kind {
        SmoothingKind::None => n,
        SmoothingKind::Greedy => greedy(grid, pts, n),
        SmoothingKind::Shortest => {
            if dist.len() < n || prev.len() < n {
                greedy(grid, pts, n)
            } else {
                shortest(grid, pts, n, dist, prev)
            }
        }
    };
    drop_collinear(pts, k)
}

/// The paper's greedy rule, in place.
fn greedy(grid: &Grid<'_>, pts: &mut [Point], n: usize) -> usize {
    // Bounds: 3 <= n <= pts.len() (see `smooth`) and anchor < i, out < i, i <= n, so no
    // `wrapping_` here wraps.
    let mut out = 1usize; // pts[0] stays.
    let mut anchor = 0usize;
    let mut i = 2usize;
    while i < n {
        let (Some(&s), Some(&p)) = (pts.get(anchor), pts.get(i)) else {
            break;
        };
        if !segment_clear(grid, s, p) {
            // The node before N becomes a waypoint and the new anchor. It is always reachable
            // from the anchor (it was seen on the previous round, or it is the anchor's successor).
            anchor = i.wrapping_sub(1);
            let Some(&w) = pts.get(anchor) else { break };
            if let Some(slot) = pts.get_mut(out) {
                *slot = w;
            }
            out = out.wrapping_add(1);
            // Note: anchor < i, and the kept prefix pts[..out] never overtakes the read position
            // because out <= anchor.
        }
        i = i.wrapping_add(1);
    }
    let last = pts.get(n.wrapping_sub(1)).copied();
    if let (Some(last), Some(slot)) = (last, pts.get_mut(out)) {
        *slot = last;
    }
    out.wrapping_add(1)
}

/// Shortest subsequence path by dynamic programming, in place.
fn shortest(
    grid: &Grid<'_>,
    pts: &mut [Point],
    n: usize,
    dist: &mut [f32],
    prev: &mut [u32],
) -> usize {
    if let (Some(d0), Some(p0)) = (dist.get_mut(0), prev.get_mut(0)) {
        *d0 = 0.0;
        *p0 = 0;
    }
    for j in 1..n {
        let Some(&pj) = pts.get(j) else { break };
        // Default: come from the previous raw cell (always clear: it is a legal move).
        let before = j.wrapping_sub(1); // j >= 1
        let (mut best, mut from) = match (dist.get(before), pts.get(before)) {
            (Some(&d), Some(&p)) => (d + distance(p, pj), before),
            _ => break,
        };
        for i in 0..j.saturating_sub(1) {
            let (Some(&di), Some(&pi)) = (dist.get(i), pts.get(i)) else {
                break;
            };
            let cand = di + distance(pi, pj);
            // Strictly shorter only, so ties keep the earlier (fewer-waypoint) choice found first.
            if cand < best && segment_clear(grid, pi, pj) {
                best = cand;
                from = i;
            }
        }
        if let (Some(d), Some(p)) = (dist.get_mut(j), prev.get_mut(j)) {
            *d = best;
            *p = from as u32;
        }
    }
    // Follow prev from the goal back to the start, reversing the links into "next" links.
    let mut cur = n.wrapping_sub(1); // n >= 3 (see `smooth`)
    let mut next = u32::MAX;
    while let Some(slot) = prev.get_mut(cur) {
        let p = *slot as usize;
        *slot = next;
        next = cur as u32;
        if cur == 0 {
            break;
        }
        cur = p;
    }
    // Walk forward, compacting the chosen cells to the front (indices only grow, so reading
    // index i after writing slot k <= i is safe).
    let mut k = 0usize;
    let mut i = 0usize;
    while let Some(&p) = pts.get(i) {
        if let Some(slot) = pts.get_mut(k) {
            *slot = p;
        }
        // The links only go forward, so at most n cells are visited: k <= n.
        k = k.wrapping_add(1);
        match prev.get(i) {
            Some(&nx) if nx != u32::MAX => i = nx as usize,
            _ => break,
        }
    }
    k
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::polyline_length;

    fn grid(rows: &[&str]) -> (Vec<u8>, u16, u16) {
        let w = rows[0].len();
        let mut b = vec![0u8; (w * rows.len()).div_ceil(8)];
        for (y, r) in rows.iter().enumerate() {
            for (x, c) in r.chars().enumerate() {
                if c == '#' {
                    let i = y * w + x;
                    b[i / 8] |= 1 << (i % 8);
                }
            }
        }
        (b, w as u16, rows.len() as u16)
    }

    fn pts(v: &[(u16, u16)]) -> Vec<Point> {
        v.iter().map(|&(x, y)| Point::new(x, y)).collect()
    }

    #[test]
    fn open_map_collapses_to_one_segment() {
        let (b, w, h) = grid(&["......", "......", "......"]);
        let g = Grid::new(w, h, &b).unwrap();
        let raw = pts(&[(0, 0), (1, 1), (2, 1), (3, 1), (4, 2), (5, 2)]);
        for kind in [SmoothingKind::Greedy, SmoothingKind::Shortest] {
            let mut p = raw.clone();
            let mut d = vec![0.0; 6];
            let mut pr = vec![0; 6];
            let k = smooth(&g, kind, &mut p, 6, &mut d, &mut pr);
            assert_eq!(&p[..k], &pts(&[(0, 0), (5, 2)])[..], "{kind:?}");
        }
    }

    #[test]
    fn none_keeps_corners_only() {
        let (b, w, h) = grid(&["....", "....", "...."]);
        let g = Grid::new(w, h, &b).unwrap();
        let mut p = pts(&[(0, 0), (1, 0), (2, 0), (3, 1), (3, 2)]);
        let k = smooth(&g, SmoothingKind::None, &mut p, 5, &mut [], &mut []);
        assert_eq!(&p[..k], &pts(&[(0, 0), (2, 0), (3, 1), (3, 2)])[..]);
    }

    #[test]
    fn shortest_beats_greedy_and_both_stay_clear() {
        // Raw path hugs a wall around an obstacle block.
        let rows = [
            "..........", //
            "..........", //
            "...####...", //
            "...####...", //
            "..........", //
        ];
        let (b, w, h) = grid(&rows);
        let g = Grid::new(w, h, &b).unwrap();
        // Go along row 4 under the block, then up the right side to (9, 0).
        let raw = pts(&[
            (0, 2),
            (1, 3),
            (2, 4),
            (3, 4),
            (4, 4),
            (5, 4),
            (6, 4),
            (7, 4),
            (8, 3),
            (9, 2),
            (9, 1),
            (9, 0),
        ]);
        let n = raw.len();
        let mut lens = vec![];
        for kind in [SmoothingKind::Greedy, SmoothingKind::Shortest] {
            let mut p = raw.clone();
            let mut d = vec![0.0; n];
            let mut pr = vec![0; n];
            let k = smooth(&g, kind, &mut p, n, &mut d, &mut pr);
            let wp = &p[..k];
            assert_eq!(wp[0], raw[0]);
            assert_eq!(wp[k - 1], raw[n - 1]);
            for s in wp.windows(2) {
                assert!(segment_clear(&g, s[0], s[1]), "{kind:?} {s:?}");
            }
            lens.push(polyline_length(wp));
        }
        assert!(lens[1] <= lens[0] + 1e-5, "{lens:?}");
        assert!(lens[1] < polyline_length(&raw));
    }

    #[test]
    fn drop_collinear_handles_reversal() {
        // A back-and-forth on one line is a turn, not a straight point.
        let mut p = pts(&[(0, 0), (2, 0), (1, 0)]);
        assert_eq!(drop_collinear(&mut p, 3), 3);
    }
}
