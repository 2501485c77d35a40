//! A path reply in parts: the bytes of a [`PathReply`] read at any offset ([`PathBody`]), and the
//! [`PathPart`] frames that carry a long one, so that no reply holds the link.
//!
//! At 115,200 baud a 2,047-step path is about 10 KB on the wire (0.9 s) and a 16,384-step one
//! about 80 KB (7 s). Sent as one frame, every reply behind it (a `Cancel`'s `Ack`, a `Stats`)
//! would wait that long. So a device sends a path whose body is longer than [`PART_BYTES`] as
//! `PathPart` frames of at most [`PART_BYTES`] body bytes each, in order, and other replies go
//! out between them: one behind a path waits for at most one part (about 17 ms at 115,200).
//!
//! The body is what a `Path` frame carries after its id and variant: postcard's bytes of the
//! [`PathReply`] (no CRC: each part's frame has its own). The host concatenates the parts'
//! `bytes` (part `k` starts at `offset`, the last ends at `total_len`) and decodes the result
//! as a [`PathReply`] ([`decode_path_body`]).
//!
//! Guarantees: [`PathBody::read`] gives exactly the bytes postcard writes for the reply (a unit
//! test checks every offset against `postcard::to_slice`), without a buffer for the whole body;
//! nothing here panics or allocates.

use serde::{Deserialize, Serialize};

use super::{EncodeError, PathReply, Waypoints, MAX_REPLY, WAYPOINT_BYTES};

/// Most body bytes in one [`PathPart`]: its frame is at most 212 bytes on the wire (id, variant,
/// offset and length under 2^21 (three varint bytes each, as no body exceeds `MAX_REPLY`),
/// byte-string length, CRC, COBS and delimiter), 18.4 ms at 115,200 baud. A path whose body is at most this long goes whole, as one `Path` frame.
pub const PART_BYTES: usize = 192;

/// Room for the fixed fields of a path (at most 50 bytes) and the length of the waypoints.
const HEAD: usize = 64;

/// One part of a path reply's body ([`super::Reply::PathPart`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct PathPart<'a> {
    /// Where `bytes` start in the body.
    pub offset: u32,
    /// The body's length: the part that ends here is the last.
    pub total_len: u32,
    /// At most [`PART_BYTES`] bytes of the body.
    pub bytes: &'a [u8],
}

/// The postcard bytes of a [`PathReply`], readable at any offset.
///
/// ```
/// use ohaca::protocol::{decode_path_body, PathBody, PathReply, Waypoints};
/// use ohaca::Point;
/// let points = [Point::new(0, 0), Point::new(3, 2)];
/// let path = PathReply { raw_length: 3.8, length: 3.6, turns: 0, iterations: 21,
///     best_iteration: 0, moves: 4200, ticks: 1689, raw_cells: 4,
///     origin: ohaca::planner::Origin::Cold, waypoints: Waypoints::Points(&points), directions: &[0, 1, 1] };
/// let body = PathBody::new(&path).unwrap();
/// let mut bytes = vec![0u8; body.len()];
/// let (first, rest) = bytes.split_at_mut(5);
/// assert_eq!(body.read(0, first), 5);                 // any split: parts of a long path
/// assert_eq!(body.read(5, rest), body.len() - 5);
/// let back = decode_path_body(&bytes).unwrap();
/// assert_eq!(back.waypoints.iter().collect::<Vec<_>>(), points);
/// ```
#[derive(Clone, Copy)]
pub struct PathBody<'a> {
    head: [u8; HEAD],
    head_len: usize,
    mid: [u8; 5],
    mid_len: usize,
    waypoints: Waypoints<'a>,
    waypoint_bytes: usize,
    directions: &'a [u8],
}

/// Append the postcard varint of `n` to `buf[at..]`; returns the bytes written.
fn put_len(buf: &mut [u8], at: usize, n: usize) -> Result<usize, EncodeError> {
    let n = u32::try_from(n).map_err(|_| EncodeError::Serialize)?;
    let room = buf.get_mut(at..).ok_or(EncodeError::Serialize)?;
    postcard::to_slice(&n, room)
        .map(|b| b.len())
        .map_err(|_| EncodeError::Serialize)
}

impl<'a> PathBody<'a> {
    /// The body of `path`. Fails with [`EncodeError::BufferTooSmall`] when no `Path` frame could
    /// carry it (its payload would exceed [`MAX_REPLY`]).
    pub fn new(path: &PathReply<'a>) -> Result<Self, EncodeError> {
        let body = Self::unchecked(path)?;
        // The widest id and the variant before it, the CRC after it.
        let payload = body.len().saturating_add(5 + 1 + 4);
        if payload > MAX_REPLY {
            return Err(EncodeError::BufferTooSmall {
                need: super::wire_len(payload),
                have: super::MAX_REPLY_WIRE,
            });
        }
        Ok(body)
    }

