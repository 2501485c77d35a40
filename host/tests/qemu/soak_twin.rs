//! Faults at scale (issue 19, item 7): map uploads of 512 x 512 and 604 x 307 cells over QEMU's
//! UART with injected byte drops and corruption, against the STM32H743's capacity twin and
//! against the F411-capacity firmware (the default QEMU build), which holds these maps in its
//! arena (`ohaca::planner::arena`); `qemu/soak.rs` soaks the latter with many small frames.
//!
//! Each round uploads `NewYork_0_512` (512 x 512, a city) and a generated 604 x 307 depot (the
//! shape of Nav2's sample depot: walls, racks, aisles, noise), each raw and run-length coded,
//! three chunks in flight like `ohaca_host::link::Link`. 15 % of the chunk frames are damaged on
//! their way, one of six ways alike: a byte dropped, the delimiter dropped (so the frame runs
//! into the next one), a bit flipped, a byte garbled, garbage inserted, or the frame cut short.
//! The host reacts as a client written from docs/PROTOCOL.md would: after a lost or refused
//! chunk it sends a lone `00` (to end a partial frame) and goes back to the first chunk not
//! acknowledged (`BadChunk` says how far the device got). Before three uploads of every four
//! (in turn) it also breaks one on purpose: abandoned half way (`Stats` says 0 x 0, a plan gets
//! `NoMap`), a run-length code that overruns the map in a frame with a good CRC (`BadRle`, no
//! map), or a restart with a wrong `total_len` (`BadMap`, and the open upload goes on
//! untouched). Each is then redone.
//!
//! What the device must answer is computed by a model fed the exact bytes written: the protocol's
//! own `RequestReader` and `decode_request`, and its `Upload` rules for the map (as
//! `src/firmware/rx.rs`). Every reply is checked against it, in order (no timeouts are needed:
//! the model knows when no reply is due). After each upload: `Stats` has the map's size, and a
//! plan on it is the host core's, bit for bit, on the map the host meant to send (so no accepted
//! byte was lost or changed). At the end, `Stats`' `frames_ok`, `frames_bad` and `rx_bytes` are
//! exactly the model's, `rx_overruns` and `replies_dropped` 0, `boots` 1.
//!
//! It keeps within the device's window (protocol 10: 8 requests and 1,024 bytes outstanding)
//! without trying: every write is at most three chunk frames and a `00`, and its replies are
//! read before the next write (asserted per write).
//!
//! `OHACA_SOAK_SCALE_ROUNDS` rounds (default 1: about 30 s), seed `OHACA_SOAK_SEED`;
//! `scripts/soak.sh` runs more rounds as its second phase. A summary is printed
//! (`--nocapture`).

use crate::qemu;

use std::io::Write;
use std::net::TcpStream;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use ohaca::protocol::{
    decode_request, encode_request, Encoding, ErrorCode, ErrorReply, MapChunk, MapLimits, Request,
    RequestReader, RleEncoder, Upload, MAX_CHUNK, MAX_REQUEST_WIRE,
};
use ohaca::{Params, Point};
use ohaca_host::link::Response;
use ohaca_host::Map;
use qemu::{
    assert_core_path, core_plan, core_plan_steps, firmware, have_qemu, maps, twin_firmware,
    CorePath, Qemu,
};

const DEFAULT_ROUNDS: usize = 1;
const DEFAULT_SEED: u64 = 0x0ACA_5CA1;
/// The twin's limits (`src/firmware/state.rs` with `ohaca::board::H743`).
const LIMITS: MapLimits = MapLimits {
    max_cells: 2_097_152,
    max_side: 4096,
};
/// Chunk frames in flight.
const WINDOW: usize = 3;
/// The device's window (`Capacity::window`, `window_bytes`: the board's `window` and `rx_ring`,
/// the same on every board). Every write's replies are read before the next write, and a write is at most
/// [`WINDOW`] chunk frames (at most 164 bytes each with inserted garbage) and a lone `00`: well
/// within it, so nothing may be lost (`rx_overruns`, `replies_dropped` 0). Asserted per write.
const DEVICE_WINDOW: (usize, usize) = (ohaca::board::H743.window, ohaca::board::H743.rx_ring);
/// How long one reply may take (a plan on 512 x 512 without `-icount` takes a second or two).
const REPLY_TIMEOUT: Duration = Duration::from_secs(120);

use crate::depot;
use depot::depot;
use ohaca_host::rng::Rng;

use qemu::{read_replies, Incoming};

