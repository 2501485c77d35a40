//! The paper's experiments: every algorithm run many times with seeds `S..S+runs-1` on one map,
//! in parallel, summarised.
//!
//! [`run`] plans every (algorithm, seed) pair on the rayon thread pool (`RAYON_NUM_THREADS`
//! sets its size) and returns the results **in job order**, so everything computed from them —
//! `results.csv`, `summary.md`, the convergence chart and the path pictures — is the same for
//! any number of threads. The one exception is time: `elapsed_us` and the mean time depend on
//! the machine and its load; [`Config::timing`] `= false` writes 0 there, and then the output
//! files are byte-identical across thread counts.
//!
//! Definitions used in the summary:
//! - **success**: the run found a path (with `--dead-end backtrack` that is every run on a
//!   reachable goal; with `die`, a run where at least one ant arrived).
//! - **ants arriving**: the share of all ants sent out (ants x iterations, over all runs) that
//!   reached the goal: 100 % unless ants die at dead ends (`--dead-end die`). The paper's
//!   "success rate" (89-98 %) reads like this figure.
//! - **length**: the output path's length (smoothed for OHACA; for ACA/PACA/HACA the raw path's),
//!   over successful runs; best = minimum, worst = maximum, std dev = sample standard deviation.
//! - **convergence iteration**: 1-based iteration in which the run's best path was first found
//!   (`best_iteration + 1`).
//! - **convergence curve**: for each iteration, the mean over successful runs of the best raw
//!   length found so far ([`ohaca::CurvePoint::best_so_far`]); a run that stopped early carries
//!   its final best forward. The curve starts at the first iteration in which every successful
//!   run has a path (before that it has no value), so every point averages the same runs and the
//!   curve never rises.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use ohaca::{Algorithm, Params};
use rayon::prelude::*;

use crate::draw::{self, Convergence, Layer, Scene, Series};
use crate::input::Scenario;
use crate::output::PlanReport;
use crate::plan_map::PlanError;
use crate::trace::plan_traced;
use ohaca::heap::HeapStorage;

/// What to run.
#[derive(Clone, Debug, PartialEq)]
pub struct Config {
    /// The variants, in output order.
    pub algorithms: Vec<Algorithm>,
    /// Runs per algorithm.
    pub runs: u32,
    /// Every planner parameter; `seed` is the first seed, `algorithm` is ignored.
    pub params: Params,
    /// Record times (`false`: write 0, for byte-identical output).
    pub timing: bool,
}

/// One run's result.
#[derive(Clone, Debug, PartialEq)]
pub struct RunResult {
    /// The variant.
    pub algorithm: Algorithm,
    /// The seed.
    pub seed: u64,
    /// The report (`elapsed_us` is 0 without timing).
    pub report: PlanReport,
    /// Best-so-far raw length per iteration.
    pub best_so_far: Vec<f32>,
    /// Ants sent out over the run.
    pub ants_sent: u64,
    /// Ants that reached the goal.
    pub ants_arrived: u64,
}

/// Every run of an experiment, in job order (algorithm by algorithm, seeds ascending).
#[derive(Clone, Debug, PartialEq)]
pub struct Outcome {
    /// The map and endpoints.
    pub scenario: Scenario,
    /// What was run.
    pub config: Config,
    /// The runs.
    pub runs: Vec<RunResult>,
}

/// The seeds of the experiment: `first, first + 1, ...` (`runs` of them, wrapping at `u64::MAX`).
pub fn seeds(first: u64, runs: u32) -> impl Iterator<Item = u64> {
    (0..u64::from(runs)).map(move |i| first.wrapping_add(i))
}

