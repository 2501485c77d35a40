//! D* Lite (`ohaca_host::dstar`) against the project's exact A* (`ohaca::astar`): the same
//! optimum (straight and diagonal steps, hence bit for bit the same length) on random maps, and
//! after random sequences of cell changes and robot moves on one persistent search; every path
//! valid move by move (`Grid::step`); a replan after a far-away change expands far fewer vertices
//! than the initial search; a replayed `ohaca replan` drive agrees with the exact optimum.

use ohaca::astar::{self, AstarError, End, Entry};
use ohaca::rng::Xoshiro128pp;
use ohaca::{Grid, Params, Point};
use ohaca_host::dstar::{self, DStarError, DStarLite, Path, Planned, CELL_BYTES, ENTRY_BYTES};
use ohaca_host::replan::{drive, HostPlanner, Scenario};
use ohaca_host::Map;

/// The exact A*'s (straight, diagonal) steps, `None` for no path.
fn astar_steps(grid: &Grid<'_>, s: Point, g: Point) -> Result<Option<(u32, u32)>, AstarError> {
    let n = grid.cells();
    let mut costs = vec![0u32; n];
    let mut heap = vec![Entry::EMPTY; 8 * n + 8];
    match astar::search_costs(grid, s, g, &mut costs, &mut heap) {
        Ok(r) => Ok(Some((r.straight, r.diagonal))),
        Err(AstarError::NoPath) => Ok(None),
        Err(e) => Err(e),
    }
}

/// Check `path` move by move on `grid` and that its counts are its own.
fn check_path(grid: &Grid<'_>, s: Point, g: Point, path: &Path) {
    assert_eq!(path.cells.first(), Some(&s));
    assert_eq!(path.cells.last(), Some(&g));
    let (mut st, mut di) = (0, 0);
    for w in path.cells.windows(2) {
        match (0..8u8).find(|&d| grid.step(w[0], d) == Some(w[1])) {
            Some(d) if d & 1 == 1 => di += 1,
            Some(_) => st += 1,
            None => panic!("{:?} -> {:?} is not a move", w[0], w[1]),
        }
    }
    assert_eq!((st, di), (path.straight, path.diagonal));
    assert_eq!(
        u64::from(path.cost),
        u64::from(st) * u64::from(astar::STRAIGHT) + u64::from(di) * u64::from(astar::DIAGONAL)
    );
    assert_eq!(path.length, ohaca::geometry::steps_length(st, di));
}

fn below(rng: &mut Xoshiro128pp, n: u32) -> u32 {
    rng.next_word() % n
}

fn random_map(rng: &mut Xoshiro128pp, w: u16, h: u16, density: u32) -> Map {
    Map::from_fn(w, h, |_, _| below(rng, 100) < density)
}

fn random_cell(rng: &mut Xoshiro128pp, map: &Map) -> Point {
    Point::new(
        below(rng, u32::from(map.width)) as u16,
        below(rng, u32::from(map.height)) as u16,
    )
}

/// Plan with `d` and compare with A* on `map` (the map `d` must see); returns the plan (`None`
/// on an error, which A* must share).
fn plan_and_compare(d: &mut DStarLite, map: &Map, what: &str) -> Option<Planned> {
    let grid = map.grid().unwrap();
    assert_eq!(d.grid().unwrap().bits(), grid.bits(), "{what}: maps differ");
    let (s, g) = (d.start(), d.goal());
    let want = if !grid.is_free(s) {
        Err(DStarError::BadCell(End::Start))
    } else if !grid.is_free(g) {
        Err(DStarError::BadCell(End::Goal))
    } else {
        Ok(astar_steps(&grid, s, g).unwrap())
    };
    match (d.plan(), want) {
        (Ok(p), Ok(steps)) => {
            let got = p.path.as_ref().map(|p| (p.straight, p.diagonal));
            assert_eq!(got, steps, "{what}: {s:?} -> {g:?}");
            if let Some(path) = &p.path {
                check_path(&grid, s, g, path);
            }
            assert_eq!(
                p.stats.memory_bytes % ENTRY_BYTES,
                (grid.cells() * CELL_BYTES) % ENTRY_BYTES
            );
            assert!(p.stats.open_peak >= p.stats.open_len);
            Some(p)
        }
        (Err(e), Err(w)) => {
            assert_eq!(e, w, "{what}");
            None
        }
        (got, want) => panic!("{what}: D* Lite {got:?}, expected {want:?}"),
    }
}

