//! The wire protocol between a host and the firmware: messages, framing, encode and decode.
//! `no_std`, allocation-free, shared by the firmware and the host tool. The full specification,
//! with a worked exchange in hex, is `docs/PROTOCOL.md`; a unit test checks that document's bytes
//! against this code.
//!
//! ```text
//! frame   = COBS(payload ++ crc32_le(payload)) ++ 0x00
//! payload = postcard((id: u32, message))      // Request from the host, Reply from the device
//! ```
//!
//! * CRC-32/ISO-HDLC ([`crc32`]) over the postcard bytes, appended little-endian.
//! * COBS: the frame contains no `0x00` except its delimiter; a lone `0x00` resynchronises.
//! * Every request carries an `id` chosen by the host; the device answers every request with
//!   exactly one reply carrying the same `id`. A frame that cannot be attributed (bad CRC, bad
//!   COBS, too long) is answered with an [`ErrorCode`] reply whose id is [`UNKNOWN_ID`].
//!
//! ```
//! use ohaca::protocol::{decode_reply, decode_request, encode_reply, encode_request, Reply,
//!                       Request, MAX_REQUEST_WIRE};
//! let mut buf = [0u8; MAX_REQUEST_WIRE];
//! let n = encode_request(7, &Request::Hello, &mut buf).unwrap();
//! assert_eq!(buf[n - 1], 0);                                   // the delimiter
//! let (id, req) = decode_request(&mut buf[..n - 1]).unwrap();  // frame without delimiter
//! assert_eq!((id, req), (7, Request::Hello));
//!
//! let n = encode_reply(7, &Reply::Ack, &mut buf).unwrap();
//! assert_eq!(decode_reply(&mut buf[..n - 1]).unwrap(), (7, Reply::Ack));
//! ```

use core::fmt;

use serde::{Deserialize, Serialize};

use crate::error::{Endpoint, Error, Param};
use crate::grid::Point;
use crate::planner::Params;

mod frame;
mod map;
mod stream;
mod wire;

pub use frame::{cobs_overhead, crc32, wire_len, Feed, FrameReader};
pub use map::{
    check_cells, check_rect, set_cells, set_rect, Encoding, MapChunk, MapLimits, RleDecoder,
    RleEncoder, RleError, Upload, MAX_UPDATE_CELLS,
};
pub use stream::PathStream;
use wire::PointDef;
pub use wire::{Waypoints, WAYPOINT_BYTES};

/// Protocol version, reported in [`HelloReply::protocol_version`]. Bumped on any change to the
/// bytes or meaning of a message (2: [`StatsReply::stack_peak`]; 3: run-length uploads, cell
/// updates, warm plans, [`Capacity`]'s sides are the largest map held).
pub const VERSION: u16 = 4;

/// The id of replies to frames whose request id could not be read. Hosts should not use it.
pub const UNKNOWN_ID: u32 = 0;

/// Most map bytes in one [`Request::SetMap`] chunk.
pub const MAX_CHUNK: usize = 128;

/// Most waypoints in a [`PathReply`].
pub const MAX_WAYPOINTS: usize = 1024;

/// Most raw-path directions in a [`PathReply`].
pub const MAX_DIRECTIONS: usize = 1024;

/// Largest request payload (postcard bytes plus CRC) a device must accept.
pub const MAX_REQUEST: usize = 256;

/// Largest reply payload (postcard bytes plus CRC) a host must accept: a [`PathReply`] with
/// [`MAX_WAYPOINTS`] waypoints and [`MAX_DIRECTIONS`] directions fits. (A device need not hold
/// one: [`PathStream`] encodes a path frame piece by piece.)
pub const MAX_REPLY: usize = 5248;

/// Largest request frame on the wire, delimiter included.
pub const MAX_REQUEST_WIRE: usize = wire_len(MAX_REQUEST);

/// Largest reply frame on the wire, delimiter included.
pub const MAX_REPLY_WIRE: usize = wire_len(MAX_REPLY);

/// A frame reader sized for requests (the device side).
pub type RequestReader = FrameReader<MAX_REQUEST_WIRE>;

/// A frame reader sized for replies (the host side).
pub type ReplyReader = FrameReader<MAX_REPLY_WIRE>;

