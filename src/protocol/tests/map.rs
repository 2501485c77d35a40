//! Map uploads (raw and run-length), cell updates and warm plans: every error path and the round
//! trips.

use super::*;

pub(super) const LIMITS: MapLimits = MapLimits {
    max_cells: 512 * 512,
    max_side: 1024,
};

fn cell(bits: &[u8], i: usize) -> bool {
    bits[i / 8] >> (i % 8) & 1 == 1
}

/// A map of `cells` cells made of runs of random lengths up to `max_run`.
fn runs_map(rng: &mut Lcg, cells: usize, max_run: u32) -> Vec<u8> {
    let mut bits = vec![0u8; cells.div_ceil(8)];
    let (mut i, mut v) = (0, rng.next() % 2 == 1);
    while i < cells {
        let run = 1 + (rng.next() % max_run) as usize;
        for j in i..(i + run).min(cells) {
            if v {
                bits[j / 8] |= 1 << (j % 8);
            }
        }
        i += run;
        v = !v;
    }
    bits
}

pub(super) fn rle(bits: &[u8], cells: usize) -> Vec<u8> {
    RleEncoder::new(bits, cells as u32).collect()
}

fn same_cells(a: &[u8], b: &[u8], cells: usize) -> bool {
    (0..cells).all(|i| cell(a, i) == cell(b, i))
}

/// Upload `code` in chunks of `chunk` bytes through [`Upload`] into `buf`.
fn upload(
    up: &mut Upload,
    enc: Encoding,
    (w, h): (u16, u16),
    code: &[u8],
    chunk: usize,
    buf: &mut [u8],
) -> Result<Option<(u16, u16)>, ErrorReply> {
    let mut done = None;
    for (k, c) in code.chunks(chunk).enumerate() {
        let m = MapChunk {
            encoding: enc,
            width: w,
            height: h,
            offset: (k * chunk) as u32,
            total_len: code.len() as u32,
            chunk: c,
        };
        up.accept(&m, LIMITS)?;
        done = up.write(&m, buf)?;
    }
    Ok(done)
}

#[test]
fn rle_known_codes() {
    // 4x3, cell 5 blocked: 5 free, 1 blocked, 6 free.
    assert_eq!(rle(&[0x20, 0x00], 12), [5, 1, 6]);
    // Starts blocked: a run of 0 free cells first.
    assert_eq!(rle(&[0x07], 3), [0, 3]);
    assert_eq!(rle(&[0x00], 3), [3]);
    // A run of 300 is the varint ac 02.
    assert_eq!(rle(&[0u8; 38], 300), [0xac, 0x02]);
    // The unused bits of the last byte do not count.
    assert_eq!(rle(&[0xF0], 4), [4]);
    assert_eq!(rle(&[], 0), [0]);
}

#[test]
fn rle_round_trips_in_any_pieces() {
    let mut rng = Lcg(7);
    for (w, h, max_run) in [
        (1, 1, 1),
        (4, 3, 3),
        (33, 7, 1),
        (64, 64, 40),
        (512, 9, 3000),
    ] {
        let cells = w * h;
        let bits = runs_map(&mut rng, cells, max_run);
        let code = rle(&bits, cells);
        assert_eq!(RleEncoder::encoded_len(&bits, cells as u32), code.len());
        for piece in [1, 2, 3, 7, MAX_CHUNK] {
            let mut out = vec![0xA5u8; cells.div_ceil(8)];
            let mut d = RleDecoder::new(cells as u32);
            for c in code.chunks(piece) {
                assert!(!d.is_complete() || c.iter().all(|&b| b == 0));
                d.feed(c, &mut out).unwrap();
            }
            assert!(d.is_complete(), "{w}x{h} piece {piece}");
            assert!(same_cells(&bits, &out, cells), "{w}x{h} piece {piece}");
            // And through the upload state machine.
            let mut out = vec![0x5Au8; cells.div_ceil(8)];
            let got = upload(
                &mut Upload::new(),
                Encoding::Rle,
                (w as u16, h as u16),
                &code,
                piece,
                &mut out,
            );
            assert_eq!(got, Ok(Some((w as u16, h as u16))));
            assert!(same_cells(&bits, &out, cells));
        }
    }
}