#[test]
fn random_maps_match_the_exact_astar() {
    let mut rng = Xoshiro128pp::from_u64(28);
    for case in 0..400 {
        let w = 1 + below(&mut rng, 30) as u16;
        let h = 1 + below(&mut rng, 30) as u16;
        let density = below(&mut rng, 45);
        let mut map = random_map(&mut rng, w, h, density);
        let (s, g) = (random_cell(&mut rng, &map), random_cell(&mut rng, &map));
        map.set(s, false).unwrap();
        map.set(g, false).unwrap();
        let mut d = DStarLite::new(&map.grid().unwrap(), s, g).unwrap();
        plan_and_compare(&mut d, &map, &format!("case {case}"));
    }
}

/// One persistent search per map; each round the robot drives some steps along its path (or
/// jumps to a random free cell), random cells flip (sometimes the robot's or the goal's), and it
/// replans: always A*'s optimum.
#[test]
fn replans_after_changes_and_moves_match_the_exact_astar() {
    let mut rng = Xoshiro128pp::from_u64(2002);
    for case in 0..120 {
        let w = 2 + below(&mut rng, 40) as u16;
        let h = 2 + below(&mut rng, 40) as u16;
        let density = below(&mut rng, 35);
        let mut map = random_map(&mut rng, w, h, density);
        let (s, g) = (random_cell(&mut rng, &map), random_cell(&mut rng, &map));
        map.set(s, false).unwrap();
        map.set(g, false).unwrap();
        let mut d = DStarLite::new(&map.grid().unwrap(), s, g).unwrap();
        let mut path =
            plan_and_compare(&mut d, &map, &format!("case {case}, initial")).and_then(|p| p.path);
        for round in 0..15 {
            let what = format!("case {case}, round {round}");
            // Move: along the path, or anywhere free (a jump also keeps the keys lower bounds).
            match &path {
                Some(p) if below(&mut rng, 4) != 0 => {
                    let k = below(&mut rng, p.cells.len() as u32) as usize;
                    d.move_robot(p.cells[k]).unwrap();
                }
                _ => {
                    let to = random_cell(&mut rng, &map);
                    if !map.is_blocked(to) {
                        d.move_robot(to).unwrap();
                    }
                }
            }
            // Change: a few random cells, a rectangle, or cells on the path.
            let mut changes = Vec::new();
            match below(&mut rng, 3) {
                0 => {
                    for _ in 0..1 + below(&mut rng, 6) {
                        changes.push((random_cell(&mut rng, &map), below(&mut rng, 2) == 0));
                    }
                }
                1 => {
                    let c = random_cell(&mut rng, &map);
                    let blocked = below(&mut rng, 2) == 0;
                    for y in c.y..(c.y + 1 + below(&mut rng, 4) as u16).min(map.height) {
                        for x in c.x..(c.x + 1 + below(&mut rng, 4) as u16).min(map.width) {
                            changes.push((Point::new(x, y), blocked));
                        }
                    }
                }
                _ => {
                    if let Some(p) = &path {
                        for _ in 0..1 + below(&mut rng, 3) {
                            let k = below(&mut rng, p.cells.len() as u32) as usize;
                            changes.push((p.cells[k], true));
                        }
                    }
                }
            }
            // Keep the robot's and the goal's cells free most of the time.
            if below(&mut rng, 8) != 0 {
                changes.retain(|&(p, _)| p != d.start() && p != d.goal());
            }
            let mut flips = 0;
            let mut after = map.clone();
            for &(p, b) in &changes {
                if after.is_blocked(p) != b {
                    after.set(p, b).unwrap();
                    flips += 1;
                }
            }
            assert_eq!(d.update_cells(&changes).unwrap(), flips, "{what}");
            map = after;
            path = plan_and_compare(&mut d, &map, &what).and_then(|p| p.path);
        }
    }
}

