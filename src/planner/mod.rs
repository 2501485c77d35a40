//! The planner: parameters, caller-provided storage, the iteration loop, early stopping and the
//! result.
//!
//! ```text
//! validate parameters, map size, start and goal
//! flood fill: goal unreachable -> the run ends, Err(NoPath)  (the first polls)
//! prune the cells no shortest path needs                 (prune)
//! tau = tau0 everywhere (a warm start keeps the previous run's tau, reset near map changes: warm)
//! repeat `iterations` times (or until the best has not improved for `patience` iterations):
//!     each of `ants` ants walks start -> goal            (ant)
//!     each ant that arrived deposits Q / L on its path    (update)
//!     HACA/OHACA: reward the iteration's best, punish its worst (update, wolves rule)
//!     tau = clamp((1 - rho) tau + deposits, tau_min, tau_max)
//! the best path found -> raw path; OHACA smooths it (smoothing)
//! ```
//!
//! | module | owns |
//! | --- | --- |
//! | `params` | [`Algorithm`], [`Params`] and their ranges |
//! | `workspace` | [`Workspace`], [`Buffers`], [`Storage`]: every buffer, one layout |
//! | `needs` | the phases' buffer needs, declared once (`SETUP`, `COLONY`, `POLISH` in `PHASES`), and each need's lending rule; the compact arena's links and its capacity cuts (`next_cut`) derive from them |
//! | `lend` | one typed view of the workspace per phase (setup, colony, polish), lending what a phase's needs take from the buffers idle in it |
//! | `run` | [`Run`]: the loop as a state machine ([`Run::poll`]: setup, walk + update + record, polish) |
//! | `plan` | [`Plan`], [`RawPath`], [`CurvePoint`]: the result |
//! | [`session`] | one replan's dispatch for the firmware and the host: the last answer ([`session::answer`]), else a warm or cold run ([`session::start`]), and what it leaves ([`session::end`]) |
//! | `short` | [`Shortfalls`]: the steps that ran short of scratch, in the result |
//! | `placed` | [`Placed`], [`Bases`]: where a plan lies in its workspace, to read it again later (the firmware's path parts) |
//! | `warm` | [`Memory`], [`Area`]: warm starts after map changes, and the pheromone repair |
//! | `reuse` | [`reuse`]: a replan answered with the rest of the last answer, when no change can block or shorten it; else why not ([`Fallback`]) |
//! | `repair` | the rest of the last answer with an exact detour around what blocks it, in a box sized by the change ([`longest_detour`]), reached through [`reuse`]; else why not ([`GiveUp`]) |
//! | [`arena`] | [`arena::carve`]: a map and a workspace laid out in one arena, per map size |
//!
//! [`Run::poll`] does one bounded piece of work, so the firmware can yield to its executor between
//! pieces and cancel a plan by dropping (or finishing) the run. [`plan`] runs it to the end.

pub mod arena;
mod lend;
mod needs;
mod params;
mod placed;
mod plan;
pub mod quorum;
mod repair;
mod reuse;
mod run;
pub mod session;
mod short;
mod warm;
mod workspace;

pub use params::{Algorithm, Params};
pub use placed::{Bases, Placed};
pub use plan::{CurvePoint, Origin, Plan, RawPath};
pub use repair::{
    longest_detour, GiveUp, BOX_MARGIN, MARGIN as REPAIR_MARGIN, PLACE_RADIUS, STRIDE,
};
pub use reuse::{reuse, Fallback};
pub use run::{settled, Poll, Run, Stage, REFINE_GAIN};
pub use short::Shortfalls;
pub use warm::{Area, Memory, BLOCKED, CELL_BY_CELL, FREED, REPAIR_RADIUS};
#[cfg(any(feature = "alloc", test))]
pub(crate) use workspace::OwnedBuffers;
pub use workspace::{Buffers, Storage, Workspace};

use crate::error::Error;
use crate::map::grid::{Grid, Point};

/// Plan a path: [`Run::new`], [`Run::poll`] until done, [`Run::finish`].
pub fn plan<'a>(
    grid: &Grid<'_>,
    start: Point,
    goal: Point,
    params: &Params,
    ws: Workspace<'a>,
) -> Result<Plan<'a>, Error> {
    // The run borrows the grid only while it runs; the plan keeps the workspace's buffers.
    let grid = *grid;
    let mut run = Run::new(&grid, start, goal, params, ws)?;
    while let Poll::Working(_) = run.poll() {}
    run.finish()
}

#[cfg(test)]
mod tests;
