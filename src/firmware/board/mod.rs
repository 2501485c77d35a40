//! The one boundary between the firmware and its hardware. A board provides a UART as an
//! `embedded-io-async` reader/writer pair, an embassy time driver, a defmt log sink, and a way to
//! stop; everything else is board-independent.
//!
//! | board | feature | UART | time driver | logs | exit |
//! | --- | --- | --- | --- | --- | --- |
//! | [`qemu`] (default) | `board-qemu` | CMSDK APB UART0, RX interrupt + ring | SysTick, 1 tick = 1 µs | semihosting | semihosting exit |
//! | [`stm32f411`] | `board-stm32f411` | USART1 `BufferedUart` (PA9 TX, PA10 RX) | embassy-stm32 (TIM) | RTT | system reset |

#[cfg(all(feature = "board-qemu", feature = "board-stm32f411"))]
compile_error!("choose one board: `board-qemu` (default) or `--no-default-features --features board-stm32f411`");
#[cfg(not(any(feature = "board-qemu", feature = "board-stm32f411")))]
compile_error!("no board selected: enable `board-qemu` or `board-stm32f411`");

#[cfg(feature = "board-qemu")]
pub mod qemu;
#[cfg(feature = "board-qemu")]
pub use qemu::Qemu as Active;

#[cfg(all(feature = "board-stm32f411", not(feature = "board-qemu")))]
pub mod stm32f411;
#[cfg(all(feature = "board-stm32f411", not(feature = "board-qemu")))]
pub use stm32f411::Stm32f411 as Active;

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
}

pub type Rx = <Active as Board>::Rx;
pub type Tx = <Active as Board>::Tx;
