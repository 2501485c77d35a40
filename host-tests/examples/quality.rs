//! Quality of one planner configuration on every shared map, as a Markdown table.
//!
//! ```text
//! cargo run --profile host -p ohaca-host-tests --target host-tuple --example quality -- \
//!     [--algorithm aca|paca|haca|ohaca] [--a A] [--beta B] [--alpha A] [--rho R] [--xi X] [--q Q]
//!     [--ants M] [--iterations N] [--patience P] [--refine-patience P] [--seeds N] [--dead-end backtrack|die]
//!     [--smoothing shortest|greedy|none] [--no-tighten]
//! ```
//!
//! Scenarios: `ohaca_host_tests::maps::scenarios()` (the 3 fixed pairs of `maps/README.md` and
//! the 20 longest `.scen` scenarios of each Moving AI map). Seeds `1..=N` (default 30). Ratios are
//! against the exact optima of `ohaca_host_tests::reference`, computed once per scenario.

use std::process::ExitCode;
use std::time::Instant;

use ohaca::{Algorithm, DeadEnd, Params, SmoothingKind};
use ohaca_host_tests::maps::scenarios;
use ohaca_host_tests::quality::{prepare, run_map, summarize};

const USAGE: &str = "usage: quality [--algorithm aca|paca|haca|ohaca] [--a A] [--beta B] \
[--alpha A] [--rho R] [--xi X] [--q Q] [--ants M] [--iterations N] [--patience P] [--refine-patience P] [--seeds N] \
[--dead-end backtrack|die] [--smoothing shortest|greedy|none] [--no-tighten]";

fn parse_args(args: &[String]) -> Result<(Params, u64), String> {
    let mut p = Params::default();
    let mut seeds = 30u64;
    let mut it = args.iter();
    while let Some(flag) = it.next() {
        if flag == "--no-tighten" {
            p.tighten = false;
            continue;
        }
        if flag == "-h" || flag == "--help" {
            return Err(String::new());
        }
        let value = it
            .next()
            .ok_or_else(|| format!("{flag} needs a value"))?
            .as_str();
        let f = || {
            value
                .parse::<f32>()
                .map_err(|_| format!("{flag}: not a number: {value}"))
        };
        let u = || {
            value
                .parse::<u16>()
                .map_err(|_| format!("{flag}: not a count: {value}"))
        };
        match flag.as_str() {
            "--algorithm" => {
                p.algorithm = Algorithm::from_name(value)
                    .ok_or_else(|| format!("unknown algorithm {value}"))?
            }
            "--dead-end" => {
                p.dead_end =
                    DeadEnd::from_name(value).ok_or_else(|| format!("unknown dead end {value}"))?
            }
            "--smoothing" => {
                p.smoothing = SmoothingKind::from_name(value)
                    .ok_or_else(|| format!("unknown smoothing {value}"))?
            }
            "--a" => p.a = f()?,
            "--beta" => p.beta = f()?,
            "--alpha" => p.alpha = f()?,
            "--rho" => p.rho = f()?,
            "--xi" => p.xi = f()?,
            "--q" => p.q = f()?,
            "--ants" => p.ants = u()?,
            "--iterations" => p.iterations = u()?,
            "--patience" => p.patience = u()?,
            "--refine-patience" => p.refine_patience = u()?,
            "--seeds" => {
                seeds = value
                    .parse()
                    .map_err(|_| format!("--seeds: not a count: {value}"))?
            }
            _ => return Err(format!("unknown option {flag}")),
        }
    }
    p.validate().map_err(|e| e.to_string())?;
    if seeds == 0 {
        return Err("--seeds must be at least 1".into());
    }
    Ok((p, seeds))
}

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (params, n_seeds) = match parse_args(&args) {
        Ok(v) => v,
        Err(e) => {
            if !e.is_empty() {
                eprintln!("error: {e}");
            }
            eprintln!("{USAGE}");
            return ExitCode::from(2);
        }
    };
    let seeds: Vec<u64> = (1..=n_seeds).collect();
    let t0 = Instant::now();
    let prepared = prepare(scenarios());
    let t_ref = t0.elapsed();
    let p = &params;
    println!(
        "## Quality: {} (ants {}, iterations {}, patience {}, alpha {}, beta {}, rho {}, a {}, \
         xi {}, q {}, dead end {}, smoothing {}, tighten {}), seeds 1..={n_seeds}\n",
        p.algorithm,
        p.ants,
        p.iterations,
        p.patience,
        p.alpha,
        p.beta,
        p.rho,
        p.a,
        p.xi,
        p.q,
        p.dead_end,
        p.smoothing,
        p.tighten
    );
    println!(
        "| map | scenarios | runs | valid % | mean raw / opt8 | mean smoothed / any-angle | \
         worst raw / opt8 | worst smoothed / any-angle | mean turns | mean best_iteration | \
         mean iterations | mean ant moves |"
    );
    println!(
        "| --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"
    );
    let mut bad = Vec::new();
    let t1 = Instant::now();
    let mut all = Vec::new();
    for prep in &prepared {
        let runs = run_map(prep, &params, &seeds);
        let s = summarize(&runs);
        println!(
            "| {} | {} | {} | {:.1} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2} | {:.2} | {:.2} | {:.0} |",
            prep.name,
            prep.cases.len(),
            s.runs,
            100.0 * s.valid as f64 / s.runs as f64,
            s.mean_raw_ratio,
            s.mean_smooth_ratio,
            s.worst_raw_ratio,
            s.worst_smooth_ratio,
            s.mean_turns,
            s.mean_best_iteration,
            s.mean_iterations,
            s.mean_moves,
        );
        bad.extend(s.invalid.iter().map(|m| format!("{}: {m}", prep.name)));
        all.extend(runs);
    }
    let s = summarize(&all);
    println!(
        "| **all** | {} | {} | {:.1} | {:.4} | {:.4} | {:.4} | {:.4} | {:.2} | {:.2} | {:.2} | {:.0} |",
        prepared.iter().map(|p| p.cases.len()).sum::<usize>(),
        s.runs,
        100.0 * s.valid as f64 / s.runs as f64,
        s.mean_raw_ratio,
        s.mean_smooth_ratio,
        s.worst_raw_ratio,
        s.worst_smooth_ratio,
        s.mean_turns,
        s.mean_best_iteration,
        s.mean_iterations,
        s.mean_moves,
    );
    println!(
        "\nopt8 = exact shortest 8-connected path (no corner cutting); any-angle = exact shortest \
         path through cell centres by the segment rule. Ratios are means over all scenario-seed \
         runs of a map. References took {:.2} s, {} plans took {:.2} s ({:.2} ms per plan).",
        t_ref.as_secs_f64(),
        s.runs,
        t1.elapsed().as_secs_f64(),
        s.mean_time.as_secs_f64() * 1e3
    );
    if s.failed > 0 {
        println!("\n{} runs returned an error.", s.failed);
    }
    if !bad.is_empty() {
        println!("\n**{} invalid plans:**\n", bad.len());
        for b in bad.iter().take(20) {
            println!("- {b}");
        }
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}