#[test]
fn rle_refuses_overruns_and_bad_varints() {
    let mut out = [0u8; 2];
    // 12 cells: 5 + 1 + 7 runs past the end.
    let mut d = RleDecoder::new(12);
    assert_eq!(
        d.feed(&[5, 1, 7], &mut out),
        Err(RleError::Overrun { at: 6 })
    );
    // A failed decoder stays failed.
    assert!(d.feed(&[0], &mut out).is_err());
    assert!(!d.is_complete());
    // A varint of more than 32 bits.
    let mut d = RleDecoder::new(12);
    assert!(d.feed(&[0xFF, 0xFF, 0xFF, 0xFF, 0x10], &mut out).is_err());
    let mut d = RleDecoder::new(12);
    assert!(d
        .feed(&[0x80, 0x80, 0x80, 0x80, 0x80, 0x01], &mut out)
        .is_err());
    // u32::MAX itself is a valid varint (and then too long a run).
    let mut d = RleDecoder::new(12);
    assert_eq!(
        d.feed(&[0xFF, 0xFF, 0xFF, 0xFF, 0x0F], &mut out),
        Err(RleError::Overrun { at: 0 })
    );
    // Short: 11 cells of 12, or a varint cut in half, is not complete.
    let mut d = RleDecoder::new(12);
    d.feed(&[5, 1, 5], &mut out).unwrap();
    assert!(!d.is_complete());
    let mut d = RleDecoder::new(300);
    let mut big = [0u8; 38];
    d.feed(&[0xac], &mut big).unwrap();
    assert!(!d.is_complete());
    d.feed(&[0x02], &mut big).unwrap();
    assert!(d.is_complete());
}

#[test]
fn raw_uploads_write_the_map() {
    let mut rng = Lcg(3);
    let (w, h) = (100u16, 37u16);
    let cells = 3700;
    let bits = runs_map(&mut rng, cells, 5);
    let mut out = vec![0u8; LIMITS.bytes()];
    let got = upload(
        &mut Upload::new(),
        Encoding::Raw,
        (w, h),
        &bits,
        128,
        &mut out,
    );
    assert_eq!(got, Ok(Some((w, h))));
    assert!(same_cells(&bits, &out, cells));
}

pub(super) fn chunk(
    enc: Encoding,
    w: u16,
    h: u16,
    offset: u32,
    total: u32,
    c: &[u8],
) -> MapChunk<'_> {
    MapChunk {
        encoding: enc,
        width: w,
        height: h,
        offset,
        total_len: total,
        chunk: c,
    }
}

