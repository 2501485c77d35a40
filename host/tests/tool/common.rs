//! Helpers shared by the end-to-end tests of the map, render and experiment features.
#![allow(dead_code)]

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Run the `ohaca` binary with `args` (and extra environment variables).
pub fn ohaca_env<S: AsRef<OsStr>>(args: &[S], env: &[(&str, &str)]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_ohaca"));
    c.args(args);
    for (k, v) in env {
        c.env(k, v);
    }
    c.output().expect("run the ohaca binary")
}

/// Run the `ohaca` binary with `args`.
pub fn ohaca<S: AsRef<OsStr>>(args: &[S]) -> Output {
    ohaca_env(args, &[])
}

pub fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).unwrap()
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).unwrap()
}

pub fn maps_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps")
}

/// A binary PGM (P5) of `rows` (each a slice of grey values), top row first.
pub fn pgm(rows: &[&[u8]]) -> Vec<u8> {
    let (w, h) = (rows[0].len(), rows.len());
    let mut v = format!("P5\n{w} {h}\n255\n").into_bytes();
    for r in rows {
        assert_eq!(r.len(), w);
        v.extend_from_slice(r);
    }
    v
}

/// Write `name.pgm` and `name.yaml` (with `yaml_extra` lines appended) into `dir`; returns the
/// YAML's path.
pub fn ros_map(
    dir: &Path,
    name: &str,
    rows: &[&[u8]],
    resolution: f64,
    origin: [f64; 2],
    yaml_extra: &str,
) -> PathBuf {
    std::fs::write(dir.join(format!("{name}.pgm")), pgm(rows)).unwrap();
    let yaml = dir.join(format!("{name}.yaml"));
    std::fs::write(
        &yaml,
        format!(
            "image: {name}.pgm\nresolution: {resolution}\norigin: [{}, {}, 0.0]\n\
             occupied_thresh: 0.65\nfree_thresh: 0.196\n{yaml_extra}",
            origin[0], origin[1]
        ),
    )
    .unwrap();
    yaml
}

/// Free, occupied and unknown in map_saver's convention.
pub const F: u8 = 254;
pub const O: u8 = 0;
pub const U: u8 = 205;
