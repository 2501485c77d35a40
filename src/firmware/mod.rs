//! The firmware: three embassy tasks around the planning core, talking the protocol of
//! [`ohaca::protocol`] over a UART.
//!
//! ```text
//!   UART rx --> [rx task] --decode--> Hello / Stats / SetParams / Cancel: answered at once
//!                  |                  SetMap(Rle) / SetRect / SetCells: cancel, lock MAP, write
//!                  |                  Plan / PlanWarm: queued (JOBS, 4 deep; full -> Busy)
//!                  v
//!              [planner task] holds MAP's lock while it plans; one Run::step() per iteration,
//!                  |            then yield; checks for cancellation (then releases MAP)
//!                  |            path: one Path frame, or PathPart frames (each read under MAP's
//!                  |            lock, sent without it, after the small replies queued) --+
//!                  v                                                                      |
//!   UART tx <-- [tx task] <-- OUT (small replies, 8 deep = the window; full -> dropped)   |
//!           <-----------------------------------------------------------------------------+
//! ```
//!
//! The receiver never waits for room in a queue, and for the map's lock at most one planner
//! piece: within the window (`state::WINDOW` requests, `state::RX_RING` bytes) the receive buffer
//! holds whatever arrives meanwhile, at any baud rate.
//!
//! Everything board-specific (UART, time driver, log sink, exit) is behind [`board::Board`].

mod board;
mod buffers;
mod limits;
mod plan;
mod rx;
mod stack;
mod state;
mod tx;

use embassy_executor::Spawner;
use embassy_sync::mutex::Mutex;
use static_cell::StaticCell;

use board::Board;

/// The UART's transmitting half, shared by the transmitter and the planner.
static TX: StaticCell<state::TxPort> = StaticCell::new();

defmt::timestamp!("{=u64:us}", embassy_time::Instant::now().as_micros());

/// Bring up the board and spawn the tasks.
pub fn run(spawner: Spawner) {
    // Before any interrupt is enabled, so the boot log is the same every time.
    let boot_stack = stack::peak();
    let (rx, tx) = board::Active::init();
    let boots = state::count_boot();
    defmt::info!(
        "ohaca {} on {}: boot {}, maps of up to {} cells ({} bytes, sides up to {}), paths of up to {} steps, storage {} bytes",
        env!("CARGO_PKG_VERSION"),
        board::Active::NAME,
        boots,
        state::PLAN_CELLS,
        state::MAP_BYTES,
        state::MAX_SIDE,
        state::PLAN_STEPS,
        buffers::BYTES
    );
    defmt::info!(
        "stack: {} bytes (RAM above the statics), {} used at boot",
        stack::size(),
        boot_stack
    );
    // The map and the planner's buffers: after the board's init (the STM32H743's enables the
    // RAM regions they live in), before any task runs.
    let storage = buffers::take(&state::MAP);
    let port = TX.init(Mutex::new(tx));
    spawner.spawn(defmt::unwrap!(tx::tx_task(port)));
    spawner.spawn(defmt::unwrap!(plan::planner_task(storage, port)));
    spawner.spawn(defmt::unwrap!(rx::rx_task(rx)));
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    defmt::error!("panic: {}", defmt::Display2Format(info));
    board::Active::exit(true)
}

#[cortex_m_rt::exception]
unsafe fn HardFault(frame: &cortex_m_rt::ExceptionFrame) -> ! {
    defmt::error!("hard fault at pc {=u32:#010x}", frame.pc());
    board::Active::exit(true)
}
