//! The `frame` target: the wire protocol's receive side, device and host.
//!
//! The input is a raw byte stream, as it would arrive on the UART. It goes byte by byte through
//! a [`RequestReader`] exactly as `src/firmware/rx.rs` feeds it (`push(b).into_frame(..)`), every
//! completed frame through [`decode_request`], and the same bytes through a [`ReplyReader`] and
//! [`decode_reply`] as the host's link does (`host/src/link/`), then into the host's owned
//! [`Response`]. Checked, besides "never panics":
//!
//! * the readers split the stream exactly as a reference splitter (split at `0x00`, drop empty
//!   frames, frames longer than the buffer become `TooLarge` with their length);
//! * every frame's verdict matches an independent oracle: a `Vec` COBS decoder and the
//!   `crc32fast` CRC (`Cobs`, `TooShort`, `BadCrc`, or decoded / `Undecodable`);
//! * every error has a `.reply()` / `.id()` the device can send, and that error reply encodes and
//!   decodes back;
//! * a decoded message re-encodes (never larger than the original payload, so within the
//!   protocol limits whenever the original was) and decodes back to the same value, bit for bit;
//! * a decoded path reply sent in parts as the firmware sends it ([`PathBody`] read a piece at a
//!   time, each piece a [`PathPart`] frame of [`encode_reply`]) reassembles to exactly the body
//!   of its whole frame, and [`PathBody::new`] refuses it exactly when that frame with the widest
//!   id would not fit [`MAX_REPLY_WIRE`];
//! * map uploads (raw and run-length) and cell updates go through the device's own state machine
//!   ([`Upload`], [`set_rect`], [`set_cells`]) on a 512x512 buffer, kept across the frames of one
//!   input as on the device: a completed map fits the limits, an accepted update did what it said.

use core::fmt::Debug;

use ohaca::protocol::{
    decode_reply, decode_request, encode_reply, encode_request, set_cells, set_rect, DecodeError,
    EncodeError, Encoding, ErrorReply, MapChunk, MapLimits, PathBody, PathPart, Reply, ReplyReader,
    Request, RequestReader, Upload, MAX_REPLY, MAX_REPLY_WIRE, MAX_REQUEST, MAX_REQUEST_WIRE,
    UNKNOWN_ID,
};
use std::cell::RefCell;

// Any shape of up to 512 x 512 cells with sides up to 4096 (the firmware's rule, other numbers).
const LIMITS: MapLimits = MapLimits {
    max_cells: 512 * 512,
    max_side: 4096,
};

/// The device's map state for one fuzz input: the upload, the buffer, the map's size.
struct MapState {
    upload: Upload,
    bits: Vec<u8>,
    size: Option<(u16, u16)>,
}

thread_local! {
    static MAP: RefCell<MapState> = RefCell::new(MapState {
        upload: Upload::new(),
        bits: vec![0; LIMITS.bytes()],
        size: None,
    });
}

fn bit(bits: &[u8], w: u16, x: u16, y: u16) -> bool {
    let i = usize::from(y) * usize::from(w) + usize::from(x);
    bits[i / 8] >> (i % 8) & 1 == 1
}

/// Apply a decoded request to the map state as `src/firmware/rx.rs` does.
fn apply_map_request(req: &Request<'_>) {
    MAP.with(|m| {
        let m = &mut *m.borrow_mut();
        let chunk = match *req {
            Request::SetMap {
                width,
                height,
                offset,
                total_len,
                chunk,
            } => (Encoding::Raw, width, height, offset, total_len, chunk),
            Request::SetMapRle {
                width,
                height,
                offset,
                total_len,
                chunk,
            } => (Encoding::Rle, width, height, offset, total_len, chunk),
            Request::SetRect {
                x,
                y,
                width,
                height,
                blocked,
            } => {
                if let Some(size) = m.size {
                    if set_rect(size, &mut m.bits, (x, y, width, height), blocked).is_ok()
                        && width > 0
                        && height > 0
                    {
                        assert_eq!(bit(&m.bits, size.0, x, y), blocked);
                        let (fx, fy) = (x + width - 1, y + height - 1);
                        assert_eq!(bit(&m.bits, size.0, fx, fy), blocked);
                    }
                }
                return;
            }
            Request::SetCells { blocked, cells } => {
                if let Some(size) = m.size {
                    if set_cells(size, &mut m.bits, &cells, blocked).is_ok() {
                        for p in cells.iter() {
                            assert_eq!(bit(&m.bits, size.0, p.x, p.y), blocked);
                        }
                    }
                }
                return;
            }
            _ => return,
        };
        let (encoding, width, height, offset, total_len, bytes) = chunk;
        let c = MapChunk {
            encoding,
            width,
            height,
            offset,
            total_len,
            chunk: bytes,
        };
        match m.upload.accept(&c, LIMITS) {
            Ok(start) => {
                if start {
                    m.size = None;
                }
                match m.upload.write(&c, &mut m.bits) {
                    Ok(Some((w, h))) => {
                        assert!(w <= 512 && h <= 512 && w > 0 && h > 0);
                        assert!(!m.upload.is_open());
                        m.size = Some((w, h));
                    }
                    Ok(None) => assert!(m.upload.is_open()),
                    Err(e) => {
                        let _ = format!("{e}");
                    }
                }
            }
            Err(e) => {
                let _ = format!("{e}");
            }
        }
    });
}
use ohaca::Point;
use ohaca_host::link::{request_name, LinkError, Response};

