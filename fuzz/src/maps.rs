//! The `map_parsers` target: the host tool's map readers (`host/src/map/`: text formats, ROS,
//! images), fed from memory.
//!
//! Input layout: the first byte picks the reader, the rest is the file. The seeds use the
//! letters; any other byte picks by `byte % 5` (0 to 4 in the table's order).
//!
//! | first byte | reader | rest of the input |
//! | --- | --- | --- |
//! | `M` | Moving AI `.map` ([`Format::MovingAi`]) | the file |
//! | `T` | text grid ([`Format::Text`]) | the file |
//! | `A`, `a` | auto-detected as [`Map::load`] does, for a file named `x.txt` (`A`) or `x.map` (`a`) | the file |
//! | `R`, `r` | ROS `map_server` YAML + image ([`RosMeta::parse`], [`ros_map`]); unknown cells blocked (`R`) or free (`r`) | YAML, `0x00`, image |
//! | `I` | plain PNG/PGM image ([`decode_image`], [`image_map`]) | the image |
//!
//! Text is read as `Map::load` reads it (invalid UTF-8 becomes U+FFFD); the YAML as `load_ros`
//! does (invalid UTF-8 is an error). Checked besides "never panics": a parsed map has sides
//! 1..=65535, `ceil(width * height / 8)` bytes, no stray bits past the last cell, a valid
//! [`ohaca::Grid`], exactly the cells its rows say (an independent reading of the rows), and it
//! survives `to_text` / `to_moving_ai` and parsing back; a ROS map's frame has the map's sides and
//! maps each corner cell to metres and back.

use std::path::Path;

use ohaca::Point;
use ohaca_host::map::{decode_image, image_map, ros_map, Mode, RosMeta, Unknown};
use ohaca_host::map::{Format, Map};

