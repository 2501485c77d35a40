//! The host side of the firmware link: a blocking client of the wire protocol
//! ([`ohaca::protocol`], `docs/PROTOCOL.md`) over any byte stream that implements [`Transport`]
//! — a TCP socket to QEMU ([`Link::tcp`]) or a serial port ([`Link::serial`]).
//!
//! * Request ids start at 1 and increase (0 is [`UNKNOWN_ID`], never used).
//! * Every call waits for the reply carrying its id, at most [`Link::timeout`] (default
//!   [`DEFAULT_TIMEOUT`]); nothing blocks longer than that, reads and writes included.
//! * Replies for other requests still in flight are kept for their caller; replies nobody waits
//!   for (a late answer to a timed-out request, the device's `id 0` answers to frames it could
//!   not read) are *strays*: skipped, counted and kept for the caller to report
//!   ([`Link::take_strays`]).
//! * Maps are uploaded in chunks of at most [`MAX_CHUNK`] bytes (less if the device says so),
//!   run-length coded when that is shorter ([`Link::set_map`], [`MapCode`]), with up to
//!   [`UPLOAD_WINDOW`] chunks in flight.
//! * [`Link::plan_many`] pipelines plans, keeping up to the device's `plan_queue` in flight, and
//!   returns the outcomes in request order.
//! * Every failure is a [`LinkError`]: a timeout, a device error reply (with its code), a closed
//!   connection, an undecodable frame, ...
//!
//! ```no_run
//! use ohaca::Point;
//! use ohaca_host::link::Link;
//! use ohaca_host::Map;
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let mut link = Link::tcp("127.0.0.1:4444", ohaca_host::link::DEFAULT_TIMEOUT)?;
//! let hello = link.hello()?;
//! let map = Map::load("maps/complex-26.map")?;
//! link.set_map(&map)?;
//! let path = link.plan(Point::new(0, 0), Point::new(25, 25), None)?;
//! println!("{} on {}: {} waypoints", path.length, hello.board, path.waypoints.len());
//! # Ok(()) }
//! ```
//!
//! | file | owns |
//! | --- | --- |
//! | `transport.rs` | the byte stream: [`Transport`], TCP and [`Serial`], time bounds |
//! | `wire.rs` | what travels: [`MapCode`] (raw or run-length map uploads), the owned replies ([`Response`], [`DeviceInfo`], [`DevicePath`]) and request names |
//! | `session.rs` | [`Link`]: ids, framing of requests and replies, waiting, strays, uploads, plans |
//! | `errors.rs` | [`LinkError`] and [`Stray`]: every way a call fails, and the frames nobody waited for |
//! | `relay.rs` | [`relay::Relay`]: a paced serial line (115200 8N1 by default) between a client and QEMU's UART, with its line clocks |

use std::collections::{BTreeMap, HashMap, HashSet, VecDeque};
use std::io::{self, Read, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::{Duration, Instant};

use ohaca::grid::{DX, DY};
use ohaca::protocol::{
    decode_path_body, decode_reply, encode_request, Capacity, DecodeError, EncodeError, ErrorCode,
    ErrorReply, HelloReply, PathReply, Reply, ReplyReader, Request, RleEncoder, StatsReply,
    Waypoints, MAX_CHUNK, MAX_REPLY, MAX_REPLY_WIRE, MAX_REQUEST_WIRE, MAX_UPDATE_CELLS,
    UNKNOWN_ID, VERSION,
};
use ohaca::{Params, Point};

use crate::map::Map;

mod errors;
#[cfg(unix)]
pub mod relay;
mod session;
#[cfg(test)]
mod tests;
mod transport;
mod wire;

pub use errors::*;
pub use session::*;
pub use transport::*;
pub use wire::*;

use errors::{is_disconnect, is_timeout, unexpected};

/// How long a call waits for its reply unless told otherwise.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(10);

/// The serial line speed unless told otherwise (the firmware's UART: 115200 8N1).
pub const DEFAULT_BAUD: u32 = 115_200;

/// Map chunks in flight during an upload: 3 frames of at most ~150 bytes stay well within a
/// board's 1 KiB receive ring (docs/FIRMWARE.md), and hide the round trip of each `Ack`.
pub const UPLOAD_WINDOW: usize = 3;

/// Most stray frames kept for [`Link::take_strays`] (older ones are only counted).
const MAX_STRAYS: usize = 64;
