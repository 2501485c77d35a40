//! Per-iteration moves on one large-map scenario (diagnostics).
use ohaca::{Params, Run};
use ohaca_host_tests::large::load_large;
use ohaca_host_tests::maps::maps_dir;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let name = args.first().map_or("Boston_0_256", |s| s.as_str());
    let k: usize = args.get(1).map_or(0, |s| s.parse().unwrap());
    let m = load_large(&maps_dir().join("large"), name, k + 1);
    let case = &m.cases[k];
    let grid = m.map.grid();
    let mut st = ohaca_host_tests::heap::storage(m.map.cells());
    let p = Params::default();
    let mut run = Run::new(&grid, case.start, case.goal, &p, st.workspace()).unwrap();
    println!(
        "{name} #{k}: {:?} -> {:?} opt {:.2}, pruned {}",
        case.start,
        case.goal,
        case.stated_opt8,
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
