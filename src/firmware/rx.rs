//! The receive task: splits the UART stream into frames, decodes them, answers everything but
//! plans at once and queues plans for the planner. Map uploads and cell updates are written into
//! the one map buffer ([`MAP`]): checked first (a refused one changes nothing), then the running
//! and queued plans are cancelled, then the buffer's lock is taken (the planner gives it up at
//! its next yield, or after reading one part of a path it is sending). It never waits for room
//! in a queue: a full plan queue is `Busy`, a full reply queue (a host beyond its window) drops
//! the reply, counted.

use embassy_futures::yield_now;
use embassy_sync::channel::TrySendError;
use embedded_io_async::Read;

use ohaca::grid::Point;
use ohaca::planner::{Area, Params};
use ohaca::protocol::{
    check_cells, check_rect, decode_request, set_cells, set_rect, Encoding, ErrorCode, ErrorReply,
    MapChunk, Request, RequestReader, Upload, Waypoints, MAX_REQUEST_WIRE,
};

use super::board;
use super::state::{self, count, reply, Job, Small, GENERATION, JOBS, LIMITS, MAP, PLAN_QUEUE};

#[embassy_executor::task]
pub async fn rx_task(mut rx: board::Rx) {
    let mut reader = RequestReader::new();
    let mut session = Session::new();
    let mut buf = [0u8; 64];
    loop {
        let n = match rx.read(&mut buf).await {
            Ok(n) => n,
            Err(_) => {
                // Framing, noise, parity or overrun: the frame in progress fails its CRC.
                count(|s| s.rx_overruns = s.rx_overruns.wrapping_add(1));
                continue;
            }
        };
        count(|s| s.rx_bytes = s.rx_bytes.wrapping_add(n as u32));
        for &b in buf.get(..n).unwrap_or(&[]) {
            let Some(frame) = reader.push(b).into_frame(MAX_REQUEST_WIRE) else {
                continue;
            };
            let decoded = frame.and_then(decode_request);
            match decoded {
                Ok((id, req)) => {
                    count(|s| s.frames_ok = s.frames_ok.wrapping_add(1));
                    board::log_request(id);
                    session.handle(id, req).await;
                }
                Err(e) => {
                    count(|s| s.frames_bad = s.frames_bad.wrapping_add(1));
                    defmt::warn!("bad frame: {}", defmt::Display2Format(&e));
                    reply(e.id(), Small::Error(e.reply()));
                }
            }
        }
    }
}

/// What the receiver keeps between requests.
struct Session {
    params: Params,
    upload: Upload,
}

/// A cell update: a rectangle or a list.
enum Update<'a> {
    Rect(u16, u16, u16, u16),
    Cells(Waypoints<'a>),
}

fn error(code: ErrorCode, detail: u32, limit: u32) -> Small {
    Small::Error(ErrorReply::with(code, detail, limit))
}

impl Session {
    fn new() -> Self {
        Session {
            params: Params::default(),
            upload: Upload::new(),
        }
    }

    async fn handle(&mut self, id: u32, req: Request<'_>) {
        let r = match req {
            Request::Hello => Small::Hello,
            Request::SetMap {
                width,
                height,
                offset,
                total_len,
                chunk,
            } => {
                let c = MapChunk {
                    encoding: Encoding::Raw,
                    width,
                    height,
                    offset,
                    total_len,
                    chunk,
                };
                self.set_map(&c).await
            }
            Request::SetMapRle {
                width,
                height,
                offset,
                total_len,
                chunk,
            } => {
                let c = MapChunk {
                    encoding: Encoding::Rle,
                    width,
                    height,
                    offset,
                    total_len,
                    chunk,
                };
                self.set_map(&c).await
            }
            Request::SetRect {
                x,
                y,
                width,
                height,
                blocked,
            } => update(Update::Rect(x, y, width, height), blocked).await,
            Request::SetCells { blocked, cells } => update(Update::Cells(cells), blocked).await,
            Request::SetParams(p) => match p.validate() {
                Ok(()) => {
                    self.params = p;
                    defmt::info!("params: {} ants x {} iterations", p.ants, p.iterations);
                    Small::Ack
                }
                Err(e) => Small::Error(e.into()),
            },
            Request::Plan { start, goal, seed } | Request::PlanWarm { start, goal, seed } => {
                let warm = matches!(req, Request::PlanWarm { .. });
                match self.enqueue(id, start, goal, seed, warm) {
                    Ok(()) => {
                        // The planner answers. Let it take the plan now if it is idle, before the
                        // next frame is handled: a burst of plans then fills the queue behind the
                        // running one, and `Busy` comes exactly when `plan_queue` plans wait.
                        yield_now().await;
                        return;
                    }
                    Err(e) => e,
                }
            }
            Request::Cancel => {
                // Also stops a path being sent: its request gets `Cancelled` before this `Ack`
                // goes out, or right after the part on the wire.
                state::stop_all();
                Small::Ack
            }
            Request::Stats => Small::Stats,
        };
        reply(id, r);
    }

