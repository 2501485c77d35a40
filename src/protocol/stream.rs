//! A path reply encoded a piece at a time, for a device without room for a whole reply frame.
//!
//! [`PathStream`] produces exactly the bytes [`super::encode_reply`] writes for a
//! [`super::Reply::Path`], in pieces as small as the caller likes: the body is read from the
//! reply's slices as it goes out ([`PathBody`]), the CRC is computed on the way, and COBS works
//! one block (at most 254 bytes) ahead. It takes about 350 bytes instead of a
//! [`MAX_REPLY_WIRE`]-byte frame buffer. A unit test checks it against [`super::encode_reply`]
//! byte for byte. It suits a link that one long frame may hold; the firmware sends long paths
//! in parts instead, so that other replies pass them (`super::parts`).

use super::frame::{crc32_step, CRC32_INIT};
use super::parts::PathBody;
use super::{wire_len, EncodeError, PathReply, MAX_REPLY, MAX_REPLY_WIRE};

/// Room for the id and the variant (at most 5 + 1 bytes).
const PREFIX: usize = 6;
/// Longest COBS block: up to 254 data bytes follow a code byte.
const BLOCK: usize = 254;
/// The variant of `Reply::Path`.
const PATH_VARIANT: u8 = 2;

/// The parts of the payload, in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Part {
    /// Id and variant (`prefix`).
    Prefix,
    /// The path's body ([`PathBody`]).
    Body,
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

/// A [`super::Reply::Path`] frame, encoded on demand by [`PathStream::fill`].
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
    prefix: [u8; PREFIX],
    prefix_len: usize,
    body: PathBody<'a>,
    part: Part,
    pos: usize,
    crc: u32,
    block: [u8; BLOCK],
    block_len: usize,
    stage: Stage,
}

impl<'a> PathStream<'a> {
    /// Prepare the frame of `Reply::Path(path)` with this `id`. Fails with
    /// [`EncodeError::BufferTooSmall`] (`have` = [`MAX_REPLY_WIRE`]) if the path is over the
    /// protocol's limits, exactly when [`super::encode_reply`] into a [`MAX_REPLY_WIRE`] buffer
    /// would.
    pub fn new(id: u32, path: &PathReply<'a>) -> Result<Self, EncodeError> {
        let body = PathBody::unchecked(path)?;
        let mut prefix = [0u8; PREFIX];
        let n = postcard::to_slice(&id, &mut prefix)
            .map_err(|_| EncodeError::Serialize)?
            .len();
        *prefix.get_mut(n).ok_or(EncodeError::Serialize)? = PATH_VARIANT;
        let prefix_len = n.wrapping_add(1); // n < PREFIX
        let payload = prefix_len.saturating_add(body.len()).saturating_add(4);
        if payload > MAX_REPLY {
            return Err(EncodeError::BufferTooSmall {
                need: wire_len(payload),
                have: MAX_REPLY_WIRE,
            });
        }
        Ok(PathStream {
            prefix,
            prefix_len,
            body,
            part: Part::Prefix,
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
                Part::Prefix => self
                    .prefix
                    .get(..self.prefix_len)
                    .and_then(|h| h.get(pos))
                    .copied(),
                Part::Body => self.body.byte(pos),
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
                        Part::Prefix => Part::Body,
                        Part::Body => Part::Crc,
                        Part::Crc | Part::End => Part::End,
                    };
                }
            }
        }
    }
}
