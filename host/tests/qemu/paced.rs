//! The firmware under QEMU behind a real serial line: the pacing relay
//! (`ohaca_host::link::relay`) between the host and QEMU's emulated UART, which otherwise moves
//! bytes instantly and buffers megabytes.
//!
//! What is asserted does not depend on the host's speed: lower bounds on time that the relay
//! itself enforces (`n` bytes take at least `n * 10 / baud`), byte counts, and line clocks (bytes
//! that passed on the line). Latencies in wall time are only printed (`-- --nocapture`; they are
//! BENCHMARKS.md's "link" numbers).
//!
//! Like `qemu/e2e.rs`, each test boots its own QEMU; `OHACA_SKIP_QEMU=1` skips them when
//! `qemu-system-arm` is missing.

use crate::qemu;

use std::time::{Duration, Instant};

use ohaca::protocol::Request;
use ohaca::{Params, Point};
use ohaca_host::link::relay::{byte_time, Counters, RelayStream, Stamp, MAX_CATCH_UP};
use ohaca_host::link::{Link, Response};
use ohaca_host::Map;
use qemu::{boot_paced, frames, have_qemu, longest_scenario, maps, Frame, TIMEOUT};

const BAUD: u32 = 115_200;

/// The most bytes QEMU may have written that the line has not delivered: the socket's few
/// (QEMU's end has the kernel's smallest send buffer) plus the byte on the line. Without the
/// relay's minimal buffers it would be the whole reply.
const MAX_BACKLOG: u64 = 32;

fn load(name: &str) -> Map {
    Map::load(maps().join(name)).expect("map")
}

/// The least time `bytes` bytes take on the line, from the first's start to the last's end.
fn line_time(bytes: u64, baud: u32) -> Duration {
    byte_time(baud) * u32::try_from(bytes).expect("bytes")
}

fn ms(d: Duration) -> f64 {
    d.as_secs_f64() * 1e3
}

/// Set the maze and its longest scenario (1,380 raw cells: a Path reply of ~2.5 KB).
fn maze(link: &mut Link<RelayStream>) -> (Point, Point) {
    let lost = link.transport().counters().to_device_dropped();
    if let Err(e) = link.set_map(&load("large/maze-128-128-2.map")) {
        let c = link.transport().counters().snapshot();
        panic!(
            "upload the maze: {e}; {c} ({lost} lost before); strays {:?}",
            link.take_strays()
        );
    }
    longest_scenario("large/maze-128-128-2-random-1.scen")
}

/// An upload is delivered to the device no faster than the line: every byte of it passed the
/// line, none lost, and its first to last byte took at least `(n - 1) * 10 / baud`.
#[test]
fn an_upload_is_paced_toward_the_device() {
    need_qemu!();
    let (_q, mut link, counters) = boot_paced(BAUD);
    link.hello().expect("hello");
    let before = counters.snapshot();
    let t0 = Instant::now();
    let map = load("large/maze-128-128-2.map");
    if let Err(e) = link.set_map(&map) {
        panic!("upload: {e}; {}", counters.snapshot());
    }
    let took = t0.elapsed();
    let last = link.transport().wait_sent(TIMEOUT).expect("sent");
    let sent = counters.snapshot().since(&before);
    let first = counters
        .stamp_of(before.to_device + 1)
        .expect("the upload's first byte's stamp");
    assert_eq!(sent.to_device_dropped, 0, "{sent}");
    assert_eq!(last.to_device - first.to_device + 1, sent.to_device);
    assert!(sent.to_device > 1000, "{sent}");
    let least = line_time(sent.to_device - 1, BAUD);
    let span = last.at - first.at;
    assert!(
        span + MAX_CATCH_UP >= least,
        "{} bytes in {span:?} < {least:?}",
        sent.to_device
    );
    // From the first write to the last byte's delivery: the whole upload's line time at least.
    assert!(last.at - t0 >= line_time(sent.to_device, BAUD));
    assert!(took >= line_time(sent.to_device, BAUD));
    println!(
        "upload of maze-128-128-2 at {BAUD}: {} bytes to the device in {:.1} ms on the line \
         (least {:.1} ms), {:.1} ms with the Acks; {} bytes back",
        sent.to_device,
        ms(span),
        ms(least),
        ms(took),
        sent.to_host
    );
}

