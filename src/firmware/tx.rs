//! The transmit task: sends the small replies queued in [`OUT`]. Paths do not come through here:
//! the planner streams them into the UART itself ([`super::plan`]). Both take the port's lock
//! for a whole frame, so frames never interleave.

use embedded_io_async::Write;

use ohaca::protocol::encode_reply;

use super::state::{count, Out, TxPort, OUT};

/// Room for every reply but a path (Hello is the largest, under 100 bytes).
const SMALL_FRAME: usize = 128;

#[embassy_executor::task]
pub async fn tx_task(port: &'static TxPort) {
    let mut buf = [0u8; SMALL_FRAME];
    loop {
        let Out(id, reply) = OUT.receive().await;
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
        sent_one(sent);
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
