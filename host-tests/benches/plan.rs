//! Criterion benchmark of a whole plan on `complex-26`, (0,0) -> (25,25), OHACA:
//!
//! - `full_50x100`: 50 ants x 100 iterations, early stop off (`patience = 0`): a fixed amount of
//!   work, the number to compare across changes;
//! - `default`: the default parameters (early stop after 10 stale iterations).
//!
//! Each prints the ant moves of one run first, so ant steps per second = moves / time.
//!
//! ```text
//! cargo bench -p ohaca-host-tests --target host-tuple --bench plan
//! ```

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use ohaca::{plan, Params, Point};
use ohaca_host_tests::heap;
use ohaca_host_tests::maps::{maps_dir, Map};

fn bench_plan(c: &mut Criterion) {
    let map = Map::load(maps_dir().join("complex-26.map")).expect("complex-26.map");
    let grid = map.grid();
    let (start, goal) = (Point::new(0, 0), Point::new(25, 25));
    let mut storage = heap::storage(map.cells());
    let configs = [
        (
            "full_50x100",
            Params {
                ants: 50,
                iterations: 100,
                patience: 0,
                refine_patience: 0,
                ..Params::default()
            },
        ),
        ("default", Params::default()),
    ];
    let mut group = c.benchmark_group("complex-26");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    for (name, params) in configs {
        let p = plan(&grid, start, goal, &params, storage.workspace()).expect("a path");
        println!(
            "complex-26/{name}: {} ant moves, {} iterations, length {:.4} per run",
            p.moves, p.iterations, p.length
        );
        group.bench_function(name, |b| {
            b.iter(|| {
                let p = plan(
                    &grid,
                    black_box(start),
                    black_box(goal),
                    black_box(&params),
                    storage.workspace(),
                )
                .expect("a path");
                black_box(p.length)
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_plan);
criterion_main!(benches);
