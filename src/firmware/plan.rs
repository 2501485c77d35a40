//! The planning task: takes plan requests from the queue and runs them a piece at a time, one
//! `Run::poll` a piece (`ohaca::planner::Run`'s docs: each piece is bounded), yielding to the
//! executor after every piece so frames keep arriving and `Cancel` works. It logs each plan's
//! largest piece in ticks (with `-icount shift=0`, a tick is 1,000 instructions) and its stage.
//!
//! The planner reads the map in place: it holds [`MAP`]'s lock from `Run::new` until its path is
//! planned (on the small boards the planner's buffers share the map's arena), and a writer (a map
//! upload, a cell update) cancels the plan first, so it gives the lock up at its next yield.
//!
//! Then it sends the path without the lock. A path whose body fits one part
//! (`ohaca::protocol::PART_BYTES`) goes whole, as one `Path` frame encoded under the lock. A
//! longer one goes as `PathPart` frames: for each, the planner takes the lock, lends itself the
//! workspace again and reads the part from where the plan lies in it (`ohaca::planner::Placed`),
//! gives the lock up, waits for the small replies queued meanwhile to go out, and sends the part.
//! So no reply waits behind more than one part, the receiver can write cell updates while a long
//! path goes out, and a `Cancel` or a map upload stops it (the request then gets `Cancelled`).

use core::sync::atomic::Ordering;

use embassy_futures::yield_now;
use embassy_time::Instant;

use ohaca::planner::session;
use ohaca::planner::{Placed, Plan, Poll, Stage};
use ohaca::protocol::{
    encode_reply, wire_len, ErrorCode, ErrorReply, PathBody, PathPart, PathReply, Reply, Waypoints,
    PART_BYTES,
};

use super::buffers;
use super::stack;
use super::state::{self, count, Job, PlanStorage, Small, TxPort, JOBS, MAP, PLANNING};
use super::tx::send_path_frame;

/// Room for a path frame: a whole path of at most [`PART_BYTES`] body bytes, or a part (id,
/// variant, offset, length and byte-string length as the longest varints, the CRC).
const FRAME: usize = wire_len(PART_BYTES + 5 + 1 + 5 + 5 + 2 + 4);

/// A planned path, ready to go out without the map's lock.
enum Ready {
    /// A whole `Path` frame of this many bytes in the frame buffer.
    Whole(usize),
    /// A path in parts: its fixed fields, where it lies in the workspace, the map it was planned
    /// on and the body's length.
    Parts {
        fixed: PathReply<'static>,
        placed: Placed,
        size: (u16, u16),
        total: usize,
    },
}

#[embassy_executor::task]
pub async fn planner_task(storage: &'static mut PlanStorage, port: &'static TxPort) {
    loop {
        let job = JOBS.receive().await;
        PLANNING.store(true, Ordering::Relaxed);
        // A Cancel or a map upload from now on stops this plan's path while it is sent.
        let stops = state::stops();
        let mut frame = [0u8; FRAME];
        let planned = plan(storage, &job, &mut frame).await;
        PLANNING.store(false, Ordering::Relaxed);
        let result = match planned {
            Ok((ticks, ready)) => send(storage, &job, ready, &mut frame, stops, port)
                .await
                .map(|()| ticks),
            Err(e) => Err(e),
        };
        match result {
            Ok(ticks) => count(|s| {
                s.plans = s.plans.wrapping_add(1);
                s.last_plan_ticks = ticks;
            }),
            Err(e) => {
                if e.code == ErrorCode::Cancelled {
                    count(|s| s.cancelled = s.cancelled.wrapping_add(1));
                } else {
                    count(|s| s.plan_errors = s.plan_errors.wrapping_add(1));
                }
                defmt::info!("plan {}: error {}", job.id, e.code.code());
                state::reply(job.id, Small::Error(e));
            }
        }
        defmt::info!("stack peak {} of {} bytes", stack::peak(), stack::size());
    }
}

