//! Soak test of the firmware's link under QEMU: thousands of frames, valid and broken, many in
//! bursts far faster than the device reads, with every reply checked.
//!
//! One QEMU (UART0 on TCP, `nodelay=on`), one connection. A seeded generator writes
//! `OHACA_SOAK_FRAMES` frames (default [`DEFAULT_FRAMES`]; seed `OHACA_SOAK_SEED`, default
//! [`DEFAULT_SEED`]): valid requests — `Hello`, `Stats`, `SetParams` (cheap: at most 6 ants and
//! 8 iterations; some out of range), `SetMap` (maps up to 16x16, now and then up to 32x32 or a corridor up
//! to 1024 cells long, in one or more chunks, some chunks re-sent, some uploads refused: a side
//! over 4096, more cells than the device holds, an empty chunk, a bad header or chunk), `Plan` (free, blocked and
//! out-of-bounds cells, with and without a seed), `Cancel` — mixed with duplicated requests (the
//! same frame twice, same id), bit-flipped, truncated, oversized, empty (a lone `00`) and
//! random-garbage frames, and frames with a good CRC around a message that does not decode.
//! About one write in eight is a burst of 8 to 64 such frames in a single `write`; one burst in
//! four starts with seven slow plans (more than the queue holds) and ends with a `Cancel`. The
//! frames depend on the seed alone (replies only decide when they are written), so a failure
//! replays with the same frames.
//!
//! What the device must answer is computed on the host by a model of its receive task
//! (`src/firmware/rx.rs`) fed the exact byte stream, split into frames by the protocol's own
//! `RequestReader` and decoded by its own `decode_request`: every bad frame gets its error reply
//! (nothing for an empty frame) and no valid request after it is lost; every valid request gets
//! exactly one reply (a duplicated frame is a valid request received twice: two replies with its
//! id). The assertions, with the reply order of docs/PROTOCOL.md ("Behaviour under stress"):
//!
//! * replies of the receive task (everything but accepted plans) come in request order, with
//!   exactly the expected content (`Hello` as at the start; `Stats` with exactly the modelled
//!   `frames_ok`, `frames_bad` and map, `boots` 1, `uptime` never going back, no overrun);
//! * plans are answered in plan order, paths and errors each (a later plan's path may overtake
//!   an earlier plan's error, which travels in the transmit queue; nothing else overtakes), each
//!   path bit-identical to the host core's on the map and parameters in force when the plan was
//!   sent, each error the core's; `Cancelled` only for a plan followed by a `Cancel` or a new
//!   map; `Busy` only for a plan sent while `plan_queue` plans were unanswered (the generator
//!   waits for room before writing plans, but in the overfilling bursts);
//! * at the end (everything answered), one `Stats` whose counters are exact: `frames_ok` = the
//!   valid frames sent, `frames_bad` = the bad frames the device saw, `rx_bytes` = every byte
//!   written, `tx_frames` = every reply received, `plans` / `plan_errors` / `cancelled` / `busy`
//!   as received, `queued` 0, `rx_overruns` 0, `boots` 1, `uptime` grown; and QEMU still runs
//!   (the firmware leaves QEMU on a panic or a hard fault).
//!
//! A summary line is printed (`--nocapture`). `scripts/soak.sh [FRAMES]` runs the long version
//! (100 000 frames by default).
//!
//! Default size: QEMU feeds the UART 10 to 16 KB/s, so the time goes with the bytes sent:
//! 10 000 frames (about 300 KB) take 20 to 40 s of wall time with `cargo test --release` on the
//! 2-core development machine, well under a minute, so the default is the full 10 000 (100 000
//! took 188 s).

#[macro_use]
#[path = "common/qemu.rs"]
mod qemu;

use std::collections::{BTreeMap, VecDeque};
use std::io::Write;
use std::net::{Shutdown, TcpStream};
use std::rc::Rc;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use ohaca::protocol::{
    decode_request, encode_request, ErrorCode, ErrorReply, Request, RequestReader, StatsReply,
    MAX_CHUNK, MAX_REQUEST_WIRE,
};
use ohaca::{Algorithm, DeadEnd, Params, Point, SmoothingKind};
use ohaca_host::link::{DeviceInfo, Response};
use ohaca_host::Map;
use qemu::{assert_core_path, core_plan, frame_of, have_qemu, try_expected_errors, Qemu, TIMEOUT};

/// Frames sent unless `OHACA_SOAK_FRAMES` says otherwise.
const DEFAULT_FRAMES: usize = 10_000;
/// The generator's seed unless `OHACA_SOAK_SEED` says otherwise.
const DEFAULT_SEED: u64 = 0x0ACA_50AC;

// ---- a small deterministic generator ------------------------------------------------------------

use ohaca_host::rng::Rng;

// ---- what the device must answer ----------------------------------------------------------------

/// The kinds of frames the generator sends.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Kind {
    Hello,
    Stats,
    SetParams,
    SetMap,
    Plan,
    Cancel,
    /// The second copy of a valid request (same bytes, same id).
    Duplicate,
    BitFlipped,
    Truncated,
    Oversized,
    /// A lone `00`.
    Empty,
    Garbage,
    /// A good CRC around a message that does not decode.
    BadMessage,
}

impl Kind {
    fn is_valid(self) -> bool {
        self <= Kind::Duplicate
    }
}

/// What the generator sends in one go: a frame, or a valid request twice (same bytes, same
/// id: two requests, two replies).
#[derive(Clone, Copy, Debug)]
enum Unit {
    Frame(Kind),
    Twice(Kind),
}

impl Unit {
    fn plans(self) -> usize {
        match self {
            Unit::Frame(Kind::Plan) => 1,
            Unit::Twice(Kind::Plan) => 2,
            _ => 0,
        }
    }
}

