//! Real robot maps end to end: ROS map_server YAML + PGM/PNG written by the tests, the image
//! y-axis flip, `negate`, unknown cells, inflation, resampling, metres in and out, errors.

use crate::common;

use std::path::Path;

use common::*;
use ohaca::Point;
use ohaca_host::input::{MapArgs, Scenario};
use ohaca_host::map::{MapError, Unknown};
use serde_json::Value;

fn args(map: &Path) -> MapArgs {
    MapArgs {
        map: map.to_path_buf(),
        start: Some(Point::new(0, 0)),
        goal: Some(Point::new(0, 0)),
        start_m: None,
        goal_m: None,
        unknown: Unknown::Blocked,
        inflate: None,
        cell: None,
    }
}

fn load(a: &MapArgs) -> Scenario {
    a.load().unwrap_or_else(|e| panic!("{e}"))
}

fn blocked(sc: &Scenario) -> Vec<String> {
    sc.map.to_text().lines().map(str::to_string).collect()
}

#[test]
fn image_row_zero_is_the_top_and_origin_is_lower_left() {
    let dir = tempfile::tempdir().unwrap();
    // 4 x 3; the obstacle is in the top row, rightmost column.
    let yaml = ros_map(
        dir.path(),
        "flip",
        &[&[F, F, F, O], &[F, F, F, F], &[F, F, F, F]],
        0.5,
        [10.0, -2.0],
        "",
    );
    let sc = load(&args(&yaml));
    assert_eq!((sc.map.width, sc.map.height), (4, 3));
    assert_eq!(blocked(&sc), ["...#", "....", "...."]);
    let f = sc.metric.unwrap();
    // The lower-left cell (0, 2) is centred half a cell from the origin.
    assert_eq!(f.to_metres(Point::new(0, 2)), [10.25, -1.75]);
    // The obstacle (3, 0) is top right: x = 10 + 3.5 * 0.5, y = -2 + 2.5 * 0.5.
    assert_eq!(f.to_metres(Point::new(3, 0)), [11.75, -0.75]);
    assert_eq!(f.cell([11.75, -0.75]), Some(Point::new(3, 0)));
    assert_eq!(f.cell([10.0, -2.0]), Some(Point::new(0, 2)));
    // Every cell round-trips.
    for y in 0..3 {
        for x in 0..4 {
            let p = Point::new(x, y);
            assert_eq!(f.cell(f.to_metres(p)), Some(p));
        }
    }
}

#[test]
fn negate_and_unknown() {
    let dir = tempfile::tempdir().unwrap();
    // With negate, 0 is free and 255 occupied.
    let yaml = ros_map(
        dir.path(),
        "neg",
        &[&[0, 255, 0], &[0, 0, 0]],
        1.0,
        [0.0, 0.0],
        "negate: 1\n",
    );
    assert_eq!(blocked(&load(&args(&yaml))), [".#.", "..."]);
    // Unknown (205) is blocked by default, free on request.
    let yaml = ros_map(
        dir.path(),
        "unk",
        &[&[F, U, O], &[F, F, F]],
        1.0,
        [0.0, 0.0],
        "",
    );
    assert_eq!(blocked(&load(&args(&yaml))), [".##", "..."]);
    let free = MapArgs {
        unknown: Unknown::Free,
        ..args(&yaml)
    };
    assert_eq!(blocked(&load(&free)), ["..#", "..."]);
}

#[test]
fn png_maps_with_and_without_yaml() {
    let dir = tempfile::tempdir().unwrap();
    let mut img = image::GrayImage::from_pixel(5, 2, image::Luma([255]));
    img.put_pixel(1, 0, image::Luma([100])); // darker than 50 %: blocked
    img.put_pixel(2, 0, image::Luma([140])); // lighter: free as a plain image
    let png = dir.path().join("plain.png");
    img.save(&png).unwrap();
    let sc = load(&args(&png));
    assert_eq!(blocked(&sc), [".#...", "....."]);
    assert!(sc.metric.is_none());
    // The same PNG through a YAML: 140 is p = 0.45, unknown, so blocked by default.
    std::fs::write(
        dir.path().join("p.yaml"),
        "image: plain.png\nresolution: 0.1\norigin: [0, 0, 0]\n",
    )
    .unwrap();
    let sc = load(&args(&dir.path().join("p.yaml")));
    assert_eq!(blocked(&sc), [".##..", "....."]);
    assert_eq!(sc.metric.unwrap().resolution, 0.1);
}

