//! Command-line values shared by the subcommands: `X,Y` points ([`parse_point`]) and the planner
//! flags ([`ParamArgs`], which builds an [`ohaca::Params`]).
//!
//! Every planner flag takes its value from a preset unless given: `--preset default` (the core's
//! [`ohaca::Params::default`], this project's setting) or `--preset paper` (the core's
//! [`ohaca::Params::paper`], the paper's algorithm as written), read at run time, so the presets
//! can never drift from the core. Explicit flags override the preset. Flag values are only parsed
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

/// A malformed flag value other than a point ([`PointError`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum ValueError {
    /// Not a name of the planner enum (serde's words: the name given and the names expected).
    #[error("{0}")]
    Name(String),
    /// Not a boolean.
    #[error("expected true or false, found `{0}`")]
    Bool(String),
    /// Not a preset's name.
    #[error("unknown preset `{0}`; expected default or paper")]
    Preset(String),
    /// Not two comma-separated parts (`X,Y` in metres).
    #[error("expected X,Y in metres (two numbers separated by a comma), found `{0}`")]
    Metres(String),
    /// A coordinate in metres is not a finite number.
    #[error("{axis} `{value}` is not a number")]
    NotANumber {
        /// `x` or `y`.
        axis: char,
        /// The text given.
        value: String,
    },
    /// Not a length: a finite number >= 0.
    #[error("expected a length >= 0, found `{0}`")]
    Length(String),
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
pub fn parse_name<T: serde::de::DeserializeOwned>(s: &str) -> Result<T, ValueError> {
    use serde::de::value::{Error, StrDeserializer};
    let lower = s.trim().to_ascii_lowercase();
    T::deserialize(StrDeserializer::<Error>::new(&lower))
        .map_err(|e| ValueError::Name(e.to_string()))
}

/// Parse a boolean flag value (`true`/`false`, `on`/`off`, `yes`/`no`, `1`/`0`).
pub fn parse_bool(s: &str) -> Result<bool, ValueError> {
    match s.trim().to_ascii_lowercase().as_str() {
        "true" | "on" | "yes" | "1" => Ok(true),
        "false" | "off" | "no" | "0" => Ok(false),
        _ => Err(ValueError::Bool(s.to_string())),
    }
}

/// A named set of planner parameters that the flags start from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Preset {
    /// [`Params::default`]: the paper's constants with 12 backtracking ants, path tightening, early
    /// stopping and shortest smoothing.
    #[default]
    Default,
    /// [`Params::paper`]: the paper's algorithm as written (ants die at dead ends, no tightening,
    /// always all iterations, greedy smoothing).
    Paper,
}

impl Preset {
    /// Both, default first.
    pub const ALL: [Preset; 2] = [Preset::Default, Preset::Paper];

    /// Lower-case name (`default`, `paper`).
    pub const fn name(self) -> &'static str {
        match self {
            Preset::Default => "default",
            Preset::Paper => "paper",
        }
    }

    /// The preset's parameters.
    pub fn params(self) -> Params {
        match self {
            Preset::Default => Params::default(),
            Preset::Paper => Params::paper(),
        }
    }
}

/// A flag's help line with its value in both presets: `[default: X]` when they agree,
/// `[default: X, paper: Y]` when they do not.
fn preset_help(what: &str, value: impl Fn(&Params) -> String) -> String {
    let (d, p) = (value(&Params::default()), value(&Params::paper()));
    if d == p {
        format!("{what} [default: {d}]")
    } else {
        format!("{what} [default: {d}, paper: {p}]")
    }
}

/// Parse a preset name (`default` or `paper`; any case).
pub fn parse_preset(s: &str) -> Result<Preset, ValueError> {
    Preset::ALL
        .into_iter()
        .find(|p| p.name().eq_ignore_ascii_case(s.trim()))
        .ok_or_else(|| ValueError::Preset(s.to_string()))
}

