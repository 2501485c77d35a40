//! `ohaca experiment` end to end: every output file, determinism across thread counts with
//! `--no-timing`, bad input.

use crate::common;

use std::path::Path;

use common::*;

fn experiment(out: &Path, threads: &str, extra: &[&str]) -> std::process::Output {
    let simple = maps_dir().join("simple-18.map");
    let mut a = vec![
        "experiment",
        "--map",
        simple.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "17,17",
        "--runs",
        "4",
        "--ants",
        "12",
        "--iterations",
        "15",
        "--out",
        out.to_str().unwrap(),
    ];
    a.extend_from_slice(extra);
    let o = ohaca_env(&a, &[("RAYON_NUM_THREADS", threads)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    o
}

const FILES: [&str; 13] = [
    "results.csv",
    "summary.md",
    "convergence.csv",
    "convergence.svg",
    "convergence.png",
    "path-aca.svg",
    "path-aca.png",
    "path-paca.svg",
    "path-paca.png",
    "path-haca.svg",
    "path-haca.png",
    "path-ohaca.svg",
    "path-ohaca.png",
];

#[test]
fn byte_identical_for_one_and_two_threads_without_timing() {
    let dir = tempfile::tempdir().unwrap();
    let (one, two) = (dir.path().join("one"), dir.path().join("two"));
    let o1 = experiment(&one, "1", &["--no-timing"]);
    let o2 = experiment(&two, "2", &["--no-timing"]);
    assert_eq!(stdout(&o1), stdout(&o2));
    for f in FILES {
        let a = std::fs::read(one.join(f)).unwrap_or_else(|e| panic!("{f}: {e}"));
        let b = std::fs::read(two.join(f)).unwrap();
        assert!(!a.is_empty(), "{f}");
        assert!(a == b, "{f} differs between 1 and 2 threads");
    }
    // No stray files.
    let mut names: Vec<String> = std::fs::read_dir(&one)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    let mut want: Vec<String> = FILES.iter().map(|s| s.to_string()).collect();
    want.sort();
    assert_eq!(names, want);
}

#[test]
fn files_have_the_promised_content() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("exp");
    let o = experiment(&out, "2", &["--algorithms", "haca,ohaca", "--seed", "3"]);
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("algorithm,seed,found,raw_length,length,turns,best_iteration,iterations,elapsed_us")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 8);
    let keys: Vec<(&str, &str)> = rows.iter().map(|r| (r[0], r[1])).collect();
    assert_eq!(
        keys,
        [
            ("haca", "3"),
            ("haca", "4"),
            ("haca", "5"),
            ("haca", "6"),
            ("ohaca", "3"),
            ("ohaca", "4"),
            ("ohaca", "5"),
            ("ohaca", "6")
        ]
    );
    for r in &rows {
        assert_eq!(r.len(), 9);
        assert_eq!(r[2], "true");
        let raw: f64 = r[3].parse().unwrap();
        let len: f64 = r[4].parse().unwrap();
        assert!(len <= raw + 1e-4);
        assert!(raw >= 26.97, "no shorter than the 8-connected optimum");
        let _: u64 = r[8].parse().unwrap();
    }
    // Each run matches `ohaca plan` with the same seed.
    let simple = maps_dir().join("simple-18.map");
    let p = ohaca(&[
        "plan",
        "--map",
        simple.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "17,17",
        "--ants",
        "12",
        "--iterations",
        "15",
        "--algorithm",
        "ohaca",
        "--seed",
        "5",
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&stdout(&p)).unwrap();
    let row = rows
        .iter()
        .find(|r| r[0] == "ohaca" && r[1] == "5")
        .unwrap();
    assert_eq!(
        row[4].parse::<f32>().unwrap(),
        v["length"].as_f64().unwrap() as f32
    );
    assert_eq!(row[5], v["turns"].to_string());
    assert_eq!(row[7], v["iterations"].to_string());
    // The summary: one row per algorithm, printed and written.
    let md = std::fs::read_to_string(out.join("summary.md")).unwrap();
    assert!(md.contains("seeds 3..=6"), "{md}");
    assert!(md.contains("| HACA | 4/4 (100 %) |"), "{md}");
    assert!(md.contains("| OHACA | 4/4 (100 %) |"), "{md}");
    assert!(!md.contains("| ACA |"));
    assert!(md.contains(stdout(&o).trim()), "stdout is the table");
    // Convergence: one column per algorithm, never increasing.
    let conv = std::fs::read_to_string(out.join("convergence.csv")).unwrap();
    assert!(conv.starts_with("iteration,haca,ohaca\n"));
    let col: Vec<f64> = conv
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(1).unwrap().parse().unwrap())
        .collect();
    assert!(
        !col.is_empty() && col.windows(2).all(|w| w[1] <= w[0] + 1e-9),
        "{conv}"
    );
    let png = image::open(out.join("convergence.png")).unwrap();
    // 960 x 600, wider only if the title (it names the map file) would not fit.
    assert_eq!(png.height(), 600);
    assert!(png.width() >= 960, "{}", png.width());
    assert!(std::fs::read_to_string(out.join("convergence.svg"))
        .unwrap()
        .starts_with("<svg"));
    assert!(image::open(out.join("path-ohaca.png")).is_ok());
}