/// Host to device.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Request<'a> {
    /// `0`: who are you? Answered with [`Reply::Hello`].
    Hello,
    /// `1`: one chunk of a map upload, answered with [`Reply::Ack`]. The map is `width x
    /// height` cells, bit-packed exactly as [`crate::grid`] stores it (row-major, LSB first,
    /// `1` = blocked), `total_len = ceil(width * height / 8)` bytes, sent as chunks of at most
    /// [`MAX_CHUNK`] bytes. A chunk with `offset` 0 starts an upload; every further chunk must
    /// have the same `width`, `height` and `total_len`, and `offset <=` the bytes received so far
    /// (re-sending a chunk is allowed). The new map becomes active when the last byte arrives;
    /// until then the previous map stays in force.
    SetMap {
        /// Columns.
        width: u16,
        /// Rows.
        height: u16,
        /// Byte offset of `chunk` in the packed map.
        offset: u32,
        /// Bytes of the whole packed map.
        total_len: u32,
        /// The bytes.
        chunk: &'a [u8],
    },
    /// `2`: the planner parameters for every later [`Request::Plan`], answered with
    /// [`Reply::Ack`] (or [`ErrorCode::BadParam`], and the old parameters stay).
    SetParams(Params),
    /// `3`: plan a path on the active map with the active parameters, answered with
    /// [`Reply::Path`] or [`Reply::Error`].
    Plan {
        /// Start cell.
        #[serde(with = "PointDef")]
        start: Point,
        /// Goal cell.
        #[serde(with = "PointDef")]
        goal: Point,
        /// Overrides the parameters' seed for this plan only.
        seed: Option<u64>,
    },
    /// `4`: stop the running plan and drop the queued ones (each answered with
    /// [`ErrorCode::Cancelled`]); answered with [`Reply::Ack`].
    Cancel,
    /// `5`: counters, answered with [`Reply::Stats`].
    Stats,
    /// `6`: one chunk of a run-length coded map upload (see [`RleEncoder`]): the same fields
    /// and rules as [`Request::SetMap`], but `offset` and `total_len` count bytes of the code.
    SetMapRle {
        /// Columns.
        width: u16,
        /// Rows.
        height: u16,
        /// Byte offset of `chunk` in the code.
        offset: u32,
        /// Bytes of the whole code.
        total_len: u32,
        /// The bytes.
        chunk: &'a [u8],
    },
    /// `7`: block (`blocked`) or clear every cell of a rectangle of the active map, answered
    /// with [`Reply::Ack`] (or `NoMap`, `OutsideMap`: nothing changes). Cancels the running and
    /// queued plans, as a new map does.
    SetRect {
        /// Left column.
        x: u16,
        /// Top row.
        y: u16,
        /// Columns.
        width: u16,
        /// Rows.
        height: u16,
        /// Block (true) or clear (false).
        blocked: bool,
    },
    /// `8`: block or clear a list of at most [`MAX_UPDATE_CELLS`] cells, 4 bytes each on the
    /// wire as [`PathReply::waypoints`]; answered and cancelling like [`Request::SetRect`] (and
    /// `TooLarge` for a longer list).
    SetCells {
        /// Block (true) or clear (false).
        blocked: bool,
        /// The cells.
        #[serde(borrow)]
        cells: Waypoints<'a>,
    },
    /// `9`: as [`Request::Plan`], asking for a warm start: keep the colony (pheromone) of the
    /// previous plan to the same goal on this map, across cell updates. A device may plan it
    /// cold; the path is valid either way.
    PlanWarm {
        /// Start cell (the robot's cell now).
        #[serde(with = "PointDef")]
        start: Point,
        /// Goal cell.
        #[serde(with = "PointDef")]
        goal: Point,
        /// Overrides the parameters' seed for this plan only.
        seed: Option<u64>,
    },
}

/// Device to host.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Reply<'a> {
    /// `0`: answer to [`Request::Hello`].
    Hello(#[serde(borrow)] HelloReply<'a>),
    /// `1`: the request was carried out.
    Ack,
    /// `2`: a planned path.
    Path(#[serde(borrow)] PathReply<'a>),
    /// `3`: the request failed.
    Error(ErrorReply),
    /// `4`: answer to [`Request::Stats`].
    Stats(StatsReply),
}

/// What the device is and can do.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HelloReply<'a> {
    /// [`VERSION`] of the device's protocol.
    pub protocol_version: u16,
    /// The firmware's version (its crate version).
    pub firmware_version: &'a str,
    /// Board name, e.g. `qemu-mps2-an386`.
    pub board: &'a str,
    /// Limits.
    pub capacity: Capacity,
    /// The parameters in force until a [`Request::SetParams`].
    pub defaults: Params,
}