    fn enqueue(
        &mut self,
        id: u32,
        start: Point,
        goal: Point,
        seed: Option<u64>,
        warm: bool,
    ) -> Result<(), Small> {
        if state::map_size().is_none() {
            return Err(error(ErrorCode::NoMap, 0, 0));
        }
        let params = Params {
            seed: seed.unwrap_or(self.params.seed),
            ..self.params
        };
        let job = Job {
            id,
            start,
            goal,
            params,
            generation: GENERATION.load(core::sync::atomic::Ordering::Acquire),
            warm,
        };
        match JOBS.try_send(job) {
            Ok(()) => Ok(()),
            Err(TrySendError::Full(_)) => {
                count(|s| s.busy = s.busy.wrapping_add(1));
                Err(error(ErrorCode::Busy, JOBS.len() as u32, PLAN_QUEUE as u32))
            }
        }
    }

    /// One chunk of a map upload (raw or run-length). A good first chunk drops the map: plans
    /// get `NoMap` until the last chunk arrives (or a broken upload ends it with no map).
    async fn set_map(&mut self, c: &MapChunk<'_>) -> Small {
        let starts = match self.upload.accept(c, LIMITS) {
            Ok(s) => s,
            Err(e) => return Small::Error(e),
        };
        if starts {
            // Plans received before this map are for the old one, and a path being sent is read
            // from buffers the new map may cover.
            state::stop_all();
            state::set_map_size(None);
        }
        let mut map = MAP.lock().await;
        if starts {
            // The pheromone in the planner's storage is for the old map.
            map.split().1.forget();
        }
        match self.upload.write(c, &mut map[..]) {
            Ok(Some((w, h))) => {
                state::set_map_size(Some((w, h)));
                defmt::info!("map {}x{} active", w, h);
                Small::Ack
            }
            Ok(None) => Small::Ack,
            Err(e) => Small::Error(e),
        }
    }
}

/// Block or clear cells of the map in place; cancels the running and queued plans.
async fn update(u: Update<'_>, blocked: bool) -> Small {
    let Some(size) = state::map_size() else {
        return error(ErrorCode::NoMap, 0, 0);
    };
    let checked = match &u {
        Update::Rect(x, y, w, h) => check_rect(size, *x, *y, *w, *h),
        Update::Cells(c) => check_cells(size, c),
    };
    if let Err(e) = checked {
        return Small::Error(e);
    }
    state::cancel_all();
    let mut map = MAP.lock().await;
    // The colony memory learns what changes, and which cells a clear frees (blocked before:
    // read from the map before it is written), for the next `PlanWarm` (`ohaca::planner::reuse`).
    let (bits, memory) = map.split();
    let was_blocked = |p: Point| {
        let i = usize::from(p.y) * usize::from(size.0) + usize::from(p.x);
        ohaca::map::bits::get(bits, i).unwrap_or(false)
    };
    let done = match u {
        Update::Rect(x, y, w, h) => {
            if let Some(a) = Area::rect(x, y, w, h) {
                memory.rect(a, blocked, was_blocked);
            }
            set_rect(size, bits, (x, y, w, h), blocked)
        }
        Update::Cells(c) => {
            for p in c.iter() {
                memory.cell(p, was_blocked(p), blocked);
            }
            set_cells(size, bits, &c, blocked)
        }
    };
    match done {
        Ok(()) => Small::Ack,
        Err(e) => Small::Error(e),
    }
}