    /// The body of `path`, whatever its length ([`PathBody::new`] checks it).
    fn unchecked(path: &PathReply<'a>) -> Result<Self, EncodeError> {
        let fixed = PathReply {
            waypoints: Waypoints::Points(&[]),
            directions: &[],
            ..*path
        };
        let mut head = [0u8; HEAD];
        let n = postcard::to_slice(&fixed, &mut head)
            .map_err(|_| EncodeError::Serialize)?
            .len();
        // It ends with the two empty byte strings, one zero length byte each: drop them.
        let head_len = n.checked_sub(2).ok_or(EncodeError::Serialize)?;
        let waypoint_bytes = path.waypoints.len().saturating_mul(WAYPOINT_BYTES);
        // `put_len` writes into `head[head_len..]`, so the sum is at most `HEAD`.
        let head_len = head_len.wrapping_add(put_len(&mut head, head_len, waypoint_bytes)?);
        let mut mid = [0u8; 5];
        let mid_len = put_len(&mut mid, 0, path.directions.len())?;
        Ok(PathBody {
            head,
            head_len,
            mid,
            mid_len,
            waypoints: path.waypoints,
            waypoint_bytes,
            directions: path.directions,
        })
    }

    /// Its length in bytes.
    pub fn len(&self) -> usize {
        self.head_len
            .saturating_add(self.waypoint_bytes)
            .saturating_add(self.mid_len)
            .saturating_add(self.directions.len())
    }

    /// True if it has no bytes (never: a path reply has fixed fields).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The byte at `at`, or `None` past the end.
    pub fn byte(&self, at: usize) -> Option<u8> {
        let Some(at) = at.checked_sub(self.head_len) else {
            return self.head.get(at).copied();
        };
        let Some(at) = at.checked_sub(self.waypoint_bytes) else {
            let p = self.waypoints.get(at / WAYPOINT_BYTES)?;
            let le = match at % WAYPOINT_BYTES {
                0 | 1 => p.x.to_le_bytes(),
                _ => p.y.to_le_bytes(),
            };
            return le.get(at % 2).copied();
        };
        match at.checked_sub(self.mid_len) {
            None => self.mid.get(at).copied(),
            Some(at) => self.directions.get(at).copied(),
        }
    }

    /// Copy the bytes from `offset` into `out`; returns how many (fewer than `out.len()` only at
    /// the end, 0 past it).
    pub fn read(&self, offset: usize, out: &mut [u8]) -> usize {
        let mut n = 0;
        for slot in out.iter_mut() {
            match self.byte(offset.saturating_add(n)) {
                Some(b) => *slot = b,
                None => break,
            }
            n = n.wrapping_add(1); // at most out.len()
        }
        n
    }
}

/// Decode a path reply's body, reassembled from its [`PathPart`]s (the whole of it, nothing
/// after).
pub fn decode_path_body(body: &[u8]) -> Option<PathReply<'_>> {
    match postcard::take_from_bytes::<PathReply<'_>>(body) {
        Ok((path, [])) => Some(path),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::grid::Point;
    use crate::planner::Origin;

    fn path<'a>(points: &'a [Point], dirs: &'a [u8]) -> PathReply<'a> {
        PathReply {
            raw_length: 1234.5,
            length: 1200.25,
            turns: 77,
            iterations: 300,
            best_iteration: 129,
            moves: u64::from(u32::MAX) + 5,
            ticks: 98_765_432,
            raw_cells: u32::try_from(dirs.len() + 1).unwrap(),
            origin: Origin::Repaired,
            waypoints: Waypoints::Points(points),
            directions: dirs,
        }
    }

    #[test]
    fn every_byte_is_postcards() {
        for n in [0usize, 1, 2, 40, 300] {
            let points: Vec<Point> = (0..n as u16).map(|i| Point::new(i * 3, 600 - i)).collect();
            let dirs: Vec<u8> = (0..n * 5).map(|i| (i % 8) as u8).collect();
            let p = path(&points, &dirs);
            let mut want = vec![0u8; 8 + n * 9 + 80];
            let want = postcard::to_slice(&p, &mut want).unwrap();
            let body = PathBody::new(&p).unwrap();
            assert_eq!(body.len(), want.len());
            let got: Vec<u8> = (0..body.len()).map(|i| body.byte(i).unwrap()).collect();
            assert_eq!(got, want);
            assert_eq!(body.byte(body.len()), None);
            // Read in parts of every size from 1 to 7 and one larger than the body.
            for part in (1..8).chain([body.len() + 1]) {
                let mut whole = Vec::new();
                let mut buf = vec![0u8; part];
                loop {
                    let k = body.read(whole.len(), &mut buf);
                    if k == 0 {
                        break;
                    }
                    whole.extend_from_slice(&buf[..k]);
                }
                assert_eq!(whole, want);
            }
            let back = decode_path_body(&got).unwrap();
            assert_eq!(back.waypoints.iter().collect::<Vec<_>>(), points);
            assert_eq!(back.directions, &dirs[..]);
            assert_eq!(back.origin, Origin::Repaired);
            assert_eq!(decode_path_body(&got[..got.len() - 1]), None);
        }
    }
}