/// The device's limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Capacity {
    /// Most cells (`width * height`) of a map the device plans on; a bigger map it holds is
    /// answered `MapTooLarge` when planned on.
    pub cells: u32,
    /// Widest map the device holds (a map upload over it gets `MapTooLarge`).
    pub max_width: u16,
    /// Tallest map the device holds.
    pub max_height: u16,
    /// Most bytes per [`Request::SetMap`] chunk.
    pub max_chunk: u16,
    /// Largest request payload accepted ([`MAX_REQUEST`] or less).
    pub max_request: u16,
    /// Plan requests that can wait while one runs; one more gets [`ErrorCode::Busy`].
    pub plan_queue: u8,
    /// Ticks per second of [`PathReply::ticks`] and [`StatsReply::uptime`].
    pub tick_hz: u32,
}

/// A planned path: the planner's [`crate::Plan`] plus the time it took.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathReply<'a> {
    /// Length of the raw 8-connected path, in cells.
    pub raw_length: f32,
    /// Length through the waypoints (smoothed for OHACA).
    pub length: f32,
    /// Turns along the waypoints.
    pub turns: u32,
    /// Iterations run.
    pub iterations: u16,
    /// Iteration (0-based) in which the best path was found.
    pub best_iteration: u16,
    /// Ant moves over the whole run.
    pub moves: u64,
    /// Ticks ([`Capacity::tick_hz`]) from accepting the plan to finishing it, on the device.
    pub ticks: u64,
    /// Cells of the raw path (`directions.len() + 1` unless the directions were cut short).
    pub raw_cells: u32,
    /// True if the run kept the colony of the previous plan (a `PlanWarm` planned warm).
    pub warm: bool,
    /// Waypoints, start first, goal last.
    #[serde(borrow)]
    pub waypoints: Waypoints<'a>,
    /// The raw path from the start as one direction per step (`0..8` = E, SE, S, SW, W, NW, N,
    /// NE; see [`crate::grid::DX`]). At most [`MAX_DIRECTIONS`].
    pub directions: &'a [u8],
}

/// Why a request failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ErrorReply {
    /// What went wrong.
    pub code: ErrorCode,
    /// A number that goes with the code (see [`ErrorCode`]), else 0.
    pub detail: u32,
    /// The limit `detail` broke (see [`ErrorCode`]), else 0.
    pub limit: u32,
}

impl ErrorReply {
    /// An error with no numbers.
    pub const fn new(code: ErrorCode) -> Self {
        ErrorReply {
            code,
            detail: 0,
            limit: 0,
        }
    }

    /// An error with its numbers.
    pub const fn with(code: ErrorCode, detail: u32, limit: u32) -> Self {
        ErrorReply {
            code,
            detail,
            limit,
        }
    }
}

/// The one mapping between the planner's errors and the wire: each [`Error`] is an [`ErrorCode`]
/// from 1 to 10 with its numbers (`MapTooLarge`: cells and capacity; `BadParam`: the parameter's
/// [`Param`] index). [`TryFrom<ErrorReply>`](#impl-TryFrom%3CErrorReply%3E-for-Error) is its
/// inverse.
impl From<Error> for ErrorReply {
    fn from(e: Error) -> Self {
        match e {
            Error::BadMap => ErrorReply::new(ErrorCode::BadMap),
            Error::MapTooLarge { cells, capacity } => {
                ErrorReply::with(ErrorCode::MapTooLarge, cells, capacity)
            }
            Error::OutOfBounds(Endpoint::Start) => ErrorReply::new(ErrorCode::StartOutOfBounds),
            Error::OutOfBounds(Endpoint::Goal) => ErrorReply::new(ErrorCode::GoalOutOfBounds),
            Error::Blocked(Endpoint::Start) => ErrorReply::new(ErrorCode::StartBlocked),
            Error::Blocked(Endpoint::Goal) => ErrorReply::new(ErrorCode::GoalBlocked),
            Error::BadParam(p) => ErrorReply::with(ErrorCode::BadParam, p.index(), 0),
            Error::NoPath => ErrorReply::new(ErrorCode::NoPath),
            Error::Cancelled => ErrorReply::new(ErrorCode::Cancelled),
            Error::NoAntArrived => ErrorReply::new(ErrorCode::NoAntArrived),
        }
    }
}

