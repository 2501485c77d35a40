//! A path reply encoded a piece at a time, for a device without room for a whole reply frame.
//!
//! [`PathStream`] produces exactly the bytes [`super::encode_reply`] writes for a
//! [`Reply::Path`], in pieces as small as the caller likes: postcard serializes the fixed fields
//! into a small buffer, the waypoints and directions are read from the caller's slices as they go
//! out, the CRC is computed on the way, and COBS works one block (at most 254 bytes) ahead. It
//! takes about 350 bytes instead of a [`MAX_REPLY_WIRE`]-byte frame buffer. A unit test checks
//! it against [`super::encode_reply`] byte for byte.

use super::frame::{crc32_step, CRC32_INIT};
use super::{
    wire_len, EncodeError, PathReply, Reply, Waypoints, MAX_REPLY, MAX_REPLY_WIRE, WAYPOINT_BYTES,
};

/// Room for the id, the variant, the fixed fields of a path (at most 50 bytes) and the length of
/// the waypoints.
const HEAD: usize = 64;
/// Longest COBS block: up to 254 data bytes follow a code byte.
const BLOCK: usize = 254;

/// The parts of the payload, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Part {
    /// Id, variant, fixed fields, length of the waypoints (`head`).
    Head,
    /// The waypoints, 4 bytes a point.
    Waypoints,
    /// Length of the directions (`mid`).
    Mid,
    /// The directions.
    Directions,
    /// The CRC, little-endian.
    Crc,
    /// Nothing left.
    End,
}

/// Where the COBS encoder is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Stage {
    /// Collect the next block from the payload.
    Gather,
    /// Send the block: its code byte (`at` = 0), then its bytes; `last` once the payload ended.
    Emit { at: usize, last: bool },
    /// Send the delimiter.
    Delimiter,
    /// The frame is complete.
    Done,
}

/// A [`Reply::Path`] frame, encoded on demand by [`PathStream::fill`].
///
/// ```
/// use ohaca::protocol::{decode_reply, encode_reply, PathReply, PathStream, Reply, Waypoints,
///                       MAX_REPLY_WIRE};
/// use ohaca::Point;
/// let points = [Point::new(0, 0), Point::new(3, 2)];
/// let path = PathReply { raw_length: 3.8, length: 3.6, turns: 0, iterations: 21,
///     best_iteration: 0, moves: 4200, ticks: 1689, raw_cells: 4,
///     origin: ohaca::planner::Origin::Cold, waypoints: Waypoints::Points(&points), directions: &[0, 1, 1] };
/// let mut stream = PathStream::new(3, &path).unwrap();
/// let (mut wire, mut piece) = (Vec::new(), [0u8; 16]);
/// loop {
///     let n = stream.fill(&mut piece);        // send `piece[..n]` here
///     if n == 0 { break; }
///     wire.extend_from_slice(&piece[..n]);
/// }
/// let mut whole = vec![0u8; MAX_REPLY_WIRE];
/// let len = encode_reply(3, &Reply::Path(path), &mut whole).unwrap();
/// assert_eq!(wire, &whole[..len]);
/// ```
pub struct PathStream<'a> {
    head: [u8; HEAD],
    head_len: usize,
    mid: [u8; 5],
    mid_len: usize,
    waypoints: Waypoints<'a>,
    waypoint_bytes: usize,
    directions: &'a [u8],
    part: Part,
    pos: usize,
    crc: u32,
    block: [u8; BLOCK],
    block_len: usize,
    stage: Stage,
}

/// Append the postcard varint of `n` to `buf[at..]`; returns the bytes written.
fn put_len(buf: &mut [u8], at: usize, n: usize) -> Result<usize, EncodeError> {
    let n = u32::try_from(n).map_err(|_| EncodeError::Serialize)?;
    let room = buf.get_mut(at..).ok_or(EncodeError::Serialize)?;
    postcard::to_slice(&n, room)
        .map(|b| b.len())
        .map_err(|_| EncodeError::Serialize)
}

