//! Interrupt-driven driver for the CMSDK APB UART (ARM DDI0479C, and QEMU's model of it).
//!
//! The UART holds one received byte. Its RX interrupt moves bytes into a 1 KiB ring (an
//! embassy-sync `Pipe`, `RX_RING` bytes) that the receive task reads. When the ring is full the
//! byte is taken and dropped, and counted, as on the STM32 boards' UARTs without flow control
//! (QEMU's model would otherwise hold the rest of the stream back, and no test would see what a
//! board does when a host sends beyond its window). Hardware overruns (STATE.RXOVERRUN) are
//! counted too. Transmit polls TXFULL and yields while the UART is busy.

use core::cell::Cell;
use core::convert::Infallible;
use core::ptr::{read_volatile, write_volatile};
use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::interrupt::InterruptNumber;
use cortex_m::peripheral::NVIC;
use embassy_futures::yield_now;
use embassy_sync::blocking_mutex::raw::CriticalSectionRawMutex as Raw;
use embassy_sync::blocking_mutex::Mutex;
use embassy_sync::pipe::Pipe;

use super::SYSCLK_HZ;
use crate::firmware::limits::RX_RING;

const BASE: usize = 0x4000_4000;
const DATA: usize = 0x00;
const STATE: usize = 0x04;
const CTRL: usize = 0x08;
/// INTSTATUS when read, INTCLEAR (write 1 to clear) when written.
const INT: usize = 0x0C;
const BAUDDIV: usize = 0x10;

const STATE_TX_FULL: u32 = 1 << 0;
const STATE_RX_FULL: u32 = 1 << 1;
const STATE_RX_OVERRUN: u32 = 1 << 3;
const CTRL_TX_EN: u32 = 1 << 0;
const CTRL_RX_EN: u32 = 1 << 1;
const CTRL_TX_INT_EN: u32 = 1 << 2;
const CTRL_RX_INT_EN: u32 = 1 << 3;
const INT_TX: u32 = 1 << 0;
const INT_RX: u32 = 1 << 1;

/// Baud rate: meaningless under QEMU (BAUDDIV only has to be >= 16), real on an FPGA board.
const BAUD: u32 = 115_200;

pub const RX_IRQ_NUMBER: i16 = 0;
/// UART0's TX interrupt on mps2-an385/an386: one above its RX interrupt.
pub const TX_IRQ_NUMBER: i16 = 1;

#[derive(Clone, Copy)]
struct Irq(u16);

// SAFETY: 0 and 1 are UART0's RX and TX interrupts on mps2-an385/an386, valid device interrupt
// numbers.
unsafe impl InterruptNumber for Irq {
    fn number(self) -> u16 {
        self.0
    }
}
const RX_IRQ: Irq = Irq(RX_IRQ_NUMBER as u16);
const TX_IRQ: Irq = Irq(TX_IRQ_NUMBER as u16);

/// Bytes the transmitter holds for the UART: as many as the STM32 boards' `TX_BUF`.
pub const TX_RING_BYTES: usize = 256;

static RING: Pipe<Raw, RX_RING> = Pipe::new();
/// What writers queued for the UART; the TX interrupt empties it.
static TX_RING: Pipe<Raw, TX_RING_BYTES> = Pipe::new();
/// The tick at which the last frame delimiter (`00`) arrived, for the latency log
/// (`crate::firmware::rx`): under `-icount shift=0` one tick is 1000 instructions.
static LAST_DELIMITER: Mutex<Raw, Cell<u64>> = Mutex::new(Cell::new(0));
static OVERRUNS: AtomicU32 = AtomicU32::new(0);

fn read(off: usize) -> u32 {
    // SAFETY: BASE + off is one of the UART's 32-bit registers (mapped on this board).
    unsafe { read_volatile((BASE + off) as *const u32) }
}

fn write(off: usize, v: u32) {
    // SAFETY: as in `read`; the registers accept any 32-bit write.
    unsafe { write_volatile((BASE + off) as *mut u32, v) }
}