/// The planner error a reply stands for (codes 1 to 10), so a host can show the core's own
/// message; the reply itself back when it is one of the protocol's own codes, or a `BadParam`
/// whose `detail` names no parameter.
impl TryFrom<ErrorReply> for Error {
    type Error = ErrorReply;

    fn try_from(r: ErrorReply) -> Result<Self, ErrorReply> {
        Ok(match r.code {
            ErrorCode::BadMap => Error::BadMap,
            ErrorCode::MapTooLarge => Error::MapTooLarge {
                cells: r.detail,
                capacity: r.limit,
            },
            ErrorCode::StartOutOfBounds => Error::OutOfBounds(Endpoint::Start),
            ErrorCode::GoalOutOfBounds => Error::OutOfBounds(Endpoint::Goal),
            ErrorCode::StartBlocked => Error::Blocked(Endpoint::Start),
            ErrorCode::GoalBlocked => Error::Blocked(Endpoint::Goal),
            ErrorCode::BadParam => Error::BadParam(Param::from_index(r.detail).ok_or(r)?),
            ErrorCode::NoPath => Error::NoPath,
            ErrorCode::Cancelled => Error::Cancelled,
            ErrorCode::NoAntArrived => Error::NoAntArrived,
            ErrorCode::BadCrc
            | ErrorCode::Undecodable
            | ErrorCode::TooLarge
            | ErrorCode::NoMap
            | ErrorCode::Busy
            | ErrorCode::BadChunk
            | ErrorCode::BadRle
            | ErrorCode::OutsideMap
            | ErrorCode::Internal => return Err(r),
        })
    }
}

impl fmt::Display for ErrorReply {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.code)?;
        match self.code {
            ErrorCode::MapTooLarge => {
                write!(f, " ({} cells, capacity {})", self.detail, self.limit)
            }
            ErrorCode::TooLarge => write!(f, " ({} bytes, limit {})", self.detail, self.limit),
            ErrorCode::BadChunk => write!(
                f,
                " (expected offset <= {} of {} bytes)",
                self.detail, self.limit
            ),
            ErrorCode::Busy => write!(f, " ({} of {} queued)", self.detail, self.limit),
            ErrorCode::BadParam => write!(f, " (parameter #{})", self.detail),
            ErrorCode::BadRle => write!(f, " ({} of {} cells)", self.detail, self.limit),
            ErrorCode::OutsideMap => write!(f, " (cell {}, {})", self.detail, self.limit),
            _ => Ok(()),
        }
    }
}

/// Error codes on the wire (one byte). 1 to 10 are the planner's [`Error`]s (mapped by
/// `From<Error> for ErrorReply` and back by `TryFrom<ErrorReply> for Error`); 16 and up are the
/// protocol's own. `detail` / `limit` of the [`ErrorReply`] are given where they mean
/// something.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(into = "u8", try_from = "u8")]
#[repr(u8)]
pub enum ErrorCode {
    /// The map has a zero side or too few bytes.
    BadMap = 1,
    /// The map has more cells than the device holds: `detail` = cells, `limit` = capacity.
    MapTooLarge = 2,
    /// The start lies outside the map.
    StartOutOfBounds = 3,
    /// The goal lies outside the map.
    GoalOutOfBounds = 4,
    /// The start is an obstacle.
    StartBlocked = 5,
    /// The goal is an obstacle.
    GoalBlocked = 6,
    /// A parameter is out of range: `detail` = which ([`crate::error::Param`] order: ants 0,
    /// iterations 1, alpha 2, beta 3, rho 4, q 5, a 6, xi 7, tau 8).
    BadParam = 7,
    /// The goal cannot be reached.
    NoPath = 8,
    /// The plan was cancelled (by [`Request::Cancel`] or a new map).
    Cancelled = 9,
    /// The goal is reachable but no ant reached it (every ant died at a dead end with
    /// [`crate::DeadEnd::Die`]).
    NoAntArrived = 10,
    /// The frame's CRC did not match (id: [`UNKNOWN_ID`]).
    BadCrc = 16,
    /// The frame was not valid COBS, or too short, or its message did not decode (id: the
    /// request's if it could be read, else [`UNKNOWN_ID`]).
    Undecodable = 17,
    /// A frame or chunk was too long: `detail` = its bytes, `limit` = the most allowed.
    TooLarge = 18,
    /// A plan was requested before any map was set.
    NoMap = 19,
    /// The plan queue is full: `detail` = plans waiting, `limit` = queue size.
    Busy = 20,
    /// A map chunk does not continue the upload: `detail` = bytes received so far, `limit` =
    /// the upload's `total_len` (0 when no upload is open).
    BadChunk = 21,
    /// The device could not build the reply (e.g. a path longer than the protocol's limits).
    Internal = 22,
    /// A run-length map code overruns the map or ends short of it: `detail` = cells decoded,
    /// `limit` = the map's cells. The upload is dropped.
    BadRle = 23,
    /// A cell update reaches outside the active map: `detail` = x, `limit` = y of the first cell
    /// outside.
    OutsideMap = 24,
}

