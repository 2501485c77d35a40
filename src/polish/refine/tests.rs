//! Tests of the local search: validity, never longer, exactness in one window, budgets and
//! resuming, determinism.

use super::*;
use crate::map::grid::{DX, DY};

fn grid(rows: &[&str]) -> (Vec<u8>, u16, u16) {
    crate::testutil::bits(rows)
}

fn open(w: usize, h: usize) -> (Vec<u8>, u16, u16) {
    (vec![0u8; (w * h).div_ceil(8)], w as u16, h as u16)
}

/// Owned scratch for a window of `cells` cells, filled with junk.
struct Heapless {
    a: Vec<u32>,
    b: Vec<u32>,
}

impl Heapless {
    fn new(cells: usize, fill: u8) -> Self {
        let words = cells + cells.div_ceil(2);
        Heapless {
            a: vec![u32::from(fill) * 0x0101_0101; words],
            b: vec![u32::from(fill).rotate_left(5); words],
        }
    }
    fn scratch(&mut self) -> Scratch<'_> {
        Scratch::new(&mut self.a, &mut self.b)
    }
}

/// Length in search units; panics unless `p` is a valid path on `g`.
fn cost(g: &Grid<'_>, p: &[Point]) -> u32 {
    assert!(g.is_free(p[0]));
    p.windows(2)
        .map(|s| {
            let d = crate::map::grid::direction(s[0], s[1]).expect("neighbours");
            assert_eq!(g.step(s[0], d), Some(s[1]), "illegal step {s:?}");
            step_cost(s[0], s[1])
        })
        .sum()
}

fn run(g: &Grid<'_>, path: &[Point], cells: usize) -> (Vec<Point>, Budget) {
    let mut out = vec![Point::default(); path.len() + 16];
    let mut s = Heapless::new(cells, 0xA5);
    let mut b = Budget::unlimited();
    let k = refine(g, path, &mut out, s.scratch(), &mut b).unwrap();
    out.truncate(k);
    assert_eq!(out[0], path[0]);
    assert_eq!(out[k - 1], *path.last().unwrap());
    assert!(cost(g, &out) <= cost(g, path));
    (out, b)
}

/// A path that walks `dirs` from `start`.
fn walk(start: Point, dirs: &[u8]) -> Vec<Point> {
    let mut p = vec![start];
    for &d in dirs {
        let q = *p.last().unwrap();
        p.push(Point::new(
            (i32::from(q.x) + DX[d as usize]) as u16,
            (i32::from(q.y) + DY[d as usize]) as u16,
        ));
    }
    p
}

/// A 10 x 8 map with a wall of three cells, and a detour around it: from (1,3) down to row 7,
/// right to x 8, up to (8,3). Its optimum (over or under the wall) is 4 diagonals and 3 straight
/// steps.
fn detour() -> ((Vec<u8>, u16, u16), Vec<Point>) {
    let rows = [
        "..........",
        "..........",
        "....#.....",
        "....#.....",
        "....#.....",
        "..........",
        "..........",
        "..........",
    ];
    let mut dirs = vec![2u8; 4];
    dirs.extend([0u8; 7]);
    dirs.extend([6u8; 4]);
    (grid(&rows), walk(Point::new(1, 3), &dirs))
}

#[test]
fn detour_becomes_the_optimum_inside_one_window() {
    // Around a wall: down, right along the bottom, up; the optimum hugs the wall's end.
    let ((b, w, h), path) = detour();
    let g = Grid::new(w, h, &b).unwrap();
    let (out, b) = run(&g, &path, 64 * 64);
    // Optimum (over or under the wall): 4 diagonals and 3 straight steps.
    assert_eq!(cost(&g, &out), 4 * DIAGONAL + 3 * STRAIGHT, "{out:?}");
    assert!(b.improved >= 1 && b.expanded > 0);
}

