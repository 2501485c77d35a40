//! `ohaca plan --format json|csv|text` and the `--json` alias.

use crate::common;

use common::*;

fn plan(extra: &[&str]) -> std::process::Output {
    let simple = maps_dir().join("simple-18.map");
    let mut a = vec![
        "plan",
        "--map",
        simple.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "17,17",
    ];
    a.extend_from_slice(extra);
    ohaca(&a)
}

#[test]
fn json_alias_is_identical() {
    let a = plan(&["--json"]);
    let b = plan(&["--format", "json"]);
    let c = plan(&["--json", "--format", "json"]);
    assert_eq!(a.status.code(), Some(0));
    let strip = |o: &std::process::Output| {
        let mut v: serde_json::Value = serde_json::from_str(&stdout(o)).unwrap();
        v["elapsed_us"] = 0.into();
        v
    };
    assert_eq!(strip(&a), strip(&b));
    assert_eq!(strip(&a), strip(&c));
}

#[test]
fn csv_is_the_waypoints_in_cells() {
    let j = plan(&["--json"]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&j)).unwrap();
    let wp: Vec<[u16; 2]> = serde_json::from_value(v["waypoints"].clone()).unwrap();
    let o = plan(&["--format", "csv"]);
    assert_eq!(o.status.code(), Some(0));
    let out = stdout(&o);
    let mut want = String::from("x,y\n");
    for [x, y] in wp {
        want.push_str(&format!("{x},{y}\n"));
    }
    assert_eq!(out, want);
    assert!(out.starts_with("x,y\n0,0\n") && out.ends_with("17,17\n"));
}

#[test]
fn text_is_the_default() {
    let a = plan(&[]);
    let b = plan(&["--format", "text"]);
    let head = |o: &std::process::Output| stdout(o).lines().take(20).collect::<Vec<_>>().join("\n");
    assert_eq!(head(&a), head(&b));
    assert!(stdout(&a).contains("S start"));
}

#[test]
fn conflicts_and_no_path() {
    let o = plan(&["--json", "--format", "csv"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("--json means --format json"),
        "{}",
        stderr(&o)
    );
    let o = plan(&["--format", "yaml"]);
    assert_eq!(o.status.code(), Some(2));
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("closed.txt");
    std::fs::write(&p, "..#..\n..#..\n..#..\n").unwrap();
    let o = ohaca(&[
        "plan",
        "--map",
        p.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "4,2",
        "--format",
        "csv",
    ]);
    assert_eq!(o.status.code(), Some(1));
    assert_eq!(stdout(&o), "x,y\n");
}