/// What a reader should report for one delimiter, per the reference splitter.
#[derive(Debug, PartialEq, Eq)]
enum Split {
    Frame(Vec<u8>),
    TooLarge(usize),
}

/// Split `data` at `0x00` as a frame reader with a buffer of `cap` bytes must: empty frames
/// vanish, longer ones are reported with their length. The unterminated tail is returned apart.
fn reference_split(data: &[u8], cap: usize) -> (Vec<Split>, usize) {
    let mut out = Vec::new();
    let mut parts = data.split(|&b| b == 0).peekable();
    let mut tail = 0;
    while let Some(part) = parts.next() {
        if parts.peek().is_none() {
            tail = part.len();
            break;
        }
        if part.is_empty() {
            continue;
        }
        out.push(if part.len() <= cap {
            Split::Frame(part.to_vec())
        } else {
            Split::TooLarge(part.len())
        });
    }
    (out, tail)
}

/// Textbook COBS decoding into a new buffer (the oracle for the in-place decoder).
fn reference_cobs(src: &[u8]) -> Option<Vec<u8>> {
    let mut out = Vec::with_capacity(src.len());
    let mut i = 0;
    while i < src.len() {
        let code = src[i];
        if code == 0 {
            return None;
        }
        i += 1;
        for _ in 1..code {
            let &b = src.get(i)?;
            if b == 0 {
                return None;
            }
            out.push(b);
            i += 1;
        }
        if code != 0xFF && i < src.len() {
            out.push(0);
        }
    }
    Some(out)
}

/// The oracle's verdict on one frame: the postcard body if COBS and CRC are fine, else the error
/// the decoder must report.
fn reference_unframe(frame: &[u8]) -> Result<Vec<u8>, DecodeError> {
    let payload = reference_cobs(frame).ok_or(DecodeError::Cobs)?;
    if payload.len() < 5 {
        return Err(DecodeError::TooShort);
    }
    let (body, crc) = payload.split_at(payload.len() - 4);
    let crc = u32::from_le_bytes([crc[0], crc[1], crc[2], crc[3]]);
    if crc32fast::hash(body) != crc {
        return Err(DecodeError::BadCrc);
    }
    Ok(body.to_vec())
}

/// A decode error must map to a reply the device can send, with the id rule of the protocol.
fn check_error(e: &DecodeError) {
    let reply: ErrorReply = e.reply();
    assert_eq!(reply.code, e.code(), "{e:?}");
    match *e {
        DecodeError::Undecodable { id: Some(id) } => assert_eq!(e.id(), id),
        DecodeError::TooLarge { len, max } => {
            assert_eq!(e.id(), UNKNOWN_ID);
            assert_eq!((reply.detail, reply.limit), (len, max));
        }
        _ => assert_eq!(e.id(), UNKNOWN_ID, "{e:?}"),
    }
    let _ = format!("{e} / {reply} / {}", LinkError::Decode(*e));
    // The device sends `Reply::Error(e.reply())` with `e.id()`: it must encode within the limits
    // and read back.
    let mut buf = vec![0u8; MAX_REQUEST_WIRE];
    let n = encode_reply(e.id(), &Reply::Error(reply), &mut buf).expect("error reply encodes");
    let (id, back) = decode_reply(&mut buf[..n - 1]).expect("error reply decodes");
    assert_eq!((id, back), (e.id(), Reply::Error(reply)));
}

