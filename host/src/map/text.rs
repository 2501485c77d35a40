//! The two text formats: Moving AI `.map` files and plain text grids, parsed into a [`Map`].
//!
//! Two formats, detected by content (a first line `type ...` means Moving AI) or else by the
//! file extension (`.map` means Moving AI, anything else a text grid):
//!
//! - **Moving AI** (`maps/README.md`): the header lines `type octile`, `height H`, `width W`
//!   (height and width in either order), `map`, then `H` rows of `W` characters. `.`, `G` and `S`
//!   are free; every other character (`@`, `O`, `T`, `W`, ...) is blocked.
//! - **Text grid**: one row per line, all rows of equal length; `.` or `0` is free, `#` or `1` is
//!   blocked, anything else is an error.
//!
//! In both, `x` is the column and `y` the row counted from the top, `(0, 0)` is the first
//! character of the first row (the core's convention, [`ohaca::grid`]). Line endings may be `\n`
//! or `\r\n`, blank lines at the end are ignored, and a UTF-8 byte-order mark is skipped. Sides
//! must be 1..=65535 cells.
//!
//! Errors are a [`MapError`] whose `Display` is one line naming the file, the line number and the
//! problem, e.g. `maps/x.map, line 7: row 3 has 25 cells, expected 26`.
//!
//! Nothing is allocated from header values alone: the rows are checked against the header before
//! the bit buffer is built, so a small file claiming a huge map fails cleanly.

use std::path::Path;

use super::bitmap::{Map, MAX_SIDE};
use super::error::{MapError, Problem};

/// The two map file formats. See the module docs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// Moving AI `.map`: a `type octile` header, then the rows.
    MovingAi,
    /// Plain text grid: `.`/`0` free, `#`/`1` blocked.
    Text,
}

impl Format {
    /// The format of `text`: Moving AI if its first line is `type ...`, else Moving AI if `path`
    /// ends in `.map` (case-insensitive), else a text grid.
    pub fn detect(text: &str, path: Option<&Path>) -> Format {
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let first = text.lines().next().unwrap_or("");
        if first.split_whitespace().next() == Some("type") {
            return Format::MovingAi;
        }
        let is_map = path
            .and_then(Path::extension)
            .is_some_and(|e| e.eq_ignore_ascii_case("map"));
        if is_map {
            Format::MovingAi
        } else {
            Format::Text
        }
    }
}

impl Map {
    /// Read a Moving AI or text-grid file, detecting which with [`Format::detect`].
    pub fn read_text(path: &Path) -> Result<Map, MapError> {
        let name = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|source| MapError::Unreadable {
            path: name.clone(),
            source,
        })?;
        // Invalid UTF-8 becomes U+FFFD: blocked in Moving AI rows, an unknown character in text
        // grids, a wrong header elsewhere — always a message with a line number.
        let text = String::from_utf8_lossy(&bytes);
        Map::parse(&text, &name, Format::detect(&text, Some(path)))
    }

    /// Parse map text in the given format; `name` stands for the file in error messages.
    pub fn parse(text: &str, name: &str, format: Format) -> Result<Map, MapError> {
        let lines = content_lines(text);
        let err = |line: usize, problem: Problem| MapError::Parse {
            path: name.to_string(),
            line,
            problem,
        };
        match format {
            Format::MovingAi => parse_moving_ai(&lines).map_err(|(l, p)| err(l, p)),
            Format::Text => parse_text(&lines).map_err(|(l, p)| err(l, p)),
        }
    }
}

/// A parse failure before the file name is attached: (1-based line, problem).
type Failure = (usize, Problem);

/// The lines of `text` without line endings (`\n` or `\r\n`), without a leading byte-order mark
/// and without trailing blank lines.
fn content_lines(text: &str) -> Vec<&str> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut lines: Vec<&str> = text
        .lines()
        .map(|l| l.strip_suffix('\r').unwrap_or(l))
        .collect();
    while lines.last().is_some_and(|l| l.trim().is_empty()) {
        lines.pop();
    }
    lines
}

