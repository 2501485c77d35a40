//! # ohaca-host — the host side of ohaca
//!
//! The library behind the `ohaca` command-line tool, reusable by the tests and by every
//! subcommand (`plan`, `render`, `experiment`, `send`; `bench` later). It runs the `no_std`
//! core ([`ohaca`]) under std: it loads maps from files, lends the planner heap buffers instead of
//! a fixed-size `Storage`, and turns results into a stable JSON report or an ASCII picture.
//!
//! Modules, one concept each:
//!
//! | module | owns |
//! | --- | --- |
//! | [`map`] | loading Moving AI `.map` files and plain text grids into an owned [`map::Map`] |
//! | [`storage`] | [`storage::HeapStorage`]: planner buffers on the heap, sized per map |
//! | [`args`] | command-line values shared by subcommands: `X,Y` points and the planner flags |
//! | [`planning`] | one planning run on a loaded map, timed, as a [`output::PlanReport`] |
//! | [`output`] | the JSON report (a stable contract) and the ASCII renderer |
//! | [`exit`] | the tool's exit codes |
//! | [`input`] | the map flags of `plan`/`render`/`experiment`: any map format, prepared, start/goal in cells or metres |
//! | [`rosmap`] | ROS `map_server` maps (YAML + PGM/PNG) and plain images as maps |
//! | [`frame`] | a map's metric frame: cell <-> metres (ROS map frame) |
//! | [`gridops`] | obstacle inflation and resampling to coarser cells |
//! | [`trace`] | a planning run that keeps its convergence curve and final pheromone |
//! | [`draw`] | pictures: the map with paths (and pheromone), the convergence chart; SVG or PNG |
//! | [`experiment`] | the paper's experiments: many seeds per algorithm, CSV, summary, pictures |
//! | [`link`] | the firmware link: a blocking protocol client over TCP or a serial port |
//!
//! ## Panic freedom
//! Like the core, nothing reachable from a file, a command line or a parameter set panics:
//! the lints `unwrap_used`, `expect_used`, `panic` and `indexing_slicing` are denied here too.
#![deny(unsafe_code)]
#![deny(missing_docs)]
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing,
    clippy::unreachable,
    clippy::todo,
    clippy::unimplemented
)]
#![cfg_attr(
    test,
    allow(
        clippy::unwrap_used,
        clippy::indexing_slicing,
        clippy::expect_used,
        clippy::panic
    )
)]

pub mod args;
pub mod draw;
pub mod exit;
pub mod experiment;
pub mod frame;
pub mod gridops;
pub mod input;
pub mod link;
pub mod map;
pub mod output;
pub mod planning;
pub mod rosmap;
pub mod storage;
pub mod trace;

pub use args::{parse_point, ParamArgs, Preset};
pub use map::{Map, MapError};
pub use output::{ParamsReport, PlanReport};
pub use planning::{plan_map, plan_map_in, PlanError};
pub use storage::HeapStorage;
