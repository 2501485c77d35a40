//! The one boundary between the firmware and its hardware. A board provides a UART as an
//! `embedded-io-async` reader/writer pair, an embassy time driver, a defmt log sink, and a way to
//! stop; everything else is board-independent.
//!
//! | board | feature | UART | time driver | logs | exit |
//! | --- | --- | --- | --- | --- | --- |
//! | [`qemu`] (default) | `board-qemu` | CMSDK APB UART0, RX and TX interrupts + rings | SysTick, 1 tick = 1 µs | semihosting | semihosting exit |
//! | [`stm32f411`] | `board-stm32f411` | USART1 `BufferedUart` (PA9 TX, PA10 RX) | embassy-stm32 (TIM) | RTT | system reset |

//! | [`stm32h743`] | `board-stm32h743` | USART3 `BufferedUart` (PD8 TX, PD9 RX: the ST-LINK's virtual COM port) | embassy-stm32 (TIM) | RTT | system reset |
//!
//! Each board module also says how much its firmware holds: its `BOARD`, one of the core's board
//! descriptions (`ohaca::board`: cells, longest ant path, buffer layout; the host tool plans from
//! the same values with `--board`): `ohaca::board::F411` on the STM32F411 and the default QEMU
//! board, `ohaca::board::H743` on the STM32H743 and on its QEMU capacity twin (`board-qemu` +
//! `twin-h743`), whose RAM regions have the H743's sizes. Where the buffers go in RAM:
//! `super::buffers`. The two STM32 boards share their UART setup and the rest of their
//! [`Board`] implementation (`stm32_uart`, the `stm32_board!` macro); each board file holds only its
//! facts: name, USART, interrupt, pins, clocks.

#[cfg(any(
    all(feature = "board-qemu", feature = "board-stm32f411"),
    all(feature = "board-qemu", feature = "board-stm32h743"),
    all(feature = "board-stm32f411", feature = "board-stm32h743"),
))]
compile_error!("choose one board: `board-qemu` (default), or `--no-default-features --features board-stm32f411` or `board-stm32h743`");
#[cfg(not(any(
    feature = "board-qemu",
    feature = "board-stm32f411",
    feature = "board-stm32h743"
)))]
compile_error!("no board selected: enable `board-qemu`, `board-stm32f411` or `board-stm32h743`");

#[cfg(any(feature = "board-stm32f411", feature = "board-stm32h743"))]
#[macro_use]
mod stm32_uart;

#[cfg(feature = "board-qemu")]
pub mod qemu;
#[cfg(feature = "board-qemu")]
pub use qemu::{Qemu as Active, BOARD};

#[cfg(all(feature = "board-stm32f411", not(feature = "board-qemu")))]
pub mod stm32f411;
#[cfg(all(feature = "board-stm32f411", not(feature = "board-qemu")))]
pub use stm32f411::{Stm32f411 as Active, BOARD};

#[cfg(all(
    feature = "board-stm32h743",
    not(any(feature = "board-qemu", feature = "board-stm32f411"))
))]
pub mod stm32h743;
#[cfg(all(
    feature = "board-stm32h743",
    not(any(feature = "board-qemu", feature = "board-stm32f411"))
))]
pub use stm32h743::{Stm32h743 as Active, BOARD};

// A path the board plans always fits one path reply (`ohaca::protocol::MAX_STEPS`, the wire's
// bound, from which `MAX_REPLY` is derived).
const _: () = assert!(BOARD.max_steps <= ohaca::protocol::MAX_STEPS);

/// What a board provides.
pub trait Board {
    /// Name reported in the Hello reply.
    const NAME: &'static str;
    /// UART receiver.
    type Rx: embedded_io_async::Read + 'static;
    /// UART transmitter.
    type Tx: embedded_io_async::Write + 'static;
    /// Start clocks, the time driver and the UART (call once, first thing).
    fn init() -> (Self::Rx, Self::Tx);
    /// Receive overruns the driver saw itself (read errors are counted by the caller).
    fn rx_overruns() -> u32;
    /// Stop: leave the emulator, or reset the chip.
    fn exit(failure: bool) -> !;
    /// The tick at which the receiver's interrupt took the last frame delimiter (`00`), if the
    /// board records it (the QEMU board does, for the latency log: [`log_request`]).
    fn frame_end() -> Option<u64> {
        None
    }
}

/// Log when request `id`'s frame ended on the line, on a board that records it: with
/// [`log_reply`], the device-side latency of each answer in ticks (under `qemu-system-arm -icount
/// shift=0` one tick is 1000 instructions; `host/tests/qemu/paced.rs` reads these lines).
pub fn log_request(id: u32) {
    if let Some(t) = Active::frame_end() {
        defmt::info!("request {=u32} in at {=u64}", id, t);
    }
}

/// Log when the last byte of a small reply to `id` was handed to the UART's transmitter (which
/// then sends it at the line's rate, whatever the planner does), on a board that logs requests
/// ([`log_request`]).
pub fn log_reply(id: u32) {
    if Active::frame_end().is_some() {
        let now = embassy_time::Instant::now().as_ticks();
        defmt::info!("reply {=u32} out at {=u64}", id, now);
    }
}

pub type Rx = <Active as Board>::Rx;
pub type Tx = <Active as Board>::Tx;
