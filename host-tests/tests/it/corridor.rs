//! Property tests of the corridor search (`ohaca::corridor`, the last step of OHACA's default
//! smoothing on small maps) against the independent any-angle reference of `ohaca_host_tests`:
//!
//! - on random maps, starting from the colony's smoothed path of the greedy (paper) rule: the
//!   result is valid under the segment rule (the reference's own segment test), starts and ends
//!   where the input did, is never longer than the input and never shorter than the exact
//!   any-angle optimum;
//! - with a radius that covers the whole map it *is* the exact any-angle optimum
//!   (`reference::any_angle`, a different search over all free cells);
//! - it returns bit for bit the path of the plain search it replaced ([`plain`] below: every
//!   improving edge walked by `segment_clear`, the open list scanned for its least `g + h`):
//!   the remembered blocked cells (shadows) only skip walks whose answer is known, and a run of
//!   live cells is skipped only when no cell of it can improve, so a shadow that hid a clear
//!   edge, a run skipped wrongly, or any change of order or ties, fails here.

use ohaca::corridor::{shortest, RADIUS};
use ohaca::geometry::{distance, drop_collinear, polyline_length, segment_clear};
use ohaca::Grid;
use ohaca::{plan, Params, Point, SmoothingKind};
use ohaca_host_tests::gen;
use ohaca_host_tests::maps::Map;
use ohaca_host_tests::reference::{any_angle, Segments};
use proptest::prelude::*;

/// The greedy-smoothed waypoints of a default colony plan, or `None` when there is no path.
fn greedy_waypoints(m: &Map, s: Point, g: Point, seed: u64) -> Option<Vec<Point>> {
    let grid = m.grid();
    let mut st = ohaca_host_tests::heap::storage(m.cells());
    let p = Params {
        seed,
        smoothing: SmoothingKind::Greedy,
        ..Params::default()
    };
    let plan = plan(&grid, s, g, &p, st.workspace()).ok()?;
    Some(plan.waypoints().to_vec())
}

/// The corridor search as it was before its shadows (main cfc0e2e, `src/polish/corridor.rs`),
/// written plainly: the corridor's cells in the same order, A* over their visibility graph with
/// the same lower bounds, the same first-minimum open list (the last open cell fills a taken
/// one's place) and the same tests, each improving edge walked by `segment_clear`.
fn plain(grid: &Grid<'_>, input: &[Point], radius: u16) -> Vec<Point> {
    let n = input.len();
    if n < 3 {
        return input.to_vec();
    }
    let (start, goal) = (input[0], input[n - 1]);
    let bound = polyline_length(input);
    let cells = grid.cells();
    let (mut g, mut parent) = (vec![f32::INFINITY; cells], vec![0usize; cells]);
    let (mut h, mut cand, mut closed) = (vec![0f32; cells], vec![false; cells], vec![false; cells]);
    // The corridor: free cells within `radius` (Chebyshev) of the cell nearest each segment at
    // each of its columns (or rows), in that order.
    let mut list = Vec::new();
    let r = i64::from(radius);
    for w in input.windows(2) {
        let (a, b) = (w[0], w[1]);
        let (ax, ay) = (i64::from(a.x), i64::from(a.y));
        let (dx, dy) = (i64::from(b.x) - ax, i64::from(b.y) - ay);
        let steps = dx.abs().max(dy.abs()).max(1);
        let at = |d: i64, k: i64| (2 * d * k + steps).div_euclid(2 * steps);
        for k in 0..=steps {
            let (x, y) = (ax + at(dx, k), ay + at(dy, k));
            for cy in (y - r).max(0)..=(y + r).min(i64::from(grid.height()) - 1) {
                for cx in (x - r).max(0)..=(x + r).min(i64::from(grid.width()) - 1) {
                    let q = Point::new(cx as u16, cy as u16);
                    if grid.is_free(q) && !cand[grid.index(q)] {
                        cand[grid.index(q)] = true;
                        list.push(q);
                    }
                }
            }
        }
    }
    for &q in &list {
        h[grid.index(q)] = distance(q, goal);
    }
    let (s, t) = (grid.index(start), grid.index(goal));
    g[s] = 0.0;
    let mut open = vec![s];
    while !open.is_empty() {
        let mut best: Option<(usize, f32)> = None;
        for (k, &c) in open.iter().enumerate() {
            let f = g[c] + h[c];
            if best.is_none_or(|(_, bf)| f < bf) {
                best = Some((k, f));
            }
        }
        let i = open.swap_remove(best.unwrap().0);
        closed[i] = true;
        if i == t {
            break;
        }
        let (p, gi) = (grid.point(i), g[i]);
        let limit = g[t].min(bound);
        for &q in &list {
            let j = grid.index(q);
            if closed[j] {
                continue;
            }
            let (dx, dy) = (p.x.abs_diff(q.x), p.y.abs_diff(q.y));
            let cheb = f32::from(dx.max(dy));
            let diag = (f32::from(dx) + f32::from(dy)) * core::f32::consts::FRAC_1_SQRT_2;
            let low = gi + if cheb > diag { cheb } else { diag };
            if low >= g[j] || low + h[j] >= limit {
                continue;
            }
            let nd = gi + distance(p, q);
            if nd < g[j] && nd + h[j] < limit && segment_clear(grid, p, q) {
                if g[j] == f32::INFINITY {
                    open.push(j);
                }
                g[j] = nd;
                parent[j] = i;
            }
        }
    }
    let improves = g[t] < bound - 1e-4;
    if !improves {
        return input.to_vec();
    }
    let mut out = vec![grid.point(t)];
    let mut c = t;
    while c != s {
        c = parent[c];
        out.push(grid.point(c));
    }
    out.reverse();
    let len = out.len();
    let m = drop_collinear(&mut out, len);
    out.truncate(m);
    out
}

