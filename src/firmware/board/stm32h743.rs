//! ST Nucleo-H743ZI2 (STM32H743ZI, Cortex-M7F): core at 400 MHz from PLL1 on the 64 MHz HSI
//! (HSI / 4 * 50 / 2, voltage scale 1, as embassy's stm32h7 examples do: no crystal needed, every
//! silicon revision), I- and D-cache on, USART3 on PD8 (TX) and PD9 (RX) at 115200 8N1 (the
//! ST-LINK's virtual COM port, so the board's USB cable carries the protocol) through
//! embassy-stm32's interrupt-driven `BufferedUart`, embassy-stm32's timer-based time driver
//! (1 tick = 1 µs), logs over RTT (`probe-rs run` shows them). Flashing: docs/FIRMWARE.md.
//!
//! Its RAM is four regions (`stm32h743-memory.x`); the map and the planner's buffers are spread
//! over them by `crate::firmware::buffers`, which `init` prepares for by enabling the SRAM1-3
//! clocks (D2 domain). No DMA touches any buffer, so the D-cache needs no maintenance.

use embassy_stm32::rcc;

/// Maps of up to 2,097,152 cells, paths of up to 16,384 steps, buffers over the RAM regions:
/// `ohaca::board::H743`.
pub const BOARD: ohaca::board::Board = ohaca::board::H743;

stm32_board! {
    board: Stm32h743,
    name: "stm32h743-nucleo",
    start: start,
    uart: USART3,
    irq: USART3,
    rx: PD9,
    tx: PD8,
}

fn clocks() -> embassy_stm32::Config {
    let mut config = embassy_stm32::Config::default();
    let r = &mut config.rcc;
    r.hsi = Some(rcc::HSIPrescaler::DIV1); // 64 MHz
    r.csi = true;
    r.pll1 = Some(rcc::Pll {
        source: rcc::PllSource::HSI,
        prediv: rcc::PllPreDiv::DIV4, // 16 MHz
        mul: rcc::PllMul::MUL50,      // VCO 800 MHz
        fracn: None,
        divp: Some(rcc::PllDiv::DIV2), // 400 MHz system clock
        divq: None,
        divr: None,
    });
    r.sys = rcc::Sysclk::PLL1_P;
    r.ahb_pre = rcc::AHBPrescaler::DIV2; // 200 MHz (max 200 at scale 1)
    r.apb1_pre = rcc::APBPrescaler::DIV2; // 100 MHz: USART3's kernel clock
    r.apb2_pre = rcc::APBPrescaler::DIV2;
    r.apb3_pre = rcc::APBPrescaler::DIV2;
    r.apb4_pre = rcc::APBPrescaler::DIV2;
    r.voltage_scale = rcc::VoltageScale::Scale1;
    config
}

/// Caches on, clocks at 400 MHz, and the D2-domain SRAMs clocked before the UART opens.
fn start() -> embassy_stm32::Peripherals {
    let mut cp = defmt::unwrap!(cortex_m::Peripherals::take());
    cp.SCB.enable_icache();
    cp.SCB.enable_dcache(&mut cp.CPUID);
    let p = embassy_stm32::init(clocks());
    // SRAM1-3 (D2 domain) hold planner buffers (`crate::firmware::buffers`): clock them
    // before they are first written (RM0433, RCC_AHB2ENR).
    embassy_stm32::pac::RCC.ahb2enr().modify(|w| {
        w.set_sram1en(true);
        w.set_sram2en(true);
        w.set_sram3en(true);
    });
    p
}
