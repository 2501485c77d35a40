//! End-to-end tests of the firmware under QEMU (`mps2-an386`) against the host side of the link
//! (`ohaca_host::link`, `ohaca send`).
//!
//! Each test boots its own QEMU (UART0 on a free local TCP port, or on a pty) and kills it when
//! done ([`Qemu`]'s `Drop`). The firmware is built once per run with `cargo build --release` in
//! the workspace root (a no-op when it is up to date; set `OHACA_FIRMWARE=path/to/elf` to use
//! another ELF and skip the build). Without `qemu-system-arm` the tests fail, unless
//! `OHACA_SKIP_QEMU=1` is set: then each prints a `SKIPPED` line and returns. The QEMU helpers are shared with the
//! soak tests (`soak.rs`) in `qemu.rs`.
//!
//! Nothing here asserts on time: every wait is bounded by generous timeouts, and latencies are
//! only printed (`cargo test ... -- --nocapture`).

use crate::qemu;

use std::io::{Read, Write};
use std::net::TcpListener;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use ohaca::protocol::{
    crc32, encode_request, Capacity, ErrorCode, ErrorReply, Request, MAX_CHUNK, MAX_REQUEST_WIRE,
    UNKNOWN_ID,
};
use ohaca::{Algorithm, Params, Point};
use ohaca_host::link::{DevicePath, Link, LinkError, PlanJob, Response, Stray, Transport};
use ohaca_host::{plan_map, Map, PlanReport};
use qemu::{
    assert_core_path, cobs, core_plan, core_plan_steps, expected_errors, frame_of, free_port,
    have_qemu, longest_scenario, maps, Qemu, DEVICE_STEPS, TIMEOUT,
};
use serde_json::Value;

// ---- the host's reference ----------------------------------------------------------------

/// A fixed start/goal pair, or one of a scenario file.
struct Case {
    map: &'static str,
    start: Point,
    goal: Point,
}

/// `maps/README.md`'s fixed pairs plus three scenarios of each Moving AI map (its first two and
/// its longest).
fn cases() -> Vec<Case> {
    let mut out = vec![
        Case {
            map: "simple-18.map",
            start: Point::new(0, 0),
            goal: Point::new(17, 17),
        },
        Case {
            map: "complex-26.map",
            start: Point::new(0, 0),
            goal: Point::new(25, 25),
        },
        Case {
            map: "classic-20.map",
            start: Point::new(0, 0),
            goal: Point::new(19, 19),
        },
    ];
    for (map, scen) in [
        (
            "movingai/random-32-32-10.map",
            "movingai/random-32-32-10-random-1.scen",
        ),
        (
            "movingai/random-32-32-20.map",
            "movingai/random-32-32-20-random-1.scen",
        ),
    ] {
        let text = std::fs::read_to_string(maps().join(scen)).expect("scenario file");
        let rows: Vec<(Point, Point, f64)> = text
            .lines()
            .skip(1)
            .filter_map(|l| {
                let f: Vec<&str> = l.split('\t').collect();
                let n = |i: usize| f.get(i)?.trim().parse::<u16>().ok();
                Some((
                    Point::new(n(4)?, n(5)?),
                    Point::new(n(6)?, n(7)?),
                    f.get(8)?.trim().parse().ok()?,
                ))
            })
            .collect();
        let longest = rows
            .iter()
            .max_by(|a, b| a.2.total_cmp(&b.2))
            .expect("scenarios");
        for &(start, goal, _) in rows.iter().take(2).chain([longest]) {
            out.push(Case { map, start, goal });
        }
    }
    out
}

