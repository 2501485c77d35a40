//! The map: its bit layout ([`bits`]), the eight moves, the occupancy grid and its rules, sets of cells at one bit a cell,
//! and the dead-end pruning that runs on the map before any ant walks.
//!
//! Owns everything that is a property of the map alone; nothing here knows about ants, pheromone
//! or paths. Each module is also reachable at the crate root (`ohaca::grid`, `ohaca::bitmap`, ...).

pub mod bitmap;
pub mod bits;
pub mod dir;
pub mod grid;
pub mod prune;