/// Run one job; returns the ticks it took and its path, ready to send.
async fn plan(
    storage: &mut PlanStorage,
    job: &Job,
    frame: &mut [u8; FRAME],
) -> Result<(u64, Ready), ErrorReply> {
    let cancelled = || ErrorReply::new(ErrorCode::Cancelled);
    if state::cancelled(job.generation) {
        return Err(cancelled());
    }
    // The map, in place. A writer cancels before it waits for the lock, so check again once
    // it is ours: a plan never starts on a map that changed after it was received.
    let mut map = MAP.lock().await;
    if state::cancelled(job.generation) {
        return Err(cancelled());
    }
    let (width, height) = state::map_size().ok_or(ErrorReply::new(ErrorCode::NoMap))?;
    let (grid, mut ws, memory) = buffers::lend(&mut map, storage, width, height)?;
    // Where the plan will lie, to read its parts again once the lock is given up.
    let bases = ws.bases();
    let t0 = Instant::now();
    // A warm plan keeps the colony if it is for this map and goal; both kinds record theirs for
    // the next `PlanWarm` once the run started (a refused plan leaves the pheromone as it was).
    // The memory lives under the map's lock (`state::MAP`).
    let (start, goal, params) = (job.start, job.goal, &job.params);
    // First, a warm plan that no change since can shorten or block is the rest of the last
    // answer: no run at all (`ohaca::planner::session`, as on the host).
    let ends = (start, goal);
    match session::answer(&grid, ends, params, &mut ws, memory, job.warm) {
        Ok(reused) => {
            let plan = reused.into_plan(ws, memory, params);
            let ticks = Instant::now().saturating_duration_since(t0).as_ticks();
            defmt::info!(
                "plan {}: {}, length {}, {} waypoints, {} ticks",
                job.id,
                plan.origin.name(),
                plan.length,
                plan.waypoints().len(),
                ticks
            );
            let ready = ready(job, &plan, ticks, bases, (width, height), frame)?;
            return Ok((ticks, ready));
        }
        // Why the colony runs: the replan could not be answered with the last answer.
        Err(Some(why)) => defmt::info!(
            "plan {}: not reused: {}",
            job.id,
            defmt::Display2Format(&why)
        ),
        Err(None) => {}
    }
    let mut run = session::start(&grid, ends, params, ws, memory, job.warm)?;
    if job.warm {
        defmt::info!("plan {}: warm start asked, warm {}", job.id, run.is_warm());
    }
    // The one loop: a bounded piece a poll, a yield after each, a cancel check. Ticks inside the
    // polls by stage (without the yields) and the largest piece.
    let t_new = Instant::now();
    let mut spent = [0u64; 3];
    // The largest piece of each stage.
    let mut most = [(0u64, ""); 3];
    let mut largest = (t_new.saturating_duration_since(t0).as_ticks(), "new");
    loop {
        let name = run.piece();
        let t = Instant::now();
        let Poll::Working(stage) = run.poll() else {
            break;
        };
        let piece = Instant::now().saturating_duration_since(t).as_ticks();
        if piece > largest.0 {
            largest = (piece, name);
        }
        let i = match stage {
            Stage::Setup => 0,
            Stage::Colony => 1,
            Stage::Polish => 2,
        };
        if let (Some(s), Some(m)) = (spent.get_mut(i), most.get_mut(i)) {
            *s = s.saturating_add(piece);
            if piece > m.0 {
                *m = (piece, name);
            }
        }
        yield_now().await;
        if state::cancelled(job.generation) {
            defmt::info!(
                "plan {} cancelled in its {} after {} iterations",
                job.id,
                stage.name(),
                run.iteration()
            );
            return Err(cancelled());
        }
    }
    let [in_setup, in_steps, in_polish] = spent;
    let [most_setup, most_colony, most_polish] = most;
    // What the run leaves in the storage for the next warm start to repair rather than rebuild
    // (its pruning marks and route links), recorded only now that it is complete; its plan.
    let t_finish = Instant::now();
    let plan = session::end(run, memory)?;
    let t_end = Instant::now();
    if !plan.shortfalls.is_empty() {
        // None on the board's own layout (`ohaca::planner::Shortfalls`): said, never silent.
        defmt::warn!(
            "plan {}: ran short of scratch: {}",
            job.id,
            defmt::Display2Format(&plan.shortfalls)
        );
    }
    let ticks = t_end.saturating_duration_since(t0).as_ticks();
    let last = t_end.saturating_duration_since(t_finish).as_ticks();
    if last > largest.0 {
        largest = (last, "finish");
    }
    // `new` is `Run::new` and the setup, `finish` the polish and `Run::finish`
    // (scripts/bench_device.py reads this line).
    defmt::info!(
        "plan {}: {} iterations, length {}, {} waypoints, {} ticks (new {}, steps {}, finish {}), largest piece {} ticks ({}; new {}, setup {} {}, colony {} {}, polish {} {}, finish {})",
        job.id,
        plan.iterations,
        plan.length,
        plan.waypoints().len(),
        ticks,
        t_new.saturating_duration_since(t0).as_ticks() + in_setup,
        in_steps,
        in_polish + last,
        largest.0,
        largest.1,
        t_new.saturating_duration_since(t0).as_ticks(),
        most_setup.0,
        most_setup.1,
        most_colony.0,
        most_colony.1,
        most_polish.0,
        most_polish.1,
        last
    );
    let ready = ready(job, &plan, ticks, bases, (width, height), frame)?;
    Ok((ticks, ready))
}