#[test]
fn upload_headers_are_checked() {
    use Encoding::{Raw, Rle};
    let e = ErrorReply::with;
    let mut up = Upload::new();
    let big = [0u8; MAX_CHUNK + 1];
    let cases: Vec<(MapChunk<'_>, ErrorReply)> = vec![
        (
            chunk(Rle, 4, 3, 0, 2, &big),
            e(ErrorCode::TooLarge, 129, 128),
        ),
        // An empty chunk is refused first, whatever else is wrong.
        (chunk(Raw, 0, 3, 0, 0, &[]), e(ErrorCode::TooLarge, 0, 128)),
        (chunk(Raw, 4, 3, 0, 2, &[]), e(ErrorCode::TooLarge, 0, 128)),
        // A zero side: BadMap with what was sent and the 0 bytes such a map would have.
        (chunk(Raw, 0, 3, 0, 0, &[0]), e(ErrorCode::BadMap, 0, 0)),
        (chunk(Raw, 0, 3, 0, 7, &[0]), e(ErrorCode::BadMap, 7, 0)),
        (chunk(Rle, 4, 0, 0, 1, &[0]), e(ErrorCode::BadMap, 1, 0)),
        (chunk(Raw, 4, 3, 0, 3, &[0]), e(ErrorCode::BadMap, 3, 2)),
        (chunk(Rle, 4, 3, 0, 0, &[0]), e(ErrorCode::BadMap, 0, 1)),
        // By side (width first), then by cells.
        (
            chunk(Raw, 1025, 1, 0, 129, &[0]),
            e(ErrorCode::MapTooLarge, 1025, 1024),
        ),
        (
            chunk(Rle, 1, 1100, 0, 3, &[0]),
            e(ErrorCode::MapTooLarge, 1100, 1024),
        ),
        (
            chunk(Raw, 2000, 2000, 0, 500_000, &[0]),
            e(ErrorCode::MapTooLarge, 2000, 1024),
        ),
        (
            chunk(Raw, 1024, 257, 0, 32_896, &[0]),
            e(ErrorCode::MapTooLarge, 1024 * 257, 512 * 512),
        ),
        // A size over the limits comes before a wrong total_len.
        (
            chunk(Raw, 1024, 257, 0, 1, &[0]),
            e(ErrorCode::MapTooLarge, 1024 * 257, 512 * 512),
        ),
        // Nothing open.
        (chunk(Raw, 4, 3, 1, 2, &[0]), e(ErrorCode::BadChunk, 0, 0)),
        // Header fits but the chunk runs past total_len.
        (
            chunk(Raw, 4, 3, 0, 2, &[0, 0, 0]),
            e(ErrorCode::BadChunk, 0, 2),
        ),
    ];
    for (c, want) in cases {
        assert_eq!(Upload::new().accept(&c, LIMITS), Err(want), "{c:?}");
    }
    // A refused first chunk (empty, or past its own total_len) opens nothing.
    assert!(up.accept(&chunk(Raw, 4, 3, 0, 2, &[]), LIMITS).is_err());
    assert!(!up.is_open());
    assert!(up
        .accept(&chunk(Raw, 4, 3, 0, 2, &[0, 0, 0]), LIMITS)
        .is_err());
    assert!(!up.is_open());
    assert_eq!(
        up.accept(&chunk(Raw, 4, 3, 1, 2, &[0]), LIMITS),
        Err(e(ErrorCode::BadChunk, 0, 0))
    );
    // Any shape within the cells and the side: 1024 x 256 is as many cells as 512 x 512.
    let mut wide = Upload::new();
    let c = chunk(Raw, 1024, 256, 0, 32_768, &[0xFF]);
    assert_eq!(wide.accept(&c, LIMITS), Ok(true));
    // A good start, then chunks that do not continue it.
    let mut up = Upload::new();
    assert_eq!(up.accept(&chunk(Rle, 4, 3, 0, 3, &[5]), LIMITS), Ok(true));
    let mut buf = [0u8; 2];
    assert_eq!(up.write(&chunk(Rle, 4, 3, 0, 3, &[5]), &mut buf), Ok(None));
    for c in [
        chunk(Rle, 4, 3, 2, 3, &[6]), // a gap: offset past the 1 byte received
        chunk(Raw, 4, 3, 1, 3, &[1]), // other encoding
        chunk(Rle, 3, 4, 1, 3, &[1]), // other sides
        chunk(Rle, 4, 3, 1, 4, &[1]), // other total_len
        chunk(Rle, 4, 3, 1, 3, &[1, 6, 0]), // past total_len
    ] {
        assert_eq!(up.accept(&c, LIMITS), Err(e(ErrorCode::BadChunk, 1, 3)));
        assert_eq!(up.write(&c, &mut buf), Err(e(ErrorCode::BadChunk, 1, 3)));
    }
    // A refused new header or first chunk leaves the open upload as it was.
    let before = up;
    assert!(up
        .accept(&chunk(Raw, 1100, 1, 0, 138, &[0]), LIMITS)
        .is_err());
    assert!(up.accept(&chunk(Raw, 4, 3, 0, 2, &[]), LIMITS).is_err());
    assert!(up
        .accept(&chunk(Raw, 4, 3, 0, 2, &[0, 0, 0]), LIMITS)
        .is_err());
    assert!(up.accept(&chunk(Rle, 4, 3, 1, 3, &[]), LIMITS).is_err());
    assert_eq!(up, before);
    // A re-sent chunk overlapping what arrived is fine; only the new bytes count.
    let c = chunk(Rle, 4, 3, 0, 3, &[5, 1]);
    assert_eq!(up.accept(&c, LIMITS), Ok(true)); // offset 0 restarts
    assert_eq!(up.write(&c, &mut buf), Ok(None));
    let c = chunk(Rle, 4, 3, 1, 3, &[1, 6]);
    assert_eq!(up.accept(&c, LIMITS), Ok(false));
    assert_eq!(up.write(&c, &mut buf), Ok(Some((4, 3))));
    assert_eq!(buf[0] & 0xF0, 0x20);
    assert_eq!(buf[1] & 0x0F, 0x00);
    // Complete: the upload is closed, a re-sent last chunk finds none.
    assert!(!up.is_open());
    assert_eq!(up.accept(&c, LIMITS), Err(e(ErrorCode::BadChunk, 0, 0)));
}

