//! Soak test of the firmware's link under QEMU: thousands of frames, valid and broken, many in
//! bursts, every reply checked, as a client that keeps within the device's window (protocol 10),
//! so that nothing is lost; then one burst beyond it, whose losses must be counted.
//!
//! One QEMU, one connection: UART0 on TCP (`nodelay=on`, QEMU's instant UART), or, with
//! `OHACA_SOAK_BAUD=BAUD`, behind the pacing relay (`ohaca_host::link::relay`: a real 8N1 line at
//! `BAUD`; `soak_over_the_relay` runs a short soak so at 115,200 baud in every test run). A seeded
//! generator writes `OHACA_SOAK_FRAMES` frames (default [`DEFAULT_FRAMES`]; seed
//! `OHACA_SOAK_SEED`, default [`DEFAULT_SEED`]): valid requests — `Hello`, `Stats`, `SetParams`
//! (cheap: at most 6 ants and 8 iterations; some out of range), `SetMap` (maps up to 16x16, now
//! and then up to 32x32 or a corridor up to 1024 cells long, in one or more chunks, some chunks
//! re-sent, some uploads refused: a side over 4096, more cells than the device holds, an empty
//! chunk, a bad header or chunk), `Plan` (free, blocked and out-of-bounds cells, with and without
//! a seed), `Cancel`, `SetRect` and `SetCells` (blocking and clearing; some outside the map, some
//! lists too long, some without a map) — mixed with duplicated requests (the same frame twice,
//! same id), bit-flipped, truncated, oversized, empty (a lone `00`) and random-garbage frames,
//! and frames with a good CRC around a message that does not decode. About one write in eight
//! starts a burst of 8 to 64 such frames; one burst in four starts with one write of a whole
//! window: slow parameters, `plan_queue + 2` slow plans (more than the queue holds beside the
//! running one: `Busy`) and a `Cancel`. Long replies: after a fifth of the frames, and then every
//! [`MAZE_EVERY`], a maze episode uploads `maps/large/maze-128-128-2.map` (16 chunks, broken
//! frames between them, chunks re-sent), plans its longest scenario (1,380 cells: a path in
//! parts), blocks a cell of that path (`SetCells`), plans again, clears a box around it
//! (`SetRect`) and plans again. The frames depend on the seed alone (replies only decide when
//! they are written), so a failure replays with the same frames.
//!
//! **The window.** The device promises nothing lost while a host has at most `capacity.window`
//! requests and `capacity.window_bytes` bytes of request frames outstanding (sent and not
//! answered in full: docs/PROTOCOL.md, "Bursts and the window"). Every frame that gets a reply
//! counts, broken ones included (each gets an `Error`); an empty frame gets none, so its bytes
//! count with the next frame that does. A burst is cut into writes of as many frames as the
//! window leaves room for (count and bytes): before a frame that does not fit, the soak writes
//! what it has and reads replies until it does. Oversized frames are at most `window_bytes - 64`
//! bytes long.
//!
//! What the device must answer is computed on the host by a model of its receive task
//! (`src/firmware/rx.rs`) fed the exact byte stream, split into frames by the protocol's own
//! `RequestReader` and decoded by its own `decode_request` (cell updates applied with the
//! protocol's own `set_rect` / `set_cells`): every bad frame gets its error reply (nothing for an
//! empty frame) and no valid request after it is lost; every valid request gets exactly one
//! reply (a duplicated frame is a valid request received twice: two replies with its id). The
//! assertions, with the reply order of docs/PROTOCOL.md ("Behaviour under stress"):
//!
//! * replies of the receive task (everything but accepted plans) come in request order, with
//!   exactly the expected content (`Hello` as at the start; `Stats` — which carries the counters
//!   of the moment it is sent, protocol 10 — with `frames_ok` and `frames_bad` between the
//!   model's when the request was handled and when the reply is read, a map the device had in
//!   between, `boots` 1, `uptime` never going back, `rx_overruns` and `replies_dropped` as at the
//!   start: nothing lost within the window);
//! * plans are answered in plan order, paths and errors each (a later plan's path may overtake
//!   an earlier plan's error, which travels in the transmit queue; nothing else overtakes), each
//!   path (long ones put together from their parts) bit-identical to the host core's on the map
//!   and parameters in force when the plan was sent, each error the core's; `Cancelled` only for
//!   a plan followed by a `Cancel`, a new map or an accepted cell update; `Busy` only for a plan
//!   sent while `plan_queue` plans were unanswered (the generator waits for room before writing
//!   plans, but in the overfilling writes);
//! * at the end (everything answered), one `Stats` whose counters are exact (relative to the
//!   device's at the start: over the relay it was booted with a few `Hello`s): `frames_ok` = the
//!   valid frames sent, `frames_bad` = the bad frames the device saw, `rx_bytes` = every byte
//!   written, `tx_frames` = every reply frame received (a path in parts counts its parts),
//!   `parted` = the paths begun in parts (at least one a maze episode),
//!   `plans` / `plan_errors` / `cancelled` / `busy` as received, `queued` 0, `rx_overruns` and
//!   `replies_dropped` unchanged, `boots` 1, `uptime` grown; QEMU still runs (the firmware leaves
//!   QEMU on a panic or a hard fault); over the relay, no byte lost on the line either;
//! * then, beyond the window: [`BEYOND`] `Stats` in one write (1,120 bytes, 160 requests). The
//!   device keeps serving (a `Hello` and a `Stats` after are answered), and the counters add up,
//!   exactly: every frame the device saw was answered or its reply counted (`replies_dropped`),
//!   every reply it sent arrived, every byte written was read (`rx_bytes`) or counted as lost by
//!   the device (`rx_overruns`) or the relay; something was counted as lost unless every `Stats`
//!   was answered. How much is lost, and where, timing decides: printed, not asserted.
//!
//! A summary line is printed (`--nocapture`), with the relay's counters over the relay.
//! `scripts/soak.sh [--baud BAUD] [FRAMES]` runs the long version (100 000 frames by default).
//!
//! Default size: the time goes with the bytes sent and the round trips the window costs. On the
//! loaded 2-core development machine (BENCHMARKS.md section 8) 10 000 frames took 31 s over TCP
//! and 61 s through the relay at 115 200 baud (27 s of line toward the device, 21 s back), and
//! `soak_over_the_relay`'s 1 000 frames at 921 600 took 6 to 9 s (it now runs at 115 200): so the default is the full
//! 10 000 over TCP, and 1 000 through the relay.

