//! End-to-end tests of the `ohaca` binary: JSON contract, exit codes, bad inputs, a 512x512 map.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use ohaca::{Params, Point};
use ohaca_host::Map;
use serde_json::Value;

fn ohaca<S: AsRef<std::ffi::OsStr>>(args: &[S]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ohaca"))
        .args(args)
        .output()
        .expect("run the ohaca binary")
}

fn maps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps")
}

fn complex() -> PathBuf {
    maps_dir().join("complex-26.map")
}

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).unwrap()
}

fn plan_json(map: &Path, start: &str, goal: &str, extra: &[&str]) -> (Output, Value) {
    let mut args = vec![
        "plan".to_string(),
        "--map".into(),
        map.display().to_string(),
        "--start".into(),
        start.into(),
        "--goal".into(),
        goal.into(),
        "--json".into(),
    ];
    args.extend(extra.iter().map(|s| s.to_string()));
    let o = ohaca(&args);
    let out = stdout(&o);
    assert_eq!(out.lines().count(), 1, "one JSON line: {out}");
    let v: Value = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}"));
    (o, v)
}

fn pt(v: &Value) -> Point {
    let a = v.as_array().unwrap();
    assert_eq!(a.len(), 2);
    Point::new(a[0].as_u64().unwrap() as u16, a[1].as_u64().unwrap() as u16)
}

/// Keys of a found report, exactly.
const FOUND_KEYS: [&str; 11] = [
    "best_iteration",
    "elapsed_us",
    "found",
    "iterations",
    "length",
    "moves",
    "params",
    "raw",
    "raw_length",
    "turns",
    "waypoints",
];

const PARAM_KEYS: [&str; 21] = [
    "a",
    "algorithm",
    "alpha",
    "ants",
    "beta",
    "dead_end",
    "iterations",
    "patience",
    "prune",
    "q",
    "refine",
    "refine_patience",
    "rho",
    "seed",
    "smoothing",
    "tau0",
    "tau_max",
    "tau_min",
    "tighten",
    "warm_patience",
    "xi",
];

fn keys(v: &Value) -> Vec<String> {
    let mut k: Vec<String> = v.as_object().unwrap().keys().cloned().collect();
    k.sort();
    k
}

/// Every raw step is one 8-connected move between free cells without cutting a corner.
fn check_raw_path(map: &Map, raw: &[Point]) {
    let g = map.grid().unwrap();
    for p in raw {
        assert!(g.is_free(*p), "{p:?} is blocked");
    }
    for w in raw.windows(2) {
        let ok = (0..8).any(|d| g.step(w[0], d) == Some(w[1]));
        assert!(ok, "{:?} -> {:?} is not a legal move", w[0], w[1]);
    }
}