fn corridor(m: &Map, input: &[Point], radius: u16) -> Vec<Point> {
    corridor_in(m, input, radius, 3 * m.cells())
}

/// [`corridor`] with a list of `words` words: from `2 V + 3 V / 16` (for `V` corridor cells, at
/// most the map's cells) the search skips runs of live cells, below it scans them all.
fn corridor_in(m: &Map, input: &[Point], radius: u16, words: usize) -> Vec<Point> {
    // Room for a path of more points than the input, as the planner's `points` has.
    let mut pts = input.to_vec();
    pts.resize(m.cells(), Point::new(0, 0));
    let mut cell = vec![[0.0f32; 4]; m.cells()];
    let mut list = vec![0u32; words];
    let n = shortest(
        &m.grid(),
        &mut pts,
        input.len(),
        radius,
        &mut cell,
        &mut list,
    );
    pts.truncate(n);
    pts
}

proptest! {
    #![proptest_config(gen::config(96))]

    #[test]
    fn the_corridor_path_is_valid_never_longer_and_exact_with_the_whole_map(
        (m, s, g) in gen::case(24),
        seed in 0u64..1000,
    ) {
        let Some(input) = greedy_waypoints(&m, s, g, seed) else { return Ok(()) };
        let (opt, _) = any_angle(&m, s, g).expect("the colony found a path, so one exists");
        let seg = Segments::new(&m);
        let before = f64::from(polyline_length(&input));
        for radius in [RADIUS, 64] {
            let out = corridor(&m, &input, radius);
            prop_assert_eq!(out.first(), Some(&s));
            prop_assert_eq!(out.last(), Some(&g));
            for w in out.windows(2) {
                prop_assert!(seg.clear(w[0], w[1]), "{:?} -> {:?} not clear", w[0], w[1]);
            }
            let after = f64::from(polyline_length(&out));
            prop_assert!(after <= before + 1e-9, "radius {radius}: {after} > {before}");
            prop_assert!(after >= opt - 1e-3, "radius {radius}: {after} < optimum {opt}");
            if radius == 64 {
                prop_assert!((after - opt).abs() < 1e-3, "whole map: {after} against {opt}");
            }
        }
    }

    /// The corridor search returns exactly the plain search's path (every point), on the
    /// colony's smoothed paths of random maps, with the planner's radius and a wider one.
    #[test]
    fn the_corridor_path_is_the_plain_search_s_bit_for_bit(
        (m, s, g) in gen::case(24),
        seed in 0u64..1000,
    ) {
        let Some(input) = greedy_waypoints(&m, s, g, seed) else { return Ok(()) };
        for radius in [RADIUS, 8] {
            let want = plain(&m.grid(), &input, radius);
            // With runs skipped (3 words a cell) and, mostly, without (2 words a cell).
            for words in [3 * m.cells(), 2 * m.cells()] {
                let out = corridor_in(&m, &input, radius, words);
                prop_assert_eq!(&out, &want, "radius {}, {} words", radius, words);
            }
        }
    }
}