fn load(name: &str) -> Map {
    Map::load(maps().join(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// `map` on the device with parameters that keep a plan running (60,000 iterations, no early
/// stop), for the tests that act while a plan runs.
fn slow_plans_on<T: Transport>(link: &mut Link<T>, map: &Map) {
    link.set_map(map).expect("set map");
    let slow = Params {
        iterations: 60_000,
        patience: 0,
        refine_patience: 0,
        ..Params::default()
    };
    link.set_params(&slow).expect("set params");
}

/// The device's path must be the host core's, bit for bit.
fn assert_same(what: &str, host: &PlanReport, start: Point, dev: &Result<DevicePath, ErrorReply>) {
    let dev = match dev {
        Ok(p) => p,
        Err(e) => panic!("{what}: device error {e}, host found={}", host.found),
    };
    assert!(host.found, "{what}: host found no path, device did");
    let raw: Vec<[u16; 2]> = dev
        .raw(start)
        .unwrap_or_else(|e| panic!("{what}: {e}"))
        .iter()
        .map(|p| [p.x, p.y])
        .collect();
    let wps: Vec<[u16; 2]> = dev.waypoints.iter().map(|p| [p.x, p.y]).collect();
    assert_eq!(raw, host.raw, "{what}: raw path (directions)");
    assert_eq!(dev.raw_cells as usize, raw.len(), "{what}: raw_cells");
    assert_eq!(wps, host.waypoints, "{what}: waypoints");
    let bits = |v: Option<f32>| v.map(f32::to_bits);
    // The host's report writes the length of a one-cell path as 0, not the core's -0
    // (`output.rs`, `unsigned_zero`); the device sends the core's bits (`core_plan` checks
    // those, in the soak test).
    let unsigned = |v: f32| if v == 0.0 { 0.0 } else { v };
    assert_eq!(
        Some(unsigned(dev.raw_length).to_bits()),
        bits(host.raw_length),
        "{what}: raw_length {} vs {:?}",
        dev.raw_length,
        host.raw_length
    );
    assert_eq!(
        Some(unsigned(dev.length).to_bits()),
        bits(host.length),
        "{what}: length {} vs {:?}",
        dev.length,
        host.length
    );
    assert_eq!(Some(dev.turns), host.turns, "{what}: turns");
    assert_eq!(Some(dev.iterations), host.iterations, "{what}: iterations");
    assert_eq!(
        Some(dev.best_iteration),
        host.best_iteration,
        "{what}: best_iteration"
    );
    assert_eq!(Some(dev.moves), host.moves, "{what}: moves");
}

fn error_code<T: std::fmt::Debug>(r: Result<T, LinkError>) -> ErrorReply {
    match r {
        Err(LinkError::Device { error, .. }) => error,
        other => panic!("expected a device error, got {other:?}"),
    }
}

// ---- tests -------------------------------------------------------------------------------

#[test]
fn device_paths_are_bit_identical_to_the_host_core() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    let info = link.hello().expect("hello");
    let defaults = Params::default();
    assert_eq!(
        info.defaults, defaults,
        "the device's defaults are not the host core's: were the firmware and this test built \
         from the same sources? (src/ changed in between?)"
    );
    link.set_params(&defaults).expect("set params");
    let cases = cases();
    let mut current = "";
    let mut checked = 0;
    for case in &cases {
        let map = load(case.map);
        if case.map != current {
            link.set_map(&map).expect("set map");
            current = case.map;
        }
        let jobs: Vec<PlanJob> = (1..=3)
            .map(|seed| PlanJob {
                start: case.start,
                goal: case.goal,
                seed: Some(seed),
            })
            .collect();
        let outcomes = link.plan_many(&jobs).expect("plans");
        for (job, o) in jobs.iter().zip(&outcomes) {
            let seed = job.seed.unwrap_or(0);
            let params = Params { seed, ..defaults };
            let host = plan_map(&map, case.start, case.goal, &params).expect("host plan");
            let what = format!(
                "{} ({},{})->({},{}) seed {seed}",
                case.map, case.start.x, case.start.y, case.goal.x, case.goal.y
            );
            assert_same(&what, &host, case.start, &o.result);
            checked += 1;
        }
    }
    // Every algorithm and non-default parameters travel through SetParams intact.
    let map = load("complex-26.map");
    link.set_map(&map).expect("set map");
    for algorithm in Algorithm::ALL {
        let params = Params {
            algorithm,
            ants: 20,
            iterations: 40,
            alpha: 1.5,
            rho: 0.2,
            seed: 7,
            ..defaults
        };
        link.set_params(&params).expect("set params");
        let (s, g) = (Point::new(0, 0), Point::new(25, 25));
        let dev = link.plan(s, g, None).map_err(|e| match e {
            LinkError::Device { error, .. } => error,
            e => panic!("{e}"),
        });
        let host = plan_map(&map, s, g, &params).expect("host plan");
        assert_same(&format!("complex-26 {}", algorithm.name()), &host, s, &dev);
        checked += 1;
    }
    // The paper's preset (`--preset paper`: dying ants, no tightening, all 100 iterations,
    // greedy smoothing) travels through SetParams too, and plans as on the host.
    for (name, s, g) in [
        ("complex-26.map", Point::new(0, 0), Point::new(25, 25)),
        ("simple-18.map", Point::new(0, 0), Point::new(17, 17)),
    ] {
        let map = load(name);
        link.set_map(&map).expect("set map");
        for algorithm in [Algorithm::Haca, Algorithm::Ohaca] {
            let params = Params {
                algorithm,
                ..Params::paper()
            };
            link.set_params(&params).expect("set params");
            let dev = link.plan(s, g, None).map_err(|e| match e {
                LinkError::Device { error, .. } => error,
                e => panic!("{e}"),
            });
            let host = plan_map(&map, s, g, &params).expect("host plan");
            assert_eq!(
                host.iterations,
                Some(100),
                "the paper preset runs all N iterations"
            );
            let what = format!("{name} paper preset {}", algorithm.name());
            assert_same(&what, &host, s, &dev);
            let core = core_plan(&map, s, g, &params).expect("core plan");
            assert_core_path(&what, &core, dev.as_ref().expect("a device path"));
            checked += 1;
        }
    }
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
    println!("{checked} device plans bit-identical to the host core");
}

#[test]
fn a_stream_of_200_goals_is_answered_in_order() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    let info = link.hello().expect("hello");
    let map = load("simple-18.map");
    let params = Params {
        iterations: 30,
        ..Params::default()
    };
    link.set_params(&params).expect("set params");
    link.set_map(&map).expect("set map");
    // Deterministic pseudo-random pairs of free cells; every 25th goal is an obstacle.
    let (free, blocked): (Vec<Point>, Vec<Point>) = (0..map.height)
        .flat_map(|y| (0..map.width).map(move |x| Point::new(x, y)))
        .partition(|&p| !map.is_blocked(p));
    assert!(!blocked.is_empty());
    let mut state = 0x2545_f491_u32;
    let mut next = |n: usize| {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        state as usize % n
    };
    let jobs: Vec<PlanJob> = (0..200)
        .map(|i| {
            let start = free[next(free.len())];
            let goal = if i % 25 == 24 {
                blocked[next(blocked.len())]
            } else {
                free[next(free.len())]
            };
            PlanJob {
                start,
                goal,
                seed: Some(i as u64 + 1),
            }
        })
        .collect();
    let first_id = link.next_id();
    let t0 = Instant::now();
    let mut order = Vec::new();
    let mut outcomes = Vec::new();
    link.plan_each(&jobs, |i, o| {
        order.push(i);
        outcomes.push(o);
    })
    .expect("200 plans");
    let elapsed = t0.elapsed();
    assert_eq!(order, (0..200).collect::<Vec<_>>(), "outcomes in job order");
    let ids: Vec<u32> = outcomes.iter().map(|o| o.id).collect();
    let want: Vec<u32> = (first_id..first_id + 200).collect();
    assert_eq!(ids, want, "request ids 1:1 with the jobs, none refused");
    let mut paths = 0;
    for (i, (job, o)) in jobs.iter().zip(&outcomes).enumerate() {
        let p = Params {
            seed: job.seed.unwrap_or(0),
            ..params
        };
        let host = plan_map(&map, job.start, job.goal, &p);
        let what = format!("goal #{i}");
        match host {
            Ok(h) if h.found => {
                assert_same(&what, &h, job.start, &o.result);
                paths += 1;
            }
            Ok(h) => {
                let e = o.result.as_ref().expect_err(&what);
                assert_eq!(e.code, ErrorCode::NoPath, "{what}: {h:?}");
            }
            Err(h) => {
                let e = o.result.as_ref().expect_err(&what);
                let device = ohaca::Error::try_from(*e);
                assert_eq!(device, Ok(core(&h)), "{what}: host {h}, device {e}");
            }
        }
    }
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
    let stats = link.stats().expect("stats");
    assert_eq!(stats.busy, 0, "the link never overfills the queue");
    println!(
        "200 pipelined requests ({paths} paths) in {:.2} s, plan_queue {}",
        elapsed.as_secs_f64(),
        info.capacity.plan_queue
    );
}

fn core(e: &ohaca_host::PlanError) -> ohaca::Error {
    match e {
        ohaca_host::PlanError::Core(c) => *c,
        other => panic!("{other}"),
    }
}

#[test]
fn broken_frames_get_error_replies_and_the_next_request_is_served() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    link.hello().expect("hello");
    let map = load("complex-26.map");
    link.set_map(&map).expect("set map");

    let mut hello = [0u8; MAX_REQUEST_WIRE];
    let n = encode_request(999, &Request::Hello, &mut hello).expect("encode");
    let hello = &hello[..n];
    let mut plan = [0u8; MAX_REQUEST_WIRE];
    let n = encode_request(
        1000,
        &Request::Plan {
            start: Point::new(0, 0),
            goal: Point::new(25, 25),
            seed: Some(3),
        },
        &mut plan,
    )
    .expect("encode");
    let plan = &plan[..n];

    // Bit flipped inside the payload, re-stuffed so the frame is valid COBS: BadCrc.
    let mut payload = b"\xe7\x07\x00".to_vec(); // id 999, Hello
    payload.extend_from_slice(&crc32(&payload).to_le_bytes());
    payload[1] ^= 0x10;
    let mut flipped = cobs(&payload);
    flipped.push(0);
    // Truncated: the Plan frame without its last three bytes.
    let mut truncated = plan[..plan.len() - 4].to_vec();
    truncated.push(0);
    // Oversized: 600 bytes, longer than the device's reader.
    let mut oversized = vec![0x01u8; 600];
    oversized.push(0);
    // Garbage: pseudo-random non-zero bytes.
    let mut garbage: Vec<u8> = (0u32..50)
        .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8 | 1)
        .collect();
    garbage.push(0);
    // A correct CRC around a message that does not decode (variant 9): Undecodable with its id.
    let unknown = frame_of(&[0xd2, 0x09, 0x09]); // id 1234, variant 9
                                                 // Too short to hold a CRC.
    let short = vec![0x02, 0x01, 0x00];
    let cases: Vec<(&str, Vec<u8>, Option<ErrorCode>)> = vec![
        ("bit-flipped", flipped, Some(ErrorCode::BadCrc)),
        ("truncated", truncated, None),
        ("oversized", oversized, Some(ErrorCode::TooLarge)),
        ("garbage", garbage, None),
        ("unknown variant", unknown, Some(ErrorCode::Undecodable)),
        ("too short", short, Some(ErrorCode::Undecodable)),
        // Empty frames are skipped without a reply.
        ("empty frames", vec![0, 0, 0], None),
    ];
    for (what, bytes, code) in cases {
        let want = expected_errors(&bytes);
        if let (Some(code), Some((_, e))) = (code, want.first()) {
            assert_eq!(e.code, code, "{what}: the test's own expectation");
        }
        link.send_raw(&bytes).expect("send");
        for (id, e) in &want {
            let (got_id, got) = link.recv().unwrap_or_else(|e| panic!("{what}: {e}"));
            assert_eq!(got, Response::Error(*e), "{what}");
            assert_eq!(got_id, *id, "{what}: reply id");
        }
        if what == "oversized" {
            assert_eq!(want.first().map(|w| w.1.detail), Some(600));
        }
        if what == "unknown variant" {
            assert_eq!(want.first().map(|w| w.0), Some(1234));
        } else {
            assert!(want.iter().all(|w| w.0 == UNKNOWN_ID), "{what}: {want:?}");
        }
        // The next valid request is served.
        let info = link.hello().unwrap_or_else(|e| panic!("after {what}: {e}"));
        assert_eq!(info.protocol_version, ohaca::protocol::VERSION);
    }
    // A valid frame glued to a broken one: the broken one is answered, the valid one served.
    let mut glued = b"\x05\x01\x02\x00".to_vec();
    glued.extend_from_slice(hello);
    let want = expected_errors(b"\x05\x01\x02\x00");
    link.send_raw(&glued).expect("send");
    let mut got = [link.recv().expect("reply"), link.recv().expect("reply")];
    got.sort_by_key(|g| g.0);
    assert_eq!(got[0], (want[0].0, Response::Error(want[0].1)));
    assert_eq!(got[1].0, 999);
    assert!(matches!(got[1].1, Response::Hello(_)));
    // A chunk over MAX_CHUNK in a valid frame: TooLarge with its id.
    let chunk = vec![0u8; MAX_CHUNK + 1];
    let e = error_code(
        link.call(&Request::SetMap {
            width: 26,
            height: 26,
            offset: 0,
            total_len: 85,
            chunk: &chunk,
        })
        .and_then(|r| match r {
            Response::Error(error) => Err(LinkError::Device {
                request: "SetMap",
                error,
            }),
            other => Ok(other),
        }),
    );
    assert_eq!(
        e,
        ErrorReply::with(
            ErrorCode::TooLarge,
            (MAX_CHUNK + 1) as u32,
            MAX_CHUNK as u32
        )
    );
    // The map survived all of this, and plans still match the host.
    let host = plan_map(
        &map,
        Point::new(0, 0),
        Point::new(25, 25),
        &Params {
            seed: 3,
            ..Params::default()
        },
    )
    .expect("host");
    let dev = link
        .plan(Point::new(0, 0), Point::new(25, 25), Some(3))
        .map_err(|e| match e {
            LinkError::Device { error, .. } => error,
            e => panic!("{e}"),
        });
    assert_same("after broken frames", &host, Point::new(0, 0), &dev);
    let stats = link.stats().expect("stats");
    assert!(stats.frames_bad >= 7, "{stats:?}");
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

