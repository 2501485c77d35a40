//! `ohaca plan`: load a map, plan from the start to the goal, print the picture, the JSON report
//! or the waypoints as CSV.
//!
//! Exit codes: 0 path found; 1 no path (with `--format json`, a report with `found: false`; with
//! `csv`, the header only); 2 bad input, with one line on stderr: an unreadable or malformed map
//! (file, line, problem), a bad parameter, or a start/goal outside the map or on an obstacle (the
//! core's message). Nothing is printed on stdout for bad input.

use ohaca::Error;
use ohaca_host::board::BoardArg;
use ohaca_host::input::{MapArgs, Scenario};
use ohaca_host::output::{render, waypoints_csv, LocatedReport, PlanReport};
use ohaca_host::{exit, plan_map_on, ParamArgs, PlanError};

use super::{bad_input, print};

/// What `plan` prints.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// The map with the path as characters, and a summary
    Text,
    /// One JSON object (the report; `waypoints_m` added for maps with a resolution)
    Json,
    /// `x,y` per waypoint with a header line: cells, or metres for maps with a resolution
    Csv,
}

/// Arguments of `ohaca plan`.
#[derive(clap::Args, Debug)]
pub struct Args {
    #[command(flatten)]
    pub input: MapArgs,
    /// What to print: text (picture), json or csv [default: text]
    #[arg(long, value_enum, value_name = "FORMAT")]
    pub format: Option<Format>,
    /// Print one JSON object instead of the picture (same as --format json)
    #[arg(long)]
    pub json: bool,
    /// Plan exactly as this board's firmware does (its buffers, layout and path bound; the same
    /// path as `ohaca send` to it): f411 (also the default QEMU firmware) or h743 (also its QEMU
    /// twin) [default: the host's own storage, every buffer for the map]
    #[arg(long, value_enum, value_name = "BOARD")]
    pub board: Option<BoardArg>,
    #[command(flatten)]
    pub params: ParamArgs,
}

/// Run `ohaca plan`; returns the exit code.
pub fn run(args: &Args) -> u8 {
    let format = match (args.json, args.format) {
        (false, f) => f.unwrap_or(Format::Text),
        (true, None | Some(Format::Json)) => Format::Json,
        (true, Some(f)) => {
            return bad_input(format_args!(
                "--json means --format json; it cannot be combined with --format {}",
                if f == Format::Csv { "csv" } else { "text" }
            ))
        }
    };
    let sc = match args.input.load() {
        Ok(s) => s,
        Err(e) => return bad_input(e),
    };
    let params = args.params.params();
    let board = args.board.map(BoardArg::board);
    let report = match plan_map_on(board, &sc.map, sc.start, sc.goal, &params) {
        Ok(r) => r,
        Err(e) => return bad_input(plan_error(&sc, &e)),
    };
    print(&output(format, &sc, &report));
    if report.found {
        exit::FOUND
    } else {
        exit::NO_PATH
    }
}

/// The one-line message for a request the core rejected: the map file, the problem, and for a
/// start/goal problem the points and the map's size.
pub fn plan_error(sc: &Scenario, e: &PlanError) -> String {
    match e {
        PlanError::Core(e @ (Error::OutOfBounds(_) | Error::Blocked(_))) => format!(
            "{}: {e} (start {},{}, goal {},{}, map {}x{})",
            sc.name, sc.start.x, sc.start.y, sc.goal.x, sc.goal.y, sc.map.width, sc.map.height
        ),
        PlanError::Core(e @ Error::BadParam(_)) => e.to_string(),
        e => format!("{}: {e}", sc.name),
    }
}

fn output(format: Format, sc: &Scenario, report: &PlanReport) -> String {
    let metres = sc.metres(&report.waypoints);
    match format {
        Format::Json => {
            let mut s = LocatedReport {
                report,
                waypoints_m: metres.as_deref(),
            }
            .to_json();
            s.push('\n');
            s
        }
        Format::Csv => waypoints_csv(&report.waypoints, metres.as_deref()),
        Format::Text => {
            let p = &report.params;
            let mut s = format!(
                "{}, ({},{}) -> ({},{}), {} seed {}\n",
                sc.name, sc.start.x, sc.start.y, sc.goal.x, sc.goal.y, p.algorithm, p.seed
            );
            s.push_str(&render(&sc.map, sc.start, sc.goal, report));
            if let (Some(m), true) = (&metres, report.found) {
                let pts: Vec<String> = m.iter().map(|[x, y]| format!("({x}, {y})")).collect();
                s.push_str("waypoints in metres (map frame): ");
                s.push_str(&pts.join(" "));
                s.push('\n');
            }
            s
        }
    }
}
