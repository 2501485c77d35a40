//! The paper's full run (50 ants x 100 iterations, no early stop) on complex-26 against one exact
//! A* (the `pathfinding` crate's `astar`, 8 moves without corner cutting), side by side in one run:
//! the issue's yardstick is the ratio of their times on the same machine at the same moment.
//!
//! ```text
//! cargo run --release -p ohaca-host-tests --target host-tuple --example full_run -- [--rounds N]
//! ```
//!
//! Each round times one full run and then 200 A* searches (one A* takes tens of microseconds, so
//! a batch keeps the clock's resolution out of it); prints the median of the rounds' ratios, and
//! the ratio for the default plan (with its early stop) the same way.

use std::time::Instant;

#[path = "../benches/shared/astar.rs"]
mod astar;
use astar::astar_cost;

use ohaca::{plan, Params, Point};
use ohaca_host_tests::maps::Map;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let rounds: usize = match args.as_slice() {
        [flag, n] if flag == "--rounds" => n.parse().expect("--rounds N"),
        _ => 15,
    };
    let dir = ohaca_host_tests::maps::maps_dir();
    let map = Map::load(dir.join("complex-26.map")).expect("complex-26");
    let (s, g) = (Point::new(0, 0), Point::new(25, 25));
    let grid = map.grid();
    let mut st = ohaca_host_tests::heap::storage(map.cells());
    let full = Params {
        ants: 50,
        patience: 0,
        refine_patience: 0,
        ..Params::default()
    };
    const BATCH: u32 = 200;
    for (name, params) in [("full 50 x 100", full), ("default", Params::default())] {
        let mut ratios = Vec::new();
        let (mut tp, mut ta) = (0.0, 0.0);
        for round in 0..rounds {
            let p = Params {
                seed: round as u64 + 1,
                ..params
            };
            let t0 = Instant::now();
            let pl = plan(&grid, s, g, &p, st.workspace()).expect("a path");
            let plan_s = t0.elapsed().as_secs_f64();
            std::hint::black_box(pl.length);
            let t0 = Instant::now();
            for _ in 0..BATCH {
                std::hint::black_box(astar_cost(&map, s, g).expect("a path"));
            }
            let astar_s = t0.elapsed().as_secs_f64() / f64::from(BATCH);
            ratios.push(plan_s / astar_s);
            tp += plan_s;
            ta += astar_s;
        }
        println!(
            "complex-26 (0,0) -> (25,25), {name}: plan {:.3} ms, A* {:.4} ms (means over {rounds} rounds); plan / A* median {:.1}x",
            tp * 1e3 / rounds as f64,
            ta * 1e3 / rounds as f64,
            median(ratios)
        );
    }
}