#[test]
fn inflation_uses_metres() {
    let dir = tempfile::tempdir().unwrap();
    let row = [F; 7];
    let mut mid = [F; 7];
    mid[3] = O;
    let yaml = ros_map(
        dir.path(),
        "inf",
        &[&row, &row, &mid, &row, &row],
        0.1,
        [0.0, 0.0],
        "",
    );
    // 0.1 m = one cell: the plus shape.
    let a = MapArgs {
        inflate: Some(0.1),
        ..args(&yaml)
    };
    assert_eq!(
        blocked(&load(&a)),
        [".......", "...#...", "..###..", "...#...", "......."]
    );
    // 0.2 m = two cells.
    let a = MapArgs {
        inflate: Some(0.2),
        ..args(&yaml)
    };
    assert_eq!(
        blocked(&load(&a)),
        ["...#...", "..###..", ".#####.", "..###..", "...#..."]
    );
    // A map without a resolution counts in cells.
    let txt = dir.path().join("g.txt");
    std::fs::write(&txt, ".....\n.....\n..#..\n.....\n.....\n").unwrap();
    let a = MapArgs {
        inflate: Some(1.0),
        ..args(&txt)
    };
    assert_eq!(
        blocked(&load(&a)),
        [".....", "..#..", ".###.", "..#..", "....."]
    );
}

#[test]
fn resampling_keeps_the_origin_and_blocks_any_covered_pixel() {
    let dir = tempfile::tempdir().unwrap();
    // 6 x 5 at 0.05 m; one occupied pixel at (4, 1); resample to 0.1 m (factor 2).
    let row = [F; 6];
    let mut r1 = [F; 6];
    r1[4] = O;
    let yaml = ros_map(
        dir.path(),
        "res",
        &[&row, &r1, &row, &row, &row],
        0.05,
        [-1.0, 2.0],
        "",
    );
    let fine = load(&args(&yaml));
    let a = MapArgs {
        cell: Some(0.1),
        ..args(&yaml)
    };
    let coarse = load(&a);
    // 3 x 3: anchored at the bottom, so the top coarse row covers only fine row 0 and the middle
    // one fine rows 1-2.
    assert_eq!(blocked(&coarse), ["...", "..#", "..."]);
    let (ff, cf) = (fine.metric.unwrap(), coarse.metric.unwrap());
    assert_eq!(cf.resolution, 0.1);
    assert_eq!(cf.origin, ff.origin);
    // A fine cell's centre lies in the coarse cell that covers it.
    let m = ff.to_metres(Point::new(4, 1));
    assert_eq!(cf.cell(m), Some(Point::new(2, 1)));
    // Coarse centres round-trip.
    for y in 0..3 {
        for x in 0..3 {
            let p = Point::new(x, y);
            assert_eq!(cf.cell(cf.to_metres(p)), Some(p));
        }
    }
    // A cell smaller than the map's is an error naming the file.
    let bad = MapArgs {
        cell: Some(0.01),
        ..args(&yaml)
    };
    let e = bad.load().unwrap_err().to_string();
    assert!(e.contains("res.yaml") && e.contains("--cell 0.01"), "{e}");
}

