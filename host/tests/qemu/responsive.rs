//! The firmware answers at every moment and a `Cancel` is final (issue 38), under QEMU behind the
//! 115200 pacing relay (`ohaca_host::link::relay`):
//!
//! * [`a_cancel_is_final`]: a plan and a `Stats` + `Cancel` sent at a different point of its
//!   answer each time (during the plan, between and inside its parts, after it), 200 times on
//!   one boot: no frame of the path ever starts after the `Cancel`'s `Ack`.
//! * [`requests_are_answered_while_a_plan_runs`]: `Stats` sent one after another while a plan
//!   runs are each answered within [`BOUND`] device instructions of their frame's last byte, and
//!   a `Cancel` stops the plan within as many. Measured in device instructions, not wall time:
//!   QEMU runs with `-icount shift=0` (a tick is 1000 instructions) and the QEMU board logs when
//!   each request's frame ended and when each small reply went to the UART (`request ID in at
//!   TICK`, `reply ID out at TICK`, `src/firmware/board/mod.rs`), read back with `defmt-print`.
//!   The bound holds because every planner piece is at most a million instructions
//!   (`Run::poll`, issue 38's first item): on complex-26, on a maze whose iterations ran 33-36 M
//!   in one piece before, and on New York.
//!
//! Each test boots its own QEMU; `OHACA_SKIP_QEMU=1` skips them when `qemu-system-arm` is
//! missing.

use crate::qemu;

use std::time::{Duration, Instant};

use ohaca::protocol::{ErrorCode, ErrorReply, Request};
use ohaca::{Params, Point};
use ohaca_host::link::relay::Counters;
use ohaca_host::link::Response;
use ohaca_host::Map;
use qemu::{boot_paced, frames, have_qemu, maps, TIMEOUT};

const BAUD: u32 = 115_200;

/// Device ticks (1 µs: 1000 instructions under `-icount shift=0`) between a request's last byte
/// and its answer going to the UART, and between a `Cancel`'s last byte and its plan's
/// `Cancelled` going to the UART: 2 M instructions, 20 ms at 100 MHz (issue 38).
const BOUND: u64 = 2_000;

/// `Stats` answered while the plan runs, each a sample.
const SAMPLES: usize = 30;

/// Corridors `w` cells long, in the odd rows' walls a gap at alternate ends: one way of
/// `(h + 1) / 2 * (w - 1) + h - 1` steps from (0, 0) to the end of the last corridor (`h` odd).
fn serpentine_of(w: u16, h: u16) -> (Map, Point, Point) {
    let map = Map::from_fn(w, h, |x, y| {
        y % 2 == 1 && x != if (y / 2) % 2 == 0 { w - 1 } else { 0 }
    });
    let end = if (h / 2) % 2 == 1 { 0 } else { w - 1 };
    (map, Point::new(0, 0), Point::new(end, h - 1))
}

/// Wait until the host-bound line has carried `n` bytes more than `base`, or `base + n` is
/// beyond what arrives (the answer ended): then return at once after a quiet moment.
fn wait_host_bytes(counters: &Counters, base: u64, n: u64) {
    let t = Instant::now();
    let mut last = (counters.to_host_line(), Instant::now());
    while counters.to_host_line() < base + n {
        std::thread::sleep(Duration::from_micros(100));
        let now = counters.to_host_line();
        if now != last.0 {
            last = (now, Instant::now());
        } else if now > base && last.1.elapsed() > Duration::from_millis(200) {
            return;
        }
        assert!(t.elapsed() < TIMEOUT, "no reply to the plan");
    }
}