/// Every planner parameter as a command-line flag. Flatten it into a subcommand's arguments
/// (`#[command(flatten)]`) and call [`ParamArgs::params`]. A flag that is not given takes the
/// value of `--preset` (default: `default`).
#[derive(clap::Args, Clone, Debug, PartialEq)]
#[command(next_help_heading = "Planner parameters (unset flags take the preset's value)")]
pub struct ParamArgs {
    /// Starting point of every flag below: default (this project's setting) or paper (the
    /// paper's algorithm as written: ants die, no tightening, all iterations, greedy smoothing)
    #[arg(long, value_name = "NAME", value_parser = parse_preset, default_value = "default")]
    pub preset: Preset,
    /// Planner variant: ohaca, haca, paca or aca
    #[arg(long, value_name = "NAME", value_parser = parse_name::<Algorithm>,
          help = preset_help("Planner variant: ohaca, haca, paca or aca", |p| p.algorithm.name().to_string()))]
    pub algorithm: Option<Algorithm>,
    /// Seed of the random generator
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          help = preset_help("Seed of the random generator", |p| p.seed.to_string()))]
    pub seed: Option<u64>,
    /// Ants per iteration (M)
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          help = preset_help("Ants per iteration (M)", |p| p.ants.to_string()))]
    pub ants: Option<u16>,
    /// Maximum iterations (N)
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          help = preset_help("Maximum iterations (N)", |p| p.iterations.to_string()))]
    pub iterations: Option<u16>,
    /// Pheromone exponent
    #[arg(long, value_name = "A", allow_negative_numbers = true,
          help = preset_help("Pheromone exponent", |p| p.alpha.to_string()))]
    pub alpha: Option<f32>,
    /// Heuristic exponent
    #[arg(long, value_name = "B", allow_negative_numbers = true,
          help = preset_help("Heuristic exponent", |p| p.beta.to_string()))]
    pub beta: Option<f32>,
    /// Evaporation rate, in (0, 1]
    #[arg(long, value_name = "R", allow_negative_numbers = true,
          help = preset_help("Evaporation rate, in (0, 1]", |p| p.rho.to_string()))]
    pub rho: Option<f32>,
    /// Pheromone deposit constant
    #[arg(long, value_name = "Q", allow_negative_numbers = true,
          help = preset_help("Pheromone deposit constant", |p| p.q.to_string()))]
    pub q: Option<f32>,
    /// Goal-attraction base, in (0, 1]
    #[arg(long, value_name = "A", allow_negative_numbers = true,
          help = preset_help("Goal-attraction base, in (0, 1]", |p| p.a.to_string()))]
    pub a: Option<f32>,
    /// Potential-field gain
    #[arg(long, value_name = "X", allow_negative_numbers = true,
          help = preset_help("Potential-field gain", |p| p.xi.to_string()))]
    pub xi: Option<f32>,
    /// Initial pheromone on every edge
    #[arg(long, value_name = "T", allow_negative_numbers = true,
          help = preset_help("Initial pheromone on every edge", |p| p.tau0.to_string()))]
    pub tau0: Option<f32>,
    /// Lower pheromone bound
    #[arg(long, value_name = "T", allow_negative_numbers = true,
          help = preset_help("Lower pheromone bound", |p| p.tau_min.to_string()))]
    pub tau_min: Option<f32>,
    /// Upper pheromone bound
    #[arg(long, value_name = "T", allow_negative_numbers = true,
          help = preset_help("Upper pheromone bound", |p| p.tau_max.to_string()))]
    pub tau_max: Option<f32>,
    /// Stop after this many iterations without improvement; 0 = never stop early
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          help = preset_help("Stop after this many iterations without improvement; 0 = never stop early", |p| p.patience.to_string()))]
    pub patience: Option<u16>,
    /// The patience of a warm replan (PlanWarm / `ohaca replan`); 0 = the same as --patience
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          help = preset_help("The patience of a warm replan (PlanWarm / `ohaca replan`); 0 = the same as --patience", |p| p.warm_patience.to_string()))]
    pub warm_patience: Option<u16>,
    /// The patience of a run that refines its path (large maps, --refine); 0 = the same as --patience
    #[arg(long, value_name = "N", allow_negative_numbers = true,
          help = preset_help("The patience of a run that refines its path (large maps, --refine); 0 = the same as --patience", |p| p.refine_patience.to_string()))]
    pub refine_patience: Option<u16>,
    /// What an ant does at a dead end: backtrack or die (the paper)
    #[arg(long, value_name = "RULE", value_parser = parse_name::<DeadEnd>,
          help = preset_help("What an ant does at a dead end: backtrack or die (the paper)", |p| p.dead_end.name().to_string()))]
    pub dead_end: Option<DeadEnd>,
    /// How OHACA smooths its path: shortest, greedy (the paper) or none
    #[arg(long, value_name = "KIND", value_parser = parse_name::<SmoothingKind>,
          help = preset_help("How OHACA smooths its path: shortest, greedy (the paper) or none", |p| p.smoothing.name().to_string()))]
    pub smoothing: Option<SmoothingKind>,
    /// Straighten each ant's path before the pheromone update (not in the paper)
    #[arg(long, value_name = "BOOL", value_parser = parse_bool, action = clap::ArgAction::Set,
          help = preset_help("Straighten each ant's path before the pheromone update (not in the paper)", |p| p.tighten.to_string()))]
    pub tighten: Option<bool>,
    /// Prune the cells no shortest path needs before the ants run (not in the paper)
    #[arg(long, value_name = "BOOL", value_parser = parse_bool, action = clap::ArgAction::Set,
          help = preset_help("Prune the cells no shortest path needs before the ants run (not in the paper)", |p| p.prune.to_string()))]
    pub prune: Option<bool>,
    /// Replace the raw path's pieces by exact shortest paths in windows around them, on maps of more than 1,024 cells (not in the paper)
    #[arg(long, value_name = "BOOL", value_parser = parse_bool, action = clap::ArgAction::Set,
          help = preset_help("Replace the raw path's pieces by exact shortest paths in windows around them, on maps of more than 1,024 cells (not in the paper)", |p| p.refine.to_string()))]
    pub refine: Option<bool>,
}