/// Parse a side from a header value: digits only, 1..=65535.
fn side(
    value: &str,
    name: &'static str,
    expected: &'static str,
    line: &str,
) -> Result<u16, Problem> {
    if value.is_empty() || !value.bytes().all(|b| b.is_ascii_digit()) {
        return Err(Problem::WrongHeader {
            expected,
            found: line.trim().to_string(),
        });
    }
    match value.parse::<u64>() {
        Ok(0) => Err(Problem::ZeroSide { side: name }),
        Ok(v) => u16::try_from(v).map_err(|_| Problem::TooLarge {
            side: name,
            value: value.to_string(),
        }),
        // All digits but does not fit in u64: certainly too large.
        Err(_) => Err(Problem::TooLarge {
            side: name,
            value: value.to_string(),
        }),
    }
}

fn parse_moving_ai(lines: &[&str]) -> Result<Map, Failure> {
    let mut it = lines.iter().copied().enumerate().map(|(i, l)| (i + 1, l));
    let eof = lines.len() + 1;
    let wrong = |expected: &'static str, line: &str| Problem::WrongHeader {
        expected,
        found: line.trim().to_string(),
    };

    const TYPE: &str = "type octile";
    let (ln, l) = it
        .next()
        .ok_or((1, Problem::TruncatedHeader { expected: TYPE }))?;
    if l.split_whitespace().ne(TYPE.split_whitespace()) {
        return Err((ln, wrong(TYPE, l)));
    }

    let (mut height, mut width) = (None, None);
    while height.is_none() || width.is_none() {
        const H: &str = "height <rows>";
        const W: &str = "width <columns>";
        let expected = if height.is_none() { H } else { W };
        let (ln, l) = it
            .next()
            .ok_or((eof, Problem::TruncatedHeader { expected }))?;
        let mut toks = l.split_whitespace();
        match (toks.next(), toks.next(), toks.next()) {
            (Some("height"), Some(v), None) if height.is_none() => {
                height = Some(side(v, "height", H, l).map_err(|p| (ln, p))?);
            }
            (Some("width"), Some(v), None) if width.is_none() => {
                width = Some(side(v, "width", W, l).map_err(|p| (ln, p))?);
            }
            _ => return Err((ln, wrong(expected, l))),
        }
    }
    let (Some(height), Some(width)) = (height, width) else {
        return Err((
            eof,
            Problem::TruncatedHeader {
                expected: "height <rows>",
            },
        ));
    };

    const MAP: &str = "map";
    let (ln, l) = it
        .next()
        .ok_or((eof, Problem::TruncatedHeader { expected: MAP }))?;
    if l.trim() != MAP {
        return Err((ln, wrong(MAP, l)));
    }

    let h = usize::from(height);
    let rows: Vec<(usize, &str)> = it.by_ref().take(h).collect();
    if rows.len() < h {
        return Err((
            eof,
            Problem::TruncatedRows {
                expected: h,
                found: rows.len(),
            },
        ));
    }
    if let Some((ln, _)) = it.next() {
        return Err((ln, Problem::ExtraRow { height: h }));
    }
    build(&rows, width, |_, c| Ok(!matches!(c, '.' | 'G' | 'S')))
}

fn parse_text(lines: &[&str]) -> Result<Map, Failure> {
    let Some(first) = lines.first() else {
        return Err((1, Problem::Empty));
    };
    if lines.len() > MAX_SIDE {
        return Err((
            MAX_SIDE + 1,
            Problem::TooLarge {
                side: "height",
                value: lines.len().to_string(),
            },
        ));
    }
    let w = first.chars().count();
    let width = u16::try_from(w).map_err(|_| {
        (
            1,
            Problem::TooLarge {
                side: "width",
                value: w.to_string(),
            },
        )
    })?;
    let rows: Vec<(usize, &str)> = lines
        .iter()
        .copied()
        .enumerate()
        .map(|(i, l)| (i + 1, l))
        .collect();
    if let Some((ln, _)) = rows.iter().find(|(_, l)| l.trim().is_empty()) {
        return Err((*ln, Problem::BlankLine));
    }
    build(&rows, width, |column, c| match c {
        '.' | '0' => Ok(false),
        '#' | '1' => Ok(true),
        ch => Err(Problem::UnknownChar { ch, column }),
    })
}

