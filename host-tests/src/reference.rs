//! Exact references, written without looking at the core's code paths:
//!
//! - [`dijkstra8`] / [`astar8`] / [`opt8`]: shortest 8-connected paths with no corner cutting (a
//!   diagonal step needs both orthogonally adjacent cells free), cost 1 per straight and `sqrt 2`
//!   per diagonal step, in `f64`.
//! - [`touches`] / [`segment_clear`]: the segment rule, decided by the separating-axis theorem in
//!   exact integer arithmetic. Cell `(x, y)` is the closed square `[x, x+1] x [y, y+1]`; a segment
//!   between two cell centres is clear iff it touches no blocked cell's closed square (a single
//!   shared point counts as touching).
//! - [`any_angle`]: the exact shortest path through cell centres with straight segments obeying
//!   the segment rule (Dijkstra / A* over the visibility graph of all free cell centres).
//!
//! The core decides the segment rule by walking the segment column by column; this module instead
//! tests the segment against each blocked cell's square as a pair of convex sets, so the two can
//! be cross-checked (see the tests).

use std::cmp::Ordering;
use std::collections::BinaryHeap;

use ohaca::Point;

use crate::maps::Map;

/// The eight moves as `(dx, dy)`.
pub const MOVES: [(i64, i64); 8] = [
    (1, 0),
    (1, 1),
    (0, 1),
    (-1, 1),
    (-1, 0),
    (-1, -1),
    (0, -1),
    (1, -1),
];

/// True if one step from `p` by `(dx, dy)` (a king move) is allowed: the target is free and, for
/// a diagonal, both orthogonally adjacent cells are free.
pub fn step_allowed(map: &Map, p: Point, dx: i64, dy: i64) -> bool {
    if (dx, dy) == (0, 0) || dx.abs() > 1 || dy.abs() > 1 {
        return false;
    }
    let (x, y) = (i64::from(p.x), i64::from(p.y));
    if !map.free(x + dx, y + dy) {
        return false;
    }
    dx == 0 || dy == 0 || (map.free(x + dx, y) && map.free(x, y + dy))
}

/// Cost of a king move.
fn step_cost(dx: i64, dy: i64) -> f64 {
    if dx != 0 && dy != 0 {
        std::f64::consts::SQRT_2
    } else {
        1.0
    }
}

/// The allowed neighbours of `p` with their step costs.
pub fn neighbours(map: &Map, p: Point) -> impl Iterator<Item = (Point, f64)> + '_ {
    MOVES
        .iter()
        .filter(move |&&(dx, dy)| step_allowed(map, p, dx, dy))
        .map(move |&(dx, dy)| {
            (
                Point::new((i64::from(p.x) + dx) as u16, (i64::from(p.y) + dy) as u16),
                step_cost(dx, dy),
            )
        })
}

/// A min-heap entry ordered by `f64` key (then index, for a total order).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Entry(f64, usize);

impl Eq for Entry {}

impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        // Reversed: BinaryHeap is a max-heap.
        o.0.total_cmp(&self.0).then_with(|| o.1.cmp(&self.1))
    }
}

impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// Shortest 8-connected distances from `start` to every cell (`f64::INFINITY` where unreachable
/// or blocked). Empty-handed (all infinite) if `start` is blocked or off the map.
pub fn dijkstra8(map: &Map, start: Point) -> Vec<f64> {
    let mut dist = vec![f64::INFINITY; map.cells()];
    if !map.is_free(start) {
        return dist;
    }
    let mut heap = BinaryHeap::new();
    dist[map.index(start)] = 0.0;
    heap.push(Entry(0.0, map.index(start)));
    while let Some(Entry(d, i)) = heap.pop() {
        if d > dist[i] {
            continue;
        }
        for (n, c) in neighbours(map, map.point(i)) {
            let j = map.index(n);
            if d + c < dist[j] {
                dist[j] = d + c;
                heap.push(Entry(d + c, j));
            }
        }
    }
    dist
}

/// Octile distance: the obstacle-free 8-connected distance.
pub fn octile(a: Point, b: Point) -> f64 {
    let dx = (i64::from(a.x) - i64::from(b.x)).unsigned_abs();
    let dy = (i64::from(a.y) - i64::from(b.y)).unsigned_abs();
    let (hi, lo) = (dx.max(dy), dx.min(dy));
    (hi - lo) as f64 + lo as f64 * std::f64::consts::SQRT_2
}

