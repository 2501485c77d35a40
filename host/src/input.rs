//! The map flags of the path-producing subcommands (`plan`, `render`, `experiment`, `send`): the
//! map file in any format [`crate::map`] reads, prepared for the robot (`--unknown`, `--inflate`,
//! `--cell`; [`crate::map::prepare`]), and the start and goal in cells or, for maps with a
//! resolution, metres (`--start-m`/`--goal-m`). [`MapArgs::load`] turns the flags into a
//! [`Scenario`]; `--start`/`--goal` are cells of the prepared grid.

use std::path::PathBuf;

use clap::parser::ValueSource;
use clap::{ArgAction, ArgMatches, Args, Command, FromArgMatches};
use ohaca::{Algorithm, Point};

use crate::args::{parse_point, ParamArgs, ValueError};
use crate::map::{prepare, Map, MapError, MapFrame, Unknown};

/// Parse `"X,Y"` in metres (any finite numbers, e.g. `-1.5,2`).
pub fn parse_metres(s: &str) -> Result<[f64; 2], ValueError> {
    let mut parts = s.split(',');
    let (Some(x), Some(y), None) = (parts.next(), parts.next(), parts.next()) else {
        return Err(ValueError::Metres(s.to_string()));
    };
    let num = |axis: char, v: &str| -> Result<f64, ValueError> {
        v.trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| ValueError::NotANumber {
                axis,
                value: v.trim().to_string(),
            })
    };
    Ok([num('x', x)?, num('y', y)?])
}

/// Parse a length in metres: a finite number >= 0.
pub fn parse_length(s: &str) -> Result<f64, ValueError> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| ValueError::Length(s.to_string()))
}

/// The map and the start and goal, as command-line flags. Flatten it into a subcommand
/// (`#[command(flatten)]`) and call [`MapArgs::load`]. The start and the goal are each required,
/// in cells or in metres (`send` relaxes that for `--goals` with `mut_arg`).
#[derive(clap::Args, Clone, Debug, PartialEq)]
pub struct MapArgs {
    /// Map file: Moving AI `.map`, a text grid (`.`/`0` free, `#`/`1` blocked), a ROS
    /// map_server `.yaml` (with its PGM/PNG image), or a PNG/PGM image (dark = blocked)
    #[arg(long, value_name = "FILE")]
    pub map: PathBuf,
    /// Start cell: column,row with 0,0 the top-left cell (of the grid after --cell)
    #[arg(long, value_name = "X,Y", value_parser = parse_point, allow_hyphen_values = true,
          required_unless_present = "start_m", conflicts_with = "start_m")]
    pub start: Option<Point>,
    /// Goal cell: column,row
    #[arg(long, value_name = "X,Y", value_parser = parse_point, allow_hyphen_values = true,
          required_unless_present = "goal_m", conflicts_with = "goal_m")]
    pub goal: Option<Point>,
    /// Start in metres, in the ROS map frame (maps with a resolution only)
    #[arg(long, value_name = "X,Y", value_parser = parse_metres, allow_hyphen_values = true)]
    pub start_m: Option<[f64; 2]>,
    /// Goal in metres, in the ROS map frame
    #[arg(long, value_name = "X,Y", value_parser = parse_metres, allow_hyphen_values = true)]
    pub goal_m: Option<[f64; 2]>,
    /// ROS maps: cells between free_thresh and occupied_thresh (unexplored) are blocked or free
    #[arg(long, value_name = "AS", value_enum, default_value_t = Unknown::Blocked)]
    pub unknown: Unknown,
    /// Block every cell whose centre is within this radius of an obstacle's centre: metres
    /// (cells for maps without a resolution)
    #[arg(long, value_name = "RADIUS", value_parser = parse_length, allow_negative_numbers = true)]
    pub inflate: Option<f64>,
    /// Resample to coarser cells of this size: metres (cells for maps without a resolution); a
    /// coarse cell is blocked if any pixel it covers is
    #[arg(long, value_name = "SIZE", value_parser = parse_length, allow_negative_numbers = true)]
    pub cell: Option<f64>,
}

