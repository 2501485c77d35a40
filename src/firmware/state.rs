//! State shared between the tasks: the map buffer and the size of the map it holds, the cancel
//! generation, the plan queue, the reply channel, the counters.
//!
//! The map lives once, in [`MAP`] (32 KiB for 512x512 cells, 1 bit a cell): the planner holds
//! its lock for a whole plan and reads it in place (no copy); the receiver writes uploads and
//! cell updates into it. A writer first bumps [`GENERATION`] (cancelling the running plan, which
//! sees it at its next yield and releases the lock: a writer waits at most one planner
//! iteration, or the sending of a path already started), and an upload first clears
//! [`MAP_SIZE`] (no map until its last chunk), so a plan never reads a half-written or changed
//! map.

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex as BlockingMutex;
use embassy_sync::channel::Channel;
use embassy_sync::mutex::Mutex;

use ohaca::grid::Point;
use ohaca::planner::{Memory, Params};
use ohaca::protocol::{MapLimits, Reply, StatsReply};

use super::board::{self, Board};
use super::buffers::{MapLock, MAP_INIT};
use super::stack;

/// The planner's storage (`super::buffers`): nothing of its own on the small boards (its
/// buffers are carved out of [`MAP`]'s arena per plan), buffers spread over the RAM regions on
/// the STM32H743 and its twin.
pub use super::buffers::PlanStorage;
/// The board's limits (`super::limits`), here too for the tasks that share the state.
pub use super::limits::{MAP_BYTES, MAX_CELLS, MAX_SIDE, PLAN_CELLS, PLAN_STEPS};
/// The map limits, for [`ohaca::protocol::Upload`].
pub const LIMITS: MapLimits = MapLimits {
    max_cells: MAX_CELLS as u32,
    max_side: MAX_SIDE,
};
/// Plan requests that can wait while one runs.
pub const PLAN_QUEUE: usize = 4;
/// Replies waiting for the transmitter.
pub const OUT_QUEUE: usize = 4;

pub type Raw = CriticalSectionRawMutex;

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
    /// ([`COLONY`]).
    pub warm: bool,
}

/// A small reply (every reply but a path) for the transmitter: the request id and the reply.
pub struct Out(pub u32, pub Reply<'static>);

/// The UART's transmitting half, shared by the transmitter (small replies) and the planner (which
/// streams each path straight into it, a piece at a time): whoever holds the lock sends one whole
/// frame, so frames never interleave.
pub type TxPort = Mutex<Raw, board::Tx>;

/// The map buffer, packed as `ohaca::grid` stores a map; [`MAP_SIZE`] says what it holds. On the
/// small boards the first [`MAP_BYTES`] bytes of the arena the planner's buffers share (103,424
/// bytes in all, `super::buffers`); on the STM32H743 and its twin a static of the AXI SRAM that
/// `super::buffers::take` lends to this lock at boot.
pub static MAP: MapLock = Mutex::new(MAP_INIT);
/// Width and height of the complete map in [`MAP`]; `None`: no map (none yet, an upload in
/// progress, or a failed one).
static MAP_SIZE: BlockingMutex<Raw, Cell<Option<(u16, u16)>>> = BlockingMutex::new(Cell::new(None));
/// What the pheromone in the planner's storage belongs to, and the cells changed since
/// (`ohaca::planner::Memory`). Read and written only while holding [`MAP`]'s lock: by the
/// planner around `Run::warm`, by the receiver when it writes the map, so a change can never slip
/// between a plan's start and its record.
static COLONY: BlockingMutex<Raw, Cell<Memory>> = BlockingMutex::new(Cell::new(Memory::new()));
/// Bumped by `Cancel`, by every map upload and by every cell update: plans received under an
/// older value are cancelled.
pub static GENERATION: AtomicU32 = AtomicU32::new(0);
pub static PLANNING: AtomicBool = AtomicBool::new(false);
pub static JOBS: Channel<Raw, Job, PLAN_QUEUE> = Channel::new();
pub static OUT: Channel<Raw, Out, OUT_QUEUE> = Channel::new();
static STATS: BlockingMutex<Raw, Cell<StatsReply>> = BlockingMutex::new(Cell::new(StatsReply {
    uptime: 0,
    boots: 0,
    frames_ok: 0,
    frames_bad: 0,
    rx_overruns: 0,
    rx_bytes: 0,
    tx_frames: 0,
    plans: 0,
    plan_errors: 0,
    cancelled: 0,
    busy: 0,
    last_plan_ticks: 0,
    map_width: 0,
    map_height: 0,
    queued: 0,
    planning: false,
    stack_peak: 0,
}));

/// Update the counters.
pub fn count(f: impl FnOnce(&mut StatsReply)) {
    STATS.lock(|c| {
        let mut s = c.get();
        f(&mut s);
        c.set(s);
    });
}

/// The counters with the live fields filled in.
pub fn stats() -> StatsReply {
    let mut s = STATS.lock(Cell::get);
    s.uptime = embassy_time::Instant::now().as_ticks();
    s.rx_overruns = s.rx_overruns.wrapping_add(board::Active::rx_overruns());
    if let Some((w, h)) = map_size() {
        (s.map_width, s.map_height) = (w, h);
    }
    s.queued = u8::try_from(JOBS.len()).unwrap_or(u8::MAX);
    s.planning = PLANNING.load(Ordering::Relaxed);
    s.stack_peak = stack::peak();
    s
}

/// The size of the map in [`MAP`], if it holds a complete one.
pub fn map_size() -> Option<(u16, u16)> {
    MAP_SIZE.lock(Cell::get)
}

/// Record what [`MAP`] holds.
pub fn set_map_size(size: Option<(u16, u16)>) {
    MAP_SIZE.lock(|c| c.set(size));
}

/// The colony memory (call with [`MAP`]'s lock held).
pub fn colony() -> Memory {
    COLONY.lock(Cell::get)
}

/// Replace the colony memory (call with [`MAP`]'s lock held).
pub fn set_colony(m: Memory) {
    COLONY.lock(|c| c.set(m));
}

/// True if plans received under `generation` are cancelled.
pub fn cancelled(generation: u32) -> bool {
    GENERATION.load(Ordering::Acquire) != generation
}

/// Cancel the running plan and every queued one.
pub fn cancel_all() {
    GENERATION.fetch_add(1, Ordering::AcqRel);
}

/// Send a small reply (waits while the transmitter is behind).
pub async fn reply(id: u32, r: Reply<'static>) {
    OUT.send(Out(id, r)).await;
}

/// Boot counter in RAM that survives a reset but not a power cycle (`.uninit` is not zeroed by
/// the startup code): a magic word marks it valid.
#[link_section = ".uninit.ohaca.boot"]
static BOOT: [AtomicU32; 2] = [AtomicU32::new(0), AtomicU32::new(0)];
const BOOT_MAGIC: u32 = u32::from_le_bytes(*b"OHCA");

/// Count this boot; returns boots since power-on (1 after a cold start).
pub fn count_boot() -> u32 {
    let [magic, n] = &BOOT;
    if magic.load(Ordering::Relaxed) != BOOT_MAGIC {
        magic.store(BOOT_MAGIC, Ordering::Relaxed);
        n.store(0, Ordering::Relaxed);
    }
    let boots = n.load(Ordering::Relaxed).wrapping_add(1);
    n.store(boots, Ordering::Relaxed);
    count(|s| s.boots = boots);
    boots
}