/// Encode → decode → encode must be stable: same id, same bytes, same value.
fn check_roundtrip<M: Debug>(
    id: u32,
    msg: &M,
    body_len: usize,
    limit: usize,
    buf_len: usize,
    encode: impl Fn(u32, &M, &mut [u8]) -> Result<usize, EncodeError>,
    decode: impl for<'b> Fn(&'b mut [u8]) -> (u32, Vec<u8>, String, bool),
) {
    // Room for anything a reader can hold, whatever the protocol's limits.
    let mut buf = vec![0u8; 2 * buf_len + 16];
    let n = encode(id, msg, &mut buf).expect("a decoded message re-encodes");
    let wire = buf[..n].to_vec();
    assert_eq!(wire.last(), Some(&0), "frame ends with its delimiter");
    assert!(!wire[..n - 1].contains(&0), "COBS leaves no zero inside");
    let payload = reference_cobs(&wire[..n - 1]).expect("own frames are valid COBS");
    let (body, crc) = payload.split_at(payload.len() - 4);
    assert_eq!(crc32fast::hash(body).to_le_bytes(), crc);
    // Canonical postcard is never longer than what was decoded.
    assert!(
        body.len() <= body_len,
        "re-encoded {} > decoded {body_len} bytes",
        body.len()
    );
    if body.len() + 4 <= limit {
        let mut small = vec![0u8; buf_len];
        let m = encode(id, msg, &mut small).expect("within the limits, the max buffer suffices");
        assert_eq!(small[..m], wire[..]);
    }
    let (id2, reencoded, debug2, same) = decode(&mut buf[..n - 1]);
    assert_eq!(id2, id);
    assert_eq!(reencoded, wire, "decode → encode is not stable");
    assert_eq!(debug2, format!("{msg:?}"));
    assert!(same, "decoded value differs from the re-encoded one");
}

/// True if `v` is unequal to itself (a NaN inside).
#[allow(clippy::eq_op)]
fn has_nan<T: PartialEq>(v: &T) -> bool {
    v != v
}

fn check_request_frame(frame: &mut [u8]) -> bool {
    let expect = reference_unframe(frame);
    match decode_request(frame) {
        Err(e) => {
            check_error(&e);
            match (&expect, e) {
                (Err(want), got) => assert_eq!(*want, got),
                (Ok(_), DecodeError::Undecodable { .. }) => {}
                (Ok(_), got) => panic!("oracle says the frame is sound, decoder says {got:?}"),
            }
            false
        }
        Ok((id, req)) => {
            let body = expect.expect("decoder accepted a frame the oracle rejects");
            if let Request::SetParams(p) = req {
                let _ = p.validate();
            }
            apply_map_request(&req);
            let _ = request_name(&req);
            check_roundtrip(
                id,
                &req,
                body.len(),
                MAX_REQUEST,
                MAX_REQUEST_WIRE,
                encode_request,
                |f| {
                    let (id2, req2) = decode_request(f).expect("re-encoded request decodes");
                    let mut out = vec![0u8; 2 * MAX_REQUEST_WIRE + 16];
                    let n = encode_request(id2, &req2, &mut out).expect("encodes again");
                    out.truncate(n);
                    // NaN parameters compare unequal to themselves; the bytes settle those.
                    let same = has_nan(&req) || req2 == req;
                    (id2, out, format!("{req2:?}"), same)
                },
            );
            true
        }
    }
}

fn check_reply_frame(frame: &mut [u8], piece: usize) -> bool {
    let expect = reference_unframe(frame);
    match decode_reply(frame) {
        Err(e) => {
            check_error(&e);
            match (&expect, e) {
                (Err(want), got) => assert_eq!(*want, got),
                (Ok(_), DecodeError::Undecodable { .. }) => {}
                (Ok(_), got) => panic!("oracle says the frame is sound, decoder says {got:?}"),
            }
            false
        }
        Ok((id, reply)) => {
            let body = expect.expect("decoder accepted a frame the oracle rejects");
            // What the host does with it.
            let resp = Response::from(&reply);
            let _ = resp.kind();
            match (&reply, &resp) {
                (Reply::Path(p), Response::Path(d)) => {
                    assert_eq!(d.waypoints.len(), p.waypoints.len());
                    assert!(d.waypoints.iter().copied().eq(p.waypoints.iter()));
                    if let Ok(raw) = d.raw(Point::new(1000, 1000)) {
                        assert_eq!(raw.len(), d.directions.len() + 1);
                    }
                    check_parts(id, &reply, piece);
                }
                (Reply::Error(e), _) => {
                    let _ = format!("{e}");
                    if let Ok(core) = ohaca::Error::try_from(*e) {
                        assert_eq!(ErrorReply::from(core).code, e.code);
                    }
                }
                _ => {}
            }
            check_roundtrip(
                id,
                &reply,
                body.len(),
                MAX_REPLY,
                MAX_REPLY_WIRE,
                encode_reply,
                |f| {
                    let (id2, r2) = decode_reply(f).expect("re-encoded reply decodes");
                    let mut out = vec![0u8; 2 * MAX_REPLY_WIRE + 16];
                    let n = encode_reply(id2, &r2, &mut out).expect("encodes again");
                    out.truncate(n);
                    let same = has_nan(&reply) || r2 == reply;
                    (id2, out, format!("{r2:?}"), same)
                },
            );
            true
        }
    }
}