/// A long Path reply takes the line's time, and the guest's transmitter waits for the line:
/// QEMU never has more than a few bytes written ahead of it.
#[test]
fn a_long_path_reply_is_paced_and_the_transmitter_waits() {
    need_qemu!();
    let (_q, mut link, counters) = boot_paced(BAUD);
    link.hello().expect("hello");
    let (start, goal) = maze(&mut link);
    link.transport().take_arrivals();
    counters.reset_backlog_max();
    let id = send_plan(&mut link, start, goal);
    let sent = link.transport().wait_sent(TIMEOUT).expect("plan sent");
    let reply = link.wait_for(id, "Plan").expect("the path");
    let Response::Path(path) = reply else {
        panic!("not a path: {reply:?}")
    };
    assert_eq!(path.raw_cells, 1380);
    let backlog = counters.backlog_max();
    let fs = frames(&link.transport().take_arrivals());
    let bytes: u64 = fs.iter().map(|f| f.len).sum();
    let (first, last) = (fs[0].first, fs[fs.len() - 1].last);
    assert!(fs.iter().all(|f| f.id == id), "{fs:?}");
    assert!(bytes > 2000, "{bytes} bytes");
    assert!(last.to_host - first.to_host + 1 >= bytes);
    let least = line_time(bytes - 1, BAUD);
    assert!(
        last.at - first.at + MAX_CATCH_UP >= least,
        "{:?} < {least:?}",
        last.at - first.at
    );
    // The reply cannot start before the request is in: its whole line time after that.
    assert!(last.at - sent.at >= line_time(bytes, BAUD));
    assert!(
        backlog <= MAX_BACKLOG,
        "QEMU had {backlog} bytes written ahead of the line"
    );
    println!(
        "maze-128-128-2 path reply at {BAUD}: {bytes} bytes in {} frame(s), {:.1} ms on the line \
         (least {:.1} ms); at most {backlog} bytes written by QEMU ahead of the line",
        fs.len(),
        ms(last.at - first.at),
        ms(least)
    );
}

/// The drop model: while the firmware plans, a burst larger than its 1 KiB receive ring: what is
/// lost is counted (by the relay when the device stops taking bytes, or by the device in
/// `rx_overruns` when it drops them itself), every other byte is received (`rx_bytes`), and the
/// device keeps serving afterwards. Today's firmware keeps reading its ring while it plans
/// (every plan step yields to the receiver), so at 115200 nothing is lost: the count is printed.
#[test]
fn a_burst_beyond_the_receive_ring_is_lost_counted_and_survived() {
    need_qemu!();
    let (mut q, mut link, counters) = boot_paced(BAUD);
    let info = link.hello().expect("hello");
    let (start, goal) = maze(&mut link);
    let before = link.stats().expect("stats");
    let line0 = counters.snapshot();
    let strays = link.stray_count();
    let slow = Params {
        iterations: 400,
        patience: 0,
        refine_patience: 0,
        seed: 1,
        ..info.defaults
    };
    link.set_params(&slow).expect("params");
    let plan = send_plan(&mut link, start, goal);
    // Let the plan start before the burst (its bytes are ahead of the burst on the line).
    link.transport().wait_sent(TIMEOUT).expect("plan sent");
    std::thread::sleep(Duration::from_millis(50));
    // Empty frames (zero bytes) only: whatever the device keeps of them, it answers nothing.
    let burst = vec![0u8; 4096];
    let t0 = Instant::now();
    link.send_raw(&burst).expect("burst");
    link.transport().wait_sent(TIMEOUT).expect("burst sent");
    let burst_time = t0.elapsed();
    let reply = link.wait_for(plan, "Plan").expect("the plan's reply");
    let planned = t0.elapsed();
    let hello = link.hello().expect("hello after the burst");
    assert_eq!(hello.board, info.board);
    let after = link.stats().expect("stats");
    let line = counters.snapshot().since(&line0);
    let relay_lost = line.to_device_dropped;
    let device_lost = u64::from(after.rx_overruns - before.rx_overruns);
    let device_got = u64::from(after.rx_bytes - before.rx_bytes);
    println!(
        "burst of {} bytes at {BAUD} during a plan ({:.0} ms on the line, plan answered {:.0} ms \
         after the burst began: {}): relay lost {relay_lost}, device counted {device_lost} \
         overruns, received {device_got} of {} bytes on the line",
        burst.len(),
        ms(burst_time),
        ms(planned),
        reply.kind(),
        line.to_device
    );
    // Every byte that crossed the line was received, or lost and counted by one side.
    assert!(
        device_got + device_lost + relay_lost >= line.to_device,
        "{line}: {device_got} received"
    );
    assert!(device_got <= line.to_device_delivered(), "{line}");
    assert!(q.is_running());
    assert_eq!(link.stray_count(), strays, "{:?}", link.take_strays());
}

