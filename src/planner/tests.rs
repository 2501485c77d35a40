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

/// Run to the end; the plan's raw path and the final pheromone.
fn run_to_end(run: Run<'_, '_>) -> (Vec<Point>, bool, u16) {
    let mut run = run;
    while run.step() {}
    let p = run.finish().unwrap();
    (p.raw().collect(), p.warm, p.iterations)
}

#[test]
fn a_warm_start_without_memory_is_the_cold_plan() {
    let (b, w, h) = grid(&ROWS);
    let g = Grid::new(w, h, &b).unwrap();
    let (s, goal) = (Point::new(0, 0), Point::new(7, 5));
    let p = Params::default();
    let mut st: S64 = Storage::new();
    let cold = run_to_end(Run::new(&g, s, goal, &p, st.workspace()).unwrap());
    let cold_tau = st.workspace().pheromone().to_vec();
    let mut st: S64 = Storage::new();
    let mut memory = Memory::new();
    let warm = run_to_end(Run::warm(&g, s, goal, &p, st.workspace(), &mut memory).unwrap());
    assert_eq!(cold, warm);
    assert!(!warm.1);
    assert_eq!(st.workspace().pheromone(), &cold_tau[..]);
    assert!(memory.is_warm_for(w, h, goal));
    // `Run::cold` never keeps the colony, and records its own.
    let mut st: S64 = Storage::new();
    let again = run_to_end(Run::cold(&g, s, goal, &p, st.workspace(), &mut memory).unwrap());
    assert_eq!(again, cold);
    assert!(memory.is_warm_for(w, h, goal));
}

#[test]
fn a_warm_start_keeps_the_pheromone_away_from_changes_and_resets_it_near_them() {
    // 32 x 32 open map: one pheromone entry per cell.
    let rows: Vec<String> = (0..32).map(|_| ".".repeat(32)).collect();
    let rows: Vec<&str> = rows.iter().map(String::as_str).collect();
    let (mut bits, w, h) = grid(&rows);
    let goal = Point::new(31, 31);
    let p = Params::default();
    let mut st: Storage<{ crate::bitmap::words(1024) }, 1024, 2048, 1024> = Storage::new();
    let mut memory = Memory::new();
    {
        let g = Grid::new(w, h, &bits).unwrap();
        run_to_end(Run::warm(&g, Point::new(0, 0), goal, &p, st.workspace(), &mut memory).unwrap());
    }
    let before = st.workspace().pheromone().to_vec();
    // Block (20, 3): entries within REPAIR_RADIUS + 1 of it go back to tau0, the rest stay.
    let c = Point::new(20, 3);
    let i = usize::from(c.y) * 32 + usize::from(c.x);
    bits[i / 8] |= 1 << (i % 8);
    memory.changed(Area::cell(c));
    let g = Grid::new(w, h, &bits).unwrap();
    let warm = Run::warm(&g, Point::new(5, 5), goal, &p, st.workspace(), &mut memory)
        .unwrap()
        .is_warm();
    assert!(warm);
    let after = st.workspace().pheromone().to_vec();
    let r = i32::from(REPAIR_RADIUS) + 1;
    let mut kept = 0;
    for (k, (a, b)) in after.iter().zip(&before).enumerate() {
        let (x, y) = ((k % 32) as i32, (k / 32) as i32);
        let near = (x - 20).abs() <= r && (y - 3).abs() <= r;
        if near {
            assert_eq!(*a, [p.tau0; 4], "entry ({x}, {y})");
        } else {
            assert_eq!(a, b, "entry ({x}, {y})");
            kept += usize::from(*a != [p.tau0; 4]);
        }
    }
    // The previous run left a trail: most of what was kept is not tau0.
    assert!(kept > 500, "{kept}");
    assert_eq!(memory.changes(), None);
}

#[test]
fn warm_runs_stop_after_the_warm_patience_and_stay_valid() {
    let (b, w, h) = grid(&ROWS);
    let g = Grid::new(w, h, &b).unwrap();
    let goal = Point::new(7, 5);
    for warm_patience in [1u16, 2, 5] {
        let p = Params {
            warm_patience,
            ..Params::default()
        };
        let mut st: S64 = Storage::new();
        let mut memory = Memory::new();
        let first = Run::warm(&g, Point::new(0, 0), goal, &p, st.workspace(), &mut memory).unwrap();
        let (_, warm, _) = run_to_end(first);
        assert!(!warm);
        let mut run =
            Run::warm(&g, Point::new(0, 5), goal, &p, st.workspace(), &mut memory).unwrap();
        assert!(run.is_warm());
        while run.step() {}
        let best = run.best_iteration().unwrap();
        let plan = run.finish().unwrap();
        assert!(plan.warm);
        assert_eq!(plan.iterations, best + warm_patience + 1);
        assert_eq!(plan.raw().last(), Some(goal));
        // Another goal: cold, with the cold patience.
        let run = Run::warm(
            &g,
            Point::new(0, 5),
            Point::new(7, 0),
            &p,
            st.workspace(),
            &mut memory,
        );
        assert!(!run.unwrap().is_warm());
    }
}

#[test]
fn a_refused_warm_start_leaves_the_memory_alone() {
    let (b, w, h) = grid(&ROWS);
    let g = Grid::new(w, h, &b).unwrap();
    let goal = Point::new(7, 5);
    let p = Params::default();
    let mut st: S64 = Storage::new();
    let mut memory = Memory::new();
    run_to_end(Run::warm(&g, Point::new(0, 0), goal, &p, st.workspace(), &mut memory).unwrap());
    let before = st.workspace().pheromone().to_vec();
    memory.changed(Area::cell(Point::new(3, 3)));
    let kept = memory;
    // The start is on an obstacle.
    let e = Run::warm(&g, Point::new(1, 1), goal, &p, st.workspace(), &mut memory);
    assert_eq!(e.err(), Some(Error::Blocked(Endpoint::Start)));
    assert_eq!(memory, kept);
    assert_eq!(st.workspace().pheromone(), &before[..]);
}

#[test]
fn a_warm_start_after_a_change_that_cuts_the_goal_off_ends_with_no_path() {
    let (mut b, w, h) = grid(&ROWS);
    let goal = Point::new(7, 5);
    let p = Params::default();
    let mut st: S64 = Storage::new();
    let mut memory = Memory::new();
    {
        let g = Grid::new(w, h, &b).unwrap();
        run_to_end(Run::cold(&g, Point::new(0, 0), goal, &p, st.workspace(), &mut memory).unwrap());
    }
    // Wall off the goal's corner: (6, 4), (7, 4) and (6, 5).
    for (x, y) in [(6usize, 4usize), (7, 4), (6, 5)] {
        let i = y * 8 + x;
        b[i / 8] |= 1 << (i % 8);
        memory.changed(Area::cell(Point::new(x as u16, y as u16)));
    }
    let g = Grid::new(w, h, &b).unwrap();
    // Warm with backtracking ants: no flood fill, the first ant proves it.
    let mut run = Run::warm(&g, Point::new(0, 0), goal, &p, st.workspace(), &mut memory).unwrap();
    assert!(run.is_warm());
    assert!(!run.step());
    assert_eq!(run.finish().err(), Some(Error::NoPath));
    // Cold: the flood fill, the first piece of the setup, ends the run before any ant walks.
    let mut run = Run::cold(&g, Point::new(0, 0), goal, &p, st.workspace(), &mut memory).unwrap();
    assert!(!run.setup_step());
    assert!(run.is_done());
    assert!(!run.step());
    assert_eq!(run.moves(), 0);
    assert_eq!(run.finish().err(), Some(Error::NoPath));
}