#[test]
fn long_zigzag_on_a_map_wider_than_the_window() {
    // 300 x 12 open map; the path zigzags between rows 2 and 8 all the way.
    let (b, w, h) = open(300, 12);
    let g = Grid::new(w, h, &b).unwrap();
    let mut dirs = vec![];
    for k in 0..50 {
        let d = if k % 2 == 0 { 1 } else { 7 }; // SE / NE
        dirs.extend([d; 5]);
    }
    dirs.extend([0; 49]);
    let path = walk(Point::new(0, 2), &dirs);
    assert_eq!(path.last().unwrap(), &Point::new(299, 2));
    let (out, b) = run(&g, &path, 32 * 32);
    // Straight along row 2 is the optimum. Windows see only local pieces: a one-row offset
    // whose two diagonals lie further apart than a window can stay (each costs
    // `DIAGONAL - STRAIGHT` extra); the zigzag itself (100 diagonals) is gone.
    let opt = 299 * STRAIGHT;
    let c = cost(&g, &out);
    let ys: Vec<(u16, u16)> = out
        .windows(2)
        .filter(|w| w[0].y != w[1].y)
        .map(|w| (w[0].x, w[0].y))
        .collect();
    assert!(
        c <= opt + 8 * (DIAGONAL - STRAIGHT),
        "{c} vs {opt} {b:?} {ys:?}"
    );
    assert!(c < cost(&g, &path) - 90 * (DIAGONAL - STRAIGHT));
    // Linear: windows are a small multiple of path / window.
    assert!(b.windows < 4 * 2 * (path.len() as u32 / 8), "{b:?}");
}

#[test]
fn never_longer_and_deterministic_whatever_the_scratch_held() {
    let rows = [
        "....#.......#.....",
        "..#.#..###..#..#..",
        "..#....#.......#..",
        "..####.#.#####.#..",
        ".......#.....#....",
    ];
    let (b, w, h) = grid(&rows);
    let g = Grid::new(w, h, &b).unwrap();
    // A wandering but valid path: BFS-free hand walk along row 4 then up the right side.
    let mut dirs = vec![0u8; 6]; // (0,4) -> (6,4)
    dirs.extend([6u8; 4]); // up to (6,0)
    dirs.extend([0u8; 5]); // -> (11,0)
    dirs.extend([2u8, 2]); // (11,2)
    dirs.extend([0u8; 3]); // (14,2)
    dirs.extend([2u8, 2]); // (14,4)
    dirs.extend([0u8; 3]); // (17,4)
    let path = walk(Point::new(0, 4), &dirs);
    let (a, _) = run(&g, &path, 64 * 64);
    for fill in [0u8, 0xFF, 0x3C] {
        let mut out = vec![Point::new(7, 7); path.len() + 3];
        let mut s = Heapless::new(64 * 64, fill);
        let k = refine(&g, &path, &mut out, s.scratch(), &mut Budget::unlimited()).unwrap();
        assert_eq!(&out[..k], &a[..]);
    }
    // Whole map in one window: the exact optimum, and fewer cells.
    assert!(cost(&g, &a) < cost(&g, &path));
}

#[test]
fn too_little_scratch_returns_the_input() {
    let (b, w, h) = open(20, 20);
    let g = Grid::new(w, h, &b).unwrap();
    let path = walk(Point::new(0, 0), &[0, 2, 0, 2, 0, 2, 0, 2]);
    let (out, bud) = run(&g, &path, MIN_SIDE * MIN_SIDE - 1);
    assert_eq!(out, path);
    assert_eq!(bud, Budget::unlimited());
    // One more cell side and it works.
    let (out, _) = run(&g, &path, MIN_SIDE * MIN_SIDE);
    assert_eq!(cost(&g, &out), 4 * DIAGONAL);
}

