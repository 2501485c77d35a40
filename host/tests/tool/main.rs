//! The `ohaca` host tool end to end, without the firmware: one test binary (`cargo test ...
//! --test tool`), one module per command or concern, so the dependency graph is linked once
//! rather than once per file. Run one module with a filter, e.g. `--test tool -- render::`.

mod common;

// The `ohaca` binary: JSON contract, exit codes, bad inputs, a 512 x 512 map.
mod cli;
// D* Lite (`ohaca_host::dstar`) against the exact A*.
mod dstar;
// `ohaca experiment`: every output file, determinism across thread counts.
mod experiment;
// `ohaca plan --format json|csv|text`.
mod plan_format;
// `ohaca render`: SVG and PNG, overlays, the heat map.
mod render;
// `ohaca ros`'s `compute_path_to_pose` action over RustDDS on loopback.
mod ros_action;
// ROS map_server maps (YAML + PGM/PNG) end to end.
mod ros_maps;
// Hand-written tables (docs/PROTOCOL.md, the Python client) against the code.
mod tables;
