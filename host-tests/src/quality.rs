//! Quality runs on the shared maps: plan every scenario over a range of seeds, validate every
//! result with [`crate::check`], and compare its lengths with the exact optima of
//! [`crate::reference`] (computed once per scenario by [`prepare`]).
//!
//! Used by `tests/it/shared_maps.rs` and by the `quality` and `paper_table` examples. Runs are spread
//! over the machine's cores, but every aggregate is summed in a fixed order, so the numbers do not
//! depend on scheduling. Wall-clock times are recorded for the examples only; no test looks at them.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use ohaca::{plan, Error, Params, Point};

use crate::check::check_plan;
use crate::heap::{self, HeapStorage};
use crate::maps::{Case, Map, MapScenarios};
use crate::reference::{self, Optima};

/// A scenario with its exact optima.
#[derive(Clone, Debug)]
pub struct PreparedCase {
    /// Start cell.
    pub start: Point,
    /// Goal cell.
    pub goal: Point,
    /// Where it came from (with the optima the source states).
    pub case: Case,
    /// The exact optima, recomputed here.
    pub optima: Optima,
}

/// A shared map with its prepared scenarios.
#[derive(Clone, Debug)]
pub struct Prepared {
    /// Short name.
    pub name: String,
    /// The map.
    pub map: Map,
    /// Its scenarios.
    pub cases: Vec<PreparedCase>,
}

/// Run `f` over `0..n` on all cores; results in index order.
pub fn par_map<T: Send>(n: usize, f: impl Fn(usize) -> T + Sync) -> Vec<T> {
    let threads = std::thread::available_parallelism()
        .map_or(1, |t| t.get())
        .min(n.max(1));
    let next = AtomicUsize::new(0);
    let out: Mutex<Vec<Option<T>>> = Mutex::new((0..n).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..threads {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                if i >= n {
                    break;
                }
                let v = f(i);
                out.lock().expect("no thread panicked")[i] = Some(v);
            });
        }
    });
    out.into_inner()
        .expect("no thread panicked")
        .into_iter()
        .map(|v| v.expect("every index ran"))
        .collect()
}

/// Compute the optima of every scenario.
///
/// # Panics
/// If a scenario is unreachable (the shared maps have none).
pub fn prepare(sets: Vec<MapScenarios>) -> Vec<Prepared> {
    let jobs: Vec<(usize, usize)> = sets
        .iter()
        .enumerate()
        .flat_map(|(m, s)| (0..s.cases.len()).map(move |c| (m, c)))
        .collect();
    let optima = par_map(jobs.len(), |k| {
        let (m, c) = jobs[k];
        let (map, case) = (&sets[m].map, &sets[m].cases[c]);
        reference::optima(map, case.start, case.goal).unwrap_or_else(|| {
            panic!(
                "{}: {:?} -> {:?} unreachable",
                sets[m].name, case.start, case.goal
            )
        })
    });
    let mut optima = optima.into_iter();
    sets.into_iter()
        .map(|s| Prepared {
            cases: s
                .cases
                .into_iter()
                .map(|case| PreparedCase {
                    start: case.start,
                    goal: case.goal,
                    optima: optima.next().expect("one per case"),
                    case,
                })
                .collect(),
            name: s.name,
            map: s.map,
        })
        .collect()
}

/// One successful, valid plan.
#[derive(Clone, Debug, PartialEq)]
pub struct RunStats {
    /// Raw length (as reported).
    pub raw_length: f64,
    /// Output length (as reported; smoothed for OHACA).
    pub length: f64,
    /// `raw_length / opt8`.
    pub raw_ratio: f64,
    /// `length / any-angle optimum`.
    pub smooth_ratio: f64,
    /// Turns along the output.
    pub turns: u32,
    /// Iteration (0-based) the best path was found in.
    pub best_iteration: u16,
    /// Iterations run.
    pub iterations: u16,
    /// Ant moves made.
    pub moves: u64,
}

/// How one run ended.
#[derive(Clone, Debug, PartialEq)]
pub enum Outcome {
    /// A valid plan.
    Valid(RunStats),
    /// The planner returned an error (e.g. `NoAntArrived` with `DeadEnd::Die`).
    Failed(Error),
    /// The planner returned a plan that fails validation: a bug.
    Invalid(String),
}

/// One run.
#[derive(Clone, Debug)]
pub struct Run {
    /// Scenario index in its map.
    pub case: usize,
    /// Seed used.
    pub seed: u64,
    /// Result.
    pub outcome: Outcome,
    /// Wall-clock time of the `plan` call (for reports only).
    pub time: Duration,
}

/// Plan one scenario with `params` (whose seed is used as given) and validate the result.
pub fn run_one(
    map: &Map,
    case: &PreparedCase,
    params: &Params,
    storage: &mut HeapStorage,
) -> (Outcome, Duration) {
    let grid = map.grid();
    let t0 = Instant::now();
    let result = plan(&grid, case.start, case.goal, params, storage.workspace());
    let time = t0.elapsed();
    let outcome = match result {
        Err(e) => Outcome::Failed(e),
        Ok(p) => match check_plan(map, case.start, case.goal, &p, heap::DEFAULT_CURVE) {
            Err(e) => Outcome::Invalid(e),
            Ok(c) => {
                let o = case.optima;
                if c.raw_length < o.opt8 - 1e-3 {
                    Outcome::Invalid(format!(
                        "raw length {} below the 8-connected optimum {}",
                        c.raw_length, o.opt8
                    ))
                } else if c.length < o.any_angle - 1e-3 {
                    Outcome::Invalid(format!(
                        "length {} below the any-angle optimum {}",
                        c.length, o.any_angle
                    ))
                } else {
                    Outcome::Valid(RunStats {
                        raw_length: f64::from(p.raw_length),
                        length: f64::from(p.length),
                        raw_ratio: f64::from(p.raw_length) / o.opt8,
                        smooth_ratio: f64::from(p.length) / o.any_angle,
                        turns: p.turns,
                        best_iteration: p.best_iteration,
                        iterations: p.iterations,
                        moves: p.moves,
                    })
                }
            }
        },
    };
    (outcome, time)
}

