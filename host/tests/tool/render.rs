//! `ohaca render` end to end: valid SVG and PNG files, the path drawn in its colour, overlays,
//! the pheromone heat map, bad input.

use crate::common;

use std::path::Path;

use common::*;
use ohaca::{Algorithm, Point};
use ohaca_host::draw::{algorithm_colour, Layout, BLOCKED};
use ohaca_host::Map;

/// A 12 x 6 map with a wall; the planned path must go around it.
const MAP: &str =
    "............\n............\n.....#......\n.....#......\n.....#......\n............\n";

fn write_map(dir: &std::path::Path) -> std::path::PathBuf {
    let p = dir.join("wall.txt");
    std::fs::write(&p, MAP).unwrap();
    p
}

fn plan_json(map: &std::path::Path, alg: &str) -> serde_json::Value {
    let o = ohaca(&[
        "plan",
        "--map",
        map.to_str().unwrap(),
        "--start",
        "0,4",
        "--goal",
        "11,4",
        "--algorithm",
        alg,
        "--json",
    ]);
    serde_json::from_str(&stdout(&o)).unwrap()
}

#[test]
fn png_has_the_size_and_the_path_colour() {
    let dir = tempfile::tempdir().unwrap();
    let map = write_map(dir.path());
    let out = dir.path().join("p.png");
    let o = ohaca(&[
        "render",
        "--map",
        map.to_str().unwrap(),
        "--start",
        "0,4",
        "--goal",
        "11,4",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // One line says what was written.
    assert_eq!(
        stdout(&o),
        format!("wrote {} (1 of 1 planners found a path)\n", out.display())
    );
    let img = image::open(&out).unwrap().to_rgb8();
    let m = Map::load(&map).unwrap();
    // The legend: header, 2 lines for the one algorithm, a gap, 6 keys.
    let layout = Layout::new(m.width, m.height, 1 + 2 + 1 + 3 + 3);
    assert_eq!((img.width(), img.height()), (layout.width, layout.height));
    // The waypoints the plan command reports (same seed, same parameters).
    let v = plan_json(&map, "ohaca");
    let wp: Vec<[u16; 2]> = serde_json::from_value(v["waypoints"].clone()).unwrap();
    assert!(wp.len() >= 3, "goes around the wall: {wp:?}");
    let c = algorithm_colour(Algorithm::Ohaca);
    // The midpoint of every output segment is drawn in the algorithm's colour.
    for s in wp.windows(2) {
        let (a, b) = (
            layout.centre(s[0][0], s[0][1]),
            layout.centre(s[1][0], s[1][1]),
        );
        let (x, y) = (((a.0 + b.0) / 2) as u32, ((a.1 + b.1) / 2) as u32);
        assert_eq!(
            img.get_pixel(x, y).0,
            [c.0, c.1, c.2],
            "segment {s:?} at {x},{y}"
        );
    }
    // Wall cells are wall-coloured (away from the path's line).
    let (cx, cy) = layout.corner(5, 3);
    let px = img.get_pixel(cx as u32 + 2, cy as u32 + 2).0;
    assert_eq!(px, [BLOCKED.0, BLOCKED.1, BLOCKED.2]);
    // A free cell far from the path is white.
    let (cx, cy) = layout.corner(11, 0);
    assert_eq!(
        img.get_pixel(cx as u32 + 3, cy as u32 + 3).0,
        [255, 255, 255]
    );
    // The same command gives the same bytes.
    let first = std::fs::read(&out).unwrap();
    let o = ohaca(&[
        "render",
        "--map",
        map.to_str().unwrap(),
        "--start",
        "0,4",
        "--goal",
        "11,4",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(std::fs::read(&out).unwrap(), first);
}

#[test]
fn svg_is_a_document_with_every_layer() {
    let dir = tempfile::tempdir().unwrap();
    let map = write_map(dir.path());
    let out = dir.path().join("all.svg");
    let o = ohaca(&[
        "render",
        "--map",
        map.to_str().unwrap(),
        "--start",
        "0,4",
        "--goal",
        "11,4",
        "--algorithm",
        "aca",
        "--algorithm",
        "haca,ohaca",
        "--pheromone",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let svg = std::fs::read_to_string(&out).unwrap();
    assert!(svg.starts_with("<svg"), "{}", &svg[..80.min(svg.len())]);
    assert!(svg.trim_end().ends_with("</svg>"));
    for name in [
        "ACA: length",
        "HACA: length",
        "OHACA: length",
        "final pheromone",
    ] {
        assert!(svg.contains(name), "{name}");
    }
    assert!(!svg.contains("PACA:"), "only the algorithms asked for");
    // Each algorithm's colour appears as a stroke.
    for a in [Algorithm::Aca, Algorithm::Haca, Algorithm::Ohaca] {
        let c = algorithm_colour(a);
        let hex = format!("#{:02X}{:02X}{:02X}", c.0, c.1, c.2);
        assert!(svg.contains(&hex), "{hex}");
    }
}

#[test]
fn pheromone_heat_map_colours_the_trail() {
    let dir = tempfile::tempdir().unwrap();
    let map = write_map(dir.path());
    let out = dir.path().join("ph.png");
    let plain = dir.path().join("plain.png");
    for (file, extra) in [(&out, Some("--pheromone")), (&plain, None)] {
        let mut a = vec![
            "render".to_string(),
            "--map".into(),
            map.display().to_string(),
            "--start".into(),
            "0,4".into(),
            "--goal".into(),
            "11,4".into(),
            "--out".into(),
            file.display().to_string(),
        ];
        a.extend(extra.map(String::from));
        let o = ohaca(&a);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let a = image::open(&out).unwrap().to_rgb8();
    let b = image::open(&plain).unwrap().to_rgb8();
    // The heat map makes some free cells non-white; without it they are white.
    let m = Map::load(&map).unwrap();
    let layout = Layout::new(m.width, m.height, 12);
    let tinted = |img: &image::RgbImage| {
        (0..m.height)
            .flat_map(|y| (0..m.width).map(move |x| (x, y)))
            .filter(|&(x, y)| !m.is_blocked(Point::new(x, y)))
            .filter(|&(x, y)| {
                let (cx, cy) = layout.corner(x, y);
                let p = img.get_pixel(cx as u32 + 2, cy as u32 + 2).0;
                p != [255, 255, 255] && p[2] > p[1]
            })
            .count()
    };
    assert!(tinted(&a) > 3, "heat map drawn");
    assert_eq!(tinted(&b), 0);
}

#[test]
fn bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let map = write_map(dir.path());
    let m = map.to_str().unwrap();
    let jpg = dir.path().join("x.jpg");
    for (args, want) in [
        (
            vec![
                "render",
                "--map",
                m,
                "--start",
                "0,4",
                "--goal",
                "11,4",
                "--out",
                jpg.to_str().unwrap(),
            ],
            "x.jpg: the picture's name must end in .svg or .png",
        ),
        (
            vec![
                "render",
                "--map",
                m,
                "--start",
                "5,3",
                "--goal",
                "11,4",
                "--out",
                "/tmp/x.png",
            ],
            "start is on an obstacle",
        ),
        (
            vec![
                "render",
                "--map",
                m,
                "--start",
                "0,4",
                "--goal",
                "11,4",
                "--out",
                "/nonexistent-dir/x.png",
            ],
            "cannot write the file",
        ),
        (
            vec![
                "render",
                "--map",
                m,
                "--start",
                "0,4",
                "--goal",
                "11,4",
                "--out",
                "/tmp/y.png",
                "--algorithm",
                "bee",
            ],
            "unknown variant `bee`",
        ),
    ] {
        let o = ohaca(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let e = stderr(&o);
        assert!(e.starts_with("error: ") && e.contains(want), "{e}");
        assert_eq!(e.lines().count(), 1, "{e}");
    }
    assert!(!jpg.exists());
}

#[test]
fn no_path_still_draws_and_exits_1() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("closed.txt");
    std::fs::write(&p, "..#..\n..#..\n..#..\n").unwrap();
    let out = dir.path().join("c.png");
    let o = ohaca(&[
        "render",
        "--map",
        p.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "4,2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(image::open(&out).is_ok());
}

#[test]
fn a_long_title_widens_a_small_map_picture() {
    // A 6 x 3 map under a long folder name: the picture used to be as wide as the map and the
    // legend only, so the title ran off the right edge.
    let dir = tempfile::tempdir().unwrap();
    let deep = dir
        .path()
        .join("a-folder-with-a-rather-long-name-for-the-robot-maps-of-the-second-floor");
    std::fs::create_dir(&deep).unwrap();
    let map = deep.join("tiny-map-of-the-corridor.txt");
    std::fs::write(&map, "......\n.##...\n......\n").unwrap();
    let out = dir.path().join("t.png");
    let o = ohaca(&[
        "render",
        "--map",
        map.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "5,2",
        "--algorithm",
        "aca,paca,haca,ohaca",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let img = image::open(&out).unwrap().to_rgb8();
    let m = Map::load(&map).unwrap();
    let plain = Layout::new(m.width, m.height, 1 + 2 * 4 + 1 + 3 + 3);
    assert!(img.width() > plain.width, "widened: {}", img.width());
    // The map stays where the plain layout puts it (same height, same cells).
    assert_eq!(img.height(), plain.height);
    let (cx, cy) = plain.corner(1, 1);
    assert_eq!(
        img.get_pixel(cx as u32 + 3, cy as u32 + 3).0,
        [BLOCKED.0, BLOCKED.1, BLOCKED.2]
    );
    // The title (rows 6..30) has ink, and none in the right margin.
    let ink = |x0: u32, x1: u32| {
        (6..30).any(|y| (x0..x1).any(|x| img.get_pixel(x, y).0.iter().any(|&c| c < 200)))
    };
    assert!(ink(16, 200));
    assert!(!ink(img.width() - 12, img.width()), "title clipped");
    // One turn is "1 turn".
    let svg = dir.path().join("t.svg");
    let o = ohaca(&[
        "render",
        "--map",
        map.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "5,2",
        "--out",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.contains(", 1 turn\n"), "{text}");
}

/// Standard base64 decoding (the test's own, to check the tool's encoder).
fn unbase64(s: &str) -> Vec<u8> {
    let val = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        b'/' => 63,
        _ => panic!("not base64: {c}"),
    };
    let bytes: Vec<u8> = s.bytes().filter(|&c| c != b'=').collect();
    let mut out = Vec::new();
    for chunk in bytes.chunks(4) {
        let mut n = 0u32;
        for (i, &c) in chunk.iter().enumerate() {
            n |= u32::from(val(c)) << (18 - 6 * i);
        }
        out.extend_from_slice(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}

#[test]
fn svg_embeds_the_font() {
    let dir = tempfile::tempdir().unwrap();
    let map = write_map(dir.path());
    let out = dir.path().join("f.svg");
    let o = ohaca(&[
        "render",
        "--map",
        map.to_str().unwrap(),
        "--start",
        "0,4",
        "--goal",
        "11,4",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let svg = std::fs::read_to_string(&out).unwrap();
    // The vendored TTF, byte for byte, in an @font-face rule inside the document.
    let start = svg.find("base64,").expect("a data: URL") + "base64,".len();
    let end = start + svg[start..].find(')').unwrap();
    let font =
        std::fs::read(Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/Go-Regular.ttf")).unwrap();
    assert!(
        unbase64(&svg[start..end]) == font,
        "the embedded font is Go Regular"
    );
    assert!(svg.contains("@font-face{font-family:\"OhacaGo\""));
    assert!(svg.find("<defs>").unwrap() < svg.find("<text").unwrap());
    // Every text asks for it first (the viewer's sans-serif only as a fallback).
    let families: Vec<&str> = svg
        .split("font-family=\"")
        .skip(1)
        .map(|s| &s[..s.find('"').unwrap()])
        .collect();
    assert!(!families.is_empty());
    assert!(
        families.iter().all(|f| *f == "OhacaGo, sans-serif"),
        "{families:?}"
    );
    // Still one well-formed document.
    assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
    assert_eq!(svg.matches("<svg").count(), 1);
}