/// One reply expected from the receive task.
#[derive(Debug)]
enum Want {
    /// Exactly this (`Ack`, an error).
    Exact(Response),
    /// The `Hello` of the start.
    Hello,
    /// A `Stats` with these counters (as the receive task counted them when it handled it).
    Stats {
        frames_ok: u32,
        frames_bad: u32,
        map: (u16, u16),
    },
    /// A plan that may be refused with `Busy` (sent while `plan_queue` plans were unanswered);
    /// if it is not, the planner answers it.
    MaybeBusy { seq: u64 },
}

#[derive(Debug)]
struct RxEntry {
    id: u32,
    want: Want,
}

/// A plan the device accepted (or may have refused with `Busy`).
#[derive(Debug)]
struct Job {
    seq: u64,
    id: u32,
    start: Point,
    goal: Point,
    params: Params,
    map: Rc<Map>,
    /// The model's cancel generation when the plan was sent.
    generation: u32,
    /// It may have been refused with `Busy` (its receive-task entry is still pending).
    busy_ok: bool,
    /// A later plan's path came first: this one's answer must be an error (or `Busy`).
    overtaken: bool,
}

/// What the model says one frame causes.
enum Event {
    Rx { id: u32, want: Want },
    Plan(Job),
}

/// A map upload in progress (the device's `Upload`).
struct Upload {
    width: u16,
    height: u16,
    total_len: u32,
    received: u32,
    bits: Vec<u8>,
}

/// The device's receive task (`src/firmware/rx.rs`, `Session`) and counters, on the host.
struct Session {
    max_cells: u32,
    max_side: u16,
    frames_ok: u32,
    frames_bad: u32,
    params: Params,
    upload: Option<Upload>,
    map: Option<Rc<Map>>,
    /// Bumped by `Cancel` and by every map upload's first chunk.
    generation: u32,
}

fn error(code: ErrorCode, detail: u32, limit: u32) -> Want {
    Want::Exact(Response::Error(ErrorReply::with(code, detail, limit)))
}

impl Session {
    fn handle(&mut self, id: u32, req: Request<'_>) -> Event {
        let want = match req {
            Request::Hello => Want::Hello,
            Request::Stats => Want::Stats {
                frames_ok: self.frames_ok,
                frames_bad: self.frames_bad,
                map: self.map.as_ref().map_or((0, 0), |m| (m.width, m.height)),
            },
            Request::SetParams(p) => match p.validate() {
                Ok(()) => {
                    self.params = p;
                    Want::Exact(Response::Ack)
                }
                Err(e) => Want::Exact(Response::Error(e.into())),
            },
            Request::SetMap {
                width,
                height,
                offset,
                total_len,
                chunk,
            } => self.set_map(width, height, offset, total_len, chunk),
            Request::Plan { start, goal, seed } => match &self.map {
                None => error(ErrorCode::NoMap, 0, 0),
                Some(map) => {
                    return Event::Plan(Job {
                        seq: 0,
                        id,
                        start,
                        goal,
                        params: Params {
                            seed: seed.unwrap_or(self.params.seed),
                            ..self.params
                        },
                        map: map.clone(),
                        generation: self.generation,
                        busy_ok: false,
                        overtaken: false,
                    })
                }
            },
            Request::Cancel => {
                self.generation += 1;
                Want::Exact(Response::Ack)
            }
            other => panic!("the soak does not send {other:?}"),
        };
        Event::Rx { id, want }
    }

    fn set_map(
        &mut self,
        width: u16,
        height: u16,
        offset: u32,
        total_len: u32,
        chunk: &[u8],
    ) -> Want {
        if chunk.is_empty() || chunk.len() > MAX_CHUNK {
            return error(ErrorCode::TooLarge, chunk.len() as u32, MAX_CHUNK as u32);
        }
        // A refused chunk changes nothing (`ohaca::protocol::Upload::accept`): a good offset-0
        // chunk replaces the open upload, a bad header or a first chunk past its own total_len
        // leaves it as it was.
        let mut fresh = None;
        if offset == 0 {
            let cells = u32::from(width) * u32::from(height);
            if cells == 0 {
                return error(ErrorCode::BadMap, total_len, 0);
            }
            for side in [width, height] {
                if side > self.max_side {
                    return error(ErrorCode::MapTooLarge, side.into(), self.max_side.into());
                }
            }
            if cells > self.max_cells {
                return error(ErrorCode::MapTooLarge, cells, self.max_cells);
            }
            let want = cells.div_ceil(8);
            if total_len != want {
                return error(ErrorCode::BadMap, total_len, want);
            }
            if chunk.len() as u32 > total_len {
                return error(ErrorCode::BadChunk, 0, total_len);
            }
            fresh = Some(Upload {
                width,
                height,
                total_len,
                received: 0,
                bits: vec![0; total_len as usize],
            });
        }
        if fresh.is_some() {
            self.upload = fresh;
        }
        let Some(up) = self.upload.as_mut() else {
            return error(ErrorCode::BadChunk, 0, 0);
        };
        let end = offset.saturating_add(chunk.len() as u32);
        let fits = (width, height, total_len) == (up.width, up.height, up.total_len)
            && offset <= up.received
            && end <= up.total_len
            && !chunk.is_empty();
        let slot = up.bits.get_mut(offset as usize..end as usize);
        let (true, Some(slot)) = (fits, slot) else {
            return error(ErrorCode::BadChunk, up.received, up.total_len);
        };
        slot.copy_from_slice(chunk);
        if offset == 0 {
            // The device holds one map: an upload's first chunk drops it and cancels the plans.
            self.map = None;
            self.generation += 1;
        }
        up.received = up.received.max(end);
        if up.received == up.total_len {
            let map = Map {
                width: up.width,
                height: up.height,
                bits: up.bits[..up.total_len as usize].to_vec(),
            };
            self.upload = None;
            self.map = Some(Rc::new(map));
        }
        Want::Exact(Response::Ack)
    }
}

