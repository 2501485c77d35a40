//! `ohaca plan`: load a map, plan from `--start` to `--goal`, print the picture or the JSON
//! report.
//!
//! Exit codes: 0 path found; 1 no path (with `--json`, a report with `found: false`); 2 bad
//! input, with one line on stderr: an unreadable or malformed map (file, line, problem), a bad
//! parameter, or a start/goal outside the map or on an obstacle (the core's message). Nothing is
//! printed on stdout for bad input.

use std::path::PathBuf;

use ohaca::{Error, Point};
use ohaca_host::output::{render, PlanReport};
use ohaca_host::{exit, parse_point, plan_map, Map, ParamArgs, PlanError};

use super::{bad_input, print};

/// Arguments of `ohaca plan`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Map file: Moving AI `.map`, or a text grid (`.`/`0` free, `#`/`1` blocked)
    #[arg(long, value_name = "FILE")]
    pub map: PathBuf,
    /// Start cell: column,row with 0,0 the top-left cell
    #[arg(long, value_name = "X,Y", value_parser = parse_point, allow_hyphen_values = true)]
    pub start: Point,
    /// Goal cell: column,row
    #[arg(long, value_name = "X,Y", value_parser = parse_point, allow_hyphen_values = true)]
    pub goal: Point,
    /// Print one JSON object instead of the picture
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub params: ParamArgs,
}

/// Run `ohaca plan`; returns the exit code.
pub fn run(args: &Args) -> u8 {
    let map = match Map::load(&args.map) {
        Ok(m) => m,
        Err(e) => return bad_input(e),
    };
    let params = args.params.params();
    let report = match plan_map(&map, args.start, args.goal, &params) {
        Ok(r) => r,
        Err(PlanError::Core(e @ (Error::OutOfBounds(_) | Error::Blocked(_)))) => {
            return bad_input(format_args!(
                "{}: {e} (start {},{}, goal {},{}, map {}x{})",
                args.map.display(),
                args.start.x,
                args.start.y,
                args.goal.x,
                args.goal.y,
                map.width,
                map.height
            ))
        }
        Err(PlanError::Core(e @ Error::BadParam(_))) => return bad_input(e),
        Err(e) => return bad_input(format_args!("{}: {e}", args.map.display())),
    };
    print(&output(args, &map, &report));
    if report.found {
        exit::FOUND
    } else {
        exit::NO_PATH
    }
}

fn output(args: &Args, map: &Map, report: &PlanReport) -> String {
    if args.json {
        let mut s = report.to_json();
        s.push('\n');
        s
    } else {
        let p = &report.params;
        let mut s = format!(
            "{}, ({},{}) -> ({},{}), {} seed {}\n",
            args.map.display(),
            args.start.x,
            args.start.y,
            args.goal.x,
            args.goal.y,
            p.algorithm,
            p.seed
        );
        s.push_str(&render(map, args.start, args.goal, report));
        s
    }
}