impl ErrorCode {
    /// Every code, in numeric order.
    pub const ALL: [ErrorCode; 19] = [
        ErrorCode::BadMap,
        ErrorCode::MapTooLarge,
        ErrorCode::StartOutOfBounds,
        ErrorCode::GoalOutOfBounds,
        ErrorCode::StartBlocked,
        ErrorCode::GoalBlocked,
        ErrorCode::BadParam,
        ErrorCode::NoPath,
        ErrorCode::Cancelled,
        ErrorCode::NoAntArrived,
        ErrorCode::BadCrc,
        ErrorCode::Undecodable,
        ErrorCode::TooLarge,
        ErrorCode::NoMap,
        ErrorCode::Busy,
        ErrorCode::BadChunk,
        ErrorCode::Internal,
        ErrorCode::BadRle,
        ErrorCode::OutsideMap,
    ];

    /// The byte on the wire.
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The code with this byte.
    pub fn from_code(b: u8) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.code() == b)
    }

    /// A short description.
    pub const fn describe(self) -> &'static str {
        match self {
            ErrorCode::BadMap => "bad map",
            ErrorCode::MapTooLarge => "map too large",
            ErrorCode::StartOutOfBounds => "start is outside the map",
            ErrorCode::GoalOutOfBounds => "goal is outside the map",
            ErrorCode::StartBlocked => "start is on an obstacle",
            ErrorCode::GoalBlocked => "goal is on an obstacle",
            ErrorCode::BadParam => "bad parameter",
            ErrorCode::NoPath => "no path",
            ErrorCode::Cancelled => "cancelled",
            ErrorCode::NoAntArrived => "no ant reached the goal",
            ErrorCode::BadCrc => "bad CRC",
            ErrorCode::Undecodable => "undecodable frame",
            ErrorCode::TooLarge => "too large",
            ErrorCode::NoMap => "no map set",
            ErrorCode::Busy => "busy: plan queue full",
            ErrorCode::BadChunk => "map chunk out of sequence",
            ErrorCode::Internal => "internal error",
            ErrorCode::BadRle => "bad run-length map code",
            ErrorCode::OutsideMap => "cell outside the map",
        }
    }
}

impl From<ErrorCode> for u8 {
    fn from(c: ErrorCode) -> u8 {
        c.code()
    }
}

impl TryFrom<u8> for ErrorCode {
    type Error = UnknownCode;
    fn try_from(b: u8) -> Result<Self, UnknownCode> {
        ErrorCode::from_code(b).ok_or(UnknownCode(b))
    }
}

impl fmt::Display for ErrorCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.describe())
    }
}

/// A byte that is no [`ErrorCode`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnknownCode(pub u8);

impl fmt::Display for UnknownCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "unknown error code {}", self.0)
    }
}

/// Counters since boot.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct StatsReply {
    /// Ticks ([`Capacity::tick_hz`]) since boot.
    pub uptime: u64,
    /// Boots since power-on (1 after a cold start; counts resets that keep RAM).
    pub boots: u32,
    /// Frames received that decoded.
    pub frames_ok: u32,
    /// Frames received that did not (bad CRC, bad COBS, undecodable, too long).
    pub frames_bad: u32,
    /// Received bytes lost because the receive buffer was full, plus UART overrun events.
    pub rx_overruns: u32,
    /// Bytes received.
    pub rx_bytes: u32,
    /// Frames sent (this reply not counted).
    pub tx_frames: u32,
    /// Plans answered with a path.
    pub plans: u32,
    /// Plans answered with a planner error (every [`ErrorCode`] below 16 but `Cancelled`).
    pub plan_errors: u32,
    /// Plans cancelled.
    pub cancelled: u32,
    /// Plans refused with [`ErrorCode::Busy`].
    pub busy: u32,
    /// Ticks of the last plan answered with a path.
    pub last_plan_ticks: u64,
    /// Active map's width (0: no map yet).
    pub map_width: u16,
    /// Active map's height (0: no map yet).
    pub map_height: u16,
    /// Plans waiting in the queue.
    pub queued: u8,
    /// True while a plan runs.
    pub planning: bool,
    /// Most stack the device has used since boot, in bytes (its high-water mark, interrupts
    /// included; 0 if the device does not measure it).
    pub stack_peak: u32,
}