/// The numbers of BENCHMARKS.md's link section and PROTOCOL.md's times, at 115200 and 921600:
/// Hello's round trip, the maze's upload, its Path reply on the line (in parts), a Stats sent
/// just after the reply starts and a Cancel during the serpentine's: how long until their
/// answers. Printed; only line-enforced bounds asserted.
#[test]
fn link_latencies_at_115200_and_921600() {
    need_qemu!();
    for baud in [115_200, 921_600] {
        latencies(baud);
    }
}

fn latencies(baud: u32) {
    let (_q, mut link, counters) = boot_paced(baud);
    link.hello().expect("hello");
    // Hello's round trip, the best of 5.
    let mut rtt = Duration::MAX;
    let mut line_bytes = 0;
    for _ in 0..5 {
        let s0 = counters.snapshot();
        let t0 = Instant::now();
        link.hello().expect("hello");
        let t = t0.elapsed();
        let d = counters.snapshot().since(&s0);
        line_bytes = d.to_device + d.to_host;
        assert!(t >= line_time(line_bytes, baud));
        rtt = rtt.min(t);
    }
    let t_up = Instant::now();
    let (start, goal) = maze(&mut link);
    let upload = t_up.elapsed();
    let plan = plan_until_it_answers(&mut link, &counters, start, goal);
    let stats = link.send(&Request::Stats).expect("send Stats");
    let sent = link.transport().wait_sent(TIMEOUT).expect("Stats sent");
    link.wait_for(plan, "Plan").expect("path");
    link.wait_for(stats, "Stats").expect("stats");
    let fs = frames(&link.transport().take_arrivals());
    let path: Vec<&Frame> = fs.iter().filter(|f| f.id == plan).collect();
    let answer = fs.iter().find(|f| f.id == stats).expect("the Stats frame");
    let path_bytes: u64 = path.iter().map(|f| f.len).sum();
    let (p0, p1) = (path[0].first, path[path.len() - 1].last);
    assert!(p1.at - p0.at + MAX_CATCH_UP >= line_time(path_bytes - 1, baud));
    let wait_bytes = answer.first.to_host.saturating_sub(sent.to_host);
    let wait = answer.first.at.saturating_duration_since(sent.at);
    println!(
        "{baud} baud: Hello round trip {:.2} ms ({line_bytes} bytes on the line, least {:.2} ms); \
         maze-128-128-2 Path reply {path_bytes} bytes in {} frame(s), {:.1} ms on the line; \
         Stats sent {} bytes into it: answered after {wait_bytes} more host-bound bytes, \
         {:.1} ms ({} {} bytes)",
        ms(rtt),
        ms(line_time(line_bytes, baud)),
        path.len(),
        ms(p1.at - p0.at),
        sent.to_host - p0.to_host + 1,
        ms(wait),
        answer.kind,
        answer.len,
    );
    // A Cancel while the serpentine's 2,014-step path goes out in parts.
    let (plan, _, _) = long_path_streaming(&mut link, &counters);
    let cancel = link.send(&Request::Cancel).expect("send Cancel");
    let sent = link.transport().wait_sent(TIMEOUT).expect("Cancel sent");
    link.wait_for(cancel, "Cancel").expect("ack");
    link.wait_for(plan, "Plan").expect("cancelled");
    let fs = frames(&link.transport().take_arrivals());
    let ack = fs.iter().find(|f| f.id == cancel).expect("the Ack");
    println!(
        "{baud} baud: maze-128-128-2 upload with its Acks {:.1} ms; Cancel \
         during a 2,014-step path in parts answered after {} host-bound bytes, {:.1} ms",
        ms(upload),
        ack.first.to_host.saturating_sub(sent.to_host),
        ms(ack.last.at.saturating_duration_since(sent.at)),
    );
    assert_eq!(counters.to_device_dropped(), 0);
    check_counters(&counters);
}

