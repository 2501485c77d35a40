//! What the tool prints: the JSON [`PlanReport`] and the ASCII picture.
//!
//! ## The JSON contract
//! `ohaca plan --json` prints one [`PlanReport`] as a single-line JSON object, and every command
//! that produces a path (e.g. a later `ohaca send`, which plans on the firmware) must print the
//! very same keys, so scripts work with either. The keys, in this order:
//!
//! | key | type | meaning |
//! | --- | --- | --- |
//! | `found` | bool | a path was found |
//! | `raw` | `[[x, y], ...]` | the raw 8-connected path, start to goal (`[]` if not found) |
//! | `waypoints` | `[[x, y], ...]` | the output path (smoothed for OHACA; `[]` if not found) |
//! | `raw_length` | number or null | length of `raw` in cell units |
//! | `length` | number or null | length of the polyline through `waypoints` |
//! | `turns` | integer or null | turns along `waypoints` |
//! | `iterations` | integer or null | iterations run (null if unknown) |
//! | `best_iteration` | integer or null | 0-based iteration in which the best path was first found |
//! | `moves` | integer or null | ant moves made, forward and backtracking, over the run |
//! | `elapsed_us` | integer | planning time in microseconds (map loading excluded) |
//! | `params` | object | every field of [`ohaca::Params`], in order; enum values by their lower-case names (`"ohaca"`, `"backtrack"`, `"shortest"`) |
//! | `error` | string | only when `found` is false: why |
//!
//! | `waypoints_m` | `[[x, y], ...]` | only for maps with a resolution (ROS YAML): `waypoints` in metres, ROS map frame ([`LocatedReport`]) |
//!
//! `x` is the column, `y` the row from the top. Numbers that describe a path are null exactly
//! when no path was found. The struct's fields are public and it derives `Deserialize`, so a
//! report can be built from plain fields (a firmware reply) or read back from JSON.
//!
//! ## The picture
//! [`render`] draws the map with the raw path (`*`), the waypoints (`o`), start `S`, goal `G`,
//! obstacles `#` and free cells `.` (cells separated by spaces, so a cell looks square in a
//! terminal), followed by a short [`summary`].

use std::fmt::Write as _;
use std::time::Duration;

use ohaca::{Params, Plan, Point};
use serde::{Deserialize, Serialize};

use crate::map::Map;

/// The result of one planning request. See the module docs for the JSON contract.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PlanReport {
    /// A path was found.
    pub found: bool,
    /// Raw 8-connected path, `[x, y]` per cell, start to goal.
    pub raw: Vec<[u16; 2]>,
    /// Output waypoints, `[x, y]`, start to goal.
    pub waypoints: Vec<[u16; 2]>,
    /// Length of the raw path.
    #[serde(serialize_with = "serialize_length")]
    pub raw_length: Option<f32>,
    /// Length through the waypoints.
    #[serde(serialize_with = "serialize_length")]
    pub length: Option<f32>,
    /// Turns along the waypoints.
    pub turns: Option<u32>,
    /// Iterations run.
    pub iterations: Option<u16>,
    /// 0-based iteration in which the best path was first found.
    pub best_iteration: Option<u16>,
    /// Ant moves over the run.
    pub moves: Option<u64>,
    /// Planning time in microseconds.
    pub elapsed_us: u64,
    /// Parameters used (enum values by their lower-case names, as the flags take them).
    pub params: Params,
    /// Why no path was found (absent when `found`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
    /// The steps that ran short of scratch (`ohaca::planner::Shortfalls`, absent when none did:
    /// always on a board's layout, and from the device, which logs them instead).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shortfalls: Option<String>,
}

/// `v` with a negative zero made positive: a path of one cell has length `0`, not `-0` (the
/// core's sum of no segments can be `-0.0`, which JSON, CSV and text would show as `-0`).
pub fn unsigned_zero(v: f32) -> f32 {
    if v == 0.0 {
        0.0
    } else {
        v
    }
}

/// Serialize a length with [`unsigned_zero`] applied, so every report (`plan`, `send`) prints
/// `0.0` for a one-cell path.
fn serialize_length<S: serde::Serializer>(v: &Option<f32>, s: S) -> Result<S::Ok, S::Error> {
    v.map(unsigned_zero).serialize(s)
}

/// `[x, y]` of a point.
pub fn xy(p: Point) -> [u16; 2] {
    [p.x, p.y]
}

