//! Plan requests between the receiver and the planner: the queue ([`JOBS`]), and the two
//! counters that stop work a host no longer wants.
//!
//! - [`GENERATION`] is bumped by `Cancel`, by every map upload and by every cell update: a plan
//!   received under an older value is cancelled (it would plan on a map the host has changed).
//! - [`STOPS`] is bumped by `Cancel` and by a map upload only: a path already planned and being
//!   sent in parts stops (its request gets `Error Cancelled`). A cell update does not stop it:
//!   the path answers the map of its request, and a costmap streaming at 5 Hz would otherwise
//!   never let a 1-second reply through.

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use embassy_sync::channel::Channel;

use ohaca::grid::Point;
use ohaca::planner::Params;

use super::Raw;

/// Plan requests that can wait while one runs.
pub const PLAN_QUEUE: usize = 4;

/// A queued plan request: everything it needs, fixed when it was received.
#[derive(Clone, Copy)]
pub struct Job {
    pub id: u32,
    pub start: Point,
    pub goal: Point,
    pub params: Params,
    /// [`GENERATION`] when it was received; a different value now means cancelled.
    pub generation: u32,
    /// `PlanWarm`: keep the previous plan's colony if it was to the same goal on this map
    /// (`super::map::colony`).
    pub warm: bool,
}

pub static JOBS: Channel<Raw, Job, PLAN_QUEUE> = Channel::new();
pub static GENERATION: AtomicU32 = AtomicU32::new(0);
pub static STOPS: AtomicU32 = AtomicU32::new(0);
pub static PLANNING: AtomicBool = AtomicBool::new(false);

/// True if plans received under `generation` are cancelled.
pub fn cancelled(generation: u32) -> bool {
    GENERATION.load(Ordering::Acquire) != generation
}

/// Cancel the running plan and every queued one.
pub fn cancel_all() {
    GENERATION.fetch_add(1, Ordering::AcqRel);
}

/// Cancel every plan, and stop a path being sent (`Cancel`, a map upload).
pub fn stop_all() {
    cancel_all();
    STOPS.fetch_add(1, Ordering::AcqRel);
}

/// [`STOPS`] now, to compare with [`stopped`] later.
pub fn stops() -> u32 {
    STOPS.load(Ordering::Acquire)
}

/// True if a path whose sending began under `stops` must stop.
pub fn stopped(stops: u32) -> bool {
    STOPS.load(Ordering::Acquire) != stops
}