/// The device's frame reader and receive task.
struct Model {
    reader: Box<RequestReader>,
    session: Session,
}

impl Model {
    /// Feed bytes as the device receives them; returns what every completed frame causes.
    fn feed(&mut self, bytes: &[u8]) -> Vec<Event> {
        let Model { reader, session } = self;
        let mut out = Vec::new();
        for &b in bytes {
            let Some(frame) = reader.push(b).into_frame(MAX_REQUEST_WIRE) else {
                continue;
            };
            match frame.and_then(decode_request) {
                Ok((id, req)) => {
                    session.frames_ok += 1;
                    out.push(session.handle(id, req));
                }
                Err(e) => {
                    session.frames_bad += 1;
                    out.push(Event::Rx {
                        id: e.id(),
                        want: Want::Exact(Response::Error(e.reply())),
                    });
                }
            }
        }
        out
    }
}

/// Replies the planner sends (everything else comes from the receive task).
fn from_planner(r: &Response) -> bool {
    use ErrorCode::*;
    match r {
        Response::Path(_) => true,
        Response::Error(e) => matches!(
            e.code,
            StartOutOfBounds
                | GoalOutOfBounds
                | StartBlocked
                | GoalBlocked
                | NoPath
                | Cancelled
                | NoAntArrived
                | PathTooLong
                | Internal
        ),
        _ => false,
    }
}

// ---- the device's replies -----------------------------------------------------------------------

use qemu::{read_replies, Incoming};

// ---- the soak -----------------------------------------------------------------------------------

fn encode(id: u32, r: &Request<'_>) -> Vec<u8> {
    let mut buf = [0u8; MAX_REQUEST_WIRE];
    let n = encode_request(id, r, &mut buf).expect("encode a request");
    buf[..n].to_vec()
}

/// Counters of the replies received, by kind.
#[derive(Default)]
struct Replies {
    hello: u64,
    ack: u64,
    path: u64,
    stats: u64,
    errors: BTreeMap<u8, u64>,
    /// Errors the planner sent, but `Cancelled`.
    plan_errors: u64,
}

impl Replies {
    fn total(&self) -> u64 {
        self.hello + self.ack + self.path + self.stats + self.errors.values().sum::<u64>()
    }

    fn error(&self, code: ErrorCode) -> u64 {
        self.errors.get(&code.code()).copied().unwrap_or(0)
    }
}

struct Soak {
    rng: Rng,
    out: TcpStream,
    rx: mpsc::Receiver<Incoming>,
    model: Model,
    info: DeviceInfo,
    plan_queue: usize,
    next_id: u32,
    next_seq: u64,
    /// Replies expected from the receive task, in order.
    pending: VecDeque<RxEntry>,
    /// Plans accepted (or maybe refused), in order.
    plans: VecDeque<Job>,
    /// The map being uploaded by the generator.
    upload_map: Option<Map>,
    /// Free cells of the model's active map (for the map at `free_of`).
    free: Vec<Point>,
    free_of: Option<Rc<Map>>,
    sent: BTreeMap<Kind, u64>,
    bytes_sent: u64,
    bursts: u64,
    burst_frames: u64,
    writes: u64,
    replies: Replies,
    last_uptime: u64,
    first_uptime: Option<u64>,
    last_stats: Option<(StatsReply, u64)>,
}

impl Soak {
    fn id(&mut self) -> u32 {
        let id = self.next_id;
        self.next_id += 1;
        id
    }

    fn frames_sent(&self) -> u64 {
        self.sent.values().sum()
    }

    /// Feed `bytes` (frames of `kind`, `count` of them) to the model and register what the
    /// device must answer; append them to `buf`.
    fn emit(&mut self, buf: &mut Vec<u8>, bytes: &[u8], kind: Kind, count: u64) {
        *self.sent.entry(kind).or_default() += count;
        buf.extend_from_slice(bytes);
        for ev in self.model.feed(bytes) {
            match ev {
                Event::Rx { id, want } => self.pending.push_back(RxEntry { id, want }),
                Event::Plan(mut job) => {
                    job.seq = self.next_seq;
                    self.next_seq += 1;
                    job.busy_ok = self.plans.len() >= self.plan_queue;
                    if job.busy_ok {
                        self.pending.push_back(RxEntry {
                            id: job.id,
                            want: Want::MaybeBusy { seq: job.seq },
                        });
                    }
                    self.plans.push_back(job);
                }
            }
        }
    }

    fn write(&mut self, bytes: &[u8]) {
        self.out.write_all(bytes).expect("write to the device");
        self.bytes_sent += bytes.len() as u64;
        self.writes += 1;
    }

    // ---- valid requests ----

