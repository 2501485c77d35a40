use super::*;

fn grid_of(rows: &[&str]) -> (u16, u16, alloc::vec::Vec<u8>) {
    let h = rows.len();
    let w = rows[0].len();
    let mut bits = alloc::vec![0u8; (w * h).div_ceil(8)];
    for (y, r) in rows.iter().enumerate() {
        for (x, c) in r.chars().enumerate() {
            if c == '#' {
                let i = y * w + x;
                bits[i / 8] |= 1 << (i % 8);
            }
        }
    }
    (w as u16, h as u16, bits)
}

/// Which variant a test runs.
#[derive(Clone, Copy, Debug)]
enum V {
    Nibbles,
    Costs,
}
const BOTH: [V; 2] = [V::Nibbles, V::Costs];

/// Search with variant `v` and write the path (checked move by move).
fn solve(
    v: V,
    grid: &Grid<'_>,
    s: Point,
    g: Point,
    heap_len: usize,
) -> Result<(Search, alloc::vec::Vec<Point>), AstarError> {
    let n = grid.cells();
    let mut heap = alloc::vec![Entry::EMPTY; heap_len];
    let mut nib = alloc::vec![0u8; nibble_bytes(n)];
    let mut costs = alloc::vec![0u32; n];
    let r = match v {
        V::Nibbles => search(grid, s, g, &mut nib, &mut heap)?,
        V::Costs => search_costs(grid, s, g, &mut costs, &mut heap)?,
    };
    let mut path = alloc::vec![Point::default(); r.steps() as usize + 1];
    let written = match v {
        V::Nibbles => write_path(grid, &nib, g, &r, &mut path),
        V::Costs => write_path_costs(grid, &costs, g, &r, &mut path),
    };
    assert_eq!(written, Ok(path.len()));
    assert_eq!((path[0], *path.last().unwrap()), (s, g));
    let (mut st, mut di) = (0, 0);
    for p in path.windows(2) {
        let d = (0..8).find(|&d| grid.step(p[0], d) == Some(p[1]));
        match d {
            Some(d) if is_diagonal(d) => di += 1,
            Some(_) => st += 1,
            None => panic!("bad step {p:?}"),
        }
    }
    assert_eq!((st, di), (r.straight, r.diagonal));
    assert!(r.peak_heap <= r.pushes);
    Ok((r, path))
}

fn run(
    v: V,
    rows: &[&str],
    s: (u16, u16),
    g: (u16, u16),
) -> Result<(Search, alloc::vec::Vec<Point>), AstarError> {
    let (w, h, bits) = grid_of(rows);
    let grid = Grid::new(w, h, &bits).unwrap();
    let (s, g) = (Point::new(s.0, s.1), Point::new(g.0, g.1));
    solve(v, &grid, s, g, 8 * grid.cells())
}

#[test]
fn costs_stay_below_2_31() {
    // The largest sums stay below 2^32 (f = g + h saturates above LIMIT).
    assert!(u64::from(LIMIT) + u64::from(DIAGONAL) < 1 << 31);
}

#[test]
fn open_map_is_octile() {
    let rows = ["......", "......", "......", "......"];
    for v in BOTH {
        let (r, path) = run(v, &rows, (0, 0), (5, 3)).unwrap();
        assert_eq!((r.straight, r.diagonal), (2, 3));
        assert_eq!(r.length, steps_length(2, 3));
        assert_eq!(path.len(), 6);
        // Deeper first and the held-out neighbour: straight down the optimal corridor.
        assert_eq!(r.expansions, 6, "{v:?}");
    }
}

#[test]
fn no_corner_cutting() {
    for v in BOTH {
        // The only diagonal gap is between two blocks touching at a corner: it must go round.
        let rows = [".#", "#."];
        assert_eq!(
            run(v, &rows, (0, 0), (1, 1)).unwrap_err(),
            AstarError::NoPath
        );
        let rows = ["..#", "#..", "..."];
        let (r, _) = run(v, &rows, (0, 0), (2, 1)).unwrap();
        // (0,0)->(1,0)->(1,1)->(2,1): the diagonal (0,0)->(1,1) is cut by (0,1).
        assert_eq!((r.straight, r.diagonal), (3, 0));
    }
}