#[test]
fn refusals_no_map_map_too_large_busy_and_cancel() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    let info = link.hello().expect("hello");
    let Capacity {
        cells, plan_queue, ..
    } = info.capacity;

    // A plan before any map.
    let e = error_code(link.plan(Point::new(0, 0), Point::new(1, 1), None));
    assert_eq!(e.code, ErrorCode::NoMap, "{e}");

    // A map one cell longer than the longest side the device takes.
    let m = info.capacity.max_side;
    let wide = Map::from_fn(m + 1, 2, |_, _| false);
    let e = error_code(link.set_map(&wide));
    assert_eq!(
        e,
        ErrorReply::with(ErrorCode::MapTooLarge, u32::from(m) + 1, u32::from(m))
    );
    // Within the side but one row more cells than the device holds: refused by cells.
    let rows = u16::try_from(cells / u32::from(m) + 1).expect("rows");
    let e = error_code(link.set_map(&Map::from_fn(m, rows, |_, _| false)));
    let n = u32::from(m) * u32::from(rows);
    assert_eq!(e, ErrorReply::with(ErrorCode::MapTooLarge, n, cells));
    // The checks' order: an empty chunk is `TooLarge` 0 before its bad header is looked at; a
    // zero side is `BadMap` with the total_len sent and 0; neither opens an upload.
    for (w, h, total) in [(0u16, 3u16, 7u32), (4, 3, 2)] {
        let r = link.call(&Request::SetMap {
            width: w,
            height: h,
            offset: 0,
            total_len: total,
            chunk: &[],
        });
        let want = Response::Error(ErrorReply::with(ErrorCode::TooLarge, 0, MAX_CHUNK as u32));
        assert_eq!(r.expect("reply"), want);
    }
    let r = link.call(&Request::SetMap {
        width: 0,
        height: 3,
        offset: 0,
        total_len: 7,
        chunk: &[0],
    });
    assert_eq!(
        r.expect("reply"),
        Response::Error(ErrorReply::with(ErrorCode::BadMap, 7, 0))
    );
    // An upload left unfinished: the device has no map from its first chunk on.
    let first = link.call(&Request::SetMap {
        width: 100,
        height: 100,
        offset: 0,
        total_len: 1250,
        chunk: &[0; MAX_CHUNK],
    });
    assert_eq!(first.expect("first chunk"), Response::Ack);
    let e = error_code(link.plan(Point::new(0, 0), Point::new(1, 1), None));
    assert_eq!(e.code, ErrorCode::NoMap, "{e}");
    // A wrong total_len, and a chunk that does not continue an upload.
    let e = error_code(link.set_map_bits(10, 10, &[0; 3]));
    assert_eq!(e, ErrorReply::with(ErrorCode::BadMap, 3, 13));
    let e = error_code(
        link.call(&Request::SetMap {
            width: 10,
            height: 10,
            offset: 5,
            total_len: 13,
            chunk: &[0],
        })
        .and_then(|r| match r {
            Response::Error(error) => Err(LinkError::Device {
                request: "SetMap",
                error,
            }),
            other => Ok(other),
        }),
    );
    assert_eq!(e.code, ErrorCode::BadChunk);
    // Still no map.
    let e = error_code(link.plan(Point::new(0, 0), Point::new(1, 1), None));
    assert_eq!(e.code, ErrorCode::NoMap);

    // A slow plan, the queue filled behind it, one more refused with Busy, then Cancel.
    let map = load("complex-26.map");
    slow_plans_on(&mut link, &map);
    let (s, g) = (Point::new(0, 0), Point::new(25, 25));
    let running = link
        .send(&Request::Plan {
            start: s,
            goal: g,
            seed: None,
        })
        .expect("send");
    let t0 = Instant::now();
    loop {
        let st = link.stats().expect("stats");
        if st.planning && st.queued == 0 {
            break;
        }
        assert!(t0.elapsed() < TIMEOUT, "the plan never started: {st:?}");
        std::thread::sleep(Duration::from_millis(10));
    }
    let mut queued = Vec::new();
    for seed in 0..u64::from(plan_queue) {
        queued.push(
            link.send(&Request::Plan {
                start: s,
                goal: g,
                seed: Some(seed),
            })
            .expect("send"),
        );
    }
    let refused = link
        .send(&Request::Plan {
            start: s,
            goal: g,
            seed: None,
        })
        .expect("send");
    let r = link.wait_for(refused, "Plan").expect("busy reply");
    assert_eq!(
        r,
        Response::Error(ErrorReply::with(
            ErrorCode::Busy,
            u32::from(plan_queue),
            u32::from(plan_queue)
        ))
    );
    let st = link.stats().expect("stats");
    assert!(st.planning, "{st:?}");
    assert_eq!(st.queued, plan_queue, "{st:?}");
    let cancel = link.send(&Request::Cancel).expect("send");
    assert_eq!(link.wait_for(cancel, "Cancel").expect("ack"), Response::Ack);
    for id in std::iter::once(running).chain(queued) {
        let r = link.wait_for(id, "Plan").expect("cancelled");
        assert_eq!(
            r,
            Response::Error(ErrorReply::new(ErrorCode::Cancelled)),
            "plan {id}"
        );
    }
    let st = link.stats().expect("stats");
    assert!(!st.planning && st.queued == 0, "{st:?}");
    assert_eq!(st.busy, 1, "{st:?}");
    assert_eq!(st.cancelled, 1 + u32::from(plan_queue), "{st:?}");

    // The device plans normally afterwards.
    link.set_params(&Params::default()).expect("set params");
    let dev = link.plan(s, g, None).map_err(|e| match e {
        LinkError::Device { error, .. } => error,
        e => panic!("{e}"),
    });
    let host = plan_map(&map, s, g, &Params::default()).expect("host");
    assert_same("after cancel", &host, s, &dev);
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// `docs/PROTOCOL.md`, SetMap: "The device holds one map: an upload's first chunk drops the
/// previous map and cancels every plan received before it (the running one and the queued ones
/// are answered with `Error Cancelled`); from then until the last byte arrives the device has no
/// map (plans get `NoMap`, `Stats` reports 0 x 0). Plans received afterwards use the new map."
#[test]
fn a_new_map_cancels_running_and_queued_plans_and_later_plans_use_it() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    link.hello().expect("hello");
    let old = load("complex-26.map");
    slow_plans_on(&mut link, &old);
    let (s, g) = (Point::new(0, 0), Point::new(25, 25));
    let plan = |link: &mut Link<_>, seed: u64| {
        link.send(&Request::Plan {
            start: s,
            goal: g,
            seed: Some(seed),
        })
        .expect("send")
    };
    let running = plan(&mut link, 1);
    let t0 = Instant::now();
    loop {
        let st = link.stats().expect("stats");
        if st.planning && st.queued == 0 {
            break;
        }
        assert!(t0.elapsed() < TIMEOUT, "the plan never started: {st:?}");
        std::thread::sleep(Duration::from_millis(10));
    }
    let queued = [plan(&mut link, 2), plan(&mut link, 3)];

    // The new map: 20x20 with a wall, sent in two chunks.
    let new = Map::from_fn(20, 20, |x, y| x == 10 && y < 17);
    let half = new.bits.len() / 2;
    fn chunk<'a>(map: &Map, offset: usize, bytes: &'a [u8]) -> Request<'a> {
        Request::SetMap {
            width: map.width,
            height: map.height,
            offset: offset as u32,
            total_len: map.bits.len() as u32,
            chunk: bytes,
        }
    }
    let first = link
        .send(&chunk(&new, 0, &new.bits[..half]))
        .expect("first chunk");
    // The chunk's Ack may come before or after the Cancelled errors: wait for each by id.
    assert_eq!(link.wait_for(first, "SetMap").expect("ack"), Response::Ack);
    for id in [running, queued[0], queued[1]] {
        let r = link.wait_for(id, "Plan").expect("cancelled");
        assert_eq!(
            r,
            Response::Error(ErrorReply::new(ErrorCode::Cancelled)),
            "plan {id}"
        );
    }
    let st = link.stats().expect("stats");
    assert_eq!((st.map_width, st.map_height), (0, 0), "{st:?}");
    assert!(
        !st.planning && st.queued == 0 && st.cancelled == 3,
        "{st:?}"
    );
    let between = plan(&mut link, 4);
    let r = link.wait_for(between, "Plan").expect("no map");
    assert_eq!(r, Response::Error(ErrorReply::new(ErrorCode::NoMap)));
    let last = link
        .call(&chunk(&new, half, &new.bits[half..]))
        .expect("last chunk");
    assert_eq!(last, Response::Ack);
    let st = link.stats().expect("stats");
    assert_eq!((st.map_width, st.map_height), (20, 20), "{st:?}");
    assert!(!st.planning && st.queued == 0, "{st:?}");
    assert_eq!(
        (st.cancelled, st.plans, st.plan_errors),
        (3, 0, 0),
        "{st:?}"
    );

    // Later plans use the new map: a path around its wall, bit-identical to the host core's on
    // the new map (and not the one the old map gives), and the old map's goal is now outside.
    let params = Params {
        seed: 5,
        ..Params::default()
    };
    link.set_params(&params).expect("set params");
    let (s2, g2) = (Point::new(0, 0), Point::new(19, 0));
    let dev = link.plan(s2, g2, None).expect("plan on the new map");
    let on_new = core_plan(&new, s2, g2, &params).expect("host plan");
    assert_core_path("on the new map", &on_new, &dev);
    assert_ne!(
        core_plan(&old, s2, g2, &params),
        Ok(on_new),
        "the test needs maps with different paths"
    );
    let e = error_code(link.plan(s, g, None));
    assert_eq!(e.code, ErrorCode::GoalOutOfBounds, "{e}");
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// A host that goes away in the middle of a frame (QEMU's `server=on,wait=off` then accepts the
/// next client): the partial frame stays in the device's reader until the next client's leading
/// `00` (which [`Link`] sends on open) ends it. The device answers that one bad frame with an
/// error reply of id 0, which the link skips as a stray; every request of the new connection is
/// served, the map is still there, and the device did not reset (`boots` 1, `uptime` grows,
/// every byte counted).
#[test]
fn a_host_that_disconnects_mid_frame_does_not_disturb_the_next_one() {
    need_qemu!();
    let mut q = Qemu::tcp();
    let map = load("simple-18.map");
    let mut before = {
        let mut link = q.link();
        link.hello().expect("hello");
        link.set_map(&map).expect("set map");
        let st = link.stats().expect("stats");
        assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
        st
    }; // the link is dropped here: disconnected
    let (s, g) = (Point::new(0, 0), Point::new(17, 17));
    let mut frame = [0u8; MAX_REQUEST_WIRE];
    let n = encode_request(
        77,
        &Request::Plan {
            start: s,
            goal: g,
            seed: Some(9),
        },
        &mut frame,
    )
    .expect("encode");
    // Cut after the first byte, in the middle, and just before the last byte (a whole frame
    // but its delimiter would be served: the next `00` completes it).
    for cut in [1, n / 2, n - 2] {
        let part = &frame[..cut];
        assert!(!part.contains(&0));
        {
            let mut raw = q.connect();
            raw.write_all(part).expect("write half a frame");
            raw.flush().expect("flush");
            // Let QEMU pass the bytes to the UART before the connection goes away (it would
            // anyway: they come before the end of the stream).
            std::thread::sleep(Duration::from_millis(200));
        }
        let mut flushed = part.to_vec();
        flushed.push(0);
        let want = expected_errors(&flushed);
        assert_eq!(want.len(), 1, "cut {cut}: {want:?}");
        assert_eq!(want[0].0, UNKNOWN_ID, "cut {cut}");

        let mut link = q.link();
        let info = link.hello().expect("hello after the reconnection");
        assert_eq!(info.board, "qemu-mps2-an386");
        let params = Params {
            seed: 9,
            ..Params::default()
        };
        let dev = link.plan(s, g, Some(9)).expect("plan");
        assert_core_path(
            &format!("cut {cut}"),
            &core_plan(&map, s, g, &params).expect("host plan"),
            &dev,
        );
        let st = link.stats().expect("stats");
        assert_eq!(
            link.take_strays(),
            vec![Stray::Reply {
                id: UNKNOWN_ID,
                response: Response::Error(want[0].1)
            }],
            "cut {cut}: the flushed partial frame's error"
        );
        assert_eq!(st.boots, 1, "cut {cut}: the device reset: {st:?}");
        assert!(
            st.uptime > before.uptime,
            "cut {cut}: {st:?} after {before:?}"
        );
        assert_eq!((st.map_width, st.map_height), (18, 18), "cut {cut}: {st:?}");
        assert_eq!(st.frames_ok, before.frames_ok + 3, "cut {cut}: {st:?}");
        assert_eq!(st.frames_bad, before.frames_bad + 1, "cut {cut}: {st:?}");
        assert_eq!(st.plans, before.plans + 1, "cut {cut}: {st:?}");
        // Every byte arrived: the partial frame, the link's `00`, Hello, Plan, Stats.
        let len = |id, r: &Request| {
            encode_request(id, r, &mut [0u8; MAX_REQUEST_WIRE]).expect("encode") as u32
        };
        let sent = cut as u32
            + 1
            + len(1, &Request::Hello)
            + len(
                2,
                &Request::Plan {
                    start: s,
                    goal: g,
                    seed: Some(9),
                },
            )
            + len(3, &Request::Stats);
        assert_eq!(st.rx_bytes, before.rx_bytes + sent, "cut {cut}: {st:?}");
        assert_eq!(st.rx_overruns, 0, "{st:?}");
        before = st;
    }
    assert!(q.is_running(), "QEMU exited");
}