    fn random_params(&mut self) -> Params {
        let r = &mut self.rng;
        let mut p = Params {
            algorithm: Algorithm::ALL[r.below(4)],
            ants: r.range(1, 6) as u16,
            iterations: r.range(1, 8) as u16,
            alpha: r.f32(0.0, 3.0),
            beta: r.f32(0.0, 5.0),
            rho: r.f32(0.01, 1.0),
            q: r.f32(0.1, 5.0),
            a: r.f32(0.01, 1.0),
            xi: r.f32(0.0, 3.0),
            tau0: 1.0,
            tau_min: 0.01,
            tau_max: 100.0,
            patience: r.range(0, 4) as u16,
            warm_patience: r.range(0, 3) as u16,
            refine_patience: r.range(0, 4) as u16,
            seed: r.next(),
            dead_end: if r.chance(0.2) {
                DeadEnd::Die
            } else {
                DeadEnd::Backtrack
            },
            smoothing: [
                SmoothingKind::None,
                SmoothingKind::Greedy,
                SmoothingKind::Shortest,
            ][r.below(3)],
            tighten: r.chance(0.5),
            prune: r.chance(0.5),
            refine: r.chance(0.5),
        };
        if r.chance(0.04) {
            // Now and then slower plans, so that the queue fills and Cancel and new maps catch
            // plans while they run.
            p.ants = r.range(10, 20) as u16;
            p.iterations = r.range(40, 120) as u16;
            p.patience = 0;
        }
        if r.chance(0.1) {
            // One parameter out of range: `BadParam`, and the old parameters stay.
            match r.below(9) {
                0 => p.ants = 0,
                1 => p.iterations = 0,
                2 => p.alpha = 17.0,
                3 => p.beta = f32::NAN,
                4 => p.rho = 0.0,
                5 => p.q = -1.0,
                6 => p.a = 1.5,
                7 => p.xi = f32::INFINITY,
                _ => p.tau_min = 2.0,
            }
        }
        p
    }

    fn random_map(&mut self) -> Map {
        let r = &mut self.rng;
        let (width, height) = if r.chance(0.01) {
            // Now and then a long corridor: wider than the 256-cell maps of protocol v5, legal
            // since v6 (capacity by cells, any shape).
            (r.range(257, 1024), r.range(1, 16))
        } else if r.chance(0.1) {
            let w = r.range(1, 32);
            (w, r.range(1, 1024 / w).min(64))
        } else {
            (r.range(2, 16), r.range(2, 16))
        };
        let density = r.unit() * 0.35;
        let cells = width * height;
        let mut bits = vec![0u8; cells.div_ceil(8)];
        for j in 0..bits.len() * 8 {
            // The unused bits of the last byte are random too: the device ignores them.
            let blocked = if j < cells {
                r.unit() < density
            } else {
                r.chance(0.5)
            };
            bits[j / 8] |= u8::from(blocked) << (j % 8);
        }
        Map {
            width: width as u16,
            height: height as u16,
            bits,
        }
    }

    /// One `SetMap`: the next chunk of the generator's upload, a new upload, or (5%) one the
    /// device refuses.
    fn set_map(&mut self, id: u32) -> Vec<u8> {
        if self.rng.chance(0.05) {
            let r = &mut self.rng;
            let chunk = r.bytes_in(1, 16);
            let req = |width, height, offset, total_len, chunk| Request::SetMap {
                width,
                height,
                offset,
                total_len,
                chunk,
            };
            return match r.below(7) {
                0 => {
                    // A side over the device's longest (4096 on every board).
                    let (w, h) = if r.chance(0.5) {
                        (r.range(4097, 6000) as u16, r.range(1, 10) as u16)
                    } else {
                        (r.range(1, 10) as u16, r.range(4097, 6000) as u16)
                    };
                    let t = (u32::from(w) * u32::from(h)).div_ceil(8);
                    encode(id, &req(w, h, 0, t, &chunk))
                }
                5 => {
                    // Sides that fit, cells that do not (any shape: 4096 x 65 > 262,144).
                    let (w, h) = (4096u16, r.range(65, 100) as u16);
                    let t = (u32::from(w) * u32::from(h)).div_ceil(8);
                    encode(id, &req(w, h, 0, t, &chunk))
                }
                6 => encode(id, &req(16, 16, 0, 32, &[])), // an empty chunk: TooLarge 0
                1 => encode(id, &req(10, 10, 0, 14, &chunk)),
                2 => encode(id, &req(0, 7, 0, 0, &chunk)),
                3 => encode(id, &req(16, 16, r.range(1, 40) as u32, 32, &chunk)),
                _ => {
                    let big = r.bytes_in(MAX_CHUNK + 1, 200);
                    encode(id, &req(16, 16, 0, 32, &big))
                }
            };
        }
        // Continue the generator's upload if the device has it open, else start a new one.
        let open = match (&self.model.session.upload, &self.upload_map) {
            (Some(up), Some(m)) if (up.width, up.height) == (m.width, m.height) => {
                Some(up.received as usize)
            }
            _ => None,
        };
        let (map, offset) = match open {
            Some(received) => {
                let map = self.upload_map.take().expect("the upload's map");
                // Now and then re-send some bytes already received (allowed).
                let back = if self.rng.chance(0.2) {
                    self.rng.range(0, received.min(8))
                } else {
                    0
                };
                (map, received - back)
            }
            None => (self.random_map(), 0),
        };
        let total = map.bits.len();
        let len = if offset == 0 && total <= MAX_CHUNK && self.rng.chance(0.6) {
            total
        } else {
            self.rng.range(1, (total - offset).min(MAX_CHUNK))
        };
        let bytes = encode(
            id,
            &Request::SetMap {
                width: map.width,
                height: map.height,
                offset: offset as u32,
                total_len: total as u32,
                chunk: &map.bits[offset..offset + len],
            },
        );
        self.upload_map = Some(map);
        bytes
    }

