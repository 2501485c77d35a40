//! The local search of `ohaca::refine` on the colony's raw paths over the large public Moving AI
//! maps (`maps/large/`): raw length over the exact 8-connected optimum before and after, and what
//! it cost (cells expanded).
//!
//! ```text
//! cargo run --profile host -p ohaca-host-tests --target host-tuple --example refine_large -- \
//!     [--maps NAME,NAME,...] [--scen N] [--sides 48,64,128] [--passes P] [--cache DIR] \
//!     [--smooth 1] [--patience P]
//! ```
//!
//! For each map: the `N` (default 20) scenarios of largest optimum (as in the `large` example),
//! the exact optimum by the reference A*, the default plan without the planner's own local search
//! (seed 1, `refine` off; `--patience` overrides the early stop), then `refine` of its raw path
//! with a window of each side. Raw paths are cached in `DIR` (default
//! `target/refine-large-cache`), so that trying other window sides does not re-plan. Prints one
//! Markdown row per map and side: every refined path checked valid, mean raw/opt8 before and
//! after, the worst after, and per plan the cells expanded, the windows searched and the windows
//! that improved.
//!
//! With `--smooth 1` it then prints a second table, on the raw paths and on the paths refined with
//! a window of 64: the length of `SmoothingKind::Shortest` with a look-back of `K` raw cells over
//! the all-pairs DP's (`K = n`), for several `K`, the greedy rule's, and the time per path of the
//! all-pairs DP and of the default look-back (wall clock, for the documentation only).

use std::path::{Path, PathBuf};
use std::time::Instant;

use ohaca::refine::{Budget, Refiner, Scratch};
use ohaca::smoothing::{shortest_with, smooth, LOOKBACK};
use ohaca::{plan, Params, Point, SmoothingKind};
use ohaca_host_tests::check::check_raw;
use ohaca_host_tests::large::{large_maps, LargeMap};
use ohaca_host_tests::quality::par_map;
use ohaca_host_tests::reference::astar8;

