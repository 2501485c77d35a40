//! The planning task: takes plan requests from the queue and runs them a piece at a time (each
//! piece of the setup, each iteration, each piece of the local search and the smoothing),
//! yielding to the executor after every piece so frames keep arriving and `Cancel` works.
//! A path is streamed into the UART as it is encoded ([`PathStream`]), a piece at a time: no
//! buffer for a whole frame (up to 80 KiB). The planner reads the map in place: it holds
//! [`MAP`]'s lock from `Run::new` until its path is sent (on the small boards the planner's
//! buffers share the map's arena), and a writer (a map upload, a cell update) cancels the plan
//! first, so it gives the lock up at its next yield, or once its path is out.

use core::sync::atomic::Ordering;

use embassy_futures::yield_now;
use embassy_time::Instant;
use embedded_io_async::Write;

use ohaca::planner::{reuse, Plan, Run};
use ohaca::protocol::{ErrorCode, ErrorReply, PathReply, PathStream, Reply, Waypoints};

use super::buffers;
use super::stack;
use super::state::{self, count, Job, PlanStorage, TxPort, JOBS, MAP, PLANNING};
use super::tx::sent_one;

/// Bytes of a path frame encoded per write to the UART.
const PIECE: usize = 64;

#[embassy_executor::task]
pub async fn planner_task(storage: &'static mut PlanStorage, port: &'static TxPort) {
    loop {
        let job = JOBS.receive().await;
        PLANNING.store(true, Ordering::Relaxed);
        let result = plan(storage, &job, port).await;
        PLANNING.store(false, Ordering::Relaxed);
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
                state::reply(job.id, Reply::Error(e)).await;
            }
        }
        defmt::info!("stack peak {} of {} bytes", stack::peak(), stack::size());
    }
}

/// Run one job and send its path; returns the ticks it took.
async fn plan(
    storage: &mut PlanStorage,
    job: &Job,
    port: &'static TxPort,
) -> Result<u64, ErrorReply> {
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
    let (grid, mut ws) = buffers::lend(&mut map, storage, width, height)?;
    let t0 = Instant::now();
    // A warm plan keeps the colony if it is for this map and goal; both kinds record theirs for
    // the next `PlanWarm` once the run started (a refused plan leaves the pheromone as it was).
    // The memory is read and written under the map's lock.
    let mut memory = state::colony();
    let (start, goal, params) = (job.start, job.goal, &job.params);
    // First, a warm plan that no change since can shorten or block is the rest of the last
    // answer: no run at all.
    if job.warm {
        if let Some(plan) = reuse(&grid, start, goal, params, &mut ws, &mut memory) {
            state::set_colony(memory);
            let ticks = Instant::now().saturating_duration_since(t0).as_ticks();
            defmt::info!(
                "plan {}: reused, length {}, {} waypoints, {} ticks",
                job.id,
                plan.length,
                plan.waypoints().len(),
                ticks
            );
            send(job, &plan, ticks, port).await?;
            return Ok(ticks);
        }
    }
    let mut run = if job.warm {
        Run::warm(&grid, start, goal, params, ws, &mut memory)
    } else {
        Run::cold(&grid, start, goal, params, ws, &mut memory)
    }?;
    state::set_colony(memory);
    if job.warm {
        defmt::info!("plan {}: warm start asked, warm {}", job.id, run.is_warm());
    }
    // The setup a piece at a time (flood fill, pruning, coarse route: each reads the whole map),
    // yielding between the pieces like between iterations.
    while run.setup_step() {
        yield_now().await;
        if state::cancelled(job.generation) {
            defmt::info!("plan {} cancelled during its setup", job.id);
            return Err(cancelled());
        }
    }
    let t_new = Instant::now();
    // Ticks spent inside `Run::step`, without the yields between iterations.
    let mut in_steps = 0u64;
    loop {
        let t = Instant::now();
        let more = run.step();
        in_steps += Instant::now().saturating_duration_since(t).as_ticks();
        yield_now().await;
        if state::cancelled(job.generation) {
            defmt::info!(
                "plan {} cancelled after {} iterations",
                job.id,
                run.iteration()
            );
            return Err(cancelled());
        }
        if !more {
            break;
        }
    }
    let t_finish = Instant::now();
    // The local search and the smoothing a piece at a time too (each piece a fraction of an
    // iteration on a 256 x 256 map).
    while run.polish_step() {
        yield_now().await;
        if state::cancelled(job.generation) {
            defmt::info!("plan {} cancelled while finishing", job.id);
            return Err(cancelled());
        }
    }
    // What the run leaves in the storage for the next warm start to repair rather than rebuild
    // (its pruning marks and route links), recorded only now that it is complete.
    run.keep(&mut memory);
    state::set_colony(memory);
    let plan = run.finish()?;
    let t_end = Instant::now();
    let ticks = t_end.saturating_duration_since(t0).as_ticks();
    defmt::info!(
        "plan {}: {} iterations, length {}, {} waypoints, {} ticks (new {}, steps {}, finish {})",
        job.id,
        plan.iterations,
        plan.length,
        plan.waypoints().len(),
        ticks,
        t_new.saturating_duration_since(t0).as_ticks(),
        in_steps,
        t_end.saturating_duration_since(t_finish).as_ticks()
    );
    send(job, &plan, ticks, port).await?;
    Ok(ticks)
}

/// Send `plan` as the path reply to `job`, a piece at a time.
async fn send(
    job: &Job,
    plan: &Plan<'_>,
    ticks: u64,
    port: &'static TxPort,
) -> Result<(), ErrorReply> {
    let reply = PathReply {
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
    };
    let mut stream = PathStream::new(job.id, &reply).map_err(|e| {
        defmt::error!("path reply: {}", defmt::Display2Format(&e));
        ErrorReply::with(
            ErrorCode::Internal,
            plan.waypoints().len() as u32,
            plan.directions().len() as u32,
        )
    })?;
    // The frame goes out while the plan's buffers are still borrowed (and with them the map's
    // lock: on the small boards they are in the same arena), so the next plan, and a writer,
    // start once it is sent.
    let mut piece = [0u8; PIECE];
    let mut tx = port.lock().await;
    let mut sent = true;
    while !stream.is_done() {
        let n = stream.fill(&mut piece);
        if tx.write_all(piece.get(..n).unwrap_or(&[])).await.is_err() {
            sent = false; // the host drops the cut frame at the next delimiter
            break;
        }
    }
    drop(tx);
    sent_one(sent);
    Ok(())
}