#[test]
fn hello_round_trip_latency() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    link.hello().expect("hello");
    let mut t: Vec<Duration> = (0..50)
        .map(|_| {
            let t0 = Instant::now();
            link.hello().expect("hello");
            t0.elapsed()
        })
        .collect();
    t.sort();
    let us = |d: Duration| d.as_secs_f64() * 1e6;
    println!(
        "Hello round trip over QEMU's TCP UART, 50 calls: min {:.0} us, median {:.0} us, \
         p90 {:.0} us, max {:.0} us",
        us(t[0]),
        us(t[25]),
        us(t[45]),
        us(t[49])
    );
}

// ---- the `ohaca send` command ------------------------------------------------------------

fn ohaca(args: &[String]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_ohaca"))
        .args(args)
        .stdin(Stdio::null())
        .output()
        .expect("run ohaca")
}

fn strings(a: &[&str]) -> Vec<String> {
    a.iter().map(|s| s.to_string()).collect()
}

fn json_lines(o: &Output) -> Vec<Value> {
    String::from_utf8_lossy(&o.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap_or_else(|e| panic!("{e}: {l}")))
        .collect()
}

/// `ohaca plan --json` on the host, as a JSON value.
fn host_json(map: &str, start: &str, goal: &str, extra: &[&str]) -> Value {
    let mut args = strings(&[
        "plan", "--map", map, "--start", start, "--goal", goal, "--json",
    ]);
    args.extend(strings(extra));
    let o = ohaca(&args);
    assert!(o.status.code().is_some_and(|c| c <= 1), "{o:?}");
    json_lines(&o).remove(0)
}

