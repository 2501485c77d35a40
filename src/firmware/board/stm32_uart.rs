//! What the two STM32 boards share, written once: the protocol UART as an interrupt-driven
//! embassy-stm32 `BufferedUart` at 115200 8N1 with its interrupt binding and ring buffers, and
//! the rest of the [`super::Board`] implementation (RTT logs through `defmt_rtt`, overruns counted
//! by the receive task, exit by system reset). A board file keeps only its facts: its name, its
//! USART, its interrupt, its pins, and a `start` function that sets its clocks (and whatever else
//! must run before the UART opens) and returns the peripherals.

/// The protocol UART's line rate (8N1).
pub const BAUD: u32 = 115_200;

/// The transmit ring's size in bytes (replies are written by the transmit task as they go).
pub const TX_RING: usize = 256;

/// Implements [`super::Board`] for `$board` on an STM32 whose protocol UART is `$usart`
/// (interrupt `$irq`) with receive pin `$rx` and transmit pin `$tx`; `$start` sets the clocks and
/// returns `embassy_stm32::Peripherals`.
macro_rules! stm32_board {
    (
        board: $board:ident,
        name: $name:literal,
        start: $start:path,
        uart: $usart:ident,
        irq: $irq:ident,
        rx: $rx:ident,
        tx: $tx:ident $(,)?
    ) => {
        use defmt_rtt as _;

        embassy_stm32::bind_interrupts!(struct Irqs {
            $irq => embassy_stm32::usart::BufferedInterruptHandler<embassy_stm32::peripherals::$usart>;
        });

        /// UART ring buffers (the planner yields once per iteration; a full map chunk is ~160
        /// bytes).
        static RX_BUF: static_cell::ConstStaticCell<[u8; crate::firmware::limits::RX_RING]> =
            static_cell::ConstStaticCell::new([0; crate::firmware::limits::RX_RING]);
        static TX_BUF: static_cell::ConstStaticCell<[u8; super::stm32_uart::TX_RING]> =
            static_cell::ConstStaticCell::new([0; super::stm32_uart::TX_RING]);

        pub struct $board;

        impl super::Board for $board {
            const NAME: &'static str = $name;
            type Rx = embassy_stm32::usart::BufferedUartRx<'static>;
            type Tx = embassy_stm32::usart::BufferedUartTx<'static>;

            fn init() -> (Self::Rx, Self::Tx) {
                let p = $start();
                let mut config = embassy_stm32::usart::Config::default();
                config.baudrate = super::stm32_uart::BAUD;
                let uart = defmt::unwrap!(embassy_stm32::usart::BufferedUart::new(
                    p.$usart,
                    p.$rx,
                    p.$tx,
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
    };
}
