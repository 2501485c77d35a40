//! Messages: every request and reply round trips, the largest fit their limits, a path sent in
//! parts is the whole reply's body byte for byte, and the planner's errors map to wire codes and back.

use super::*;

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
        warm_patience: u16::MAX,
        refine_patience: u16::MAX,
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
        origin: crate::planner::Origin::Warm,
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

/// `p` sent as the firmware sends a long path: its [`PathBody`] read `piece` bytes at a time,
/// each piece a [`PathPart`] frame of the one encoder ([`encode_reply`]); returns the bytes the
/// host reassembles from the frames it decodes.
fn in_parts(id: u32, p: &PathReply<'_>, piece: usize) -> Vec<u8> {
    let body = PathBody::new(p).unwrap();
    let mut out = vec![];
    let mut buf = vec![0u8; piece];
    loop {
        let n = body.read(out.len(), &mut buf);
        if n == 0 {
            break;
        }
        assert!(
            n == piece || out.len() + n == body.len(),
            "a short piece before the end"
        );
        let part = PathPart {
            offset: out.len() as u32,
            total_len: body.len() as u32,
            bytes: &buf[..n],
        };
        let mut f = enc_rep(id, &Reply::PathPart(part));
        assert_eq!(f.pop(), Some(0));
        let (got_id, got) = decode_reply(&mut f).unwrap();
        assert_eq!(got_id, id);
        let Reply::PathPart(got) = got else {
            panic!("not a part: {got:?}")
        };
        assert_eq!(
            (got.offset as usize, got.total_len as usize),
            (out.len(), body.len())
        );
        out.extend_from_slice(got.bytes);
    }
    out
}

#[test]
fn a_path_in_parts_is_the_whole_replys_body() {
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
            // The whole reply's frame, COBS and CRC undone: the id, the variant, the body.
            let mut whole = enc_rep(id, &Reply::Path(p));
            assert_eq!(whole.pop(), Some(0));
            let n = cobs_decode_in_place(&mut whole).unwrap();
            let payload = &whole[..n - 4];
            for piece in [1, 2, 7, 64, 255, 256, PART_BYTES] {
                let body = in_parts(id, &p, piece);
                let head = payload.len() - body.len();
                assert_eq!(
                    &payload[head..],
                    &body[..],
                    "case {i} id {id} piece {piece}"
                );
                // What is before the body is the id's varint and the variant.
                assert_eq!(head, varint_len(id as usize) + 1, "case {i} id {id}");
                let back = decode_path_body(&body).unwrap();
                assert_eq!(back.directions, &dirs[..]);
            }
        }
    }
}

#[test]
fn a_path_body_is_refused_exactly_when_no_path_frame_could_carry_it() {
    // Refused exactly when the reply with the widest id would not fit MAX_REPLY_WIRE.
    for extra in [0usize, 1, 2, 3, 4, 5, 40] {
        let wp = vec![Point::new(u16::MAX, u16::MAX); MAX_WAYPOINTS + extra];
        let dirs = vec![7u8; MAX_DIRECTIONS];
        let p = PathReply {
            waypoints: Waypoints::Points(&wp),
            directions: &dirs,
            ..path()
        };
        let mut buf = vec![0u8; MAX_REPLY_WIRE];
        let whole = encode_reply(u32::MAX, &Reply::Path(p), &mut buf);
        assert_eq!(
            PathBody::new(&p).err(),
            whole.err(),
            "{extra} more waypoints"
        );
    }
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
        (
            Error::PathTooLong {
                ants: 5000,
                limit: 1023,
            },
            11,
        ),
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
        "map too large (2000 over the limit 1024)"
    );
    assert_eq!(
        DecodeError::TooLarge { len: 9, max: 8 }.to_string(),
        "frame of 9 bytes exceeds the limit of 8"
    );
}
