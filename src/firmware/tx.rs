//! The transmit task: sends the small replies queued in `OUT`, each encoded as it goes out (a
//! `Stats` reply carries the counters of that moment). Paths do not come through here: the
//! planner sends their frames itself ([`super::plan`]) and lets these pass between the frames
//! of a long one. Both take the port's lock for a whole frame, so frames never interleave.

use core::sync::atomic::Ordering;

use embedded_io_async::Write;

use ohaca::planner::Params;
use ohaca::protocol::{encode_reply, Capacity, HelloReply, Reply, MAX_CHUNK, MAX_REQUEST, VERSION};

use super::board::{self, Board};
use super::state::{
    count, stats, Out, Small, TxPort, MAX_CELLS, MAX_SIDE, OUT, PLAN_CELLS, PLAN_QUEUE, PLAN_STEPS,
    RX_RING, SENDING_SMALL, WINDOW,
};

/// Room for every reply but a path (Hello is the largest, under 110 bytes).
const SMALL_FRAME: usize = 128;

#[embassy_executor::task]
pub async fn tx_task(port: &'static TxPort) {
    let mut buf = [0u8; SMALL_FRAME];
    loop {
        let Out(id, small) = OUT.receive().await;
        SENDING_SMALL.store(true, Ordering::Release);
        let reply = match small {
            Small::Ack => Reply::Ack,
            Small::Error(e) => Reply::Error(e),
            Small::Hello => Reply::Hello(hello()),
            Small::Stats => Reply::Stats(stats()),
        };
        let sent = match encode_reply(id, &reply, &mut buf) {
            Ok(n) => {
                let mut tx = port.lock().await;
                tx.write_all(buf.get(..n).unwrap_or(&[])).await.is_ok()
            }
            Err(e) => {
                defmt::error!("reply {}: {}", id, defmt::Display2Format(&e));
                false
            }
        };
        SENDING_SMALL.store(false, Ordering::Release);
        sent_one(sent);
    }
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