/// A loaded, prepared map with its start and goal in cells.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// The map file as given (for messages and titles).
    pub name: String,
    /// The grid the planner sees.
    pub map: Map,
    /// Where the grid's cells are in metres (maps with a resolution).
    pub metric: Option<MapFrame>,
    /// Start cell.
    pub start: Point,
    /// Goal cell.
    pub goal: Point,
}

impl Scenario {
    /// Metres of each point (rounded to a micrometre), if the map has a resolution.
    pub fn metres(&self, points: &[[u16; 2]]) -> Option<Vec<[f64; 2]>> {
        self.metric.map(|f| f.points_m(points))
    }
}

/// A start or goal (`what`) given in cells or in metres, as a cell of the prepared grid.
/// `name` is the map file, for messages.
pub fn resolve_point(
    name: &str,
    metric: Option<MapFrame>,
    what: &str,
    cells: Option<Point>,
    metres: Option<[f64; 2]>,
) -> Result<Point, MapError> {
    let err = |problem: String| MapError::File {
        path: name.to_string(),
        problem,
    };
    match (cells, metres, metric) {
        (Some(p), _, _) => Ok(p),
        (None, Some(m), Some(f)) => f.cell(m).ok_or_else(|| {
            let [x0, x1, y0, y1] = f.extent();
            let bounds = if f.yaw == 0.0 {
                format!(" (x from {x0} to {x1} m, y from {y0} to {y1} m)")
            } else {
                String::new()
            };
            err(format!(
                "{what} ({}, {}) m is outside the map{bounds}",
                m[0], m[1]
            ))
        }),
        (None, Some(_), None) => Err(err(format!(
            "--{what}-m needs a map with a resolution (a ROS map_server YAML file); \
                 give --{what} in cells"
        ))),
        (None, None, _) => Err(err(format!("no {what} given (--{what} or --{what}-m)"))),
    }
}

impl MapArgs {
    /// Load and prepare the map ([`prepare`]), and resolve the start and goal.
    pub fn load(&self) -> Result<Scenario, MapError> {
        let name = self.map.display().to_string();
        let (map, metric) = prepare(&self.map, self.unknown, self.inflate, self.cell)?;
        let start = resolve_point(&name, metric, "start", self.start, self.start_m)?;
        let goal = resolve_point(&name, metric, "goal", self.goal, self.goal_m)?;
        Ok(Scenario {
            name,
            map,
            metric,
            start,
            goal,
        })
    }
}

/// [`ParamArgs`] whose `--algorithm` may be given several times or as a comma-separated list
/// (alias `--algorithms`), for the commands that run several variants.
#[derive(Clone, Debug, PartialEq)]
pub struct MultiParamArgs {
    /// Every planner flag; `params.params().algorithm` is the first algorithm given.
    pub params: ParamArgs,
    /// The algorithms given, in order, without repeats (empty if none was given).
    pub given: Vec<Algorithm>,
}

impl MultiParamArgs {
    /// The algorithms given, or `default` if none was.
    pub fn algorithms(&self, default: &[Algorithm]) -> Vec<Algorithm> {
        if self.given.is_empty() {
            default.to_vec()
        } else {
            self.given.clone()
        }
    }
}

impl FromArgMatches for MultiParamArgs {
    fn from_arg_matches(m: &ArgMatches) -> Result<Self, clap::Error> {
        Self::from_arg_matches_mut(&mut m.clone())
    }

    fn from_arg_matches_mut(m: &mut ArgMatches) -> Result<Self, clap::Error> {
        let mut given = Vec::new();
        if m.value_source("algorithm") == Some(ValueSource::CommandLine) {
            for a in m.get_many::<Algorithm>("algorithm").into_iter().flatten() {
                if !given.contains(a) {
                    given.push(*a);
                }
            }
        }
        let params = ParamArgs::from_arg_matches_mut(m)?;
        Ok(MultiParamArgs { params, given })
    }