#[test]
fn bad_inputs_are_errors() {
    let (b, w, h) = open(8, 8);
    let g = Grid::new(w, h, &b).unwrap();
    let mut out = vec![Point::default(); 8];
    let mut s = Heapless::new(64, 0);
    let mut bud = Budget::unlimited();
    let jump = [Point::new(0, 0), Point::new(2, 0)];
    assert_eq!(
        refine(&g, &jump, &mut out, s.scratch(), &mut bud),
        Err(Error::NoPath)
    );
    assert_eq!(
        refine(&g, &[], &mut out, s.scratch(), &mut bud),
        Err(Error::NoPath)
    );
    let off = [Point::new(8, 0)];
    assert_eq!(
        refine(&g, &off, &mut out, s.scratch(), &mut bud),
        Err(Error::NoPath)
    );
    let long = walk(Point::new(0, 0), &[0; 7]);
    assert_eq!(
        refine(&g, &long, &mut out[..7], s.scratch(), &mut bud),
        Err(Error::MapTooLarge {
            cells: 8,
            capacity: 7
        })
    );
    // A single cell is a path.
    assert_eq!(
        refine(&g, &long[..1], &mut out, s.scratch(), &mut bud),
        Ok(1)
    );
}

#[test]
fn a_budget_stops_and_resumes_to_the_same_result() {
    // A zigzag through scattered obstacles (on open ground the windows would take their straight
    // lines, `line`, and expand nothing).
    let (mut b, w, h) = open(200, 30);
    for x in (4..200).step_by(5) {
        let i = 6 * 200 + x;
        b[i / 8] |= 1 << (i % 8);
    }
    let g = Grid::new(w, h, &b).unwrap();
    let mut dirs = vec![];
    for k in 0..39 {
        dirs.extend(if k % 2 == 0 {
            [1u8, 1, 0, 0, 0]
        } else {
            [7u8, 7, 0, 0, 0]
        });
    }
    let path = walk(Point::new(0, 5), &dirs);
    assert!(cost(&g, &path) > 0);
    let (whole, total) = run(&g, &path, 24 * 24);
    let mut out = vec![Point::default(); path.len() + 16];
    let mut s = Heapless::new(24 * 24, 0);
    let mut r = Refiner::new(&g, &path, &mut out, DEFAULT_PASSES).unwrap();
    let mut calls = 0;
    let mut spent = Budget::unlimited();
    loop {
        let mut bud = Budget::new(50);
        calls += 1;
        let done = r.resume(&g, &mut out, &mut s.scratch(), &mut bud);
        // Stops at most one window past the limit.
        assert!(bud.expanded < 50 + 24 * 24);
        spent.expanded += bud.expanded;
        spent.windows += bud.windows;
        if done {
            break;
        }
    }
    let k = r.finish(&mut out);
    assert_eq!(&out[..k], &whole[..]);
    assert_eq!(spent.expanded, total.expanded);
    assert_eq!(spent.windows, total.windows);
    assert!(calls > 3, "{calls}");
}