/// A path reply sent in [`PathPart`] frames of `piece` bytes (as the firmware sends a long path)
/// must reassemble to the body of `encode_reply`'s whole frame, and [`PathBody::new`] must
/// refuse it exactly when that frame with the widest id does not fit [`MAX_REPLY_WIRE`].
fn check_parts(id: u32, reply: &Reply<'_>, piece: usize) {
    let Reply::Path(p) = reply else { return };
    let mut whole = vec![0u8; MAX_REPLY_WIRE];
    let widest = encode_reply(u32::MAX, reply, &mut whole);
    match (PathBody::new(p), widest) {
        (Ok(body), Ok(_)) => {
            let n = encode_reply(id, reply, &mut whole).expect("fits with the widest id");
            let payload = reference_unframe(&whole[..n - 1]).expect("own frame");
            let mut got = Vec::with_capacity(body.len());
            let mut buf = vec![0u8; piece.clamp(1, ohaca::protocol::PART_BYTES)];
            let mut frame = vec![0u8; MAX_REPLY_WIRE];
            loop {
                let k = body.read(got.len(), &mut buf);
                if k == 0 {
                    break;
                }
                let part = PathPart {
                    offset: got.len() as u32,
                    total_len: body.len() as u32,
                    bytes: &buf[..k],
                };
                let m = encode_reply(id, &Reply::PathPart(part), &mut frame).expect("a part fits");
                match decode_reply(&mut frame[..m - 1]) {
                    Ok((i, Reply::PathPart(back))) if i == id => {
                        assert_eq!(back.offset as usize, got.len());
                        got.extend_from_slice(back.bytes);
                    }
                    other => panic!("a part decodes as {other:?}"),
                }
                assert!(got.len() <= body.len(), "parts longer than the body");
            }
            assert!(payload.ends_with(&got), "parts are not the whole reply's body");
            assert_eq!(got.len(), body.len());
        }
        (Err(a), Err(b)) => assert_eq!(a, b),
        (a, b) => panic!("PathBody {:?} vs encode_reply {b:?}", a.map(|_| ())),
    }
}

/// Feed `data` through a reader of capacity `cap` and check every delimiter's verdict against
/// the reference splitter; `frame` gets every complete frame.
fn run_reader<const N: usize>(
    reader: &mut ohaca::protocol::FrameReader<N>,
    data: &[u8],
    mut frame: impl FnMut(&mut [u8]) -> bool,
) -> usize {
    let (want, tail) = reference_split(data, N);
    let mut got = Vec::with_capacity(want.len());
    let mut decoded = 0;
    for &b in data {
        // Exactly as `src/firmware/rx.rs` and `host/src/link/` do it.
        let Some(f) = reader.push(b).into_frame(N) else {
            continue;
        };
        match f {
            Ok(f) => {
                got.push(Split::Frame(f.to_vec()));
                decoded += usize::from(frame(f));
            }
            Err(e) => {
                let DecodeError::TooLarge { len, max } = e else {
                    panic!("a reader reports only TooLarge, got {e:?}");
                };
                assert_eq!(max as usize, N);
                check_error(&e);
                got.push(Split::TooLarge(len as usize));
            }
        }
    }
    assert_eq!(got, want, "frame splitting differs from the reference");
    assert_eq!(reader.pending(), tail);
    decoded
}

/// Check `data` as a request stream and as a reply stream; returns how many frames decoded as
/// requests and as replies.
pub fn check_streams(data: &[u8]) -> (usize, usize) {
    let mut requests = Box::new(RequestReader::new());
    let req = run_reader(&mut requests, data, check_request_frame);
    let piece = data.first().map_or(7, |&b| usize::from(b) + 1);
    let mut replies = Box::new(ReplyReader::new());
    let rep = run_reader(&mut replies, data, |f| check_reply_frame(f, piece));
    (req, rep)
}

/// The `frame` fuzz target.
pub fn fuzz_wire_frame(data: &[u8]) {
    // Every input starts on a device without a map.
    MAP.with(|m| {
        let m = &mut *m.borrow_mut();
        m.upload = Upload::new();
        m.size = None;
    });
    check_streams(data);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn oracle_agrees_on_own_frames() {
        let mut buf = [0u8; MAX_REQUEST_WIRE];
        let n = encode_request(9, &Request::Stats, &mut buf).unwrap();
        assert!(reference_unframe(&buf[..n - 1]).is_ok());
        fuzz_wire_frame(&buf[..n]);
    }

    #[test]
    fn reference_split_rules() {
        let (s, tail) = reference_split(&[0, 1, 2, 0, 0, 3, 3, 3, 0, 4], 2);
        assert_eq!(s, vec![Split::Frame(vec![1, 2]), Split::TooLarge(3)]);
        assert_eq!(tail, 1);
    }
}