/// `send`'s JSON is `plan`'s keys plus `ticks` and `device`; everything but the times equal.
fn assert_send_matches_plan(send: &Value, plan: &Value, board: &str) {
    let s = send.as_object().expect("object");
    let p = plan.as_object().expect("object");
    let mut keys: Vec<&String> = s.keys().collect();
    keys.retain(|k| *k != "ticks" && *k != "device");
    assert_eq!(keys, p.keys().collect::<Vec<_>>(), "same keys as plan");
    for (k, v) in p {
        if k != "elapsed_us" {
            assert_eq!(&s[k], v, "key {k}");
        }
    }
    assert_eq!(s["device"], board);
    assert!(s.contains_key("ticks"));
}

#[test]
fn send_command_over_tcp() {
    need_qemu!();
    let q = Qemu::tcp();
    let complex = maps().join("complex-26.map").display().to_string();
    let addr = q.addr().to_string();
    let base = |extra: &[&str]| {
        let mut a = strings(&[
            "send",
            "--tcp",
            &addr,
            "--map",
            &complex,
            "--timeout",
            "120",
        ]);
        a.extend(strings(extra));
        a
    };

    // One plan, JSON: plan's keys, same values.
    let o = ohaca(&base(&[
        "--start", "0,0", "--goal", "25,25", "--json", "--seed", "5",
    ]));
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let send = json_lines(&o);
    assert_eq!(send.len(), 1);
    let plan = host_json(&complex, "0,0", "25,25", &["--seed", "5"]);
    assert_send_matches_plan(&send[0], &plan, "qemu-mps2-an386");
    assert!(send[0]["ticks"].as_u64().is_some_and(|t| t > 0));

    // The picture: the same map drawing as `plan`.
    let o = ohaca(&base(&["--start", "0,0", "--goal", "25,25"]));
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let text = String::from_utf8_lossy(&o.stdout).into_owned();
    let p = ohaca(&strings(&[
        "plan", "--map", &complex, "--start", "0,0", "--goal", "25,25",
    ]));
    let host_text = String::from_utf8_lossy(&p.stdout).into_owned();
    let picture = |t: &str| -> Vec<String> {
        t.lines()
            .filter(|l| l.len() == 26 * 2 - 1)
            .map(str::to_string)
            .collect()
    };
    assert_eq!(picture(&text).len(), 26, "{text}");
    assert_eq!(picture(&text), picture(&host_text));
    assert!(text.contains("qemu-mps2-an386"), "{text}");
    assert!(text.contains("ticks"), "{text}");

    // CSV: the same waypoint lines as `plan --format csv`.
    let o = ohaca(&base(&[
        "--start", "0,0", "--goal", "25,25", "--format", "csv",
    ]));
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let p = ohaca(&strings(&[
        "plan", "--map", &complex, "--start", "0,0", "--goal", "25,25", "--format", "csv",
    ]));
    assert_eq!(
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&p.stdout)
    );
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("x,y\n"));

    // A goal on an obstacle: bad input, exit 2, one line on stderr.
    let o = ohaca(&base(&["--start", "0,0", "--goal", "3,1"]));
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("goal is on an obstacle"), "{err}");
    assert!(o.stdout.is_empty());

    // A map larger than the device, free everywhere: nothing to crop, so resampled to fit (2x2
    // cells per cell), with a note on stderr; start, goal and output are the original map's
    // cells (the waypoints between them are the centres of the coarse cells).
    let big = maps().join("movingai/random-32-32-10.map");
    let dir = tempfile::tempdir().expect("tempdir");
    let huge = dir.path().join("huge.map");
    let mut text = String::from("type octile\nheight 600\nwidth 600\nmap\n");
    for _ in 0..600 {
        text.push_str(&".".repeat(600));
        text.push('\n');
    }
    std::fs::write(&huge, text).expect("write map");
    let mut a = base(&["--start", "0,0", "--goal", "599,599", "--json"]);
    a[4] = huge.display().to_string();
    let o = ohaca(&a);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("note: ") && err.contains("resampled, 2x2 cells per cell: 300x300"),
        "{err}"
    );
    let line = json_lines(&o).remove(0);
    assert_eq!(line["found"], true, "{line}");
    assert_eq!(line["raw"][0], serde_json::json!([0, 0]), "{line}");
    assert_eq!(
        line["waypoints"].as_array().and_then(|w| w.last()),
        Some(&serde_json::json!([599, 599])),
        "{line}"
    );

    // A ROS map shaped like Nav2's TurtleBot sandbox, grown to 600 x 600 cells of 5 cm (more than
    // the device's 262,144: Nav2's 384 x 384 now fits as it is), unknown but an 80 x 80 known
    // area. Cropped to the known area it fits at full resolution: no resampling,
    // start and goal stay the free cells they are, and the path is the host's on the crop,
    // reported in the original cells and metres.
    let mut pgm = b"P5\n600 600\n255\n".to_vec();
    for y in 0..600u32 {
        for x in 0..600u32 {
            let known = (150..230).contains(&x) && (150..230).contains(&y);
            let wall = known && x == 190 && y < 215;
            pgm.push(if !known {
                205
            } else if wall {
                0
            } else {
                254
            });
        }
    }
    std::fs::write(dir.path().join("sandbox.pgm"), pgm).expect("write pgm");
    let sandbox = dir.path().join("sandbox.yaml");
    std::fs::write(
        &sandbox,
        "image: sandbox.pgm\nresolution: 0.05\norigin: [-10.0, -10.0, 0.0]\nnegate: 0\n\
         occupied_thresh: 0.65\nfree_thresh: 0.196\n",
    )
    .expect("write yaml");
    let o = ohaca(&{
        let mut a = base(&["--start", "152,152", "--goal", "227,160", "--json"]);
        a[4] = sandbox.display().to_string();
        a
    });
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(
        err.contains(
            "cropped to its free area at full resolution: 82x82 cells from cell (149, 149)"
        ),
        "{err}"
    );
    let line = json_lines(&o).remove(0);
    assert_eq!(line["found"], true, "{line}");
    let way = line["waypoints"].as_array().expect("waypoints").clone();
    assert_eq!(way.first(), Some(&serde_json::json!([152, 152])), "{line}");
    assert_eq!(way.last(), Some(&serde_json::json!([227, 160])), "{line}");
    // The crop's path, moved back by (149, 149), is the host core's on the crop.
    let mut crop = String::from("type octile\nheight 82\nwidth 82\nmap\n");
    for y in 149..231u32 {
        for x in 149..231u32 {
            let known = (150..230).contains(&x) && (150..230).contains(&y);
            let wall = known && x == 190 && y < 215;
            crop.push(if !known || wall { '@' } else { '.' });
        }
        crop.push('\n');
    }
    let crop_path = dir.path().join("crop.map");
    std::fs::write(&crop_path, crop).expect("write crop");
    let plan = host_json(&crop_path.display().to_string(), "3,3", "78,11", &[]);
    let moved: Vec<Value> = plan["waypoints"]
        .as_array()
        .expect("host waypoints")
        .iter()
        .map(|p| serde_json::json!([p[0].as_u64().unwrap() + 149, p[1].as_u64().unwrap() + 149]))
        .collect();
    assert_eq!(way, moved, "{line}\n{plan}");
    assert_eq!(line["length"], plan["length"]);
    // Metres: the start's cell centre in the sandbox's frame.
    let m = &line["waypoints_m"][0];
    assert!(
        (m[0].as_f64().unwrap() - (-10.0 + 152.5 * 0.05)).abs() < 1e-6,
        "{m}"
    );
    assert!(
        (m[1].as_f64().unwrap() - (-10.0 + (599.0 - 152.0 + 0.5) * 0.05)).abs() < 1e-6,
        "{m}"
    );

    // With --cell the map is taken as given: refused before the upload, exit 2.
    a.truncate(a.len() - 1);
    a.extend(strings(&["--cell", "1"]));
    let o = ohaca(&a);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("map too large for the device"), "{err}");
    assert!(err.contains("360000 cells"), "{err}");

    // --goals: one JSON line per request, in order, identical to the host's plans.
    let goals = dir.path().join("goals.txt");
    std::fs::write(
        &goals,
        "# start goal\n0,0 25,25\n\n25,25 0,0   # back\n5,5\n0,0 11,11\n",
    )
    .expect("write goals");
    let mut a = base(&["--goals", &goals.display().to_string(), "--start", "1,0"]);
    a.push("--ants".into());
    a.push("30".into());
    let o = ohaca(&a);
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let lines = json_lines(&o);
    let pairs = [
        ("0,0", "25,25"),
        ("25,25", "0,0"),
        ("1,0", "5,5"),
        ("0,0", "11,11"),
    ];
    assert_eq!(lines.len(), pairs.len(), "{lines:?}");
    for (line, (s, g)) in lines.iter().zip(pairs) {
        let plan = host_json(&complex, s, g, &["--ants", "30"]);
        assert_send_matches_plan(line, &plan, "qemu-mps2-an386");
    }

    // --goals with a blocked goal: its line says why, the others are planned, exit 2.
    std::fs::write(&goals, "0,0 25,25\n0,0 3,1\n0,0 11,11\n").expect("write goals");
    let o = ohaca(&base(&["--goals", &goals.display().to_string()]));
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let lines = json_lines(&o);
    assert_eq!(lines.len(), 3);
    assert_eq!(lines[0]["found"], true);
    assert_eq!(lines[1]["found"], false);
    assert!(lines[1]["error"]
        .as_str()
        .is_some_and(|e| e.contains("goal is on an obstacle")));
    assert_eq!(lines[2]["found"], true);

    // A malformed goals file: exit 2 before connecting, file and line named.
    std::fs::write(&goals, "0,0 25,25\n0,0 x,1\n").expect("write goals");
    let o = ohaca(&base(&["--goals", &goals.display().to_string()]));
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(err.contains("line 2"), "{err}");

    // A Moving AI benchmark map at the capacity (32x32) plans too.
    let o = ohaca(&{
        let mut a = base(&["--start", "11,6", "--goal", "7,18", "--json"]);
        a[4] = big.display().to_string();
        a
    });
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let plan = host_json(&big.display().to_string(), "11,6", "7,18", &[]);
    assert_send_matches_plan(&json_lines(&o)[0], &plan, "qemu-mps2-an386");

    // A ROS map_server map (YAML + PGM, 5 cm cells): the same keys as `plan`, `waypoints_m`
    // included.
    let mut pgm = b"P5\n20 12\n255\n".to_vec();
    for y in 0..12 {
        for x in 0..20 {
            let wall = x == 9 && y < 9;
            pgm.push(if wall { 0 } else { 254 });
        }
    }
    std::fs::write(dir.path().join("lab.pgm"), pgm).expect("write pgm");
    let yaml = dir.path().join("lab.yaml");
    std::fs::write(
        &yaml,
        "image: lab.pgm\nresolution: 0.05\norigin: [-0.5, -0.25, 0.0]\nnegate: 0\n\
         occupied_thresh: 0.65\nfree_thresh: 0.196\n",
    )
    .expect("write yaml");
    let yaml = yaml.display().to_string();
    let o = ohaca(&{
        let mut a = base(&["--start", "1,1", "--goal", "18,2", "--json"]);
        a[4] = yaml.clone();
        a
    });
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let send = json_lines(&o).remove(0);
    let plan = host_json(&yaml, "1,1", "18,2", &[]);
    assert!(plan["waypoints_m"].is_array(), "{plan}");
    assert_send_matches_plan(&send, &plan, "qemu-mps2-an386");
}

