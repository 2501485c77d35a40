//! Maps and scenarios: a small Moving AI loader, ASCII maps for tests, and the shared benchmark
//! scenarios of `maps/README.md`.
//!
//! **`.map`** (Moving AI): header lines `type octile`, `height H`, `width W`, `map`, then `H` rows
//! of `W` characters. `.`, `G` and `S` are free; every other character (`@`, `O`, `T`, `W`, ...)
//! is blocked. `(0, 0)` is the first character of the first row, `x` grows to the right and `y`
//! downwards, as in the core.
//!
//! **`.scen`**: a `version 1` line, then one tab-separated line per scenario:
//! `bucket map width height sx sy gx gy optimal`.
//!
//! [`Map`] keeps the cells both as booleans (for the references, which never look at the core's
//! bit layout) and as the core's row-major, LSB-first bit buffer (for [`Map::grid`]).

use std::fmt;
use std::path::{Path, PathBuf};

use ohaca::{Grid, Point};

/// An occupancy map owned on the heap.
#[derive(Clone, PartialEq, Eq)]
pub struct Map {
    width: u16,
    height: u16,
    blocked: Vec<bool>,
    bits: Vec<u8>,
}

impl fmt::Debug for Map {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "Map {}x{}:", self.width, self.height)?;
        f.write_str(&self.to_ascii())
    }
}

impl Map {
    /// A map of `width x height` cells; `blocked[y * width + x]` is true for an obstacle.
    ///
    /// # Panics
    /// If a side is zero or `blocked` has the wrong length.
    pub fn new(width: u16, height: u16, blocked: Vec<bool>) -> Map {
        assert!(width > 0 && height > 0, "empty map");
        assert_eq!(
            blocked.len(),
            usize::from(width) * usize::from(height),
            "cell count"
        );
        let mut bits = vec![0u8; ohaca::map::bits::bytes(blocked.len())];
        for (i, _) in blocked.iter().enumerate().filter(|(_, b)| **b) {
            ohaca::map::bits::set(&mut bits, i, true);
        }
        Map {
            width,
            height,
            blocked,
            bits,
        }
    }

    /// An obstacle-free map.
    pub fn empty(width: u16, height: u16) -> Map {
        Map::new(
            width,
            height,
            vec![false; usize::from(width) * usize::from(height)],
        )
    }

    /// A map from ASCII rows: `#` and `@` are blocked, anything else is free. All rows must have
    /// the same length.
    ///
    /// # Panics
    /// On ragged or empty rows.
    pub fn from_rows(rows: &[&str]) -> Map {
        let h = rows.len();
        let w = rows.first().map_or(0, |r| r.chars().count());
        let mut blocked = Vec::with_capacity(w * h);
        for r in rows {
            assert_eq!(r.chars().count(), w, "ragged map rows");
            blocked.extend(r.chars().map(|c| c == '#' || c == '@'));
        }
        Map::new(to_u16(w), to_u16(h), blocked)
    }

    /// Parse a Moving AI `.map` file's text.
    pub fn parse(text: &str) -> Result<Map, String> {
        let mut lines = text.lines();
        let (mut width, mut height) = (None, None);
        loop {
            let line = lines.next().ok_or("missing `map` line")?.trim();
            let mut words = line.split_whitespace();
            match (words.next(), words.next()) {
                (Some("map"), None) => break,
                (Some("type"), Some(_)) => {}
                (Some("height"), Some(v)) => height = Some(parse_num::<u16>(v, "height")?),
                (Some("width"), Some(v)) => width = Some(parse_num::<u16>(v, "width")?),
                (None, _) => {}
                _ => return Err(format!("unexpected header line {line:?}")),
            }
        }
        let (w, h) = (
            width.ok_or("missing width")?,
            height.ok_or("missing height")?,
        );
        if w == 0 || h == 0 {
            return Err("zero-sized map".into());
        }
        let mut blocked = Vec::with_capacity(usize::from(w) * usize::from(h));
        for y in 0..h {
            let row = lines
                .next()
                .ok_or_else(|| format!("missing row {y}"))?
                .trim_end_matches('\r');
            if row.chars().count() != usize::from(w) {
                return Err(format!(
                    "row {y} has {} characters, expected {w}",
                    row.chars().count()
                ));
            }
            blocked.extend(row.chars().map(|c| !matches!(c, '.' | 'G' | 'S')));
        }
        Ok(Map::new(w, h, blocked))
    }

