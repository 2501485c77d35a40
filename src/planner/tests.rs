//! Unit tests of the planner.

use super::*;
use crate::error::{Endpoint, Param};
use crate::grid::Point;

/// Storage for maps of up to 64 cells.
type S64 = Storage<2, 64, 128, 64>;
/// Storage for maps of up to 32 cells.
type S32 = Storage<1, 32, 64, 32>;

fn grid(rows: &[&str]) -> (Vec<u8>, u16, u16) {
    crate::testutil::bits(rows)
}

const ROWS: [&str; 6] = [
    "........", //
    ".####...", //
    "....#.#.", //
    ".##.#.#.", //
    "......#.", //
    "........", //
];

#[test]
fn finds_a_path_on_a_small_map() {
    let (b, w, h) = grid(&ROWS);
    let g = Grid::new(w, h, &b).unwrap();
    let mut s: S64 = Storage::new();
    let plan = plan(
        &g,
        Point::new(0, 0),
        Point::new(7, 5),
        &Params::default(),
        s.workspace(),
    )
    .unwrap();
    let raw: Vec<_> = plan.raw().collect();
    assert_eq!(raw[0], Point::new(0, 0));
    assert_eq!(*raw.last().unwrap(), Point::new(7, 5));
    assert!(plan.length <= plan.raw_length + 1e-4);
    assert_eq!(plan.waypoints()[0], Point::new(0, 0));
    assert_eq!(*plan.waypoints().last().unwrap(), Point::new(7, 5));
}

#[test]
fn errors() {
    let (b, w, h) = grid(&ROWS);
    let g = Grid::new(w, h, &b).unwrap();
    let mut s: S64 = Storage::new();
    let p = Params::default();
    let e = |st: Point, go: Point, p: &Params, s: &mut S64| {
        plan(&g, st, go, p, s.workspace()).map(|_| ()).unwrap_err()
    };
    assert_eq!(
        e(Point::new(8, 0), Point::new(0, 0), &p, &mut s),
        Error::OutOfBounds(Endpoint::Start)
    );
    assert_eq!(
        e(Point::new(0, 0), Point::new(1, 1), &p, &mut s),
        Error::Blocked(Endpoint::Goal)
    );
    assert_eq!(
        e(
            Point::new(0, 0),
            Point::new(0, 0),
            &Params { ants: 0, ..p },
            &mut s
        ),
        Error::BadParam(Param::Ants)
    );
    assert_eq!(
        e(
            Point::new(0, 0),
            Point::new(0, 0),
            &Params { rho: 0.0, ..p },
            &mut s
        ),
        Error::BadParam(Param::Rho)
    );
    assert_eq!(
        e(
            Point::new(0, 0),
            Point::new(0, 0),
            &Params { rho: f32::NAN, ..p },
            &mut s
        ),
        Error::BadParam(Param::Rho)
    );
    let mut small: S32 = Storage::new();
    assert_eq!(
        plan(
            &g,
            Point::new(0, 0),
            Point::new(1, 0),
            &p,
            small.workspace()
        )
        .map(|_| ())
        .unwrap_err(),
        Error::MapTooLarge {
            cells: 48,
            capacity: 32
        }
    );
    // Walled-in goal.
    let (b, w, h) = grid(&["..#.", ".###", "...."]);
    let g2 = Grid::new(w, h, &b).unwrap();
    assert_eq!(
        plan(&g2, Point::new(0, 0), Point::new(3, 0), &p, s.workspace())
            .map(|_| ())
            .unwrap_err(),
        Error::NoPath
    );
}

#[test]
fn start_equals_goal() {
    let (b, w, h) = grid(&ROWS);
    let g = Grid::new(w, h, &b).unwrap();
    let mut s: S64 = Storage::new();
    let plan = plan(
        &g,
        Point::new(3, 2),
        Point::new(3, 2),
        &Params::default(),
        s.workspace(),
    )
    .unwrap();
    assert_eq!(plan.waypoints(), &[Point::new(3, 2)]);
    assert_eq!(plan.raw_length, 0.0);
}

#[test]
fn storage_size_matches_the_formula() {
    assert_eq!(core::mem::size_of::<CurvePoint>(), 16);
    type Device = Storage<{ crate::bitmap::words(65536) }, 1024, 4096, 1024>;
    // Pheromone and increments, two bit sets, the move table, four tours, points, links, curve,
    // the coarse route.
    let want =
        2 * 16 * 1024 + 2 * 8192 + 1024 + 4 * 1024 + 4 * 1024 + 4 * 4096 + 16 * 128 + 4 * 4096;
    assert_eq!(Device::BYTES, want);
    // `Workspace::bytes` for the same capacities (2047 steps) gives the same but for the fourth
    // byte of each tour the storage rounds up to.
    assert_eq!(
        Workspace::bytes(65536, 1023, false, 128) + 1024 + 4 * (4096 - 2048),
        want - 4
    );
}

#[test]
fn paper_preset_differs_from_default_only_where_documented() {
    let d = Params::default();
    assert_eq!(
        Params::paper(),
        Params {
            patience: 0,
            dead_end: crate::DeadEnd::Die,
            smoothing: crate::SmoothingKind::Greedy,
            tighten: false,
            prune: false,
            warm_patience: 0,
            ..d
        }
    );
    assert_eq!(Params::paper().validate(), Ok(()));
}

#[test]
fn deterministic_per_seed() {
    let (b, w, h) = grid(&ROWS);
    let g = Grid::new(w, h, &b).unwrap();
    let run = |seed, alg| {
        let mut s: S64 = Storage::new();
        let p = Params {
            seed,
            algorithm: alg,
            ..Params::default()
        };
        let pl = plan(&g, Point::new(0, 5), Point::new(7, 0), &p, s.workspace()).unwrap();
        (
            pl.raw().collect::<Vec<_>>(),
            pl.waypoints().to_vec(),
            pl.length.to_bits(),
            pl.iterations,
            pl.moves,
        )
    };
    for alg in Algorithm::ALL {
        assert_eq!(run(7, alg), run(7, alg));
    }
}