#[test]
fn start_is_goal() {
    for v in BOTH {
        let (r, path) = run(v, &["..."], (1, 0), (1, 0)).unwrap();
        assert_eq!((r.steps(), r.length, r.expansions), (0, 0.0, 1));
        assert_eq!(path, [Point::new(1, 0)]);
    }
}

#[test]
fn errors() {
    for v in BOTH {
        assert_eq!(
            run(v, &[".#"], (0, 0), (1, 0)).unwrap_err(),
            AstarError::BadCell(End::Goal)
        );
        assert_eq!(
            run(v, &[".."], (2, 0), (1, 0)).unwrap_err(),
            AstarError::BadCell(End::Start)
        );
    }
    let (w, h, bits) = grid_of(&["....", "...."]);
    let grid = Grid::new(w, h, &bits).unwrap();
    let (s, g) = (Point::new(0, 0), Point::new(3, 1));
    let mut heap = [Entry::EMPTY; 1];
    let mut nib = [0u8; 3];
    let mut costs = [0u32; 7];
    assert_eq!(
        search(&grid, s, g, &mut nib, &mut heap),
        Err(AstarError::StorageTooSmall { needed: 4, got: 3 })
    );
    assert_eq!(
        search_costs(&grid, s, g, &mut costs, &mut heap),
        Err(AstarError::StorageTooSmall { needed: 8, got: 7 })
    );
    // The first expansion holds one of its three neighbours out and pushes two.
    let mut nib = [0u8; 4];
    let mut costs = [0u32; 8];
    assert_eq!(
        search(&grid, s, g, &mut nib, &mut heap),
        Err(AstarError::HeapFull { capacity: 1 })
    );
    assert_eq!(
        search_costs(&grid, s, g, &mut costs, &mut heap),
        Err(AstarError::HeapFull { capacity: 1 })
    );
    let mut heap = [Entry::EMPTY; 32];
    let r = search(&grid, s, g, &mut nib, &mut heap).unwrap();
    assert_eq!(r.ram_bytes(), 4 + 12 * r.peak_heap as usize);
    let mut short = [Point::default(); 2];
    let too_long = Err(AstarError::PathTooLong {
        cells: 4,
        capacity: 2,
    });
    assert_eq!(write_path(&grid, &nib, g, &r, &mut short), too_long);
    let rc = search_costs(&grid, s, g, &mut costs, &mut heap).unwrap();
    assert_eq!(rc.ram_bytes(), 32 + 12 * rc.peak_heap as usize);
    assert_eq!(
        write_path_costs(&grid, &costs, g, &rc, &mut short),
        too_long
    );
    // Storage with no tree.
    let mut out = [Point::default(); 8];
    assert_eq!(
        write_path(&grid, &[0u8; 4], g, &r, &mut out),
        Err(AstarError::NoTree)
    );
    assert_eq!(
        write_path_costs(&grid, &[u32::MAX; 8], g, &rc, &mut out),
        Err(AstarError::NoTree)
    );
    // Costs that lead nowhere: the goal's cost has no neighbour one step cheaper.
    let mut bad = [u32::MAX; 8];
    bad[grid.index(g)] = 3 * STRAIGHT;
    bad[grid.index(s)] = 0;
    assert_eq!(
        write_path_costs(&grid, &bad, g, &rc, &mut out),
        Err(AstarError::NoTree)
    );
    assert!(alloc::format!("{}", AstarError::NoPath).contains("no path"));
    assert!(alloc::format!("{}", AstarError::TooFar).contains("36000"));
}

