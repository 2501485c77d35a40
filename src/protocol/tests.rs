use super::frame::{cobs_decode_in_place, cobs_encode_in_place};
use super::*;
use crate::ant::DeadEnd;
use crate::error::Param;
use crate::planner::Algorithm;
use crate::smoothing::SmoothingKind;

/// A small deterministic generator for the fuzz-style tests.
struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 33) as u32
    }
    fn byte(&mut self) -> u8 {
        self.next() as u8
    }
}

fn cobs(data: &[u8]) -> Vec<u8> {
    let src = cobs_overhead(data.len());
    let mut buf = vec![0u8; src + data.len()];
    buf[src..].copy_from_slice(data);
    let n = cobs_encode_in_place(&mut buf, src, data.len()).unwrap();
    buf.truncate(n);
    buf
}

fn uncobs(data: &[u8]) -> Option<Vec<u8>> {
    let mut b = data.to_vec();
    let n = cobs_decode_in_place(&mut b)?;
    b.truncate(n);
    Some(b)
}

/// A frame (without delimiter) around arbitrary postcard bytes, with a correct CRC.
fn frame_body(body: &[u8]) -> Vec<u8> {
    let mut p = body.to_vec();
    p.extend_from_slice(&crc32(body).to_le_bytes());
    cobs(&p)
}

fn enc_req(id: u32, r: &Request<'_>) -> Vec<u8> {
    let mut buf = vec![0u8; MAX_REQUEST_WIRE];
    let n = encode_request(id, r, &mut buf).unwrap();
    buf.truncate(n);
    buf
}

fn enc_rep(id: u32, r: &Reply<'_>) -> Vec<u8> {
    let mut buf = vec![0u8; MAX_REPLY_WIRE];
    let n = encode_reply(id, r, &mut buf).unwrap();
    buf.truncate(n);
    buf
}

const MAP: [u8; 2] = [0x20, 0x00];
const DIRS: [u8; 4] = [0, 0, 1, 1];
const WPTS: [Point; 3] = [Point::new(0, 0), Point::new(2, 0), Point::new(3, 2)];

fn params() -> Params {
    Params {
        algorithm: Algorithm::Haca,
        ants: 300,
        iterations: 70_00,
        alpha: 1.5,
        beta: -0.0,
        rho: f32::MIN_POSITIVE,
        q: 3.25,
        a: 0.5,
        xi: 2.0,
        tau0: 1.0,
        tau_min: 0.01,
        tau_max: 1e30,
        patience: 0,
        seed: u64::MAX,
        dead_end: DeadEnd::Die,
        smoothing: SmoothingKind::Greedy,
        tighten: false,
        prune: true,
    }
}

fn requests() -> Vec<Request<'static>> {
    vec![
        Request::Hello,
        Request::SetMap {
            width: 4,
            height: 3,
            offset: 0,
            total_len: 2,
            chunk: &MAP,
        },
        Request::SetMap {
            width: u16::MAX,
            height: 1,
            offset: u32::MAX,
            total_len: 1 << 20,
            chunk: &[0xFF; MAX_CHUNK],
        },
        Request::SetParams(Params::default()),
        Request::SetParams(params()),
        Request::Plan {
            start: Point::new(0, 0),
            goal: Point::new(25, 25),
            seed: None,
        },
        Request::Plan {
            start: Point::new(u16::MAX, 300),
            goal: Point::new(1, u16::MAX),
            seed: Some(u64::MAX),
        },
        Request::Cancel,
        Request::Stats,
        Request::SetMapRle {
            width: 256,
            height: 256,
            offset: 128,
            total_len: 1000,
            chunk: &[5, 1, 6],
        },
        Request::SetRect {
            x: 1,
            y: 2,
            width: 3,
            height: 4,
            blocked: true,
        },
        Request::SetCells {
            blocked: false,
            cells: Waypoints::Points(&WPTS),
        },
        Request::SetCells {
            blocked: true,
            cells: Waypoints::Points(&[]),
        },
        Request::PlanWarm {
            start: Point::new(3, 4),
            goal: Point::new(500, 511),
            seed: Some(9),
        },
    ]
}

fn hello() -> HelloReply<'static> {
    HelloReply {
        protocol_version: VERSION,
        firmware_version: "0.1.0",
        board: "qemu-mps2-an386",
        capacity: Capacity {
            cells: 65536,
            max_width: 256,
            max_height: 256,
            max_chunk: MAX_CHUNK as u16,
            max_request: MAX_REQUEST as u16,
            plan_queue: 4,
            tick_hz: 1_000_000,
        },
        defaults: Params::default(),
    }
}

fn path() -> PathReply<'static> {
    PathReply {
        raw_length: 4.828427,
        length: 3.828427,
        turns: 1,
        iterations: 21,
        best_iteration: 0,
        moves: 4200,
        ticks: 123_456,
        raw_cells: 5,
        waypoints: Waypoints::Points(&WPTS),
        directions: &DIRS,
    }
}

