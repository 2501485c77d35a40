//! An embassy time driver on SysTick: 1 tick = 1 µs.
//!
//! SysTick runs from the 25 MHz core clock and interrupts once a millisecond (25 000 cycles);
//! `now` is milliseconds counted by the interrupt plus the elapsed part of the current one read
//! from the counter, divided down to microseconds. The timer queue is checked on every
//! interrupt, so timers fire with 1 ms granularity.
//!
//! Under `qemu-system-arm -icount shift=0` the guest's clocks are virtual and advance exactly
//! 1 ns per executed instruction while the CPU runs, so 1 tick = 1 µs = 1000 instructions.

use core::cell::{Cell, RefCell};

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::{SCB, SYST};
use cortex_m_rt::exception;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex as Raw;
use embassy_sync::blocking_mutex::Mutex;
use embassy_time_driver::Driver;
use embassy_time_queue_utils::Queue;

use super::SYSCLK_HZ;

const CYCLES_PER_TICK: u32 = SYSCLK_HZ / 1_000_000;
const TICKS_PER_PERIOD: u64 = 1000;
const RELOAD: u32 = CYCLES_PER_TICK * TICKS_PER_PERIOD as u32 - 1;

struct State {
    periods: u64,
    next_alarm: u64,
    queue: Queue,
    /// The last time `now` returned: time never goes backwards (see `State::now`).
    last: Cell<u64>,
}

struct SysTickDriver {
    state: Mutex<Raw, RefCell<State>>,
}

embassy_time_driver::time_driver_impl!(static DRIVER: SysTickDriver = SysTickDriver {
    state: Mutex::new(RefCell::new(State {
        periods: 0,
        next_alarm: u64::MAX,
        queue: Queue::new(),
        last: Cell::new(0),
    })),
});

pub fn init(mut syst: SYST) {
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(RELOAD);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
}

impl State {
    /// Ticks now; call with interrupts masked. Never less than a value it returned before.
    ///
    /// QEMU's SysTick is not cycle-exact: without `-icount`, and with the host busy, the counter
    /// can already have wrapped (it reads near the reload value again) while the wrap's pending
    /// bit is not set yet, because QEMU raises it from a host timer that runs later. The sum
    /// below then reads up to one period (1 ms) early, and an `Instant` subtraction in
    /// embassy-time panics on the negative difference (the soak test found it:
    /// `unwrap failed: self.ticks.checked_sub(earlier.ticks)`). Clamping to the last value keeps
    /// time monotonic; it stands still for that moment and catches up at the next interrupt.
    fn now(&self) -> u64 {
        let t = self.raw_now().max(self.last.get());
        self.last.set(t);
        t
    }

    /// Periods counted plus the counter's elapsed part, as the hardware reads.
    fn raw_now(&self) -> u64 {
        let mut periods = self.periods;
        let mut cvr = SYST::get_current();
        if SCB::is_pendst_pending() {
            // The counter wrapped and the interrupt has not counted it yet. Re-read: a counter
            // still at 0 has not reloaded, so it is the end of the counted period.
            cvr = SYST::get_current();
            if cvr != 0 {
                periods += 1;
            }
        }
        let elapsed = RELOAD.saturating_sub(cvr) / CYCLES_PER_TICK;
        periods * TICKS_PER_PERIOD + u64::from(elapsed)
    }

    fn wake_expired(&mut self, now: u64) {
        self.next_alarm = self.queue.next_expiration(now);
    }
}

impl Driver for SysTickDriver {
    fn now(&self) -> u64 {
        self.state.lock(|s| s.borrow().now())
    }

    fn schedule_wake(&self, at: u64, waker: &core::task::Waker) {
        self.state.lock(|s| {
            let mut s = s.borrow_mut();
            if s.queue.schedule_wake(at, waker) {
                let now = s.now();
                s.wake_expired(now);
            }
        });
    }
}

#[exception]
fn SysTick() {
    DRIVER.state.lock(|s| {
        let mut s = s.borrow_mut();
        s.periods += 1;
        // This interrupt marks the wrap itself: the time is exactly `periods` periods. (Reading
        // the counter here could give a whole period more, since QEMU may not have reloaded it
        // yet when the handler starts; `now` must not remember such a reading.)
        let now = (s.periods * TICKS_PER_PERIOD).max(s.last.get());
        if now >= s.next_alarm {
            s.wake_expired(now);
        }
    });
}
