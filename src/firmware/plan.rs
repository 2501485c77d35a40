//! The planning task: takes plan requests from the queue and runs them one iteration at a time,
//! yielding to the executor after every iteration so frames keep arriving and `Cancel` works.

use core::sync::atomic::Ordering;

use embassy_futures::yield_now;
use embassy_time::Instant;

use ohaca::grid::Grid;
use ohaca::planner::{Run, Storage};
use ohaca::protocol::{encode_reply, ErrorCode, ErrorReply, PathReply, Reply, Waypoints};

use super::state::{self, count, Job, Out, CELLS, JOBS, MAP, OUT, PATH_FRAME, PLANNING};

#[embassy_executor::task]
pub async fn planner_task(storage: &'static mut Storage<CELLS>) {
    loop {
        let job = JOBS.receive().await;
        PLANNING.store(true, Ordering::Relaxed);
        let result = plan(storage, &job).await;
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
    }
}

/// Run one job and send its path; returns the ticks it took.
async fn plan(storage: &mut Storage<CELLS>, job: &Job) -> Result<u64, ErrorReply> {
    let cancelled = || ErrorReply::new(ErrorCode::Cancelled);
    if state::cancelled(job.generation) {
        return Err(cancelled());
    }
    // A private copy: the receiver may switch maps while this plan runs (and cancels it then).
    let map = MAP
        .lock(|m| m.get())
        .ok_or(ErrorReply::new(ErrorCode::NoMap))?;
    let grid = Grid::new(map.width, map.height, &map.bits)?;
    let t0 = Instant::now();
    let mut run = Run::new(&grid, job.start, job.goal, &job.params, storage.workspace())?;
    loop {
        let more = run.step();
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
    let plan = run.finish()?;
    let ticks = t0.elapsed().as_ticks();
    defmt::info!(
        "plan {}: {} iterations, length {}, {} waypoints, {} ticks",
        job.id,
        plan.iterations,
        plan.length,
        plan.waypoints().len(),
        ticks
    );
    let reply = Reply::Path(PathReply {
        raw_length: plan.raw_length,
        length: plan.length,
        turns: plan.turns,
        iterations: plan.iterations,
        best_iteration: plan.best_iteration,
        moves: plan.moves,
        ticks,
        raw_cells: u32::try_from(plan.raw_len()).unwrap_or(u32::MAX),
        waypoints: Waypoints::Points(plan.waypoints()),
        directions: plan.directions(),
    });
    // Waits until the transmitter has sent the previous path.
    let mut frame = PATH_FRAME.lock().await;
    match encode_reply(job.id, &reply, &mut frame.buf) {
        Ok(n) => {
            frame.len = n;
            OUT.send(Out::Frame(frame)).await;
            Ok(ticks)
        }
        Err(e) => {
            defmt::error!("path reply: {}", defmt::Display2Format(&e));
            Err(ErrorReply::with(
                ErrorCode::Internal,
                plan.waypoints().len() as u32,
                plan.directions().len() as u32,
            ))
        }
    }
}
