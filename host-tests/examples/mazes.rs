//! Quality and cost of the default plan on fresh wide-corridor mazes (issue 21, item 2): perfect
//! mazes with corridors 4 to 32 cells wide and one-cell walls ([`ohaca_host_tests::gen::maze`]),
//! generated from a seed, so nobody has tuned the planner on them. Side by side with one exact A*
//! of the `pathfinding` crate per case, timed in the same run.
//!
//! ```text
//! cargo run --release -p ohaca-host-tests --target host-tuple --example mazes -- \
//!     [--side N] [--widths 4,8,16,32] [--mazes N] [--pairs N] [--seeds N]
//! ```
//!
//! Per width: `--mazes` mazes (default 2) of `--side` cells a side (default 512), `--pairs` far
//! start/goal pairs in each (default 3, [`ohaca_host_tests::gen::far_pair`]), planning seeds
//! `1..=--seeds` (default 2). Prints one Markdown row per width: validity, raw length over the
//! exact 8-connected optimum (mean, max), smoothed over it, ant moves, iterations, and the plan's
//! wall-clock time over the A*'s.

use std::time::Instant;

#[path = "../benches/shared/astar.rs"]
mod astar;
use astar::astar_cost;

use ohaca::{plan, Params};
use ohaca_host_tests::check::check_plan;
use ohaca_host_tests::gen::{far_pair, maze};
use ohaca_host_tests::reference::astar8;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mut side, mut mazes, mut pairs, mut seeds) = (512u16, 2u64, 3usize, 2u64);
    let mut widths = vec![4u16, 8, 16, 32];
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let v = it.next().expect("every option takes a value");
        match flag.as_str() {
            "--side" => side = v.parse().expect("--side N"),
            "--widths" => widths = v.split(',').map(|w| w.parse().expect("a width")).collect(),
            "--mazes" => mazes = v.parse().expect("--mazes N"),
            "--pairs" => pairs = v.parse().expect("--pairs N"),
            "--seeds" => seeds = v.parse().expect("--seeds N"),
            _ => panic!("unknown option {flag}"),
        }
    }
    println!(
        "| corridor | size | runs | valid | raw/opt8 mean | max | smoothed/opt8 | moves/run | iters | plan ms | A* ms | plan/A* |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    for &width in &widths {
        let (mut n, mut valid) = (0usize, 0usize);
        let (mut raw, mut raw_max, mut smooth, mut moves, mut iters) = (0.0, 0.0f64, 0.0, 0.0, 0.0);
        let (mut t_plan, mut t_astar) = (0.0f64, 0.0f64);
        for m in 0..mazes {
            let map = maze(side, width, m + 1);
            let grid = map.grid();
            let mut st = ohaca_host_tests::heap::storage(map.cells());
            for k in 0..pairs {
                let (s, g) = far_pair(&map, k).expect("a maze has free cells");
                let opt = astar8(&map, s, g).expect("a maze is connected").0;
                for seed in 1..=seeds {
                    // One pathfinding A*, then the plan, alternately: the same machine state.
                    let t0 = Instant::now();
                    let a = astar_cost(&map, s, g);
                    t_astar += t0.elapsed().as_secs_f64();
                    assert!(a.is_some());
                    let p = Params {
                        seed,
                        ..Params::default()
                    };
                    let t0 = Instant::now();
                    let r = plan(&grid, s, g, &p, st.workspace());
                    t_plan += t0.elapsed().as_secs_f64();
                    n += 1;
                    match r {
                        Ok(pl) => {
                            if let Err(e) = check_plan(&map, s, g, &pl, usize::MAX) {
                                eprintln!("width {width} maze {m} pair {k} seed {seed}: {e}");
                                continue;
                            }
                            valid += 1;
                            let q = f64::from(pl.raw_length) / opt;
                            raw += q;
                            raw_max = raw_max.max(q);
                            smooth += f64::from(pl.length) / opt;
                            moves += pl.moves as f64;
                            iters += f64::from(pl.iterations);
                        }
                        Err(e) => eprintln!("width {width} maze {m} pair {k} seed {seed}: {e}"),
                    }
                }
            }
        }
        let k = valid.max(1) as f64;
        println!(
            "| {width} | {side}x{side} | {n} | {valid} | {:.4} | {:.4} | {:.4} | {:.0} | {:.1} | {:.1} | {:.2} | {:.1} |",
            raw / k,
            raw_max,
            smooth / k,
            moves / k,
            iters / k,
            t_plan / n.max(1) as f64 * 1e3,
            t_astar / n.max(1) as f64 * 1e3,
            t_plan / t_astar
        );
    }
}
