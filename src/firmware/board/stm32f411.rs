//! WeAct "Black Pill" STM32F411CEU6: 25 MHz crystal, core at 96 MHz (HSE / 25 * 192 / 2), USART1
//! on PA9 (TX) and PA10 (RX) at 115200 8N1 through embassy-stm32's interrupt-driven
//! `BufferedUart`, embassy-stm32's timer-based time driver (1 tick = 1 µs), logs over RTT
//! (`probe-rs run` shows them). Wiring and flashing: docs/FIRMWARE.md.

use defmt_rtt as _;
use embassy_stm32::time::Hertz;
use embassy_stm32::usart::{BufferedUart, BufferedUartRx, BufferedUartTx, Config};
use embassy_stm32::{bind_interrupts, peripherals, rcc, usart};
use static_cell::ConstStaticCell;

use super::Board;

/// Maps of up to 262,144 cells, paths of up to 4,095 steps (2,047 up to 68,256 cells), in one
/// arena of 103,424 bytes: `ohaca::board::F411`.
pub const BOARD: ohaca::board::Board = ohaca::board::F411;

bind_interrupts!(struct Irqs {
    USART1 => usart::BufferedInterruptHandler<peripherals::USART1>;
});

/// UART ring buffers (the planner yields once per iteration; a full map chunk is ~160 bytes).
static RX_BUF: ConstStaticCell<[u8; crate::firmware::limits::RX_RING]> =
    ConstStaticCell::new([0; crate::firmware::limits::RX_RING]);
static TX_BUF: ConstStaticCell<[u8; 256]> = ConstStaticCell::new([0; 256]);

pub struct Stm32f411;

fn clocks() -> embassy_stm32::Config {
    let mut config = embassy_stm32::Config::default();
    let r = &mut config.rcc;
    r.hse = Some(rcc::Hse {
        freq: Hertz(25_000_000),
        mode: rcc::HseMode::Oscillator,
    });
    r.pll_src = rcc::PllSource::HSE;
    r.pll = Some(rcc::Pll {
        prediv: rcc::PllPreDiv::DIV25,
        mul: rcc::PllMul::MUL192,
        divp: Some(rcc::PllPDiv::DIV2), // 96 MHz system clock
        divq: Some(rcc::PllQDiv::DIV4), // 48 MHz for USB
        divr: None,
    });
    r.sys = rcc::Sysclk::PLL1_P;
    r.ahb_pre = rcc::AHBPrescaler::DIV1;
    r.apb1_pre = rcc::APBPrescaler::DIV2; // 48 MHz (max 50)
    r.apb2_pre = rcc::APBPrescaler::DIV1;
    config
}

impl Board for Stm32f411 {
    const NAME: &'static str = "stm32f411-blackpill";
    type Rx = BufferedUartRx<'static>;
    type Tx = BufferedUartTx<'static>;

    fn init() -> (Self::Rx, Self::Tx) {
        let p = embassy_stm32::init(clocks());
        let mut config = Config::default();
        config.baudrate = 115_200;
        let uart = defmt::unwrap!(BufferedUart::new(
            p.USART1,
            p.PA10,
            p.PA9,
            TX_BUF.take(),
            RX_BUF.take(),
            Irqs,
            config,
        ));
        let (tx, rx) = uart.split();
        (rx, tx)
    }

    fn rx_overruns() -> u32 {
        // BufferedUart reports overruns as read errors, which the receive task counts.
        0
    }

    fn exit(_failure: bool) -> ! {
        cortex_m::peripheral::SCB::sys_reset()
    }
}
