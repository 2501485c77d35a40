//! The receive task: splits the UART stream into frames, decodes them, answers everything but
//! `Plan` at once and queues plans for the planner.

use embassy_futures::yield_now;
use embassy_sync::channel::TrySendError;
use embedded_io_async::Read;

use ohaca::grid::Point;
use ohaca::planner::Params;
use ohaca::protocol::{
    decode_request, Capacity, ErrorCode, ErrorReply, HelloReply, Reply, Request, RequestReader,
    MAX_CHUNK, MAX_REQUEST, MAX_REQUEST_WIRE, VERSION,
};

use super::board::{self, Board};
use super::state::{
    self, count, reply, ActiveMap, Job, CELLS, GENERATION, JOBS, MAP, MAP_BYTES, PLAN_QUEUE,
};

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
                    session.handle(id, req).await;
                }
                Err(e) => {
                    count(|s| s.frames_bad = s.frames_bad.wrapping_add(1));
                    defmt::warn!("bad frame: {}", defmt::Display2Format(&e));
                    reply(e.id(), Reply::Error(e.reply())).await;
                }
            }
        }
    }
}

/// A map upload in progress.
struct Upload {
    width: u16,
    height: u16,
    total_len: u32,
    received: u32,
    bits: [u8; MAP_BYTES],
}

/// What the receiver keeps between requests.
struct Session {
    params: Params,
    upload: Option<Upload>,
}

fn error(code: ErrorCode, detail: u32, limit: u32) -> Reply<'static> {
    Reply::Error(ErrorReply::with(code, detail, limit))
}

fn hello() -> HelloReply<'static> {
    HelloReply {
        protocol_version: VERSION,
        firmware_version: env!("CARGO_PKG_VERSION"),
        board: board::Active::NAME,
        capacity: Capacity {
            cells: CELLS as u32,
            max_width: CELLS as u16,
            max_height: CELLS as u16,
            max_chunk: MAX_CHUNK as u16,
            max_request: MAX_REQUEST as u16,
            plan_queue: PLAN_QUEUE as u8,
            tick_hz: embassy_time::TICK_HZ as u32,
        },
        defaults: Params::default(),
    }
}

impl Session {
    fn new() -> Self {
        Session {
            params: Params::default(),
            upload: None,
        }
    }

    async fn handle(&mut self, id: u32, req: Request<'_>) {
        let r = match req {
            Request::Hello => Reply::Hello(hello()),
            Request::SetMap {
                width,
                height,
                offset,
                total_len,
                chunk,
            } => self.set_map(width, height, offset, total_len, chunk),
            Request::SetParams(p) => match p.validate() {
                Ok(()) => {
                    self.params = p;
                    defmt::info!("params: {} ants x {} iterations", p.ants, p.iterations);
                    Reply::Ack
                }
                Err(e) => Reply::Error(e.into()),
            },
            Request::Plan { start, goal, seed } => match self.enqueue(id, start, goal, seed) {
                Ok(()) => {
                    // The planner answers. Let it take the plan now if it is idle, before the
                    // next frame is handled: a burst of plans then fills the queue behind the
                    // running one, and `Busy` comes exactly when `plan_queue` plans wait.
                    yield_now().await;
                    return;
                }
                Err(e) => e,
            },
            Request::Cancel => {
                state::cancel_all();
                Reply::Ack
            }
            Request::Stats => Reply::Stats(state::stats()),
        };
        reply(id, r).await;
    }

    fn enqueue(
        &mut self,
        id: u32,
        start: Point,
        goal: Point,
        seed: Option<u64>,
    ) -> Result<(), Reply<'static>> {
        if MAP.lock(|m| m.get().is_none()) {
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
        };
        match JOBS.try_send(job) {
            Ok(()) => Ok(()),
            Err(TrySendError::Full(_)) => {
                count(|s| s.busy = s.busy.wrapping_add(1));
                Err(error(ErrorCode::Busy, JOBS.len() as u32, PLAN_QUEUE as u32))
            }
        }
    }

    fn set_map(
        &mut self,
        width: u16,
        height: u16,
        offset: u32,
        total_len: u32,
        chunk: &[u8],
    ) -> Reply<'static> {
        if chunk.len() > MAX_CHUNK {
            return error(ErrorCode::TooLarge, chunk.len() as u32, MAX_CHUNK as u32);
        }
        if offset == 0 {
            // A new upload; the previous unfinished one (if any) is dropped.
            self.upload = None;
            let cells = u32::from(width) * u32::from(height);
            if cells == 0 {
                return error(ErrorCode::BadMap, 0, 0);
            }
            if cells > CELLS as u32 {
                return error(ErrorCode::MapTooLarge, cells, CELLS as u32);
            }
            let want = cells.div_ceil(8);
            if total_len != want {
                return error(ErrorCode::BadMap, total_len, want);
            }
            self.upload = Some(Upload {
                width,
                height,
                total_len,
                received: 0,
                bits: [0; MAP_BYTES],
            });
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
        up.received = up.received.max(end);
        if up.received == up.total_len {
            let map = ActiveMap {
                width: up.width,
                height: up.height,
                bits: up.bits,
            };
            self.upload = None;
            // Plans received before this map are for the old one: cancel them, then switch.
            state::cancel_all();
            MAP.lock(|m| m.set(Some(map)));
            defmt::info!("map {}x{} active", map.width, map.height);
        }
        Reply::Ack
    }
}