#[test]
fn dying_ants_can_fail_and_bad_input_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("die");
    experiment(
        &out,
        "2",
        &["--dead-end", "die", "--algorithms", "aca", "--no-timing"],
    );
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    for l in csv.lines().skip(1) {
        let f: Vec<&str> = l.split(',').collect();
        if f[2] == "false" {
            assert_eq!(&f[3..7], ["", "", "", ""], "{l}");
        }
    }
    let simple = maps_dir().join("simple-18.map");
    let o = ohaca(&[
        "experiment",
        "--map",
        simple.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "40,40",
        "--out",
        dir.path().join("x").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(
        stderr(&o).contains("goal is outside the map"),
        "{}",
        stderr(&o)
    );
    assert!(
        !dir.path().join("x").exists(),
        "nothing written for bad input"
    );
    let o = ohaca(&[
        "experiment",
        "--map",
        simple.to_str().unwrap(),
        "--start",
        "0,0",
        "--goal",
        "17,17",
        "--runs",
        "0",
        "--out",
        dir.path().join("y").to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn progress_bar_only_on_a_terminal() {
    let dir = tempfile::tempdir().unwrap();
    // Not a terminal (a pipe): nothing on stderr.
    let o = experiment(&dir.path().join("pipe"), "2", &["--no-timing"]);
    assert_eq!(stderr(&o), "", "quiet when stderr is not a terminal");
    // A terminal: `script` (util-linux) runs the tool on a pseudo-terminal and copies what it
    // draws to its own stdout.
    let have_script = std::process::Command::new("script")
        .arg("--version")
        .output()
        .is_ok_and(|o| o.status.success());
    if !have_script {
        eprintln!("skipped the terminal half: no `script` command");
        return;
    }
    let simple = maps_dir().join("simple-18.map");
    let cmd = format!(
        "'{}' experiment --map '{}' --start 0,0 --goal 17,17 --runs 3 --ants 12 \
         --iterations 15 --algorithms aca --no-timing --out '{}' 2>&1 >/dev/null",
        env!("CARGO_BIN_EXE_ohaca"),
        simple.display(),
        dir.path().join("tty").display()
    );
    let o = std::process::Command::new("script")
        .args(["-qec", &cmd, "/dev/null"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    let tty = String::from_utf8_lossy(&o.stdout);
    assert!(tty.contains("/3 runs"), "a bar on the terminal: {tty:?}");
    assert!(dir.path().join("tty/results.csv").exists());
}

#[test]
fn a_one_cell_path_is_length_0_in_every_file() {
    let dir = tempfile::tempdir().unwrap();
    let map = dir.path().join("m.txt");
    std::fs::write(&map, "...\n...\n").unwrap();
    let out = dir.path().join("x");
    let o = ohaca(&[
        "experiment",
        "--map",
        map.to_str().unwrap(),
        "--start",
        "1,1",
        "--goal",
        "1,1",
        "--runs",
        "2",
        "--no-timing",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let csv = std::fs::read_to_string(out.join("results.csv")).unwrap();
    assert!(csv.contains("\nohaca,1,true,0,0,0,0,"), "{csv}");
    for f in ["results.csv", "summary.md", "convergence.csv"] {
        let text = std::fs::read_to_string(out.join(f)).unwrap();
        assert!(!text.contains("-0"), "{f}: {text}");
    }
}