#[test]
fn no_corner_cutting() {
    // (0,0) -> (1,1) between two blocks touching at a corner: no way through.
    let map = Map::from_fn(2, 2, |x, y| x != y);
    let mut d = DStarLite::new(&map.grid().unwrap(), Point::new(0, 0), Point::new(1, 1)).unwrap();
    assert_eq!(d.plan().unwrap().path, None);
    // (0,0) -> (2,1) with (2,0) and (0,1) blocked: the diagonals from (0,0) and to (2,1) are
    // cut, so it goes round: three straight steps.
    let map = Map::from_fn(3, 3, |x, y| (x, y) == (2, 0) || (x, y) == (0, 1));
    let mut d = DStarLite::new(&map.grid().unwrap(), Point::new(0, 0), Point::new(2, 1)).unwrap();
    let p = d.plan().unwrap().path.unwrap();
    assert_eq!((p.straight, p.diagonal), (3, 0));
    // Clearing (0,1) opens the diagonal (0,0) -> (1,1): one diagonal and one straight step.
    d.update_cells(&[(Point::new(0, 1), false)]).unwrap();
    let p = d.plan().unwrap().path.unwrap();
    assert_eq!((p.straight, p.diagonal), (1, 1));
}

#[test]
fn errors_are_values() {
    let map = Map::from_fn(4, 3, |x, _| x == 3);
    let grid = map.grid().unwrap();
    let (s, g) = (Point::new(0, 0), Point::new(2, 2));
    assert_eq!(
        DStarLite::new(&grid, Point::new(4, 0), g).unwrap_err(),
        DStarError::OffMap(Point::new(4, 0))
    );
    let mut d = DStarLite::new(&grid, s, Point::new(3, 1)).unwrap();
    assert_eq!(d.plan().unwrap_err(), DStarError::BadCell(End::Goal));
    let mut d = DStarLite::new(&grid, s, g).unwrap();
    assert_eq!(
        d.move_robot(Point::new(0, 3)),
        Err(DStarError::OffMap(Point::new(0, 3)))
    );
    // An off-map cell changes nothing, not even the cells before it.
    assert_eq!(
        d.update_cells(&[(Point::new(1, 1), true), (Point::new(9, 9), true)]),
        Err(DStarError::OffMap(Point::new(9, 9)))
    );
    assert!(!d.grid().unwrap().blocked_xy(1, 1));
    // A blocked start is an error; clearing it, the search goes on.
    assert_eq!(d.update_cells(&[(s, true)]), Ok(1));
    assert_eq!(d.update_cells(&[(s, true)]), Ok(0));
    assert_eq!(d.plan().unwrap_err(), DStarError::BadCell(End::Start));
    d.update_cells(&[(s, false)]).unwrap();
    let p = d.plan().unwrap().path.unwrap();
    assert_eq!((p.straight, p.diagonal), (0, 2));
    // Start is goal.
    let mut d = DStarLite::new(&grid, g, g).unwrap();
    let p = d.plan().unwrap().path.unwrap();
    assert_eq!((p.cells.len(), p.cost), (1, 0));
    assert!(DStarError::BadCell(End::Goal).to_string().contains("goal"));
}