use crate::qemu;

use std::collections::{BTreeMap, VecDeque};
use std::io::Write;
use std::rc::Rc;
use std::sync::atomic::Ordering;
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

use ohaca::protocol::{
    decode_request, encode_request, set_cells, set_rect, ErrorCode, ErrorReply, Request,
    RequestReader, StatsReply, Waypoints, MAX_CHUNK, MAX_REQUEST_WIRE, MAX_UPDATE_CELLS,
};
use ohaca::{Algorithm, DeadEnd, Params, Point, SmoothingKind};
use ohaca_host::link::relay::{Counters, Snapshot};
use ohaca_host::link::{DeviceInfo, Response};
use ohaca_host::Map;
use qemu::{
    assert_core_path, boot_paced, core_plan, frame_of, have_qemu, longest_scenario, maps,
    try_expected_errors, Qemu, TIMEOUT,
};

/// Frames sent unless `OHACA_SOAK_FRAMES` says otherwise.
const DEFAULT_FRAMES: usize = 10_000;
/// The generator's seed unless `OHACA_SOAK_SEED` says otherwise.
const DEFAULT_SEED: u64 = 0x0ACA_50AC;
/// Frames [`soak_over_the_relay`] sends unless `OHACA_SOAK_RELAY_FRAMES` says otherwise.
const RELAY_FRAMES: usize = 1_000;
/// The line [`soak_over_the_relay`] runs at unless `OHACA_SOAK_RELAY_BAUD` says otherwise: the
/// boards' usual 115,200. The relay's room toward QEMU is a socket send buffer, which the kernel
/// caps at `net.core.wmem_max` (208 KiB by default, 550 bytes of it usable here): about 48 ms of
/// this line, where at 921,600 it would be 6 ms, shorter than a loaded CI host may pause QEMU.
const RELAY_BAUD: u32 = 115_200;
/// The maze of the long path plans, and its scenarios (the longest: a path in parts).
const MAZE: &str = "large/maze-128-128-2.map";
const MAZE_SCEN: &str = "large/maze-128-128-2-random-1.scen";
/// Frames between two maze episodes (the first comes after a fifth of the frames).
const MAZE_EVERY: u64 = 4_000;
/// Stats frames of the burst beyond the window at the end (1,120 bytes: over 1 KiB and over 8
/// requests).
const BEYOND: u32 = 160;

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
    SetRect,
    SetCells,
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
    /// A `Stats`. It carries the counters of the moment it is sent (protocol 10), so at least
    /// these (as the receive task counted them when it handled it) and at most the model's when
    /// the reply is read; its map one the device had from then on (`maps[map..]`).
    Stats {
        frames_ok: u32,
        frames_bad: u32,
        map: usize,
    },
    /// A plan that may be refused with `Busy` (sent while `plan_queue` plans were unanswered);
    /// if it is not, the planner answers it.
    MaybeBusy { seq: u64 },
}

#[derive(Debug)]
struct RxEntry {
    id: u32,
    want: Want,
    /// Bytes of its frame on the wire (with the empty frames just before it): what it holds
    /// of the window until answered (0 for a `MaybeBusy`, whose [`Job`] holds them).
    bytes: usize,
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
    /// Bytes of its frame on the wire: what it holds of the window until answered.
    bytes: usize,
}

/// What the model says one frame causes.
enum Event {
    Rx { id: u32, want: Want, bytes: usize },
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
    /// Bumped by `Cancel`, by every map upload's first chunk and by every accepted cell update.
    generation: u32,
    /// The map's size after every change (0 x 0: none), oldest first.
    maps: Vec<(u16, u16)>,
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
                map: self.maps.len() - 1,
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
                        bytes: 0,
                    })
                }
            },
            Request::Cancel => {
                self.generation += 1;
                Want::Exact(Response::Ack)
            }
            Request::SetRect {
                x,
                y,
                width,
                height,
                blocked,
            } => self.update(|size, bits| set_rect(size, bits, (x, y, width, height), blocked)),
            Request::SetCells { blocked, cells } => {
                self.update(|size, bits| set_cells(size, bits, &cells, blocked))
            }
            other => panic!("the soak does not send {other:?}"),
        };
        Event::Rx { id, want, bytes: 0 }
    }

    /// A cell update (`SetRect`, `SetCells`: the protocol's own `set_rect` / `set_cells`, as
    /// `src/firmware/rx.rs`): `NoMap` without a map (none yet, or an upload open); a refused one
    /// changes and cancels nothing; an accepted one cancels the plans and changes the map.
    fn update(
        &mut self,
        apply: impl FnOnce((u16, u16), &mut [u8]) -> Result<(), ErrorReply>,
    ) -> Want {
        let Some(map) = &self.map else {
            return error(ErrorCode::NoMap, 0, 0);
        };
        let mut m = Map::clone(map);
        match apply((m.width, m.height), &mut m.bits) {
            Ok(()) => {
                self.generation += 1;
                self.map = Some(Rc::new(m));
                Want::Exact(Response::Ack)
            }
            Err(e) => Want::Exact(Response::Error(e)),
        }
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
            self.maps.push((0, 0));
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
            self.maps.push((map.width, map.height));
            self.map = Some(Rc::new(map));
        }
        Want::Exact(Response::Ack)
    }
}

