//! Whole-map searches that stand beside the planner: the exact A* baseline (4 bits a cell plus a
//! heap), which the tests and benchmarks measure the planner against; the planner does not use it.
//! And the searches' shared building blocks: the one binary heap ([`heap`]) that every open list
//! of the crate (and the host's D* Lite) is built on, and the step costs ([`cost`]) they all
//! count in.
//!
//! Depends on [`crate::map`] only. Also reachable at the crate root (`ohaca::astar`).

pub mod astar;
pub mod cost;
pub mod heap;
