//! Instructions per frame of the wire's framing (CRC-32/ISO-HDLC and COBS): the hand-written
//! code of `src/protocol/frame.rs` against the `crc` crate (`NoTable`, `Table<1>`, `Table<16>`),
//! the `cobs` crate and postcard's COBS flavour (`CrcModifier<Cobs<Slice>>`, as
//! `postcard::to_slice_cobs` and `postcard::ser_flavors::crc` build it). Issue 29, item 6;
//! BENCHMARKS.md, "Dependencies by measurement".
//!
//! Two payloads: a 256-byte request (`MAX_REQUEST`) and a 2,520-byte path reply, both fixed
//! pseudo-random bytes with zeros in them. Every variant's frame is checked byte for byte against
//! the hand-written one (and decoded back) before anything is counted.
//!
//! Count instructions with callgrind, which does not drift with load: run a variant once with
//! `1` and once with `101` frames and divide the difference of the two totals by 100.
//!
//! ```text
//! cargo build --release -p ohaca-host-tests --target host-tuple --example frame_bench
//! scripts/frame-bench.sh        # every variant, both payloads: the table in BENCHMARKS.md
//! target/x86_64-unknown-linux-gnu/release/examples/frame_bench VARIANT LEN REPS
//! ```

#[allow(dead_code)]
#[path = "../../src/protocol/frame.rs"]
mod frame;

use std::hint::black_box;

use crc::{Crc, NoTable, Table, CRC_32_ISO_HDLC};
use postcard::ser_flavors::crc::CrcModifier;
use postcard::ser_flavors::{Cobs, Flavor, Slice};

static CRC_NOTABLE: Crc<u32, NoTable> = Crc::<u32, NoTable>::new(&CRC_32_ISO_HDLC);
static CRC_T1: Crc<u32, Table<1>> = Crc::<u32, Table<1>>::new(&CRC_32_ISO_HDLC);
static CRC_T16: Crc<u32, Table<16>> = Crc::<u32, Table<16>>::new(&CRC_32_ISO_HDLC);

const VARIANTS: &[&str] = &[
    "crc-hand",
    "crc-notable",
    "crc-table1",
    "crc-table16",
    "crc-hand-bytewise",
    "crc-notable-bytewise",
    "crc-table1-bytewise",
    "crc-table16-bytewise",
    "cobs-enc-hand",
    "cobs-enc-crate",
    "cobs-dec-hand",
    "cobs-dec-crate",
    "frame-enc-hand",
    "frame-enc-postcard",
    "frame-dec-hand",
    "frame-dec-postcard",
];

/// `len` fixed pseudo-random bytes, about one in 16 of them zero.
fn payload(len: usize) -> Vec<u8> {
    let mut s: u32 = 0x9E37_79B9;
    (0..len)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            if s & 15 == 0 {
                0
            } else {
                (s >> 8) as u8 | 1
            }
        })
        .collect()
}

/// The hand-written frame: `COBS(body ++ crc32_le(body)) ++ [0x00]`, as `protocol::encode` makes it.
fn frame_hand(body: &[u8], out: &mut [u8]) -> usize {
    let payload = body.len() + 4;
    let src = frame::cobs_overhead(payload);
    out[src..src + body.len()].copy_from_slice(body);
    let crc = frame::crc32(&out[src..src + body.len()]);
    out[src + body.len()..src + payload].copy_from_slice(&crc.to_le_bytes());
    let n = frame::cobs_encode_in_place(out, src, payload).unwrap();
    out[n] = 0;
    n + 1
}

/// The same frame from postcard's flavours: what `serialize_with_flavor` does with each byte the
/// serializer emits (postcard's CRC flavour takes the `crc` crate's default `Table<1>` digest).
fn frame_postcard(body: &[u8], out: &mut [u8]) -> usize {
    let cobs = Cobs::try_new(Slice::new(out)).unwrap();
    let mut f = CrcModifier::new(cobs, CRC_T1.digest());
    f.try_extend(body).unwrap();
    f.finalize().unwrap().len()
}

/// Decode a frame (delimiter included) and check its CRC, as `protocol::unframe` does.
fn unframe_hand(frame: &mut [u8]) -> usize {
    let end = frame.len() - 1;
    let n = frame::cobs_decode_in_place(&mut frame[..end]).unwrap();
    let (body, crc) = frame[..n].split_at(n - 4);
    assert_eq!(frame::crc32(body).to_le_bytes(), crc);
    n - 4
}

/// The same with the `cobs` crate (postcard's `from_bytes_cobs`) and the `crc` crate's
/// `Table<1>` (postcard's `from_bytes_crc32`).
fn unframe_postcard(frame: &mut [u8]) -> usize {
    let n = cobs::decode_in_place(frame).unwrap();
    let (body, crc) = frame[..n].split_at(n - 4);
    assert_eq!(CRC_T1.checksum(body).to_le_bytes(), crc);
    n - 4
}