    fn random_cell(&mut self) -> Point {
        let map = self.model.session.map.clone().expect("a map");
        if self.free_of.as_ref().is_none_or(|m| !Rc::ptr_eq(m, &map)) {
            self.free = (0..map.height)
                .flat_map(|y| (0..map.width).map(move |x| Point::new(x, y)))
                .filter(|&p| !map.is_blocked(p))
                .collect();
            self.free_of = Some(map.clone());
        }
        let r = &mut self.rng;
        let roll = r.unit();
        if roll < 0.04 {
            // Outside the map.
            Point::new(
                map.width + r.below(3) as u16,
                r.below(usize::from(map.height)) as u16,
            )
        } else if roll < 0.12 || self.free.is_empty() {
            // Any cell, maybe an obstacle.
            Point::new(
                r.below(usize::from(map.width)) as u16,
                r.below(usize::from(map.height)) as u16,
            )
        } else {
            self.free[r.below(self.free.len())]
        }
    }

    fn plan(&mut self, id: u32) -> Vec<u8> {
        let (start, goal) = if self.model.session.map.is_some() {
            (self.random_cell(), self.random_cell())
        } else {
            (Point::new(0, 0), Point::new(1, 1)) // NoMap
        };
        let seed = self.rng.chance(0.7).then(|| self.rng.next());
        encode(id, &Request::Plan { start, goal, seed })
    }

    /// A valid request of `kind` with a new id.
    fn valid(&mut self, kind: Kind) -> Vec<u8> {
        let id = self.id();
        match kind {
            Kind::Hello => encode(id, &Request::Hello),
            Kind::Stats => encode(id, &Request::Stats),
            Kind::Cancel => encode(id, &Request::Cancel),
            Kind::SetParams => {
                let p = self.random_params();
                encode(id, &Request::SetParams(p))
            }
            Kind::SetMap => self.set_map(id),
            Kind::Plan => self.plan(id),
            other => unreachable!("{other:?} is not a request"),
        }
    }

    /// Any frame the device decodes as a request, for breaking (its id is used up).
    fn some_frame(&mut self) -> Vec<u8> {
        let id = self.id();
        match self.rng.below(4) {
            0 => encode(id, &Request::Stats),
            1 => {
                let p = self.random_params();
                encode(id, &Request::SetParams(p))
            }
            2 => {
                let chunk = self.rng.bytes_in(1, 40);
                encode(
                    id,
                    &Request::SetMap {
                        width: 16,
                        height: 16,
                        offset: 0,
                        total_len: 32,
                        chunk: &chunk,
                    },
                )
            }
            _ => {
                let (start, goal) = (Point::new(1, 2), Point::new(3, 4));
                encode(
                    id,
                    &Request::Plan {
                        start,
                        goal,
                        seed: Some(self.rng.next()),
                    },
                )
            }
        }
    }

    /// A broken frame of `kind`, ending with its delimiter, in which no frame decodes.
    fn broken(&mut self, kind: Kind) -> Vec<u8> {
        loop {
            let bytes = match kind {
                Kind::BitFlipped => {
                    let mut f = self.some_frame();
                    let body = f.len() - 1;
                    for _ in 0..self.rng.range(1, 3) {
                        let at = self.rng.below(body);
                        f[at] ^= 1 << self.rng.below(8);
                    }
                    f
                }
                Kind::Truncated => {
                    let f = self.some_frame();
                    // At least one byte short (the whole frame but its delimiter, completed by
                    // a `00`, would be valid).
                    let mut t = f[..self.rng.range(1, f.len() - 2)].to_vec();
                    t.push(0);
                    t
                }
                Kind::Oversized => {
                    // Mostly just over the limit: QEMU feeds the UART 10 to 16 KB/s, so bytes
                    // are what a soak spends its time on.
                    let n = if self.rng.chance(0.1) {
                        self.rng.range(300, 2000)
                    } else {
                        self.rng.range(MAX_REQUEST_WIRE + 1, 300)
                    };
                    let mut f = self.rng.nonzero_bytes(n);
                    if self.rng.chance(0.5) {
                        // A valid frame's start, then too much.
                        let v = self.some_frame();
                        f[..v.len() - 1].copy_from_slice(&v[..v.len() - 1]);
                    }
                    f.push(0);
                    f
                }
                Kind::Garbage => {
                    let mut f = self.rng.bytes_in(1, 100);
                    f.push(0);
                    f
                }
                Kind::BadMessage => {
                    let id = self.id();
                    let mut body = Vec::new();
                    let mut v = id;
                    while v >= 0x80 {
                        body.push(v as u8 | 0x80);
                        v >>= 7;
                    }
                    body.push(v as u8);
                    match self.rng.below(3) {
                        // An unknown request variant.
                        0 => body.push(self.rng.range(6, 127) as u8),
                        // Hello or Cancel with trailing bytes.
                        1 => {
                            body.push(if self.rng.chance(0.5) { 0 } else { 4 });
                            let extra = self.rng.range(1, 5);
                            body.extend(self.rng.bytes(extra));
                        }
                        // SetParams with an unknown algorithm.
                        _ => {
                            body.push(2);
                            body.push(self.rng.range(4, 127) as u8);
                        }
                    }
                    frame_of(&body)
                }
                other => unreachable!("{other:?} is not a broken frame"),
            };
            // Checked alone: the stream is at a frame boundary before it, and it ends with a
            // delimiter. (A random frame that decodes is possible in principle: try again.)
            if try_expected_errors(&bytes).is_some() {
                return bytes;
            }
        }
    }