/// Euclidean distance between two cell centres.
pub fn euclid(a: Point, b: Point) -> f64 {
    let dx = f64::from(a.x) - f64::from(b.x);
    let dy = f64::from(a.y) - f64::from(b.y);
    (dx * dx + dy * dy).sqrt()
}

/// Shortest 8-connected path from `start` to `goal` by A* with the octile heuristic, as the
/// length and the cells. `None` if either end is blocked or the goal is unreachable.
pub fn astar8(map: &Map, start: Point, goal: Point) -> Option<(f64, Vec<Point>)> {
    if !map.is_free(start) || !map.is_free(goal) {
        return None;
    }
    let n = map.cells();
    let mut g = vec![f64::INFINITY; n];
    let mut parent = vec![usize::MAX; n];
    let mut closed = vec![false; n];
    let (s, t) = (map.index(start), map.index(goal));
    g[s] = 0.0;
    let mut heap = BinaryHeap::new();
    heap.push(Entry(octile(start, goal), s));
    while let Some(Entry(_, i)) = heap.pop() {
        if closed[i] {
            continue;
        }
        closed[i] = true;
        if i == t {
            let mut path = vec![goal];
            let mut c = t;
            while c != s {
                c = parent[c];
                path.push(map.point(c));
            }
            path.reverse();
            return Some((g[t], path));
        }
        for (nb, c) in neighbours(map, map.point(i)) {
            let j = map.index(nb);
            if !closed[j] && g[i] + c < g[j] {
                g[j] = g[i] + c;
                parent[j] = i;
                heap.push(Entry(g[j] + octile(nb, goal), j));
            }
        }
    }
    None
}

/// Shortest 8-connected path length, or `None` if unreachable (or an end is blocked).
pub fn opt8(map: &Map, start: Point, goal: Point) -> Option<f64> {
    astar8(map, start, goal).map(|(l, _)| l)
}

/// True iff the segment between the centres of `a` and `b` touches the closed square of `cell`.
///
/// Exact: in doubled coordinates the centres are odd integers and the square is
/// `[2cx, 2cx + 2] x [2cy, 2cy + 2]`. Two closed convex sets in the plane are disjoint iff some
/// axis separates them strictly; for a segment and an axis-aligned box the candidate axes are the
/// two coordinate axes and the segment's normal.
pub fn touches(a: Point, b: Point, cell: (i64, i64)) -> bool {
    let (ax, ay) = (2 * i64::from(a.x) + 1, 2 * i64::from(a.y) + 1);
    let (bx, by) = (2 * i64::from(b.x) + 1, 2 * i64::from(b.y) + 1);
    let (x0, x1) = (2 * cell.0, 2 * cell.0 + 2);
    let (y0, y1) = (2 * cell.1, 2 * cell.1 + 2);
    // Coordinate axes.
    if ax.max(bx) < x0 || ax.min(bx) > x1 || ay.max(by) < y0 || ay.min(by) > y1 {
        return false;
    }
    // The segment's normal: the sign of cross(b - a, corner - a) for each corner.
    let (dx, dy) = (bx - ax, by - ay);
    let side = |px: i64, py: i64| (dx * (py - ay) - dy * (px - ax)).signum();
    let s = [side(x0, y0), side(x1, y0), side(x0, y1), side(x1, y1)];
    !(s.iter().all(|&v| v > 0) || s.iter().all(|&v| v < 0))
}

/// The segment rule on `map`, by brute force over the cells of the segment's bounding box.
pub fn segment_clear(map: &Map, a: Point, b: Point) -> bool {
    let (x0, x1) = (i64::from(a.x.min(b.x)), i64::from(a.x.max(b.x)));
    let (y0, y1) = (i64::from(a.y.min(b.y)), i64::from(a.y.max(b.y)));
    // A cell outside the bounding box of the two endpoint cells cannot be touched: the segment's
    // x-range is [min + 0.5, max + 0.5], which meets [cx, cx + 1] only for cx in [min, max].
    for cy in y0..=y1 {
        for cx in x0..=x1 {
            if !map.free(cx, cy) && touches(a, b, (cx, cy)) {
                return false;
            }
        }
    }
    true
}

