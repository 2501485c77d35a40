//! Criterion benchmark of the default plan on large public maps, side by side with one exact A*
//! (the `pathfinding` crate's `astar`, 8 moves without corner cutting, integer costs 1000 / 1414)
//! on the same map and scenario: the issue's yardstick is the plan's time over the A*'s,
//! measured in the same run on the same machine.
//!
//! Scenarios: the longest scenario of `maze512-1-0` (512 x 512 maze), `NewYork_0_512` (city)
//! and `Boston_0_256` (city), from `maps/large/`.
//!
//! ```text
//! cargo bench -p ohaca-host-tests --target host-tuple --bench large
//! ```

use std::hint::black_box;
use std::time::{Duration, Instant};

#[path = "shared/astar.rs"]
mod astar;
use astar::astar_cost;
use criterion::{criterion_group, criterion_main, Criterion};
use ohaca::{plan, Params};
use ohaca_host_tests::large::load_large;
use ohaca_host_tests::maps::maps_dir;

fn bench_large(c: &mut Criterion) {
    let dir = maps_dir().join("large");
    let mut group = c.benchmark_group("large");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_secs(5));
    for name in ["maze512-1-0", "NewYork_0_512", "Boston_0_256"] {
        let m = load_large(&dir, name, 1);
        let case = m.cases[0].clone();
        let grid = m.map.grid();
        let mut storage = ohaca_host_tests::heap::storage(m.map.cells());
        let params = Params::default();
        // Side by side first: 5 of each, alternating, so both see the same machine.
        let (mut tp, mut ta) = (Duration::ZERO, Duration::ZERO);
        let mut summary = String::new();
        for _ in 0..5 {
            let t0 = Instant::now();
            let p =
                plan(&grid, case.start, case.goal, &params, storage.workspace()).expect("a path");
            tp += t0.elapsed();
            let t0 = Instant::now();
            let a = astar_cost(&m.map, case.start, case.goal).expect("a path");
            ta += t0.elapsed();
            summary = format!(
                "raw {:.3} (optimum {:.3}, {:.4}x), {} moves, {} iterations",
                p.raw_length,
                f64::from(a) / 1000.0,
                f64::from(p.raw_length) / case.stated_opt8,
                p.moves,
                p.iterations
            );
        }
        println!(
            "large/{name}: plan {:.1} ms, A* {:.1} ms, plan/A* = {:.1}; {summary}",
            tp.as_secs_f64() * 200.0,
            ta.as_secs_f64() * 200.0,
            tp.as_secs_f64() / ta.as_secs_f64()
        );
        group.bench_function(format!("ohaca/{name}"), |b| {
            b.iter(|| {
                let p = plan(
                    &grid,
                    black_box(case.start),
                    black_box(case.goal),
                    &params,
                    storage.workspace(),
                )
                .expect("a path");
                black_box(p.length)
            })
        });
        group.bench_function(format!("astar/{name}"), |b| {
            b.iter(|| {
                black_box(astar_cost(
                    &m.map,
                    black_box(case.start),
                    black_box(case.goal),
                ))
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_large);
criterion_main!(benches);