    /// A random unit: one frame, or a valid request sent twice.
    fn roll(&mut self) -> Unit {
        let kind = match self.rng.below(100) {
            0..=9 => Kind::Hello,
            10..=19 => Kind::Stats,
            20..=27 => Kind::SetParams,
            28..=41 => Kind::SetMap,
            42..=59 => Kind::Plan,
            60..=62 => Kind::Cancel,
            63..=67 => Kind::Duplicate,
            68..=74 => Kind::BitFlipped,
            75..=80 => Kind::Truncated,
            81..=83 => Kind::Oversized,
            84..=88 => Kind::Empty,
            89..=95 => Kind::Garbage,
            _ => Kind::BadMessage,
        };
        if kind != Kind::Duplicate {
            return Unit::Frame(kind);
        }
        Unit::Twice(match self.rng.below(20) {
            0..=5 => Kind::Plan,
            6 => Kind::Cancel,
            7..=9 => Kind::Hello,
            10..=12 => Kind::Stats,
            13..=15 => Kind::SetParams,
            _ => Kind::SetMap,
        })
    }

    /// Build `unit`'s bytes, feed them to the model and append them to `buf`.
    fn build(&mut self, buf: &mut Vec<u8>, unit: Unit) {
        match unit {
            Unit::Twice(of) => {
                let f = self.valid(of);
                self.emit(buf, &f, of, 1);
                self.emit(buf, &f, Kind::Duplicate, 1);
            }
            Unit::Frame(Kind::Empty) => {
                let n = self.rng.range(1, 3);
                self.emit(buf, &vec![0; n], Kind::Empty, n as u64);
            }
            Unit::Frame(k) if k.is_valid() => {
                let f = self.valid(k);
                self.emit(buf, &f, k, 1);
            }
            Unit::Frame(k) => {
                let f = self.broken(k);
                self.emit(buf, &f, k, 1);
            }
        }
    }

    /// Wait for replies until at most `n` plans are unanswered. (Waiting changes only when
    /// frames are written, never which: the stream depends on the seed alone.)
    fn wait_for_plans(&mut self, n: usize) {
        while self.plans.len() > n {
            self.pump(Some(TIMEOUT));
        }
    }

    // ---- replies ----

    /// Check every reply that has arrived; with `wait`, first wait (at most that long) for one.
    fn pump(&mut self, wait: Option<Duration>) {
        if let Some(t) = wait {
            match self.rx.recv_timeout(t) {
                Ok(r) => self.on_incoming(r),
                Err(e) => panic!(
                    "no reply within {t:?} ({e}); waiting for {:?} and plans {:?}",
                    self.pending.front(),
                    self.plans.iter().map(|j| j.id).collect::<Vec<_>>()
                ),
            }
        }
        while let Ok(r) = self.rx.try_recv() {
            self.on_incoming(r);
        }
    }

    fn on_incoming(&mut self, r: Incoming) {
        let (id, resp) = r.unwrap_or_else(|e| panic!("{e}"));
        let replies_before = self.replies.total();
        match &resp {
            Response::Hello(_) => self.replies.hello += 1,
            Response::Ack => self.replies.ack += 1,
            Response::Path(_) => self.replies.path += 1,
            Response::Stats(_) => self.replies.stats += 1,
            Response::Error(e) => *self.replies.errors.entry(e.code.code()).or_default() += 1,
            Response::Part(_) => panic!("reply {id}: a path part the reader did not put together"),
        }
        if from_planner(&resp) {
            self.on_plan_reply(id, resp);
            return;
        }
        loop {
            let Some(entry) = self.pending.pop_front() else {
                panic!("reply {id} {resp:?}: no reply from the receive task was expected");
            };
            if let Want::MaybeBusy { seq } = entry.want {
                let pos = self.plans.iter().position(|j| j.seq == seq);
                if entry.id == id
                    && resp
                        == Response::Error(ErrorReply::with(
                            ErrorCode::Busy,
                            self.plan_queue as u32,
                            self.plan_queue as u32,
                        ))
                {
                    let pos = pos.unwrap_or_else(|| panic!("plan {id} refused after its answer"));
                    self.plans.remove(pos);
                    return;
                }
                // A later reply of the receive task: this plan was accepted.
                if let Some(pos) = pos {
                    self.plans[pos].busy_ok = false;
                }
                continue;
            }
            assert_eq!(
                entry.id, id,
                "reply {resp:?} has id {id}, the receive task's next reply should be {entry:?}"
            );
            match entry.want {
                Want::Exact(want) => assert_eq!(resp, want, "reply {id}"),
                Want::Hello => assert_eq!(resp, Response::Hello(self.info.clone()), "Hello {id}"),
                Want::Stats {
                    frames_ok,
                    frames_bad,
                    map,
                } => {
                    let Response::Stats(s) = resp else {
                        panic!("Stats {id} answered with {resp:?}");
                    };
                    assert_eq!(s.boots, 1, "the device reset: {s:?}");
                    assert!(s.uptime >= self.last_uptime, "uptime went back: {s:?}");
                    assert_eq!(
                        (s.frames_ok, s.frames_bad),
                        (frames_ok, frames_bad),
                        "Stats {id}: frames ok / bad: {s:?}"
                    );
                    assert_eq!((s.map_width, s.map_height), map, "Stats {id}: map {s:?}");
                    assert_eq!(s.rx_overruns, 0, "Stats {id}: {s:?}");
                    self.last_uptime = s.uptime;
                    self.first_uptime.get_or_insert(s.uptime);
                    self.last_stats = Some((s, replies_before));
                }
                Want::MaybeBusy { .. } => unreachable!(),
            }
            return;
        }
    }