#[test]
fn send_command_over_a_pty() {
    need_qemu!();
    let q = Qemu::pty();
    let pty = q.pty.clone().expect("pty");
    // A USB-serial adapter's way: open the port by name, Hello, one plan.
    {
        let mut link = Link::serial(&pty, 115_200, TIMEOUT).expect("open the pty");
        let info = link.hello().expect("hello over the pty");
        assert_eq!(info.board, "qemu-mps2-an386");
        link.transport().set_io_timeout(TIMEOUT).expect("timeout");
    }
    let complex = maps().join("complex-26.map").display().to_string();
    let o = ohaca(&strings(&[
        "send",
        "--serial",
        &pty,
        "--baud",
        "115200",
        "--timeout",
        "120",
        "--map",
        &complex,
        "--start",
        "0,0",
        "--goal",
        "25,25",
        "--json",
    ]));
    assert_eq!(o.status.code(), Some(0), "{o:?}");
    let plan = host_json(&complex, "0,0", "25,25", &[]);
    assert_send_matches_plan(&json_lines(&o)[0], &plan, "qemu-mps2-an386");
}

#[test]
fn send_fails_cleanly_without_a_device() {
    // No QEMU needed: a port nobody listens on, and a listener that never answers.
    let complex = maps().join("complex-26.map").display().to_string();
    let port = free_port();
    let o = ohaca(&strings(&[
        "send",
        "--tcp",
        &format!("127.0.0.1:{port}"),
        "--timeout",
        "5",
        "--map",
        &complex,
        "--start",
        "0,0",
        "--goal",
        "25,25",
    ]));
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.starts_with("error: cannot open 127.0.0.1:"), "{err}");

    let silent = TcpListener::bind("127.0.0.1:0").expect("bind");
    let addr = silent.local_addr().expect("addr").to_string();
    let keep = std::thread::spawn(move || {
        // Accept and read whatever comes, never answer; ends when the client goes away.
        if let Ok((mut s, _)) = silent.accept() {
            let mut buf = [0u8; 256];
            while matches!(s.read(&mut buf), Ok(n) if n > 0) {}
            let _ = s.flush();
        }
    });
    let o = ohaca(&strings(&[
        "send",
        "--tcp",
        &addr,
        "--timeout",
        "0.5",
        "--map",
        &complex,
        "--start",
        "0,0",
        "--goal",
        "25,25",
    ]));
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(
        err.trim(),
        format!("error: {addr}: no reply to Hello (request 1) within 0.5 s")
    );
    let _ = keep.join();

    // A serial device that does not exist.
    let o = ohaca(&strings(&[
        "send",
        "--serial",
        "/dev/ttyOHACA-missing",
        "--map",
        &complex,
        "--start",
        "0,0",
        "--goal",
        "25,25",
    ]));
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.starts_with("error: cannot open /dev/ttyOHACA-missing"),
        "{err}"
    );

    // Bad arguments: neither --tcp nor --serial.
    let o = ohaca(&strings(&[
        "send", "--map", &complex, "--start", "0,0", "--goal", "25,25",
    ]));
    assert_eq!(o.status.code(), Some(2), "{o:?}");
}