/// Raw path of the default plan, from the cache or planned (and cached).
fn raw_path(cache: &Path, m: &LargeMap, c: usize, seed: u64, patience: u16) -> (Vec<Point>, u16) {
    let case = &m.cases[c];
    let file = cache.join(format!(
        "{}-{}-{}-{}-{}-s{seed}-p{patience}-colony.txt",
        m.name, case.start.x, case.start.y, case.goal.x, case.goal.y
    ));
    if let Ok(text) = std::fs::read_to_string(&file) {
        let mut lines = text.lines();
        let iterations = lines
            .next()
            .and_then(|l| l.strip_prefix("# iterations "))
            .and_then(|n| n.parse().ok())
            .expect("cache header");
        let raw = lines
            .map(|l| {
                let (x, y) = l.split_once(' ').expect("x y");
                Point::new(x.parse().expect("x"), y.parse().expect("y"))
            })
            .collect();
        return (raw, iterations);
    }
    let mut st = ohaca_host_tests::heap::storage(m.map.cells());
    let grid = m.map.grid();
    // The colony's own raw path: the planner's local search off, `patience` as given.
    let p = Params {
        seed,
        patience,
        refine: false,
        ..Params::default()
    };
    let pl = plan(&grid, case.start, case.goal, &p, st.workspace()).expect("a plan");
    let raw: Vec<Point> = pl.raw().collect();
    let mut text = format!("# iterations {}\n", pl.iterations);
    text.extend(raw.iter().map(|p| format!("{} {}\n", p.x, p.y)));
    std::fs::write(&file, text).expect("write the cache");
    (raw, pl.iterations)
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut scen = 20usize;
    let mut sides = vec![48usize, 64, 128];
    let mut passes = ohaca::refine::DEFAULT_PASSES;
    let mut only: Option<Vec<String>> = None;
    let mut cache = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("target")
        .join("refine-large-cache");
    let mut smooth_table = false;
    let mut patience = Params::default().patience;
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let v = it.next().expect("every option takes a value");
        match flag.as_str() {
            "--maps" => only = Some(v.split(',').map(str::to_string).collect()),
            "--scen" => scen = v.parse().expect("--scen N"),
            "--sides" => sides = v.split(',').map(|s| s.parse().expect("side")).collect(),
            "--passes" => passes = v.parse().expect("--passes P"),
            "--cache" => cache = PathBuf::from(v),
            "--smooth" => smooth_table = v == "1",
            "--patience" => patience = v.parse().expect("--patience P"),
            _ => panic!("unknown option {flag}"),
        }
    }
    std::fs::create_dir_all(&cache).expect("cache dir");
    let maps: Vec<LargeMap> = large_maps(scen)
        .into_iter()
        .filter(|m| only.as_ref().is_none_or(|o| o.iter().any(|n| n == &m.name)))
        .collect();
    println!("| map | size | iterations | side | runs | valid | raw/opt8 before | after | max after | expanded/plan | expanded/raw cell | windows/plan | improved/plan |");
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    let mut totals = vec![(0.0f64, 0.0f64, 0usize); sides.len()];
    let mut bases = vec![];
    for m in &maps {
        // Optimum and raw path per scenario (planned in parallel, once).
        let base = par_map(m.cases.len(), |c| {
            let case = &m.cases[c];
            let opt = astar8(&m.map, case.start, case.goal)
                .map(|(d, _)| d)
                .expect("solvable");
            let (raw, iterations) = raw_path(&cache, m, c, 1, patience);
            (opt, raw, iterations)
        });
        let iterations =
            base.iter().map(|b| f64::from(b.2)).sum::<f64>() / base.len().max(1) as f64;
        bases.push(base.iter().map(|b| b.1.clone()).collect::<Vec<_>>());
        for (si, &side) in sides.iter().enumerate() {
            let res: Vec<(bool, f64, f64, Budget, usize)> = base
                .iter()
                .enumerate()
                .map(|(c, (opt, raw, _))| {
                    let case = &m.cases[c];
                    let before = check_raw(&m.map, case.start, case.goal, raw).expect("raw valid");
                    let words = Scratch::words(side);
                    let (mut a, mut b) = (vec![0u32; words], vec![0u32; words]);
                    let scratch = Scratch::new(&mut a, &mut b);
                    let mut out = vec![Point::default(); raw.len() + side];
                    let mut b = Budget::unlimited();
                    let grid = m.map.grid();
                    let mut r = Refiner::new(&grid, raw, &mut out, passes).expect("valid raw path");
                    let mut scratch = scratch;
                    r.resume(&grid, &mut out, &mut scratch, &mut b);
                    let k = r.finish(&mut out);
                    let after = check_raw(&m.map, case.start, case.goal, &out[..k]);
                    let ok = after.as_ref().is_ok_and(|&a| a <= before + 1e-9);
                    if let Err(e) = &after {
                        eprintln!("{}: invalid refined path: {e}", m.name);
                    }
                    (
                        ok,
                        before / opt,
                        after.unwrap_or(f64::NAN) / opt,
                        b,
                        raw.len(),
                    )
                })
                .collect();
            let n = res.len() as f64;
            let valid = res.iter().filter(|r| r.0).count();
            let before = res.iter().map(|r| r.1).sum::<f64>() / n;
            let after = res.iter().map(|r| r.2).sum::<f64>() / n;
            let worst = res.iter().map(|r| r.2).fold(0.0, f64::max);
            let exp = res.iter().map(|r| r.3.expanded as f64).sum::<f64>() / n;
            let cells = res.iter().map(|r| r.4 as f64).sum::<f64>() / n;
            let win = res.iter().map(|r| f64::from(r.3.windows)).sum::<f64>() / n;
            let imp = res.iter().map(|r| f64::from(r.3.improved)).sum::<f64>() / n;
            totals[si].0 += before * n;
            totals[si].1 += after * n;
            totals[si].2 += res.len();
            println!(
                "| {} | {}x{} | {iterations:.1} | {side} | {} | {valid} | {before:.4} | {after:.4} | {worst:.4} | {exp:.0} | {:.1} | {win:.1} | {imp:.1} |",
                m.name,
                m.map.width(),
                m.map.height(),
                res.len(),
                exp / cells,
            );
        }
    }
    for (si, side) in sides.iter().enumerate() {
        let (b, a, n) = totals[si];
        let n = n.max(1) as f64;
        println!(
            "\nside {side}: mean raw/opt8 over all runs {:.4} -> {:.4}",
            b / n,
            a / n
        );
    }
    if smooth_table {
        smoothing_table(&maps, &bases);
    }
}

