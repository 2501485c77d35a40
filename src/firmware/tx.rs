//! The transmit task: the only writer of the UART, so frames never interleave.

use embedded_io_async::Write;

use ohaca::protocol::encode_reply;

use super::board;
use super::state::{count, Out, OUT};

/// Room for every reply but a path (Hello is the largest, under 100 bytes).
const SMALL_FRAME: usize = 256;

#[embassy_executor::task]
pub async fn tx_task(mut tx: board::Tx) {
    let mut buf = [0u8; SMALL_FRAME];
    loop {
        let sent = match OUT.receive().await {
            Out::Reply(id, reply) => match encode_reply(id, &reply, &mut buf) {
                Ok(n) => tx.write_all(buf.get(..n).unwrap_or(&[])).await.is_ok(),
                Err(e) => {
                    defmt::error!("reply {}: {}", id, defmt::Display2Format(&e));
                    false
                }
            },
            // The guard is dropped at the end of this arm: the planner may encode the next path.
            Out::Frame(frame) => tx
                .write_all(frame.buf.get(..frame.len).unwrap_or(&[]))
                .await
                .is_ok(),
        };
        if sent {
            count(|s| s.tx_frames = s.tx_frames.wrapping_add(1));
        } else {
            defmt::warn!("reply not sent");
        }
    }
}