/// Plan every scenario of `prep` for every seed in `seeds`, with `params` otherwise.
pub fn run_map(prep: &Prepared, params: &Params, seeds: &[u64]) -> Vec<Run> {
    let jobs: Vec<(usize, u64)> = (0..prep.cases.len())
        .flat_map(|c| seeds.iter().map(move |&s| (c, s)))
        .collect();
    let cells = prep.map.cells();
    let storage: Mutex<Vec<HeapStorage>> = Mutex::new(Vec::new());
    par_map(jobs.len(), |k| {
        let (case, seed) = jobs[k];
        let mut st = storage
            .lock()
            .expect("no thread panicked")
            .pop()
            .unwrap_or_else(|| heap::storage(cells));
        let p = Params { seed, ..*params };
        let (outcome, time) = run_one(&prep.map, &prep.cases[case], &p, &mut st);
        storage.lock().expect("no thread panicked").push(st);
        Run {
            case,
            seed,
            outcome,
            time,
        }
    })
}

/// Aggregates over a set of runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Summary {
    /// Runs.
    pub runs: usize,
    /// Runs that returned a valid plan.
    pub valid: usize,
    /// Runs that returned an error.
    pub failed: usize,
    /// Runs that returned an invalid plan (bugs), with their messages.
    pub invalid: Vec<String>,
    /// Mean of `raw / opt8` over valid runs.
    pub mean_raw_ratio: f64,
    /// Mean of `length / any-angle` over valid runs.
    pub mean_smooth_ratio: f64,
    /// Largest `raw / opt8`.
    pub worst_raw_ratio: f64,
    /// Largest `length / any-angle`.
    pub worst_smooth_ratio: f64,
    /// Shortest output length.
    pub best_length: f64,
    /// Mean output length.
    pub mean_length: f64,
    /// Longest output length.
    pub worst_length: f64,
    /// Population standard deviation of the output length.
    pub std_length: f64,
    /// Mean turns.
    pub mean_turns: f64,
    /// Mean `best_iteration` (0-based).
    pub mean_best_iteration: f64,
    /// Mean iterations run.
    pub mean_iterations: f64,
    /// Mean ant moves per run.
    pub mean_moves: f64,
    /// Mean wall-clock time per plan (all runs).
    pub mean_time: Duration,
}

/// Summarise runs (in the given order).
pub fn summarize(runs: &[Run]) -> Summary {
    let valid: Vec<&RunStats> = runs
        .iter()
        .filter_map(|r| match &r.outcome {
            Outcome::Valid(s) => Some(s),
            _ => None,
        })
        .collect();
    let n = valid.len().max(1) as f64;
    let mean = |f: &dyn Fn(&RunStats) -> f64| valid.iter().map(|s| f(s)).sum::<f64>() / n;
    let max = |f: &dyn Fn(&RunStats) -> f64| valid.iter().map(|s| f(s)).fold(f64::NAN, f64::max);
    let min = |f: &dyn Fn(&RunStats) -> f64| valid.iter().map(|s| f(s)).fold(f64::NAN, f64::min);
    let mean_length = mean(&|s| s.length);
    // Sample variance (n - 1), as `ohaca experiment`'s summary.md, so the two tables agree.
    let count = valid.len() as f64;
    let var = if count > 1.0 {
        mean(&|s| (s.length - mean_length).powi(2)) * count / (count - 1.0)
    } else {
        0.0
    };
    let total: Duration = runs.iter().map(|r| r.time).sum();
    Summary {
        runs: runs.len(),
        valid: valid.len(),
        failed: runs
            .iter()
            .filter(|r| matches!(r.outcome, Outcome::Failed(_)))
            .count(),
        invalid: runs
            .iter()
            .filter_map(|r| match &r.outcome {
                Outcome::Invalid(m) => Some(format!("case {} seed {}: {m}", r.case, r.seed)),
                _ => None,
            })
            .collect(),
        mean_raw_ratio: mean(&|s| s.raw_ratio),
        mean_smooth_ratio: mean(&|s| s.smooth_ratio),
        worst_raw_ratio: max(&|s| s.raw_ratio),
        worst_smooth_ratio: max(&|s| s.smooth_ratio),
        best_length: min(&|s| s.length),
        mean_length,
        worst_length: max(&|s| s.length),
        std_length: var.sqrt(),
        mean_turns: mean(&|s| f64::from(s.turns)),
        mean_best_iteration: mean(&|s| f64::from(s.best_iteration)),
        mean_iterations: mean(&|s| f64::from(s.iterations)),
        mean_moves: mean(&|s| s.moves as f64),
        mean_time: if runs.is_empty() {
            Duration::ZERO
        } else {
            total / runs.len() as u32
        },
    }
}

/// The seeds the shared-map runs use: `1..=30`.
pub fn default_seeds() -> Vec<u64> {
    (1..=30).collect()
}
