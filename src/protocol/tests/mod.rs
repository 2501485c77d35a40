//! Tests of the wire protocol, by topic: [`frames`] (CRC, COBS, corruption, the frame reader),
//! [`messages`] (every message round trips and fits its limits, path streaming, error codes),
//! [`document`] (the worked exchange of docs/PROTOCOL.md, byte for byte), [`map`] (uploads,
//! run-length codes, cell updates) and [`map_document`] (the "Big maps and cell updates" examples
//! of docs/PROTOCOL.md). This file holds what they share: generators, sample messages, encoding
//! and document helpers.

use super::frame::{cobs_decode_in_place, cobs_encode_in_place};
use super::*;
use crate::colony::ant::DeadEnd;
use crate::error::{Error, Param};
use crate::map::grid::Point;
use crate::planner::Algorithm;
use crate::planner::Params;
use crate::polish::smoothing::SmoothingKind;
use serde::Serialize;

mod document;
mod frames;
mod map;
mod map_document;
mod messages;

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
        warm_patience: 7,
        refine_patience: 300,
        seed: u64::MAX,
        dead_end: DeadEnd::Die,
        smoothing: SmoothingKind::Greedy,
        tighten: false,
        prune: true,
        refine: true,
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
            cells: crate::board::F411.cells as u32,
            max_side: crate::board::F411.max_side,
            max_steps: crate::board::F411.max_steps as u32,
            max_chunk: MAX_CHUNK as u16,
            max_request: MAX_REQUEST as u16,
            plan_queue: 4,
            tick_hz: 1_000_000,
            window: crate::board::F411.window as u8,
            window_bytes: crate::board::F411.rx_ring as u16,
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
        origin: crate::planner::Origin::Warm,
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
        Reply::PathPart(PathPart {
            offset: 0,
            total_len: 77,
            bytes: &[],
        }),
        Reply::PathPart(PathPart {
            offset: u32::MAX,
            total_len: u32::MAX,
            bytes: &[0xff; PART_BYTES],
        }),
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

fn hex(b: &[u8]) -> String {
    b.iter()
        .map(|x| format!("{x:02x}"))
        .collect::<Vec<_>>()
        .join(" ")
}
