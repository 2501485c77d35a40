//! Per-iteration moves on one large-map scenario, or on a fresh maze (diagnostics).
//!
//! ```text
//! cargo run --profile host -p ohaca-host-tests --target host-tuple --example diag -- [MAP [K]]
//! cargo run --profile host -p ohaca-host-tests --target host-tuple --example diag -- maze:WIDTH[:SIDE] [K]
//! ```
use ohaca::{Params, Run};
use ohaca_host_tests::gen::{far_pair, maze};
use ohaca_host_tests::large::load_large;
use ohaca_host_tests::maps::maps_dir;
use ohaca_host_tests::reference::astar8;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("Boston_0_256", |s| s.as_str());
    let k: usize = args.get(1).map_or(0, |s| s.parse().unwrap());
    let (map, start, goal, opt) = if let Some(spec) = name.strip_prefix("maze:") {
        let mut it = spec.split(':').map(|v| v.parse::<u16>().unwrap());
        let width = it.next().unwrap();
        let side = it.next().unwrap_or(512);
        let map = maze(side, width, 1);
        let (s, g) = far_pair(&map, k).unwrap();
        let opt = astar8(&map, s, g).unwrap().0;
        (map, s, g, opt)
    } else {
        let m = load_large(&maps_dir().join("large"), name, k + 1);
        let case = &m.cases[k];
        (m.map.clone(), case.start, case.goal, case.stated_opt8)
    };
    let grid = map.grid();
    let mut st = ohaca_host_tests::heap::storage(map.cells());
    let p = Params::default();
    let mut run = Run::new(&grid, start, goal, &p, st.workspace()).unwrap();
    println!(
        "{name} #{k}: {start:?} -> {goal:?} opt {opt:.2}, pruned {}",
        run.pruned()
    );
    let mut last = 0;
    while run.step() || run.iteration() > 0 && last == 0 {
        println!(
            "it {} moves {} best {:?}",
            run.iteration(),
            run.moves() - last,
            run.best_length()
        );
        last = run.moves();
        if run.is_done() {
            break;
        }
    }
}