    /// Load a Moving AI `.map` file.
    pub fn load(path: impl AsRef<Path>) -> Result<Map, String> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
        Map::parse(&text).map_err(|e| format!("{}: {e}", path.display()))
    }

    /// Columns.
    pub fn width(&self) -> u16 {
        self.width
    }

    /// Rows.
    pub fn height(&self) -> u16 {
        self.height
    }

    /// `width * height`.
    pub fn cells(&self) -> usize {
        self.blocked.len()
    }

    /// Row-major index of an in-map point.
    pub fn index(&self, p: Point) -> usize {
        usize::from(p.y) * usize::from(self.width) + usize::from(p.x)
    }

    /// The point with row-major index `i`.
    pub fn point(&self, i: usize) -> Point {
        let w = usize::from(self.width);
        Point::new(to_u16(i % w), to_u16(i / w))
    }

    /// True if `(x, y)` is inside the map and free. Signed, so callers may ask beyond the border.
    pub fn free(&self, x: i64, y: i64) -> bool {
        x >= 0
            && y >= 0
            && x < i64::from(self.width)
            && y < i64::from(self.height)
            && !self.blocked[(y as usize) * usize::from(self.width) + x as usize]
    }

    /// True if `p` is inside the map and free.
    pub fn is_free(&self, p: Point) -> bool {
        self.free(i64::from(p.x), i64::from(p.y))
    }

    /// True if `p` is inside the map.
    pub fn contains(&self, p: Point) -> bool {
        p.x < self.width && p.y < self.height
    }

    /// Set cell `p` blocked or free.
    pub fn set(&mut self, p: Point, blocked: bool) {
        let i = self.index(p);
        self.blocked[i] = blocked;
        ohaca::map::bits::set(&mut self.bits, i, blocked);
    }

    /// The cells as booleans, row-major, `true` = blocked.
    pub fn blocked(&self) -> &[bool] {
        &self.blocked
    }

    /// The core's bit buffer (row-major, LSB first, 1 = blocked).
    pub fn bits(&self) -> &[u8] {
        &self.bits
    }

    /// The core's view of this map.
    pub fn grid(&self) -> Grid<'_> {
        Grid::new(self.width, self.height, &self.bits).expect("a Map is never empty")
    }

    /// Number of blocked cells.
    pub fn obstacles(&self) -> usize {
        self.blocked.iter().filter(|b| **b).count()
    }

    /// The map as ASCII rows (`.` free, `#` blocked), one line per row.
    pub fn to_ascii(&self) -> String {
        let mut s = String::with_capacity(self.cells() + usize::from(self.height));
        for row in self.blocked.chunks(usize::from(self.width)) {
            s.extend(row.iter().map(|&b| if b { '#' } else { '.' }));
            s.push('\n');
        }
        s
    }

    /// The map as a Moving AI `.map` text.
    pub fn to_movingai(&self) -> String {
        let mut s = format!(
            "type octile\nheight {}\nwidth {}\nmap\n",
            self.height, self.width
        );
        for row in self.blocked.chunks(usize::from(self.width)) {
            s.extend(row.iter().map(|&b| if b { '@' } else { '.' }));
            s.push('\n');
        }
        s
    }
}

fn to_u16(v: usize) -> u16 {
    u16::try_from(v).expect("map dimension fits in u16")
}

fn parse_num<T: std::str::FromStr>(s: &str, what: &str) -> Result<T, String> {
    s.trim().parse().map_err(|_| format!("bad {what} {s:?}"))
}

/// One line of a `.scen` file.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenEntry {
    /// The benchmark's difficulty bucket.
    pub bucket: u32,
    /// The map file name the scenario refers to.
    pub map: String,
    /// Map width the scenario was made for.
    pub width: u16,
    /// Map height the scenario was made for.
    pub height: u16,
    /// Start cell.
    pub start: Point,
    /// Goal cell.
    pub goal: Point,
    /// Shortest 8-connected path length (no corner cutting), as written in the file.
    pub optimal: f64,
}