/// `docs/PROTOCOL.md`, SetMap, chunk by chunk: an over-long chunk gets `TooLarge` and changes
/// nothing; an empty chunk gets `BadChunk` (not `TooLarge`), and at offset 0 still restarts the
/// upload first; a chunk whose width, height or total_len differ from the open upload's gets
/// `BadChunk` (bytes received / total_len); a refused chunk leaves the upload open, and the next
/// good chunk continues it.
#[test]
fn set_map_chunks_are_refused_as_the_document_says() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    link.hello().expect("hello");
    // The device holds 1024 cells: a 32x32 map is one full chunk, sent here in two halves.
    let map = Map::from_fn(32, 32, |x, y| x == 16 && y > 3);
    let total = map.bits.len();
    assert_eq!(total, MAX_CHUNK);
    fn chunk<'a>(w: u16, h: u16, offset: usize, total_len: usize, bytes: &'a [u8]) -> Request<'a> {
        Request::SetMap {
            width: w,
            height: h,
            offset: offset as u32,
            total_len: total_len as u32,
            chunk: bytes,
        }
    }
    let (w, h) = (map.width, map.height);
    let err = |code, detail: usize, limit: usize| {
        Response::Error(ErrorReply::with(code, detail as u32, limit as u32))
    };
    let call = |link: &mut Link<_>, r: &Request<'_>| link.call(r).expect("reply");
    // An empty chunk: `TooLarge` 0 (chunks have 1 to MAX_CHUNK bytes), checked before anything
    // else, and it opens no upload: the next chunk past offset 0 finds none.
    assert_eq!(
        call(&mut link, &chunk(w, h, 0, total, &[])),
        err(ErrorCode::TooLarge, 0, MAX_CHUNK)
    );
    assert_eq!(
        call(&mut link, &chunk(w, h, 1, total, &map.bits[1..2])),
        err(ErrorCode::BadChunk, 0, 0)
    );
    // The first half.
    let half = total / 2;
    assert_eq!(
        call(&mut link, &chunk(w, h, 0, total, &map.bits[..half])),
        Response::Ack
    );
    // Refused, and each leaves the upload as it was:
    let big = vec![0u8; MAX_CHUNK + 1];
    assert_eq!(
        call(&mut link, &chunk(w, h, half, total, &big)),
        err(ErrorCode::TooLarge, MAX_CHUNK + 1, MAX_CHUNK)
    );
    assert_eq!(
        call(&mut link, &chunk(w, h, half, total, &[])),
        err(ErrorCode::TooLarge, 0, MAX_CHUNK),
        "an empty chunk inside an upload"
    );
    // A new upload's refused first chunk (past its own total_len) leaves this one open.
    assert_eq!(
        call(&mut link, &chunk(2, 2, 0, 1, &[0, 0])),
        err(ErrorCode::BadChunk, 0, 1),
        "a first chunk past its total_len"
    );
    assert_eq!(
        call(&mut link, &chunk(w + 1, h, half, total, &map.bits[half..])),
        err(ErrorCode::BadChunk, half, total),
        "a different width"
    );
    assert_eq!(
        call(&mut link, &chunk(w, h - 1, half, total, &map.bits[half..])),
        err(ErrorCode::BadChunk, half, total),
        "a different height"
    );
    assert_eq!(
        call(&mut link, &chunk(w, h, half, total + 1, &map.bits[half..])),
        err(ErrorCode::BadChunk, half, total),
        "a different total_len"
    );
    assert_eq!(
        call(
            &mut link,
            &chunk(w, h, half + 1, total, &map.bits[half + 1..])
        ),
        err(ErrorCode::BadChunk, half, total),
        "a gap"
    );
    let st = link.stats().expect("stats");
    assert_eq!((st.map_width, st.map_height), (0, 0), "no map yet: {st:?}");
    // The upload is still open at `half`: the rest completes the map.
    assert_eq!(
        call(&mut link, &chunk(w, h, half, total, &map.bits[half..])),
        Response::Ack
    );
    let st = link.stats().expect("stats");
    assert_eq!((st.map_width, st.map_height), (w, h), "{st:?}");
    let (s, g) = (Point::new(0, 0), Point::new(31, 31));
    let dev = link.plan(s, g, None).map_err(|e| match e {
        LinkError::Device { error, .. } => error,
        e => panic!("{e}"),
    });
    let host = plan_map(&map, s, g, &Params::default()).expect("host plan");
    assert_same("after the refused chunks", &host, s, &dev);
    // A completed map leaves no upload open: a re-sent last chunk finds none.
    assert_eq!(
        call(&mut link, &chunk(w, h, half, total, &map.bits[half..])),
        err(ErrorCode::BadChunk, 0, 0)
    );
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

// ---- big maps and cell updates (docs/PROTOCOL.md, "Big maps and cell updates") ------------

/// Block (or clear) one cell of a host map.
fn set_cell(map: &mut Map, p: Point, blocked: bool) {
    let i = usize::from(p.y) * usize::from(map.width) + usize::from(p.x);
    if blocked {
        map.bits[i / 8] |= 1 << (i % 8);
    } else {
        map.bits[i / 8] &= !(1 << (i % 8));
    }
}

/// A 256x256 map of city blocks: long runs, as real maps have.
fn blocks_256() -> Map {
    Map::from_fn(256, 256, |x, y| {
        (x % 32 >= 6 && y % 24 >= 5) && !(x % 32 == 19 || y % 24 == 14)
    })
}

