//! Command-line values shared by the subcommands: `X,Y` points ([`parse_point`]) and the planner
//! flags ([`ParamArgs`], which builds an [`ohaca::Params`]).
//!
//! Every planner flag defaults to the field of [`ohaca::Params::default`] (the paper's setting),
//! read at run time, so the defaults can never drift from the core. Flag values are only parsed
//! here; their ranges are checked by the core ([`ohaca::Params::validate`]) so the tool reports
//! exactly the core's message.

use ohaca::{Algorithm, DeadEnd, Params, Point, SmoothingKind};

/// A malformed `X,Y` point.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum PointError {
    /// Not two comma-separated parts.
    #[error("expected X,Y (two whole numbers separated by a comma), found `{0}`")]
    Shape(String),
    /// A coordinate is not a non-negative whole number.
    #[error("{axis} `{value}` is not a non-negative whole number")]
    NotANumber {
        /// `x` or `y`.
        axis: char,
        /// The text given.
        value: String,
    },
    /// A coordinate does not fit a map side.
    #[error("{axis} {value} is more than 65535")]
    TooLarge {
        /// `x` or `y`.
        axis: char,
        /// The text given.
        value: String,
    },
}

/// Parse `"X,Y"` (column, row from the top; spaces around either number are allowed).
pub fn parse_point(s: &str) -> Result<Point, PointError> {
    let mut parts = s.split(',');
    let (Some(x), Some(y), None) = (parts.next(), parts.next(), parts.next()) else {
        return Err(PointError::Shape(s.to_string()));
    };
    let coord = |axis: char, v: &str| -> Result<u16, PointError> {
        let v = v.trim();
        if v.is_empty() || !v.bytes().all(|b| b.is_ascii_digit()) {
            return Err(PointError::NotANumber {
                axis,
                value: v.to_string(),
            });
        }
        v.parse::<u16>().map_err(|_| PointError::TooLarge {
            axis,
            value: v.to_string(),
        })
    };
    Ok(Point::new(coord('x', x)?, coord('y', y)?))
}

/// Parse a planner enum ([`Algorithm`], [`DeadEnd`], [`SmoothingKind`]) by its lower-case name,
/// in any case: the names of the core's serde derive, which the JSON report prints too.
pub fn parse_name<T: serde::de::DeserializeOwned>(s: &str) -> Result<T, String> {
    use serde::de::value::{Error, StrDeserializer};
    let lower = s.trim().to_ascii_lowercase();
    T::deserialize(StrDeserializer::<Error>::new(&lower)).map_err(|e| e.to_string())
}

/// Parse a boolean flag value (`true`/`false`, `on`/`off`, `yes`/`no`, `1`/`0`).
pub fn parse_bool(s: &str) -> Result<bool, String> {
    match s.trim().to_ascii_lowercase().as_str() {
        "true" | "on" | "yes" | "1" => Ok(true),
        "false" | "off" | "no" | "0" => Ok(false),
        _ => Err(format!("expected true or false, found `{s}`")),
    }
}

/// Every planner parameter as a command-line flag. Flatten it into a subcommand's arguments
/// (`#[command(flatten)]`) and call [`ParamArgs::params`].
#[derive(clap::Args, Clone, Debug, PartialEq)]
#[command(next_help_heading = "Planner parameters (defaults: the paper's setting)")]
pub struct ParamArgs {
    /// Planner variant: ohaca, haca, paca or aca
    #[arg(long, value_name = "NAME", value_parser = parse_name::<Algorithm>,
          default_value_t = Params::default().algorithm)]
    pub algorithm: Algorithm,
    /// Seed of the random generator
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          default_value_t = Params::default().seed)]
    pub seed: u64,
    /// Ants per iteration (M)
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          default_value_t = Params::default().ants)]
    pub ants: u16,
    /// Maximum iterations (N)
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          default_value_t = Params::default().iterations)]
    pub iterations: u16,
    /// Pheromone exponent
    #[arg(long, value_name = "A", allow_negative_numbers = true,
          default_value_t = Params::default().alpha)]
    pub alpha: f32,
    /// Heuristic exponent
    #[arg(long, value_name = "B", allow_negative_numbers = true,
          default_value_t = Params::default().beta)]
    pub beta: f32,
    /// Evaporation rate, in (0, 1]
    #[arg(long, value_name = "R", allow_negative_numbers = true,
          default_value_t = Params::default().rho)]
    pub rho: f32,
    /// Pheromone deposit constant
    #[arg(long, value_name = "Q", allow_negative_numbers = true,
          default_value_t = Params::default().q)]
    pub q: f32,
    /// Goal-attraction base, in (0, 1]
    #[arg(long, value_name = "A", allow_negative_numbers = true,
          default_value_t = Params::default().a)]
    pub a: f32,
    /// Potential-field gain
    #[arg(long, value_name = "X", allow_negative_numbers = true,
          default_value_t = Params::default().xi)]
    pub xi: f32,
    /// Initial pheromone on every edge
    #[arg(long, value_name = "T", allow_negative_numbers = true,
          default_value_t = Params::default().tau0)]
    pub tau0: f32,
    /// Lower pheromone bound
    #[arg(long, value_name = "T", allow_negative_numbers = true,
          default_value_t = Params::default().tau_min)]
    pub tau_min: f32,
    /// Upper pheromone bound
    #[arg(long, value_name = "T", allow_negative_numbers = true,
          default_value_t = Params::default().tau_max)]
    pub tau_max: f32,
    /// Stop after this many iterations without improvement; 0 = never stop early
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          default_value_t = Params::default().patience)]
    pub patience: u16,
    /// What an ant does at a dead end: backtrack or die (the paper)
    #[arg(long, value_name = "RULE", value_parser = parse_name::<DeadEnd>,
          default_value_t = Params::default().dead_end)]
    pub dead_end: DeadEnd,
    /// How OHACA smooths its path: shortest, greedy (the paper) or none
    #[arg(long, value_name = "KIND", value_parser = parse_name::<SmoothingKind>,
          default_value_t = Params::default().smoothing)]
    pub smoothing: SmoothingKind,
    /// Straighten each ant's path before the pheromone update (not in the paper)
    #[arg(long, value_name = "BOOL", value_parser = parse_bool, action = clap::ArgAction::Set,
          default_value = if Params::default().tighten { "true" } else { "false" })]
    pub tighten: bool,
}

