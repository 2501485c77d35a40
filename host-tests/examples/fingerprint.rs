//! A fingerprint of the planner's output on the shared maps: one line per (map, scenario,
//! algorithm, seed) with the raw path's length and a hash of the raw path and the waypoints.
//! Diff two runs to see whether a change moved any path (a refactor must not).
//!
//! ```text
//! cargo run --profile host -p ohaca-host-tests --target host-tuple --example fingerprint > before.txt
//! ```
//!
//! `OHACA_NO_PRUNE=1` turns dead-end pruning off (`Params::prune`). `--large N`: the `N` longest
//! scenarios of every large map (`maps/large/`) instead, seeds 1 and 2, OHACA only, once with the
//! host's storage and once bounded like the STM32F411's (`device` lines: 2,047 steps, no move
//! table, the iteration's best and worst ants walked again instead of kept).

use std::hash::{DefaultHasher, Hash, Hasher};

use ohaca::heap::HeapStorage;
use ohaca::{plan, Algorithm, Params, Plan};
use ohaca_host_tests::large::large_maps;
use ohaca_host_tests::maps::scenarios;

fn line(pl: &Plan<'_>) -> String {
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

fn large(scen: usize) {
    for m in large_maps(scen) {
        let grid = m.map.grid();
        let mut host = ohaca_host_tests::heap::storage(m.map.cells());
        let mut device = HeapStorage::with_steps(m.map.cells(), 2047, false, 1024)
            .unwrap_or_else(|e| panic!("{e}"))
            .replaying();
        for (c, case) in m.cases.iter().enumerate() {
            for seed in 1..=2u64 {
                let p = Params {
                    seed,
                    ..Params::default()
                };
                for (name, st) in [("host", &mut host), ("device", &mut device)] {
                    let l = match plan(&grid, case.start, case.goal, &p, st.workspace()) {
                        Err(e) => format!("error {e}"),
                        Ok(pl) => line(&pl),
                    };
                    println!("{} {c} {seed} {name}: {l}", m.name);
                }
            }
        }
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if let [flag, n] = &args[..] {
        assert_eq!(flag, "--large", "usage: fingerprint [--large N]");
        large(n.parse().expect("--large N"));
        return;
    }
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
                        Ok(pl) => line(&pl),
                    };
                    println!("{} {c} {alg} {seed}: {line}", set.name);
                }
            }
        }
    }
}