fn replies() -> Vec<Reply<'static>> {
    let mut v = vec![
        Reply::Hello(hello()),
        Reply::Ack,
        Reply::Path(path()),
        Reply::Path(PathReply {
            waypoints: Waypoints::Points(&[]),
            directions: &[],
            ..path()
        }),
        Reply::Stats(StatsReply::default()),
        Reply::Stats(StatsReply {
            uptime: u64::MAX,
            boots: 1,
            frames_ok: u32::MAX,
            planning: true,
            queued: 4,
            stack_peak: u32::MAX,
            ..StatsReply::default()
        }),
    ];
    for c in ErrorCode::ALL {
        v.push(Reply::Error(ErrorReply::with(c, 7, u32::MAX)));
    }
    v
}

#[test]
fn crc32_check_value() {
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    assert_eq!(crc32(b""), 0);
    assert_eq!(crc32(&[0]), 0xD202_EF8D);
}

#[test]
fn cobs_known_vectors() {
    // The examples of Cheshire & Baker / Wikipedia.
    assert_eq!(cobs(&[0x00]), [0x01, 0x01]);
    assert_eq!(cobs(&[0x00, 0x00]), [0x01, 0x01, 0x01]);
    assert_eq!(
        cobs(&[0x11, 0x22, 0x00, 0x33]),
        [0x03, 0x11, 0x22, 0x02, 0x33]
    );
    assert_eq!(
        cobs(&[0x11, 0x22, 0x33, 0x44]),
        [0x05, 0x11, 0x22, 0x33, 0x44]
    );
    assert_eq!(
        cobs(&[0x11, 0x00, 0x00, 0x00]),
        [0x02, 0x11, 0x01, 0x01, 0x01]
    );
    let run: Vec<u8> = (1..=254).collect();
    let mut want = vec![0xFF];
    want.extend(&run);
    want.push(0x01);
    assert_eq!(cobs(&run), want);
    let run: Vec<u8> = (1..=255).collect();
    let mut want = vec![0xFF];
    want.extend(1..=254u8);
    want.extend([0x02, 0xFF]);
    assert_eq!(cobs(&run), want);
}

#[test]
fn cobs_round_trips() {
    let mut rng = Lcg(1);
    for len in (0..600).chain([1020, 1021, 5000]) {
        for zero_rate in [0u32, 1, 16, 256] {
            let data: Vec<u8> = (0..len)
                .map(|_| {
                    if zero_rate > 0 && rng.next() % zero_rate == 0 {
                        0
                    } else {
                        rng.byte().max(1)
                    }
                })
                .collect();
            let e = cobs(&data);
            assert!(!e.contains(&0));
            assert!(e.len() <= data.len() + cobs_overhead(data.len()));
            assert_eq!(uncobs(&e).unwrap(), data, "len {len}");
        }
    }
}

#[test]
fn cobs_rejects_malformed() {
    assert_eq!(uncobs(&[0x00]), None);
    assert_eq!(uncobs(&[0x05, 0x11, 0x22]), None);
    assert_eq!(uncobs(&[0x03, 0x11, 0x00]), None);
    assert_eq!(uncobs(&[]), Some(vec![]));
}

#[test]
fn every_request_round_trips() {
    for (i, r) in requests().into_iter().enumerate() {
        let id = i as u32 * 0x0101_0101;
        let mut f = enc_req(id, &r);
        assert_eq!(f.pop(), Some(0));
        assert!(!f.contains(&0));
        assert_eq!(decode_request(&mut f).unwrap(), (id, r));
    }
}

#[test]
fn every_reply_round_trips() {
    for (i, r) in replies().into_iter().enumerate() {
        let id = u32::MAX - i as u32;
        let mut f = enc_rep(id, &r);
        assert_eq!(f.pop(), Some(0));
        let (got_id, got) = decode_reply(&mut f).unwrap();
        assert_eq!((got_id, got), (id, r));
        if let Reply::Path(p) = got {
            // Received waypoints come back packed and read the same.
            assert!(matches!(p.waypoints, Waypoints::Packed(_)));
            if !p.waypoints.is_empty() {
                assert_eq!(p.waypoints.iter().collect::<Vec<_>>(), WPTS);
                assert_eq!(p.waypoints.get(2), Some(Point::new(3, 2)));
                assert_eq!(p.waypoints.get(3), None);
            }
        }
    }
}

#[test]
fn largest_messages_fit_their_limits() {
    let chunk = [0xFFu8; MAX_CHUNK];
    let big = Request::SetMap {
        width: u16::MAX,
        height: u16::MAX,
        offset: u32::MAX,
        total_len: u32::MAX,
        chunk: &chunk,
    };
    let mut buf = [0u8; MAX_REQUEST_WIRE];
    encode_request(u32::MAX, &big, &mut buf).unwrap();
    let p = Params {
        seed: u64::MAX,
        ants: u16::MAX,
        iterations: u16::MAX,
        patience: u16::MAX,
        ..Params::default()
    };
    encode_request(u32::MAX, &Request::SetParams(p), &mut buf).unwrap();

    let wp = vec![Point::new(u16::MAX, u16::MAX); MAX_WAYPOINTS];
    let dirs = vec![7u8; MAX_DIRECTIONS];
    let r = Reply::Path(PathReply {
        raw_length: f32::MAX,
        length: f32::MAX,
        turns: u32::MAX,
        iterations: u16::MAX,
        best_iteration: u16::MAX,
        moves: u64::MAX,
        ticks: u64::MAX,
        raw_cells: u32::MAX,
        waypoints: Waypoints::Points(&wp),
        directions: &dirs,
    });
    let mut f = vec![0u8; MAX_REPLY_WIRE];
    let n = encode_reply(u32::MAX, &r, &mut f).unwrap();
    assert!(n <= MAX_REPLY_WIRE);
    let mut reader = ReplyReader::new();
    let mut got = None;
    for &b in &f[..n] {
        if let Feed::Frame(fr) = reader.push(b) {
            got = Some(decode_reply(fr).map(|(id, r)| (id, format!("{r:?}"))));
        }
    }
    assert_eq!(got.unwrap().unwrap(), (u32::MAX, format!("{r:?}")));
}