/// A reply the model predicts.
#[derive(Debug, PartialEq)]
enum Want {
    /// `Ack`, `Error` (the receive task's replies, exactly).
    Exact(u32, Response),
    /// `Stats` with this id (checked by the caller).
    Stats(u32),
    /// A plan's reply with this id (checked by the caller).
    Plan(u32),
}

/// The device's map state as `src/firmware/rx.rs` keeps it.
struct Model {
    upload: Upload,
    bits: Vec<u8>,
    size: Option<(u16, u16)>,
}

impl Model {
    /// What `src/firmware/rx.rs` answers to `req`, and its effect on the model's map.
    fn apply(&mut self, id: u32, req: &Request<'_>) -> Want {
        let c = match *req {
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
            Request::Stats => return Want::Stats(id),
            Request::Plan { .. } | Request::PlanWarm { .. } if self.size.is_some() => {
                return Want::Plan(id)
            }
            Request::Plan { .. } | Request::PlanWarm { .. } => {
                return Want::Exact(id, Response::Error(ErrorReply::new(ErrorCode::NoMap)))
            }
            Request::SetParams(_) => return Want::Exact(id, Response::Ack),
            ref other => panic!("a damaged frame decoded as {other:?}: CRC collision?"),
        };
        let (encoding, width, height, offset, total_len, chunk) = c;
        let c = MapChunk {
            encoding,
            width,
            height,
            offset,
            total_len,
            chunk,
        };
        let starts = match self.upload.accept(&c, LIMITS) {
            Ok(s) => s,
            Err(e) => return Want::Exact(id, Response::Error(e)),
        };
        if starts {
            self.size = None;
        }
        match self.upload.write(&c, &mut self.bits) {
            Ok(Some(size)) => {
                self.size = Some(size);
                Want::Exact(id, Response::Ack)
            }
            Ok(None) => Want::Exact(id, Response::Ack),
            Err(e) => Want::Exact(id, Response::Error(e)),
        }
    }
}

/// The device as the host models it, and the link to it.
struct Device {
    out: TcpStream,
    rx: mpsc::Receiver<Incoming>,
    reader: Box<RequestReader>,
    model: Model,
    next_id: u32,
    frames_ok: u32,
    frames_bad: u32,
    rx_bytes: u64,
    faults: [u32; 6],
    resent: u32,
}

const FAULTS: [&str; 6] = [
    "dropped byte",
    "dropped delimiter",
    "flipped bit",
    "garbled byte",
    "inserted garbage",
    "cut short",
];

impl Device {
    fn new(q: &Qemu) -> Device {
        let s = q.connect();
        let r = s.try_clone().expect("clone the stream");
        let (tx, rx) = mpsc::channel();
        std::thread::spawn(move || read_replies(r, tx));
        let mut d = Device {
            out: s,
            rx,
            reader: Box::new(RequestReader::new()),
            model: Model {
                upload: Upload::new(),
                bits: vec![0; LIMITS.bytes()],
                size: None,
            },
            next_id: 1,
            frames_ok: 0,
            frames_bad: 0,
            rx_bytes: 0,
            faults: [0; 6],
            resent: 0,
        };
        // A fresh connection: end whatever partial frame a previous client left.
        let none = d.write(&[0]);
        assert!(none.is_empty());
        d
    }

    fn id(&mut self) -> u32 {
        self.next_id += 1;
        self.next_id
    }

    /// Write `bytes` and return the replies they call for, in order, from the model.
    fn write(&mut self, bytes: &[u8]) -> Vec<Want> {
        assert!(
            bytes.len() <= DEVICE_WINDOW.1,
            "a write beyond the window: {} bytes",
            bytes.len()
        );
        self.out.write_all(bytes).expect("write to the device");
        self.rx_bytes += bytes.len() as u64;
        let mut want = Vec::new();
        for &b in bytes {
            let Some(f) = self.reader.push(b).into_frame(MAX_REQUEST_WIRE) else {
                continue;
            };
            match f.and_then(decode_request) {
                Err(e) => {
                    self.frames_bad += 1;
                    want.push(Want::Exact(e.id(), Response::Error(e.reply())));
                }
                Ok((id, req)) => {
                    self.frames_ok += 1;
                    want.push(self.model.apply(id, &req));
                }
            }
        }
        assert!(
            want.len() <= DEVICE_WINDOW.0,
            "a write beyond the window: {} requests",
            want.len()
        );
        want
    }