fn check_counters(c: &Counters) {
    assert!(
        c.backlog_max() <= MAX_BACKLOG,
        "backlog {}",
        c.backlog_max()
    );
    assert!(!c.device_closed());
}

// ---- long paths in parts: nothing waits behind them (protocol 10) -----------------------------

/// 50 ms of the line at 115,200 baud, in bytes: the most host-bound bytes a small reply may wait
/// behind once its request is in (issue 30: "a Cancel answered within 50 ms of its last byte").
const FIFTY_MS: u64 = 576;

/// A serpentine of corridors 62 cells long: its one way from the top-left corner to the end of
/// the last corridor is 2,014 steps, near the F411's 2,047; its reply is about 2.4 KB in 13
/// parts (13 x 18.5 ms at 115,200 baud).
fn serpentine() -> (Map, Point, Point) {
    serpentine_of(62, 63)
}

/// Corridors `w` cells long, in the odd rows' walls a gap at alternate ends: a way of
/// `(h + 1) / 2 * (w - 1) + h - 1` steps from (0, 0) to the end of the last corridor (`h` odd).
fn serpentine_of(w: u16, h: u16) -> (Map, Point, Point) {
    let map = Map::from_fn(w, h, |x, y| {
        // Odd rows are walls with a gap at the right end, then the left, then the right...
        y % 2 == 1 && x != if (y / 2) % 2 == 0 { w - 1 } else { 0 }
    });
    // The corridors run right, left, right...: the last ends at x = 0 if their count is even.
    let end = if (h / 2) % 2 == 1 { 0 } else { w - 1 };
    (map, Point::new(0, 0), Point::new(end, h - 1))
}

/// Plan the serpentine's way and wait for the first byte of its reply on the line; returns the
/// plan's id and the parameters it was planned with.
fn long_path_streaming(link: &mut Link<RelayStream>, counters: &Counters) -> (u32, Params, Map) {
    long_path_on(link, counters, serpentine())
}

/// [`long_path_streaming`] on another serpentine.
fn long_path_on(
    link: &mut Link<RelayStream>,
    counters: &Counters,
    (map, start, goal): (Map, Point, Point),
) -> (u32, Params, Map) {
    let info = link.info().expect("hello first").clone();
    link.set_map(&map).expect("upload the serpentine");
    let plan = plan_until_it_answers(link, counters, start, goal);
    (
        plan,
        Params {
            seed: 1,
            ..info.defaults
        },
        map,
    )
}

/// Send a plan (seed 1) without waiting; returns its id.
fn send_plan(link: &mut Link<RelayStream>, start: Point, goal: Point) -> u32 {
    link.send(&Request::Plan {
        start,
        goal,
        seed: Some(1),
    })
    .expect("send the plan")
}

/// Send a plan (seed 1) and wait for the first byte of its answer on the line (what arrived
/// before is dropped); returns its id.
fn plan_until_it_answers(
    link: &mut Link<RelayStream>,
    counters: &Counters,
    start: Point,
    goal: Point,
) -> u32 {
    link.transport().take_arrivals();
    let base = counters.to_host_line();
    let plan = send_plan(link, start, goal);
    let t = Instant::now();
    while counters.to_host_line() == base {
        assert!(t.elapsed() < TIMEOUT, "no reply to the plan");
        std::thread::sleep(Duration::from_micros(200));
    }
    plan
}

/// A wall cell of every serpentine (row 1 is a wall): blocking it again changes the map's bits
/// nothing, so the path in flight stays the answer.
const WALL_CELL: Point = Point::new(5, 1);

