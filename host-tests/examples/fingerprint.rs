//! A fingerprint of the planner's output on the shared maps: one line per (map, scenario,
//! algorithm, seed) with the raw path's length and a hash of the raw path and the waypoints.
//! Diff two runs to see whether a change moved any path (a refactor must not).
//!
//! ```text
//! cargo run --release -p ohaca-host-tests --target host-tuple --example fingerprint > before.txt
//! ```
//!
//! `OHACA_NO_PRUNE=1` turns dead-end pruning off (`Params::prune`).

use std::hash::{DefaultHasher, Hash, Hasher};

use ohaca::{plan, Algorithm, Params};
use ohaca_host_tests::maps::scenarios;

fn main() {
    for set in scenarios() {
        let grid = set.map.grid();
        let mut st = ohaca_host_tests::heap::storage(set.map.cells());
        for (c, case) in set.cases.iter().enumerate().take(5) {
            for alg in Algorithm::ALL {
                for seed in 1..=3u64 {
                    let p = Params {
                        algorithm: alg,
                        seed,
                        prune: std::env::var_os("OHACA_NO_PRUNE").is_none(),
                        ..Params::default()
                    };
                    let line = match plan(&grid, case.start, case.goal, &p, st.workspace()) {
                        Err(e) => format!("error {e}"),
                        Ok(pl) => {
                            let mut h = DefaultHasher::new();
                            pl.raw().collect::<Vec<_>>().hash(&mut h);
                            pl.waypoints().hash(&mut h);
                            format!(
                                "raw {:.4} len {:.4} it {} best {} moves {} hash {:016x}",
                                pl.raw_length,
                                pl.length,
                                pl.iterations,
                                pl.best_iteration,
                                pl.moves,
                                h.finish()
                            )
                        }
                    };
                    println!("{} {c} {alg} {seed}: {line}", set.name);
                }
            }
        }
    }
}