    fn update_from_arg_matches(&mut self, m: &ArgMatches) -> Result<(), clap::Error> {
        *self = Self::from_arg_matches(m)?;
        Ok(())
    }
}

impl Args for MultiParamArgs {
    fn augment_args(cmd: Command) -> Command {
        ParamArgs::augment_args(cmd).mut_arg("algorithm", |a| {
            a.action(ArgAction::Append)
                .value_delimiter(',')
                .visible_alias("algorithms")
                .hide_default_value(true)
                .help(
                    "Planner variants: ohaca, haca, paca, aca; repeat or separate with commas \
                     [default: render ohaca, experiment all four]",
                )
        })
    }

    fn augment_args_for_update(cmd: Command) -> Command {
        Self::augment_args(cmd)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser, Debug)]
    struct T {
        #[command(flatten)]
        m: MapArgs,
        #[command(flatten)]
        p: MultiParamArgs,
    }

    fn parse(args: &[&str]) -> Result<T, clap::Error> {
        T::try_parse_from(std::iter::once("t").chain(args.iter().copied()))
    }

    #[test]
    fn metres_and_lengths() {
        assert_eq!(parse_metres("-1.5, 2"), Ok([-1.5, 2.0]));
        assert!(parse_metres("1").is_err());
        assert!(parse_metres("1,x").is_err());
        assert!(parse_metres("1,inf").is_err());
        assert_eq!(parse_length("0.25"), Ok(0.25));
        assert!(parse_length("-1").is_err());
        assert!(parse_length("nan").is_err());
    }

    #[test]
    fn start_in_cells_or_metres() {
        let t = parse(&["--map", "m", "--start", "1,2", "--goal-m", "-1.5,2"]).unwrap();
        assert_eq!(t.m.start, Some(Point::new(1, 2)));
        assert_eq!(t.m.goal_m, Some([-1.5, 2.0]));
        assert!(
            parse(&["--map", "m", "--goal", "1,2"]).is_err(),
            "start missing"
        );
        assert!(parse(&[
            "--map",
            "m",
            "--start",
            "1,2",
            "--start-m",
            "1,2",
            "--goal",
            "1,1"
        ])
        .is_err());
        let t = parse(&["--map", "m", "--start", "0,0", "--goal", "1,1"]).unwrap();
        assert_eq!(t.m.unknown, Unknown::Blocked);
        let t = parse(&[
            "--map",
            "m",
            "--start",
            "0,0",
            "--goal",
            "1,1",
            "--unknown",
            "free",
            "--inflate",
            "0.3",
            "--cell",
            "0.1",
        ])
        .unwrap();
        assert_eq!(
            (t.m.unknown, t.m.inflate, t.m.cell),
            (Unknown::Free, Some(0.3), Some(0.1))
        );
    }

    #[test]
    fn several_algorithms() {
        let base = ["--map", "m", "--start", "0,0", "--goal", "1,1"];
        let with = |extra: &[&str]| {
            let mut a = base.to_vec();
            a.extend_from_slice(extra);
            parse(&a).unwrap().p
        };
        let p = with(&[]);
        assert!(p.given.is_empty());
        assert_eq!(p.params.params().algorithm, Algorithm::Ohaca);
        assert_eq!(p.algorithms(&Algorithm::ALL), Algorithm::ALL.to_vec());
        let p = with(&["--algorithm", "aca", "--algorithm", "ohaca", "--ants", "7"]);
        assert_eq!(p.given, vec![Algorithm::Aca, Algorithm::Ohaca]);
        assert_eq!(p.params.params().algorithm, Algorithm::Aca);
        assert_eq!(p.params.params().ants, 7);
        let p = with(&["--algorithms", "haca,paca,haca"]);
        assert_eq!(p.given, vec![Algorithm::Haca, Algorithm::Paca]);
        assert!(parse(&[&base[..], &["--algorithm", "bee"]].concat()).is_err());
    }
}