#[test]
fn bad_run_length_codes_close_the_upload() {
    use Encoding::Rle;
    let mut buf = [0u8; 2];
    // Overrun in the middle.
    let mut up = Upload::new();
    let c = chunk(Rle, 4, 3, 0, 4, &[5, 1, 7, 0]);
    assert_eq!(up.accept(&c, LIMITS), Ok(true));
    assert_eq!(
        up.write(&c, &mut buf),
        Err(ErrorReply::with(ErrorCode::BadRle, 6, 12))
    );
    assert!(!up.is_open());
    // Ends short of the map (11 of 12 cells).
    let c = chunk(Rle, 4, 3, 0, 3, &[5, 1, 5]);
    up.accept(&c, LIMITS).unwrap();
    assert_eq!(
        up.write(&c, &mut buf),
        Err(ErrorReply::with(ErrorCode::BadRle, 11, 12))
    );
    // Ends inside a varint.
    let c = chunk(Rle, 4, 3, 0, 3, &[5, 1, 0x86]);
    up.accept(&c, LIMITS).unwrap();
    assert_eq!(
        up.write(&c, &mut buf),
        Err(ErrorReply::with(ErrorCode::BadRle, 6, 12))
    );
    // Trailing empty runs after the last cell are harmless.
    let c = chunk(Rle, 4, 3, 0, 5, &[5, 1, 6, 0, 0]);
    up.accept(&c, LIMITS).unwrap();
    assert_eq!(up.write(&c, &mut buf), Ok(Some((4, 3))));
}

#[test]
fn write_without_accept_is_refused() {
    let mut buf = [0u8; 2];
    let c = chunk(Encoding::Raw, 4, 3, 0, 2, &[0, 0]);
    assert_eq!(
        Upload::new().write(&c, &mut buf),
        Err(ErrorReply::with(ErrorCode::BadChunk, 0, 0))
    );
    // A buffer too small for the map is a BadChunk, not a panic.
    let mut up = Upload::new();
    up.accept(&c, LIMITS).unwrap();
    assert!(up.write(&c, &mut [0u8; 1]).is_err());
}

/// The naive rectangle: every cell by hand.
fn naive_rect(w: u16, bits: &mut [u8], (x, y, rw, rh): (u16, u16, u16, u16), v: bool) {
    for yy in y..y + rh {
        for xx in x..x + rw {
            let i = yy as usize * w as usize + xx as usize;
            if v {
                bits[i / 8] |= 1 << (i % 8);
            } else {
                bits[i / 8] &= !(1 << (i % 8));
            }
        }
    }
}

#[test]
fn rectangles_change_exactly_their_cells() {
    let mut rng = Lcg(11);
    let (w, h) = (37u16, 29u16);
    let cells = 37 * 29;
    let mut a = runs_map(&mut rng, cells, 6);
    let mut b = a.clone();
    for _ in 0..300 {
        let x = (rng.next() % w as u32) as u16;
        let y = (rng.next() % h as u32) as u16;
        let rw = (rng.next() % (w - x) as u32 + 1) as u16;
        let rh = (rng.next() % (h - y) as u32 + 1) as u16;
        let v = rng.next() % 2 == 0;
        set_rect((w, h), &mut a, (x, y, rw, rh), v).unwrap();
        naive_rect(w, &mut b, (x, y, rw, rh), v);
        assert!(same_cells(&a, &b, cells));
    }
}

