//! End-to-end tests of the firmware under QEMU (`mps2-an386`) against the host side of the link
//! (`ohaca_host::link`, `ohaca send`).
//!
//! Each test boots its own QEMU (UART0 on a free local TCP port, or on a pty) and kills it when
//! done ([`Qemu`]'s `Drop`). The firmware is built once per run with `cargo build --release` in
//! the workspace root (a no-op when it is up to date; set `OHACA_FIRMWARE=path/to/elf` to use
//! another ELF and skip the build). Without `qemu-system-arm` the tests are skipped with a
//! message, except under CI (`CI` set), where they fail.
//!
//! Nothing here asserts on time: every wait is bounded by generous timeouts, and latencies are
//! only printed (`cargo test ... -- --nocapture`).

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use ohaca::protocol::{
    crc32, decode_request, encode_request, Capacity, ErrorCode, ErrorReply, Request, RequestReader,
    MAX_CHUNK, MAX_REQUEST_WIRE, UNKNOWN_ID,
};
use ohaca::{Algorithm, Params, Point};
use ohaca_host::link::{DevicePath, Link, LinkError, PlanJob, Response, Transport};
use ohaca_host::{plan_map, Map, PlanReport};
use serde_json::Value;

/// How long any single reply may take (QEMU on a loaded 2-core CI machine can be slow).
const TIMEOUT: Duration = Duration::from_secs(120);

// ---- QEMU --------------------------------------------------------------------------------

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn maps() -> PathBuf {
    root().join("maps")
}

/// True if QEMU can run; false (skip) if it is missing outside CI.
fn have_qemu() -> bool {
    let ok = Command::new("qemu-system-arm")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        assert!(
            std::env::var_os("CI").is_none(),
            "qemu-system-arm is missing, and CI needs these tests to run \
             (apt-get install qemu-system-arm, or source scripts/setup.sh)"
        );
        eprintln!("SKIPPED: qemu-system-arm is not installed (apt-get install qemu-system-arm)");
    }
    ok
}

/// The firmware ELF, built once per test run.
fn firmware() -> &'static Path {
    static ELF: OnceLock<PathBuf> = OnceLock::new();
    ELF.get_or_init(|| {
        if let Some(p) = std::env::var_os("OHACA_FIRMWARE") {
            return PathBuf::from(p);
        }
        let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
        let out = Command::new(cargo)
            .args(["build", "--release", "-q"])
            .current_dir(root())
            .stdout(Stdio::inherit())
            .output()
            .expect("run cargo build --release for the firmware");
        assert!(
            out.status.success(),
            "cargo build --release (the firmware) failed:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let target = std::env::var_os("CARGO_TARGET_DIR")
            .map(PathBuf::from)
            .unwrap_or_else(|| root().join("target"));
        let elf = target.join("thumbv7em-none-eabihf/release/ohaca");
        assert!(elf.is_file(), "no firmware at {}", elf.display());
        elf
    })
}

/// A running QEMU with the firmware; killed on drop.
struct Qemu {
    child: Child,
    /// `127.0.0.1:PORT` of UART0 (TCP mode).
    addr: Option<String>,
    /// `/dev/pts/N` of UART0 (pty mode).
    pty: Option<String>,
}

