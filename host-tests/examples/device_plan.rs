//! One plan as the device makes it (ant paths bounded to the STM32F411 firmware's 2,047 steps of its
//! full layout, or
//! `--steps N`, e.g. the STM32H743's 16384; no move table on maps of more than 1,024 cells; the
//! iteration's best and worst ants walked again instead of kept), for profiling the core on the
//! host with callgrind, whose instruction counts follow the device's: the phases are the
//! functions `Run::new`, `Run::step` and `Run::finish`.
//!
//! ```text
//! cargo build --release -p ohaca-host-tests --target host-tuple --example device_plan
//! valgrind --tool=callgrind target/x86_64-unknown-linux-gnu/release/examples/device_plan \
//!     [--map maps/large/Boston_0_256.map] [--start 184,0] [--goal 8,254] [--seeds 1] [--patience P] \
//!     [--steps 2047]
//! ```
//!
//! Prints one line per seed: iterations, lengths, ant moves and a hash of the raw path and the
//! waypoints (identical lines before and after a change: identical paths).

use std::hash::{DefaultHasher, Hash, Hasher};

use ohaca::grid::Point;
use ohaca::heap::HeapStorage;
use ohaca::planner::{Poll, Run};
use ohaca::Params;
use ohaca_host_tests::maps::Map;

/// The STM32F411's bound in its full layout (maps of up to 68,256 cells; the compact one, beyond,
/// keeps 4,095 steps in other buffers than these).
const STEPS: usize = ohaca::planner::arena::FULL_STEPS;

fn point(s: &str) -> Point {
    let (x, y) = s.split_once(',').expect("X,Y");
    Point::new(x.parse().expect("X"), y.parse().expect("Y"))
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut map = String::from("maps/large/Boston_0_256.map");
    let (mut start, mut goal) = (Point::new(184, 0), Point::new(8, 254));
    let mut seeds = 1u64;
    let mut params = Params::default();
    let mut steps = STEPS;
    let mut arena: Option<usize> = None;
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let v = it.next().expect("every option takes a value");
        match flag.as_str() {
            "--map" => map = v.clone(),
            "--start" => start = point(v),
            "--goal" => goal = point(v),
            "--seeds" => seeds = v.parse().expect("--seeds N"),
            "--patience" => params.patience = v.parse().expect("--patience P"),
            "--steps" => steps = v.parse().expect("--steps N"),
            "--arena" => arena = Some(v.parse().expect("--arena WORDS")),
            _ => panic!("unknown option {flag}"),
        }
    }
    let m = Map::load(&map).unwrap_or_else(|e| panic!("{e}"));
    let grid = m.grid();
    let mut st = HeapStorage::with_steps(m.cells(), steps, m.cells() <= 1024, 1024)
        .unwrap_or_else(|e| panic!("{e}"))
        .replaying();
    for seed in 1..=seeds {
        let p = Params { seed, ..params };
        let mut words = vec![0u32; arena.unwrap_or(0)];
        let ws = match arena {
            Some(_) => {
                ohaca::planner::arena::carve(&mut words, m.cells(), steps)
                    .expect("the map fits the arena")
                    .workspace
            }
            None => st.workspace(),
        };
        let mut run = Run::new(&grid, start, goal, &p, ws).expect("plan");
        while let Poll::Working(_) = run.poll() {}
        let pl = run.finish().expect("a path");
        let mut h = DefaultHasher::new();
        pl.raw().collect::<Vec<_>>().hash(&mut h);
        pl.waypoints().hash(&mut h);
        println!(
            "seed {seed}: it {} best {} raw {:.4} len {:.4} moves {} pruned {} hash {:016x}",
            pl.iterations,
            pl.best_iteration,
            pl.raw_length,
            pl.length,
            pl.moves,
            pl.pruned,
            h.finish()
        );
    }
}