/// A 256x256 map goes up run-length coded in chunks, the device reports its size, and a plan on
/// it at full resolution is the host core's, bit for bit (or, on a device with fewer `cells`,
/// `MapTooLarge` with the numbers).
/// The upload's bytes and time are printed (`--nocapture`), not asserted.
#[test]
fn a_256x256_map_goes_up_run_length_coded() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    let info = link.hello().expect("hello");
    let map = blocks_256();
    let code = ohaca_host::link::MapCode::of(&map);
    assert!(matches!(code, ohaca_host::link::MapCode::Rle(_)));
    let t0 = Instant::now();
    link.set_map(&map).expect("upload");
    let took = t0.elapsed();
    let frames = code.bytes().len().div_ceil(MAX_CHUNK);
    println!(
        "256x256: {} bytes packed, {} bytes run-length coded, {frames} chunks, {:.0} ms over QEMU's UART",
        map.bits.len(),
        code.bytes().len(),
        took.as_secs_f64() * 1e3
    );
    let st = link.stats().expect("stats");
    assert_eq!((st.map_width, st.map_height), (256, 256), "{st:?}");
    assert_eq!(st.frames_bad, 0);
    // (255, 254) is free: row 254 is one of the map's gaps (y % 24 == 14).
    let (s, g) = (Point::new(0, 0), Point::new(255, 254));
    let cells = info.capacity.cells;
    match link.plan(s, g, None) {
        Ok(dev) if cells >= 65536 => {
            let host = core_plan(&map, s, g, &Params::default()).expect("host plan");
            assert_core_path("256x256", &host, &dev);
        }
        r => {
            let e = error_code(r);
            assert_eq!(e, ErrorReply::with(ErrorCode::MapTooLarge, 65536, cells));
        }
    }
    // A broken run-length code: BadRle, and no map is left.
    let e = error_code(link.upload(16, 16, &ohaca_host::link::MapCode::Rle(vec![200, 2])));
    assert_eq!(e, ErrorReply::with(ErrorCode::BadRle, 0, 256));
    let st = link.stats().expect("stats");
    assert_eq!((st.map_width, st.map_height), (0, 0), "{st:?}");
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// Capacity is by cells, not by side: a 1024 x 64 corridor of offices (as many cells as
/// 256 x 256, four times wider) goes up whole and is planned at full resolution, bit for bit as
/// the host core plans it.
#[test]
fn a_map_wider_than_256_cells_is_one_map() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    let info = link.hello().expect("hello");
    let (w, h) = (1024u16, 64u16);
    assert!(u32::from(w) * u32::from(h) <= info.capacity.cells);
    assert!(w <= info.capacity.max_side);
    // Rooms 32 cells wide along a corridor (rows 28..36), each with a door onto it.
    let map = Map::from_fn(w, h, |x, y| {
        let wall = x % 32 == 0 && !(28..36).contains(&y);
        let side = (y == 27 || y == 36) && x % 32 != 16;
        wall || side
    });
    link.set_map(&map).expect("upload");
    let st = link.stats().expect("stats");
    assert_eq!((st.map_width, st.map_height), (w, h), "{st:?}");
    // From a room at the left to a room 600 cells to the right, through two doors.
    let (s, g) = (Point::new(5, 5), Point::new(605, 60));
    let dev = link.plan(s, g, None).expect("device plan");
    let host = core_plan(&map, s, g, &Params::default()).expect("host plan");
    assert_core_path("1024x64", &host, &dev);
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// Cell updates between plans change the device's answer, exactly as the same change does on
/// the host: a wall across the map makes the goal unreachable (`NoPath`), a gap opened in it
/// makes it reachable again, through the gap; a `PlanWarm` after it keeps its colony. Updates
/// outside the map change nothing.
#[test]
fn cell_updates_between_plans_change_the_answer() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    link.hello().expect("hello");
    let mut map = Map::from_fn(20, 20, |_, _| false);
    link.set_map(&map).expect("set map");
    let (s, g) = (Point::new(0, 10), Point::new(19, 10));
    let p = Params::default();
    link.plan(s, g, None).expect("open map");

    // A wall at x = 10, the whole height.
    link.set_rect((10, 0), (1, 20), true).expect("wall");
    let e = error_code(link.plan(s, g, None));
    assert_eq!(e.code, ErrorCode::NoPath, "{e}");
    // Outside: refused, and nothing changed.
    let e = error_code(link.set_rect((10, 15), (1, 6), false));
    assert_eq!(e, ErrorReply::with(ErrorCode::OutsideMap, 10, 20));
    let e = error_code(link.set_cells(&[Point::new(10, 3), Point::new(20, 3)], false));
    assert_eq!(e, ErrorReply::with(ErrorCode::OutsideMap, 20, 3));
    let e = error_code(link.plan_warm(s, g, None));
    assert_eq!(e.code, ErrorCode::NoPath, "{e}");

    // A gap at (10, 3): reachable, through the gap, bit-identical to the host on that map.
    link.set_cells(&[Point::new(10, 3)], false).expect("gap");
    for y in 0..20 {
        set_cell(&mut map, Point::new(10, y), y != 3);
    }
    let host = core_plan(&map, s, g, &p).expect("host plan");
    let dev = link.plan(s, g, None).expect("through the gap");
    assert_core_path("through the gap", &host, &dev);
    assert!(dev.raw(s).expect("raw").contains(&Point::new(10, 3)));
    // The cold plan through the gap recorded its colony: this one keeps it (the host's warm
    // replans are checked against the device's in `qemu/replan.rs`).
    let warm = link.plan_warm(s, g, None).expect("warm");
    assert!(
        warm.origin.is_warm(),
        "PlanWarm after a plan to the same goal"
    );
    assert!(warm.raw(s).expect("raw").contains(&Point::new(10, 3)));
    let st = link.stats().expect("stats");
    assert_eq!(
        (st.plans, st.plan_errors, st.cancelled),
        (3, 2, 0),
        "{st:?}"
    );
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// `docs/PROTOCOL.md`: "a cell update cancels the running plan and the queued ones (`Error
/// Cancelled`), then changes the map"; plans received after it plan on the changed map.
#[test]
fn a_cell_update_during_a_plan_cancels_it() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    link.hello().expect("hello");
    let map = load("complex-26.map");
    slow_plans_on(&mut link, &map);
    let (s, g) = (Point::new(0, 0), Point::new(25, 25));
    let plan = |link: &mut Link<_>| {
        link.send(&Request::Plan {
            start: s,
            goal: g,
            seed: None,
        })
        .expect("send")
    };
    let running = plan(&mut link);
    let t0 = Instant::now();
    while !link.stats().expect("stats").planning {
        assert!(t0.elapsed() < TIMEOUT, "the plan never started");
        std::thread::sleep(Duration::from_millis(10));
    }
    let queued = plan(&mut link);
    // Block the goal's neighbours but one: the update is acknowledged, both plans cancelled.
    let wall = [Point::new(24, 24), Point::new(24, 25)];
    let upd = link
        .send(&Request::SetCells {
            blocked: true,
            cells: ohaca::protocol::Waypoints::Points(&wall),
        })
        .expect("send update");
    assert_eq!(link.wait_for(upd, "SetCells").expect("ack"), Response::Ack);
    for id in [running, queued] {
        let r = link.wait_for(id, "Plan").expect("cancelled");
        assert_eq!(
            r,
            Response::Error(ErrorReply::new(ErrorCode::Cancelled)),
            "{id}"
        );
    }
    // The next plan runs on the changed map.
    link.set_params(&Params::default()).expect("params");
    let mut changed = map.clone();
    for p in wall {
        set_cell(&mut changed, p, true);
    }
    let host = core_plan(&changed, s, g, &Params::default()).expect("host");
    let dev = link.plan(s, g, None).expect("plan after the update");
    assert_core_path("after the update", &host, &dev);
    let st = link.stats().expect("stats");
    assert_eq!((st.cancelled, st.plans), (2, 1), "{st:?}");
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// A plan whose only way is longer than the device keeps (a serpentine of 128-cell rows: about
/// 4,000 steps, over the firmware's 2,047) ends with `PathTooLong`, giving the ants dropped and
/// the step limit, not the old, misleading `NoAntArrived`, as the host core with the device's
/// bound says; the device keeps serving, and a goal within reach on the same map is planned.
#[test]
fn a_path_longer_than_the_device_keeps_is_path_too_long() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    let defaults = link.hello().expect("hello").defaults;
    // Walls on every odd row, open at the right end on rows 1, 5, 9, ... and at the left on 3,
    // 7, 11, ...: the way from the top left to the bottom left runs the whole width every two rows.
    let map = Map::from_fn(128, 63, |x, y| {
        y % 2 == 1 && if y % 4 == 1 { x != 127 } else { x != 0 }
    });
    link.set_map(&map).expect("upload");
    let params = Params {
        ants: 4,
        iterations: 2,
        ..defaults
    };
    link.set_params(&params).expect("set params");
    let (s, g) = (Point::new(0, 0), Point::new(0, 62));
    let e = error_code(link.plan(s, g, None));
    assert_eq!(e, ErrorReply::with(ErrorCode::PathTooLong, 8, 2047));
    assert_eq!(core_plan(&map, s, g, &params).err(), Some(e));
    assert_eq!(
        e.to_string(),
        "path longer than the device keeps (8 ants dropped, limit 2047 steps)"
    );
    let near = link
        .plan(Point::new(0, 0), Point::new(0, 8), None)
        .expect("a goal within reach");
    assert!(near.raw_cells > 1);
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}

/// `maps/large/maze-128-128-2`'s longest scenario ((86, 122) to (17, 99) through a maze of 2-wide
/// corridors: the optimum has 1,379 steps, over the 1,023 this build kept while it stored the
/// iteration's best and worst paths) plans on the STM32F411-capacity firmware, whose Hello
/// reports 2,047 steps: bit for bit as the host core plans it with that bound (the host keeps
/// the two paths the device walks again), and its raw path is the optimum. The upload's and the
/// plan's times (well under a second each in QEMU) are printed (`--nocapture`), not asserted.
#[test]
fn the_longest_maze_128_128_2_scenario_plans_on_the_device() {
    need_qemu!();
    let q = Qemu::tcp();
    let mut link = q.link();
    let info = link.hello().expect("hello");
    let steps = info.capacity.max_steps as usize;
    assert_eq!(steps, DEVICE_STEPS, "{info:?}");
    assert_eq!(
        steps,
        ohaca_host::replan::DEVICE_STEPS,
        "the host's replan bound"
    );
    let map = load("large/maze-128-128-2.map");
    assert!(map.cells() <= info.capacity.cells as usize);
    let t0 = Instant::now();
    link.set_map(&map).expect("upload");
    let upload = t0.elapsed();
    let (start, goal) = longest_scenario("large/maze-128-128-2-random-1.scen");
    assert_eq!((start, goal), (Point::new(86, 122), Point::new(17, 99)));
    let params = Params {
        seed: 1,
        ..info.defaults
    };
    let t0 = Instant::now();
    let dev = link.plan(start, goal, Some(1)).expect("device path");
    let took = t0.elapsed();
    let host = core_plan_steps(&map, start, goal, &params, steps).expect("host plan");
    assert_core_path("maze-128-128-2", &host, &dev);
    assert_eq!(dev.raw_cells, 1380, "the optimum's 1,379 steps");
    assert!(
        (f64::from(dev.raw_length) - 1458.1148).abs() < 0.001,
        "raw {}",
        dev.raw_length
    );
    // The bound is what lets it through: with the old one no ant arrives.
    let old = core_plan_steps(&map, start, goal, &params, 1023).err();
    assert_eq!(
        old.map(|e| (e.code, e.limit)),
        Some((ErrorCode::PathTooLong, 1023))
    );
    println!(
        "maze-128-128-2 {start:?} -> {goal:?}: upload {:.1} s, plan {:.1} s over QEMU's UART; \
         {} cells, raw {}, length {}, {} iterations, {} ticks",
        upload.as_secs_f64(),
        took.as_secs_f64(),
        dev.raw_cells,
        dev.raw_length,
        dev.length,
        dev.iterations,
        dev.ticks
    );
    assert_eq!(link.stray_count(), 0, "{:?}", link.take_strays());
}