/// The lines a map file consists of: byte-order mark skipped, `\n` or `\r\n` endings, blank lines
/// at the end ignored (the documented rules, read independently of the parser).
fn rows_of(text: &str) -> Vec<&str> {
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

/// Invariants of every map a loader returns.
fn check_map(map: &Map) {
    assert!(
        map.width > 0 && map.height > 0,
        "{}x{}",
        map.width,
        map.height
    );
    let cells = usize::from(map.width) * usize::from(map.height);
    assert_eq!(map.cells(), cells);
    assert_eq!(map.bits.len(), cells.div_ceil(8), "bit buffer size");
    if cells % 8 != 0 {
        let last = map.bits[map.bits.len() - 1];
        assert_eq!(last >> (cells % 8), 0, "bits set past the last cell");
    }
    let grid = map.grid().expect("a loaded map is a valid grid");
    assert_eq!(grid.cells(), cells);
    for (x, y) in [(0, 0), (map.width - 1, map.height - 1)] {
        let p = Point::new(x, y);
        assert_eq!(grid.is_free(p), !map.is_blocked(p));
    }
    // Writing it out and reading it back gives the same map.
    let text = Map::parse(&map.to_text(), "back.txt", Format::Text).expect("to_text reads back");
    assert_eq!(&text, map, "to_text round trip");
    let mai = Map::parse(&map.to_moving_ai(), "back.map", Format::MovingAi)
        .expect("to_moving_ai reads back");
    assert_eq!(&mai, map, "to_moving_ai round trip");
}

/// The map must hold exactly the cells of `rows`: `blocked(c)` for each character.
fn check_rows(map: &Map, rows: &[&str], blocked: impl Fn(char) -> bool) {
    assert_eq!(rows.len(), usize::from(map.height), "rows vs height");
    for (y, row) in rows.iter().enumerate() {
        assert_eq!(
            row.chars().count(),
            usize::from(map.width),
            "row {y} vs width"
        );
        for (x, c) in row.chars().enumerate() {
            // Both fit in u16: the sides do.
            let p = Point::new(x as u16, y as u16);
            assert_eq!(map.is_blocked(p), blocked(c), "cell ({x}, {y}) = {c:?}");
        }
    }
}

fn moving_ai_blocked(c: char) -> bool {
    !matches!(c, '.' | 'G' | 'S')
}

fn text_blocked(c: char) -> bool {
    match c {
        '.' | '0' => false,
        '#' | '1' => true,
        _ => panic!("text grid accepted {c:?}"),
    }
}

fn grid_file(text: &str, format: Format) -> bool {
    let Ok(map) = Map::parse(text, "fuzz", format) else {
        return false;
    };
    check_map(&map);
    let rows = rows_of(text);
    match format {
        Format::MovingAi => {
            // Four header lines (type, height, width in either order, map), then the rows.
            let header = rows.get(..4).expect("a Moving AI map has its header");
            assert!(header[0].split_whitespace().eq(["type", "octile"]));
            assert_eq!(header[3].trim(), "map");
            check_rows(&map, &rows[4..], moving_ai_blocked);
        }
        Format::Text => check_rows(&map, &rows, text_blocked),
    }
    true
}

/// The `map_parsers` fuzz target.
pub fn fuzz_map_parsers(data: &[u8]) {
    check_map_input(data);
}

/// Check one input (layout in the module docs); returns whether a map was loaded.
pub fn check_map_input(data: &[u8]) -> bool {
    let Some((&sel, rest)) = data.split_first() else {
        return false;
    };
    let pick = match sel {
        b'M' => 0,
        b'T' => 1,
        b'A' | b'a' => 2,
        b'R' | b'r' => 3,
        b'I' => 4,
        b => b % 5,
    };
    // The variant bit: lower case letters, or the top bit of other bytes.
    let alt = sel.is_ascii_lowercase() || (!sel.is_ascii_alphabetic() && sel & 0x80 != 0);
    match pick {
        0 => grid_file(&String::from_utf8_lossy(rest), Format::MovingAi),
        1 => grid_file(&String::from_utf8_lossy(rest), Format::Text),
        2 => {
            let text = String::from_utf8_lossy(rest);
            let name = if alt { "x.map" } else { "x.txt" };
            let format = Format::detect(&text, Some(Path::new(name)));
            grid_file(&text, format)
        }
        3 => {
            let (yaml, image) = match rest.iter().position(|&b| b == 0) {
                Some(i) => (&rest[..i], &rest[i + 1..]),
                None => (rest, &[][..]),
            };
            let unknown = if alt { Unknown::Free } else { Unknown::Blocked };
            ros(yaml, image, unknown)
        }
        _ => {
            let Ok(img) = decode_image(rest, "fuzz.png") else {
                return false;
            };
            let map = image_map(&img);
            assert_eq!(
                (u32::from(map.width), u32::from(map.height)),
                img.dimensions()
            );
            check_map(&map);
            true
        }
    }
}

fn ros(yaml: &[u8], image: &[u8], unknown: Unknown) -> bool {
    let Ok(text) = std::str::from_utf8(yaml) else {
        return false;
    };
    let Ok(meta) = RosMeta::parse(text, Path::new("/fuzz/lab.yaml")) else {
        return false;
    };
    // What the parser promises about the fields.
    assert!(meta.resolution.is_finite() && meta.resolution > 0.0);
    assert!(meta.origin.iter().all(|v| v.is_finite()));
    assert!((0.0..=1.0).contains(&meta.free_thresh));
    assert!((0.0..=1.0).contains(&meta.occupied_thresh));
    assert!(meta.free_thresh <= meta.occupied_thresh);
    assert!(
        meta.image.is_absolute(),
        "image path resolved against the YAML's folder"
    );
    for v in [0.0, 89.0, 127.5, 205.0, 254.0, 255.0] {
        let _ = meta.classify(v, 255);
        let _ = meta.classify(v, 0);
    }
    let Ok(img) = decode_image(image, "fuzz.pgm") else {
        return false;
    };
    let (map, frame) = ros_map(&meta, &img, unknown);
    check_map(&map);
    assert_eq!((frame.width, frame.height), (map.width, map.height));
    assert_eq!(frame.resolution, meta.resolution);
    // Cells -> metres -> cells, where floating point can hold it (origin and yaw of sane size).
    let sane = meta.resolution >= 1e-6
        && meta.resolution <= 1e6
        && meta.origin[..2]
            .iter()
            .all(|o| o.abs() / meta.resolution <= 1e9)
        && meta.origin[2].abs() <= 1e3;
    if sane {
        let (w, h) = (map.width - 1, map.height - 1);
        for p in [(0, 0), (w, 0), (0, h), (w, h), (w / 2, h / 2)] {
            let p = Point::new(p.0, p.1);
            assert_eq!(frame.cell(frame.to_metres(p)), Some(p), "{frame:?}");
        }
    }
    if meta.mode == Mode::Raw {
        // Raw values above 100 % are unknown whatever the thresholds.
        assert_eq!(
            meta.classify(if meta.negate { 0.0 } else { 255.0 }, 255),
            ohaca_host::map::Occupancy::Unknown
        );
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn small_maps_pass() {
        fuzz_map_parsers(b"T..#\n1.0\n");
        fuzz_map_parsers(b"Mtype octile\nwidth 2\nheight 1\nmap\n.@\n");
        fuzz_map_parsers(b"Atype octile\nheight 1\nwidth 1\nmap\nT\n");
        fuzz_map_parsers(b"a..#\n#..\n");
    }
}