#[test]
fn json_on_complex_26() {
    let (o, v) = plan_json(&complex(), "0,0", "25,25", &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(o.stderr.is_empty());
    assert_eq!(keys(&v), FOUND_KEYS);
    assert_eq!(keys(&v["params"]), PARAM_KEYS);
    assert_eq!(v["found"], true);

    let raw: Vec<Point> = v["raw"].as_array().unwrap().iter().map(pt).collect();
    let wps: Vec<Point> = v["waypoints"].as_array().unwrap().iter().map(pt).collect();
    assert_eq!(raw.first(), Some(&Point::new(0, 0)));
    assert_eq!(raw.last(), Some(&Point::new(25, 25)));
    assert_eq!(wps.first(), Some(&Point::new(0, 0)));
    assert_eq!(wps.last(), Some(&Point::new(25, 25)));
    let map = Map::load(complex()).unwrap();
    check_raw_path(&map, &raw);

    // maps/README.md: the shortest 8-connected path is 41.7990, the any-angle one 39.1470.
    let raw_len = v["raw_length"].as_f64().unwrap();
    let len = v["length"].as_f64().unwrap();
    assert!(raw_len >= 41.799 - 1e-3, "{raw_len}");
    assert!(len >= 39.147 - 1e-3, "{len}");
    assert!(len <= raw_len + 1e-4);
    let steps: f64 = raw
        .windows(2)
        .map(|w| {
            if w[0].x != w[1].x && w[0].y != w[1].y {
                2f64.sqrt()
            } else {
                1.0
            }
        })
        .sum();
    assert!((steps - raw_len).abs() < 1e-3, "{steps} vs {raw_len}");

    let iterations = v["iterations"].as_u64().unwrap();
    assert!((1..=100).contains(&iterations));
    assert!(v["best_iteration"].as_u64().unwrap() < iterations);
    assert!(v["turns"].as_u64().unwrap() as usize <= wps.len().saturating_sub(2));
    assert!(v["moves"].as_u64().unwrap() >= raw.len() as u64 - 1);
    assert!(v["elapsed_us"].is_u64());

    // The params object is exactly the core's defaults.
    let params: Params = serde_json::from_value(v["params"].clone()).unwrap();
    assert_eq!(params, Params::default());
    assert_eq!(v["params"]["algorithm"], "ohaca");
    assert_eq!(v["params"]["ants"], 12);
    assert_eq!(v["params"]["iterations"], 100);
    assert_eq!(v["params"]["seed"], 1);
    assert_eq!(v["params"]["dead_end"], "backtrack");
    assert_eq!(v["params"]["smoothing"], "shortest");
}

#[test]
fn same_seed_same_answer_and_flags_reach_the_params() {
    let run = |extra: &[&str]| {
        let (o, mut v) = plan_json(&complex(), "0,0", "25,25", extra);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        v.as_object_mut().unwrap().remove("elapsed_us");
        v
    };
    let flags = [
        "--algorithm",
        "haca",
        "--seed",
        "7",
        "--ants",
        "20",
        "--iterations",
        "30",
        "--alpha",
        "1.5",
        "--beta",
        "2.5",
        "--rho",
        "0.2",
        "--q",
        "2",
        "--a",
        "0.1",
        "--xi",
        "0.5",
        "--tau0",
        "2",
        "--tau-min",
        "0.1",
        "--tau-max",
        "50",
        "--patience",
        "0",
        "--dead-end",
        "backtrack",
        "--smoothing",
        "greedy",
    ];
    let a = run(&flags);
    assert_eq!(a, run(&flags));
    let p = &a["params"];
    assert_eq!(p["algorithm"], "haca");
    assert_eq!(p["seed"], 7);
    assert_eq!(p["ants"], 20);
    assert_eq!(p["iterations"], 30);
    assert_eq!(p["patience"], 0);
    assert_eq!(p["smoothing"], "greedy");
    for (k, want) in [
        ("alpha", 1.5),
        ("beta", 2.5),
        ("rho", 0.2),
        ("q", 2.0),
        ("a", 0.1),
        ("xi", 0.5),
        ("tau0", 2.0),
        ("tau_min", 0.1),
        ("tau_max", 50.0),
    ] {
        assert_eq!(p[k].as_f64().unwrap() as f32, want as f32, "{k}");
    }
    // patience 0: all iterations run. HACA does not smooth: waypoints are the raw corners.
    assert_eq!(a["iterations"], 30);
    let (len, raw) = (
        a["length"].as_f64().unwrap(),
        a["raw_length"].as_f64().unwrap(),
    );
    assert!((len - raw).abs() < 1e-4, "{len} vs {raw}");
    // Another seed is allowed to differ but must still be a valid answer.
    let b = run(&["--seed", "8"]);
    assert_eq!(b["found"], true);
}

#[test]
fn picture_and_summary() {
    let o = ohaca(&[
        "plan",
        "--map",
        complex().to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "25,25",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let out = stdout(&o);
    let lines: Vec<&str> = out.lines().collect();
    // title, legend, 26 rows, 2 summary lines
    assert_eq!(lines.len(), 30, "{out}");
    assert!(lines[0].contains("(0,0) -> (25,25)"));
    assert!(lines[1].contains("o waypoint"));
    let rows = &lines[2..28];
    assert!(rows.iter().all(|r| r.len() == 2 * 26 - 1), "{out}");
    assert!(rows[0].starts_with("S "));
    assert!(rows[25].ends_with(" G"));
    // complex-26 row 1 is "...@@@....@@..." : obstacles at columns 3..=5
    assert_eq!(&rows[1][6..11], "# # #");
    assert!(out.contains('*') && out.contains('o'));
    assert!(lines[28].starts_with("raw length "), "{out}");
    assert!(lines[28].contains("turns"));
    assert!(
        lines[29].contains("iterations") && lines[29].contains(" ms"),
        "{out}"
    );
}

#[test]
fn no_path_exits_1() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("walled.txt");
    // The goal (4,3) is walled in.
    std::fs::write(&f, ".....\n.....\n...##\n...#.\n").unwrap();
    let (o, v) = plan_json(&f, "0,0", "4,3", &[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(o.stderr.is_empty(), "{}", stderr(&o));
    let mut want: Vec<&str> = FOUND_KEYS.to_vec();
    want.push("error");
    want.sort();
    assert_eq!(keys(&v), want);
    assert_eq!(v["found"], false);
    assert_eq!(v["raw"], serde_json::json!([]));
    assert_eq!(v["waypoints"], serde_json::json!([]));
    assert!(v["raw_length"].is_null() && v["length"].is_null());
    assert!(v["error"].as_str().unwrap().starts_with("no path"));
    assert_eq!(keys(&v["params"]), PARAM_KEYS);

    let o = ohaca(&[
        "plan",
        "--map",
        f.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "4,3",
    ]);
    assert_eq!(o.status.code(), Some(1));
    let out = stdout(&o);
    assert!(out.contains("no path"), "{out}");
    assert!(out.contains("S . . . ."), "{out}");
    assert!(out.contains(". . . # G"), "{out}");
}

#[test]
fn start_equals_goal() {
    let (o, v) = plan_json(&complex(), "7,7", "7,7", &[]);
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(v["raw"], serde_json::json!([[7, 7]]));
    assert_eq!(v["waypoints"], serde_json::json!([[7, 7]]));
    assert_eq!(v["raw_length"], 0.0);
}

#[test]
fn a_one_cell_path_has_length_zero_not_minus_zero() {
    // The core sums no segments into -0.0 for OHACA's smoothed path; the tool prints 0.
    for alg in ["ohaca", "haca", "aca"] {
        let (o, v) = plan_json(&complex(), "7,7", "7,7", &["--algorithm", alg]);
        assert_eq!(o.status.code(), Some(0));
        let text = stdout(&o);
        assert!(
            text.contains("\"raw_length\":0.0,\"length\":0.0,"),
            "{alg}: {text}"
        );
        assert!(!text.contains("-0"), "{alg}: {text}");
        assert!(v["length"].as_f64().unwrap().is_sign_positive());
    }
    let o = ohaca(&[
        "plan",
        "--map",
        complex().to_str().unwrap(),
        "--start",
        "7,7",
        "--goal",
        "7,7",
    ]);
    let text = stdout(&o);
    assert!(
        text.contains("raw length 0.000   waypoint path 0.000 (1 waypoint)   0 turns"),
        "{text}"
    );
    let o = ohaca(&[
        "plan",
        "--map",
        complex().to_str().unwrap(),
        "--start",
        "7,7",
        "--goal",
        "7,7",
        "--format",
        "csv",
    ]);
    assert_eq!(stdout(&o), "x,y\n7,7\n");
}

/// One bad-input case: a map file's content (None = do not create the file), extra arguments,
/// and substrings the single stderr line must contain.
struct Bad {
    name: &'static str,
    file: &'static str,
    content: Option<&'static str>,
    start: &'static str,
    goal: &'static str,
    extra: &'static [&'static str],
    expect: &'static [&'static str],
}

#[test]
fn bad_inputs_exit_2_with_one_line() {
    let cases = [
        Bad {
            name: "truncated map",
            file: "trunc.map",
            content: Some("type octile\nheight 3\nwidth 4\nmap\n....\n....\n"),
            start: "0,0",
            goal: "1,1",
            extra: &[],
            expect: &[
                "trunc.map",
                "line 7",
                "truncated map: expected 3 rows, found 2",
            ],
        },
        Bad {
            name: "truncated header",
            file: "head.map",
            content: Some("type octile\nheight 3\n"),
            start: "0,0",
            goal: "1,1",
            extra: &[],
            expect: &["head.map", "line 3", "truncated map", "width <columns>"],
        },
        Bad {
            name: "wrong header",
            file: "hdr.map",
            content: Some("type octile\nheight 3\nwidht 4\nmap\n....\n....\n....\n"),
            start: "0,0",
            goal: "1,1",
            extra: &[],
            expect: &["hdr.map", "line 3", "wrong header", "widht 4"],
        },
        Bad {
            name: "wrong map type",
            file: "type.map",
            content: Some("type hex\nheight 3\nwidth 4\nmap\n....\n....\n....\n"),
            start: "0,0",
            goal: "1,1",
            extra: &[],
            expect: &["type.map", "line 1", "wrong header", "type octile"],
        },
        Bad {
            name: "row of wrong length (moving ai)",
            file: "row.map",
            content: Some("type octile\nheight 3\nwidth 4\nmap\n....\n...\n....\n"),
            start: "0,0",
            goal: "1,1",
            extra: &[],
            expect: &["row.map", "line 6", "row 2 has 3 cells, expected 4"],
        },
        Bad {
            name: "row of wrong length (text)",
            file: "row.txt",
            content: Some("....\n....\n.....\n"),
            start: "0,0",
            goal: "1,1",
            extra: &[],
            expect: &["row.txt", "line 3", "row 3 has 5 cells, expected 4"],
        },
        Bad {
            name: "unknown character",
            file: "char.txt",
            content: Some("....\n..x.\n....\n"),
            start: "0,0",
            goal: "1,1",
            extra: &[],
            expect: &["char.txt", "line 2", "unknown character 'x' in column 3"],
        },
        Bad {
            name: "map too large",
            file: "huge.map",
            content: Some("type octile\nheight 70000\nwidth 4\nmap\n....\n"),
            start: "0,0",
            goal: "1,1",
            extra: &[],
            expect: &["huge.map", "line 2", "map too large", "70000"],
        },
        Bad {
            name: "empty file",
            file: "empty.txt",
            content: Some(""),
            start: "0,0",
            goal: "1,1",
            extra: &[],
            expect: &["empty.txt", "line 1", "empty map"],
        },
        Bad {
            name: "unreadable file",
            file: "missing.map",
            content: None,
            start: "0,0",
            goal: "1,1",
            extra: &[],
            expect: &["missing.map", "cannot read the file"],
        },
        Bad {
            name: "start on obstacle",
            file: "ok.map",
            content: Some("type octile\nheight 3\nwidth 4\nmap\n.@..\n....\n....\n"),
            start: "1,0",
            goal: "3,2",
            extra: &[],
            expect: &["ok.map", "start is on an obstacle"],
        },
        Bad {
            name: "goal on obstacle",
            file: "ok.map",
            content: Some("type octile\nheight 3\nwidth 4\nmap\n.@..\n....\n....\n"),
            start: "0,0",
            goal: "1,0",
            extra: &[],
            expect: &["goal is on an obstacle"],
        },
        Bad {
            name: "goal outside the map",
            file: "ok.map",
            content: None,
            start: "0,0",
            goal: "4,0",
            extra: &[],
            expect: &["goal is outside the map"],
        },
        Bad {
            name: "bad parameter (core range check)",
            file: "ok.map",
            content: None,
            start: "0,0",
            goal: "3,2",
            extra: &["--rho", "0"],
            expect: &["bad parameter: rho must be in (0, 1]"],
        },
        Bad {
            name: "negative parameter",
            file: "ok.map",
            content: None,
            start: "0,0",
            goal: "3,2",
            extra: &["--alpha", "-1"],
            expect: &["bad parameter: alpha"],
        },
        Bad {
            name: "nan parameter",
            file: "ok.map",
            content: None,
            start: "0,0",
            goal: "3,2",
            extra: &["--tau0", "NaN"],
            expect: &["bad parameter: need 0 < tau_min <= tau0 <= tau_max"],
        },
        Bad {
            name: "zero ants",
            file: "ok.map",
            content: None,
            start: "0,0",
            goal: "3,2",
            extra: &["--ants", "0"],
            expect: &["bad parameter: ants must be at least 1"],
        },
    ];
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(
        dir.path().join("ok.map"),
        "type octile\nheight 3\nwidth 4\nmap\n.@..\n....\n....\n",
    )
    .unwrap();
    for c in &cases {
        let path = dir.path().join(c.file);
        if let Some(text) = c.content {
            std::fs::write(&path, text).unwrap();
        }
        let mut args = vec![
            "plan",
            "--map",
            path.to_str().unwrap(),
            "--start",
            c.start,
            "--goal",
            c.goal,
            "--json",
        ];
        args.extend_from_slice(c.extra);
        let o = ohaca(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{}: {err}", c.name);
        assert!(o.stdout.is_empty(), "{}: stdout {}", c.name, stdout(&o));
        assert_eq!(err.lines().count(), 1, "{}: one line: {err}", c.name);
        assert!(err.starts_with("error: "), "{}: {err}", c.name);
        for want in c.expect {
            assert!(err.contains(want), "{}: {want:?} not in {err}", c.name);
        }
    }
}

#[test]
fn bad_command_lines_exit_2() {
    let m = complex();
    let m = m.to_str().unwrap();
    for (args, want) in [
        (
            vec![
                "plan", "--map", m, "--start", "0,0", "--goal", "25,25", "--seed", "abc",
            ],
            "--seed",
        ),
        (
            vec![
                "plan", "--map", m, "--start", "0,0", "--goal", "25,25", "--ants", "-1",
            ],
            "--ants",
        ),
        (
            vec![
                "plan", "--map", m, "--start", "0,0", "--goal", "25,25", "--ants", "70000",
            ],
            "--ants",
        ),
        (
            vec![
                "plan", "--map", m, "--start", "0,0", "--goal", "25,25", "--rho", "x",
            ],
            "--rho",
        ),
        (
            vec!["plan", "--map", m, "--start", "a,b", "--goal", "25,25"],
            "--start",
        ),
        (
            vec!["plan", "--map", m, "--start", "-1,0", "--goal", "25,25"],
            "--start",
        ),
        (
            vec!["plan", "--map", m, "--start", "0,0", "--goal", "25"],
            "--goal",
        ),
        (
            vec!["plan", "--map", m, "--start", "0,0", "--goal", "99999,0"],
            "--goal",
        ),
        (
            vec![
                "plan",
                "--map",
                m,
                "--start",
                "0,0",
                "--goal",
                "25,25",
                "--algorithm",
                "bee",
            ],
            "--algorithm",
        ),
        (
            vec![
                "plan",
                "--map",
                m,
                "--start",
                "0,0",
                "--goal",
                "25,25",
                "--dead-end",
                "x",
            ],
            "--dead-end",
        ),
        (
            vec![
                "plan",
                "--map",
                m,
                "--start",
                "0,0",
                "--goal",
                "25,25",
                "--smoothing",
                "x",
            ],
            "--smoothing",
        ),
        (vec!["plan", "--map", m, "--start", "0,0"], "--goal"),
        (vec!["plan", "--start", "0,0", "--goal", "1,1"], "--map"),
        (vec!["fly"], "fly"),
        (vec![], "Usage"),
    ] {
        let o = ohaca(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(o.stdout.is_empty(), "{args:?}");
        assert!(err.contains(want), "{args:?}: {want} not in {err}");
        if !args.is_empty() {
            assert_eq!(err.lines().count(), 1, "{args:?}: one line: {err}");
            assert!(err.starts_with("error: "), "{err}");
        }
    }
}

#[test]
fn help_and_version() {
    let o = ohaca(&["plan", "--help"]);
    assert_eq!(o.status.code(), Some(0));
    let out = stdout(&o);
    for flag in [
        "--map",
        "--start",
        "--goal",
        "--json",
        "--algorithm",
        "--seed",
        "--ants",
        "--iterations",
        "--alpha",
        "--beta",
        "--rho",
        "--q",
        "--a",
        "--xi",
        "--tau0",
        "--tau-min",
        "--tau-max",
        "--patience",
        "--dead-end",
        "--smoothing",
    ] {
        assert!(out.contains(flag), "{flag} missing from help");
    }
    assert!(out.contains("[default: 12, paper: 50]"), "{out}");
    assert_eq!(ohaca(&["--version"]).status.code(), Some(0));
}

#[test]
fn directory_and_binary_garbage_never_panic() {
    let dir = tempfile::tempdir().unwrap();
    let garbage: Vec<u8> = (0..4096u32)
        .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
        .collect();
    let g = dir.path().join("garbage.map");
    std::fs::write(&g, &garbage).unwrap();
    let t = dir.path().join("garbage.txt");
    std::fs::write(&t, &garbage).unwrap();
    let mut header_then_garbage = b"type octile\nheight 4\nwidth 4\nmap\n".to_vec();
    header_then_garbage.extend_from_slice(&[0xff, 0xfe, b'.', b'.', b'\n']);
    let h = dir.path().join("half.map");
    std::fs::write(&h, &header_then_garbage).unwrap();
    for p in [dir.path(), g.as_path(), t.as_path(), h.as_path()] {
        let o = ohaca(&[
            "plan",
            "--map",
            p.to_str().unwrap(),
            "--start",
            "0,0",
            "--goal",
            "1,1",
        ]);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{}: {err}", p.display());
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(&p.display().to_string()), "{err}");
    }
}

#[test]
fn plans_on_every_shipped_map() {
    for (name, goal) in [
        ("simple-18.map", "17,17"),
        ("complex-26.map", "25,25"),
        ("classic-20.map", "19,19"),
        ("movingai/random-32-32-10.map", "31,31"),
    ] {
        let path = maps_dir().join(name);
        let map = Map::load(&path).unwrap();
        let (o, v) = plan_json(&path, "0,0", goal, &[]);
        // The random Moving AI map may wall (0,0) or the corner in; both outcomes are legal,
        // but the exit code must agree with the report.
        let code = o.status.code();
        match code {
            Some(0) => {
                assert_eq!(v["found"], true);
                let raw: Vec<Point> = v["raw"].as_array().unwrap().iter().map(pt).collect();
                check_raw_path(&map, &raw);
            }
            Some(1) => assert_eq!(v["found"], false),
            Some(2) => assert!(stderr(&o).contains("obstacle"), "{name}"),
            _ => panic!("{name}: {code:?}"),
        }
    }
}

/// A 512x512 map with long walls (each with a door) planned from corner to corner with the
/// default parameters: the planner's buffers (about 14 MiB) live on the heap.
#[test]
fn plans_on_a_512x512_map() {
    let map = Map::from_fn(512, 512, |x, y| {
        (x % 64 == 32 && !(20..26).contains(&(y % 64)))
            || (y % 64 == 48 && !(50..56).contains(&(x % 64)))
    });
    let dir = tempfile::tempdir().unwrap();
    for (file, text) in [("big.map", map.to_moving_ai()), ("big.txt", map.to_text())] {
        let path = dir.path().join(file);
        std::fs::write(&path, text).unwrap();
        assert_eq!(Map::load(&path).unwrap(), map);
        let (o, v) = plan_json(&path, "0,0", "511,511", &[]);
        assert_eq!(o.status.code(), Some(0), "{file}: {}", stderr(&o));
        assert_eq!(v["found"], true);
        let raw: Vec<Point> = v["raw"].as_array().unwrap().iter().map(pt).collect();
        assert_eq!(raw.first(), Some(&Point::new(0, 0)));
        assert_eq!(raw.last(), Some(&Point::new(511, 511)));
        check_raw_path(&map, &raw);
        // Octile distance corner to corner is 511 * sqrt 2.
        assert!(v["raw_length"].as_f64().unwrap() >= 511.0 * 2f64.sqrt() - 1e-2);
    }
}
