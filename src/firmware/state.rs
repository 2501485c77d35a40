//! State shared between the tasks: the active map, the cancel generation, the plan queue, the
//! reply channel, the counters.

use core::cell::Cell;
use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex;
use embassy_sync::blocking_mutex::Mutex as BlockingMutex;
use embassy_sync::channel::Channel;
use embassy_sync::mutex::Mutex;

use ohaca::grid::Point;
use ohaca::planner::Params;
use ohaca::protocol::{Reply, StatsReply};

use super::board::{self, Board};
use super::stack;

/// Largest map, in cells (32 x 32).
pub const CELLS: usize = 1024;
/// Bytes of the largest packed map.
pub const MAP_BYTES: usize = CELLS.div_ceil(8);
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
}

/// The map plans run on. The planner copies it when a plan starts, so the receiver may replace
/// it at any time (which also bumps [`GENERATION`]).
#[derive(Clone, Copy)]
pub struct ActiveMap {
    pub width: u16,
    pub height: u16,
    pub bits: [u8; MAP_BYTES],
}

/// A small reply (every reply but a path) for the transmitter: the request id and the reply.
pub struct Out(pub u32, pub Reply<'static>);

/// The UART's transmitting half, shared by the transmitter (small replies) and the planner (which
/// streams each path straight into it, a piece at a time): whoever holds the lock sends one whole
/// frame, so frames never interleave.
pub type TxPort = Mutex<Raw, board::Tx>;

pub static MAP: BlockingMutex<Raw, Cell<Option<ActiveMap>>> = BlockingMutex::new(Cell::new(None));
/// Bumped by `Cancel` and by every new map: plans received under an older value are cancelled.
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
    if let Some(m) = MAP.lock(Cell::get) {
        (s.map_width, s.map_height) = (m.width, m.height);
    }
    s.queued = u8::try_from(JOBS.len()).unwrap_or(u8::MAX);
    s.planning = PLANNING.load(Ordering::Relaxed);
    s.stack_peak = stack::peak();
    s
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