/// The frame [`PathStream`] produces, read `piece` bytes at a time.
fn streamed(id: u32, p: &PathReply<'_>, piece: usize) -> Vec<u8> {
    let mut s = PathStream::new(id, p).unwrap();
    let mut out = vec![];
    let mut buf = vec![0u8; piece];
    while !s.is_done() {
        let n = s.fill(&mut buf);
        assert!(n == piece || s.is_done(), "a short piece before the end");
        out.extend_from_slice(&buf[..n]);
    }
    assert_eq!(s.fill(&mut buf), 0);
    assert!(s.is_done());
    out
}

#[test]
fn path_stream_is_byte_exact() {
    let mut rng = Lcg(7);
    // Lengths around COBS's 254-byte blocks, bytes with and without zeros, every id size.
    let mut cases: Vec<(Vec<Point>, Vec<u8>)> = vec![
        (vec![], vec![]),
        (WPTS.to_vec(), DIRS.to_vec()),
        (
            vec![Point::new(u16::MAX, u16::MAX); MAX_WAYPOINTS],
            vec![7; MAX_DIRECTIONS],
        ),
        (
            vec![Point::new(0, 0); MAX_WAYPOINTS],
            vec![0; MAX_DIRECTIONS],
        ),
    ];
    for n in [
        1usize, 60, 61, 62, 63, 64, 200, 250, 251, 252, 253, 254, 255, 256, 508, 509, 1000,
    ] {
        let pts = (0..n / 4 + 1)
            .map(|_| Point::new(rng.next() as u16 % 300 + 1, rng.next() as u16 % 300 + 1))
            .collect();
        let dirs = (0..n).map(|_| rng.byte() % 8).collect();
        cases.push((pts, dirs));
        let dirs_nonzero = (0..n).map(|_| rng.byte() % 7 + 1).collect();
        cases.push((vec![Point::new(257, 513)], dirs_nonzero));
    }
    for (i, (pts, dirs)) in cases.iter().enumerate() {
        for id in [0, 1, 300, u32::MAX] {
            let p = PathReply {
                ticks: u64::from(rng.next()) << (i % 32),
                moves: if i % 2 == 0 { 0 } else { u64::MAX },
                raw_length: if i % 3 == 0 { 0.0 } else { 41.799 },
                waypoints: Waypoints::Points(pts),
                directions: dirs,
                ..path()
            };
            let want = enc_rep(id, &Reply::Path(p));
            for piece in [1, 2, 7, 64, 255, 256, 6000] {
                assert_eq!(
                    streamed(id, &p, piece),
                    want,
                    "case {i} id {id} piece {piece}"
                );
            }
        }
    }
}

#[test]
fn path_stream_refuses_what_encode_reply_refuses() {
    let wp = vec![Point::new(u16::MAX, u16::MAX); MAX_WAYPOINTS + 40];
    let dirs = vec![7u8; MAX_DIRECTIONS];
    let p = PathReply {
        waypoints: Waypoints::Points(&wp),
        directions: &dirs,
        ..path()
    };
    let mut buf = vec![0u8; MAX_REPLY_WIRE];
    let whole = encode_reply(1, &Reply::Path(p), &mut buf);
    assert!(matches!(whole, Err(EncodeError::BufferTooSmall { .. })));
    assert_eq!(PathStream::new(1, &p).err(), whole.err());
}

#[test]
fn small_buffers_are_refused_not_overrun() {
    for r in requests() {
        let full = enc_req(9, &r);
        let payload = uncobs(&full[..full.len() - 1]).unwrap().len();
        let need = wire_len(payload);
        assert!(need >= full.len());
        for len in 0..need {
            let mut buf = vec![0xAAu8; len];
            assert_eq!(
                encode_request(9, &r, &mut buf),
                Err(EncodeError::BufferTooSmall { need, have: len })
            );
        }
        // The worst-case size for the payload is enough.
        let mut buf = vec![0u8; need];
        assert_eq!(encode_request(9, &r, &mut buf).unwrap(), full.len());
        assert_eq!(&buf[..full.len()], &full[..]);
    }
}

