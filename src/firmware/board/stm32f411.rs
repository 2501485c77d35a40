//! WeAct "Black Pill" STM32F411CEU6: 25 MHz crystal, core at 96 MHz (HSE / 25 * 192 / 2), USART1
//! on PA9 (TX) and PA10 (RX) at 115200 8N1 through embassy-stm32's interrupt-driven
//! `BufferedUart`, embassy-stm32's timer-based time driver (1 tick = 1 µs), logs over RTT
//! (`probe-rs run` shows them). Wiring and flashing: docs/FIRMWARE.md.

use embassy_stm32::rcc;
use embassy_stm32::time::Hertz;

/// Maps of up to 262,144 cells, paths of up to 4,095 steps (2,047 up to 68,256 cells), in one
/// arena of 103,424 bytes: `ohaca::board::F411`.
pub const BOARD: ohaca::board::Board = ohaca::board::F411;

stm32_board! {
    board: Stm32f411,
    name: "stm32f411-blackpill",
    start: start,
    uart: USART1,
    irq: USART1,
    rx: PA10,
    tx: PA9,
}

/// Clocks: 96 MHz from the 25 MHz crystal.
fn start() -> embassy_stm32::Peripherals {
    embassy_stm32::init(clocks())
}

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
