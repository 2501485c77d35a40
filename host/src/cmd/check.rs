//! `ohaca check`: check a path in metres against a map file, as a robot would follow it — the
//! test of `ohaca ros`'s `/plan` messages from another DDS (scripts/ros_interop.py), and of any
//! planner's output. The map is prepared as `plan` prepares it (`--unknown`, `--inflate`); the
//! path is a JSON list of `[x, y]` points in the map frame (metres), start first.
//!
//! Valid means: at least two points; the first is `--start-m` and the last `--goal-m` (within
//! `--tolerance` metres); every point lies on a free cell; and the straight segment between the
//! cells of each two consecutive points touches no blocked cell (the core's segment rule,
//! [`ohaca::geometry::segment_clear`], the one its smoothing keeps). Prints one JSON object
//! (`valid`, `points`, `length_m`, `error`).
//!
//! Exit codes: 0 valid; 1 invalid; 2 bad input (map, path file, flags).

use std::path::PathBuf;

use ohaca::geometry::segment_clear;
use ohaca::Point;
use ohaca_host::exit;
use ohaca_host::input::{parse_length, parse_metres};
use ohaca_host::map::{prepare, Unknown};

use super::{bad_input, print};

/// Arguments of `ohaca check`.
#[derive(clap::Args, Debug)]
pub struct Args {
    /// Map file with a resolution (ROS map_server YAML)
    #[arg(long, value_name = "FILE")]
    pub map: PathBuf,
    /// The path: a JSON file `[[x, y], ...]` in metres (map frame), start first
    #[arg(long, value_name = "FILE")]
    pub path: PathBuf,
    /// Where the path must start (metres)
    #[arg(long, value_name = "X,Y", value_parser = parse_metres, allow_hyphen_values = true)]
    pub start_m: [f64; 2],
    /// Where the path must end (metres)
    #[arg(long, value_name = "X,Y", value_parser = parse_metres, allow_hyphen_values = true)]
    pub goal_m: [f64; 2],
    /// How far (metres) the first and last points may be from --start-m and --goal-m
    #[arg(long, value_name = "METRES", default_value_t = 1e-6)]
    pub tolerance: f64,
    /// ROS maps: unexplored cells are blocked or free
    #[arg(long, value_name = "AS", value_enum, default_value_t = Unknown::Blocked)]
    pub unknown: Unknown,
    /// Block every cell within this radius (metres) of an obstacle first
    #[arg(long, value_name = "RADIUS", value_parser = parse_length)]
    pub inflate: Option<f64>,
}

/// Run `ohaca check`; returns the exit code.
pub fn run(args: &Args) -> u8 {
    let (map, frame) = match prepare(&args.map, args.unknown, args.inflate, None) {
        Ok((m, Some(f))) => (m, f),
        Ok((_, None)) => {
            return bad_input(format!(
                "{}: the map has no resolution (give a ROS map_server YAML)",
                args.map.display()
            ))
        }
        Err(e) => return bad_input(e),
    };
    let text = match std::fs::read_to_string(&args.path) {
        Ok(t) => t,
        Err(e) => return bad_input(format!("{}: {e}", args.path.display())),
    };
    let points: Vec<[f64; 2]> = match serde_json::from_str(&text) {
        Ok(p) => p,
        Err(e) => {
            return bad_input(format!(
                "{}: expected a JSON list of [x, y] points: {e}",
                args.path.display()
            ))
        }
    };
    let grid = match map.grid() {
        Ok(g) => g,
        Err(e) => return bad_input(format!("{}: {e}", args.map.display())),
    };
    let length_m: f64 = points
        .windows(2)
        .map(|w| match w {
            [a, b] => (b[0] - a[0]).hypot(b[1] - a[1]),
            _ => 0.0,
        })
        .sum();
    let near = |a: Option<&[f64; 2]>, b: [f64; 2]| {
        a.is_some_and(|a| (a[0] - b[0]).hypot(a[1] - b[1]) <= args.tolerance)
    };
    let verdict = (|| -> Result<(), Invalid> {
        if points.len() < 2 {
            return Err(Invalid::TooShort(points.len()));
        }
        if !near(points.first(), args.start_m) {
            return Err(Invalid::Start {
                at: points.first().copied(),
                start: args.start_m,
            });
        }
        if !near(points.last(), args.goal_m) {
            return Err(Invalid::Goal {
                at: points.last().copied(),
                goal: args.goal_m,
            });
        }
        let mut cells = Vec::with_capacity(points.len());
        for (i, p) in points.iter().enumerate() {
            let c = frame.cell(*p).ok_or(Invalid::OffMap { index: i, at: *p })?;
            if map.is_blocked(c) {
                return Err(Invalid::OnObstacle {
                    index: i,
                    at: *p,
                    cell: c,
                });
            }
            cells.push(c);
        }
        for (i, w) in cells.windows(2).enumerate() {
            if let [a, b] = w {
                if !segment_clear(&grid, *a, *b) {
                    return Err(Invalid::Segment {
                        index: i,
                        from: *a,
                        to: *b,
                    });
                }
            }
        }
        Ok(())
    })();
    let out = serde_json::json!({
        "valid": verdict.is_ok(),
        "points": points.len(),
        "length_m": length_m,
        "error": verdict.as_ref().err().map(ToString::to_string),
    });
    print(&format!("{out}\n"));
    match verdict {
        Ok(()) => exit::FOUND,
        Err(e) => {
            eprintln!("invalid path: {e}");
            exit::NO_PATH
        }
    }
}

/// Why a path is not valid on the map (`error` in the JSON line, and `invalid path: ...`).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
enum Invalid {
    /// Fewer than two points.
    #[error("{0} points: a path needs at least 2")]
    TooShort(usize),
    /// The first point is not the start.
    #[error("the path starts at {at:?}, not at the start {start:?}")]
    Start {
        /// The first point.
        at: Option<[f64; 2]>,
        /// `--start-m`.
        start: [f64; 2],
    },
    /// The last point is not the goal.
    #[error("the path ends at {at:?}, not at the goal {goal:?}")]
    Goal {
        /// The last point.
        at: Option<[f64; 2]>,
        /// `--goal-m`.
        goal: [f64; 2],
    },
    /// A point is off the map.
    #[error("point {index} ({:.3}, {:.3}) is off the map", .at[0], .at[1])]
    OffMap {
        /// The point's index.
        index: usize,
        /// The point in metres.
        at: [f64; 2],
    },
    /// A point is on an obstacle.
    #[error("point {index} ({:.3}, {:.3}) is on an obstacle (cell {},{})", .at[0], .at[1], .cell.x, .cell.y)]
    OnObstacle {
        /// The point's index.
        index: usize,
        /// The point in metres.
        at: [f64; 2],
        /// Its cell.
        cell: Point,
    },
    /// A segment between two points touches an obstacle.
    #[error("segment {index} from cell {},{} to {},{} touches an obstacle", .from.x, .from.y, .to.x, .to.y)]
    Segment {
        /// The segment's index.
        index: usize,
        /// Its first cell.
        from: Point,
        /// Its last cell.
        to: Point,
    },
}