#[test]
fn every_bit_flip_in_the_payload_is_a_bad_crc() {
    for r in requests().iter().take(6) {
        let f = enc_req(3, r);
        let payload = uncobs(&f[..f.len() - 1]).unwrap();
        for bit in 0..payload.len() * 8 {
            let mut p = payload.clone();
            p[bit / 8] ^= 1 << (bit % 8);
            let mut e = cobs(&p);
            assert_eq!(
                decode_request(&mut e),
                Err(DecodeError::BadCrc),
                "bit {bit}"
            );
        }
    }
}

#[test]
fn every_bit_flip_on_the_wire_is_detected() {
    for r in requests() {
        let f = enc_req(0x1234_5678, &r);
        let body = &f[..f.len() - 1];
        for bit in 0..body.len() * 8 {
            let mut wire = body.to_vec();
            wire[bit / 8] ^= 1 << (bit % 8);
            // A flip may create a delimiter: then each piece must fail on its own.
            for piece in wire.split_mut(|&b| b == 0).filter(|p| !p.is_empty()) {
                assert!(decode_request(piece).is_err(), "{r:?} bit {bit}");
            }
        }
    }
}

#[test]
fn every_truncation_is_detected() {
    for r in requests() {
        let f = enc_req(77, &r);
        for len in 0..f.len() - 1 {
            let mut t = f[..len].to_vec();
            assert!(decode_request(&mut t).is_err(), "{r:?} cut at {len}");
        }
    }
    for r in replies() {
        let f = enc_rep(77, &r);
        for len in 0..f.len() - 1 {
            let mut t = f[..len].to_vec();
            assert!(decode_reply(&mut t).is_err(), "{r:?} cut at {len}");
        }
    }
}

#[test]
fn short_frames_are_too_short() {
    for n in 1..=4 {
        let mut e = cobs(&vec![1u8; n]);
        assert_eq!(decode_request(&mut e), Err(DecodeError::TooShort));
    }
    // Only a CRC: no message.
    let mut e = cobs(&crc32(&[]).to_le_bytes());
    assert_eq!(decode_request(&mut e), Err(DecodeError::TooShort));
}

#[test]
fn garbage_never_decodes_and_never_panics() {
    let mut rng = Lcg(42);
    for _ in 0..20_000 {
        let len = (rng.next() % 300) as usize;
        let mut g: Vec<u8> = (0..len).map(|_| rng.byte()).collect();
        let mut h = g.clone();
        assert!(decode_request(&mut h).is_err());
        let _ = decode_reply(&mut g);
    }
}

#[test]
fn random_bodies_with_a_good_crc_never_panic() {
    // Past the CRC: postcard must reject or accept, never panic, and accepted ones re-encode.
    let mut rng = Lcg(7);
    let mut accepted = 0;
    for i in 0..50_000 {
        let len = 1 + (rng.next() % 80) as usize;
        let mut body: Vec<u8> = (0..len).map(|_| rng.byte()).collect();
        // Steer the message tag into range half the time.
        if len > 1 && i % 2 == 0 {
            body[0] &= 0x7F;
            body[1] %= 8;
        }
        let mut f = frame_body(&body);
        match decode_request(&mut f) {
            Ok((id, r)) => {
                accepted += 1;
                let mut again = enc_req(id, &r);
                again.pop();
                assert_eq!(decode_request(&mut again).unwrap(), (id, r));
            }
            Err(e) => assert!(matches!(e, DecodeError::Undecodable { .. })),
        }
        let mut f = frame_body(&body);
        let _ = decode_reply(&mut f);
    }
    assert!(accepted > 100, "only {accepted} accepted");
}

#[test]
fn undecodable_keeps_the_id_when_it_can() {
    // id 300, then variant 99.
    let mut f = frame_body(&[0xAC, 0x02, 99]);
    assert_eq!(
        decode_request(&mut f),
        Err(DecodeError::Undecodable { id: Some(300) })
    );
    assert_eq!(DecodeError::Undecodable { id: Some(300) }.id(), 300);
    // Trailing bytes after a valid message.
    let mut f = frame_body(&[5, 0, 0]);
    assert_eq!(
        decode_request(&mut f),
        Err(DecodeError::Undecodable { id: Some(5) })
    );
    // A bad id varint.
    let mut f = frame_body(&[0xFF; 6]);
    assert_eq!(
        decode_request(&mut f),
        Err(DecodeError::Undecodable { id: None })
    );
    assert_eq!(DecodeError::BadCrc.id(), UNKNOWN_ID);
    // Bad UTF-8 in a Hello reply's strings.
    let mut f = frame_body(&[1, 0, 1, 1, 0xFF]);
    assert!(matches!(
        decode_reply(&mut f),
        Err(DecodeError::Undecodable { id: Some(1) })
    ));
    // Waypoints not a multiple of 4 bytes.
    let mut body = vec![1, 2];
    body.extend([0; 4 + 4 + 1 + 1 + 1 + 1 + 1 + 1]);
    body.extend([3, 1, 2, 3, 0]);
    let mut f = frame_body(&body);
    assert!(decode_reply(&mut f).is_err());
    // Unknown error code.
    let mut f = frame_body(&[1, 3, 15, 0, 0]);
    assert!(decode_reply(&mut f).is_err());
    let mut f = frame_body(&[1, 3, 16, 0, 0]);
    assert_eq!(
        decode_reply(&mut f).unwrap(),
        (1, Reply::Error(ErrorReply::new(ErrorCode::BadCrc)))
    );
}