    /// A reply of the planner. Paths come in plan order, and so do its errors; but errors
    /// travel with the receive task's small replies (through the transmit queue) while paths
    /// are streamed by the planner itself, so a later plan's path may overtake an earlier
    /// plan's error (or `Busy`). Nothing else may overtake.
    fn on_plan_reply(&mut self, id: u32, resp: Response) {
        let Some(pos) = self.plans.iter().position(|j| j.id == id) else {
            panic!(
                "planner reply {id} {resp:?}: no such plan waiting (plans {:?})",
                self.plans.iter().map(|j| j.id).collect::<Vec<_>>()
            );
        };
        let is_path = matches!(resp, Response::Path(_));
        for j in self.plans.iter_mut().take(pos) {
            // Still unanswered: its answer (an error, or `Busy`) is behind in the queue.
            assert!(
                is_path,
                "plan {} unanswered when the planner's error for {id} came: {resp:?}",
                j.id
            );
            j.overtaken = true;
        }
        let job = self.plans.remove(pos).expect("the plan");
        assert!(
            !(is_path && job.overtaken),
            "plan {id}: a path after a later plan's path"
        );
        if job.busy_ok {
            // Accepted after all: it is no longer expected from the receive task.
            self.pending
                .retain(|e| !matches!(e.want, Want::MaybeBusy { seq } if seq == job.seq));
        }
        let what = format!(
            "plan {id} ({},{})->({},{}) on {}x{}",
            job.start.x, job.start.y, job.goal.x, job.goal.y, job.map.width, job.map.height
        );
        if resp == Response::Error(ErrorReply::new(ErrorCode::Cancelled)) {
            assert!(
                job.generation < self.model.session.generation,
                "{what}: cancelled, but no Cancel or new map came after it"
            );
            return;
        }
        let want = core_plan(&job.map, job.start, job.goal, &job.params);
        match (&want, &resp) {
            (Ok(core), Response::Path(dev)) => assert_core_path(&what, core, dev),
            (Err(e), Response::Error(got)) => {
                assert_eq!(got, e, "{what}");
                self.replies.plan_errors += 1;
            }
            _ => panic!("{what}: device {resp:?}, host core {want:?}"),
        }
    }
}