/// Microseconds of `d`, saturating.
pub fn micros(d: Duration) -> u64 {
    u64::try_from(d.as_micros()).unwrap_or(u64::MAX)
}

impl PlanReport {
    /// The report of a successful plan that took `elapsed`.
    pub fn from_plan(plan: &Plan<'_>, elapsed: Duration) -> Self {
        PlanReport {
            found: true,
            raw: plan.raw().map(xy).collect(),
            waypoints: plan.waypoints().iter().copied().map(xy).collect(),
            raw_length: Some(unsigned_zero(plan.raw_length)),
            length: Some(unsigned_zero(plan.length)),
            turns: Some(plan.turns),
            iterations: Some(plan.iterations),
            best_iteration: Some(plan.best_iteration),
            moves: Some(plan.moves),
            elapsed_us: micros(elapsed),
            params: plan.params,
            error: None,
            shortfalls: (!plan.shortfalls.is_empty()).then(|| plan.shortfalls.to_string()),
        }
    }

    /// The report of a request that found no path: `error` says why, `iterations` is how many
    /// ran if known.
    pub fn not_found(
        params: &Params,
        error: impl std::fmt::Display,
        iterations: Option<u16>,
        elapsed: Duration,
    ) -> Self {
        PlanReport {
            found: false,
            raw: Vec::new(),
            waypoints: Vec::new(),
            raw_length: None,
            length: None,
            turns: None,
            iterations,
            best_iteration: None,
            moves: None,
            elapsed_us: micros(elapsed),
            params: *params,
            error: Some(error.to_string()),
            shortfalls: None,
        }
    }

    /// One line of JSON (no trailing newline).
    pub fn to_json(&self) -> String {
        // Serialising plain numbers, strings and vectors cannot fail; NaN/inf become null.
        serde_json::to_string(self).unwrap_or_else(|e| {
            format!(
                "{{\"found\":false,\"error\":{}}}",
                serde_json::Value::String(e.to_string())
            )
        })
    }
}

/// A [`PlanReport`] with the waypoints in metres appended as `waypoints_m` (after every
/// other key) when the map has a metric frame; without one it prints exactly the report.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct LocatedReport<'a> {
    /// The report.
    #[serde(flatten)]
    pub report: &'a PlanReport,
    /// Waypoints in metres, `[x, y]`, ROS map frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub waypoints_m: Option<&'a [[f64; 2]]>,
}

impl LocatedReport<'_> {
    /// One line of JSON (no trailing newline).
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).unwrap_or_else(|_| self.report.to_json())
    }
}

/// Waypoints as CSV: a header line, then `x,y` per waypoint: cells (header `x,y`), or metres
/// (header `x_m,y_m`) when `metres` is given.
pub fn waypoints_csv(waypoints: &[[u16; 2]], metres: Option<&[[f64; 2]]>) -> String {
    let mut s = String::new();
    match metres {
        Some(m) => {
            s.push_str("x_m,y_m\n");
            for [x, y] in m {
                let _ = writeln!(s, "{x},{y}");
            }
        }
        None => {
            s.push_str("x,y\n");
            for [x, y] in waypoints {
                let _ = writeln!(s, "{x},{y}");
            }
        }
    }
    s
}

/// The map as characters, with the path drawn on it: `#` obstacle, `.` free, `*` raw path,
/// `o` waypoint, `S` start, `G` goal (later marks win). Points outside the map are ignored.
/// One line per row, cells separated by a space, each line ending in `\n`.
pub fn picture(
    map: &Map,
    start: Point,
    goal: Point,
    raw: &[[u16; 2]],
    waypoints: &[[u16; 2]],
) -> String {
    let (w, h) = (usize::from(map.width), usize::from(map.height));
    let mut cells: Vec<u8> = (0..w * h)
        .map(|i| {
            // i < w * h, so both fit in u16.
            let p = Point::new((i % w) as u16, (i / w) as u16);
            if map.is_blocked(p) {
                b'#'
            } else {
                b'.'
            }
        })
        .collect();
    let mut mark = |[x, y]: [u16; 2], c: u8| {
        if x < map.width && y < map.height {
            if let Some(slot) = cells.get_mut(usize::from(y) * w + usize::from(x)) {
                *slot = c;
            }
        }
    };
    for &p in raw {
        mark(p, b'*');
    }
    for &p in waypoints {
        mark(p, b'o');
    }
    mark(xy(start), b'S');
    mark(xy(goal), b'G');
    let mut s = String::with_capacity(h * (2 * w + 1));
    for row in cells.chunks(w.max(1)) {
        for (i, &c) in row.iter().enumerate() {
            if i > 0 {
                s.push(' ');
            }
            s.push(char::from(c));
        }
        s.push('\n');
    }
    s
}