#[test]
fn reader_splits_a_stream() {
    let frames: Vec<Vec<u8>> = requests().iter().map(|r| enc_req(5, r)).collect();
    let mut stream = vec![0u8, 0];
    for f in &frames {
        stream.extend(f);
        stream.push(0); // an empty frame between: ignored
    }
    let mut reader = RequestReader::new();
    let want = requests();
    let mut got = 0;
    for &b in &stream {
        if let Feed::Frame(f) = reader.push(b) {
            assert_eq!(decode_request(f).unwrap().1, want[got]);
            got += 1;
        }
    }
    assert_eq!(got, want.len());
}

#[test]
fn reader_drops_oversize_frames_and_recovers() {
    let mut reader: FrameReader<8> = FrameReader::new();
    for b in 1..=20u8 {
        assert_eq!(reader.push(b), Feed::Pending);
    }
    assert_eq!(reader.push(0), Feed::TooLarge { len: 20 });
    assert_eq!(
        reader.push(0).into_frame(8).map(|r| r.map(|f| f.len())),
        None
    );
    for b in 1..=8u8 {
        reader.push(b);
    }
    assert_eq!(reader.pending(), 8);
    assert_eq!(reader.push(0), Feed::Frame(&mut [1, 2, 3, 4, 5, 6, 7, 8]));
    for b in 1..=9u8 {
        reader.push(b);
    }
    let e = reader.push(0).into_frame(8).unwrap().unwrap_err();
    assert_eq!(e, DecodeError::TooLarge { len: 9, max: 8 });
    assert_eq!(e.reply(), ErrorReply::with(ErrorCode::TooLarge, 9, 8));
    reader.push(3);
    reader.clear();
    assert_eq!(reader.push(0), Feed::Pending);

    // An oversize request on the wire: a chunk too big for the request reader.
    let chunk = [1u8; 400];
    let r = Request::SetMap {
        width: 64,
        height: 64,
        offset: 0,
        total_len: 512,
        chunk: &chunk,
    };
    let mut big = vec![0u8; 1024];
    let n = encode_request(1, &r, &mut big).unwrap();
    let mut reader = RequestReader::new();
    let last = big[..n]
        .iter()
        .map(|&b| {
            reader
                .push(b)
                .into_frame(MAX_REQUEST_WIRE)
                .map(|r| r.map(|f| f.len()))
        })
        .last();
    assert_eq!(
        last.unwrap().unwrap(),
        Err(DecodeError::TooLarge {
            len: (n - 1) as u32,
            max: MAX_REQUEST_WIRE as u32
        })
    );
}

#[test]
fn error_codes_map_the_planner_errors_both_ways() {
    use crate::error::Endpoint::{Goal, Start};
    // Every planner error with the wire code docs/PROTOCOL.md gives it.
    let all = [
        (Error::BadMap, 1),
        (
            Error::MapTooLarge {
                cells: 2000,
                capacity: 1024,
            },
            2,
        ),
        (Error::OutOfBounds(Start), 3),
        (Error::OutOfBounds(Goal), 4),
        (Error::Blocked(Start), 5),
        (Error::Blocked(Goal), 6),
        (Error::BadParam(Param::Tau), 7),
        (Error::NoPath, 8),
        (Error::Cancelled, 9),
        (Error::NoAntArrived, 10),
    ];
    for (e, code) in all {
        let reply = ErrorReply::from(e);
        assert_eq!(reply.code.code(), code, "{e:?}");
        assert_eq!(Error::try_from(reply), Ok(e), "{e:?}");
    }
    for p in Param::ALL {
        let e = Error::BadParam(p);
        assert_eq!(Error::try_from(ErrorReply::from(e)), Ok(e));
    }
    // The protocol's own codes, and a parameter number out of range, are no planner error.
    for c in ErrorCode::ALL.into_iter().filter(|c| c.code() >= 16) {
        assert_eq!(Error::try_from(ErrorReply::new(c)), Err(ErrorReply::new(c)));
    }
    let bad = ErrorReply::with(ErrorCode::BadParam, 9, 0);
    assert_eq!(Error::try_from(bad), Err(bad));
    assert_eq!(
        ErrorReply::from(Error::MapTooLarge {
            cells: 2000,
            capacity: 1024
        }),
        ErrorReply::with(ErrorCode::MapTooLarge, 2000, 1024)
    );
    assert_eq!(
        ErrorReply::from(Error::BadParam(Param::Rho)),
        ErrorReply::with(ErrorCode::BadParam, 4, 0)
    );
    for (i, c) in ErrorCode::ALL.iter().enumerate() {
        assert_eq!(ErrorCode::from_code(c.code()), Some(*c));
        assert!(!c.to_string().is_empty());
        if i > 0 {
            assert!(ErrorCode::ALL[i - 1].code() < c.code());
        }
    }
    assert_eq!(ErrorCode::try_from(0u8), Err(UnknownCode(0)));
    assert_eq!(
        ErrorReply::with(ErrorCode::MapTooLarge, 2000, 1024).to_string(),
        "map too large (2000 cells, capacity 1024)"
    );
    assert_eq!(
        DecodeError::TooLarge { len: 9, max: 8 }.to_string(),
        "frame of 9 bytes exceeds the limit of 8"
    );
}