impl<'a> PathStream<'a> {
    /// Prepare the frame of `Reply::Path(path)` with this `id`. Fails with
    /// [`EncodeError::BufferTooSmall`] (`have` = [`MAX_REPLY_WIRE`]) if the path is over the
    /// protocol's limits, exactly when [`super::encode_reply`] into a [`MAX_REPLY_WIRE`] buffer
    /// would.
    pub fn new(id: u32, path: &PathReply<'a>) -> Result<Self, EncodeError> {
        let fixed = Reply::Path(PathReply {
            waypoints: Waypoints::Points(&[]),
            directions: &[],
            ..*path
        });
        let mut head = [0u8; HEAD];
        let n = postcard::to_slice(&(id, &fixed), &mut head)
            .map_err(|_| EncodeError::Serialize)?
            .len();
        // It ends with the two empty byte strings, one zero length byte each: drop them.
        let head_len = n.checked_sub(2).ok_or(EncodeError::Serialize)?;
        let waypoint_bytes = path.waypoints.len().saturating_mul(WAYPOINT_BYTES);
        // `put_len` writes into `head[head_len..]`, so the sum is at most `HEAD`.
        let head_len = head_len.wrapping_add(put_len(&mut head, head_len, waypoint_bytes)?);
        let mut mid = [0u8; 5];
        let mid_len = put_len(&mut mid, 0, path.directions.len())?;
        let payload = head_len
            .saturating_add(waypoint_bytes)
            .saturating_add(mid_len)
            .saturating_add(path.directions.len())
            .saturating_add(4);
        if payload > MAX_REPLY {
            return Err(EncodeError::BufferTooSmall {
                need: wire_len(payload),
                have: MAX_REPLY_WIRE,
            });
        }
        Ok(PathStream {
            head,
            head_len,
            mid,
            mid_len,
            waypoints: path.waypoints,
            waypoint_bytes,
            directions: path.directions,
            part: Part::Head,
            pos: 0,
            crc: CRC32_INIT,
            block: [0; BLOCK],
            block_len: 0,
            stage: Stage::Gather,
        })
    }

    /// True once every byte of the frame (delimiter included) has been handed out.
    pub fn is_done(&self) -> bool {
        self.stage == Stage::Done
    }

    /// Write the next bytes of the frame into `out`; returns how many (`out.len()` unless the
    /// frame ends first; 0 once it is complete).
    pub fn fill(&mut self, out: &mut [u8]) -> usize {
        let mut n = 0;
        while let Some(slot) = out.get_mut(n) {
            match self.stage {
                Stage::Gather => self.gather(),
                Stage::Emit { at, last } => {
                    let byte = match at.checked_sub(1) {
                        // The code byte: block_len <= 254, so 1..=255 without wrapping.
                        None => (self.block_len as u8).wrapping_add(1),
                        Some(i) => self.block.get(i).copied().unwrap_or(0),
                    };
                    *slot = byte;
                    n = n.wrapping_add(1); // < out.len(): the slot existed
                    self.stage = if at < self.block_len {
                        Stage::Emit {
                            at: at.wrapping_add(1), // <= block_len <= BLOCK
                            last,
                        }
                    } else if last {
                        Stage::Delimiter
                    } else {
                        Stage::Gather
                    };
                }
                Stage::Delimiter => {
                    *slot = 0;
                    n = n.wrapping_add(1); // < out.len(): the slot existed
                    self.stage = Stage::Done;
                }
                Stage::Done => break,
            }
        }
        n
    }

    /// Read the next COBS block: payload bytes up to a zero (which the block stands for), 254
    /// non-zero bytes, or the end of the payload.
    fn gather(&mut self) {
        self.block_len = 0;
        let last = loop {
            match self.next_byte() {
                None => break true,
                Some(0) => break false,
                Some(b) => {
                    if let Some(slot) = self.block.get_mut(self.block_len) {
                        *slot = b;
                    }
                    self.block_len = self.block_len.wrapping_add(1); // < BLOCK before
                    if self.block_len == BLOCK {
                        break false;
                    }
                }
            }
        };
        self.stage = Stage::Emit { at: 0, last };
    }

    /// The next payload byte (postcard bytes, then the CRC), or `None` at its end.
    fn next_byte(&mut self) -> Option<u8> {
        loop {
            let pos = self.pos;
            let byte = match self.part {
                Part::Head => self
                    .head
                    .get(..self.head_len)
                    .and_then(|h| h.get(pos))
                    .copied(),
                Part::Waypoints if pos < self.waypoint_bytes => {
                    let p = self.waypoints.get(pos / WAYPOINT_BYTES).unwrap_or_default();
                    let le = match pos % WAYPOINT_BYTES {
                        0 | 1 => p.x.to_le_bytes(),
                        _ => p.y.to_le_bytes(),
                    };
                    le.get(pos % 2).copied()
                }
                Part::Waypoints => None,
                Part::Mid => self
                    .mid
                    .get(..self.mid_len)
                    .and_then(|m| m.get(pos))
                    .copied(),
                Part::Directions => self.directions.get(pos).copied(),
                Part::Crc => {
                    let crc = (!self.crc).to_le_bytes();
                    if let Some(&b) = crc.get(pos) {
                        self.pos = pos.wrapping_add(1); // pos < 4
                        return Some(b);
                    }
                    None
                }
                Part::End => return None,
            };
            match byte {
                Some(b) => {
                    // `pos` indexed a byte of the current part, so it is below a slice length.
                    self.pos = pos.wrapping_add(1);
                    self.crc = crc32_step(self.crc, b);
                    return Some(b);
                }
                None => {
                    self.pos = 0;
                    self.part = match self.part {
                        Part::Head => Part::Waypoints,
                        Part::Waypoints => Part::Mid,
                        Part::Mid => Part::Directions,
                        Part::Directions => Part::Crc,
                        Part::Crc | Part::End => Part::End,
                    };
                }
            }
        }
    }
}