/// The device's frame reader and receive task.
struct Model {
    reader: Box<RequestReader>,
    session: Session,
    /// Bytes fed since the last frame that calls for a reply (empty frames, a frame not ended
    /// yet): they go with the next such frame in the window.
    loose: usize,
}

impl Model {
    /// Feed bytes as the device receives them; returns what every completed frame causes, each
    /// with its bytes (and the empty frames' before it).
    fn feed(&mut self, bytes: &[u8]) -> Vec<Event> {
        let Model {
            reader,
            session,
            loose,
        } = self;
        let mut out = Vec::new();
        for &b in bytes {
            *loose += 1;
            let Some(frame) = reader.push(b).into_frame(MAX_REQUEST_WIRE) else {
                continue;
            };
            let n = std::mem::take(loose);
            match frame.and_then(decode_request) {
                Ok((id, req)) => {
                    session.frames_ok += 1;
                    out.push(match session.handle(id, req) {
                        Event::Rx { id, want, .. } => Event::Rx { id, want, bytes: n },
                        Event::Plan(job) => Event::Plan(Job { bytes: n, ..job }),
                    });
                }
                Err(e) => {
                    session.frames_bad += 1;
                    out.push(Event::Rx {
                        id: e.id(),
                        want: Want::Exact(Response::Error(e.reply())),
                        bytes: n,
                    });
                }
            }
        }
        out
    }
}

/// What `bytes` (whole frames, from a frame boundary) hold of the window: the frames that call
/// for a reply (every non-empty one), and the bytes.
fn cost(bytes: &[u8]) -> (usize, usize) {
    let frames = bytes.split(|&b| b == 0).filter(|f| !f.is_empty()).count();
    (frames, bytes.len())
}

/// One unit's frames as the generator sends them: bytes, kind, frames of that kind.
type Pieces = Vec<(Vec<u8>, Kind, u64)>;