/// Check every row's length, then build the bits. `classify(column, char)` says whether a cell
/// is blocked (`column` is 1-based).
fn build(
    rows: &[(usize, &str)],
    width: u16,
    classify: impl Fn(usize, char) -> Result<bool, Problem>,
) -> Result<Map, Failure> {
    let w = usize::from(width);
    for (row, (ln, l)) in rows.iter().enumerate() {
        let found = l.chars().count();
        if found != w {
            return Err((
                *ln,
                Problem::RowLength {
                    row: row + 1,
                    expected: w,
                    found,
                },
            ));
        }
    }
    let height = u16::try_from(rows.len()).map_err(|_| {
        (
            MAX_SIDE + 1,
            Problem::TooLarge {
                side: "height",
                value: rows.len().to_string(),
            },
        )
    })?;
    let mut bits = vec![0u8; ohaca::map::bits::bytes(w * rows.len())];
    for (y, (ln, l)) in rows.iter().enumerate() {
        for (x, c) in l.chars().enumerate() {
            if classify(x + 1, c).map_err(|p| (*ln, p))? {
                ohaca::map::bits::set(&mut bits, y * w + x, true);
            }
        }
    }
    Ok(Map {
        width,
        height,
        bits,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use ohaca::Point;

    fn text(s: &str) -> Result<Map, MapError> {
        Map::parse(s, "t.txt", Format::Text)
    }
    fn mai(s: &str) -> Result<Map, MapError> {
        Map::parse(s, "t.map", Format::MovingAi)
    }
    fn problem(r: Result<Map, MapError>) -> (usize, Problem) {
        match r.unwrap_err() {
            MapError::Parse { line, problem, .. } => (line, problem),
            e => panic!("unexpected {e}"),
        }
    }

    #[test]
    fn text_grid_layout() {
        let m = text("..#\n1.0\n\n\n").unwrap();
        assert_eq!((m.width, m.height), (3, 2));
        assert!(m.is_blocked(Point::new(2, 0)));
        assert!(m.is_blocked(Point::new(0, 1)));
        assert!(!m.is_blocked(Point::new(1, 1)));
        assert!(!m.is_blocked(Point::new(2, 1)));
        assert!(m.is_blocked(Point::new(3, 0)), "outside counts as blocked");
        // bit i = cell (i % w, i / w), LSB first
        assert_eq!(m.bits, vec![0b0000_1100]);
        let g = m.grid().unwrap();
        assert!(!g.is_free(Point::new(2, 0)));
        assert!(g.is_free(Point::new(1, 0)));
    }

    #[test]
    fn crlf_and_bom() {
        let m = text("\u{feff}.#\r\n#.\r\n").unwrap();
        assert_eq!(m.bits, vec![0b0110]);
        let m = mai("type octile\r\nheight 1\r\nwidth 2\r\nmap\r\n.@\r\n").unwrap();
        assert_eq!(m.bits, vec![0b10]);
    }

    #[test]
    fn moving_ai_layout() {
        let m = mai("type octile\nwidth 4\nheight 2\nmap\n.GS@\nOTW.\n").unwrap();
        assert_eq!((m.width, m.height), (4, 2));
        assert_eq!(m.bits, vec![0b0111_1000]);
    }

    #[test]
    fn round_trips() {
        let m = Map::from_fn(13, 5, |x, y| (x * 7 + y * 3) % 5 == 0);
        assert_eq!(text(&m.to_text()).unwrap(), m);
        assert_eq!(mai(&m.to_moving_ai()).unwrap(), m);
    }

    #[test]
    fn detect() {
        fn p(s: &str) -> Option<&Path> {
            Some(Path::new(s))
        }
        assert_eq!(
            Format::detect("type octile\n", p("a.txt")),
            Format::MovingAi
        );
        assert_eq!(Format::detect("..\n", p("a.MAP")), Format::MovingAi);
        assert_eq!(Format::detect("..\n", p("a.txt")), Format::Text);
        assert_eq!(Format::detect("..\n", None), Format::Text);
        assert_eq!(Format::detect("typewriter\n", None), Format::Text);
    }

    #[test]
    fn moving_ai_errors() {
        let cases: &[(&str, usize, Problem)] = &[
            (
                "",
                1,
                Problem::TruncatedHeader {
                    expected: "type octile",
                },
            ),
            (
                "type tile\n",
                1,
                Problem::WrongHeader {
                    expected: "type octile",
                    found: "type tile".into(),
                },
            ),
            (
                "type octile\nheight 2\n",
                3,
                Problem::TruncatedHeader {
                    expected: "width <columns>",
                },
            ),
            (
                "type octile\nheight x\nwidth 2\nmap\n",
                2,
                Problem::WrongHeader {
                    expected: "height <rows>",
                    found: "height x".into(),
                },
            ),
            (
                "type octile\nheight 2\nheight 2\n",
                3,
                Problem::WrongHeader {
                    expected: "width <columns>",
                    found: "height 2".into(),
                },
            ),
            (
                "type octile\nheight 0\nwidth 2\nmap\n",
                2,
                Problem::ZeroSide { side: "height" },
            ),
            (
                "type octile\nheight 2\nwidth 70000\nmap\n",
                3,
                Problem::TooLarge {
                    side: "width",
                    value: "70000".into(),
                },
            ),
            (
                "type octile\nheight 2\nwidth 99999999999999999999999\nmap\n",
                3,
                Problem::TooLarge {
                    side: "width",
                    value: "99999999999999999999999".into(),
                },
            ),
            (
                "type octile\nheight 2\nwidth 2\nmap2\n",
                4,
                Problem::WrongHeader {
                    expected: "map",
                    found: "map2".into(),
                },
            ),
            (
                "type octile\nheight 3\nwidth 2\nmap\n..\n..\n\n",
                7,
                Problem::TruncatedRows {
                    expected: 3,
                    found: 2,
                },
            ),
            (
                "type octile\nheight 2\nwidth 2\nmap\n..\n...\n",
                6,
                Problem::RowLength {
                    row: 2,
                    expected: 2,
                    found: 3,
                },
            ),
            (
                "type octile\nheight 1\nwidth 2\nmap\n..\n..\n",
                6,
                Problem::ExtraRow { height: 1 },
            ),
            (
                "type octile\nheight 65535\nwidth 65535\nmap\n..\n",
                6,
                Problem::TruncatedRows {
                    expected: 65535,
                    found: 1,
                },
            ),
        ];
        for (src, line, p) in cases {
            assert_eq!(problem(mai(src)), (*line, p.clone()), "{src:?}");
        }
    }

    #[test]
    fn text_errors() {
        let cases: &[(&str, usize, Problem)] = &[
            ("", 1, Problem::Empty),
            ("\n\n", 1, Problem::Empty),
            (
                "..\n.\n",
                2,
                Problem::RowLength {
                    row: 2,
                    expected: 2,
                    found: 1,
                },
            ),
            ("..\n\n..\n", 2, Problem::BlankLine),
            ("\n..\n", 1, Problem::BlankLine),
            ("..\n.x\n", 2, Problem::UnknownChar { ch: 'x', column: 2 }),
            (". \n..\n", 1, Problem::UnknownChar { ch: ' ', column: 2 }),
        ];
        for (src, line, p) in cases {
            assert_eq!(problem(text(src)), (*line, p.clone()), "{src:?}");
        }
        let wide = ".".repeat(70_000);
        assert_eq!(
            problem(text(&wide)),
            (
                1,
                Problem::TooLarge {
                    side: "width",
                    value: "70000".into()
                }
            )
        );
        let tall = ".\n".repeat(70_000);
        assert_eq!(
            problem(text(&tall)).1,
            Problem::TooLarge {
                side: "height",
                value: "70000".into()
            }
        );
    }

    #[test]
    fn display_names_file_line_and_problem() {
        let e = mai("type octile\nheight 2\nwidth 2\nmap\n..\n...\n").unwrap_err();
        assert_eq!(
            e.to_string(),
            "t.map, line 6: row 2 has 3 cells, expected 2"
        );
        assert_eq!(e.line(), Some(6));
        let e = Map::load("/nonexistent/dir/x.map").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("/nonexistent/dir/x.map: cannot read the file: "),
            "{e}"
        );
        assert!(e.problem().is_none());
    }

    #[test]
    fn hand_built_bad_map_is_rejected_by_grid() {
        let m = Map {
            width: 10,
            height: 10,
            bits: vec![0; 3],
        };
        assert_eq!(m.grid().unwrap_err(), ohaca::Error::BadMap);
        assert!(m.is_blocked(Point::new(9, 9)));
    }
}