impl ParamArgs {
    /// The flags over the preset, as core parameters (not yet validated: [`ohaca::plan`] does
    /// that).
    pub fn params(&self) -> Params {
        let base = self.preset.params();
        Params {
            algorithm: self.algorithm.unwrap_or(base.algorithm),
            seed: self.seed.unwrap_or(base.seed),
            ants: self.ants.unwrap_or(base.ants),
            iterations: self.iterations.unwrap_or(base.iterations),
            alpha: self.alpha.unwrap_or(base.alpha),
            beta: self.beta.unwrap_or(base.beta),
            rho: self.rho.unwrap_or(base.rho),
            q: self.q.unwrap_or(base.q),
            a: self.a.unwrap_or(base.a),
            xi: self.xi.unwrap_or(base.xi),
            tau0: self.tau0.unwrap_or(base.tau0),
            tau_min: self.tau_min.unwrap_or(base.tau_min),
            tau_max: self.tau_max.unwrap_or(base.tau_max),
            patience: self.patience.unwrap_or(base.patience),
            warm_patience: self.warm_patience.unwrap_or(base.warm_patience),
            refine_patience: self.refine_patience.unwrap_or(base.refine_patience),
            dead_end: self.dead_end.unwrap_or(base.dead_end),
            smoothing: self.smoothing.unwrap_or(base.smoothing),
            tighten: self.tighten.unwrap_or(base.tighten),
            prune: self.prune.unwrap_or(base.prune),
            refine: self.refine.unwrap_or(base.refine),
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
            "--warm-patience",
            "5",
            "--refine-patience",
            "4",
            "--dead-end",
            "die",
            "--smoothing",
            "greedy",
            "--tighten",
            "false",
            "--refine",
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
                warm_patience: 5,
                refine_patience: 4,
                seed: u64::MAX,
                dead_end: DeadEnd::Die,
                smoothing: SmoothingKind::Greedy,
                tighten: false,
                prune: true,
                refine: false,
            }
        );
    }

    #[test]
    fn the_paper_preset_is_the_cores() {
        assert_eq!(parse(&["--preset", "paper"]).unwrap(), Params::paper());
        assert_eq!(parse(&["--preset", "PAPER"]).unwrap(), Params::paper());
        assert_eq!(parse(&["--preset", "default"]).unwrap(), Params::default());
        assert!(parse(&["--preset", "book"]).is_err());
    }

    #[test]
    fn explicit_flags_override_the_preset() {
        // Either order: a flag wins over the preset whether it comes before or after it.
        for args in [
            &[
                "--preset",
                "paper",
                "--dead-end",
                "backtrack",
                "--seed",
                "9",
            ][..],
            &[
                "--dead-end",
                "backtrack",
                "--seed",
                "9",
                "--preset",
                "paper",
            ],
        ] {
            assert_eq!(
                parse(args).unwrap(),
                Params {
                    dead_end: DeadEnd::Backtrack,
                    seed: 9,
                    ..Params::paper()
                },
                "{args:?}"
            );
        }
        // A flag given with the preset's own value changes nothing.
        assert_eq!(
            parse(&["--preset", "paper", "--tighten", "false", "--patience", "0"]).unwrap(),
            Params::paper()
        );
        assert_eq!(
            parse(&["--patience", "0"]).unwrap(),
            Params {
                patience: 0,
                ..Params::default()
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
            .to_string()
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