#[test]
fn start_and_goal_in_metres() {
    let dir = tempfile::tempdir().unwrap();
    let row = [F; 8];
    let yaml = ros_map(
        dir.path(),
        "m",
        &[&row, &row, &row, &row],
        0.25,
        [1.0, 1.0],
        "",
    );
    let a = MapArgs {
        start: None,
        goal: None,
        start_m: Some([1.1, 1.1]),
        goal_m: Some([2.9, 1.99]),
        ..args(&yaml)
    };
    let sc = load(&a);
    assert_eq!(sc.start, Point::new(0, 3), "lower-left cell");
    assert_eq!(sc.goal, Point::new(7, 0), "top-right cell");
    let outside = MapArgs {
        start_m: Some([0.5, 1.5]),
        ..a.clone()
    };
    match outside.load() {
        Err(MapError::File { path, problem }) => {
            assert!(path.ends_with("m.yaml"));
            assert_eq!(
                problem,
                "start (0.5, 1.5) m is outside the map (x from 1 to 3 m, y from 1 to 2 m)"
            );
        }
        other => panic!("{other:?}"),
    }
    // Metres on a map without a resolution.
    let txt = dir.path().join("g.txt");
    std::fs::write(&txt, "...\n").unwrap();
    let e = MapArgs {
        start_m: Some([0.0, 0.0]),
        start: None,
        ..args(&txt)
    }
    .load()
    .unwrap_err()
    .to_string();
    assert!(e.contains("--start-m needs a map with a resolution"), "{e}");
}