/// Cancel is final: 200 plans on one boot, each answered in 3 parts, with a `Stats` and a
/// `Cancel` sent together after a different number of the answer's bytes each time (0 to 250 of
/// its 489: during the plan, between and inside parts, after the last part was committed). No `Path` or `PathPart`
/// of the plan ever starts after the `Ack`; the plan's answer is `Cancelled` or the whole path;
/// the device counts them exactly, and each `Stats` (answered before, between or after the parts)
/// counts in `tx_frames` exactly the frames before it on the line.
///
/// The `Stats` in front makes the old race likely: the transmitter holds it while the planner,
/// past its stop check, waits for it; the `Ack` queued meanwhile went out first, then the part.
#[test]
fn a_cancel_is_final() {
    need_qemu!();
    const ROUNDS: u64 = 200;
    const SPAN: u64 = 251;
    let t0 = Instant::now();
    let (_q, mut link, counters) = boot_paced(BAUD);
    let info = link.hello().expect("hello");
    let (map, start, goal) = serpentine_of(30, 21);
    link.set_map(&map).expect("upload the serpentine");
    // Short plans: the colony has one corridor to find.
    let quick = Params {
        ants: 4,
        iterations: 4,
        seed: 1,
        ..info.defaults
    };
    link.set_params(&quick).expect("params");
    // The whole answer once: its bytes on the line.
    link.transport().take_arrivals();
    let path = link.plan(start, goal, Some(1)).expect("the path");
    assert_eq!(path.raw_cells, 11 * 29 + 21);
    let whole = frames(&link.transport().take_arrivals());
    let total: u64 = whole.iter().map(|f| f.len).sum();
    assert_eq!(whole.len(), 3, "{whole:?}");
    let before = link.stats().expect("stats");
    // Reply frames the device has sent so far: those before `before` and `before` itself (no
    // other reply is outstanding).
    let mut sent = before.tx_frames + 1;
    let last = frames(&link.transport().take_arrivals())
        .last()
        .map(|f| f.id);
    assert_eq!(last, Some(link.next_id() - 1), "the Stats reply came last");
    let (mut stopped, mut unstarted, mut complete) = (0u32, 0u32, 0u32);
    for round in 0..ROUNDS {
        // 0, 7, 14, ... host-bound bytes into the answer, wrapping at SPAN: the last part is in
        // the transmitter's 256-byte buffer once about 190 bytes are out, so the later offsets
        // find the path complete.
        let k = (round * 7) % SPAN;
        link.transport().take_arrivals();
        let base = counters.to_host_line();
        let plan = link
            .send(&Request::Plan {
                start,
                goal,
                seed: Some(1),
            })
            .expect("send the plan");
        if k > 0 {
            wait_host_bytes(&counters, base, k);
        }
        let stats = link.send(&Request::Stats).expect("send Stats");
        let cancel = link.send(&Request::Cancel).expect("send Cancel");
        assert_eq!(link.wait_for(cancel, "Cancel").expect("ack"), Response::Ack);
        let answer = link.wait_for(plan, "Plan").expect("the plan's answer");
        let Response::Stats(counted) = link.wait_for(stats, "Stats").expect("stats") else {
            panic!("round {round}: not a Stats reply")
        };
        let fs = frames(&link.transport().take_arrivals());
        // The Stats counts exactly the frames before it on the line (a part just before it
        // included), not itself.
        for f in &fs {
            if f.id == stats {
                assert_eq!(counted.tx_frames, sent, "round {round}: tx_frames: {fs:?}");
            }
            sent += 1;
        }
        let ack = fs.iter().find(|f| f.id == cancel).expect("the Ack's frame");
        let ours: Vec<_> = fs
            .iter()
            .filter(|f| f.id == plan && matches!(f.kind, "Path" | "PathPart"))
            .collect();
        let late: Vec<_> = ours
            .iter()
            .filter(|f| f.first.to_host > ack.first.to_host)
            .collect();
        assert!(
            late.is_empty(),
            "round {round} (Cancel after {k} bytes): {} path frame(s) after the Ack: {fs:?}",
            late.len()
        );
        match answer {
            Response::Path(p) => {
                assert_eq!(p.raw_cells, path.raw_cells, "round {round}");
                complete += 1;
            }
            Response::Error(e) if e == ErrorReply::new(ErrorCode::Cancelled) => {
                if ours.is_empty() {
                    unstarted += 1;
                } else {
                    stopped += 1;
                }
            }
            other => panic!("round {round}: {other:?}"),
        }
    }
    let after = link.stats().expect("stats");
    println!(
        "{ROUNDS} plans of a {total}-byte answer at {BAUD}, each with a Stats and a Cancel after \
         0..{SPAN} of its bytes: {stopped} stopped between parts, {unstarted} cancelled before \
         any part, {complete} complete; no path frame after an Ack; {:.1} s",
        t0.elapsed().as_secs_f64()
    );
    assert_eq!(u64::from(stopped + unstarted + complete), ROUNDS);
    assert!(stopped >= 100, "only {stopped} paths stopped mid-parts");
    assert_eq!(after.cancelled - before.cancelled, stopped + unstarted);
    assert_eq!(after.plans - before.plans, complete);
    assert_eq!((after.replies_dropped, after.rx_overruns), (0, 0));
}

