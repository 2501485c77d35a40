//! The transmit task: sends the small replies queued in `OUT`, each encoded once it holds the
//! port (a `Stats` reply carries the counters of that moment: every frame before it in the byte
//! stream counted in `tx_frames`, itself not). Paths do not come through here: the planner sends
//! their frames itself ([`super::plan`]) through [`send_path_frame`] and lets these pass between
//! the frames of a long one. Both take the port's lock for a whole frame, so frames never
//! interleave.
//!
//! **A Cancel is final.** [`send_path_frame`] is the only way a path's bytes reach the UART, and
//! it looks at `STOPS` (`super::state::stopped`) while it holds the port, after it took the
//! lock: the receiver bumps `STOPS` before it queues the `Ack` of a `Cancel` (or of a map's first
//! chunk), and that `Ack` can reach the UART only through the same lock. So either the frame was
//! in the port before the `Ack` was even queued, or the planner sees the stop and sends nothing:
//! no frame of a stopped path ever follows the `Ack`.

use core::sync::atomic::Ordering;

use embedded_io_async::Write;

use ohaca::planner::Params;
use ohaca::protocol::{encode_reply, Capacity, HelloReply, Reply, MAX_CHUNK, MAX_REQUEST, VERSION};

use super::board::{self, Board};
use ohaca::protocol::{ErrorCode, ErrorReply};

use super::state::{
    self, count, small_sent, stats, Out, Small, TxPort, MAX_CELLS, MAX_SIDE, OUT, PLAN_CELLS,
    PLAN_QUEUE, PLAN_STEPS, RX_RING, SENDING_SMALL, WINDOW,
};

/// Room for every reply but a path (Hello is the largest, under 110 bytes).
const SMALL_FRAME: usize = 128;

#[embassy_executor::task]
pub async fn tx_task(port: &'static TxPort) {
    let mut buf = [0u8; SMALL_FRAME];
    loop {
        let Out(id, small) = OUT.receive().await;
        SENDING_SMALL.store(true, Ordering::Release);
        // The port first, then the reply: a `Stats` counts every frame before it on the line.
        let mut tx = port.lock().await;
        let reply = match small {
            Small::Ack => Reply::Ack,
            Small::Error(e) => Reply::Error(e),
            Small::Hello => Reply::Hello(hello()),
            Small::Stats => Reply::Stats(stats()),
        };
        let sent = match encode_reply(id, &reply, &mut buf) {
            Ok(n) => {
                let sent = tx.write_all(buf.get(..n).unwrap_or(&[])).await.is_ok();
                // Every byte of it is the transmitter's now: it goes out at the line's rate.
                board::log_reply(id);
                sent
            }
            Err(e) => {
                defmt::error!("reply {}: {}", id, defmt::Display2Format(&e));
                false
            }
        };
        sent_one(sent);
        drop(tx);
        small_sent();
    }
}

/// Send one frame of a path (a whole `Path` or a `PathPart`) of a plan whose sending began under
/// `stops`: after the small replies queued meanwhile, and only if no `Cancel` or map upload
/// stopped it (checked under the port's lock: see the module's docs). `Cancelled` if stopped.
pub async fn send_path_frame(port: &TxPort, frame: &[u8], stops: u32) -> Result<(), ErrorReply> {
    state::wait_for_small().await;
    let mut tx = port.lock().await;
    if state::stopped(stops) {
        return Err(ErrorReply::new(ErrorCode::Cancelled));
    }
    let sent = tx.write_all(frame).await.is_ok();
    sent_one(sent);
    Ok(())
}

/// What the device is and can do.
fn hello() -> HelloReply<'static> {
    HelloReply {
        protocol_version: VERSION,
        firmware_version: env!("CARGO_PKG_VERSION"),
        board: board::Active::NAME,
        capacity: Capacity {
            cells: PLAN_CELLS.min(MAX_CELLS) as u32,
            max_side: MAX_SIDE,
            max_steps: PLAN_STEPS as u32,
            max_chunk: MAX_CHUNK as u16,
            max_request: MAX_REQUEST as u16,
            plan_queue: PLAN_QUEUE as u8,
            tick_hz: embassy_time::TICK_HZ as u32,
            window: WINDOW as u8,
            window_bytes: RX_RING as u16,
        },
        defaults: Params::default(),
    }
}

/// Count a frame sent, or warn that it was not.
pub fn sent_one(sent: bool) {
    if sent {
        count(|s| s.tx_frames = s.tx_frames.wrapping_add(1));
    } else {
        defmt::warn!("reply not sent");
    }
}
