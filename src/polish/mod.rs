//! The polish: what turns the colony's raw path into the answer. Line-of-sight smoothing, the
//! taut pull over the cell centres, the exact any-angle corridor (small maps) and the windowed
//! local search (refine).
//!
//! Depends on [`crate::map`] and [`crate::colony`]'s pheromone storage; only the planner depends
//! on it. Each module is also reachable at the crate root (`ohaca::smoothing`, `ohaca::refine`, ...).

pub mod corridor;
pub mod links;
pub mod refine;
pub mod smoothing;
pub mod sweep;
pub mod taut;
