//! What the tasks share, one file per thing owned:
//!
//! | file | owns |
//! | --- | --- |
//! | `map` | the map buffer and its lock, the map's size, the colony memory |
//! | `jobs` | the plan queue, and the counters that cancel plans and stop paths being sent |
//! | `replies` | the UART's transmitting half, the small-reply queue and the request window |
//! | `stats` | the counters of `Stats`, the boot counter |
//!
//! Nothing here waits but [`replies::wait_for_small`] and the map's lock; the receiver takes
//! neither while bytes arrive for longer than one planner piece (`crate::firmware::rx`).

mod jobs;
mod map;
mod replies;
mod stats;

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;

use ohaca::protocol::MapLimits;

pub use jobs::{
    cancel_all, cancelled, stop_all, stopped, stops, Job, GENERATION, JOBS, PLANNING, PLAN_QUEUE,
};
pub use map::{map_size, set_map_size, MAP};
pub use replies::{
    reply, small_sent, wait_for_small, Out, Small, TxPort, OUT, SENDING_SMALL, WINDOW,
};
pub use stats::{count, count_boot, stats};

/// The planner's storage (`super::buffers`): nothing of its own on the small boards (its
/// buffers are carved out of [`MAP`]'s arena per plan), buffers spread over the RAM regions on
/// the STM32H743 and its twin.
pub use super::buffers::PlanStorage;
/// The board's limits (`super::limits`), here too for the tasks that share the state.
pub use super::limits::{MAP_BYTES, MAX_CELLS, MAX_SIDE, PLAN_CELLS, PLAN_STEPS, RX_RING};
/// The map limits, for [`ohaca::protocol::Upload`].
pub const LIMITS: MapLimits = MapLimits {
    max_cells: MAX_CELLS as u32,
    max_side: MAX_SIDE,
};

pub type Raw = CriticalSectionRawMutex;