#[test]
fn a_memo_changes_no_path() {
    // The memo skips a search only when a record holds the same ends and box and says the piece
    // would not improve: the refined path must be the same, bit for bit, with or without it,
    // also cut into budgets with the memo reopened at each (as the planner does).
    let (mut remembered, mut searched) = (0u32, 0u32);
    for case in 0..16u64 {
        let density = 0.05 + 0.008 * case as f32;
        let mut rng = crate::rng::Xoshiro128pp::from_u64(case);
        let (b, path) = crate::testutil::heading_walk(&mut rng, 150, 60, density, 400, 200);
        let g = Grid::new(150, 60, &b).unwrap();
        let cells = 20 * 20;
        let (want, plain) = run(&g, &path, cells);
        // At once.
        let mut out = vec![Point::default(); path.len() + 16];
        let mut s = Heapless::new(cells, 0x5A);
        let mut words = vec![0xDEAD_BEEFu32; crate::polish::refine::memo_words(8)];
        let memo = Memo::clear(&mut words);
        let mut budget = Budget::unlimited();
        let k = refine(
            &g,
            &path,
            &mut out,
            s.scratch().with_memo(memo),
            &mut budget,
        )
        .unwrap();
        assert_eq!(&out[..k], &want[..], "case {case}");
        assert_eq!(budget.improved, plain.improved, "case {case}");
        assert_eq!(
            budget.windows + budget.remembered,
            plain.windows,
            "case {case}"
        );
        remembered += budget.remembered;
        searched += budget.windows;
        // Records that differ from a real search only in the box, or only in one end, and claim
        // no window could improve: none may be taken for that search (a key that leaves out the
        // box or an end takes them, and a window that would improve is skipped).
        let held = words[1] as usize;
        let records: Vec<Vec<u32>> = words[2..]
            .chunks_exact(RECORD_WORDS)
            .take(held)
            .map(<[u32]>::to_vec)
            .collect();
        let mut poisoned = vec![0u32; crate::polish::refine::memo_words(4 * held)];
        let mut bad = Memo::clear(&mut poisoned);
        let cell = |v: u32| Point::new(v as u16, (v >> 16) as u16);
        for r in &records {
            let (ps, pt, corner, size) = (cell(r[0]), cell(r[1]), cell(r[2]), cell(r[3]));
            let bx = |x0: u16, w: u16| Box2 {
                x0,
                y0: corner.y,
                w: usize::from(w),
                h: usize::from(size.y),
            };
            let shifted = |p: Point| Point::new(p.x ^ 1, p.y);
            for key in [
                memo::Key::new(ps, pt, &bx(corner.x ^ 1, size.x)),
                memo::Key::new(ps, pt, &bx(corner.x, size.x ^ 1)),
                memo::Key::new(shifted(ps), pt, &bx(corner.x, size.x)),
                memo::Key::new(ps, shifted(pt), &bx(corner.x, size.x)),
            ] {
                bad.put(key, u32::MAX);
            }
        }
        let mut out = vec![Point::default(); path.len() + 16];
        let memo = Memo::reopen(&mut poisoned);
        let mut b = Budget::unlimited();
        let k = refine(&g, &path, &mut out, s.scratch().with_memo(memo), &mut b).unwrap();
        assert_eq!(&out[..k], &want[..], "poisoned, case {case}");
        // In pieces of a few hundred expansions, the memo reopened each time.
        let mut out = vec![Point::default(); path.len() + 16];
        let mut r = Refiner::new(&g, &path, &mut out, DEFAULT_PASSES).unwrap();
        Memo::clear(&mut words);
        let mut budget = Budget::new(0);
        loop {
            budget.limit = budget.expanded + 300;
            let memo = Memo::reopen(&mut words);
            let mut scratch = s.scratch().with_memo(memo);
            if r.resume(&g, &mut out, &mut scratch, &mut budget) {
                break;
            }
        }
        let k = r.finish(&mut out);
        assert_eq!(&out[..k], &want[..], "pieces, case {case}");
    }
    // The memo was used, and saved searches.
    assert!(remembered > 10, "{remembered} remembered of {searched}");
}

#[test]
fn a_line_has_the_octile_cost_and_ends_at_its_goal() {
    // Every direction and slope: `max(dx, dy)` 8-connected moves from `a` to `b`, costing
    // exactly `octile(a, b)` (what `line`'s proof rests on).
    let a = Point::new(20, 20);
    for bx in 0..41u16 {
        for by in 0..41u16 {
            let b = Point::new(bx, by);
            let l = line::Line::new(a, b);
            let n = l.len();
            let mut cells = vec![a];
            cells.extend(l);
            assert_eq!(cells.len() as u32, n + 1);
            assert_eq!(*cells.last().unwrap(), b);
            let c: u32 = cells
                .windows(2)
                .map(|s| {
                    assert!(
                        crate::map::grid::direction(s[0], s[1]).is_some(),
                        "{a:?}->{b:?}"
                    );
                    step_cost(s[0], s[1])
                })
                .sum();
            assert_eq!(c, octile(a, b), "{a:?}->{b:?}");
        }
    }
}

