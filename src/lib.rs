//! # ohaca — the Optimized Hybrid Ant Colony planner
//!
//! A `no_std`, allocation-free implementation of the path planner of *An Optimized Hybrid Ant
//! Colony Algorithm for Robot Path Planning* (OHACA) and of the three variants the paper compares
//! it with (ACA, PACA, HACA). The same code runs on a Cortex-M4F (the firmware in `src/main.rs`)
//! and under std on a PC (the `ohaca` host tool and the tests), and gives bit-identical results on
//! both: every float function comes from [`libm`], and the random numbers from a local
//! [`rng::Xoshiro128pp`].
//!
//! The files are grouped by phase: [`map`] (the map and what is known of it before any ant
//! walks), [`colony`] (the ants and their memory), [`polish`] (what turns the raw path into the
//! answer), [`search`] (the exact A* beside the planner), then [`planner`] which drives them all;
//! [`board`], `protocol` and the firmware stand apart. Each module below is also at the crate
//! root. Modules, one concept each:
//!
//! | module | owns |
//! | --- | --- |
//! | [`dir`] | the eight moves: direction codes and their offsets |
//! | [`grid`] | the occupancy map, cells, the no-corner-cutting rule, reachability |
//! | [`bitmap`] | sets of cells at one bit per cell (tabu lists, pruned cells) |
//! | [`prune`] | dead-end pruning: the cells no shortest path needs |
//! | [`route`] | the coarse route whose sub-goals the potential field pulls towards on large maps: the blocks' links, and a search over them bounded by the plan |
//! | [`geometry`] | path lengths and the segment rule used by smoothing and path checks |
//! | [`heuristic`] | the distance heuristic and the goal attraction of the potential field |
//! | [`pheromone`] | the pheromone table: storage, evaporation, deposit, clamping |
//! | [`ant`] | one ant's walk: the transition rule, tabu list, backtracking (or dying) |
//! | [`tighten`] | path tightening: a finished ant path straightened before the pheromone update |
//! | [`update`] | the per-iteration pheromone update: classic deposit and the wolves rule |
//! | [`smoothing`] | line-of-sight smoothing of the raw ant path |
//! | [`taut`] | the smoothed path pulled taut over the cell centres around it |
//! | [`corridor`] | the exact any-angle path through the cells around a smoothed path (small maps) |
//! | [`refine`] | local search: the exact shortest path in a window sliding along a raw path |
//! | [`astar`] | the exact A* baseline: a whole-map search in 4 bits a cell plus a heap (not used by the planner) |
//! | [`search::heap`] | the one binary min-heap every open list is built on (A*, the route, the refine window) |
//! | [`search::cost`] | the step costs of every integer search: the exact scale and the route's coarse one |
//! | [`planner`] | parameters, caller-provided storage, the iteration loop and the result; warm starts, reused and repaired answers |
//! | [`board`] | what each board's firmware holds (cells, longest path, buffer layout), described once for the firmware and the host |
//! | `heap` | (feature `alloc`) the planner's storage on the heap, sized at run time |
//! | `protocol` | (feature `protocol`) the wire protocol between a host and the firmware |
//! | [`rng`] | the small seedable generator every platform shares |
//! | [`error`] | the error enum |
//!
//! ## Features
//! None is needed to plan. `serde` derives `Serialize`/`Deserialize` for [`Params`] and its
//! enums (values by their lower-case names, `"ohaca"`, `"backtrack"`, `"shortest"`): the one
//! parameter table the protocol and the host tool's JSON both use. `protocol` adds the wire
//! protocol (and `serde`); both firmware boards turn it on. `alloc` adds `heap::HeapStorage`.
//! `defmt` adds `defmt::Format` impls.
//!
//! ## Panic freedom
//! Nothing reachable from a map, a start/goal pair or a parameter set panics: indexing goes
//! through `get`, and integer arithmetic is `checked_*` where an input can make it overflow,
//! `saturating_*` for counters and `wrapping_*` only where the value is bounded by construction
//! (map coordinates are `u16`, so every cell index fits a 32-bit `usize`). The clippy lints
//! `unwrap_used`, `expect_used`, `panic`, `indexing_slicing` and `arithmetic_side_effects` are
//! denied for the whole crate.
//!
//! ## Example
//! ```
//! use ohaca::{grid::Grid, planner::{plan, Params, Storage}, grid::Point};
//!
//! // 4x3 map, one wall cell in the middle ('#').
//! let map = "....\n.#..\n....";
//! let mut bits = [0u8; 2];
//! for (y, row) in map.lines().enumerate() {
//!     for (x, c) in row.chars().enumerate() {
//!         if c == '#' { let i = y * 4 + x; bits[i / 8] |= 1 << (i % 8); }
//!     }
//! }
//! let grid = Grid::new(4, 3, &bits).unwrap();
//! // Storage for maps up to 32 cells (1 bit-set word), ant paths of up to 15 steps, 32 links and
//! // the move table; a firmware puts this in a `static`.
//! let mut storage: Storage<1, 16, 32, 32> = Storage::new();
//! let plan = plan(&grid, Point::new(0, 0), Point::new(3, 2), &Params::default(),
//!                 storage.workspace()).unwrap();
//! assert_eq!(plan.raw().next(), Some(Point::new(0, 0)));
//! assert_eq!(plan.waypoints().last(), Some(&Point::new(3, 2)));
//! ```
#![cfg_attr(not(test), no_std)]
#![deny(unsafe_code)]
#![deny(missing_docs)]
#![deny(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::indexing_slicing,
    clippy::arithmetic_side_effects,
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
        clippy::panic,
        clippy::arithmetic_side_effects
    )
)]

#[cfg(any(feature = "alloc", test))]
extern crate alloc;

pub(crate) mod fmt;
mod named;

pub mod board;
pub mod colony;
pub mod error;
pub mod geometry;
#[cfg(any(feature = "alloc", test))]
pub mod heap;
pub mod map;
pub mod planner;
pub mod polish;
#[cfg(feature = "protocol")]
pub mod protocol;
pub mod rng;
pub mod search;

// Every phase's modules at the crate root as well: `ohaca::grid`, `ohaca::ant`, ... are the paths
// the host, the tests, the examples and the fuzz targets use, and the ones the code inside the
// crate uses (`crate::map::grid`); the folders above are where the files live.
pub use colony::{ant, heuristic, pheromone, route, tabu, tighten, update, weights};
pub use map::{bitmap, dir, grid, prune};
pub use planner::quorum;
pub use polish::{corridor, links, refine, smoothing, taut};
pub use search::astar;

#[cfg(test)]
mod testutil;

pub use ant::DeadEnd;
pub use error::Error;
pub use grid::{Grid, Point};
pub use planner::{
    plan, Algorithm, Buffers, CurvePoint, Params, Plan, RawPath, Run, Storage, Workspace,
};
pub use smoothing::SmoothingKind;