/// A serpentine of 1-wide rows `w` long joined at alternate ends: its only path, from the
/// top-left corner to the end of the last row, is `rows (w - 1) + 2 (rows - 1)` straight
/// steps.
fn serpentine(w: usize, rows: usize) -> (u16, u16, alloc::vec::Vec<u8>) {
    let h = 2 * rows - 1;
    let mut bits = alloc::vec![0u8; (w * h).div_ceil(8)];
    for y in (1..h).step_by(2) {
        let gap = if y % 4 == 1 { w - 1 } else { 0 };
        for x in (0..w).filter(|&x| x != gap) {
            let i = y * w + x;
            bits[i / 8] |= 1 << (i % 8);
        }
    }
    (w as u16, h as u16, bits)
}

#[test]
fn long_paths_exact_up_to_max_length_then_too_far() {
    let w = 300usize;
    for (rows, fits) in [(101usize, true), (123, false)] {
        let (gw, gh, bits) = serpentine(w, rows);
        let grid = Grid::new(gw, gh, &bits).unwrap();
        let goal_x = if rows % 2 == 1 { w - 1 } else { 0 };
        let (s, g) = (Point::new(0, 0), Point::new(goal_x as u16, gh - 1));
        let steps = (rows * (w - 1) + 2 * (rows - 1)) as u32;
        for v in BOTH {
            let got = solve(v, &grid, s, g, 64);
            if fits {
                let (r, _) = got.unwrap();
                assert_eq!((r.straight, r.diagonal), (steps, 0), "{v:?}");
            } else {
                assert!(steps > MAX_LENGTH);
                assert_eq!(got.unwrap_err(), AstarError::TooFar, "{v:?}");
            }
        }
    }
}

/// Bellman-Ford over `Grid::step` in f64: the optimum, or None.
fn brute(grid: &Grid<'_>, s: Point, g: Point) -> Option<f64> {
    let n = grid.cells();
    let mut dist = alloc::vec![f64::INFINITY; n];
    dist[grid.index(s)] = 0.0;
    loop {
        let mut changed = false;
        for i in 0..n {
            let p = grid.point(i);
            if !dist[i].is_finite() {
                continue;
            }
            for d in 0..8u8 {
                if let Some(q) = grid.step(p, d) {
                    let c = if is_diagonal(d) {
                        core::f64::consts::SQRT_2
                    } else {
                        1.0
                    };
                    let j = grid.index(q);
                    if dist[i] + c < dist[j] - 1e-12 {
                        dist[j] = dist[i] + c;
                        changed = true;
                    }
                }
            }
        }
        if !changed {
            break;
        }
    }
    dist[grid.index(g)].is_finite().then(|| dist[grid.index(g)])
}

#[test]
fn random_maps_match_brute_force() {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..400 {
        let w = 1 + (next() % 14) as u16;
        let h = 1 + (next() % 14) as u16;
        let n = usize::from(w) * usize::from(h);
        let density = next() % 45;
        let mut bits = alloc::vec![0u8; n.div_ceil(8)];
        for i in 0..n {
            if next() % 100 < density {
                bits[i / 8] |= 1 << (i % 8);
            }
        }
        let (si, gi) = ((next() as usize) % n, (next() as usize) % n);
        for i in [si, gi] {
            bits[i / 8] &= !(1 << (i % 8));
        }
        let grid = Grid::new(w, h, &bits).unwrap();
        let (s, g) = (grid.point(si), grid.point(gi));
        for v in BOTH {
            match (brute(&grid, s, g), solve(v, &grid, s, g, 8 * n)) {
                (None, Err(AstarError::NoPath)) => {}
                (Some(opt), Ok((r, _))) => {
                    let exact =
                        f64::from(r.straight) + f64::from(r.diagonal) * core::f64::consts::SQRT_2;
                    assert!((exact - opt).abs() < 1e-9, "{v:?}: {opt} vs {r:?}");
                }
                (b, a) => panic!("{v:?}: brute {b:?}, astar {a:?}"),
            }
        }
    }
}