/// Send a Stats, then a SetCells blocking [`WALL_CELL`]; their ids and when each was delivered.
fn stats_and_a_cell_update(link: &mut Link<RelayStream>) -> (u32, Stamp, u32, Stamp) {
    let stats = link.send(&Request::Stats).expect("send Stats");
    let s1 = link.transport().wait_sent(TIMEOUT).expect("Stats sent");
    let update = link
        .send(&Request::SetCells {
            blocked: true,
            cells: ohaca::protocol::Waypoints::Points(&[WALL_CELL]),
        })
        .expect("send SetCells");
    let s2 = link.transport().wait_sent(TIMEOUT).expect("SetCells sent");
    (stats, s1, update, s2)
}

/// Host-bound bytes between a request's last byte reaching the device and its answer's first.
fn waited(frames: &[Frame], id: u32, sent: Stamp) -> u64 {
    let f = frames
        .iter()
        .find(|f| f.id == id)
        .unwrap_or_else(|| panic!("no reply to {id}: {frames:?}"));
    f.first.to_host.saturating_sub(sent.to_host)
}

/// A Stats and a SetCells sent while a 2,014-step path goes out in parts are answered between
/// its parts, within 50 ms of the line each; the cell update does not stop the path, which is
/// the host core's, bit for bit.
#[test]
fn stats_and_a_cell_update_pass_a_long_path() {
    need_qemu!();
    let (_q, mut link, counters) = boot_paced(BAUD);
    link.hello().expect("hello");
    let (plan, params, map) = long_path_streaming(&mut link, &counters);
    let (stats, s1, update, s2) = stats_and_a_cell_update(&mut link);
    let path = link.wait_for(plan, "Plan").expect("the path");
    assert_eq!(
        link.wait_for(stats, "Stats").expect("stats").kind(),
        "Stats"
    );
    assert_eq!(
        link.wait_for(update, "SetCells").expect("ack"),
        Response::Ack
    );
    let fs = frames(&link.transport().take_arrivals());
    let parts = fs.iter().filter(|f| f.id == plan).count();
    let (w1, w2) = (waited(&fs, stats, s1), waited(&fs, update, s2));
    println!(
        "2,014-step path in {parts} parts at {BAUD}: Stats answered after {w1} host-bound bytes, \
         SetCells after {w2} (50 ms = {FIFTY_MS})"
    );
    assert!(parts >= 10, "{fs:?}");
    assert!(w1 <= FIFTY_MS && w2 <= FIFTY_MS, "{w1}, {w2}: {fs:?}");
    // Both answers came between the parts: some of the path arrived after each.
    let last_part = fs
        .iter()
        .filter(|f| f.id == plan)
        .map(|f| f.last.to_host)
        .max();
    for id in [stats, update] {
        let f = fs.iter().find(|f| f.id == id).expect("answer");
        assert!(
            Some(f.last.to_host) < last_part,
            "{id} after the whole path"
        );
    }
    let Response::Path(path) = path else {
        panic!("not a path: {path:?}")
    };
    let (_, start, goal) = serpentine();
    let core = qemu::core_plan(&map, start, goal, &params).expect("the core plans it");
    qemu::assert_core_path("serpentine", &core, &path);
    assert_eq!(path.raw_cells, 2015);
    let s = link.stats().expect("stats");
    assert_eq!((s.parted, s.replies_dropped, s.rx_overruns), (1, 0, 0));
}

