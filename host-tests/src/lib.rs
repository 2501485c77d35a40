//! Host-side helpers for testing the `ohaca` core under std.
//!
//! Everything here is written independently of the core's own algorithms, so the tests compare
//! the core against something that could disagree with it:
//!
//! | module | what it gives the tests |
//! | --- | --- |
//! | [`maps`] | a Moving AI `.map` / `.scen` loader, ASCII maps, and the shared benchmark scenarios |
//! | [`heap`] | a heap-backed [`ohaca::Workspace`] for any map size |
//! | [`reference`] | exact optima: 8-connected Dijkstra / A*, the any-angle optimum, the segment rule |
//! | [`check`] | validators for raw paths, smoothed waypoints and reported lengths |
//! | [`gen`] | random map and endpoint generators (proptest strategies) |
//! | [`quality`] | the shared-map quality runs used by the tests and the examples |
//! | [`large`] | the large Moving AI maps of `maps/large/` and their longest scenarios |
//!
//! This crate does not depend on the host tool (`ohaca-host`): it only needs the core.

pub mod check;
pub mod gen;
pub mod heap;
pub mod large;
pub mod maps;
pub mod quality;
pub mod reference;

pub use maps::Map;
