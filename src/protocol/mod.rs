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
//!   exactly one reply carrying the same `id` (a long path: with [`PathPart`] frames that
//!   together are that reply, [`parts`](PathBody)). A frame that cannot be attributed (bad CRC, bad
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
//!
//! This module owns the limits and turning a message into a frame and back ([`encode_request`],
//! [`decode_reply`], ...); the rest lives in one file a concept:
//!
//! | file | owns |
//! | --- | --- |
//! | `message` | [`Request`], [`Reply`] and the reply bodies |
//! | `error_reply` | [`ErrorReply`], [`ErrorCode`] and their mapping to the planner's errors |
//! | `frame` | CRC-32, COBS and the byte-at-a-time [`FrameReader`] |
//! | `wire` | serde glue: points on the wire, the packed [`Waypoints`] |
//! | `parts` | [`PathBody`], [`PathPart`]: a long path reply in frames other replies can pass |
//! | `map` | map uploads (raw and run-length) and cell updates as the device applies them |

use core::fmt;

use serde::{Deserialize, Serialize};

mod error_reply;
mod frame;
mod map;
mod message;
mod parts;
mod wire;

pub use error_reply::{ErrorCode, ErrorReply, UnknownCode};

pub use frame::{cobs_overhead, crc32, wire_len, Feed, FrameReader};
pub use map::{
    check_cells, check_rect, set_cells, set_rect, Encoding, MapChunk, MapLimits, RleDecoder,
    RleEncoder, RleError, Upload, MAX_UPDATE_CELLS,
};
pub use message::{Capacity, HelloReply, PathReply, Reply, Request, StatsReply};
pub use parts::{decode_path_body, PathBody, PathPart, PART_BYTES};
pub use wire::{Waypoints, WAYPOINT_BYTES};

/// Protocol version, reported in [`HelloReply::protocol_version`]. Bumped on any change to the
/// bytes or meaning of a message (2: [`StatsReply::stack_peak`]; 3: run-length uploads, cell
/// updates, warm plans, [`Capacity`]'s sides are the largest map held; 4: warm replies and
/// `warm_patience`; 5: `refine_patience` and `refine`; 6: [`Capacity`] by cells, `max_side` and
/// `max_steps`; 7: [`MAX_REPLY`] carries every path of [`MAX_STEPS`] steps; 8: [`MAX_STEPS`]
/// 16,384; 9: [`PathReply::origin`] replaces `warm`, a `PlanWarm` may be answered with the rest
/// of the previous answer; 10: a path longer than [`PART_BYTES`] comes as [`Reply::PathPart`]s,
/// [`Capacity::window`] and `window_bytes`, [`StatsReply::replies_dropped`] and `parted`).
pub const VERSION: u16 = 10;

/// The id of replies to frames whose request id could not be read. Hosts should not use it.
pub const UNKNOWN_ID: u32 = 0;

/// Most map bytes in one [`Request::SetMap`] chunk.
pub const MAX_CHUNK: usize = 128;

/// Longest path, in steps, a device may plan ([`Capacity::max_steps`] is at most this): the
/// wire's bound, not a board's (each board's is `crate::board::Board::max_steps`); today it
/// equals the STM32H743's 16,384, the largest of the boards. Every such path fits one
/// [`PathReply`].
pub const MAX_STEPS: usize = 16_384;

/// Most waypoints in a [`PathReply`]: every cell of a path of [`MAX_STEPS`] steps.
pub const MAX_WAYPOINTS: usize = MAX_STEPS + 1;

/// Most raw-path directions in a [`PathReply`]: one a step of a path of [`MAX_STEPS`] steps.
pub const MAX_DIRECTIONS: usize = MAX_STEPS;

/// Largest request payload (postcard bytes plus CRC) a device must accept.
pub const MAX_REQUEST: usize = 256;

/// Bytes of postcard's varint of `n`.
const fn varint_len(n: usize) -> usize {
    let mut len: usize = 1;
    let mut rest = n >> 7;
    while rest > 0 {
        len = len.wrapping_add(1); // at most 10
        rest >>= 7;
    }
    len
}

/// Most bytes of a [`Reply::Path`] payload (postcard bytes plus CRC) with `waypoints` waypoints
/// and `directions` directions: every fixed field at its widest (the id and the integers as the
/// longest varints), then the two byte strings with their lengths, then the CRC.
pub const fn path_payload(waypoints: usize, directions: usize) -> usize {
    // id, variant, raw_length, length, turns, iterations, best_iteration, moves, ticks,
    // raw_cells, warm.
    const FIXED: usize = 5 + 1 + 4 + 4 + 5 + 3 + 3 + 10 + 10 + 5 + 1;
    let points = waypoints.saturating_mul(WAYPOINT_BYTES);
    FIXED
        .saturating_add(varint_len(points))
        .saturating_add(points)
        .saturating_add(varint_len(directions))
        .saturating_add(directions)
        .saturating_add(4)
}

/// Largest reply payload (postcard bytes plus CRC) a host must accept: a [`PathReply`] with
/// [`MAX_WAYPOINTS`] waypoints and [`MAX_DIRECTIONS`] directions, every path of [`MAX_STEPS`]
/// steps, fits (81,985 bytes). A device need not hold one: it sends a long path in
/// [`PathPart`] frames read from a [`PathBody`], each encoded by the one encoder,
/// [`encode_reply`].
pub const MAX_REPLY: usize = path_payload(MAX_WAYPOINTS, MAX_DIRECTIONS);

// The figure docs/PROTOCOL.md gives (`host-tests/tests/it/documents.rs` reads it there and encodes
// the widest path reply): a change to `MAX_STEPS` or to `PathReply` is a new protocol version.
// Each board checks its `max_steps` against `MAX_STEPS` (`firmware::board`).
const _: () = assert!(MAX_REPLY == 81_985);

/// Largest request frame on the wire, delimiter included.
pub const MAX_REQUEST_WIRE: usize = wire_len(MAX_REQUEST);

/// Largest reply frame on the wire, delimiter included.
pub const MAX_REPLY_WIRE: usize = wire_len(MAX_REPLY);

/// A frame reader sized for requests (the device side).
pub type RequestReader = FrameReader<MAX_REQUEST_WIRE>;

/// A frame reader sized for replies (the host side).
pub type ReplyReader = FrameReader<MAX_REPLY_WIRE>;

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
mod tests;
