//! Framing: the CRC, COBS, what corruption, truncation and garbage do, buffers too small, and
//! the frame reader.

use super::*;

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