#[test]
fn plan_json_has_waypoints_in_metres() {
    let dir = tempfile::tempdir().unwrap();
    let row = [F; 10];
    let mut wall = [O; 10];
    wall[9] = F;
    let yaml = ros_map(
        dir.path(),
        "lab",
        &[&row, &wall, &row, &row],
        0.05,
        [-0.5, 3.0],
        "",
    );
    let o = ohaca(&[
        "plan",
        "--map",
        yaml.to_str().unwrap(),
        "--start-m",
        "-0.49,3.01",
        "--goal",
        "0,0",
        "--format",
        "json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    let wp = v["waypoints"].as_array().unwrap();
    let wm = v["waypoints_m"].as_array().unwrap();
    assert_eq!(wp.len(), wm.len());
    assert_eq!(
        wp[0],
        serde_json::json!([0, 3]),
        "start-m is the lower-left cell"
    );
    // Lower-left cell centre: origin + half a cell.
    assert_eq!(wm[0], serde_json::json!([-0.475, 3.025]));
    // Top-left cell (0, 0): 3.5 cells up.
    assert_eq!(wm.last().unwrap(), &serde_json::json!([-0.475, 3.175]));
    // Every waypoint: metres = origin + (x + 0.5, H - 1 - y + 0.5) * resolution.
    for (p, m) in wp.iter().zip(wm) {
        let (x, y) = (p[0].as_f64().unwrap(), p[1].as_f64().unwrap());
        let (mx, my) = (m[0].as_f64().unwrap(), m[1].as_f64().unwrap());
        assert!((mx - (-0.5 + (x + 0.5) * 0.05)).abs() < 1e-9);
        assert!((my - (3.0 + (4.0 - 1.0 - y + 0.5) * 0.05)).abs() < 1e-9);
    }
    // CSV in metres.
    let o = ohaca(&[
        "plan",
        "--map",
        yaml.to_str().unwrap(),
        "--start",
        "0,3",
        "--goal",
        "0,0",
        "--format",
        "csv",
    ]);
    let out = stdout(&o);
    let mut lines = out.lines();
    assert_eq!(lines.next(), Some("x_m,y_m"));
    assert_eq!(lines.next(), Some("-0.475,3.025"));
    assert_eq!(out.lines().last(), Some("-0.475,3.175"));
    // Moving AI maps have no metres.
    let o = ohaca(&[
        "plan",
        "--map",
        maps_dir().join("simple-18.map").to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "17,17",
        "--json",
    ]);
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert!(v.get("waypoints_m").is_none());
}

#[test]
fn clear_errors_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let run = |yaml: &str, extra: &[&str]| {
        let p = d.join("e.yaml");
        std::fs::write(&p, yaml).unwrap();
        let mut a = vec![
            "plan",
            "--map",
            p.to_str().unwrap(),
            "--start",
            "0,0",
            "--goal",
            "1,0",
        ];
        a.extend_from_slice(extra);
        let o = ohaca(&a);
        assert_eq!(o.status.code(), Some(2), "{yaml}: {}", stderr(&o));
        assert!(stdout(&o).is_empty());
        let e = stderr(&o);
        assert_eq!(e.lines().count(), 1, "{e}");
        e
    };
    let e = run(
        "image: nothere.pgm\nresolution: 0.05\norigin: [0, 0, 0]\n",
        &[],
    );
    assert!(
        e.contains("e.yaml: image `") && e.contains("nothere.pgm` does not exist"),
        "{e}"
    );
    let e = run("image: x.pgm\nresolution: fast\norigin: [0, 0, 0]\n", &[]);
    assert!(
        e.contains("e.yaml: field `resolution` must be a number greater than 0, found `fast`"),
        "{e}"
    );
    let e = run("image: x.pgm\nresolution: -1\norigin: [0, 0, 0]\n", &[]);
    assert!(e.contains("greater than 0, found `-1`"), "{e}");
    let e = run("image: x.pgm\nresolution: 0\norigin: [0, 0, 0]\n", &[]);
    assert!(e.contains("greater than 0, found `0`"), "{e}");
    let e = run(
        "image: x.pgm\nresolution: 1\norigin: [0, 0, 0]\nmode: fancy\n",
        &[],
    );
    assert!(e.contains("field `mode`"), "{e}");
    // A real image, a start outside it.
    std::fs::write(d.join("ok.pgm"), pgm(&[&[F, F], &[F, F]])).unwrap();
    let p = d.join("ok.yaml");
    std::fs::write(&p, "image: ok.pgm\nresolution: 1\norigin: [0, 0, 0]\n").unwrap();
    let o = ohaca(&[
        "plan",
        "--map",
        p.to_str().unwrap(),
        "--start",
        "5,5",
        "--goal",
        "1,0",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("ok.yaml: start is outside the map (start 5,5, goal 1,0, map 2x2)"),
        "{}",
        stderr(&o)
    );
    let o = ohaca(&[
        "plan",
        "--map",
        p.to_str().unwrap(),
        "--start-m",
        "5,5",
        "--goal",
        "1,0",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("ok.yaml: start (5, 5) m is outside the map"),
        "{}",
        stderr(&o)
    );
    // A broken image.
    std::fs::write(d.join("bad.pgm"), b"P5\n2 2\n255\n\x00").unwrap();
    std::fs::write(&p, "image: bad.pgm\nresolution: 1\norigin: [0, 0, 0]\n").unwrap();
    let o = ohaca(&[
        "plan",
        "--map",
        p.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "1,0",
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("bad.pgm: cannot decode the image"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn inflation_radius_larger_than_the_map_is_fast() {
    // The inflation used to allocate a disc of (2r + 1)^2 offsets, r in cells: 1000 m at
    // 0.05 m per cell was 1.6e9 offsets, and the tool died of memory exhaustion. Now it is a
    // distance transform whose cost does not depend on r.
    let dir = tempfile::tempdir().unwrap();
    let row = [F; 40];
    let mut mid = [F; 40];
    mid[20] = O;
    let yaml = ros_map(
        dir.path(),
        "big",
        &[&row, &row, &mid, &row, &row],
        0.05,
        [0.0, 0.0],
        "",
    );
    let t = std::time::Instant::now();
    let o = ohaca(&[
        "plan",
        "--map",
        yaml.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "39,4",
        "--inflate",
        "1000",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("big.yaml: start is on an obstacle"),
        "{}",
        stderr(&o)
    );
    assert!(t.elapsed().as_secs() < 30, "{:?}", t.elapsed());
    // Every cell is within 1000 m of the one obstacle.
    let a = MapArgs {
        inflate: Some(1000.0),
        ..args(&yaml)
    };
    assert!(blocked(&load(&a)).iter().all(|r| r == &"#".repeat(40)));
    // 0.5 m = 10 cells: the columns 10..=30 of the obstacle's row, fewer above and below.
    let a = MapArgs {
        inflate: Some(0.5),
        ..args(&yaml)
    };
    let rows = blocked(&load(&a));
    assert_eq!(
        rows[2],
        format!("{}{}{}", ".".repeat(10), "#".repeat(21), ".".repeat(9))
    );
    // Row 0 is 2 cells away: |dx| <= sqrt(100 - 4) = 9.8.
    assert_eq!(
        rows[0],
        format!("{}{}{}", ".".repeat(11), "#".repeat(19), ".".repeat(10))
    );
}
