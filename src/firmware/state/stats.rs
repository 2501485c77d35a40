//! The counters a `Stats` request reads ([`stats`]), and the boot counter that survives a reset.

use core::cell::Cell;
use core::sync::atomic::{AtomicU32, Ordering};

use embassy_sync::blocking_mutex::Mutex as BlockingMutex;

use ohaca::protocol::StatsReply;

use super::jobs::{JOBS, PLANNING};
use super::map::map_size;
use super::Raw;
use crate::firmware::board::{self, Board};
use crate::firmware::stack;

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
    replies_dropped: 0,
    parted: 0,
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
