//! # ohaca-host — the host side of ohaca
//!
//! The library behind the `ohaca` command-line tool, reusable by the tests and by every
//! subcommand (`plan`, `render`, `experiment`, `send`; `bench` later). It runs the `no_std`
//! core ([`ohaca`]) under std: it loads maps from files, lends the planner heap buffers instead of
//! a fixed-size `Storage` (the core's [`HeapStorage`], feature `alloc`), and turns results into a
//! stable JSON report or an ASCII picture.
//!
//! Modules, one concept each:
//!
//! | module | owns |
//! | --- | --- |
//! | [`map`] | every map format (Moving AI, text grid, ROS YAML, image), one `load`, the metric frame, inflation, resampling and fitting a device |
//! | [`args`] | command-line values shared by subcommands: `X,Y` points and the planner flags |
//! | [`board`] | `--board`: the host core planning in a board's buffers and layout, bit for bit the device's |
//! | [`plan_map`](mod@plan_map) | one planning run on a loaded map, timed, as a [`output::PlanReport`] |
//! | [`output`] | the JSON report (a stable contract) and the ASCII renderer |
//! | [`exit`] | the tool's exit codes |
//! | [`input`] | the map flags of `plan`/`render`/`experiment`/`send`: the map prepared, start/goal in cells or metres |
//! | [`trace`] | a planning run that keeps its convergence curve and final pheromone |
//! | [`draw`] | pictures: the map with paths (and pheromone), the convergence chart; SVG or PNG |
//! | [`experiment`] | the paper's experiments: many seeds per algorithm, CSV, summary, pictures |
//! | [`link`] | the firmware link: a blocking protocol client over TCP or a serial port |
//! | [`strip`] | pictures of a replanning drive: a PNG strip, an animated GIF |
//! | [`dstar`] | D* Lite, the incremental exact baseline of replanning: a persistent search on the core's 8-connected grid, and a drive of `replan` replayed into it |
//! | [`replan`] | replanning scenarios: a robot driving while cells change, warm or cold replans on the core or a device |
//! | [`stream`] | a robot's costmap stream: small obstacles coming and going at a fixed rate, a replan after each, and what it cost |
//! | [`rng`] | SplitMix64, the seeded generator of the simulations and tests |
//! | [`ros`] | `ohaca ros`: a ROS 2 node (map, goal and pose topics, `/plan`, Nav2's `compute_path_to_pose`) |
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
pub mod board;
pub mod draw;
pub mod dstar;
pub mod exit;
pub mod experiment;
pub mod input;
pub mod link;
pub mod map;
pub mod output;
pub mod plan_map;
pub mod replan;
pub mod rng;
pub mod ros;
pub mod stream;
pub mod strip;
pub mod trace;

pub use args::{parse_point, ParamArgs, Preset};
pub use map::{Map, MapError};
pub use ohaca::heap::HeapStorage;
pub use output::PlanReport;
pub use plan_map::{plan_map, plan_map_in, plan_map_on, PlanError};