/// Why a message could not be encoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EncodeError {
    /// The output buffer is too small: `need` bytes on the wire, `have` in the buffer.
    BufferTooSmall {
        /// Bytes the frame needs, delimiter included.
        need: usize,
        /// Bytes the buffer has.
        have: usize,
    },
    /// The serializer refused the message (cannot happen with this module's types).
    Serialize,
}

impl fmt::Display for EncodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            EncodeError::BufferTooSmall { need, have } => {
                write!(f, "frame needs {need} bytes, buffer has {have}")
            }
            EncodeError::Serialize => f.write_str("message could not be serialized"),
        }
    }
}

/// Why a frame could not be decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DecodeError {
    /// Not valid COBS (a `0x00` inside, or a code byte pointing past the end).
    Cobs,
    /// Fewer than 5 bytes once COBS-decoded: no room for a message and its CRC.
    TooShort,
    /// The CRC does not match: the frame was corrupted.
    BadCrc,
    /// The CRC matches but the message does not decode (unknown variant, bad value, bad UTF-8,
    /// trailing bytes). `id` is the request id when its leading varint could be read.
    Undecodable {
        /// The frame's id, if readable.
        id: Option<u32>,
    },
    /// The frame was longer than the reader's buffer ([`Feed::TooLarge`]).
    TooLarge {
        /// Its length on the wire (saturating at `u32::MAX`).
        len: u32,
        /// The most the reader takes.
        max: u32,
    },
}

impl DecodeError {
    /// The error code to answer this frame with.
    pub const fn code(&self) -> ErrorCode {
        match self {
            DecodeError::BadCrc => ErrorCode::BadCrc,
            DecodeError::TooLarge { .. } => ErrorCode::TooLarge,
            DecodeError::Cobs | DecodeError::TooShort | DecodeError::Undecodable { .. } => {
                ErrorCode::Undecodable
            }
        }
    }

    /// The id to answer this frame with ([`UNKNOWN_ID`] when unreadable).
    pub const fn id(&self) -> u32 {
        match self {
            DecodeError::Undecodable { id: Some(id) } => *id,
            _ => UNKNOWN_ID,
        }
    }

    /// The whole reply to send for this frame.
    pub const fn reply(&self) -> ErrorReply {
        match self {
            DecodeError::TooLarge { len, max } => ErrorReply::with(ErrorCode::TooLarge, *len, *max),
            e => ErrorReply::new(e.code()),
        }
    }
}

impl fmt::Display for DecodeError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            DecodeError::Cobs => f.write_str("frame is not valid COBS"),
            DecodeError::TooShort => f.write_str("frame too short for a message and its CRC"),
            DecodeError::BadCrc => f.write_str("frame CRC mismatch"),
            DecodeError::Undecodable { id: Some(id) } => {
                write!(f, "message {id} does not decode")
            }
            DecodeError::Undecodable { id: None } => f.write_str("message does not decode"),
            DecodeError::TooLarge { len, max } => {
                write!(f, "frame of {len} bytes exceeds the limit of {max}")
            }
        }
    }
}

impl<'a> Feed<'a> {
    /// The reader's verdict as a decode result: `None` while pending, the encoded frame, or a
    /// [`DecodeError::TooLarge`] carrying `max`, the reader's capacity.
    pub fn into_frame(self, max: usize) -> Option<Result<&'a mut [u8], DecodeError>> {
        match self {
            Feed::Pending => None,
            Feed::Frame(f) => Some(Ok(f)),
            Feed::TooLarge { len } => Some(Err(DecodeError::TooLarge {
                len: u32::try_from(len).unwrap_or(u32::MAX),
                max: u32::try_from(max).unwrap_or(u32::MAX),
            })),
        }
    }
}

