//! One replan's dispatch, written once for every caller that keeps a colony between plans (the
//! firmware, and the host's `replan`, `plan --board` and `ros --host`):
//!
//! 1. [`answer`]: a warm request is first answered from the last answer ([`super::reuse`], its
//!    repair), without a run; [`Reused::plan`] gives the plan;
//! 2. else [`start`]: a warm or cold [`Run`], which the caller drives with [`Run::poll`]
//!    (yielding between pieces as it likes);
//! 3. [`end`]: what the run leaves for the next warm start, recorded, and its plan.
//!
//! The caller owns the map and the [`Memory`] (on the device, under one lock) and tells the
//! memory what changes ([`Memory::cell`], [`Memory::rect`]). Three calls rather than one that
//! returns either a plan or a run: the run is built in place where the caller keeps it (on the
//! device, in the planner task's future) instead of being moved there through an enum (1.2 KiB
//! more stack on the STM32F411, measured). Nothing here allocates or panics.

use crate::error::Error;
use crate::map::grid::{Grid, Point};

pub use super::plan::Reused;

use super::params::Params;
use super::plan::Plan;
use super::reuse::Fallback;
use super::run::Run;
use super::warm::Memory;
use super::workspace::Workspace;

/// The request from `start` to `goal` answered from the last answer the workspace holds, for a
/// warm request (`warm`) that no change since can block or shorten (or whose repair holds);
/// else why not (`None`: a cold request, which never reuses), and the caller [`start`]s a run.
#[inline(always)]
pub fn answer(
    grid: &Grid<'_>,
    (start, goal): (Point, Point),
    params: &Params,
    ws: &mut Workspace<'_>,
    memory: &mut Memory,
    warm: bool,
) -> Result<Reused, Option<Fallback>> {
    if !warm {
        return Err(None);
    }
    super::reuse::answer(grid, start, goal, params, ws, memory).map_err(Some)
}

/// A run for the request: warm (`warm`: it keeps the colony if the memory's is for this map and
/// goal) or cold. Once begun it has recorded itself in `memory`.
#[inline(always)]
pub fn start<'g, 'a>(
    grid: &'g Grid<'g>,
    (start, goal): (Point, Point),
    params: &Params,
    ws: Workspace<'a>,
    memory: &mut Memory,
    warm: bool,
) -> Result<Run<'g, 'a>, Error> {
    if warm {
        Run::warm(grid, start, goal, params, ws, memory)
    } else {
        Run::cold(grid, start, goal, params, ws, memory)
    }
}

/// End a run [`start`] gave: record in `memory` what it leaves for the next warm start (its
/// answer, pruning marks and route links), then its plan.
#[inline(always)]
pub fn end<'a>(run: Run<'_, 'a>, memory: &mut Memory) -> Result<Plan<'a>, Error> {
    run.keep(memory);
    run.finish()
}

impl Reused {
    /// The plan [`answer`] gave, read from the workspace it answered in.
    pub fn into_plan<'a>(self, ws: Workspace<'a>, memory: &Memory, params: &Params) -> Plan<'a> {
        let Workspace { best, points, .. } = ws;
        self.plan(best, points, memory, params)
    }
}
