//! The map the device holds: its buffer ([`MAP`], behind the one lock the planner and the
//! receiver share, with what the planner's storage remembers of the last plan on it, the colony
//! memory `ohaca::planner::Memory`) and its size ([`MAP_SIZE`]).
//!
//! The map lives once (32 KiB for 512x512 cells, 1 bit a cell): the planner holds the lock
//! while it plans, a piece at a time, and reads the map in place (no copy); the receiver takes
//! it to write uploads and cell updates. A writer first cancels the running plan
//! (`super::jobs`), which sees it at its next yield and gives the lock up, so a writer waits at
//! most one planner piece; an upload first clears [`MAP_SIZE`] (no map until its last chunk), so
//! a plan never reads a half-written or changed map. The lock is never held across the wire:
//! the planner sends a long path a part at a time, taking the lock only to read each part
//! (`super::super::plan`).

use core::cell::Cell;

use embassy_sync::blocking_mutex::Mutex as BlockingMutex;
use embassy_sync::mutex::Mutex;

use super::Raw;
use crate::firmware::buffers::{MapLock, MAP_INIT};

/// The map buffer, packed as `ohaca::grid` stores a map; [`MAP_SIZE`] says what it holds. On the
/// small boards the first `MAP_BYTES` bytes of the arena the planner's buffers share (103,424
/// bytes in all, `crate::firmware::buffers`); on the STM32H743 and its twin a static of the AXI
/// SRAM that `crate::firmware::buffers::take` lends to this lock at boot. The colony memory lives
/// under the same lock (`MapBuf::split`): the planner reads and writes it around `Run::warm`,
/// the receiver when it writes the map, so a change can never slip between a plan's start and
/// its record.
pub static MAP: MapLock = Mutex::new(MAP_INIT);
/// Width and height of the complete map in [`MAP`]; `None`: no map (none yet, an upload in
/// progress, or a failed one).
static MAP_SIZE: BlockingMutex<Raw, Cell<Option<(u16, u16)>>> = BlockingMutex::new(Cell::new(None));

/// The size of the map in [`MAP`], if it holds a complete one.
pub fn map_size() -> Option<(u16, u16)> {
    MAP_SIZE.lock(Cell::get)
}

/// Record what [`MAP`] holds.
pub fn set_map_size(size: Option<(u16, u16)>) {
    MAP_SIZE.lock(|c| c.set(size));
}
