//! The core's exact A* (`ohaca::astar`, both variants of issue 27's baseline) against the independent
//! references: the `optimal` column of every large map's `.scen` file (8-connected, no corner
//! cutting: `maps/large/README.md`) and `reference::astar8` on random maps. Its path must be
//! valid move by move (`reference::step_allowed`, written without the core's move code) and its
//! step counts must give the optimum.

use ohaca::astar::{self, AstarError, Entry, Search};
use ohaca::{Grid, Point};
use ohaca_host_tests::gen;
use ohaca_host_tests::large::large_maps;
use ohaca_host_tests::maps::{load_scen, maps_dir, Map};
use ohaca_host_tests::reference::{astar8, step_allowed};
use proptest::prelude::*;

/// Run both variants of the core's A* on `map` (the 4-bit [`astar::search`] and the cost-a-cell
/// [`astar::search_costs`]), check the paths they write and that they agree on the optimum;
/// return the 4-bit result and the path's exact length.
fn solve(map: &Map, s: Point, g: Point) -> Result<(Search, f64), AstarError> {
    let a = solve_one(map, s, g, false);
    let b = solve_one(map, s, g, true);
    match (&a, &b) {
        // Both are exact: the same optimum. Their expansions may differ by a few cells (on a
        // tie of f and g the 4-bit variant's held-out neighbour and lazy heap pop in another
        // order than the cost variant's decrease-key), so they are not compared.
        (Ok((_, la)), Ok((_, lb))) => {
            assert_eq!(la, lb, "the variants' lengths differ");
        }
        (Err(ea), Err(eb)) => assert_eq!(ea, eb),
        _ => panic!("4-bit {a:?}, costs {b:?}"),
    }
    a
}

/// One variant: check the path it writes, return the result and the path's exact length
/// (`straight + diagonal * sqrt 2` in f64).
fn solve_one(map: &Map, s: Point, g: Point, costs: bool) -> Result<(Search, f64), AstarError> {
    let grid: Grid<'_> = map.grid();
    let mut nib = vec![0u8; astar::nibble_bytes(map.cells())];
    let mut cost = vec![0u32; map.cells()];
    let mut heap = vec![Entry::EMPTY; 8 * map.cells() + 8];
    let r = if costs {
        astar::search_costs(&grid, s, g, &mut cost, &mut heap)?
    } else {
        astar::search(&grid, s, g, &mut nib, &mut heap)?
    };
    let mut path = vec![Point::default(); r.steps() as usize + 1];
    let n = if costs {
        astar::write_path_costs(&grid, &cost, g, &r, &mut path)?
    } else {
        astar::write_path(&grid, &nib, g, &r, &mut path)?
    };
    assert_eq!(n, path.len());
    assert_eq!((path[0], path[n - 1]), (s, g));
    let (mut st, mut di) = (0u32, 0u32);
    for w in path.windows(2) {
        let dx = i64::from(w[1].x) - i64::from(w[0].x);
        let dy = i64::from(w[1].y) - i64::from(w[0].y);
        assert!(
            step_allowed(map, w[0], dx, dy),
            "{:?} -> {:?} is not a move",
            w[0],
            w[1]
        );
        if dx != 0 && dy != 0 {
            di += 1;
        } else {
            st += 1;
        }
    }
    assert_eq!((st, di), (r.straight, r.diagonal));
    assert_eq!(r.length, ohaca::geometry::steps_length(st, di));
    assert!(r.peak_heap as usize <= r.pushes as usize);
    Ok((r, f64::from(st) + f64::from(di) * std::f64::consts::SQRT_2))
}

/// Every map of `maps/large/`, its 3 longest scenarios and 3 more spread over the file: the step
/// counts give the stated optimum (8 decimals; 5 in `random512-10-0.map.scen`, README).
#[test]
fn large_maps_match_the_scen_optimum() {
    let dir = maps_dir().join("large");
    for lm in large_maps(3) {
        let random = dir.join(format!("{}-random-1.scen", lm.name));
        let scen = if random.exists() {
            random
        } else {
            dir.join(format!("{}.map.scen", lm.name))
        };
        let entries = load_scen(&scen).unwrap();
        let spread = (1..=3).map(|k| &entries[k * (entries.len() - 1) / 3]);
        let cases = lm
            .cases
            .iter()
            .map(|c| (c.start, c.goal, c.stated_opt8))
            .chain(spread.map(|e| (e.start, e.goal, e.optimal)));
        let tol = if lm.name.starts_with("random512") {
            6e-4
        } else {
            1e-5
        };
        for (s, g, opt) in cases {
            let (r, exact) = solve(&lm.map, s, g).unwrap_or_else(|e| panic!("{}: {e}", lm.name));
            println!(
                "{}: {s:?} -> {g:?} {exact:.5} (scen {opt:.5}), {} expansions, peak heap {}",
                lm.name, r.expansions, r.peak_heap
            );
            assert!(
                (exact - opt).abs() < tol,
                "{}: {s:?} -> {g:?}: {exact} vs {opt}",
                lm.name
            );
        }
    }
}

/// The fixed maps of `maps/README.md` and Nav2's depot (`maps/depot.map`).
#[test]
fn fixed_maps_and_the_depot() {
    for (file, s, g, opt) in [
        ("complex-26.map", (0, 0), (25, 25), Some(41.7990)),
        ("simple-18.map", (0, 0), (17, 17), Some(26.9706)),
        ("classic-20.map", (0, 0), (19, 19), Some(37.8995)),
        ("depot.map", DEPOT.0, DEPOT.1, None),
    ] {
        let map = Map::load(maps_dir().join(file)).unwrap();
        let (s, g) = (Point::new(s.0, s.1), Point::new(g.0, g.1));
        let (_, exact) = solve(&map, s, g).unwrap();
        let opt = opt.unwrap_or_else(|| astar8(&map, s, g).unwrap().0);
        assert!((exact - opt).abs() < 5e-5, "{file}: {exact} vs {opt}");
    }
}

/// The depot's far-corner pair (`scripts/bench_sizes.py`, `host/assets/ros/README.md`).
const DEPOT: ((u16, u16), (u16, u16)) = ((9, 4), (596, 300));

proptest! {
    #![proptest_config(gen::config(600))]

    /// Random maps up to 24 x 24: `NoPath` exactly when the reference finds none, else the
    /// reference's optimum.
    #[test]
    fn random_maps_match_the_reference((m, s, g) in gen::case(24)) {
        match (astar8(&m, s, g), solve(&m, s, g)) {
            (None, Err(AstarError::NoPath)) => {}
            (Some((opt, _)), Ok((_, exact))) => {
                prop_assert!((exact - opt).abs() < 1e-9, "{exact} vs {opt}\n{}", m.to_ascii());
            }
            (r, a) => prop_assert!(false, "reference {r:?}, astar {a:?}\n{}", m.to_ascii()),
        }
    }
}