// ---- docs/PROTOCOL.md: the worked exchange -------------------------------------------------

const EXAMPLE_WAYPOINTS: [Point; 4] = [
    Point::new(0, 0),
    Point::new(1, 0),
    Point::new(3, 1),
    Point::new(3, 2),
];
const EXAMPLE_DIRECTIONS: [u8; 4] = [0, 0, 1, 2];
/// Ticks (µs of virtual time) the QEMU firmware reported for the example plan.
const EXAMPLE_TICKS: u64 = 885;

fn example_path() -> PathReply<'static> {
    PathReply {
        raw_length: 4.414_213_7,
        length: 4.236_068,
        turns: 2,
        iterations: 11,
        best_iteration: 0,
        moves: 2200,
        ticks: EXAMPLE_TICKS,
        raw_cells: 5,
        waypoints: Waypoints::Points(&EXAMPLE_WAYPOINTS),
        directions: &EXAMPLE_DIRECTIONS,
    }
}

/// What the QEMU firmware answered to `Stats` after the example's first three requests.
fn example_stats() -> StatsReply {
    StatsReply {
        uptime: 22_327,
        boots: 1,
        frames_ok: 4,
        frames_bad: 0,
        rx_overruns: 0,
        rx_bytes: 45,
        tx_frames: 3,
        plans: 1,
        plan_errors: 0,
        cancelled: 0,
        busy: 0,
        last_plan_ticks: EXAMPLE_TICKS,
        map_width: 4,
        map_height: 3,
        queued: 0,
        planning: false,
        stack_peak: 1556,
    }
}

/// The exchange of the document: Hello, SetMap (the 4x3 map of the crate docs), Plan, Stats.
fn example() -> Vec<(u32, Request<'static>, Reply<'static>)> {
    vec![
        (1, Request::Hello, Reply::Hello(hello())),
        (
            2,
            Request::SetMap {
                width: 4,
                height: 3,
                offset: 0,
                total_len: 2,
                chunk: &MAP,
            },
            Reply::Ack,
        ),
        (
            3,
            Request::Plan {
                start: Point::new(0, 0),
                goal: Point::new(3, 2),
                seed: None,
            },
            Reply::Path(example_path()),
        ),
        (4, Request::Stats, Reply::Stats(example_stats())),
    ]
}

fn payload_of(frame: &[u8]) -> Vec<u8> {
    uncobs(&frame[..frame.len() - 1]).unwrap()
}

/// The hex after each `marker` line of the document, concatenated (`;` starts a comment, `|`
/// separates fields).
fn doc_bytes(doc: &str, marker: &str) -> Vec<u8> {
    doc.lines()
        .filter_map(|l| l.strip_prefix(marker))
        .flat_map(|l| {
            l.split(';')
                .next()
                .unwrap_or("")
                .split_whitespace()
                .filter(|t| *t != "|")
                .map(|t| u8::from_str_radix(t, 16).unwrap_or_else(|_| panic!("bad hex {t:?}")))
                .collect::<Vec<_>>()
        })
        .collect()
}

#[test]
fn protocol_doc_example_is_exact() {
    let doc = include_str!("../../docs/PROTOCOL.md");
    let (mut req_wire, mut rep_wire, mut req_pay, mut rep_pay) = (vec![], vec![], vec![], vec![]);
    for (id, req, rep) in example() {
        let f = enc_req(id, &req);
        req_pay.extend(payload_of(&f));
        req_wire.extend(f);
        let f = enc_rep(id, &rep);
        rep_pay.extend(payload_of(&f));
        rep_wire.extend(f);
    }
    let hint = "docs/PROTOCOL.md drifted: regenerate the example with \
        `cargo test -p ohaca --lib --target host-tuple print_protocol_doc_example -- --ignored --nocapture`";
    assert_eq!(doc_bytes(doc, "=> "), req_pay, "{hint}");
    assert_eq!(doc_bytes(doc, "<= "), rep_pay, "{hint}");
    assert_eq!(doc_bytes(doc, ">> "), req_wire, "{hint}");
    assert_eq!(doc_bytes(doc, "<< "), rep_wire, "{hint}");
    // And the wire bytes decode to the example's messages.
    let mut reader = ReplyReader::new();
    let mut n = 0;
    for b in rep_wire {
        if let Feed::Frame(f) = reader.push(b) {
            let (id, r) = decode_reply(f).unwrap();
            assert_eq!((id, r), (example()[n].0, example()[n].2));
            n += 1;
        }
    }
    assert_eq!(n, example().len());
}

#[test]
fn protocol_doc_example_is_what_the_planner_returns() {
    use crate::grid::Grid;
    use crate::planner::{plan, Storage};
    let g = Grid::new(4, 3, &MAP).unwrap();
    let mut s: Storage<1, 16, 32, 16> = Storage::new();
    let p = plan(
        &g,
        Point::new(0, 0),
        Point::new(3, 2),
        &hello().defaults,
        s.workspace(),
    )
    .unwrap();
    let want = example_path();
    assert_eq!(p.waypoints(), EXAMPLE_WAYPOINTS);
    assert_eq!(p.directions(), EXAMPLE_DIRECTIONS);
    assert_eq!(
        (p.raw_length, p.length, p.turns, p.iterations),
        (want.raw_length, want.length, want.turns, want.iterations)
    );
    assert_eq!(
        (p.best_iteration, p.moves, p.raw_len() as u32),
        (want.best_iteration, want.moves, want.raw_cells)
    );
}

