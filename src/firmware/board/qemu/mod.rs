//! QEMU `mps2-an386`: Cortex-M4 at 25 MHz, 4 MiB flash at 0, 4 MiB RAM at 0x2000_0000 (the
//! firmware uses 512 KiB and 128 KiB of them, as on the STM32F411: `memory.x`), CMSDK APB UART0 at
//! 0x4000_4000 (its RX interrupt is IRQ 0, its TX interrupt IRQ 1). Logs and exit go through semihosting, so run QEMU with
//! `-semihosting-config enable=on,target=native`.

mod systick;
mod uart;

use defmt_semihosting as _;

use super::Board;

/// The STM32F411's board (the default: `ohaca::board::F411`, its capacity and arena, so what
/// QEMU proves holds on the chip), or with feature `twin-h743` the STM32H743's: the twin also has
/// the H743's RAM regions (`twin-h743-memory.x`) and buffer placement.
#[cfg(not(feature = "twin-h743"))]
pub const BOARD: ohaca::board::Board = ohaca::board::F411;
/// The STM32H743's board (`ohaca::board::H743`): this is its QEMU twin (`twin-h743-memory.x`
/// has the H743's RAM regions, `crate::firmware::buffers` places the buffers as on the chip).
#[cfg(feature = "twin-h743")]
pub const BOARD: ohaca::board::Board = ohaca::board::H743;

/// System clock of the MPS2 FPGA images, also the SysTick and UART clock.
pub const SYSCLK_HZ: u32 = 25_000_000;

pub struct Qemu;

impl Board for Qemu {
    #[cfg(not(feature = "twin-h743"))]
    const NAME: &'static str = "qemu-mps2-an386";
    #[cfg(feature = "twin-h743")]
    const NAME: &'static str = "qemu-mps2-an386-twin-h743";
    type Rx = uart::Rx;
    type Tx = uart::Tx;

    fn init() -> (uart::Rx, uart::Tx) {
        let cp = defmt::unwrap!(cortex_m::Peripherals::take());
        systick::init(cp.SYST);
        uart::init()
    }

    fn rx_overruns() -> u32 {
        uart::overruns()
    }

    fn frame_end() -> Option<u64> {
        Some(uart::last_delimiter())
    }

    fn exit(failure: bool) -> ! {
        use cortex_m_semihosting::debug::{exit, EXIT_FAILURE, EXIT_SUCCESS};
        exit(if failure { EXIT_FAILURE } else { EXIT_SUCCESS });
        // Without a debugger attached semihosting exit returns: reset instead.
        cortex_m::peripheral::SCB::sys_reset()
    }
}

/// Device interrupts: this board has no PAC, so every IRQ lands in cortex-m-rt's default
/// handler with its number.
#[cortex_m_rt::exception]
unsafe fn DefaultHandler(irqn: i16) {
    match irqn {
        uart::RX_IRQ_NUMBER => uart::on_rx_interrupt(),
        uart::TX_IRQ_NUMBER => uart::on_tx_interrupt(),
        _ => defmt::panic!("unexpected interrupt {}", irqn),
    }
}