/// Parse a `.scen` file's text.
pub fn parse_scen(text: &str) -> Result<Vec<ScenEntry>, String> {
    let mut lines = text.lines().filter(|l| !l.trim().is_empty());
    match lines
        .next()
        .map(str::split_whitespace)
        .map(|mut w| (w.next(), w.next()))
    {
        Some((Some("version"), Some(v))) if v.starts_with('1') => {}
        other => return Err(format!("expected `version 1`, got {other:?}")),
    }
    lines
        .enumerate()
        .map(|(n, line)| {
            let f: Vec<&str> = line.trim_end_matches('\r').split('\t').collect();
            if f.len() != 9 {
                return Err(format!(
                    "scenario line {}: {} fields, expected 9",
                    n + 1,
                    f.len()
                ));
            }
            let u = |i: usize, what: &str| parse_num::<u16>(f[i], what);
            Ok(ScenEntry {
                bucket: parse_num(f[0], "bucket")?,
                map: f[1].to_string(),
                width: u(2, "width")?,
                height: u(3, "height")?,
                start: Point::new(u(4, "sx")?, u(5, "sy")?),
                goal: Point::new(u(6, "gx")?, u(7, "gy")?),
                optimal: parse_num(f[8], "optimal")?,
            })
        })
        .collect()
}

