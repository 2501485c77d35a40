//! `ohaca experiment`: run every algorithm `--runs` times (seeds `--seed`, `--seed`+1, ...) on
//! one map, in parallel, and write `results.csv`, `summary.md`, `convergence.csv`,
//! `convergence.svg`/`.png` and a picture of each algorithm's best run into `--out`
//! (see [`ohaca_host::experiment`]). The summary table is also printed on stdout.
//!
//! Thread count: rayon's, set with `RAYON_NUM_THREADS`. Every output file is the same whatever
//! the thread count except the time columns; `--no-timing` writes 0 there, so the files are
//! byte-identical. A progress bar is drawn on stderr only when stderr is a terminal.
//!
//! Exit codes: 0 the files were written and some run found a path; 1 written, but no run found
//! a path; 2 bad input (map, parameters, start/goal) or an output file could not be written.

use std::io::IsTerminal;
use std::path::PathBuf;

use indicatif::{ProgressBar, ProgressStyle};
use ohaca::Algorithm;
use ohaca_host::exit;
use ohaca_host::experiment::{self, Config};
use ohaca_host::input::{MapArgs, MultiParamArgs};

use super::plan::plan_error;
use super::{bad_input, print};

/// Arguments of `ohaca experiment`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub input: MapArgs,
    /// Runs per algorithm; the seeds are --seed, --seed + 1, ... (1..=runs by default)
    #[arg(long, value_name = "N", default_value_t = 30,
          value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    pub runs: u32,
    /// Folder for the output files (created if missing)
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Write 0 for every time, so the output files are byte-identical for any thread count
    #[arg(long)]
    pub no_timing: bool,
    /// Planner flags; --algorithm may be repeated or a list (default: aca,paca,haca,ohaca)
    #[command(flatten)]
    pub params: MultiParamArgs,
}

/// Run `ohaca experiment`; returns the exit code.
pub fn run(args: &Args) -> u8 {
    let sc = match args.input.load() {
        Ok(s) => s,
        Err(e) => return bad_input(e),
    };
    let config = Config {
        algorithms: args.params.algorithms(&Algorithm::ALL),
        runs: args.runs,
        params: args.params.params.params(),
        timing: !args.no_timing,
    };
    let total = config.algorithms.len() as u64 * u64::from(config.runs);
    let bar = if std::io::stderr().is_terminal() {
        let bar = ProgressBar::new(total);
        if let Ok(style) =
            ProgressStyle::with_template("{elapsed_precise} [{bar:40}] {pos}/{len} runs {eta}")
        {
            bar.set_style(style.progress_chars("=> "));
        }
        bar
    } else {
        ProgressBar::hidden()
    };
    let outcome = experiment::run(&sc, &config, &|| bar.inc(1));
    bar.finish_and_clear();
    let outcome = match outcome {
        Ok(o) => o,
        Err(e) => return bad_input(plan_error(&sc, &e)),
    };
    if let Err(e) = outcome.write(&args.out) {
        return bad_input(e);
    }
    print(&outcome.table());
    if outcome.runs.iter().any(|r| r.report.found) {
        exit::FOUND
    } else {
        exit::NO_PATH
    }
}