/// The reply to `job` for `plan`: its fixed fields and slices.
fn path_reply<'a>(plan: &Plan<'a>, ticks: u64) -> PathReply<'a> {
    PathReply {
        raw_length: plan.raw_length,
        length: plan.length,
        turns: plan.turns,
        iterations: plan.iterations,
        best_iteration: plan.best_iteration,
        moves: plan.moves,
        ticks,
        raw_cells: u32::try_from(plan.raw_len()).unwrap_or(u32::MAX),
        origin: plan.origin,
        waypoints: Waypoints::Points(plan.waypoints()),
        directions: plan.directions(),
    }
}

/// An error for a path the protocol cannot carry (it never happens within the board's limits).
fn unsendable(plan: &Plan<'_>) -> ErrorReply {
    ErrorReply::with(
        ErrorCode::Internal,
        plan.waypoints().len() as u32,
        plan.directions().len() as u32,
    )
}

/// Get `plan` ready to send: a short one encoded whole into `frame`, a long one placed.
fn ready(
    job: &Job,
    plan: &Plan<'_>,
    ticks: u64,
    bases: ohaca::planner::Bases,
    size: (u16, u16),
    frame: &mut [u8; FRAME],
) -> Result<Ready, ErrorReply> {
    let reply = path_reply(plan, ticks);
    let total = match PathBody::new(&reply) {
        Ok(body) => body.len(),
        Err(e) => {
            defmt::error!("path reply: {}", defmt::Display2Format(&e));
            return Err(unsendable(plan));
        }
    };
    if total <= PART_BYTES {
        let n = encode_reply(job.id, &Reply::Path(reply), frame).map_err(|_| unsendable(plan))?;
        return Ok(Ready::Whole(n));
    }
    let placed = plan.place(bases).ok_or_else(|| unsendable(plan))?;
    let fixed = PathReply {
        waypoints: Waypoints::Points(&[]),
        directions: &[],
        ..reply
    };
    Ok(Ready::Parts {
        fixed,
        placed,
        size,
        total,
    })
}

/// Send a planned path: whole, or a part at a time with the small replies passing between the
/// parts. A `Cancel` or a map upload since `stops` stops it (`Cancelled`): no frame of it follows
/// their `Ack` (`super::tx::send_path_frame`).
async fn send(
    storage: &mut PlanStorage,
    job: &Job,
    ready: Ready,
    frame: &mut [u8; FRAME],
    stops: u32,
    port: &'static TxPort,
) -> Result<(), ErrorReply> {
    let (fixed, placed, size, total) = match ready {
        Ready::Whole(n) => {
            return send_path_frame(port, frame.get(..n).unwrap_or(&[]), stops).await;
        }
        Ready::Parts {
            fixed,
            placed,
            size,
            total,
        } => (fixed, placed, size, total),
    };
    count(|s| s.parted = s.parted.wrapping_add(1));
    let mut offset = 0;
    let mut bytes = [0u8; PART_BYTES];
    while offset < total {
        let at = offset;
        // Read the part under the map's lock, from the workspace lent again as it was.
        let n = {
            let mut map = MAP.lock().await;
            if state::stopped(stops) || state::map_size() != Some(size) {
                defmt::info!(
                    "plan {}: path stopped after {} of {} bytes",
                    job.id,
                    offset,
                    total
                );
                return Err(ErrorReply::new(ErrorCode::Cancelled));
            }
            let (_grid, ws, _) = buffers::lend(&mut map, storage, size.0, size.1)?;
            let (tour, waypoints) = ws
                .placed(&placed)
                .ok_or(ErrorReply::new(ErrorCode::Internal))?;
            let reply = PathReply {
                waypoints: Waypoints::Points(waypoints),
                directions: tour,
                ..fixed
            };
            let body = PathBody::new(&reply).map_err(|_| ErrorReply::new(ErrorCode::Internal))?;
            let k = body.read(offset, &mut bytes);
            let part = PathPart {
                offset: offset as u32,
                total_len: total as u32,
                bytes: bytes.get(..k).unwrap_or(&[]),
            };
            let n = encode_reply(job.id, &Reply::PathPart(part), frame)
                .map_err(|_| ErrorReply::new(ErrorCode::Internal))?;
            offset = offset.saturating_add(k.max(1));
            n
        };
        // The small replies queued meanwhile go first; then this part, unless stopped since.
        if let Err(e) = send_path_frame(port, frame.get(..n).unwrap_or(&[]), stops).await {
            defmt::info!(
                "plan {}: path stopped after {} of {} bytes",
                job.id,
                at,
                total
            );
            return Err(e);
        }
    }
    Ok(())
}