/// A Cancel sent while a long path goes out is answered within 50 ms of the line, the path stops
/// (no part after the Cancel's answer: `qemu/responsive.rs` repeats it 200 times) and its plan
/// gets `Cancelled`;
/// the device then plans and answers as before.
#[test]
fn a_cancel_stops_a_long_path_at_once() {
    need_qemu!();
    let (_q, mut link, counters) = boot_paced(BAUD);
    link.hello().expect("hello");
    let (plan, _, _) = long_path_streaming(&mut link, &counters);
    let cancel = link.send(&Request::Cancel).expect("send Cancel");
    let sent = link.transport().wait_sent(TIMEOUT).expect("Cancel sent");
    assert_eq!(link.wait_for(cancel, "Cancel").expect("ack"), Response::Ack);
    let r = link.wait_for(plan, "Plan").expect("the plan's answer");
    assert_eq!(
        r,
        Response::Error(ohaca::protocol::ErrorReply::new(
            ohaca::protocol::ErrorCode::Cancelled
        ))
    );
    let fs = frames(&link.transport().take_arrivals());
    let w = waited(&fs, cancel, sent);
    let ack = fs.iter().find(|f| f.id == cancel).expect("the Ack");
    let after: Vec<&Frame> = fs
        .iter()
        .filter(|f| f.id == plan && f.kind == "PathPart" && f.first.to_host > ack.first.to_host)
        .collect();
    let parts = fs.iter().filter(|f| f.kind == "PathPart").count();
    println!(
        "Cancel during a 2,014-step path at {BAUD}: answered after {w} host-bound bytes \
         (50 ms = {FIFTY_MS}); {parts} parts sent, {} after the Ack",
        after.len()
    );
    assert!(w <= FIFTY_MS, "{w}: {fs:?}");
    assert!(after.is_empty(), "{after:?}");
    assert!(parts < 13, "the whole path went out: {fs:?}");
    let s = link.stats().expect("stats");
    assert_eq!((s.cancelled, s.replies_dropped, s.rx_overruns), (1, 0, 0));
    // It serves on: the same plan again, whole.
    let (_, start, goal) = serpentine();
    let again = link.plan(start, goal, Some(1)).expect("plan again");
    assert_eq!(again.raw_cells, 2015);
}

/// Within the window nothing is lost; beyond it the device keeps serving and counts what it
/// dropped. 8 Stats at once are all answered; 160 at once (1,120 bytes in 97 ms at 115,200,
/// their replies 1.4 s) overflow the 8-deep reply queue: every one is answered or counted in
/// `replies_dropped`, exactly, and Hello is answered after.
#[test]
fn the_window_holds_and_beyond_it_drops_are_counted() {
    need_qemu!();
    let (_q, mut link, counters) = boot_paced(BAUD);
    let info = link.hello().expect("hello");
    assert_eq!(
        (info.capacity.window, info.capacity.window_bytes),
        (8, 1024)
    );
    let before = link.stats().expect("stats");
    // Within the window: 8 at once, every one answered.
    let ids: Vec<u32> = (0..8)
        .map(|_| link.send(&Request::Stats).expect("send"))
        .collect();
    for id in ids {
        assert_eq!(link.wait_for(id, "Stats").expect("stats").kind(), "Stats");
    }
    let mid = link.stats().expect("stats");
    assert_eq!(mid.replies_dropped, before.replies_dropped);
    // Beyond it: 160 Stats in one write, ids 1000.. (raw: `Link::send` would keep the window).
    let mut burst = Vec::new();
    for id in 1000..1160u32 {
        let mut buf = [0u8; ohaca::protocol::MAX_REQUEST_WIRE];
        let n = ohaca::protocol::encode_request(id, &Request::Stats, &mut buf).expect("encode");
        burst.extend_from_slice(&buf[..n]);
    }
    let strays = link.stray_count();
    link.send_raw(&burst).expect("burst");
    link.transport().wait_sent(TIMEOUT).expect("burst sent");
    // Wait until the line back is quiet (the queued replies are out), so the next request's
    // reply finds room; how long that takes decides nothing asserted.
    let mut quiet = (counters.to_host_line(), Instant::now());
    while quiet.1.elapsed() < Duration::from_millis(300) {
        std::thread::sleep(Duration::from_millis(20));
        if counters.to_host_line() != quiet.0 {
            quiet = (counters.to_host_line(), Instant::now());
        }
    }
    link.hello().expect("hello after the burst");
    assert!(link.take_strays().iter().all(
        |s| matches!(s, ohaca_host::link::Stray::Reply { id, .. } if (1000..1160).contains(id))
    ));
    let answered = (link.stray_count() - strays) as u32;
    let after = link.stats().expect("stats");
    let dropped = after.replies_dropped - mid.replies_dropped;
    let lost = after.rx_overruns - mid.rx_overruns;
    println!(
        "160 Stats in one burst at {BAUD}: {answered} answered, {dropped} replies dropped, \
         {lost} bytes lost"
    );
    assert_eq!(lost, 0, "the receiver kept up with the line");
    assert!(dropped > 0, "160 replies of 100 bytes cannot all queue");
    assert_eq!(answered + dropped, 160);
}

