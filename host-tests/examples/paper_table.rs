//! The paper's comparison of ACA, PACA, HACA and OHACA on the simple and complex maps, as
//! Markdown tables.
//!
//! ```text
//! cargo run --release -p ohaca-host-tests --target host-tuple --example paper_table [-- --seeds N]
//! ```
//!
//! `simple-18` (0,0)->(17,17) and `complex-26` (0,0)->(25,25), seeds `1..=N` (default 30).
//! Three tables: [`Params::default`] (dead ends handled by backtracking), the default with dying
//! ants (`--dead-end die`), and [`Params::paper`] (`--preset paper`: the paper's algorithm as
//! written, i.e. dying ants, no tightening, always 100 iterations, greedy smoothing).
//!
//! - *success* is the share of runs that returned a path;
//! - *ants arriving* is the share of first-iteration ants (pheromone still uniform) that reach the
//!   goal, 50 ants per seed: the paper's "lost ants" measure, which run-level success cannot show
//!   because a run succeeds as soon as any ant of any iteration arrives;
//! - lengths are the output lengths (smoothed for OHACA), turns along the output path;
//! - *convergence* is `best_iteration + 1`, the iteration the best path was first found in;
//! - *time* is the wall-clock time of one `plan` call on this machine, runs done one at a time.

use std::time::Duration;

use ohaca::ant::Ant;
use ohaca::bitmap::words;
use ohaca::grid::Moves;
use ohaca::heuristic::Heuristic;
use ohaca::pheromone::{Blocks, Table};
use ohaca::prune::prune;
use ohaca::rng::Xoshiro128pp;
use ohaca::{Algorithm, DeadEnd, Params};
use ohaca_host_tests::heap;
use ohaca_host_tests::maps::scenarios;
use ohaca_host_tests::quality::{prepare, run_one, summarize, Prepared, Run};

/// Share of `params.ants` first-iteration ants per seed that reach the goal.
fn first_iteration_arrivals(prep: &Prepared, params: &Params, seeds: &[u64]) -> f64 {
    let map = &prep.map;
    let grid = map.grid();
    let case = &prep.cases[0];
    let cells = map.cells();
    let blocks = Blocks::new(map.width(), map.height());
    let mut tau_buf = vec![[params.tau0; 4]; blocks.count()];
    let tau = Table::new(blocks, &mut tau_buf);
    let heuristic = Heuristic::new(case.goal, params.attraction(), params.beta);
    let moves = Moves::new(grid, &[]);
    // The first iteration as the planner runs it, pruning included when the parameters ask.
    let mut dead = vec![0u32; words(cells)];
    if params.prune {
        let mut stack = vec![0u32; cells];
        prune(&moves, case.start, case.goal, &mut dead, &mut stack);
    }
    let ant = Ant {
        moves: &moves,
        start: case.start,
        goal: case.goal,
        tau: &tau,
        heuristic: &heuristic,
        alpha: params.alpha,
        dead_end: params.dead_end,
        dead: &dead,
        route: None,
        weights: None,
        budget: u32::MAX,
    };
    let (mut arrived, mut total) = (0u64, 0u64);
    let mut tabu = vec![0u32; words(cells)];
    let mut tour = vec![0u8; cells];
    for &seed in seeds {
        let mut rng = Xoshiro128pp::from_u64(seed);
        for _ in 0..params.ants {
            total += 1;
            arrived += u64::from(
                ant.walk(
                    &mut rng,
                    &mut ohaca::colony::tabu::TabuSet::new(&mut tabu),
                    &mut tour,
                )
                .is_ok(),
            );
        }
    }
    arrived as f64 / total as f64
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let n_seeds: u64 = match args.as_slice() {
        [] => 30,
        [flag, n] if flag == "--seeds" => n.parse().expect("--seeds N"),
        _ => {
            eprintln!("usage: paper_table [--seeds N]");
            std::process::exit(2);
        }
    };
    let seeds: Vec<u64> = (1..=n_seeds).collect();
    let prepared: Vec<Prepared> = prepare(
        scenarios()
            .into_iter()
            .filter(|s| s.name == "simple-18" || s.name == "complex-26")
            .collect(),
    );
    let settings = [
        ("default parameters", Params::default()),
        (
            "default parameters with --dead-end die",
            Params {
                dead_end: DeadEnd::Die,
                ..Params::default()
            },
        ),
        ("the paper preset (--preset paper)", Params::paper()),
    ];
    for (setting, base) in settings {
        println!("## Paper comparison, {setting}, seeds 1..={n_seeds}\n");
        println!(
            "| map | algorithm | success % | ants arriving (1st iteration) % | best | mean | worst | \
             std dev | mean turns | mean convergence iteration | mean iterations | mean time/plan (ms) |"
        );
        println!(
            "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
        );
        for prep in &prepared {
            let case = &prep.cases[0];
            for algorithm in Algorithm::ALL {
                let params = Params { algorithm, ..base };
                let mut storage = heap::storage(prep.map.cells());
                let runs: Vec<Run> = seeds
                    .iter()
                    .map(|&seed| {
                        let p = Params { seed, ..params };
                        let (outcome, time) = run_one(&prep.map, case, &p, &mut storage);
                        Run {
                            case: 0,
                            seed,
                            outcome,
                            time,
                        }
                    })
                    .collect();
                let s = summarize(&runs);
                assert!(s.invalid.is_empty(), "invalid plans: {:?}", s.invalid);
                let arriving = first_iteration_arrivals(prep, &params, &seeds);
                println!(
                    "| {} | {} | {:.1} | {:.1} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2} | {:.2} | {:.2} | {:.2} |",
                    prep.name,
                    algorithm.name().to_uppercase(),
                    100.0 * s.valid as f64 / s.runs as f64,
                    100.0 * arriving,
                    s.best_length,
                    s.mean_length,
                    s.worst_length,
                    s.std_length,
                    s.mean_turns,
                    s.mean_best_iteration + 1.0,
                    s.mean_iterations,
                    ms(s.mean_time),
                );
            }
        }
        println!();
    }
    for prep in &prepared {
        let o = prep.cases[0].optima;
        println!(
            "{}: exact 8-connected optimum {:.4}, any-angle optimum {:.4}.",
            prep.name, o.opt8, o.any_angle
        );
    }
    println!(
        "\nLengths of ACA, PACA and HACA are raw 8-connected lengths; OHACA's are smoothed. \
         Statistics are over the runs that returned a path."
    );
}