    fn recv(&mut self) -> (u32, Response) {
        match self.rx.recv_timeout(REPLY_TIMEOUT) {
            Ok(Ok(r)) => r,
            Ok(Err(e)) => panic!("{e}"),
            Err(e) => panic!("no reply within {REPLY_TIMEOUT:?}: {e}"),
        }
    }

    /// Read the replies `want` predicts and check the exact ones; returns them all.
    fn expect(&mut self, want: &[Want]) -> Vec<(u32, Response)> {
        let mut got = Vec::with_capacity(want.len());
        for w in want {
            let r = self.recv();
            match w {
                Want::Exact(id, resp) => {
                    assert_eq!((&r.0, &r.1), (id, resp), "reply vs the model")
                }
                Want::Stats(id) => {
                    assert_eq!(r.0, *id);
                    assert!(matches!(r.1, Response::Stats(_)), "{r:?}");
                }
                Want::Plan(id) => assert_eq!(r.0, *id),
            }
            got.push(r);
        }
        got
    }

    /// Send one request (whole) and read its replies.
    fn call(&mut self, req: &Request<'_>) -> (u32, Response) {
        let id = self.id();
        let want = self.write(&frame(id, req));
        assert_eq!(want.len(), 1, "{want:?}");
        self.expect(&want).remove(0)
    }

    fn stats(&mut self) -> ohaca::protocol::StatsReply {
        match self.call(&Request::Stats).1 {
            Response::Stats(s) => s,
            r => panic!("{r:?}"),
        }
    }

    /// Damage `f` (a frame with its delimiter) at random; counts the kind.
    fn damage(&mut self, f: &mut Vec<u8>, rng: &mut Rng) {
        let k = rng.below(FAULTS.len());
        self.faults[k] += 1;
        let last = f.len() - 1;
        let at = rng.below(last);
        match k {
            0 => {
                f.remove(at);
            }
            1 => {
                f.pop();
            }
            2 => f[at] ^= 1 << rng.below(8),
            3 => f[at] = rng.next() as u8,
            4 => {
                let n = 1 + rng.below(8);
                for _ in 0..n {
                    f.insert(at, rng.next() as u8 | 1);
                }
            }
            _ => {
                f.truncate(at.max(1));
                f.push(0);
            }
        }
    }

    /// Upload `code` (the map's packed bits or its run-length code) in chunks, `faulty` of the
    /// chunk frames damaged on the way, until the device has all of it; returns the chunk frames
    /// written.
    fn upload(
        &mut self,
        map: &Map,
        enc: Encoding,
        code: &[u8],
        rng: &mut Rng,
        faulty: f64,
        stop_after: Option<usize>,
    ) -> usize {
        let chunks: Vec<&[u8]> = code.chunks(MAX_CHUNK).collect();
        let mut next = 0; // the first chunk not known to be acknowledged
        let mut written = 0;
        let mut stalled = 0;
        while next < chunks.len() {
            let end = (next + WINDOW).min(chunks.len());
            let mut bytes = Vec::new();
            let mut ids = Vec::new();
            for (k, chunk) in chunks.iter().enumerate().take(end).skip(next) {
                let id = self.id();
                let req = chunk_request(map, enc, code.len(), k, chunk);
                let mut f = frame(id, &req);
                if rng.chance(faulty) {
                    self.damage(&mut f, rng);
                }
                bytes.extend(f);
                ids.push((id, k));
            }
            written += ids.len();
            let want = self.write(&bytes);
            let mut got = self.expect(&want);
            let all_acked = |got: &[(u32, Response)]| {
                ids.iter().all(|(id, _)| {
                    got.iter()
                        .any(|(i, r)| i == id && matches!(r, Response::Ack))
                })
            };
            if !all_acked(&got) {
                // A lost or refused chunk: end a partial frame (whose reply then comes: a frame
                // that lost only its delimiter is whole again), then go back.
                self.resent += 1;
                let want = self.write(&[0]);
                got.extend(self.expect(&want));
            }
            // A run-length code that overran the map closed the upload: nothing to redo.
            if got
                .iter()
                .any(|(_, r)| matches!(r, Response::Error(e) if e.code == ErrorCode::BadRle))
            {
                return written;
            }
            // The chunks acknowledged in order from `next`: the device holds every byte before
            // the first one that is not (a chunk is accepted only if it continues what arrived).
            let acked = ids
                .iter()
                .take_while(|(id, _)| {
                    got.iter()
                        .any(|(i, r)| i == id && matches!(r, Response::Ack))
                })
                .count();
            stalled = if acked == 0 { stalled + 1 } else { 0 };
            assert!(
                stalled < 50,
                "no progress at chunk {next} of {}: {got:?}",
                chunks.len()
            );
            next += acked;
            if stop_after.is_some_and(|n| next >= n) {
                return written;
            }
        }
        written
    }
}