/// Counters the soak checks relative to (the device's at the soak's start).
#[derive(Clone, Copy, Default)]
struct Base {
    frames_ok: u32,
    frames_bad: u32,
    rx_bytes: u32,
    tx_frames: u32,
    plans: u32,
    plan_errors: u32,
    cancelled: u32,
    busy: u32,
    rx_overruns: u32,
    replies_dropped: u32,
    parted: u32,
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

use qemu::{read_replies_counting, Incoming, PartCounts};

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
    out: Box<dyn Write>,
    rx: mpsc::Receiver<Incoming>,
    /// Reply frames that were parts of long paths, counted by the reader.
    parts: Arc<PartCounts>,
    model: Model,
    info: DeviceInfo,
    plan_queue: usize,
    /// The device's window: requests, and bytes of request frames, outstanding.
    window: usize,
    window_bytes: usize,
    /// The device's counters at the start.
    base: Base,
    /// The maze and its longest scenario; maze episodes run, and when the next one is due.
    maze: Rc<Map>,
    maze_route: (Point, Point),
    mazes: u64,
    next_maze: u64,
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
                Event::Rx { id, want, bytes } => {
                    self.pending.push_back(RxEntry { id, want, bytes })
                }
                Event::Plan(mut job) => {
                    job.seq = self.next_seq;
                    self.next_seq += 1;
                    job.busy_ok = self.plans.len() >= self.plan_queue;
                    if job.busy_ok {
                        self.pending.push_back(RxEntry {
                            id: job.id,
                            want: Want::MaybeBusy { seq: job.seq },
                            bytes: 0,
                        });
                    }
                    self.plans.push_back(job);
                }
            }
        }
    }

    /// What is outstanding (emitted, not answered in full): requests, and their bytes with the
    /// empty frames' not yet followed by a request.
    fn outstanding(&self) -> (usize, usize) {
        let rx = self
            .pending
            .iter()
            .filter(|e| !matches!(e.want, Want::MaybeBusy { .. }));
        let requests = rx.clone().count() + self.plans.len();
        let bytes = rx.map(|e| e.bytes).sum::<usize>()
            + self.plans.iter().map(|j| j.bytes).sum::<usize>()
            + self.model.loose;
        (requests, bytes)
    }

    fn fits(&self, (requests, bytes): (usize, usize)) -> bool {
        let (r, b) = self.outstanding();
        r + requests <= self.window && b + bytes <= self.window_bytes
    }

    /// Append one unit's `pieces` to `buf` (fed to the model in order), within the device's
    /// window: if they do not fit beside what is outstanding (`buf` included), write `buf` first
    /// and wait for replies until they do. So a burst is cut into writes of at most what the
    /// window leaves room for. (Waiting changes when frames are written, never which.)
    fn put(&mut self, buf: &mut Vec<u8>, pieces: &[(Vec<u8>, Kind, u64)]) {
        let bytes: Vec<u8> = pieces.iter().flat_map(|p| p.0.iter().copied()).collect();
        let need = cost(&bytes);
        assert!(
            need.0 <= self.window && need.1 + self.model.loose <= self.window_bytes,
            "a unit beyond the window: {need:?}"
        );
        if !self.fits(need) {
            if !buf.is_empty() {
                self.write(buf);
                buf.clear();
            }
            // Nothing outstanding but empty frames' bytes: nothing to wait for (the unit
            // fits with them, asserted above).
            while !self.fits(need) && self.outstanding().0 > 0 {
                self.pump(Some(TIMEOUT));
            }
        }
        for (b, k, n) in pieces {
            self.emit(buf, b, *k, *n);
        }
    }

    fn write(&mut self, bytes: &[u8]) {
        let (requests, outstanding) = self.outstanding();
        assert!(
            requests <= self.window && outstanding <= self.window_bytes,
            "beyond the window: {requests} requests, {outstanding} bytes"
        );
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

    /// The model's map's size (16 x 16 without one: the update gets `NoMap`).
    fn map_size(&self) -> (usize, usize) {
        self.model
            .session
            .map
            .as_ref()
            .map_or((16, 16), |m| (usize::from(m.width), usize::from(m.height)))
    }

    /// A cell of the map, or (`outside` of the time) just beyond its right or bottom edge.
    fn update_cell(&mut self, outside: f64) -> Point {
        let (w, h) = self.map_size();
        let r = &mut self.rng;
        let (x, y) = (r.below(w), r.below(h));
        match (r.chance(outside), r.chance(0.5)) {
            (true, true) => Point::new((w + r.below(3)) as u16, y as u16),
            (true, false) => Point::new(x as u16, (h + r.below(3)) as u16),
            _ => Point::new(x as u16, y as u16),
        }
    }

    /// A `SetRect` of up to 4 x 4 cells (a zero side now and then), blocking or clearing; its
    /// origin or far corner outside the map now and then (`OutsideMap`).
    fn set_rect(&mut self, id: u32) -> Vec<u8> {
        let p = self.update_cell(0.05);
        let r = &mut self.rng;
        let (width, height) = (r.range(0, 4) as u16, r.range(0, 4) as u16);
        let blocked = r.chance(0.6);
        encode(
            id,
            &Request::SetRect {
                x: p.x,
                y: p.y,
                width,
                height,
                blocked,
            },
        )
    }

    /// A `SetCells` of up to 8 cells (none now and then), blocking or clearing; a cell outside
    /// the map now and then (`OutsideMap`), and now and then one cell too many (`TooLarge`).
    fn set_cells(&mut self, id: u32) -> Vec<u8> {
        let n = if self.rng.chance(0.03) {
            MAX_UPDATE_CELLS + 1
        } else {
            self.rng.range(0, 8)
        };
        let cells: Vec<Point> = (0..n).map(|_| self.update_cell(0.02)).collect();
        let blocked = self.rng.chance(0.6);
        encode(
            id,
            &Request::SetCells {
                blocked,
                cells: Waypoints::Points(&cells),
            },
        )
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
            Kind::SetRect => self.set_rect(id),
            Kind::SetCells => self.set_cells(id),
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
                    // At most the window's bytes (less the empty frames' that may precede it).
                    let n = if self.rng.chance(0.1) {
                        self.rng.range(300, self.window_bytes - 64)
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
            // delimiter. (A random frame that decodes is possible in principle, and garbage
            // with more frames than the window holds: try again.)
            if try_expected_errors(&bytes).is_some_and(|e| e.len() <= self.window) {
                return bytes;
            }
        }
    }

    /// A random unit: one frame, or a valid request sent twice.
    fn roll(&mut self) -> Unit {
        let kind = match self.rng.below(100) {
            0..=8 => Kind::Hello,
            9..=17 => Kind::Stats,
            18..=25 => Kind::SetParams,
            26..=39 => Kind::SetMap,
            40..=56 => Kind::Plan,
            57..=59 => Kind::Cancel,
            60..=61 => Kind::SetRect,
            62..=63 => Kind::SetCells,
            64..=67 => Kind::Duplicate,
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

    /// `unit`'s frames.
    fn pieces(&mut self, unit: Unit) -> Pieces {
        match unit {
            Unit::Twice(of) => {
                let f = self.valid(of);
                vec![(f.clone(), of, 1), (f, Kind::Duplicate, 1)]
            }
            Unit::Frame(Kind::Empty) => {
                let n = self.rng.range(1, 3);
                vec![(vec![0; n], Kind::Empty, n as u64)]
            }
            Unit::Frame(k) if k.is_valid() => vec![(self.valid(k), k, 1)],
            Unit::Frame(k) => vec![(self.broken(k), k, 1)],
        }
    }

    /// Build `unit`'s bytes, feed them to the model and append them to `buf`, within the
    /// window ([`Soak::put`]).
    fn build(&mut self, buf: &mut Vec<u8>, unit: Unit) {
        let p = self.pieces(unit);
        self.put(buf, &p);
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
                    let now = &self.model.session;
                    assert!(
                        (frames_ok..=now.frames_ok).contains(&s.frames_ok)
                            && (frames_bad..=now.frames_bad).contains(&s.frames_bad),
                        "Stats {id}: frames ok / bad {} / {}, from {frames_ok} / {frames_bad} to \
                         {} / {}: {s:?}",
                        s.frames_ok,
                        s.frames_bad,
                        now.frames_ok,
                        now.frames_bad
                    );
                    assert!(
                        now.maps[map..].contains(&(s.map_width, s.map_height)),
                        "Stats {id}: map {} x {}, not one of {:?}: {s:?}",
                        s.map_width,
                        s.map_height,
                        &now.maps[map..]
                    );
                    // Within the window nothing is lost.
                    assert_eq!(
                        (s.rx_overruns, s.replies_dropped),
                        (self.base.rx_overruns, self.base.replies_dropped),
                        "Stats {id}: lost within the window: {s:?}"
                    );
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

impl Soak {
    /// Write `buf` (if anything is in it) and empty it.
    fn flush(&mut self, buf: &mut Vec<u8>) {
        if !buf.is_empty() {
            self.write(buf);
            buf.clear();
        }
    }

    /// One valid request, within the window.
    fn put_request(&mut self, buf: &mut Vec<u8>, kind: Kind, req: &Request<'_>) {
        let f = encode(self.id(), req);
        self.put(buf, &[(f, kind, 1)]);
    }

    /// A plan, once the plan queue has room for it (never `Busy`).
    fn put_plan(&mut self, buf: &mut Vec<u8>, start: Point, goal: Point, seed: u64) {
        self.flush(buf);
        self.wait_for_plans(self.plan_queue - 1);
        let req = Request::Plan {
            start,
            goal,
            seed: Some(seed),
        };
        self.put_request(buf, Kind::Plan, &req);
    }

    /// A broken frame now and then (`p`), of any kind, within the window.
    fn maybe_broken(&mut self, buf: &mut Vec<u8>, p: f64) {
        if self.rng.chance(p) {
            let kind = [
                Kind::BitFlipped,
                Kind::Truncated,
                Kind::Garbage,
                Kind::BadMessage,
                Kind::Empty,
            ][self.rng.below(5)];
            self.build(buf, Unit::Frame(kind));
        }
    }

    /// Long replies: upload `maps/large/maze-128-128-2.map` (2,048 bytes in 16 chunks, broken
    /// frames between them, chunks re-sent), plan its longest scenario with the device's default
    /// parameters (1,380 cells: a path in parts), block a cell of that path (`SetCells`) and plan
    /// again, clear a box around it (`SetRect`) and plan again, with refused updates (outside the
    /// map) between. Every frame within the window; every reply checked as the others.
    fn maze_episode(&mut self) {
        self.mazes += 1;
        let mut buf = Vec::new();
        let maze = self.maze.clone();
        let (start, goal) = self.maze_route;
        let params = Params {
            seed: 1,
            ..self.info.defaults
        };
        self.put_request(&mut buf, Kind::SetParams, &Request::SetParams(params));
        let total = maze.bits.len();
        for (k, chunk) in maze.bits.chunks(MAX_CHUNK).enumerate() {
            self.maybe_broken(&mut buf, 0.3);
            let f = encode(
                self.id(),
                &Request::SetMap {
                    width: maze.width,
                    height: maze.height,
                    offset: (k * MAX_CHUNK) as u32,
                    total_len: total as u32,
                    chunk,
                },
            );
            let mut pieces = vec![(f.clone(), Kind::SetMap, 1)];
            if self.rng.chance(0.15) {
                // Re-sent (allowed; the last chunk's copy finds no upload open: BadChunk).
                pieces.push((f, Kind::Duplicate, 1));
            }
            self.put(&mut buf, &pieces);
        }
        self.put_request(&mut buf, Kind::Stats, &Request::Stats);
        self.put_plan(&mut buf, start, goal, 1);
        self.put_request(&mut buf, Kind::Hello, &Request::Hello);
        self.maybe_broken(&mut buf, 0.5);
        // Its answer before the update (which would cancel it).
        self.flush(&mut buf);
        self.wait_for_plans(0);
        let on_path = match core_plan(&maze, start, goal, &params) {
            Ok(p) => p.waypoints[p.waypoints.len() / 2],
            Err(_) => Point::new(maze.width / 2, maze.height / 2),
        };
        let cells = [on_path];
        let block = Request::SetCells {
            blocked: true,
            cells: Waypoints::Points(&cells),
        };
        self.put_request(&mut buf, Kind::SetCells, &block);
        let outside = [Point::new(3, 3), Point::new(maze.width, 7)];
        let refused = Request::SetCells {
            blocked: true,
            cells: Waypoints::Points(&outside),
        };
        self.put_request(&mut buf, Kind::SetCells, &refused);
        self.put_plan(&mut buf, start, goal, 2);
        self.put_request(&mut buf, Kind::Stats, &Request::Stats);
        self.flush(&mut buf);
        self.wait_for_plans(0);
        let clear = Request::SetRect {
            x: on_path.x.saturating_sub(1),
            y: on_path.y.saturating_sub(1),
            width: 3,
            height: 3,
            blocked: false,
        };
        self.put_request(&mut buf, Kind::SetRect, &clear);
        let refused = Request::SetRect {
            x: maze.width - 2,
            y: 5,
            width: 4,
            height: 1,
            blocked: true,
        };
        self.put_request(&mut buf, Kind::SetRect, &refused);
        self.maybe_broken(&mut buf, 0.5);
        self.put_plan(&mut buf, start, goal, 3);
        self.flush(&mut buf);
    }

    /// Valid cheap parameters (for after the overfilling bursts' slow ones).
    fn cheap_params(&mut self) -> Params {
        loop {
            let p = self.random_params();
            if p.validate().is_ok() {
                return p;
            }
        }
    }
}

/// The soak's frame and seed, from the environment.
fn env_or<T: std::str::FromStr>(var: &str, default: T) -> T {
    std::env::var(var).ok().map_or(default, |v| {
        v.parse()
            .unwrap_or_else(|_| panic!("{var}: not a number: {v:?}"))
    })
}

#[test]
fn soak_thousands_of_valid_and_broken_frames() {
    need_qemu!();
    let frames = env_or("OHACA_SOAK_FRAMES", DEFAULT_FRAMES as u64);
    let seed = env_or("OHACA_SOAK_SEED", DEFAULT_SEED);
    let baud = std::env::var("OHACA_SOAK_BAUD").ok().map(|v| {
        v.parse::<u32>()
            .unwrap_or_else(|_| panic!("OHACA_SOAK_BAUD: not a baud rate: {v:?}"))
    });
    soak(frames, seed, baud);
}

/// The soak through the pacing relay (a real serial line, 8N1; `ohaca_host::link::relay`):
/// `OHACA_SOAK_RELAY_FRAMES` frames (default [`RELAY_FRAMES`]) at `OHACA_SOAK_RELAY_BAUD`
/// (default [`RELAY_BAUD`]), nothing lost within the window, by the device or by the relay.
#[test]
fn soak_over_the_relay() {
    need_qemu!();
    let frames = env_or("OHACA_SOAK_RELAY_FRAMES", RELAY_FRAMES as u64);
    let seed = env_or("OHACA_SOAK_SEED", DEFAULT_SEED);
    let baud = env_or("OHACA_SOAK_RELAY_BAUD", RELAY_BAUD);
    soak(frames, seed, Some(baud));
}

/// The device: a QEMU on a TCP port, or behind the relay at a baud rate.
enum Device {
    Tcp(Qemu),
    Paced(qemu::PacedQemu),
}

impl Device {
    fn is_running(&mut self) -> bool {
        match self {
            Device::Tcp(q) => q.is_running(),
            Device::Paced(q) => q.is_running(),
        }
    }
}

fn stats_of(r: Response) -> StatsReply {
    match r {
        Response::Stats(s) => s,
        other => panic!("Stats answered with {other:?}"),
    }
}

/// `frames` frames seeded `seed`, over TCP (`baud` None) or through the relay at `baud`.
fn soak(frames: u64, seed: u64, baud: Option<u32>) {
    // The device, a writer, a reader thread, and the counters at the start.
    let parts = Arc::new(PartCounts::default());
    let (mut device, out, rx, base, relay) = match baud {
        None => {
            let q = Qemu::tcp();
            let stream = q.connect();
            stream
                .set_write_timeout(Some(TIMEOUT))
                .expect("write timeout");
            let (tx, rx) = mpsc::channel();
            let s = stream.try_clone().expect("clone the socket");
            let counts = Arc::clone(&parts);
            std::thread::spawn(move || read_replies_counting(s, tx, &counts));
            let out: Box<dyn Write> = Box::new(stream);
            (Device::Tcp(q), out, rx, Base::default(), None)
        }
        Some(baud) => {
            // Booted with a Link (Hello until the firmware answers: bytes sent before it takes
            // them are lost, as on a board); then its counters, and two clients of the relay.
            let (q, mut link, counters) = boot_paced(baud);
            let s = link.stats().expect("Stats at the start");
            drop(link);
            let base = Base {
                frames_ok: s.frames_ok,
                frames_bad: s.frames_bad,
                rx_bytes: s.rx_bytes,
                tx_frames: s.tx_frames + 1, // with this Stats' reply
                plans: s.plans,
                plan_errors: s.plan_errors,
                cancelled: s.cancelled,
                busy: s.busy,
                rx_overruns: s.rx_overruns,
                replies_dropped: s.replies_dropped,
                parted: s.parted,
            };
            let reader = q.relay.client();
            let out: Box<dyn Write> = Box::new(q.relay.client());
            let (tx, rx) = mpsc::channel();
            let counts = Arc::clone(&parts);
            std::thread::spawn(move || read_replies_counting(reader, tx, &counts));
            let line0 = counters.snapshot();
            (
                Device::Paced(q),
                out,
                rx,
                base,
                Some((baud, counters, line0)),
            )
        }
    };
    let t0 = Instant::now();

    // Flush (`00`), Hello: the device's limits, then the soak.
    let mut first = vec![0];
    first.extend(encode(1, &Request::Hello));
    let mut out = out;
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
    let (window, window_bytes) = (usize::from(cap.window), usize::from(cap.window_bytes));
    assert!(
        window >= usize::from(cap.plan_queue) + 4 && window_bytes >= MAX_REQUEST_WIRE + 64,
        "the soak's overfilling bursts need a window of plan_queue + 4 requests: {cap:?}"
    );
    let maze = Map::load(maps().join(MAZE)).expect("the maze");
    let mut soak = Soak {
        rng: Rng(seed),
        out,
        rx,
        parts,
        model: Model {
            reader: Box::new(RequestReader::new()),
            session: Session {
                max_cells: cap.cells,
                max_side: cap.max_side,
                frames_ok: base.frames_ok,
                frames_bad: base.frames_bad,
                params: info.defaults,
                upload: None,
                map: None,
                generation: 0,
                maps: vec![(0, 0)],
            },
            loose: 0,
        },
        info: info.clone(),
        plan_queue: usize::from(cap.plan_queue),
        window,
        window_bytes,
        base,
        maze: Rc::new(maze),
        maze_route: longest_scenario(MAZE_SCEN),
        mazes: 0,
        next_maze: frames / 5,
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
    // Cheap parameters before the first plan (the defaults take 12 ants x 100 iterations).
    let mut buf = Vec::new();
    let cheap = Params {
        ants: 4,
        iterations: 6,
        ..Params::default()
    };
    soak.put_request(&mut buf, Kind::SetParams, &Request::SetParams(cheap));
    soak.flush(&mut buf);

    let queue = soak.plan_queue;
    while soak.frames_sent() < frames {
        soak.pump(None);
        if soak.frames_sent() >= soak.next_maze {
            soak.maze_episode();
            soak.next_maze = soak.frames_sent() + MAZE_EVERY;
            continue;
        }
        let mut buf = Vec::new();
        if soak.rng.chance(0.12) {
            // A burst: 8 to 64 frames, cut into writes of as many as the window leaves room
            // for. Normal bursts hold at most `plan_queue` plans and are written once the
            // device has room for them (so none is refused); one in four starts with a write
            // that overfills the plan queue on purpose.
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
                // One write of a whole window: slow parameters, then `plan_queue + 2` slow
                // plans back to back, more than the queue holds beside the running one (the
                // last are refused with Busy, unless the first ones fail at once, on an
                // obstacle, say), and a Cancel that stops the others. Cheap parameters after.
                let slow = Params {
                    ants: 20,
                    iterations: 60_000,
                    patience: 0,
                    refine_patience: 0,
                    ..Params::default()
                };
                let mut pieces = vec![(
                    encode(soak.id(), &Request::SetParams(slow)),
                    Kind::SetParams,
                    1,
                )];
                for _ in 0..queue + 2 {
                    pieces.push((soak.valid(Kind::Plan), Kind::Plan, 1));
                }
                pieces.push((soak.valid(Kind::Cancel), Kind::Cancel, 1));
                soak.put(&mut buf, &pieces);
                soak.flush(&mut buf);
                let p = soak.cheap_params();
                soak.put_request(&mut buf, Kind::SetParams, &Request::SetParams(p));
            }
            for u in units {
                soak.build(&mut buf, u);
            }
            soak.bursts += 1;
            soak.burst_frames += soak.frames_sent() - before;
            soak.flush(&mut buf);
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
                soak.flush(&mut buf);
            }
        }
    }

    // A Stats as a fence (after its reply every Busy is known), then the last plans.
    let mut buf = Vec::new();
    soak.put_request(&mut buf, Kind::Stats, &Request::Stats);
    soak.flush(&mut buf);
    while !soak.pending.is_empty() || !soak.plans.is_empty() {
        soak.pump(Some(TIMEOUT));
    }
    // Everything is answered: the final counters are exact.
    soak.put_request(&mut buf, Kind::Stats, &Request::Stats);
    soak.flush(&mut buf);
    while !soak.pending.is_empty() {
        soak.pump(Some(TIMEOUT));
    }
    let wall = t0.elapsed();
    let (st, replies_before) = soak.last_stats.take().expect("the final Stats");
    let r = &soak.replies;
    let valid: u64 = soak
        .sent
        .iter()
        .filter(|(k, _)| k.is_valid())
        .map(|(_, n)| n)
        .sum();
    let session = &soak.model.session;
    let b = soak.base;
    let d = |now: u32, then: u32| u64::from(now - then);
    assert_eq!(
        d(st.frames_ok, b.frames_ok),
        valid,
        "frames_ok = the valid frames sent: {st:?}"
    );
    assert_eq!(st.frames_ok, session.frames_ok, "{st:?}");
    assert_eq!(st.frames_bad, session.frames_bad, "{st:?}");
    assert_eq!(
        d(st.rx_bytes, b.rx_bytes),
        soak.bytes_sent,
        "every byte read: {st:?}"
    );
    // Every reply frame sent: a path in parts is one reply in as many frames as parts.
    let part_frames = soak.parts.frames.load(Ordering::Acquire);
    let part_paths = soak.parts.paths.load(Ordering::Acquire);
    let parted = soak.parts.begun.load(Ordering::Acquire);
    assert_eq!(
        d(st.tx_frames, b.tx_frames),
        replies_before + part_frames - part_paths,
        "every reply frame sent ({part_frames} parts of {part_paths} paths): {st:?}"
    );
    // Paths begun in parts (a Cancel may stop one between its parts: then `Cancelled`).
    assert_eq!(
        d(st.parted, b.parted),
        parted,
        "paths begun in parts: {st:?}"
    );
    assert_eq!(d(st.plans, b.plans), r.path, "{st:?}");
    assert_eq!(d(st.plan_errors, b.plan_errors), r.plan_errors, "{st:?}");
    assert_eq!(
        d(st.cancelled, b.cancelled),
        r.error(ErrorCode::Cancelled),
        "{st:?}"
    );
    assert_eq!(d(st.busy, b.busy), r.error(ErrorCode::Busy), "{st:?}");
    assert_eq!((st.queued, st.planning), (0, false), "{st:?}");
    assert_eq!(st.boots, 1, "{st:?}");
    assert_eq!(
        (st.rx_overruns, st.replies_dropped),
        (b.rx_overruns, b.replies_dropped),
        "nothing lost within the window: {st:?}"
    );
    assert!(
        d(st.parted, b.parted) >= soak.mazes,
        "every maze episode's first path came in parts: {st:?}"
    );
    assert!(
        st.uptime > soak.first_uptime.expect("a Stats"),
        "uptime did not grow: {st:?}"
    );
    assert!(device.is_running(), "QEMU exited");
    let line = relay.as_ref().map(|(_, c, line0)| {
        let line = c.snapshot().since(line0);
        assert_eq!(
            line.to_device_dropped, 0,
            "the relay lost bytes within the window: {line}"
        );
        line
    });

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
    let over = match (baud, &line) {
        (Some(baud), Some(line)) => format!("over the relay at {baud} baud ({line})"),
        _ => "over TCP".to_string(),
    };
    println!(
        "soak {over}: {} frames ({} valid, {} bad or empty; {} bursts of {} frames; {} maze \
         episodes; {} writes, {} bytes) in {:.1} s, {part_paths} paths in {part_frames} parts ({parted} begun), seed {seed}; sent: {}; replies {}: Hello {}, \
         Ack {}, Path {}, Stats {}, Error {} ({}); device: frames_ok {}, frames_bad {}, \
         rx_overruns {}, replies_dropped {}, rx_bytes {}, tx_frames {}, plans {}, plan_errors {}, \
         cancelled {}, busy {}, parted {}, boots {}, uptime {:.1} s, stack_peak {} B",
        soak.frames_sent(),
        valid,
        soak.frames_sent() - valid,
        soak.bursts,
        soak.burst_frames,
        soak.mazes,
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
        st.replies_dropped,
        st.rx_bytes,
        st.tx_frames,
        st.plans,
        st.plan_errors,
        st.cancelled,
        st.busy,
        st.parted,
        st.boots,
        st.uptime as f64 / f64::from(cap.tick_hz),
        st.stack_peak,
    );

    beyond_the_window(
        &mut soak,
        st,
        relay.as_ref().map(|(_, c, _)| (c.as_ref(), c.snapshot())),
    );
    if let Some((_, c, _)) = &relay {
        println!("relay at the end: {}", c.snapshot());
    }
    assert!(
        device.is_running(),
        "QEMU exited after the burst beyond the window"
    );
    // The reader thread ends when QEMU (and the relay) are gone.
    drop(soak);
    drop(device);
}

/// Beyond the window, at the end: [`BEYOND`] Stats in one write (over 1 KiB and over 8
/// requests), raw. The device keeps serving (Hello and Stats answered after), and what it lost is
/// counted: every frame it saw (valid or not) was answered or its reply dropped
/// (`replies_dropped`), and every byte written was read (`rx_bytes`), dropped by the device
/// (`rx_overruns`) or lost by the relay. Which is lost, and how much, timing decides.
fn beyond_the_window(soak: &mut Soak, st: StatsReply, relay: Option<(&Counters, Snapshot)>) {
    let first = 1_000_000u32;
    let mut burst = Vec::new();
    for id in first..first + BEYOND {
        burst.extend(encode(id, &Request::Stats));
    }
    soak.out.write_all(&burst).expect("the burst");
    // Every reply that comes, until the line back is quiet (how long decides no assertion).
    let mut got = Vec::new();
    while let Ok(r) = soak.rx.recv_timeout(Duration::from_secs(2)) {
        got.push(r.unwrap_or_else(|e| panic!("{e}")));
    }
    // A lone `00` (the burst may have left a partial frame), Hello, Stats.
    let (hello, stats) = (first + BEYOND, first + BEYOND + 1);
    let mut fence = vec![0];
    fence.extend(encode(hello, &Request::Hello));
    fence.extend(encode(stats, &Request::Stats));
    soak.out.write_all(&fence).expect("the fence");
    let after = loop {
        let (id, resp) = soak
            .rx
            .recv_timeout(TIMEOUT)
            .expect("an answer after the burst")
            .unwrap_or_else(|e| panic!("{e}"));
        match id {
            _ if id == hello => assert_eq!(resp, Response::Hello(soak.info.clone())),
            _ if id == stats => break stats_of(resp),
            _ => got.push((id, resp)),
        }
    };
    let relay_lost = relay.map_or(0, |(c, l0)| c.snapshot().since(&l0).to_device_dropped);
    let answered = got.len() as u64;
    let stats_answered = got
        .iter()
        .filter(|(id, r)| (first..first + BEYOND).contains(id) && matches!(r, Response::Stats(_)))
        .count() as u64;
    assert!(
        got.iter().all(|(id, r)| (matches!(r, Response::Stats(_))
            && (first..first + BEYOND).contains(id))
            || (*id == 0 && matches!(r, Response::Error(_)))),
        "only the burst's Stats, and errors (id 0) for frames that lost bytes: {got:?}"
    );
    let d = |now: u32, then: u32| u64::from(now - then);
    let ok = d(after.frames_ok, st.frames_ok) - 2; // but the Hello and Stats after
    let bad = d(after.frames_bad, st.frames_bad);
    let dropped = d(after.replies_dropped, st.replies_dropped);
    let overruns = d(after.rx_overruns, st.rx_overruns);
    let sent = d(after.tx_frames, st.tx_frames) - 2; // but the final Stats' and the Hello's
    let read = d(after.rx_bytes, st.rx_bytes);
    let written = (burst.len() + fence.len()) as u64;
    println!(
        "beyond the window: {BEYOND} Stats in one write ({} bytes): {stats_answered} answered, \
         {} errors for broken frames; device: {ok} valid and {bad} bad frames seen, \
         {dropped} replies dropped, {overruns} bytes dropped (rx_overruns), {read} of {written} \
         bytes read; relay lost {relay_lost} bytes",
        burst.len(),
        answered - stats_answered,
    );
    assert_eq!(after.boots, 1, "{after:?}");
    assert_eq!(
        answered, sent,
        "every reply the device sent arrived: {after:?}"
    );
    assert_eq!(
        ok + bad,
        sent + dropped,
        "every frame the device saw was answered or its reply counted as dropped: {after:?}"
    );
    assert!(ok <= u64::from(BEYOND) && stats_answered <= ok, "{after:?}");
    // (The QEMU board counts every byte it drops in `rx_overruns`; the STM32 boards count
    // overrun events.)
    assert_eq!(
        read + overruns + relay_lost,
        written,
        "every byte written was read, or counted as lost by the device or the relay: {after:?}"
    );
    assert!(
        dropped + overruns + relay_lost > 0 || stats_answered == u64::from(BEYOND),
        "nothing counted as lost, yet not every Stats was answered: {after:?}"
    );
}