impl ParamArgs {
    /// The flags as core parameters (not yet validated: [`ohaca::plan`] does that).
    pub fn params(&self) -> Params {
        Params {
            algorithm: self.algorithm,
            ants: self.ants,
            iterations: self.iterations,
            alpha: self.alpha,
            beta: self.beta,
            rho: self.rho,
            q: self.q,
            a: self.a,
            xi: self.xi,
            tau0: self.tau0,
            tau_min: self.tau_min,
            tau_max: self.tau_max,
            patience: self.patience,
            seed: self.seed,
            dead_end: self.dead_end,
            smoothing: self.smoothing,
            tighten: self.tighten,
        }
    }
}

impl From<&ParamArgs> for Params {
    fn from(a: &ParamArgs) -> Params {
        a.params()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser, Debug)]
    struct T {
        #[command(flatten)]
        p: ParamArgs,
    }

    fn parse(args: &[&str]) -> Result<Params, clap::Error> {
        T::try_parse_from(std::iter::once("t").chain(args.iter().copied())).map(|t| t.p.params())
    }

    #[test]
    fn defaults_are_the_cores() {
        assert_eq!(parse(&[]).unwrap(), Params::default());
    }

    #[test]
    fn every_flag_maps_to_its_field() {
        let p = parse(&[
            "--algorithm",
            "PACA",
            "--seed",
            "18446744073709551615",
            "--ants",
            "7",
            "--iterations",
            "9",
            "--alpha",
            "1.5",
            "--beta",
            "3",
            "--rho",
            "0.25",
            "--q",
            "2",
            "--a",
            "0.5",
            "--xi",
            "0.75",
            "--tau0",
            "2",
            "--tau-min",
            "0.5",
            "--tau-max",
            "10",
            "--patience",
            "0",
            "--dead-end",
            "die",
            "--smoothing",
            "greedy",
            "--tighten",
            "false",
        ])
        .unwrap();
        assert_eq!(
            p,
            Params {
                algorithm: Algorithm::Paca,
                ants: 7,
                iterations: 9,
                alpha: 1.5,
                beta: 3.0,
                rho: 0.25,
                q: 2.0,
                a: 0.5,
                xi: 0.75,
                tau0: 2.0,
                tau_min: 0.5,
                tau_max: 10.0,
                patience: 0,
                seed: u64::MAX,
                dead_end: DeadEnd::Die,
                smoothing: SmoothingKind::Greedy,
                tighten: false,
            }
        );
    }

    #[test]
    fn negative_floats_reach_the_core() {
        let p = parse(&["--alpha", "-1"]).unwrap();
        assert_eq!(p.alpha, -1.0);
        assert!(p.validate().is_err());
    }

    #[test]
    fn bad_flag_values() {
        for args in [
            &["--ants", "-1"][..],
            &["--ants", "70000"],
            &["--seed", "abc"],
            &["--rho", "x"],
            &["--algorithm", "bee"],
            &["--dead-end", "fly"],
            &["--smoothing", "bezier"],
            &["--tighten", "maybe"],
        ] {
            assert!(parse(args).is_err(), "{args:?}");
        }
    }

    #[test]
    fn names_round_trip() {
        for a in Algorithm::ALL {
            assert_eq!(parse_name(a.name()), Ok(a));
            assert_eq!(parse_name(&a.name().to_uppercase()), Ok(a));
        }
        for d in DeadEnd::ALL {
            assert_eq!(parse_name(d.name()), Ok(d));
        }
        for k in SmoothingKind::ALL {
            assert_eq!(parse_name(k.name()), Ok(k));
        }
        assert!(parse_name::<Algorithm>("bee")
            .unwrap_err()
            .contains("`ohaca`"));
    }

    #[test]
    fn points() {
        assert_eq!(parse_point("3,4"), Ok(Point::new(3, 4)));
        assert_eq!(parse_point(" 0 , 65535 "), Ok(Point::new(0, 65535)));
        assert_eq!(parse_point("3"), Err(PointError::Shape("3".into())));
        assert_eq!(parse_point("1,2,3"), Err(PointError::Shape("1,2,3".into())));
        assert_eq!(
            parse_point("-1,2"),
            Err(PointError::NotANumber {
                axis: 'x',
                value: "-1".into()
            })
        );
        assert_eq!(
            parse_point("1,"),
            Err(PointError::NotANumber {
                axis: 'y',
                value: "".into()
            })
        );
        assert_eq!(
            parse_point("1,+2"),
            Err(PointError::NotANumber {
                axis: 'y',
                value: "+2".into()
            })
        );
        assert_eq!(
            parse_point("65536,0"),
            Err(PointError::TooLarge {
                axis: 'x',
                value: "65536".into()
            })
        );
        assert_eq!(
            parse_point("1,2").map(|p| (p.x, p.y)),
            Ok((1, 2)),
            "x is the column, y the row"
        );
    }
}