/// `12.345 ms` style duration from microseconds.
pub fn format_us(us: u64) -> String {
    if us >= 1_000_000 {
        format!("{:.3} s", us as f64 / 1e6)
    } else {
        format!("{:.3} ms", us as f64 / 1e3)
    }
}

/// `n thing` or `n things`.
pub fn count(n: u64, thing: &str) -> String {
    if n == 1 {
        format!("1 {thing}")
    } else {
        format!("{n} {thing}s")
    }
}

/// A short summary of a report: lengths, turns, iterations, time (two lines, each ending in
/// `\n`).
pub fn summary(r: &PlanReport) -> String {
    let mut s = String::new();
    let n =
        |v: Option<f32>| v.map_or_else(|| "-".to_string(), |v| format!("{:.3}", unsigned_zero(v)));
    if r.found {
        let _ = writeln!(
            s,
            "raw length {}   waypoint path {} ({})   {}",
            n(r.raw_length),
            n(r.length),
            count(r.waypoints.len() as u64, "waypoint"),
            r.turns
                .map_or_else(|| "- turns".to_string(), |t| count(u64::from(t), "turn")),
        );
    } else {
        // The core's error already says "no path: ..." (no "no path: no path:").
        let why = r.error.as_deref().unwrap_or("no path found");
        if why.starts_with("no path") {
            let _ = writeln!(s, "{why}");
        } else {
            let _ = writeln!(s, "no path: {why}");
        }
    }
    let mut line = String::new();
    if let Some(it) = r.iterations {
        line.push_str(&count(u64::from(it), "iteration"));
        if let Some(b) = r.best_iteration {
            let _ = write!(line, " (best found in iteration {})", u32::from(b) + 1);
        }
        line.push_str("   ");
    }
    if let Some(m) = r.moves {
        let _ = write!(line, "{m} ant moves   ");
    }
    let p = &r.params;
    let _ = write!(
        line,
        "planned in {}   {} seed {}, {} ants",
        format_us(r.elapsed_us),
        p.algorithm,
        p.seed,
        p.ants
    );
    s.push_str(&line);
    s.push('\n');
    if let Some(short) = &r.shortfalls {
        let _ = writeln!(s, "ran short of scratch (a cheaper form ran): {short}");
    }
    s
}

/// The legend line of [`picture`].
pub const LEGEND: &str = "S start   G goal   o waypoint   * raw ant path   # obstacle   . free";