/// [`segment_clear`] with a summed-area table, so segments whose bounding box holds no obstacle
/// are accepted at once and only blocked cells are tested. Same answers, much faster on the
/// visibility graph.
#[derive(Clone, Debug)]
pub struct Segments<'m> {
    map: &'m Map,
    /// `sum[(y) * (w + 1) + x]` = blocked cells in `[0, x) x [0, y)`.
    sum: Vec<u32>,
}

impl<'m> Segments<'m> {
    /// Precompute the table for `map`.
    pub fn new(map: &'m Map) -> Self {
        let (w, h) = (usize::from(map.width()), usize::from(map.height()));
        let mut sum = vec![0u32; (w + 1) * (h + 1)];
        for y in 0..h {
            for x in 0..w {
                let b = u32::from(map.blocked()[y * w + x]);
                sum[(y + 1) * (w + 1) + x + 1] =
                    b + sum[y * (w + 1) + x + 1] + sum[(y + 1) * (w + 1) + x]
                        - sum[y * (w + 1) + x];
            }
        }
        Segments { map, sum }
    }

    /// Blocked cells in the inclusive box `[x0, x1] x [y0, y1]`.
    fn count(&self, x0: usize, x1: usize, y0: usize, y1: usize) -> u32 {
        let w1 = usize::from(self.map.width()) + 1;
        self.sum[(y1 + 1) * w1 + x1 + 1] + self.sum[y0 * w1 + x0]
            - self.sum[y0 * w1 + x1 + 1]
            - self.sum[(y1 + 1) * w1 + x0]
    }

    /// The segment rule (see [`segment_clear`]).
    pub fn clear(&self, a: Point, b: Point) -> bool {
        let (x0, x1) = (usize::from(a.x.min(b.x)), usize::from(a.x.max(b.x)));
        let (y0, y1) = (usize::from(a.y.min(b.y)), usize::from(a.y.max(b.y)));
        if self.count(x0, x1, y0, y1) == 0 {
            return true;
        }
        let w = usize::from(self.map.width());
        for cy in y0..=y1 {
            // Skip obstacle-free rows of the box quickly.
            if self.count(x0, x1, cy, cy) == 0 {
                continue;
            }
            for cx in x0..=x1 {
                if self.map.blocked()[cy * w + cx] && touches(a, b, (cx as i64, cy as i64)) {
                    return false;
                }
            }
        }
        true
    }
}

/// The exact any-angle optimum through cell centres: the shortest polyline from `start` to `goal`
/// whose vertices are free cell centres and whose segments all obey the segment rule. A* over the
/// visibility graph of all free cells (edges generated lazily), Euclidean heuristic. `None` if
/// unreachable or an end is blocked.
///
/// Returns the length and the vertices.
pub fn any_angle(map: &Map, start: Point, goal: Point) -> Option<(f64, Vec<Point>)> {
    if !map.is_free(start) || !map.is_free(goal) {
        return None;
    }
    let seg = Segments::new(map);
    let free: Vec<usize> = (0..map.cells()).filter(|&i| !map.blocked()[i]).collect();
    let n = map.cells();
    let mut g = vec![f64::INFINITY; n];
    let mut parent = vec![usize::MAX; n];
    let mut closed = vec![false; n];
    let (s, t) = (map.index(start), map.index(goal));
    g[s] = 0.0;
    let mut heap = BinaryHeap::new();
    heap.push(Entry(euclid(start, goal), s));
    while let Some(Entry(_, i)) = heap.pop() {
        if closed[i] {
            continue;
        }
        closed[i] = true;
        let p = map.point(i);
        if i == t {
            let mut path = vec![goal];
            let mut c = t;
            while c != s {
                c = parent[c];
                path.push(map.point(c));
            }
            path.reverse();
            return Some((g[t], path));
        }
        for &j in &free {
            if closed[j] {
                continue;
            }
            let q = map.point(j);
            let nd = g[i] + euclid(p, q);
            // Improve first (cheap), then prove the segment clear (expensive). Anything that
            // cannot beat the best known way to the goal is not worth a segment test either.
            if nd < g[j] && nd + euclid(q, goal) < g[t] && seg.clear(p, q) {
                g[j] = nd;
                parent[j] = i;
                heap.push(Entry(nd + euclid(q, goal), j));
            }
        }
    }
    None
}