/// Refine `raw` with a window of `side` (unlimited budget).
fn refined(m: &LargeMap, raw: &[Point], side: usize) -> Vec<Point> {
    let words = Scratch::words(side);
    let (mut a, mut b) = (vec![0u32; words], vec![0u32; words]);
    let scratch = Scratch::new(&mut a, &mut b);
    let mut out = vec![Point::default(); raw.len() + side];
    let k = ohaca::refine::refine(
        &m.map.grid(),
        raw,
        &mut out,
        scratch,
        &mut Budget::unlimited(),
    )
    .expect("valid");
    out.truncate(k);
    out
}

/// Smoothed length with look-back `k` (`usize::MAX`: all pairs; 0: greedy) and seconds taken.
fn smoothed(m: &LargeMap, path: &[Point], k: usize) -> (f64, f64) {
    let n = path.len();
    let mut p = path.to_vec();
    let (mut dist, mut prev) = (vec![0f32; n], vec![0u32; n]);
    let grid = m.map.grid();
    let t0 = Instant::now();
    let len = if k == 0 {
        smooth(
            &grid,
            SmoothingKind::Greedy,
            &mut p,
            n,
            &mut [],
            &mut ohaca::polish::links::PathLinks::new(&mut []),
        )
    } else {
        let c = shortest_with(
            &grid,
            &mut p,
            n,
            &mut dist,
            &mut ohaca::polish::links::PathLinks::new(&mut prev),
            k,
        );
        ohaca::smoothing::drop_collinear(&mut p, c)
    };
    let t = t0.elapsed().as_secs_f64();
    let w = &p[..len];
    let l = ohaca_host_tests::check::check_waypoints(&m.map, path[0], path[n - 1], w)
        .expect("valid waypoints");
    (l, t)
}

fn smoothing_table(maps: &[LargeMap], bases: &[Vec<Vec<Point>>]) {
    let ks = [32usize, 64, LOOKBACK, 256];
    for (what, side) in [("raw", 0usize), ("refined (64)", 64)] {
        println!("\nSmoothing the {what} paths: length over the all-pairs DP's (mean, max), time per path");
        print!("| map | cells/path | greedy |");
        for k in ks {
            print!(" K={k} mean | max |");
        }
        println!(" all-pairs ms | K={LOOKBACK} ms |");
        print!("| --- | --- | --- |");
        for _ in ks {
            print!(" --- | --- |");
        }
        println!(" --- | --- |");
        for (m, raws) in maps.iter().zip(bases) {
            let paths: Vec<Vec<Point>> = raws
                .iter()
                .map(|r| {
                    if side == 0 {
                        r.clone()
                    } else {
                        refined(m, r, side)
                    }
                })
                .collect();
            let rows = par_map(paths.len(), |i| {
                let p = &paths[i];
                let (full, tf) = smoothed(m, p, usize::MAX);
                let (gr, _) = smoothed(m, p, 0);
                let mut r = vec![gr / full];
                let mut tk = 0.0;
                for k in ks {
                    let (l, t) = smoothed(m, p, k);
                    if k == LOOKBACK {
                        tk = t;
                    }
                    r.push(l / full);
                }
                (r, tf, tk, p.len())
            });
            let n = rows.len() as f64;
            let mean = |j: usize| rows.iter().map(|r| r.0[j]).sum::<f64>() / n;
            let max = |j: usize| rows.iter().map(|r| r.0[j]).fold(0.0, f64::max);
            print!(
                "| {} | {:.0} | {:.4} |",
                m.name,
                rows.iter().map(|r| r.3 as f64).sum::<f64>() / n,
                mean(0)
            );
            for j in 1..=ks.len() {
                print!(" {:.4} | {:.4} |", mean(j), max(j));
            }
            println!(
                " {:.2} | {:.2} |",
                rows.iter().map(|r| r.1).sum::<f64>() / n * 1e3,
                rows.iter().map(|r| r.2).sum::<f64>() / n * 1e3
            );
        }
    }
}