#[test]
fn updates_outside_the_map_change_nothing() {
    let e = |x, y| Err(ErrorReply::with(ErrorCode::OutsideMap, x, y));
    let map = (10u16, 5u16);
    let mut bits = [0u8; 7];
    assert_eq!(set_rect(map, &mut bits, (10, 0, 1, 1), true), e(10, 0));
    assert_eq!(set_rect(map, &mut bits, (0, 5, 1, 1), true), e(0, 5));
    assert_eq!(set_rect(map, &mut bits, (8, 3, 3, 1), true), e(10, 3));
    assert_eq!(set_rect(map, &mut bits, (8, 3, 1, 3), true), e(8, 5));
    assert_eq!(
        set_rect(map, &mut bits, (9, 4, u16::MAX, u16::MAX), true),
        e(65543, 65538)
    );
    assert_eq!(bits, [0; 7]);
    // A zero-size rectangle inside changes nothing and is fine.
    assert_eq!(set_rect(map, &mut bits, (3, 3, 0, 0), true), Ok(()));
    assert_eq!(bits, [0; 7]);
    // The whole map.
    assert_eq!(set_rect(map, &mut bits, (0, 0, 10, 5), true), Ok(()));
    assert!((0..50).all(|i| cell(&bits, i)));

    let pts = [Point::new(0, 0), Point::new(9, 4), Point::new(3, 5)];
    let mut bits = [0u8; 7];
    assert_eq!(
        set_cells(map, &mut bits, &Waypoints::Points(&pts), true),
        e(3, 5)
    );
    assert_eq!(bits, [0; 7]);
    assert_eq!(
        set_cells(map, &mut bits, &Waypoints::Points(&pts[..2]), true),
        Ok(())
    );
    assert!(cell(&bits, 0) && cell(&bits, 49));
    assert_eq!((1..49).filter(|&i| cell(&bits, i)).count(), 0);
    assert_eq!(
        set_cells(map, &mut bits, &Waypoints::Points(&pts[..1]), false),
        Ok(())
    );
    assert!(!cell(&bits, 0));
    assert_eq!(
        set_cells(map, &mut bits, &Waypoints::Points(&[]), true),
        Ok(())
    );
    let many = [Point::new(1, 1); MAX_UPDATE_CELLS + 1];
    assert_eq!(
        set_cells(map, &mut bits, &Waypoints::Points(&many), true),
        Err(ErrorReply::with(ErrorCode::TooLarge, 61, 60))
    );
    assert_eq!(
        set_cells(map, &mut bits, &Waypoints::Points(&many[1..]), true),
        Ok(())
    );
}

#[test]
fn the_largest_new_requests_fit_a_request_frame() {
    let cells = [Point::new(u16::MAX, u16::MAX); MAX_UPDATE_CELLS];
    let chunk = [0xFFu8; MAX_CHUNK];
    let mut buf = [0u8; MAX_REQUEST_WIRE];
    for r in [
        Request::SetCells {
            blocked: true,
            cells: Waypoints::Points(&cells),
        },
        Request::SetMapRle {
            width: u16::MAX,
            height: u16::MAX,
            offset: u32::MAX,
            total_len: u32::MAX,
            chunk: &chunk,
        },
        Request::SetRect {
            x: u16::MAX,
            y: u16::MAX,
            width: u16::MAX,
            height: u16::MAX,
            blocked: true,
        },
        Request::PlanWarm {
            start: Point::new(u16::MAX, u16::MAX),
            goal: Point::new(u16::MAX, u16::MAX),
            seed: Some(u64::MAX),
        },
    ] {
        let n = encode_request(u32::MAX, &r, &mut buf).unwrap();
        // Payload (postcard + CRC) within MAX_REQUEST.
        assert!(n <= MAX_REQUEST_WIRE);
        let (id, back) = decode_request(&mut buf[..n - 1]).unwrap();
        assert_eq!((id, back), (u32::MAX, r));
    }
}

#[test]
fn set_cells_with_a_ragged_byte_string_does_not_decode() {
    // id 1, SetCells, blocked, 3 bytes: not a multiple of 4.
    let body = [1u8, 8, 1, 3, 0, 0, 0];
    let mut p = body.to_vec();
    p.extend_from_slice(&crc32(&body).to_le_bytes());
    let mut f = vec![0u8; p.len() + 2];
    let src = cobs_overhead(p.len());
    f[src..src + p.len()].copy_from_slice(&p);
    let n = frame::cobs_encode_in_place(&mut f, src, p.len()).unwrap();
    assert_eq!(
        decode_request(&mut f[..n]),
        Err(DecodeError::Undecodable { id: Some(1) })
    );
}