/// Both optima for one start/goal pair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Optima {
    /// Shortest 8-connected path (no corner cutting).
    pub opt8: f64,
    /// Shortest path through cell centres with straight segments (segment rule).
    pub any_angle: f64,
}

/// Both optima, or `None` if the goal is unreachable.
pub fn optima(map: &Map, start: Point, goal: Point) -> Option<Optima> {
    let opt8 = opt8(map, start, goal)?;
    let (any_angle, _) = any_angle(map, start, goal)?;
    Some(Optima { opt8, any_angle })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn p(x: u16, y: u16) -> Point {
        Point::new(x, y)
    }

    #[test]
    fn touching_rules() {
        // (0,0)->(2,2) passes exactly through the corners (1,1) and (2,2).
        assert!(touches(p(0, 0), p(2, 2), (1, 0)));
        assert!(touches(p(0, 0), p(2, 2), (0, 1)));
        assert!(touches(p(0, 0), p(2, 2), (1, 1)));
        assert!(!touches(p(0, 0), p(2, 2), (2, 0)));
        assert!(!touches(p(0, 0), p(2, 2), (0, 2)));
        // Horizontal segment grazes nothing above or below.
        assert!(!touches(p(0, 0), p(3, 0), (1, 1)));
        assert!(touches(p(0, 0), p(3, 0), (3, 0)));
        assert!(!touches(p(0, 0), p(3, 0), (4, 0)));
        // (0,0)->(2,1): passes (1.5, 1.0), the top edge of cell (1,1).
        assert!(touches(p(0, 0), p(2, 1), (1, 1)));
        // A point segment touches only its own cell.
        assert!(touches(p(1, 1), p(1, 1), (1, 1)));
        assert!(!touches(p(1, 1), p(1, 1), (0, 0)));
    }

    #[test]
    fn single_steps_are_the_no_corner_cutting_rule() {
        let m = Map::from_rows(&["...", ".#.", "..."]);
        for y in 0..3u16 {
            for x in 0..3u16 {
                let a = p(x, y);
                if !m.is_free(a) {
                    continue;
                }
                for (dx, dy) in MOVES {
                    let (nx, ny) = (i64::from(x) + dx, i64::from(y) + dy);
                    if !(0..3).contains(&nx) || !(0..3).contains(&ny) {
                        continue;
                    }
                    let b = p(nx as u16, ny as u16);
                    assert_eq!(segment_clear(&m, a, b), step_allowed(&m, a, dx, dy));
                }
            }
        }
    }

    #[test]
    fn fast_segments_match_brute_force() {
        let m = Map::from_rows(&[
            "......#...",
            "..#.......",
            ".....##...",
            "#.........",
            "....#...#.",
        ]);
        let s = Segments::new(&m);
        for i in 0..m.cells() {
            for j in 0..m.cells() {
                let (a, b) = (m.point(i), m.point(j));
                assert_eq!(s.clear(a, b), segment_clear(&m, a, b), "{a:?} {b:?}");
            }
        }
    }

    #[test]
    fn astar_matches_dijkstra() {
        let m = Map::from_rows(&[
            "......#...",
            "..#...#...",
            "..#..##...",
            "#.#.......",
            "....#...#.",
        ]);
        let s = p(0, 0);
        let d = dijkstra8(&m, s);
        for (i, &di) in d.iter().enumerate() {
            match opt8(&m, s, m.point(i)) {
                Some(v) => assert!((v - di).abs() < 1e-9),
                None => assert!(di.is_infinite()),
            }
        }
    }

    #[test]
    fn any_angle_on_open_map_is_euclidean() {
        let m = Map::empty(9, 6);
        let (l, path) = any_angle(&m, p(0, 0), p(8, 5)).unwrap();
        assert!((l - euclid(p(0, 0), p(8, 5))).abs() < 1e-12);
        assert_eq!(path, vec![p(0, 0), p(8, 5)]);
    }

    #[test]
    fn unreachable_is_none() {
        // A diagonal wall of touching obstacles.
        let m = Map::from_rows(&["..#", ".#.", "#.."]);
        assert_eq!(opt8(&m, p(0, 0), p(2, 2)), None);
        assert_eq!(any_angle(&m, p(0, 0), p(2, 2)), None);
        assert!(dijkstra8(&m, p(0, 0))[m.index(p(2, 2))].is_infinite());
    }
}
