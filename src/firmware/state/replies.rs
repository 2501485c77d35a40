//! Replies on their way to the host: the UART's transmitting half ([`TxPort`]), the queue of
//! small replies ([`OUT`]) and the window that keeps the queue from filling.
//!
//! Every reply but a path is small and goes through [`OUT`] to the transmit task
//! (`crate::firmware::tx`), which encodes it when it sends it (a `Stats` reply has the counters
//! of that moment). The planner sends paths itself, a frame at a time, and lets the small
//! replies pass between the frames of a long one ([`wait_for_small`]).
//!
//! A host keeps at most [`WINDOW`] requests outstanding (`Capacity::window`), each answered by
//! one small reply or one path, so [`OUT`] (as deep as the window) never fills within it: the
//! receiver never waits for room. Beyond the window a reply that finds the queue full is dropped
//! and counted (`StatsReply::replies_dropped`), and the device keeps serving.

use core::sync::atomic::{AtomicBool, Ordering};

use embassy_sync::channel::Channel;
use embassy_sync::mutex::Mutex;
use embassy_sync::signal::Signal;

use ohaca::protocol::ErrorReply;

use super::{count, Raw};
use crate::firmware::board;

pub use crate::firmware::limits::WINDOW;

/// A small reply, as the transmitter encodes it.
#[derive(Clone, Copy)]
pub enum Small {
    /// `Reply::Ack`.
    Ack,
    /// `Reply::Error`.
    Error(ErrorReply),
    /// `Reply::Hello`.
    Hello,
    /// `Reply::Stats`, with the counters when it is sent.
    Stats,
}

/// A small reply for the transmitter: the request id and the reply.
#[derive(Clone, Copy)]
pub struct Out(pub u32, pub Small);

/// The UART's transmitting half, shared by the transmitter (small replies) and the planner (path
/// frames): whoever holds the lock sends one whole frame, so frames never interleave.
pub type TxPort = Mutex<Raw, board::Tx>;

pub static OUT: Channel<Raw, Out, WINDOW> = Channel::new();
/// True while the transmitter holds a small reply it took from [`OUT`] and has not sent yet.
pub static SENDING_SMALL: AtomicBool = AtomicBool::new(false);
/// Raised by the transmitter each time it has handed a small reply to the UART: what
/// [`wait_for_small`] sleeps on.
static SMALL_SENT: Signal<Raw, ()> = Signal::new();

/// Queue a small reply; never waits. A full queue (a host beyond its window) drops it, counted.
pub fn reply(id: u32, r: Small) {
    if OUT.try_send(Out(id, r)).is_err() {
        count(|s| s.replies_dropped = s.replies_dropped.wrapping_add(1));
        defmt::warn!("reply {} dropped: the reply queue is full", id);
    }
}

/// Wait until no small reply is queued or being sent: the planner calls it before each frame of
/// a path, so a small reply waits for at most the frame on the wire when it was queued. It
/// sleeps (no polling) until the transmitter says it sent one ([`small_sent`]), then looks again.
pub async fn wait_for_small() {
    while !OUT.is_empty() || SENDING_SMALL.load(Ordering::Acquire) {
        // One waiter (the planner); a signal raised before it waits is kept, so none is missed
        // (the executor runs one task at a time: nothing sends between the check and the wait).
        SMALL_SENT.wait().await;
    }
}

/// The transmitter has handed a small reply to the UART (or given up on it): wake
/// [`wait_for_small`].
pub fn small_sent() {
    SENDING_SMALL.store(false, Ordering::Release);
    SMALL_SENT.signal(());
}