fn frame(id: u32, req: &Request<'_>) -> Vec<u8> {
    let mut buf = [0u8; MAX_REQUEST_WIRE];
    let n = encode_request(id, req, &mut buf).expect("encode");
    buf[..n].to_vec()
}

fn chunk_request<'a>(
    map: &Map,
    enc: Encoding,
    total: usize,
    k: usize,
    chunk: &'a [u8],
) -> Request<'a> {
    let (width, height) = (map.width, map.height);
    let (offset, total_len) = ((k * MAX_CHUNK) as u32, total as u32);
    match enc {
        Encoding::Raw => Request::SetMap {
            width,
            height,
            offset,
            total_len,
            chunk,
        },
        Encoding::Rle => Request::SetMapRle {
            width,
            height,
            offset,
            total_len,
            chunk,
        },
    }
}

fn code_of(map: &Map, enc: Encoding) -> Vec<u8> {
    match enc {
        Encoding::Raw => map.bits.clone(),
        Encoding::Rle => RleEncoder::new(&map.bits, map.cells() as u32).collect(),
    }
}

/// A free cell near `(x, y)` (searching right, then down).
fn free_near(map: &Map, x: u16, y: u16) -> Point {
    for dy in 0..map.height {
        for dx in 0..map.width {
            let (px, py) = ((x + dx) % map.width, (y + dy) % map.height);
            if !map.is_blocked(Point::new(px, py)) {
                return Point::new(px, py);
            }
        }
    }
    panic!("no free cell");
}

#[test]
fn uploads_of_512x512_and_604x307_survive_drops_and_corruption() {
    need_qemu!();
    soak_at_scale(twin_firmware(), |map, start, goal, params| {
        core_plan_steps(map, start, goal, params, 16_384)
    });
}

/// The same soak on the STM32F411-capacity firmware (the default QEMU build), which holds these
/// maps since it plans them in one arena with the map (`ohaca::planner::arena`): every plan is
/// the host core's in an arena of the same length (`core_plan`).
#[test]
fn the_f411_build_survives_the_same_uploads() {
    need_qemu!();
    soak_at_scale(firmware(), core_plan);
}