fn ser<T: Serialize + ?Sized>(v: &T) -> Vec<u8> {
    let mut buf = vec![0u8; 8192];
    let n = postcard::to_slice(v, &mut buf).unwrap().len();
    buf.truncate(n);
    buf
}

fn hex(b: &[u8]) -> String {
    b.iter()
        .map(|x| format!("{x:02x}"))
        .collect::<Vec<_>>()
        .join(" ")
}

fn params_fields(p: &Params) -> Vec<(String, Vec<u8>)> {
    vec![
        (
            format!("  algorithm = {}", p.algorithm.name()),
            vec![p.algorithm as u8],
        ),
        (format!("  ants = {}", p.ants), ser(&p.ants)),
        (
            format!("  iterations = {}", p.iterations),
            ser(&p.iterations),
        ),
        (format!("  alpha = {} (f32 LE)", p.alpha), ser(&p.alpha)),
        (format!("  beta = {}", p.beta), ser(&p.beta)),
        (format!("  rho = {}", p.rho), ser(&p.rho)),
        (format!("  q = {}", p.q), ser(&p.q)),
        (format!("  a = {}", p.a), ser(&p.a)),
        (format!("  xi = {}", p.xi), ser(&p.xi)),
        (format!("  tau0 = {}", p.tau0), ser(&p.tau0)),
        (format!("  tau_min = {}", p.tau_min), ser(&p.tau_min)),
        (format!("  tau_max = {}", p.tau_max), ser(&p.tau_max)),
        (format!("  patience = {}", p.patience), ser(&p.patience)),
        (format!("  seed = {}", p.seed), ser(&p.seed)),
        (
            format!("  dead_end = {:?}", p.dead_end),
            vec![p.dead_end as u8],
        ),
        (
            format!("  smoothing = {:?}", p.smoothing),
            vec![p.smoothing as u8],
        ),
        (format!("  tighten = {}", p.tighten), ser(&p.tighten)),
        (format!("  prune = {}", p.prune), ser(&p.prune)),
    ]
}

fn request_fields(id: u32, r: &Request<'_>) -> Vec<(String, Vec<u8>)> {
    let mut v = vec![(format!("id = {id}"), ser(&id))];
    match *r {
        Request::Hello => v.push(("Request::Hello (variant 0)".into(), vec![0])),
        Request::SetMap {
            width,
            height,
            offset,
            total_len,
            chunk,
        } => {
            v.push(("Request::SetMap (variant 1)".into(), vec![1]));
            v.push((format!("  width = {width}"), ser(&width)));
            v.push((format!("  height = {height}"), ser(&height)));
            v.push((format!("  offset = {offset}"), ser(&offset)));
            v.push((format!("  total_len = {total_len}"), ser(&total_len)));
            v.push((
                format!(
                    "  chunk: length {}, bits LSB first (0x20: cell 5 = (1,1) blocked)",
                    chunk.len()
                ),
                ser(chunk),
            ));
        }
        Request::Plan { start, goal, seed } => {
            v.push(("Request::Plan (variant 3)".into(), vec![3]));
            v.push((
                format!("  start = ({}, {})", start.x, start.y),
                ser(&(start.x, start.y)),
            ));
            v.push((
                format!("  goal = ({}, {})", goal.x, goal.y),
                ser(&(goal.x, goal.y)),
            ));
            v.push((format!("  seed = {seed:?}"), ser(&seed)));
        }
        Request::Stats => v.push(("Request::Stats (variant 5)".into(), vec![5])),
        _ => panic!("not used by the example"),
    }
    v
}