/// Encode `(id, msg)` as one frame into `out`; returns the frame's length, delimiter included.
fn encode<T: Serialize>(id: u32, msg: &T, out: &mut [u8]) -> Result<usize, EncodeError> {
    let value = (id, msg);
    let body = postcard::serialize_with_flavor(&value, postcard::ser_flavors::Size::default())
        .map_err(|_| EncodeError::Serialize)?;
    let payload = body.saturating_add(4);
    let need = wire_len(payload);
    let have = out.len();
    let too_small = EncodeError::BufferTooSmall { need, have };
    if need > have {
        return Err(too_small);
    }
    // Serialize at an offset that leaves room for COBS's extra bytes, then encode in place.
    let src = cobs_overhead(payload);
    // `src + body <= src + payload == need - 1 < have` (`need` did not saturate, or it would
    // exceed `have`), so neither sum wraps.
    let body_end = src.wrapping_add(body);
    let payload_end = src.wrapping_add(payload);
    let region = out.get_mut(src..body_end).ok_or(too_small)?;
    let written = postcard::to_slice(&value, region)
        .map_err(|_| EncodeError::Serialize)?
        .len();
    if written != body {
        return Err(EncodeError::Serialize);
    }
    let crc = crc32(out.get(src..body_end).ok_or(too_small)?);
    let crc_slot = out.get_mut(body_end..payload_end).ok_or(too_small)?;
    // Byte by byte rather than `copy_from_slice`, which keeps a panic path for unequal lengths.
    for (d, b) in crc_slot.iter_mut().zip(crc.to_le_bytes()) {
        *d = b;
    }
    let n = frame::cobs_encode_in_place(out, src, payload).ok_or(too_small)?;
    *out.get_mut(n).ok_or(too_small)? = 0;
    Ok(n.wrapping_add(1)) // n < out.len()
}

/// Undo COBS in place and check the CRC; returns the postcard bytes.
fn unframe(frame: &mut [u8]) -> Result<&[u8], DecodeError> {
    let n = frame::cobs_decode_in_place(frame).ok_or(DecodeError::Cobs)?;
    let payload = frame.get(..n).ok_or(DecodeError::Cobs)?;
    let body_len = n.checked_sub(4).ok_or(DecodeError::TooShort)?;
    if body_len == 0 {
        return Err(DecodeError::TooShort);
    }
    let (body, crc) = payload
        .split_at_checked(body_len)
        .ok_or(DecodeError::TooShort)?;
    let crc = match crc {
        &[a, b, c, d] => u32::from_le_bytes([a, b, c, d]),
        _ => return Err(DecodeError::TooShort),
    };
    if crc32(body) != crc {
        return Err(DecodeError::BadCrc);
    }
    Ok(body)
}

fn decode<'a, T: Deserialize<'a>>(frame: &'a mut [u8]) -> Result<(u32, T), DecodeError> {
    let body = unframe(frame)?;
    match postcard::take_from_bytes::<(u32, T)>(body) {
        Ok((msg, [])) => Ok(msg),
        _ => Err(DecodeError::Undecodable {
            id: postcard::take_from_bytes::<u32>(body)
                .ok()
                .map(|(id, _)| id),
        }),
    }
}

/// Encode a request as one frame (delimiter included) into `out`; returns its length.
/// [`MAX_REQUEST_WIRE`] bytes always suffice for a request within the protocol's limits.
pub fn encode_request(id: u32, req: &Request<'_>, out: &mut [u8]) -> Result<usize, EncodeError> {
    encode(id, req, out)
}

/// Encode a reply as one frame (delimiter included) into `out`; returns its length.
/// [`MAX_REPLY_WIRE`] bytes always suffice for a reply within the protocol's limits.
pub fn encode_reply(id: u32, reply: &Reply<'_>, out: &mut [u8]) -> Result<usize, EncodeError> {
    encode(id, reply, out)
}

/// Decode one request frame: the bytes between two delimiters (as [`Feed::Frame`] gives them).
/// Decodes in place, so the request borrows `frame`.
pub fn decode_request(frame: &mut [u8]) -> Result<(u32, Request<'_>), DecodeError> {
    decode(frame)
}

/// Decode one reply frame: the bytes between two delimiters (as [`Feed::Frame`] gives them).
/// Decodes in place, so the reply borrows `frame`.
pub fn decode_reply(frame: &mut [u8]) -> Result<(u32, Reply<'_>), DecodeError> {
    decode(frame)
}

#[cfg(test)]
mod map_tests;
#[cfg(test)]
mod tests;