/// One responsiveness run: upload `map`, plan `start` to `goal` with `params`, send `Stats` one
/// after another while it plans (each once the last is answered), then a `Cancel`; returns the
/// device ticks of the [`SAMPLES`] answers given while the plan ran (frame end to reply out) and the
/// `Cancel`'s (its frame end to its plan's `Cancelled` out).
fn while_planning(map: &Map, start: Point, goal: Point, params: &Params) -> (Vec<u64>, u64) {
    let dir = std::env::temp_dir().join(format!("ohaca-responsive-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let log = dir.join(format!("{}x{}.defmt", map.width, map.height));
    let (_q, mut link, _counters) = qemu::boot_paced_icount(BAUD, &log);
    link.hello().expect("hello");
    link.set_map(map).expect("upload");
    link.set_params(params).expect("params");
    let plan = link
        .send(&Request::Plan {
            start,
            goal,
            seed: Some(params.seed),
        })
        .expect("send the plan");
    link.transport().wait_sent(TIMEOUT).expect("plan sent");
    let mut during = Vec::new();
    while during.len() < SAMPLES {
        let id = link.send(&Request::Stats).expect("send Stats");
        match link.wait_for(id, "Stats").expect("stats") {
            Response::Stats(s) if s.planning => during.push(id),
            Response::Stats(s) if s.plans > 0 || s.plan_errors > 0 => {
                panic!(
                    "the plan ended after {} samples: make it longer",
                    during.len()
                )
            }
            Response::Stats(_) => {}
            other => panic!("{other:?}"),
        }
    }
    let cancel = link.send(&Request::Cancel).expect("send Cancel");
    assert_eq!(link.wait_for(cancel, "Cancel").expect("ack"), Response::Ack);
    let answer = link.wait_for(plan, "Plan").expect("the plan's answer");
    assert_eq!(
        answer,
        Response::Error(ErrorReply::new(ErrorCode::Cancelled)),
        "the plan ended before the Cancel: make it longer"
    );
    // The log lines are written before the replies they time: all there now.
    let (ins, outs) = qemu::device_times(&qemu::device_log(&log));
    let _ = std::fs::remove_file(&log);
    let latency = |req: u32, reply: u32| -> u64 {
        let t_in = *ins
            .get(&req)
            .unwrap_or_else(|| panic!("no log of request {req}"));
        let t_out = outs
            .get(&reply)
            .and_then(|v| v.iter().copied().find(|&t| t >= t_in))
            .unwrap_or_else(|| panic!("no log of a reply to {reply}"));
        t_out - t_in
    };
    let answers = during.iter().map(|&id| latency(id, id)).collect();
    (answers, latency(cancel, plan))
}

/// Parameters for a plan that runs long: `iterations` iterations, no early stop, and without
/// the local search (with it, a large map's run stops once the ants settled the corridor).
fn long_plan(iterations: u16) -> Params {
    Params {
        iterations,
        patience: 0,
        refine_patience: 0,
        refine: false,
        seed: 1,
        ..Params::default()
    }
}

fn check(what: &str, (answers, cancel): (Vec<u64>, u64)) {
    let worst = answers.iter().copied().max().unwrap_or(0);
    println!(
        "{what}: {} Stats answered while it planned, the slowest {:.2} M instructions after its \
         last byte (all: {answers:?} ticks); a Cancel stopped it within {:.2} M",
        answers.len(),
        worst as f64 / 1e3,
        cancel as f64 / 1e3
    );
    assert!(worst <= BOUND, "{what}: a Stats waited {worst} ticks");
    assert!(
        cancel <= BOUND,
        "{what}: the Cancel took {cancel} ticks to stop it"
    );
}

/// A plan that runs long (4000 iterations, no early stop) on a 26 x 26 map: answered and
/// cancelled within 2 M instructions.
#[test]
fn requests_are_answered_while_a_plan_runs() {
    need_qemu!();
    let map = Map::load(maps().join("complex-26.map")).expect("map");
    let (start, goal) = (Point::new(0, 0), Point::new(25, 25));
    let params = long_plan(4000);
    check("complex-26", while_planning(&map, start, goal, &params));
}

/// The same on New York (512 x 512), issue 38's case: before the planner ran in pieces of at
/// most a million instructions (`Run::poll`) its setup piece and iterations ran 13-21 M, and an
/// answer waited up to 19.7 M.
#[test]
fn requests_are_answered_while_new_york_plans() {
    need_qemu!();
    let map = Map::load(maps().join("large/NewYork_0_512.map")).expect("map");
    let params = long_plan(400);
    check(
        "NewYork_0_512",
        while_planning(&map, Point::new(509, 443), Point::new(0, 9), &params),
    );
}

/// The same on maze-128-128-2's longest scenario, whose whole iterations (33-36 M instructions)
/// were one piece before `Run::poll` and made an answer wait 36 M; with a long walk's tightening
/// in one piece (1.27 M) the slowest answer still took 2.33 M, with the tightening in pieces
/// 1.38 M.
#[test]
fn requests_are_answered_while_a_maze_plans() {
    need_qemu!();
    let map = Map::load(maps().join("large/maze-128-128-2.map")).expect("map");
    let (start, goal) = qemu::longest_scenario("large/maze-128-128-2-random-1.scen");
    let params = long_plan(400);
    check("maze-128-128-2", while_planning(&map, start, goal, &params));
}

/// The QEMU board's receive side, measured (docs/FIRMWARE.md, "Receiving"): while New York
/// plans (planner pieces of 7-20 M instructions today), a burst of empty frames as large as the
/// window (1,024 bytes) and then one of 8,192 bytes, each at the line's rate. Within the window
/// nothing is lost. Beyond it, what is lost is counted: by the firmware (`rx_overruns`, its
/// 1 KiB ring full) or by the relay (QEMU's socket full: QEMU's UART model holds bytes back in
/// its character device while the firmware has not read the last, which a board's UART does
/// not). Printed: what QEMU held back at most, and who dropped what.
#[test]
fn the_receive_side_within_and_beyond_the_window() {
    need_qemu!();
    let (mut q, mut link, counters) = boot_paced(BAUD);
    link.hello().expect("hello");
    let map = Map::load(maps().join("large/NewYork_0_512.map")).expect("map");
    link.set_map(&map).expect("upload New York");
    let params = long_plan(4000);
    link.set_params(&params).expect("params");
    let plan = link
        .send(&Request::Plan {
            start: Point::new(509, 443),
            goal: Point::new(0, 9),
            seed: Some(1),
        })
        .expect("send the plan");
    link.transport().wait_sent(TIMEOUT).expect("plan sent");
    for burst in [1024usize, 8192] {
        let before = link.stats().expect("stats");
        assert!(before.planning, "the plan ended: make it longer");
        let line0 = counters.snapshot();
        counters.reset_backlog_max();
        link.send_raw(&vec![0u8; burst]).expect("burst");
        link.transport().wait_sent(TIMEOUT).expect("burst sent");
        // A Stats (after a `00`, should a dropped byte have left a partial frame).
        let after = (0..3)
            .find_map(|_| {
                let _ = link.send_raw(&[0]);
                link.stats().ok()
            })
            .expect("stats after the burst");
        let line = counters.snapshot().since(&line0);
        let relay_lost = line.to_device_dropped;
        let device_lost = u64::from(after.rx_overruns - before.rx_overruns);
        // The Stats request itself is in rx_bytes too.
        let device_got = u64::from(after.rx_bytes - before.rx_bytes);
        println!(
            "burst of {burst} bytes at {BAUD} while New York plans: QEMU held back up to {} \
             bytes; the relay lost {relay_lost} (QEMU's socket full), the firmware dropped \
             {device_lost} (its ring full) and read {device_got}; still planning: {}",
            counters.held_max(),
            after.planning
        );
        assert!(
            device_got + device_lost + relay_lost >= line.to_device,
            "{line}"
        );
        if burst <= 1024 {
            assert_eq!((relay_lost, device_lost), (0, 0), "lost inside the window");
        }
    }
    link.send(&Request::Cancel).expect("cancel");
    let r = link.wait_for(plan, "Plan").expect("the plan's answer");
    assert_eq!(r, Response::Error(ErrorReply::new(ErrorCode::Cancelled)));
    assert!(q.is_running());
}
