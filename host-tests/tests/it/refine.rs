//! Property tests of the local search `ohaca::refine` on random maps, against the independent
//! references of `ohaca_host_tests`:
//!
//! - the refined path is a valid 8-connected path from the start to the goal (`check::check_raw`);
//! - it is never longer than the input;
//! - it is the exact 8-connected optimum (`reference::astar8`) when the whole map fits one window;
//! - it is the same whatever the scratch and the output buffer held before, and the same when run
//!   in budget-limited slices through `Refiner::resume`.
//!
//! Inputs: detours (an exact path to a random middle cell, then on to the goal) and the colony's
//! own raw paths (the default plan with a random seed).

use ohaca::refine::{refine, Budget, Refiner, Scratch, DEFAULT_PASSES};
use ohaca::{plan, Params, Point};
use ohaca_host_tests::check::{check_raw, length_tolerance};
use ohaca_host_tests::gen;
use ohaca_host_tests::maps::Map;
use ohaca_host_tests::reference::astar8;
use proptest::prelude::*;

/// Owned scratch for a window of `side * side` cells, filled with `fill`.
struct Owned {
    a: Vec<u32>,
    b: Vec<u32>,
}

impl Owned {
    fn new(side: usize, fill: u32) -> Self {
        let n = Scratch::words(side);
        Owned {
            a: vec![fill; n],
            b: vec![fill.rotate_left(7); n],
        }
    }

    fn scratch(&mut self) -> Scratch<'_> {
        Scratch::new(&mut self.a, &mut self.b)
    }
}

/// Refine with a window of `side`, an output buffer of `spare` extra cells and junk `fill`.
fn run(m: &Map, path: &[Point], side: usize, spare: usize, fill: u32) -> (Vec<Point>, Budget) {
    let mut s = Owned::new(side, fill);
    let mut out = vec![Point::new(fill as u16, 3); path.len() + spare];
    let mut b = Budget::unlimited();
    let k = refine(&m.grid(), path, &mut out, s.scratch(), &mut b).expect("a valid input path");
    out.truncate(k);
    (out, b)
}

/// The shared checks; returns the refined path.
fn check(
    m: &Map,
    s: Point,
    g: Point,
    path: &[Point],
    side: usize,
    salt: u32,
) -> Result<Vec<Point>, TestCaseError> {
    let before = check_raw(m, s, g, path).map_err(TestCaseError::fail)?;
    let (out, b) = run(m, path, side, side, 0);
    let after = check_raw(m, s, g, &out)
        .map_err(|e| TestCaseError::fail(format!("refined path invalid: {e}\n{out:?}")))?;
    prop_assert!(
        after <= before + length_tolerance(before),
        "{after} > {before}"
    );
    let (opt, _) = astar8(m, s, g).expect("reachable");
    prop_assert!(after >= opt - length_tolerance(opt));
    if usize::from(m.width()) <= side && usize::from(m.height()) <= side {
        prop_assert!(
            (after - opt).abs() <= length_tolerance(opt),
            "whole map in one window: {after} vs optimum {opt}"
        );
    }
    // Same result from junk scratch and a tight output buffer (no spare: a longer replacement
    // may then be skipped, so only validity and length hold there).
    let (again, b2) = run(m, path, side, side, salt);
    prop_assert_eq!(&again, &out);
    prop_assert_eq!(b2, b);
    let (tight, _) = run(m, path, side, 0, salt);
    let t = check_raw(m, s, g, &tight).map_err(TestCaseError::fail)?;
    prop_assert!(t <= before + length_tolerance(before));
    // Budget-limited slices give the same path.
    let grid = m.grid();
    let mut buf = vec![Point::default(); path.len() + side];
    let mut r = Refiner::new(&grid, path, &mut buf, DEFAULT_PASSES).expect("valid");
    let mut sc = Owned::new(side, salt);
    let mut calls = 0;
    while !r.resume(&grid, &mut buf, &mut sc.scratch(), &mut Budget::new(7)) {
        calls += 1;
        prop_assert!(calls < 100_000);
    }
    let k = r.finish(&mut buf);
    prop_assert_eq!(&buf[..k], &out[..]);
    Ok(out)
}

/// A valid path with a detour: exact to `mid`, then exact to the goal.
fn detour(m: &Map, s: Point, mid: Point, g: Point) -> Option<Vec<Point>> {
    let (_, mut a) = astar8(m, s, mid)?;
    let (_, b) = astar8(m, mid, g)?;
    a.pop();
    a.extend(b);
    Some(a)
}

proptest! {
    #![proptest_config(gen::config(300))]

    /// Detours on maps up to 24 x 24, with a window that covers the map (exact) or not.
    #[test]
    fn detours_are_refined_validly(
        (m, s, g) in gen::case(24),
        mid in any::<prop::sample::Index>(),
        side in prop::sample::select(vec![8usize, 11, 16, 24]),
        salt in any::<u32>(),
    ) {
        let mut m = m;
        let mid = m.point(mid.index(m.cells()));
        m.set(mid, false);
        let Some(path) = detour(&m, s, mid, g) else {
            return Ok(());
        };
        check(&m, s, g, &path, side, salt)?;
    }

    /// The colony's own raw paths (default plan, random seed) on maps up to 20 x 20.
    #[test]
    fn colony_paths_are_refined_validly(
        (m, s, g) in gen::case(20),
        seed in any::<u64>(),
        side in prop::sample::select(vec![8usize, 13, 20]),
        salt in any::<u32>(),
    ) {
        let mut st = ohaca_host_tests::heap::storage(m.cells());
        let p = Params { seed, ..Params::default() };
        let Ok(pl) = plan(&m.grid(), s, g, &p, st.workspace()) else {
            return Ok(());
        };
        let raw: Vec<Point> = pl.raw().collect();
        check(&m, s, g, &raw, side, salt)?;
    }
}

/// A long path on a map much wider than the window: still valid, shorter, and the work linear.
#[test]
fn long_detour_on_a_wide_map() {
    let rows: Vec<String> = (0..40)
        .map(|y| {
            (0..400)
                .map(|x| {
                    if x % 37 == 5 && y < 12 + (x % 7) {
                        '#'
                    } else {
                        '.'
                    }
                })
                .collect()
        })
        .collect();
    let r: Vec<&str> = rows.iter().map(String::as_str).collect();
    let m = Map::from_rows(&r);
    let (s, g) = (Point::new(0, 30), Point::new(399, 0));
    // Exact legs through cells alternating between rows 24 and 36: a zigzag of 19 local detours.
    let mut path = vec![s];
    let mut at = s;
    for k in 1..=20u16 {
        let to = if k == 20 {
            g
        } else {
            Point::new(20 * k, if k % 2 == 0 { 24 } else { 36 })
        };
        let (_, leg) = astar8(&m, at, to).expect("leg");
        path.extend(&leg[1..]);
        at = to;
    }
    let out = check(&m, s, g, &path, 32, 99).expect("checks");
    let (opt, _) = astar8(&m, s, g).expect("reachable");
    let (before, after) = (
        check_raw(&m, s, g, &path).unwrap(),
        check_raw(&m, s, g, &out).unwrap(),
    );
    eprintln!("before {before} after {after} optimum {opt}");
    assert!(after < before, "{after} {before}");
    assert!(after <= opt * 1.03, "{after} vs {opt}");
    let (_, b) = run(&m, &path, 32, 32, 0);
    // Linear: well below one full window per raw cell.
    assert!(
        b.expanded < 20 * path.len() as u64,
        "{b:?} for {} cells",
        path.len()
    );
}