impl Drop for Qemu {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn qemu_command(serial: &str) -> Command {
    let mut c = Command::new("qemu-system-arm");
    c.args(["-M", "mps2-an386", "-display", "none", "-monitor", "none"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .args(["-serial", serial])
        .arg("-kernel")
        .arg(firmware())
        .stdin(Stdio::null());
    c
}

fn free_port() -> u16 {
    let l = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    l.local_addr().expect("local addr").port()
}

impl Qemu {
    /// Boot with UART0 on a free TCP port; returns once the port accepts connections.
    fn tcp() -> Qemu {
        for _ in 0..5 {
            let port = free_port();
            let child = qemu_command(&format!(
                "tcp:127.0.0.1:{port},server=on,wait=off,nodelay=on"
            ))
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("start qemu-system-arm");
            let mut q = Qemu {
                child,
                addr: Some(format!("127.0.0.1:{port}")),
                pty: None,
            };
            let t0 = Instant::now();
            while t0.elapsed() < Duration::from_secs(30) {
                if let Ok(Some(status)) = q.child.try_wait() {
                    let mut err = String::new();
                    if let Some(mut e) = q.child.stderr.take() {
                        let _ = e.read_to_string(&mut err);
                    }
                    eprintln!("qemu exited ({status}) on port {port}: {err}; retrying");
                    break;
                }
                if TcpStream::connect(("127.0.0.1", port)).is_ok() {
                    return q;
                }
                std::thread::sleep(Duration::from_millis(20));
            }
        }
        panic!("could not start QEMU with UART0 on a TCP port");
    }

    /// Boot with UART0 on a pty, as a USB-serial adapter would appear.
    fn pty() -> Qemu {
        let mut child = qemu_command("pty")
            .stdout(Stdio::piped())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("start qemu-system-arm");
        let stdout = child.stdout.take().expect("qemu stdout");
        let (tx, rx) = std::sync::mpsc::channel();
        // QEMU prints `char device redirected to /dev/pts/N (label serial0)` on stdout, then
        // the firmware's defmt frames (semihosting) follow: keep draining them, or QEMU blocks.
        std::thread::spawn(move || {
            let mut r = BufReader::new(stdout);
            let mut line = Vec::new();
            let _ = r.read_until(b'\n', &mut line);
            let _ = tx.send(String::from_utf8_lossy(&line).into_owned());
            let _ = std::io::copy(&mut r, &mut std::io::sink());
        });
        let mut q = Qemu {
            child,
            addr: None,
            pty: None,
        };
        let line = rx
            .recv_timeout(Duration::from_secs(30))
            .expect("QEMU's `char device redirected to` line");
        let pty = line
            .split_whitespace()
            .find(|w| w.starts_with("/dev/"))
            .unwrap_or_else(|| panic!("no pty in QEMU's line {line:?}"))
            .to_string();
        q.pty = Some(pty);
        q
    }

    fn addr(&self) -> &str {
        self.addr.as_deref().expect("a TCP QEMU")
    }

    fn link(&self) -> Link<TcpStream> {
        let t0 = Instant::now();
        loop {
            match Link::tcp(self.addr(), TIMEOUT) {
                Ok(l) => return l,
                Err(e) if t0.elapsed() > Duration::from_secs(30) => panic!("connect: {e}"),
                Err(_) => std::thread::sleep(Duration::from_millis(50)),
            }
        }
    }
}

macro_rules! need_qemu {
    () => {
        if !have_qemu() {
            return;
        }
    };
}

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
    assert_eq!(
        Some(dev.raw_length.to_bits()),
        bits(host.raw_length),
        "{what}: raw_length {} vs {:?}",
        dev.raw_length,
        host.raw_length
    );
    assert_eq!(
        Some(dev.length.to_bits()),
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
                assert_eq!(e.code.code(), h_code(&h), "{what}: host {h}, device {e}");
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

fn h_code(e: &ohaca_host::PlanError) -> u8 {
    match e {
        ohaca_host::PlanError::Core(c) => c.code(),
        other => panic!("{other}"),
    }
}

/// COBS encode (the protocol's own encoder is private): for building broken frames.
fn cobs(data: &[u8]) -> Vec<u8> {
    let mut out = vec![0];
    let (mut code_at, mut code) = (0usize, 1u8);
    for &b in data {
        if b == 0 {
            out[code_at] = code;
            code_at = out.len();
            out.push(0);
            code = 1;
        } else {
            out.push(b);
            code += 1;
            if code == 0xff {
                out[code_at] = code;
                code_at = out.len();
                out.push(0);
                code = 1;
            }
        }
    }
    out[code_at] = code;
    out
}

/// A frame of raw postcard bytes with a correct CRC.
fn frame_of(body: &[u8]) -> Vec<u8> {
    let mut p = body.to_vec();
    p.extend_from_slice(&crc32(body).to_le_bytes());
    let mut f = cobs(&p);
    f.push(0);
    f
}

/// What the firmware must answer to `bytes`, computed with the protocol's own reader and
/// decoder (exactly what the device runs): one `(id, error)` per broken frame, nothing for
/// empty ones.
fn expected_errors(bytes: &[u8]) -> Vec<(u32, ErrorReply)> {
    let mut r = RequestReader::new();
    let mut out = Vec::new();
    for &b in bytes {
        if let Some(f) = r.push(b).into_frame(MAX_REQUEST_WIRE) {
            match f.and_then(decode_request) {
                Ok((id, req)) => panic!("test frame decodes: {id} {req:?}"),
                Err(e) => out.push((e.id(), e.reply())),
            }
        }
    }
    out
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

    // A map one row and column larger than the capacity's square.
    let side = (1..).find(|s: &u32| s * s > cells).expect("a side") as u16;
    let big = Map::from_fn(side, side, |_, _| false);
    let e = error_code(link.set_map(&big));
    assert_eq!(
        e,
        ErrorReply::with(
            ErrorCode::MapTooLarge,
            u32::from(side) * u32::from(side),
            cells
        )
    );
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
    link.set_map(&map).expect("set map");
    let slow = Params {
        iterations: 60_000,
        patience: 0,
        ..Params::default()
    };
    link.set_params(&slow).expect("set params");
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

    // A goal on an obstacle: bad input, exit 2, one line on stderr.
    let o = ohaca(&base(&["--start", "0,0", "--goal", "3,1"]));
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("goal is on an obstacle"), "{err}");
    assert!(o.stdout.is_empty());

    // A map larger than the device: refused before the upload, exit 2.
    let big = maps().join("movingai/random-32-32-10.map");
    let dir = tempfile::tempdir().expect("tempdir");
    let huge = dir.path().join("huge.map");
    let mut text = String::from("type octile\nheight 40\nwidth 40\nmap\n");
    for _ in 0..40 {
        text.push_str(&".".repeat(40));
        text.push('\n');
    }
    std::fs::write(&huge, text).expect("write map");
    let mut a = base(&["--start", "0,0", "--goal", "39,39"]);
    a[4] = huge.display().to_string();
    let o = ohaca(&a);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("map too large for the device"), "{err}");
    assert!(err.contains("1600 cells"), "{err}");

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

    // Bad arguments: neither --tcp nor --serial.
    let o = ohaca(&strings(&[
        "send", "--map", &complex, "--start", "0,0", "--goal", "25,25",
    ]));
    assert_eq!(o.status.code(), Some(2), "{o:?}");
}