/// Legend, picture and summary.
pub fn render(map: &Map, start: Point, goal: Point, report: &PlanReport) -> String {
    let mut s = String::new();
    s.push_str(LEGEND);
    s.push('\n');
    s.push_str(&picture(map, start, goal, &report.raw, &report.waypoints));
    s.push_str(&summary(report));
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::Format;
    use ohaca::{Algorithm, DeadEnd, SmoothingKind};

    fn report() -> PlanReport {
        PlanReport {
            found: true,
            raw: vec![[0, 0], [1, 1], [2, 1]],
            waypoints: vec![[0, 0], [2, 1]],
            raw_length: Some(2.4142137),
            length: Some(2.236068),
            turns: Some(0),
            iterations: Some(3),
            best_iteration: Some(0),
            moves: Some(42),
            elapsed_us: 1500,
            params: Params::default(),
            error: None,
            shortfalls: None,
        }
    }

    #[test]
    fn json_keys_in_order() {
        let j = report().to_json();
        let v: serde_json::Value = serde_json::from_str(&j).unwrap();
        let keys: Vec<_> = v.as_object().unwrap().keys().cloned().collect();
        // serde_json's map is sorted unless preserve_order; check presence and the text order.
        let mut pos = Vec::new();
        for k in [
            "found",
            "raw",
            "waypoints",
            "raw_length",
            "length",
            "turns",
            "iterations",
            "best_iteration",
            "moves",
            "elapsed_us",
            "params",
        ] {
            assert!(keys.contains(&k.to_string()), "{k}");
            pos.push(j.find(&format!("\"{k}\":")).unwrap());
        }
        assert!(pos.windows(2).all(|w| w[0] < w[1]), "{j}");
        assert_eq!(keys.len(), 11, "no error key when found: {j}");
        assert!(j.contains("\"raw\":[[0,0],[1,1],[2,1]]"), "{j}");
        assert!(j.contains("\"raw_length\":2.4142137"), "{j}");
        assert_eq!(serde_json::from_str::<PlanReport>(&j).unwrap(), report());
    }

    #[test]
    fn located_report_appends_metres() {
        let r = report();
        let plain = LocatedReport {
            report: &r,
            waypoints_m: None,
        };
        assert_eq!(plain.to_json(), r.to_json());
        let m = [[0.025, 1.5], [-2.0, 0.0]];
        let j = LocatedReport {
            report: &r,
            waypoints_m: Some(&m),
        }
        .to_json();
        assert!(j.starts_with(&r.to_json()[..r.to_json().len() - 1]), "{j}");
        assert!(
            j.ends_with(",\"waypoints_m\":[[0.025,1.5],[-2.0,0.0]]}"),
            "{j}"
        );
        let back: PlanReport = serde_json::from_str(&j).unwrap();
        assert_eq!(back, r);
    }

    #[test]
    fn csv_waypoints() {
        assert_eq!(waypoints_csv(&[[0, 0], [2, 1]], None), "x,y\n0,0\n2,1\n");
        assert_eq!(
            waypoints_csv(&[[0, 0]], Some(&[[0.5, -1.25]])),
            "x_m,y_m\n0.5,-1.25\n"
        );
        assert_eq!(waypoints_csv(&[], None), "x,y\n");
    }

    #[test]
    fn params_by_name_and_back() {
        let p = Params::default();
        let j = serde_json::to_value(p).unwrap();
        assert_eq!(j["algorithm"], "ohaca");
        assert_eq!(j["dead_end"], "backtrack");
        assert_eq!(j["smoothing"], "shortest");
        assert_eq!(j["rho"].as_f64().unwrap() as f32, 0.1);
        assert_eq!(serde_json::from_value::<Params>(j).unwrap(), p);
        // The derive's names are the core's names (which the flags and messages use).
        let name = |v: serde_json::Value| v.as_str().unwrap().to_string();
        for a in Algorithm::ALL {
            assert_eq!(name(serde_json::to_value(a).unwrap()), a.name());
        }
        for d in DeadEnd::ALL {
            assert_eq!(name(serde_json::to_value(d).unwrap()), d.name());
        }
        for k in SmoothingKind::ALL {
            assert_eq!(name(serde_json::to_value(k).unwrap()), k.name());
        }
        assert!(serde_json::from_str::<Algorithm>("\"bee\"").is_err());
    }

    #[test]
    fn not_found_has_error_and_nulls() {
        let r = PlanReport::not_found(
            &Params::default(),
            ohaca::Error::NoPath,
            Some(0),
            Duration::from_micros(7),
        );
        let v: serde_json::Value = serde_json::from_str(&r.to_json()).unwrap();
        assert_eq!(v["found"], false);
        assert_eq!(v["raw"], serde_json::json!([]));
        assert!(v["length"].is_null());
        assert_eq!(v["iterations"], 0);
        assert_eq!(v["elapsed_us"], 7);
        assert_eq!(
            v["error"],
            "no path: the goal is not reachable from the start"
        );
    }

    #[test]
    fn draws_marks_over_the_map() {
        let map = Map::parse("...\n.#.\n", "t", Format::Text).unwrap();
        let r = report();
        let pic = picture(
            &map,
            Point::new(0, 0),
            Point::new(2, 1),
            &r.raw,
            &r.waypoints,
        );
        assert_eq!(pic, "S . .\n. * G\n");
        // Out-of-map points are ignored.
        let pic = picture(&map, Point::new(9, 9), Point::new(2, 0), &[[5, 5]], &[]);
        assert_eq!(pic, ". . G\n. # .\n");
        let all = render(&map, Point::new(0, 0), Point::new(2, 1), &r);
        assert!(all.starts_with(LEGEND));
        assert!(all.contains("raw length 2.414   waypoint path 2.236 (2 waypoints)   0 turns"));
        assert!(all.contains("3 iterations (best found in iteration 1)"));
        assert!(all.contains("1.500 ms"));
    }
}