/// A 200 x 200 map with random obstacles: the initial search expands thousands of vertices; a
/// block flipped off the path near the goal (inside the searched region) or at a far corner
/// costs a handful, and driving along the path with nothing changed costs nothing.
#[test]
fn a_far_change_costs_far_less_than_the_initial_search() {
    let mut rng = Xoshiro128pp::from_u64(476);
    let mut map = random_map(&mut rng, 200, 200, 20);
    let (s, g) = (Point::new(2, 100), Point::new(197, 100));
    for p in [s, g] {
        map.set(p, false).unwrap();
    }
    let mut d = DStarLite::new(&map.grid().unwrap(), s, g).unwrap();
    let first = plan_and_compare(&mut d, &map, "initial").unwrap();
    let initial = first.stats.expanded;
    println!("initial: {:?}", first.stats);
    assert!(initial > 2000, "{initial}");
    // What it keeps: 12 bytes a cell and 16 an entry of the queue at its most (in the first
    // plan, this call's peak).
    assert_eq!((CELL_BYTES, ENTRY_BYTES), (12, 16));
    assert_eq!(
        first.stats.memory_bytes,
        200 * 200 * CELL_BYTES + ENTRY_BYTES * first.stats.open_peak
    );
    let path = first.path.unwrap();
    // Drive a third of the way: nothing changed, nothing to expand.
    d.move_robot(path.cells[path.cells.len() / 3]).unwrap();
    let moved = plan_and_compare(&mut d, &map, "moved").unwrap();
    assert_eq!(moved.stats.expanded, 0, "{:?}", moved.stats);
    // Block 3 x 3 cells 8 rows off the path near the goal, and flip a far corner.
    let near = *path.cells.iter().rev().nth(12).unwrap();
    let mut changes = vec![(Point::new(0, 199), !map.is_blocked(Point::new(0, 199)))];
    for y in near.y + 7..near.y + 10 {
        for x in near.x - 1..near.x + 2 {
            changes.push((Point::new(x, y), true));
        }
    }
    d.update_cells(&changes).unwrap();
    for &(p, b) in &changes {
        map.set(p, b).unwrap();
    }
    let far = plan_and_compare(&mut d, &map, "far change").unwrap();
    println!("far change: {:?}", far.stats);
    assert!(far.path.is_some());
    assert!(far.stats.cells_changed > 0 && far.stats.updated > 0);
    assert!(
        far.stats.expanded * 20 < initial,
        "far change: {} expansions, initial {initial}",
        far.stats.expanded
    );
    assert!(far.stats.memory_bytes >= 200 * 200 * CELL_BYTES);
    // A wall across the path ahead: a real repair, still cheaper than starting over.
    let ahead = path.cells[path.cells.len() / 2];
    let wall: Vec<(Point, bool)> = (ahead.y - 6..=ahead.y + 6)
        .map(|y| (Point::new(ahead.x, y), true))
        .collect();
    d.update_cells(&wall).unwrap();
    for &(p, b) in &wall {
        map.set(p, b).unwrap();
    }
    let walled = plan_and_compare(&mut d, &map, "wall").unwrap();
    println!("wall: {:?}", walled.stats);
    assert!(walled.stats.expanded > 0 && walled.stats.expanded < initial);
}

/// A drive of `ohaca replan` (the host colony, a wall appearing ahead, then cleared) replayed
/// into D* Lite: one row per plan, every optimum the drive's own (`Step::optimum`, Dijkstra in
/// f64), and the replans cheaper than the initial search.
#[test]
fn a_replayed_drive_agrees_with_its_optima() {
    let map = Map::from_fn(40, 30, |x, y| x == 20 && (5..25).contains(&y));
    let sc = Scenario::parse(
        r#"{"events":[{"at":0.3,"wall_ahead":{"cells":7,"ahead":5}},
                      {"at":0.5,"rect":[20,5,1,20],"blocked":false}]}"#,
    )
    .unwrap();
    let ends = (Point::new(2, 15), Point::new(37, 15));
    let mut host = HostPlanner::new(Params::default());
    let dr = drive(&sc, &map, ends, &mut host, true).unwrap();
    let rows = dstar::replay(&dr, ends.1).unwrap();
    assert_eq!(rows.len(), dr.steps.len());
    for (r, s) in rows.iter().zip(&dr.steps) {
        assert_eq!(r.robot, s.robot);
        let (len, opt) = (f64::from(r.length.unwrap()), s.optimum.unwrap());
        assert!((len - opt).abs() < 1e-4, "plan {}: {len} vs {opt}", r.plan);
        assert!(r.astar.expanded > 0);
    }
    println!("{rows:#?}");
    assert!(rows[0].dstar.expanded > 0);
    assert!(rows[1].dstar.cells_changed > 0);
    assert!(rows[2].dstar.cells_changed >= 20);
}