pub fn init() -> (Rx, Tx) {
    write(BAUDDIV, SYSCLK_HZ / BAUD);
    write(
        CTRL,
        CTRL_TX_EN | CTRL_RX_EN | CTRL_TX_INT_EN | CTRL_RX_INT_EN,
    );
    // SAFETY: the handlers (`on_rx_interrupt`, `on_tx_interrupt`) only touch the rings and the
    // UART, both safe to use from interrupt context; no critical section relies on these
    // interrupts being masked.
    unsafe {
        NVIC::unmask(RX_IRQ);
        NVIC::unmask(TX_IRQ);
    }
    (Rx { _private: () }, Tx { _private: () })
}

pub fn overruns() -> u32 {
    OVERRUNS.load(Ordering::Relaxed)
}

/// The RX interrupt: move every waiting byte into the ring (or drop it, counted, if the ring is
/// full).
pub fn on_rx_interrupt() {
    // Clear first: a byte arriving after the drain below raises the interrupt again.
    write(INT, INT_RX);
    loop {
        let state = read(STATE);
        if state & STATE_RX_OVERRUN != 0 {
            write(STATE, STATE_RX_OVERRUN);
            OVERRUNS.fetch_add(1, Ordering::Relaxed);
        }
        if state & STATE_RX_FULL == 0 {
            break;
        }
        let byte = read(DATA) as u8;
        if byte == 0 {
            let now = embassy_time::Instant::now().as_ticks();
            LAST_DELIMITER.lock(|t| t.set(now));
        }
        if RING.try_write(&[byte]).is_err() {
            OVERRUNS.fetch_add(1, Ordering::Relaxed);
        }
    }
}

/// The tick of the last frame delimiter received.
pub fn last_delimiter() -> u64 {
    LAST_DELIMITER.lock(Cell::get)
}

/// The TX interrupt: the holding register emptied; give it the next byte.
pub fn on_tx_interrupt() {
    write(INT, INT_TX);
    pump();
}

/// Move bytes from [`TX_RING`] into the UART while it takes them (QEMU's model takes the next at
/// once while its character device accepts bytes, and raises the TX interrupt when it has sent
/// one it held). With interrupts masked, so the interrupt and a writer never both write `DATA`
/// after one reading of `TXFULL` (a second write would overrun the holding register).
fn pump() {
    critical_section::with(|_| {
        let mut byte = [0u8];
        while read(STATE) & STATE_TX_FULL == 0 {
            match TX_RING.try_read(&mut byte) {
                Ok(1) => write(DATA, u32::from(byte[0])),
                _ => break,
            }
        }
    });
}

/// The receiving half.
pub struct Rx {
    _private: (),
}

/// The transmitting half.
pub struct Tx {
    _private: (),
}

impl embedded_io_async::ErrorType for Rx {
    type Error = Infallible;
}

impl embedded_io_async::ErrorType for Tx {
    type Error = Infallible;
}

impl embedded_io_async::Read for Rx {
    async fn read(&mut self, buf: &mut [u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        Ok(RING.read(buf).await)
    }
}

impl embedded_io_async::Write for Tx {
    /// Queue what fits of `buf` in the transmit ring (waiting, woken by the TX interrupt, while
    /// it is full) and start the UART if it is idle.
    async fn write(&mut self, buf: &[u8]) -> Result<usize, Infallible> {
        if buf.is_empty() {
            return Ok(0);
        }
        let n = TX_RING.write(buf).await;
        // An idle UART raises no TX interrupt: hand it the first byte (the interrupt sends the
        // rest as each one leaves).
        pump();
        Ok(n)
    }

    /// Wait until the ring is empty (its last byte is in the UART).
    async fn flush(&mut self) -> Result<(), Infallible> {
        while !TX_RING.is_empty() {
            pump();
            yield_now().await;
        }
        Ok(())
    }
}
