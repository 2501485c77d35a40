//! The colony: what the ants read and write while they walk. The pheromone table, the distance
//! heuristic and goal attraction, one ant's walk, the tightening of a finished walk, the
//! per-iteration pheromone update, the iteration's weight table, and the coarse route whose sub-goals the potential field pulls
//! towards on large maps (it is laid over the pheromone's blocks, so it lives here).
//!
//! Depends on [`crate::map`] only (and the crate's shared leaves); the polish and the planner
//! depend on it, never the other way round. Each module is also reachable at the crate root
//! (`ohaca::ant`, `ohaca::pheromone`, ...).

pub mod ant;
pub mod heuristic;
pub mod pheromone;
pub mod route;
pub mod tabu;
pub mod tighten;
pub mod update;
pub mod weights;
