//! The one boundary between the firmware and its hardware. A board provides a UART as an
//! `embedded-io-async` reader/writer pair, an embassy time driver, a defmt log sink, and a way to
//! stop; everything else is board-independent.
//!
//! | board | feature | UART | time driver | logs | exit |
//! | --- | --- | --- | --- | --- | --- |
//! | [`qemu`] (default) | `board-qemu` | CMSDK APB UART0, RX interrupt + ring | SysTick, 1 tick = 1 µs | semihosting | semihosting exit |
//! | [`stm32f411`] | `board-stm32f411` | USART1 `BufferedUart` (PA9 TX, PA10 RX) | embassy-stm32 (TIM) | RTT | system reset |

//! | [`stm32h743`] | `board-stm32h743` | USART3 `BufferedUart` (PD8 TX, PD9 RX: the ST-LINK's virtual COM port) | embassy-stm32 (TIM) | RTT | system reset |
//!
//! Each board module also says how much its firmware holds: its [`Capacity`] (`CAPACITY`),
//! [`SMALL`] on the STM32F411 and the default QEMU board, [`LARGE`] on the STM32H743 and on its
//! QEMU capacity twin (`board-qemu` + `twin-h743`), whose RAM regions have the H743's sizes.
//! Where the buffers go in RAM: `super::buffers`.

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

#[cfg(feature = "board-qemu")]
pub mod qemu;
#[cfg(feature = "board-qemu")]
pub use qemu::{Qemu as Active, CAPACITY};

#[cfg(all(feature = "board-stm32f411", not(feature = "board-qemu")))]
pub mod stm32f411;
#[cfg(all(feature = "board-stm32f411", not(feature = "board-qemu")))]
pub use stm32f411::{Stm32f411 as Active, CAPACITY};

#[cfg(all(
    feature = "board-stm32h743",
    not(any(feature = "board-qemu", feature = "board-stm32f411"))
))]
pub mod stm32h743;
#[cfg(all(
    feature = "board-stm32h743",
    not(any(feature = "board-qemu", feature = "board-stm32f411"))
))]
pub use stm32h743::{Stm32h743 as Active, CAPACITY};

/// How much a board's firmware holds: maps of up to `cells` cells (any shape, one bit a cell in
/// the map buffer) planned at full resolution, and ant paths of up to `steps` steps (a longer
/// one is `Error PathTooLong`). Hello reports both.
#[derive(Clone, Copy)]
pub struct Capacity {
    /// Most cells of a map.
    pub cells: usize,
    /// Longest ant path, in steps.
    pub steps: usize,
}

/// The STM32F411's capacity (128 KiB of RAM), and the default QEMU board's, which copies it so
/// that what QEMU proves holds on the chip: 262,144 cells (512 x 512, or Nav2's 604 x 307 depot
/// at 5 cm) at full resolution, and paths of up to 2,047 steps (102 m at 5 cm;
/// `maps/large/maze-128-128-2`'s longest scenario has 1,379). The map and the planner share one
/// arena of 103,424 bytes (`ohaca::planner::arena`): maps of up to 68,256 cells get every
/// buffer (the pruning marks, 1,024 pheromone entries) and 2,047 steps; larger ones the compact
/// layout (no pruning, 64 pheromone entries) and as many steps as are left, 1,876 at 512 x 512
/// (`Error PathTooLong` says the bound of the plan).
#[cfg(not(any(feature = "twin-h743", feature = "board-stm32h743")))]
pub const SMALL: Capacity = Capacity {
    cells: 262_144,
    steps: 2047,
};

/// The STM32H743's capacity, and its QEMU twin's: 2,097,152 cells (2048 x 1024, or Nav2's
/// 1006 x 1674 warehouse at 3 cm; a 256 KiB map), paths of 16,384 steps (820 m at 5 cm). The map
/// and the planner's two per-cell bit sets take 768 KiB of the chip's 1,056 KiB of RAM (ITCM
/// included); the ant paths take 6 bytes a step in the DTCM (two tours, the path cells: the
/// iteration's best and worst ants are walked again) and tightening's hash table fills SRAM4 at
/// a load factor of up to 2/3 (`super::buffers` has the arithmetic).
#[cfg(any(feature = "twin-h743", feature = "board-stm32h743"))]
pub const LARGE: Capacity = Capacity {
    cells: 2_097_152,
    steps: 16_384,
};

// A path the board plans always fits one path reply (`ohaca::protocol::MAX_STEPS`, from which
// `MAX_REPLY` is derived).
const _: () = assert!(CAPACITY.steps <= ohaca::protocol::MAX_STEPS);

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
