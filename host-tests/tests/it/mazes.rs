//! Fresh wide-corridor mazes (issue 21, item 2): the default plan stays near the optimum on
//! perfect mazes with corridors 4 to 32 cells wide that nobody tuned the planner on
//! (`ohaca_host_tests::gen::maze`, a new maze per width and seed). The `mazes` example measures
//! the same on 512 x 512 mazes, with the cost against A* (`BENCHMARKS.md` 1b).

use ohaca::{plan, Params};
use ohaca_host_tests::check::check_plan;
use ohaca_host_tests::gen::{far_pair, maze};
use ohaca_host_tests::reference::astar8;

/// Every plan valid (`check_plan`: path, lengths, early stop, curve), each raw path within 1 % of
/// the exact 8-connected optimum and the mean within 0.3 %.
#[test]
fn fresh_wide_corridor_mazes_plan_near_the_optimum() {
    let (mut sum, mut n) = (0.0f64, 0usize);
    for (side, width) in [(129u16, 4u16), (163, 8), (205, 16), (199, 32)] {
        for m in 1..=2u64 {
            let map = maze(side, width, 100 + m);
            let grid = map.grid();
            let mut st = ohaca_host_tests::heap::storage(map.cells());
            let (s, g) = far_pair(&map, m as usize).expect("free cells");
            let opt = astar8(&map, s, g).expect("a perfect maze is connected").0;
            let p = Params {
                seed: m,
                ..Params::default()
            };
            let pl = plan(&grid, s, g, &p, st.workspace()).expect("a path exists");
            check_plan(&map, s, g, &pl, usize::MAX)
                .unwrap_or_else(|e| panic!("width {width}, maze {m}: {e}"));
            let q = f64::from(pl.raw_length) / opt;
            assert!(q <= 1.01, "width {width}, maze {m}: raw/opt8 {q:.4}");
            sum += q;
            n += 1;
        }
    }
    let mean = sum / n as f64;
    assert!(mean <= 1.003, "mean raw/opt8 {mean:.4}");
}

/// The generator makes what it says: one-cell walls, `width`-cell corridors, every free cell
/// reachable from every other (a spanning tree of rooms), and the far pair far apart.
#[test]
fn the_maze_generator_makes_connected_wide_corridors() {
    let map = maze(52, 16, 7);
    // (52 - 1) / 17 = 3 rooms a side: 9 rooms of 16 x 16 and 8 openings of 16 cells.
    let free = (0..map.cells())
        .filter(|&i| map.is_free(map.point(i)))
        .count();
    assert_eq!(free, 9 * 16 * 16 + 8 * 16);
    let (s, g) = far_pair(&map, 0).expect("free cells");
    let d = ohaca_host_tests::reference::dijkstra8(&map, s);
    assert!((0..map.cells()).all(|i| !map.is_free(map.point(i)) || d[i].is_finite()));
    assert!(
        d[map.index(g)] > 3.0 * 16.0,
        "far pair only {} apart",
        d[map.index(g)]
    );
}
