//! Quality and cost of the planner on the large public Moving AI maps (`maps/large/`), side by side
//! with one exact A* per scenario.
//!
//! ```text
//! cargo run --release -p ohaca-host-tests --target host-tuple --example large -- \
//!     [--maps NAME,NAME,...] [--scen N] [--seeds N] [--ants M] [--iterations N] [--patience P]
//!     [--alpha A] [--beta B]
//!     [--refine-patience P] [--steps N] [--arena WORDS]
//!
//! `--steps N` bounds the ant paths as a device does; `--arena WORDS` plans in an arena of that
//! many words laid out by `ohaca::planner::arena::carve` (the STM32F411's: 25856), paths bounded
//! by `--steps` (default the STM32F411's bound, `ohaca::board::F411.max_steps`).
//! ```
//!
//! For each map: the `N` (default 20) scenarios of largest `optimal` of its scenario file, the exact
//! 8-connected optimum by the reference A* (checked against the file), then the default plan for
//! every seed. Prints one Markdown row per map: validity, mean / max raw length over the optimum,
//! mean smoothed length over the optimum, ant moves, iterations, and the plan's wall-clock time
//! over the A*'s (a ratio measured in the same run, on the same machine).

use std::time::Instant;

use ohaca::{plan, Params};
use ohaca_host_tests::check::check_plan;
use ohaca_host_tests::large::{large_maps, LargeMap};
use ohaca_host_tests::quality::par_map;
use ohaca_host_tests::reference::astar8;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mut params = Params::default();
    let mut seeds = 1u64;
    let mut scen = 20usize;
    let mut only: Option<Vec<String>> = None;
    let mut steps: Option<usize> = None;
    let mut arena: Option<usize> = None;
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        let v = it.next().expect("every option takes a value");
        match flag.as_str() {
            "--maps" => only = Some(v.split(',').map(str::to_string).collect()),
            "--scen" => scen = v.parse().expect("--scen N"),
            "--seeds" => seeds = v.parse().expect("--seeds N"),
            "--ants" => params.ants = v.parse().expect("--ants M"),
            "--iterations" => params.iterations = v.parse().expect("--iterations N"),
            "--alpha" => params.alpha = v.parse().expect("--alpha A"),
            "--beta" => params.beta = v.parse().expect("--beta B"),
            "--patience" => params.patience = v.parse().expect("--patience P"),
            "--refine-patience" => params.refine_patience = v.parse().expect("--refine-patience P"),
            "--steps" => steps = Some(v.parse().expect("--steps N")),
            "--arena" => arena = Some(v.parse().expect("--arena WORDS")),
            _ => panic!("unknown option {flag}"),
        }
    }
    let maps: Vec<LargeMap> = large_maps(scen)
        .into_iter()
        .filter(|m| only.as_ref().is_none_or(|o| o.iter().any(|n| n == &m.name)))
        .collect();
    println!(
        "| map | size | runs | valid | raw/opt8 mean | max | smoothed/opt8 | moves/run | iters | plan ms | A* ms | plan/A* |"
    );
    println!("| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |");
    let (mut all_raw, mut all_n) = (0.0f64, 0usize);
    for m in &maps {
        let cases = &m.cases;
        let jobs: Vec<(usize, u64)> = (0..cases.len())
            .flat_map(|c| (1..=seeds).map(move |s| (c, s)))
            .collect();
        let res = par_map(jobs.len(), |j| {
            let (c, seed) = jobs[j];
            let case = &cases[c];
            let t0 = Instant::now();
            let opt = astar8(&m.map, case.start, case.goal).map(|(d, _)| d);
            let astar = t0.elapsed().as_secs_f64();
            let opt = opt.expect("scenario is solvable");
            assert!(
                (opt - case.stated_opt8).abs() < 1e-3,
                "{}: A* {} vs stated {}",
                m.name,
                opt,
                case.stated_opt8
            );
            let cells = m.map.cells();
            let mut st = match steps {
                Some(s) if arena.is_none() => {
                    ohaca::heap::HeapStorage::with_steps(cells, s, cells <= 1024, 1024)
                        .expect("host storage")
                }
                _ => ohaca_host_tests::heap::storage(cells),
            };
            let mut words = vec![0u32; arena.unwrap_or(0)];
            let mut curve = vec![ohaca::planner::CurvePoint::default(); 1024];
            let grid = m.map.grid();
            let p = Params { seed, ..params };
            let t0 = Instant::now();
            let ws = match arena {
                Some(_) => {
                    let c = ohaca::planner::arena::carve(
                        &mut words,
                        cells,
                        steps.unwrap_or(ohaca::board::F411.max_steps),
                    )
                    .expect("the map fits the arena");
                    c.workspace.with_curve(&mut curve)
                }
                None => st.workspace(),
            };
            let r = plan(&grid, case.start, case.goal, &p, ws);
            let time = t0.elapsed().as_secs_f64();
            match r {
                Err(e) => (false, 0.0, 0.0, 0, 0, time, astar, format!("{e}")),
                Ok(pl) => {
                    let check = check_plan(&m.map, case.start, case.goal, &pl, usize::MAX);
                    let ok = check.is_ok();
                    (
                        ok,
                        f64::from(pl.raw_length) / opt,
                        f64::from(pl.length) / opt,
                        pl.moves,
                        u64::from(pl.iterations),
                        time,
                        astar,
                        check.err().unwrap_or_default(),
                    )
                }
            }
        });
        let n = res.len();
        let valid = res.iter().filter(|r| r.0).count();
        let ok: Vec<_> = res.iter().filter(|r| r.0).collect();
        let k = ok.len().max(1) as f64;
        let raw = ok.iter().map(|r| r.1).sum::<f64>() / k;
        let raw_max = ok.iter().map(|r| r.1).fold(0.0, f64::max);
        let sm = ok.iter().map(|r| r.2).sum::<f64>() / k;
        let moves = ok.iter().map(|r| r.3 as f64).sum::<f64>() / k;
        let iters = ok.iter().map(|r| r.4 as f64).sum::<f64>() / k;
        let t = res.iter().map(|r| r.5).sum::<f64>() / n as f64 * 1e3;
        let a = res.iter().map(|r| r.6).sum::<f64>() / n as f64 * 1e3;
        all_raw += raw * ok.len() as f64;
        all_n += ok.len();
        for r in res.iter().filter(|r| !r.0) {
            eprintln!("{}: failed {}", m.name, r.7);
        }
        println!(
            "| {} | {}x{} | {} | {} | {:.4} | {:.4} | {:.4} | {:.0} | {:.1} | {:.1} | {:.2} | {:.1} |",
            m.name,
            m.map.width(),
            m.map.height(),
            n,
            valid,
            raw,
            raw_max,
            sm,
            moves,
            iters,
            t,
            a,
            t / a
        );
    }
    println!(
        "\nmean raw/opt8 over all valid runs: {:.5}",
        all_raw / all_n.max(1) as f64
    );
}