fn reply_fields(id: u32, r: &Reply<'_>) -> Vec<(String, Vec<u8>)> {
    let mut v = vec![(format!("id = {id}"), ser(&id))];
    match r {
        Reply::Hello(h) => {
            v.push(("Reply::Hello (variant 0)".into(), vec![0]));
            v.push((
                format!("  protocol_version = {}", h.protocol_version),
                ser(&h.protocol_version),
            ));
            v.push((
                format!("  firmware_version = {:?}", h.firmware_version),
                ser(h.firmware_version),
            ));
            v.push((format!("  board = {:?}", h.board), ser(h.board)));
            let c = h.capacity;
            v.push((format!("  capacity.cells = {}", c.cells), ser(&c.cells)));
            v.push((
                format!("  capacity.max_width = {}", c.max_width),
                ser(&c.max_width),
            ));
            v.push((
                format!("  capacity.max_height = {}", c.max_height),
                ser(&c.max_height),
            ));
            v.push((
                format!("  capacity.max_chunk = {}", c.max_chunk),
                ser(&c.max_chunk),
            ));
            v.push((
                format!("  capacity.max_request = {}", c.max_request),
                ser(&c.max_request),
            ));
            v.push((
                format!("  capacity.plan_queue = {}", c.plan_queue),
                ser(&c.plan_queue),
            ));
            v.push((
                format!("  capacity.tick_hz = {}", c.tick_hz),
                ser(&c.tick_hz),
            ));
            for (name, b) in params_fields(&h.defaults) {
                v.push((name.replacen("  ", "  defaults.", 1), b));
            }
        }
        Reply::Ack => v.push(("Reply::Ack (variant 1)".into(), vec![1])),
        Reply::Path(p) => {
            v.push(("Reply::Path (variant 2)".into(), vec![2]));
            v.push((
                format!("  raw_length = {} (f32 LE)", p.raw_length),
                ser(&p.raw_length),
            ));
            v.push((format!("  length = {}", p.length), ser(&p.length)));
            v.push((format!("  turns = {}", p.turns), ser(&p.turns)));
            v.push((
                format!("  iterations = {}", p.iterations),
                ser(&p.iterations),
            ));
            v.push((
                format!("  best_iteration = {}", p.best_iteration),
                ser(&p.best_iteration),
            ));
            v.push((format!("  moves = {}", p.moves), ser(&p.moves)));
            v.push((format!("  ticks = {}", p.ticks), ser(&p.ticks)));
            v.push((format!("  raw_cells = {}", p.raw_cells), ser(&p.raw_cells)));
            let pts: Vec<String> = p
                .waypoints
                .iter()
                .map(|q| format!("({},{})", q.x, q.y))
                .collect();
            v.push((
                format!(
                    "  waypoints: {} bytes = {}",
                    p.waypoints.len() * 4,
                    pts.join(" ")
                ),
                ser(&p.waypoints),
            ));
            v.push((
                format!("  directions: {:?} (E E SE S)", p.directions),
                ser(p.directions),
            ));
        }
        Reply::Stats(s) => {
            v.push(("Reply::Stats (variant 4)".into(), vec![4]));
            let fields: [(&str, Vec<u8>, String); 17] = [
                ("uptime", ser(&s.uptime), s.uptime.to_string()),
                ("boots", ser(&s.boots), s.boots.to_string()),
                ("frames_ok", ser(&s.frames_ok), s.frames_ok.to_string()),
                ("frames_bad", ser(&s.frames_bad), s.frames_bad.to_string()),
                (
                    "rx_overruns",
                    ser(&s.rx_overruns),
                    s.rx_overruns.to_string(),
                ),
                ("rx_bytes", ser(&s.rx_bytes), s.rx_bytes.to_string()),
                ("tx_frames", ser(&s.tx_frames), s.tx_frames.to_string()),
                ("plans", ser(&s.plans), s.plans.to_string()),
                (
                    "plan_errors",
                    ser(&s.plan_errors),
                    s.plan_errors.to_string(),
                ),
                ("cancelled", ser(&s.cancelled), s.cancelled.to_string()),
                ("busy", ser(&s.busy), s.busy.to_string()),
                (
                    "last_plan_ticks",
                    ser(&s.last_plan_ticks),
                    s.last_plan_ticks.to_string(),
                ),
                ("map_width", ser(&s.map_width), s.map_width.to_string()),
                ("map_height", ser(&s.map_height), s.map_height.to_string()),
                ("queued", ser(&s.queued), s.queued.to_string()),
                ("planning", ser(&s.planning), s.planning.to_string()),
                ("stack_peak", ser(&s.stack_peak), s.stack_peak.to_string()),
            ];
            for (name, b, val) in fields {
                v.push((format!("  {name} = {val}"), b));
            }
        }
        _ => panic!("not used by the example"),
    }
    v
}

fn print_frame(marker: &str, wire_marker: &str, fields: Vec<(String, Vec<u8>)>, frame: &[u8]) {
    let payload = payload_of(frame);
    let mut all = vec![];
    for (name, b) in &fields {
        all.extend(b);
        // Long fields wrap at 16 bytes a line.
        let mut chunks: Vec<&[u8]> = b.chunks(16).collect();
        if chunks.is_empty() {
            chunks.push(&[]);
        }
        for (i, c) in chunks.iter().enumerate() {
            let h2 = hex(c);
            if i == 0 {
                println!("{marker}{h2:<48}; {name}");
            } else {
                println!("{marker}{h2}");
            }
        }
    }
    let crc = &payload[all.len()..];
    assert_eq!(&payload[..all.len()], &all[..]);
    println!(
        "{marker}{:<48}; CRC-32 = 0x{:08x}, little endian",
        hex(crc),
        u32::from_le_bytes(crc.try_into().unwrap())
    );
    for c in frame.chunks(16) {
        println!("{wire_marker}{}", hex(c));
    }
}

#[test]
#[ignore = "prints the example block of docs/PROTOCOL.md"]
fn print_protocol_doc_example() {
    for (id, req, rep) in example() {
        println!("\n# request {id}");
        print_frame("=> ", ">> ", request_fields(id, &req), &enc_req(id, &req));
        println!("\n# reply {id}");
        print_frame("<= ", "<< ", reply_fields(id, &rep), &enc_rep(id, &rep));
    }
}