/// Upload both maps `OHACA_SOAK_SCALE_ROUNDS` times (default 1) to the firmware `elf` through the
/// faults, and require every plan to be `core`'s.
fn soak_at_scale(
    elf: &std::path::Path,
    core: impl Fn(&Map, Point, Point, &Params) -> Result<CorePath, ErrorReply>,
) {
    let rounds: usize = std::env::var("OHACA_SOAK_SCALE_ROUNDS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(DEFAULT_ROUNDS);
    let seed: u64 = std::env::var("OHACA_SOAK_SEED")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(DEFAULT_SEED);
    let mut rng = Rng(seed);
    let mut q = Qemu::tcp_with(elf);
    let mut dev = Device::new(&q);
    let t0 = Instant::now();
    let new_york = Map::load(maps().join("large/NewYork_0_512.map")).expect("NewYork_0_512");
    let depot = depot(seed);
    // Cheap plans: the point is the map, not the colony.
    let params = Params {
        ants: 8,
        iterations: 4,
        ..Params::default()
    };
    let (id, r) = dev.call(&Request::SetParams(params));
    assert_eq!(r, Response::Ack, "{id}");
    let (mut uploads, mut chunk_frames, mut broken, mut plans) = (0, 0, [0u32; 3], 0);
    for round in 0..rounds {
        for (name, map) in [("NewYork_0_512", &new_york), ("depot 604x307", &depot)] {
            for enc in [Encoding::Raw, Encoding::Rle] {
                let code = code_of(map, enc);
                // A broken upload first (each kind once a round, in turn), then the real one.
                let kind = (round + uploads) % 4;
                match kind {
                    0 => {
                        // Abandoned part way: no map until it is redone.
                        broken[0] += 1;
                        let half = code.len().div_ceil(MAX_CHUNK) / 2;
                        chunk_frames += dev.upload(map, enc, &code, &mut rng, 0.15, Some(half));
                        let st = dev.stats();
                        assert_eq!((st.map_width, st.map_height), (0, 0), "{st:?}");
                        let plan = Request::Plan {
                            start: Point::new(0, 0),
                            goal: Point::new(1, 1),
                            seed: None,
                        };
                        let (_, r) = dev.call(&plan);
                        assert_eq!(r, Response::Error(ErrorReply::new(ErrorCode::NoMap)));
                    }
                    1 => {
                        // A run-length code that overruns the map, in a frame with a good CRC.
                        broken[1] += 1;
                        let cells = map.cells() as u32;
                        let bad: Vec<u8> = RleEncoder::new(&map.bits, cells)
                            .chain([0x7f, 0x7f])
                            .collect();
                        chunk_frames += dev.upload(map, Encoding::Rle, &bad, &mut rng, 0.15, None);
                        let st = dev.stats();
                        assert_eq!((st.map_width, st.map_height), (0, 0), "{st:?}");
                    }
                    2 => {
                        // An upload under way, then a restart with a wrong total_len: BadMap,
                        // and the open upload carries on (the real upload below restarts it).
                        broken[2] += 1;
                        chunk_frames += dev.upload(map, enc, &code, &mut rng, 0.15, Some(3));
                        let mut req = chunk_request(map, Encoding::Raw, 5, 0, &[1, 2, 3]);
                        if let Request::SetMap { total_len, .. } = &mut req {
                            *total_len = 5;
                        }
                        let (_, r) = dev.call(&req);
                        assert!(
                            matches!(r, Response::Error(e) if e.code == ErrorCode::BadMap),
                            "{r:?}"
                        );
                    }
                    _ => {}
                }
                let t = Instant::now();
                chunk_frames += dev.upload(map, enc, &code, &mut rng, 0.15, None);
                uploads += 1;
                assert_eq!(dev.model.size, Some((map.width, map.height)));
                assert_eq!(
                    &dev.model.bits[..map.bits.len()],
                    &map.bits[..],
                    "the model's map is the map sent"
                );
                let st = dev.stats();
                assert_eq!((st.map_width, st.map_height), (map.width, map.height));
                let up = t.elapsed().as_secs_f64();
                // A plan across the map: the host core's on the map meant, bit for bit.
                let start = free_near(map, rng.below(64) as u16, rng.below(64) as u16);
                let goal = free_near(
                    map,
                    map.width - 64 + rng.below(60) as u16,
                    map.height - 64 + rng.below(60) as u16,
                );
                let seed = rng.next() % 1000;
                let (_, r) = dev.call(&Request::Plan {
                    start,
                    goal,
                    seed: Some(seed),
                });
                let core = core(map, start, goal, &Params { seed, ..params });
                let outcome = match (r, core) {
                    (Response::Path(p), Ok(c)) => {
                        assert_core_path(name, &c, &p);
                        format!("{} cells", p.raw_cells)
                    }
                    (Response::Error(e), Err(c)) => {
                        assert_eq!(e, c, "{name}");
                        format!("{e}")
                    }
                    (r, c) => panic!("{name}: device {r:?}, core {c:?}"),
                };
                plans += 1;
                println!(
                    "round {round} {name} {enc:?} (broken first: {}): {} B of code, upload \
                     {up:.1} s; plan {start:?} -> {goal:?}: {outcome}",
                    ["abandoned", "BadRle", "BadMap restart", "no"][kind],
                    code.len()
                );
            }
        }
    }
    let st = dev.stats();
    assert_eq!(st.frames_ok, dev.frames_ok, "{st:?}");
    assert_eq!(st.frames_bad, dev.frames_bad, "{st:?}");
    assert_eq!(u64::from(st.rx_bytes), dev.rx_bytes, "{st:?}");
    assert_eq!(
        (st.rx_overruns, st.replies_dropped, st.boots, st.queued),
        (0, 0, 1, 0),
        "{st:?}"
    );
    assert!(q.is_running(), "QEMU exited: the firmware crashed");
    let faults: Vec<String> = FAULTS
        .iter()
        .zip(dev.faults)
        .map(|(n, c)| format!("{n} {c}"))
        .collect();
    println!(
        "soak at scale (seed {seed:#x}, {rounds} rounds): {uploads} uploads and {plans} plans, \
         broken on purpose {} abandoned / {} BadRle / {} BadMap restart; {chunk_frames} chunk \
         frames, faults: {}; {} go-backs; device frames ok {} bad {}, {} bytes; stack peak {} B; \
         {:.1} s",
        broken[0],
        broken[1],
        broken[2],
        faults.join(", "),
        dev.resent,
        st.frames_ok,
        st.frames_bad,
        st.rx_bytes,
        st.stack_peak,
        t0.elapsed().as_secs_f64()
    );
}