/// Load a `.scen` file.
pub fn load_scen(path: impl AsRef<Path>) -> Result<Vec<ScenEntry>, String> {
    let path = path.as_ref();
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    parse_scen(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// The repository's `maps/` directory.
pub fn maps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("..")
        .join("maps")
}

/// One start/goal pair on a shared map.
#[derive(Clone, Debug, PartialEq)]
pub struct Case {
    /// Start cell.
    pub start: Point,
    /// Goal cell.
    pub goal: Point,
    /// The 8-connected optimum the source states (the `.scen` column, or `maps/README.md`).
    pub stated_opt8: f64,
    /// The any-angle optimum `maps/README.md` states, for the fixed pairs only.
    pub stated_any_angle: Option<f64>,
}

/// A shared map and the start/goal pairs it is benchmarked on.
#[derive(Clone, Debug)]
pub struct MapScenarios {
    /// Short name, e.g. `simple-18` or `random-32-32-10`.
    pub name: String,
    /// The map.
    pub map: Map,
    /// Its start/goal pairs.
    pub cases: Vec<Case>,
}

/// The `n` scenarios of largest `optimal` (a stable sort: equal `optimal` keep file order) as
/// cases with their stated 8-connected optimum.
pub fn longest(mut entries: Vec<ScenEntry>, n: usize) -> Vec<Case> {
    entries.sort_by(|a, b| b.optimal.total_cmp(&a.optimal));
    entries.truncate(n);
    entries
        .into_iter()
        .map(|e| Case {
            start: e.start,
            goal: e.goal,
            stated_opt8: e.optimal,
            stated_any_angle: None,
        })
        .collect()
}

/// How many `.scen` scenarios [`scenarios`] takes from each Moving AI map.
pub const SCEN_PER_MAP: usize = 20;

/// `(file, start, goal, 8-connected optimum, any-angle optimum)` of a fixed pair.
pub type FixedPair = (&'static str, (u16, u16), (u16, u16), f64, f64);

/// The fixed maps and their start/goal pairs and optima, from `maps/README.md`:
/// `(file, start, goal, 8-connected optimum, any-angle optimum)`.
pub const FIXED: [FixedPair; 3] = [
    ("simple-18", (0, 0), (17, 17), 26.9706, 24.9541),
    ("complex-26", (0, 0), (25, 25), 41.7990, 39.1470),
    ("classic-20", (0, 0), (19, 19), 37.8995, 36.8518),
];

/// The Moving AI maps and their scenario files, relative to `maps/`.
pub const MOVINGAI: [(&str, &str); 2] = [
    ("random-32-32-10", "movingai/random-32-32-10-random-1.scen"),
    ("random-32-32-20", "movingai/random-32-32-20-random-1.scen"),
];

/// Every shared map with its scenarios: the three fixed maps with the start/goal of
/// `maps/README.md`, then the two Moving AI maps, each with the [`SCEN_PER_MAP`] scenarios of
/// largest `optimal` (ties keep file order).
///
/// # Panics
/// If a file is missing or malformed (these are the repository's own files).
pub fn scenarios() -> Vec<MapScenarios> {
    let dir = maps_dir();
    let mut out = Vec::new();
    for (name, s, g, opt8, any) in FIXED {
        let map = Map::load(dir.join(format!("{name}.map"))).unwrap_or_else(|e| panic!("{e}"));
        out.push(MapScenarios {
            name: name.to_string(),
            map,
            cases: vec![Case {
                start: Point::new(s.0, s.1),
                goal: Point::new(g.0, g.1),
                stated_opt8: opt8,
                stated_any_angle: Some(any),
            }],
        });
    }
    for (name, scen) in MOVINGAI {
        let map =
            Map::load(dir.join(format!("movingai/{name}.map"))).unwrap_or_else(|e| panic!("{e}"));
        let entries = load_scen(dir.join(scen)).unwrap_or_else(|e| panic!("{e}"));
        for e in &entries {
            assert_eq!(e.map, format!("{name}.map"), "scenario for another map");
            assert_eq!((e.width, e.height), (map.width(), map.height()));
        }
        out.push(MapScenarios {
            name: name.to_string(),
            map,
            cases: longest(entries, SCEN_PER_MAP),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_header_variants_and_rows() {
        let m = Map::parse("type octile\r\nheight 2\r\nwidth 3\r\nmap\r\n.@T\r\nGS.\r\n").unwrap();
        assert_eq!((m.width(), m.height()), (3, 2));
        assert!(m.free(0, 0) && !m.free(1, 0) && !m.free(2, 0));
        assert!(m.free(0, 1) && m.free(1, 1) && m.free(2, 1));
        assert!(!m.free(-1, 0) && !m.free(3, 0) && !m.free(0, 2));
        // The bit layout: cells 1 and 2 blocked.
        assert_eq!(m.bits(), &[0b0000_0110]);
        assert!(Map::parse("type octile\nheight 2\nwidth 3\nmap\n...\n").is_err());
        assert!(Map::parse("type octile\nheight 1\nwidth 3\nmap\n....\n").is_err());
    }

    #[test]
    fn grid_agrees_with_map() {
        let m = Map::from_rows(&["..#..", "#...#", "..@.."]);
        let g = m.grid();
        for i in 0..m.cells() {
            assert_eq!(g.is_free(m.point(i)), m.is_free(m.point(i)));
        }
        let mut m2 = m.clone();
        m2.set(Point::new(2, 0), false);
        m2.set(Point::new(0, 0), true);
        assert!(m2.grid().is_free(Point::new(2, 0)));
        assert!(!m2.grid().is_free(Point::new(0, 0)));
        assert_eq!(Map::parse(&m.to_movingai()).unwrap(), m);
    }

    #[test]
    fn scen_parsing() {
        let t = "version 1\n3\tx.map\t32\t32\t11\t6\t7\t18\t13.65685425\n";
        let s = parse_scen(t).unwrap();
        assert_eq!(s.len(), 1);
        assert_eq!(s[0].start, Point::new(11, 6));
        assert_eq!(s[0].goal, Point::new(7, 18));
        assert!((s[0].optimal - 13.65685425).abs() < 1e-12);
        assert!(parse_scen("version 2\n").is_err());
        assert!(parse_scen("version 1\n1\t2\n").is_err());
    }

    #[test]
    fn shared_scenarios_load() {
        let all = scenarios();
        assert_eq!(all.len(), 5);
        let counts: Vec<usize> = all.iter().map(|m| m.cases.len()).collect();
        assert_eq!(counts, [1, 1, 1, SCEN_PER_MAP, SCEN_PER_MAP]);
        for m in &all {
            for c in &m.cases {
                assert!(
                    m.map.is_free(c.start) && m.map.is_free(c.goal),
                    "{}",
                    m.name
                );
            }
            // Largest first.
            for w in m.cases.windows(2) {
                assert!(w[0].stated_opt8 >= w[1].stated_opt8);
            }
        }
    }
}