/// The STM32H743's twin sends a 16,318-step path (a serpentine of 64 corridors of 254 cells,
/// near its 16,384): about 19 KB in 100 parts. A Stats and a SetCells sent during it are answered
/// within 50 ms of the line each and the path is the host core's (`--board h743`); then a Cancel
/// during the same plan again stops it at once.
#[test]
fn the_twins_16000_step_path_lets_replies_pass_and_stops_at_a_cancel() {
    need_qemu!();
    let (_q, mut link, counters) = qemu::boot_paced_with(qemu::twin_firmware(), BAUD);
    let info = link.hello().expect("hello");
    assert_eq!(
        info.capacity.max_steps as usize,
        ohaca::board::H743.max_steps
    );
    let (w, h) = (254u16, 127u16);
    let (plan, params, map) = long_path_on(&mut link, &counters, serpentine_of(w, h));
    let (stats, s1, update, s2) = stats_and_a_cell_update(&mut link);
    link.set_timeout(TIMEOUT);
    let path = link.wait_for(plan, "Plan").expect("the path");
    link.wait_for(stats, "Stats").expect("stats");
    assert_eq!(
        link.wait_for(update, "SetCells").expect("ack"),
        Response::Ack
    );
    let fs = frames(&link.transport().take_arrivals());
    let parts = fs.iter().filter(|f| f.id == plan).count();
    let bytes: u64 = fs.iter().filter(|f| f.id == plan).map(|f| f.len).sum();
    let (w1, w2) = (waited(&fs, stats, s1), waited(&fs, update, s2));
    let Response::Path(path) = path else {
        panic!("not a path: {path:?}")
    };
    println!(
        "twin: {}-step path in {parts} parts ({bytes} bytes) at {BAUD}: Stats answered after \
         {w1} host-bound bytes, SetCells after {w2} (50 ms = {FIFTY_MS})",
        path.raw_cells - 1
    );
    assert_eq!(
        path.raw_cells as usize,
        usize::from(h).div_ceil(2) * (usize::from(w) - 1) + usize::from(h)
    );
    assert!(w1 <= FIFTY_MS && w2 <= FIFTY_MS, "{w1}, {w2}");
    let (_, start, goal) = serpentine_of(w, h);
    let core = qemu::core_plan_on(ohaca::board::H743, &map, start, goal, &params)
        .expect("the core plans it");
    qemu::assert_core_path("the twin's serpentine", &core, &path);
    // The same plan again (uploaded again: the cell update above is undone), cancelled while it
    // goes out.
    let (plan, _, _) = long_path_on(&mut link, &counters, serpentine_of(w, h));
    let cancel = link.send(&Request::Cancel).expect("send Cancel");
    let sent = link.transport().wait_sent(TIMEOUT).expect("Cancel sent");
    assert_eq!(link.wait_for(cancel, "Cancel").expect("ack"), Response::Ack);
    assert_eq!(
        link.wait_for(plan, "Plan").expect("cancelled"),
        Response::Error(ohaca::protocol::ErrorReply::new(
            ohaca::protocol::ErrorCode::Cancelled
        ))
    );
    let fs = frames(&link.transport().take_arrivals());
    let w3 = waited(&fs, cancel, sent);
    println!("twin: Cancel during it answered after {w3} host-bound bytes");
    assert!(w3 <= FIFTY_MS, "{w3}");
    // No part follows the Ack (issue 38: a Cancel is final).
    let ack = fs.iter().find(|f| f.id == cancel).expect("the Ack");
    let after = fs
        .iter()
        .filter(|f| f.id == plan && f.kind == "PathPart" && f.first.to_host > ack.first.to_host)
        .count();
    assert_eq!(after, 0, "{after} parts after the Ack");
    let s = link.stats().expect("stats");
    assert_eq!((s.parted, s.cancelled, s.replies_dropped), (2, 1, 0));
}