#[test]
fn soak_thousands_of_valid_and_broken_frames() {
    need_qemu!();
    let frames: u64 = std::env::var("OHACA_SOAK_FRAMES")
        .ok()
        .map(|v| v.parse().expect("OHACA_SOAK_FRAMES: a number"))
        .unwrap_or(DEFAULT_FRAMES as u64);
    let seed: u64 = std::env::var("OHACA_SOAK_SEED")
        .ok()
        .map(|v| v.parse().expect("OHACA_SOAK_SEED: a number"))
        .unwrap_or(DEFAULT_SEED);
    let mut q = Qemu::tcp();
    let stream = q.connect();
    stream
        .set_write_timeout(Some(TIMEOUT))
        .expect("write timeout");
    let (tx, rx) = mpsc::channel();
    let reader = {
        let s = stream.try_clone().expect("clone the socket");
        std::thread::spawn(move || read_replies(s, tx))
    };
    let t0 = Instant::now();

    // Flush (`00`), Hello: the device's limits, then the soak.
    let mut first = vec![0];
    first.extend(encode(1, &Request::Hello));
    let mut out = stream;
    out.write_all(&first).expect("write");
    let (id, hello) = rx
        .recv_timeout(TIMEOUT)
        .expect("a reply to Hello")
        .expect("a reply");
    let Response::Hello(info) = hello else {
        panic!("Hello answered with {hello:?}");
    };
    assert_eq!(id, 1);
    let cap = info.capacity;
    let mut soak = Soak {
        rng: Rng(seed),
        out,
        rx,
        model: Model {
            reader: Box::new(RequestReader::new()),
            session: Session {
                max_cells: cap.cells,
                max_side: cap.max_side,
                frames_ok: 0,
                frames_bad: 0,
                params: info.defaults,
                upload: None,
                map: None,
                generation: 0,
            },
        },
        info: info.clone(),
        plan_queue: usize::from(cap.plan_queue),
        next_id: 2,
        next_seq: 0,
        pending: VecDeque::new(),
        plans: VecDeque::new(),
        upload_map: None,
        free: Vec::new(),
        free_of: None,
        sent: BTreeMap::new(),
        bytes_sent: first.len() as u64,
        bursts: 0,
        burst_frames: 0,
        writes: 1,
        replies: Replies {
            hello: 1,
            ..Replies::default()
        },
        last_uptime: 0,
        first_uptime: None,
        last_stats: None,
    };
    // The model saw the same: an empty frame, then Hello (answered above).
    let mut scratch = Vec::new();
    soak.emit(&mut scratch, &first, Kind::Hello, 1);
    *soak.sent.entry(Kind::Empty).or_default() += 1;
    soak.pending.clear();
    // Cheap parameters before the first plan (the defaults take 50 ants x 100 iterations).
    let mut buf = Vec::new();
    let cheap = Params {
        ants: 4,
        iterations: 6,
        ..Params::default()
    };
    let f = encode(soak.id(), &Request::SetParams(cheap));
    soak.emit(&mut buf, &f, Kind::SetParams, 1);
    soak.write(&buf);

    let queue = soak.plan_queue;
    while soak.frames_sent() < frames {
        soak.pump(None);
        let mut buf = Vec::new();
        if soak.rng.chance(0.12) {
            // A burst: many frames in one write. Normal bursts hold at most `plan_queue` plans
            // and are written once the device has room for them (so none is refused); one in
            // four overfills the plan queue on purpose.
            let overfill = soak.rng.chance(0.25) && soak.model.session.map.is_some();
            let n = soak.rng.range(8, 64);
            let mut units: Vec<Unit> = (0..n).map(|_| soak.roll()).collect();
            let cap = if overfill { 0 } else { queue };
            let mut plans = 0;
            for u in &mut units {
                if plans + u.plans() > cap {
                    *u = Unit::Frame(Kind::Stats);
                } else {
                    plans += u.plans();
                }
            }
            soak.wait_for_plans(cap - plans);
            let before = soak.frames_sent();
            if overfill {
                // Slow plans back to back, more than the queue holds: the last ones are refused
                // with Busy (unless the first ones fail at once, on an obstacle, say); a Cancel
                // at the end of the burst stops the others.
                let slow = Params {
                    ants: 20,
                    iterations: 60_000,
                    patience: 0,
                    refine_patience: 0,
                    ..Params::default()
                };
                let f = encode(soak.id(), &Request::SetParams(slow));
                soak.emit(&mut buf, &f, Kind::SetParams, 1);
                for _ in 0..queue + 3 {
                    let f = soak.valid(Kind::Plan);
                    soak.emit(&mut buf, &f, Kind::Plan, 1);
                }
                let f = soak.valid(Kind::SetParams);
                soak.emit(&mut buf, &f, Kind::SetParams, 1);
            }
            for u in units {
                soak.build(&mut buf, u);
            }
            if overfill {
                let f = soak.valid(Kind::Cancel);
                soak.emit(&mut buf, &f, Kind::Cancel, 1);
            }
            soak.bursts += 1;
            soak.burst_frames += soak.frames_sent() - before;
            soak.write(&buf);
        } else {
            let u = soak.roll();
            soak.wait_for_plans(queue - u.plans());
            soak.build(&mut buf, u);
            if buf.len() > 2 && soak.rng.chance(0.05) {
                // A frame in two writes.
                let at = soak.rng.range(1, buf.len() - 1);
                soak.write(&buf[..at]);
                soak.write(&buf[at..]);
            } else {
                soak.write(&buf);
            }
        }
    }

    // A Stats as a fence (after its reply every Busy is known), then the last plans.
    let mut buf = Vec::new();
    let f = soak.valid(Kind::Stats);
    soak.emit(&mut buf, &f, Kind::Stats, 1);
    soak.write(&buf);
    while !soak.pending.is_empty() || !soak.plans.is_empty() {
        soak.pump(Some(TIMEOUT));
    }
    // Everything is answered: the final counters are exact.
    let mut buf = Vec::new();
    let f = soak.valid(Kind::Stats);
    soak.emit(&mut buf, &f, Kind::Stats, 1);
    soak.write(&buf);
    while !soak.pending.is_empty() {
        soak.pump(Some(TIMEOUT));
    }
    let wall = t0.elapsed();
    let (st, replies_before) = soak.last_stats.expect("the final Stats");
    let r = &soak.replies;
    let valid: u64 = soak
        .sent
        .iter()
        .filter(|(k, _)| k.is_valid())
        .map(|(_, n)| n)
        .sum();
    let session = &soak.model.session;
    assert_eq!(
        u64::from(st.frames_ok),
        valid,
        "frames_ok = the valid frames sent: {st:?}"
    );
    assert_eq!(st.frames_ok, session.frames_ok, "{st:?}");
    assert_eq!(st.frames_bad, session.frames_bad, "{st:?}");
    assert_eq!(
        u64::from(st.rx_bytes),
        soak.bytes_sent,
        "every byte read: {st:?}"
    );
    assert_eq!(
        u64::from(st.tx_frames),
        replies_before,
        "every reply sent: {st:?}"
    );
    assert_eq!(u64::from(st.plans), r.path, "{st:?}");
    assert_eq!(u64::from(st.plan_errors), r.plan_errors, "{st:?}");
    assert_eq!(
        u64::from(st.cancelled),
        r.error(ErrorCode::Cancelled),
        "{st:?}"
    );
    assert_eq!(u64::from(st.busy), r.error(ErrorCode::Busy), "{st:?}");
    assert_eq!((st.queued, st.planning), (0, false), "{st:?}");
    assert_eq!((st.boots, st.rx_overruns), (1, 0), "{st:?}");
    assert!(
        st.uptime > soak.first_uptime.expect("a Stats"),
        "uptime did not grow: {st:?}"
    );
    assert!(q.is_running(), "QEMU exited");

    let sent: Vec<String> = soak
        .sent
        .iter()
        .map(|(k, n)| format!("{k:?} {n}"))
        .collect();
    let errors: Vec<String> = r
        .errors
        .iter()
        .map(|(c, n)| {
            let name = ErrorCode::from_code(*c).map_or("?".into(), |c| format!("{c:?}"));
            format!("{name} {n}")
        })
        .collect();
    println!(
        "soak: {} frames ({} valid, {} bad or empty; {} bursts of {} frames; {} writes, {} bytes) \
         in {:.1} s, seed {seed}; sent: {}; replies {}: Hello {}, Ack {}, Path {}, Stats {}, \
         Error {} ({}); device: frames_ok {}, frames_bad {}, rx_overruns {}, rx_bytes {}, \
         tx_frames {}, plans {}, plan_errors {}, cancelled {}, busy {}, boots {}, uptime {:.1} s, \
         stack_peak {} B",
        soak.frames_sent(),
        valid,
        soak.frames_sent() - valid,
        soak.bursts,
        soak.burst_frames,
        soak.writes,
        soak.bytes_sent,
        wall.as_secs_f64(),
        sent.join(", "),
        r.total(),
        r.hello,
        r.ack,
        r.path,
        r.stats,
        r.errors.values().sum::<u64>(),
        errors.join(", "),
        st.frames_ok,
        st.frames_bad,
        st.rx_overruns,
        st.rx_bytes,
        st.tx_frames,
        st.plans,
        st.plan_errors,
        st.cancelled,
        st.busy,
        st.boots,
        st.uptime as f64 / f64::from(cap.tick_hz),
        st.stack_peak,
    );
    let _ = soak.out.shutdown(Shutdown::Both);
    drop(soak);
    let _ = reader.join();
}