/// Run the experiment. `tick` is called once per finished run (from any thread), e.g. for a
/// progress bar. Fails on bad input (parameters, start/goal outside the map or on an obstacle).
pub fn run(
    scenario: &Scenario,
    config: &Config,
    tick: &(dyn Fn() + Sync),
) -> Result<Outcome, PlanError> {
    config.params.validate()?;
    let jobs: Vec<(Algorithm, u64)> = config
        .algorithms
        .iter()
        .flat_map(|&a| seeds(config.params.seed, config.runs).map(move |s| (a, s)))
        .collect();
    let runs = jobs
        .par_iter()
        .map_init(HeapStorage::default, |storage, &(algorithm, seed)| {
            let params = Params {
                algorithm,
                seed,
                ..config.params
            };
            let t = plan_traced(
                storage,
                &scenario.map,
                scenario.start,
                scenario.goal,
                &params,
                false,
            );
            tick();
            t.map(|t| {
                let mut report = t.report;
                if !config.timing {
                    report.elapsed_us = 0;
                }
                RunResult {
                    algorithm,
                    seed,
                    report,
                    best_so_far: t.best_so_far,
                    ants_sent: t.ants_sent,
                    ants_arrived: t.ants_arrived,
                }
            })
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok(Outcome {
        scenario: scenario.clone(),
        config: config.clone(),
        runs,
    })
}

/// Per-algorithm statistics.
#[derive(Clone, Debug, PartialEq)]
pub struct Stats {
    /// The variant.
    pub algorithm: Algorithm,
    /// Runs.
    pub runs: usize,
    /// Runs that found a path.
    pub found: usize,
    /// Share of all ants sent out that reached the goal, in per cent (the paper's "success
    /// rate" reads like this; below 100 only when ants die at dead ends).
    pub ant_success: Option<f64>,
    /// Shortest output length.
    pub best: Option<f64>,
    /// Mean output length.
    pub mean: Option<f64>,
    /// Sample standard deviation of the output length (0 for one run).
    pub std_dev: Option<f64>,
    /// Longest output length.
    pub worst: Option<f64>,
    /// Mean raw length.
    pub mean_raw: Option<f64>,
    /// Mean turns.
    pub mean_turns: Option<f64>,
    /// Mean 1-based convergence iteration.
    pub mean_convergence: Option<f64>,
    /// Mean iterations run (all runs).
    pub mean_iterations: Option<f64>,
    /// Mean time in milliseconds (all runs).
    pub mean_ms: f64,
}

fn mean(v: &[f64]) -> Option<f64> {
    if v.is_empty() {
        None
    } else {
        Some(v.iter().sum::<f64>() / v.len() as f64)
    }
}

impl Outcome {
    /// The runs of one algorithm.
    pub fn runs_of(&self, a: Algorithm) -> impl Iterator<Item = &RunResult> {
        self.runs.iter().filter(move |r| r.algorithm == a)
    }

    /// Statistics of one algorithm (sums in job order, so they are deterministic).
    pub fn stats(&self, a: Algorithm) -> Stats {
        let runs: Vec<&RunResult> = self.runs_of(a).collect();
        let ok: Vec<&PlanReport> = runs.iter().map(|r| &r.report).filter(|r| r.found).collect();
        let lens: Vec<f64> = ok.iter().filter_map(|r| r.length).map(f64::from).collect();
        let m = mean(&lens);
        let std_dev = m.map(|m| {
            if lens.len() < 2 {
                0.0
            } else {
                let ss: f64 = lens.iter().map(|l| (l - m) * (l - m)).sum();
                (ss / (lens.len() - 1) as f64).sqrt()
            }
        });
        let of = |f: &dyn Fn(&PlanReport) -> Option<f64>| -> Option<f64> {
            mean(&ok.iter().filter_map(|r| f(r)).collect::<Vec<_>>())
        };
        let iterations: Vec<f64> = runs
            .iter()
            .filter_map(|r| r.report.iterations.map(f64::from))
            .collect();
        let times: Vec<f64> = runs
            .iter()
            .map(|r| r.report.elapsed_us as f64 / 1e3)
            .collect();
        let sent: u64 = runs.iter().map(|r| r.ants_sent).sum();
        let arrived: u64 = runs.iter().map(|r| r.ants_arrived).sum();
        Stats {
            algorithm: a,
            runs: runs.len(),
            found: ok.len(),
            ant_success: (sent > 0).then(|| 100.0 * arrived as f64 / sent as f64),
            best: lens.iter().copied().reduce(f64::min),
            mean: m,
            std_dev,
            worst: lens.iter().copied().reduce(f64::max),
            mean_raw: of(&|r| r.raw_length.map(f64::from)),
            mean_turns: of(&|r| r.turns.map(f64::from)),
            mean_convergence: of(&|r| r.best_iteration.map(|b| f64::from(b) + 1.0)),
            mean_iterations: mean(&iterations),
            mean_ms: mean(&times).unwrap_or(0.0),
        }
    }

    /// `results.csv`: a header, then one row per run.
    pub fn results_csv(&self) -> String {
        let mut s = String::from(
            "algorithm,seed,found,raw_length,length,turns,best_iteration,iterations,elapsed_us\n",
        );
        let opt = |v: Option<String>| v.unwrap_or_default();
        for r in &self.runs {
            let p = &r.report;
            let _ = writeln!(
                s,
                "{},{},{},{},{},{},{},{},{}",
                r.algorithm.name(),
                r.seed,
                p.found,
                opt(p.raw_length.map(|v| v.to_string())),
                opt(p.length.map(|v| v.to_string())),
                opt(p.turns.map(|v| v.to_string())),
                opt(p.best_iteration.map(|v| v.to_string())),
                opt(p.iterations.map(|v| v.to_string())),
                p.elapsed_us
            );
        }
        s
    }

    /// The mean best-so-far curve of one algorithm (see the module docs).
    pub fn convergence_of(&self, a: Algorithm) -> Vec<f64> {
        let curves: Vec<&[f32]> = self
            .runs_of(a)
            .filter(|r| r.report.found && !r.best_so_far.is_empty())
            .map(|r| r.best_so_far.as_slice())
            .collect();
        let n = self
            .runs
            .iter()
            .map(|r| r.best_so_far.len())
            .max()
            .unwrap_or(0);
        (0..n)
            .map(|i| {
                // Every successful run at iteration i (its final best once it has stopped); no
                // value while some run has no path yet, so the mean is always over the same runs.
                let vals: Option<Vec<f64>> = curves
                    .iter()
                    .map(|c| {
                        c.get(i)
                            .or_else(|| c.last())
                            .copied()
                            .filter(|v| v.is_finite())
                            .map(f64::from)
                    })
                    .collect();
                vals.and_then(|v| mean(&v)).unwrap_or(f64::INFINITY)
            })
            .collect()
    }

    /// `convergence.csv`: `iteration` then one column per algorithm (empty where no run has
    /// a path yet).
    pub fn convergence_csv(&self) -> String {
        let algs = &self.config.algorithms;
        let curves: Vec<Vec<f64>> = algs.iter().map(|&a| self.convergence_of(a)).collect();
        let mut s = String::from("iteration");
        for a in algs {
            s.push(',');
            s.push_str(a.name());
        }
        s.push('\n');
        let n = curves.iter().map(Vec::len).max().unwrap_or(0);
        for i in 0..n {
            let _ = write!(s, "{}", i + 1);
            for c in &curves {
                s.push(',');
                if let Some(v) = c.get(i).filter(|v| v.is_finite()) {
                    let _ = write!(s, "{v:.4}");
                }
            }
            s.push('\n');
        }
        s
    }

    /// The convergence chart.
    pub fn convergence(&self) -> Convergence {
        Convergence {
            title: format!(
                "{}: best raw length so far, mean of {} runs",
                self.scenario.name, self.config.runs
            ),
            y_label: "best-so-far raw path length (cells)".to_string(),
            series: self
                .config
                .algorithms
                .iter()
                .map(|&a| Series {
                    algorithm: a,
                    values: self.convergence_of(a),
                })
                .collect(),
        }
    }

    /// The best run of an algorithm: shortest output path, then the lowest seed.
    pub fn best_run(&self, a: Algorithm) -> Option<&RunResult> {
        self.runs_of(a).filter(|r| r.report.found).min_by(|x, y| {
            let l = |r: &RunResult| r.report.length.unwrap_or(f32::INFINITY);
            l(x).total_cmp(&l(y)).then(x.seed.cmp(&y.seed))
        })
    }

    /// The picture of an algorithm's best run.
    pub fn path_scene(&self, a: Algorithm) -> Scene {
        let sc = &self.scenario;
        let (layer, which) = match self.best_run(a) {
            Some(r) => (
                Layer::from_report(a, &r.report, sc.metric.map(|f| f.resolution)),
                format!("best of {} runs (seed {})", self.config.runs, r.seed),
            ),
            None => {
                let mut l = Layer {
                    algorithm: a,
                    raw: Vec::new(),
                    waypoints: Vec::new(),
                    line1: "no path".to_string(),
                    line2: String::new(),
                };
                if let Some(r) = self.runs_of(a).next() {
                    l.line2 = r.report.error.clone().unwrap_or_default();
                }
                (l, format!("no path in {} runs", self.config.runs))
            }
        };
        Scene {
            title: format!(
                "{}: {} from ({},{}) to ({},{})",
                sc.name,
                draw::display_name(a),
                sc.start.x,
                sc.start.y,
                sc.goal.x,
                sc.goal.y
            ),
            subtitle: format!("{which}; {}", params_brief(&self.config.params)),
            map: sc.map.clone(),
            start: sc.start,
            goal: sc.goal,
            layers: vec![layer],
            pheromone: None,
            pheromone_label: String::new(),
            metric: sc.metric,
        }
    }

    /// `summary.md`.
    pub fn summary_md(&self) -> String {
        let sc = &self.scenario;
        let c = &self.config;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "# Experiment: {}, ({},{}) -> ({},{})\n",
            sc.name, sc.start.x, sc.start.y, sc.goal.x, sc.goal.y
        );
        let last = c
            .params
            .seed
            .wrapping_add(u64::from(c.runs.saturating_sub(1)));
        let _ = writeln!(
            s,
            "{} runs per algorithm, seeds {}..={}; map {}x{} cells{}.\n",
            c.runs,
            c.params.seed,
            last,
            sc.map.width,
            sc.map.height,
            sc.metric
                .map_or_else(String::new, |f| format!(", 1 cell = {} m", f.resolution))
        );
        let _ = writeln!(s, "Parameters: {}.\n", params_line(&c.params));
        s.push_str(&self.table());
        s.push_str(
            "\nLengths are in cells: the output path (smoothed for OHACA, the raw 8-connected \
             path otherwise) over the successful runs; std dev is the sample standard deviation. \
             Convergence iteration: the 1-based iteration in which a run's best path was first \
             found. Iterations: how many ran (early stop after `patience` iterations without \
             improvement). Time: the core's planning time per run",
        );
        if c.timing {
            s.push_str(
                " on this machine; it varies from run to run and with the number of threads \
                 (everything else in these files does not).\n",
            );
        } else {
            s.push_str(
                ": not recorded (`--no-timing`), so these files are byte-identical for \
                        any number of threads.\n",
            );
        }
        s
    }

    /// The summary table (Markdown), one row per algorithm.
    pub fn table(&self) -> String {
        let mut s = String::from(
            "| algorithm | success | ants arriving | best length | mean length | std dev | \
             worst length | mean raw length | mean turns | mean convergence iteration | \
             mean iterations | mean time (ms) |\n\
             | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n",
        );
        let f =
            |v: Option<f64>, d: usize| v.map_or_else(|| "-".to_string(), |v| format!("{v:.d$}"));
        for &a in &self.config.algorithms {
            let st = self.stats(a);
            let rate = if st.runs == 0 {
                0.0
            } else {
                100.0 * st.found as f64 / st.runs as f64
            };
            let _ = writeln!(
                s,
                "| {} | {}/{} ({rate:.0} %) | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.3} |",
                draw::display_name(a),
                st.found,
                st.runs,
                st.ant_success
                    .map_or_else(|| "-".to_string(), |v| format!("{v:.1} %")),
                f(st.best, 3),
                f(st.mean, 3),
                f(st.std_dev, 3),
                f(st.worst, 3),
                f(st.mean_raw, 3),
                f(st.mean_turns, 2),
                f(st.mean_convergence, 1),
                f(st.mean_iterations, 1),
                st.mean_ms
            );
        }
        s
    }

    /// Write every output file into `dir` (created if missing): `results.csv`, `summary.md`,
    /// `convergence.csv`, `convergence.svg`, `convergence.png`, and `path-<algorithm>.svg` /
    /// `.png` for each algorithm. The error is one line naming the file.
    pub fn write(&self, dir: &Path) -> Result<(), WriteError> {
        std::fs::create_dir_all(dir).map_err(|error| WriteError::Folder {
            path: dir.to_path_buf(),
            error,
        })?;
        let text = |name: &str, body: String| -> Result<(), WriteError> {
            let path = dir.join(name);
            std::fs::write(&path, body).map_err(|error| WriteError::File { path, error })
        };
        text("results.csv", self.results_csv())?;
        text("summary.md", self.summary_md())?;
        text("convergence.csv", self.convergence_csv())?;
        let chart = self.convergence();
        draw::save(&chart, &dir.join("convergence.svg"))?;
        draw::save(&chart, &dir.join("convergence.png"))?;
        for &a in &self.config.algorithms {
            let scene = self.path_scene(a);
            draw::save(&scene, &dir.join(format!("path-{}.svg", a.name())))?;
            draw::save(&scene, &dir.join(format!("path-{}.png", a.name())))?;
        }
        Ok(())
    }
}

/// Why [`Experiment::write`] failed: one line naming the file.
#[derive(Debug, thiserror::Error)]
pub enum WriteError {
    /// The output folder cannot be created.
    #[error("{}: cannot create the folder: {error}", .path.display())]
    Folder {
        /// The folder.
        path: PathBuf,
        /// The system's error.
        error: std::io::Error,
    },
    /// A text file cannot be written.
    #[error("{}: cannot write the file: {error}", .path.display())]
    File {
        /// The file.
        path: PathBuf,
        /// The system's error.
        error: std::io::Error,
    },
    /// A picture cannot be drawn or written.
    #[error(transparent)]
    Picture(#[from] draw::DrawError),
}

/// The parameters that matter most, as a short line for picture subtitles.
pub fn params_brief(p: &Params) -> String {
    format!(
        "{} ants, up to {} iterations, patience {}, dead end {}, smoothing {}{}",
        p.ants,
        p.iterations,
        p.patience,
        p.dead_end.name(),
        p.smoothing.name(),
        if p.tighten { "" } else { ", no tightening" }
    )
}

/// The parameters as one line (for titles and summaries).
pub fn params_line(p: &Params) -> String {
    format!(
        "{} ants, up to {} iterations, alpha {}, beta {}, rho {}, q {}, a {}, xi {}, tau0 {}, \
         tau in [{}, {}], patience {}, dead end {}, smoothing {}, tighten {}",
        p.ants,
        p.iterations,
        p.alpha,
        p.beta,
        p.rho,
        p.q,
        p.a,
        p.xi,
        p.tau0,
        p.tau_min,
        p.tau_max,
        p.patience,
        p.dead_end.name(),
        p.smoothing.name(),
        p.tighten
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::{Format, Map};
    use ohaca::Point;

    fn scenario() -> Scenario {
        Scenario {
            name: "t".into(),
            map: Map::parse(
                "........\n.###....\n....##..\n........\n",
                "t",
                Format::Text,
            )
            .unwrap(),
            metric: None,
            start: Point::new(0, 0),
            goal: Point::new(7, 3),
        }
    }

    fn config() -> Config {
        Config {
            algorithms: vec![Algorithm::Aca, Algorithm::Ohaca],
            runs: 3,
            params: Params {
                ants: 8,
                iterations: 12,
                seed: 5,
                ..Params::default()
            },
            timing: false,
        }
    }

    #[test]
    fn jobs_in_order_and_stats() {
        let o = run(&scenario(), &config(), &|| {}).unwrap();
        let order: Vec<_> = o.runs.iter().map(|r| (r.algorithm, r.seed)).collect();
        assert_eq!(
            order,
            vec![
                (Algorithm::Aca, 5),
                (Algorithm::Aca, 6),
                (Algorithm::Aca, 7),
                (Algorithm::Ohaca, 5),
                (Algorithm::Ohaca, 6),
                (Algorithm::Ohaca, 7)
            ]
        );
        assert!(o.runs.iter().all(|r| r.report.elapsed_us == 0));
        let st = o.stats(Algorithm::Ohaca);
        assert_eq!((st.runs, st.found), (3, 3));
        assert!(st.best.unwrap() <= st.mean.unwrap() && st.mean.unwrap() <= st.worst.unwrap());
        let csv = o.results_csv();
        assert_eq!(csv.lines().count(), 7);
        assert!(csv.lines().nth(1).unwrap().starts_with("aca,5,true,"));
        assert!(csv.lines().nth(1).unwrap().ends_with(",0"));
        let md = o.summary_md();
        assert!(md.contains("| OHACA | 3/3 (100 %) |"), "{md}");
        assert!(md.contains("seeds 5..=7"));
        // The convergence curve never increases and ends at the mean best raw length.
        let c = o.convergence_of(Algorithm::Aca);
        assert!(c.windows(2).all(|w| w[1] <= w[0] + 1e-9));
        assert_eq!(o.convergence_csv().lines().count(), c.len() + 1);
    }

    #[test]
    fn early_stop_keeps_the_last_value() {
        let mut o = run(&scenario(), &config(), &|| {}).unwrap();
        // Fake two runs: one of 2 iterations, one of 4.
        o.runs.truncate(2);
        o.runs[0].best_so_far = vec![10.0, 8.0];
        o.runs[1].best_so_far = vec![f32::INFINITY, 12.0, 9.0, 6.0];
        let c = o.convergence_of(Algorithm::Aca);
        assert_eq!(c, vec![f64::INFINITY, 10.0, 8.5, 7.0]);
    }

    #[test]
    fn the_convergence_curve_never_rises() {
        let mut o = run(&scenario(), &config(), &|| {}).unwrap();
        o.runs.truncate(3);
        // A run that stopped at once on a short path, one that found a long path late (ants that
        // die may find none for a while), one that stopped after two iterations.
        o.runs[0].best_so_far = vec![5.0];
        o.runs[1].best_so_far = vec![f32::INFINITY, f32::INFINITY, 20.0, 11.0];
        o.runs[2].best_so_far = vec![9.0, 8.0];
        let c = o.convergence_of(Algorithm::Aca);
        assert_eq!(c, vec![f64::INFINITY, f64::INFINITY, 11.0, 8.0]);
        let finite: Vec<f64> = c.into_iter().filter(|v| v.is_finite()).collect();
        assert!(finite.windows(2).all(|w| w[1] <= w[0]), "{finite:?}");
    }

    #[test]
    fn std_dev_is_the_sample_one() {
        let mut o = run(&scenario(), &config(), &|| {}).unwrap();
        for (r, l) in o.runs.iter_mut().zip([2.0f32, 4.0, 6.0]) {
            r.report.length = Some(l);
        }
        let st = o.stats(Algorithm::Aca);
        assert_eq!(st.mean, Some(4.0));
        assert_eq!(st.std_dev, Some(2.0));
        assert_eq!((st.best, st.worst), (Some(2.0), Some(6.0)));
    }

    #[test]
    fn bad_input_is_an_error() {
        let mut sc = scenario();
        sc.start = Point::new(1, 1);
        assert!(run(&sc, &config(), &|| {}).is_err());
    }
}