fn cobs_hand(data: &[u8], out: &mut [u8]) -> usize {
    let src = frame::cobs_overhead(data.len());
    out[src..src + data.len()].copy_from_slice(data);
    frame::cobs_encode_in_place(out, src, data.len()).unwrap()
}

/// Run `variant` once on `data`; returns something that depends on the whole result.
fn run(variant: &str, data: &[u8], enc: &[u8], buf: &mut [u8]) -> u64 {
    let data = black_box(data);
    match variant {
        "crc-hand" => frame::crc32(data).into(),
        "crc-notable" => CRC_NOTABLE.checksum(data).into(),
        "crc-table1" => CRC_T1.checksum(data).into(),
        "crc-table16" => CRC_T16.checksum(data).into(),
        // A byte at a time, as a frame encoded piece by piece would feed its CRC.
        "crc-hand-bytewise" => {
            let mut r = frame::CRC32_INIT;
            for &b in data {
                r = frame::crc32_step(black_box(r), b);
            }
            (!r).into()
        }
        "crc-notable-bytewise" => {
            let mut d = CRC_NOTABLE.digest();
            for &b in data {
                d.update(black_box(&[b]));
            }
            d.finalize().into()
        }
        "crc-table1-bytewise" => {
            let mut d = CRC_T1.digest();
            for &b in data {
                d.update(black_box(&[b]));
            }
            d.finalize().into()
        }
        "crc-table16-bytewise" => {
            let mut d = CRC_T16.digest();
            for &b in data {
                d.update(black_box(&[b]));
            }
            d.finalize().into()
        }
        "cobs-enc-hand" => cobs_hand(data, buf) as u64,
        "cobs-enc-crate" => cobs::encode(data, buf) as u64,
        "cobs-dec-hand" => {
            buf[..enc.len()].copy_from_slice(enc);
            frame::cobs_decode_in_place(&mut buf[..enc.len()]).unwrap() as u64
        }
        "cobs-dec-crate" => {
            buf[..enc.len()].copy_from_slice(enc);
            cobs::decode_in_place(&mut buf[..enc.len()]).unwrap() as u64
        }
        "frame-enc-hand" => frame_hand(data, buf) as u64,
        "frame-enc-postcard" => frame_postcard(data, buf) as u64,
        // `enc` is the whole frame here.
        "frame-dec-hand" => {
            buf[..enc.len()].copy_from_slice(enc);
            unframe_hand(&mut buf[..enc.len()]) as u64
        }
        "frame-dec-postcard" => {
            buf[..enc.len()].copy_from_slice(enc);
            unframe_postcard(&mut buf[..enc.len()]) as u64
        }
        _ => panic!("unknown variant {variant}; one of {VARIANTS:?}"),
    }
}

/// Every variant agrees with the hand-written code, byte for byte.
fn check(data: &[u8]) {
    let mut a = vec![0; frame::wire_len(data.len() + 4)];
    let mut b = a.clone();
    let want = frame::crc32(data);
    assert_eq!(CRC_NOTABLE.checksum(data), want);
    assert_eq!(CRC_T1.checksum(data), want);
    assert_eq!(CRC_T16.checksum(data), want);
    let na = cobs_hand(data, &mut a);
    let nb = cobs::encode(data, &mut b);
    assert_eq!(a[..na], b[..nb], "cobs");
    let na = frame_hand(data, &mut a);
    let nb = frame_postcard(data, &mut b);
    assert_eq!(a[..na], b[..nb], "frame");
    let mut c = a[..na].to_vec();
    assert_eq!(unframe_postcard(&mut c), data.len());
    assert_eq!(c[..data.len()], *data);
    let mut c = a[..na].to_vec();
    assert_eq!(unframe_hand(&mut c), data.len());
    assert_eq!(c[..data.len()], *data);
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.is_empty() {
        for len in [256, 2520] {
            check(&payload(len));
        }
        println!("all variants agree byte for byte; variants: {VARIANTS:?}");
        return;
    }
    let (variant, len, reps) = match &args[..] {
        [v, l, r] => (v.as_str(), l.parse().unwrap(), r.parse::<u32>().unwrap()),
        _ => panic!("usage: frame_bench [VARIANT LEN REPS]"),
    };
    let data = payload(len);
    check(&data);
    let mut buf = vec![0u8; frame::wire_len(len + 4)];
    let enc = if variant.starts_with("frame-dec") {
        let n = frame_hand(&data, &mut buf);
        buf[..n].to_vec()
    } else {
        let n = cobs_hand(&data, &mut buf);
        buf[..n].to_vec()
    };
    let mut acc = 0u64;
    for _ in 0..reps {
        acc = acc.wrapping_add(run(variant, &data, &enc, &mut buf));
    }
    println!("{variant} {len} {reps} {acc}");
}