#[test]
fn a_line_is_taken_only_when_free() {
    // A window takes the straight line between its ends instead of searching only when every
    // move of it is allowed. The line from (0,0) to (2,1) is (1,0) then the diagonal to (2,1).
    // - `corner`: (2,0) blocked, so the diagonal cuts a corner; the optimum (0,0) (1,1) (2,1)
    //   has the same cost and must come from the search.
    // - `cell`: (1,0) blocked, the line enters it.
    // `run` panics on an illegal step: a line taken without either check fails here.
    let cases: [(&str, [&str; 4], &[u8]); 2] = [
        ("corner", ["..#.", "....", "....", "...."], &[2, 0, 0]),
        ("cell", [".#..", "....", "....", "...."], &[2, 1, 7]),
    ];
    for (name, rows, dirs) in cases {
        let (b, w, h) = grid(&rows);
        let g = Grid::new(w, h, &b).unwrap();
        let path = walk(Point::new(0, 0), dirs);
        assert_eq!(*path.last().unwrap(), Point::new(2, 1), "{name}");
        assert!(!line::free(&g, path[0], Point::new(2, 1)), "{name}");
        let (out, budget) = run(&g, &path, 16 * 16);
        assert_eq!(budget.lines, 0, "{name}");
        assert!(budget.windows > 0 && budget.improved > 0, "{name}");
        assert!(cost(&g, &out) < cost(&g, &path), "{name}");
    }
    // On open ground the same detour is answered by its line, without a search.
    let (b, w, h) = open(4, 4);
    let g = Grid::new(w, h, &b).unwrap();
    let path = walk(Point::new(0, 0), &[2, 0, 0]);
    let (out, budget) = run(&g, &path, 16 * 16);
    assert_eq!((budget.lines, budget.windows), (1, 0));
    assert_eq!(
        out,
        vec![Point::new(0, 0), Point::new(1, 0), Point::new(2, 1)]
    );
}

#[test]
fn a_whole_map_window_that_replaces_the_whole_path_ends_the_refinement() {
    // The detour map of `detour_becomes_the_optimum_inside_one_window` fits one window: the
    // first search is the exact optimum on the map, so no second window looks again.
    let ((b, w, h), path) = detour();
    let g = Grid::new(w, h, &b).unwrap();
    let (out, b) = run(&g, &path, 64 * 64);
    assert_eq!(cost(&g, &out), 4 * DIAGONAL + 3 * STRAIGHT, "{out:?}");
    assert_eq!((b.windows, b.improved), (1, 1), "{b:?}");
}

#[test]
fn a_window_smaller_than_the_map_looks_again_after_replacing_the_whole_path() {
    // A 40 x 40 map and a 16 x 16 window: the whole path (a detour around one blocked cell)
    // fits the window, but the window is not the map, so its optimum is not known to be the
    // map's and the refinement goes on (the window over the new path is searched again).
    let mut rows = vec!["........................................".to_string(); 40];
    rows[2].replace_range(6..7, "#");
    let rows: Vec<&str> = rows.iter().map(String::as_str).collect();
    let (b, w, h) = grid(&rows);
    let g = Grid::new(w, h, &b).unwrap();
    // (2,2) -> down to row 6, east to x 10, up to (10,2).
    let mut dirs = vec![2u8; 4];
    dirs.extend([0u8; 8]);
    dirs.extend([6u8; 4]);
    let path = walk(Point::new(2, 2), &dirs);
    let (out, b) = run(&g, &path, 16 * 16);
    assert_eq!(cost(&g, &out), 6 * STRAIGHT + 2 * DIAGONAL, "{out:?}");
    assert_eq!(b.lines, 0, "{b:?}");
    assert!(b.improved == 1 && b.windows >= 2, "{b:?}");
}
