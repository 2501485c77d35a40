//! One replan's dispatch, written once for every caller that keeps a colony between plans (the
//! firmware, and the host's `replan`, `plan --board` and `ros --host`): a warm request is first
//! answered from the last answer ([`super::reuse`], its repair), else it is a warm or cold
//! [`Run`] that the caller drives with [`Run::poll`] (yielding between pieces as it likes) and
//! ends with [`end`], which records what the run leaves for the next warm start.
//!
//! The caller owns the map and the [`Memory`] (on the device, under one lock) and tells the
//! memory what changes ([`Memory::cell`], [`Memory::rect`]). Nothing here allocates or panics.

use crate::error::Error;
use crate::map::grid::{Grid, Point};

use super::params::Params;
use super::plan::Plan;
use super::reuse::{answer, Fallback};
use super::run::Run;
use super::warm::Memory;
use super::workspace::Workspace;

/// How a request begins ([`begin`]).
// The run is the large variant and the usual one; there is no allocator to box it, and the
// value is taken apart at once by the caller.
#[allow(clippy::large_enum_variant)]
pub enum Begun<'g, 'a> {
    /// Answered from the last answer, without a run ([`super::Origin::Reused`] or `Repaired`).
    Answered(Plan<'a>),
    /// A run to drive to its end, then [`end`]; for a warm request, why the last answer could
    /// not answer it.
    Running(Run<'g, 'a>, Option<Fallback>),
}

/// Begin a request from `start` to `goal` on `grid` in the workspace the last plan used: warm
/// (`warm`: the last answer if it still holds, else a run that keeps the colony) or cold. The
/// run, once begun, has recorded itself in `memory`.
pub fn begin<'g, 'a>(
    grid: &'g Grid<'g>,
    (start, goal): (Point, Point),
    params: &Params,
    mut ws: Workspace<'a>,
    memory: &mut Memory,
    warm: bool,
) -> Result<Begun<'g, 'a>, Error> {
    let mut why = None;
    if warm {
        match answer(grid, start, goal, params, &mut ws, memory) {
            Ok(reused) => {
                let Workspace { best, points, .. } = ws;
                return Ok(Begun::Answered(reused.plan(best, points, memory, params)));
            }
            Err(w) => why = Some(w),
        }
    }
    let run = if warm {
        Run::warm(grid, start, goal, params, ws, memory)
    } else {
        Run::cold(grid, start, goal, params, ws, memory)
    }?;
    Ok(Begun::Running(run, why))
}

/// End a run [`begin`] gave: record in `memory` what it leaves for the next warm start (its
/// answer, pruning marks and route links), then its plan.
pub fn end<'a>(run: Run<'_, 'a>, memory: &mut Memory) -> Result<Plan<'a>, Error> {
    run.keep(memory);
    run.finish()
}
