//! QEMU helpers shared by the firmware's end-to-end tests (`e2e.rs`, `soak.rs`, ...):
//! build the firmware once, boot it in `qemu-system-arm -M mps2-an386` with UART0 on a free
//! local TCP port (or a pty; or behind the pacing relay at a real baud rate: [`boot_paced`]),
//! connect a [`Link`], build broken frames, and compute what the
//! device must answer with the protocol's own reader and decoder, and what its plans must be
//! with the host's copy of the core.
//!
//! `main.rs` declares it first, with `#[macro_use]`, so every module sees `need_qemu!`; the
//! modules import it with `use crate::qemu;`.
#![allow(dead_code)]

use std::collections::HashMap;
use std::io::{BufRead, BufReader, Read};
use std::net::{TcpListener, TcpStream};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, OnceLock};
use std::time::{Duration, Instant};

use ohaca::protocol::{
    crc32, decode_request, ErrorCode, ErrorReply, RequestReader, MAX_REQUEST_WIRE,
};
use ohaca::{Params, Point};
use ohaca_host::link::relay::{Arrival, Counters, Relay, RelayStream, Stamp};
use ohaca_host::link::{DevicePath, Link};
use ohaca_host::{HeapStorage, Map};

/// How long any single reply may take (QEMU on a loaded 2-core CI machine can be slow).
pub const TIMEOUT: Duration = Duration::from_secs(120);

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

pub fn maps() -> PathBuf {
    root().join("maps")
}

/// The environment variable that lets the QEMU tests be skipped (`OHACA_SKIP_QEMU=1`).
pub const SKIP_VAR: &str = "OHACA_SKIP_QEMU";

/// True if QEMU can run. Without `qemu-system-arm` the test fails, unless `OHACA_SKIP_QEMU=1`
/// asks to skip it: then it prints a `SKIPPED` line and returns false. A missing QEMU never
/// passes silently.
pub fn have_qemu() -> bool {
    let skip = std::env::var(SKIP_VAR).is_ok_and(|v| v == "1");
    let ok = Command::new("qemu-system-arm")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if !ok {
        assert!(
            skip,
            "qemu-system-arm is missing: install it (apt-get install qemu-system-arm, or source \
             scripts/setup.sh), or set {SKIP_VAR}=1 to skip the firmware's end-to-end tests"
        );
        eprintln!(
            "SKIPPED: qemu-system-arm is not installed and {SKIP_VAR}=1 (this test did not run)"
        );
    }
    ok
}

/// Return early (skip the test, with a `SKIPPED` line) when QEMU is missing and
/// `OHACA_SKIP_QEMU=1`; fail when it is missing otherwise.
macro_rules! need_qemu {
    () => {
        if !have_qemu() {
            return;
        }
    };
}

/// The firmware ELF, built once per test run.
pub fn firmware() -> &'static Path {
    static ELF: OnceLock<PathBuf> = OnceLock::new();
    ELF.get_or_init(|| build_firmware("OHACA_FIRMWARE", &[], None))
}

/// The STM32H743's QEMU capacity twin (`--features twin-h743`, in `target/twin-h743`), built
/// once per test run; `OHACA_TWIN_FIRMWARE=path/to/elf` uses another ELF and skips the build.
pub fn twin_firmware() -> &'static Path {
    static ELF: OnceLock<PathBuf> = OnceLock::new();
    ELF.get_or_init(|| {
        build_firmware(
            "OHACA_TWIN_FIRMWARE",
            &["--features", "twin-h743"],
            Some(root().join("target/twin-h743")),
        )
    })
}

/// `cargo build --release -q` plus `args` in the workspace root, into `target_dir` (default: the
/// workspace's target directory); the ELF, or the path in `$var` if set (then nothing is built).
fn build_firmware(var: &str, args: &[&str], target_dir: Option<PathBuf>) -> PathBuf {
    if let Some(p) = std::env::var_os(var) {
        return PathBuf::from(p);
    }
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let mut c = Command::new(cargo);
    c.args(["build", "--release", "-q"]).args(args);
    if let Some(dir) = &target_dir {
        c.arg("--target-dir").arg(dir);
    }
    let out = c
        .current_dir(root())
        .stdout(Stdio::inherit())
        .output()
        .expect("run cargo build --release for the firmware");
    assert!(
        out.status.success(),
        "cargo build --release {args:?} (the firmware) failed:\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let target = target_dir
        .or_else(|| std::env::var_os("CARGO_TARGET_DIR").map(PathBuf::from))
        .unwrap_or_else(|| root().join("target"));
    let elf = target.join("thumbv7em-none-eabihf/release/ohaca");
    assert!(elf.is_file(), "no firmware at {}", elf.display());
    elf
}

/// A running QEMU with the firmware; killed on drop.
pub struct Qemu {
    child: Child,
    /// `127.0.0.1:PORT` of UART0 (TCP mode).
    pub addr: Option<String>,
    /// `/dev/pts/N` of UART0 (pty mode).
    pub pty: Option<String>,
}

impl Drop for Qemu {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Where the firmware's defmt log (QEMU's stdout) goes: discarded, unless `OHACA_QEMU_LOG` names
/// a file (decode it with `defmt-print -e target/thumbv7em-none-eabihf/release/ohaca < FILE`).
fn defmt_log() -> Stdio {
    std::env::var_os("OHACA_QEMU_LOG")
        .and_then(|p| std::fs::File::create(p).ok())
        .map_or_else(Stdio::null, Stdio::from)
}

fn qemu_command(serial: &str) -> Command {
    qemu_command_for(serial, firmware())
}

/// `qemu-system-arm` for the mps2-an386 board booting `elf` (semihosting for its logs), its
/// UART not chosen yet.
fn qemu_base(elf: &Path) -> Command {
    let mut c = Command::new("qemu-system-arm");
    c.args(["-M", "mps2-an386", "-display", "none", "-monitor", "none"])
        .args(["-semihosting-config", "enable=on,target=native"])
        .arg("-kernel")
        .arg(elf)
        .stdin(Stdio::null());
    c
}

fn qemu_command_for(serial: &str, elf: &Path) -> Command {
    let mut c = qemu_base(elf);
    c.args(["-serial", serial]);
    c
}

pub fn free_port() -> u16 {
    let l = TcpListener::bind("127.0.0.1:0").expect("bind a free port");
    l.local_addr().expect("local addr").port()
}

impl Qemu {
    /// Boot with UART0 on a free TCP port (`server=on,wait=off,nodelay=on`: one client at a
    /// time, a new one accepted after it disconnects); returns once the port accepts
    /// connections.
    pub fn tcp() -> Qemu {
        Qemu::tcp_with(firmware())
    }

    /// [`Qemu::tcp`] with another firmware ELF (e.g. [`twin_firmware`]).
    pub fn tcp_with(elf: &Path) -> Qemu {
        for _ in 0..5 {
            let port = free_port();
            let child = qemu_command_for(
                &format!("tcp:127.0.0.1:{port},server=on,wait=off,nodelay=on"),
                elf,
            )
            .stdout(defmt_log())
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
    pub fn pty() -> Qemu {
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

    pub fn addr(&self) -> &str {
        self.addr.as_deref().expect("a TCP QEMU")
    }

    /// True while QEMU runs (the firmware leaves it through semihosting on a panic or a hard
    /// fault, so a dead QEMU means a crashed device).
    pub fn is_running(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }

    /// A plain TCP connection to UART0 (`TCP_NODELAY`), retried while QEMU has not yet taken
    /// the previous client's disconnection.
    pub fn connect(&self) -> TcpStream {
        let t0 = Instant::now();
        loop {
            match TcpStream::connect(self.addr()) {
                Ok(s) => {
                    s.set_nodelay(true).expect("nodelay");
                    return s;
                }
                Err(e) if t0.elapsed() > Duration::from_secs(30) => panic!("connect: {e}"),
                Err(_) => std::thread::sleep(Duration::from_millis(50)),
            }
        }
    }

    /// A [`Link`] over TCP (it sends a leading `00` to flush a partial frame).
    pub fn link(&self) -> Link<TcpStream> {
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

/// A running QEMU whose UART0 is behind a pacing relay (`ohaca_host::link::relay`: a real
/// serial line, `baud` 8N1, between the test and the emulated UART); QEMU is killed on drop,
/// then the relay stops.
pub struct PacedQemu {
    child: Child,
    /// The relay (its counters: [`Relay::counters`]; more clients: [`Relay::client`]).
    pub relay: Relay,
}

impl Drop for PacedQemu {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl PacedQemu {
    /// True while QEMU runs.
    pub fn is_running(&mut self) -> bool {
        matches!(self.child.try_wait(), Ok(None))
    }
}

/// How long a [`boot_paced`] link waits for each reply.
pub const PACED_TIMEOUT: Duration = Duration::from_secs(30);

/// Boot the firmware ([`firmware`]) with UART0 behind a relay at `baud`: the QEMU, a [`Link`]
/// over the relay's in-process client (its line clocks: `link.transport().wait_sent(..)` and
/// `.take_arrivals()`), and the relay's counters.
pub fn boot_paced(baud: u32) -> (PacedQemu, Link<RelayStream>, Arc<Counters>) {
    boot_paced_with(firmware(), baud)
}

/// [`boot_paced`] with another firmware ELF.
pub fn boot_paced_with(elf: &Path, baud: u32) -> (PacedQemu, Link<RelayStream>, Arc<Counters>) {
    let mut c = qemu_base(elf);
    c.stdout(defmt_log()).stderr(Stdio::inherit());
    paced(c, baud)
}

/// [`boot_paced`] under `-icount shift=0` (one device tick = 1000 instructions), the firmware's
/// defmt log (QEMU's stdout) kept in `log` for [`device_log`].
pub fn boot_paced_icount(baud: u32, log: &Path) -> (PacedQemu, Link<RelayStream>, Arc<Counters>) {
    let mut c = qemu_base(firmware());
    c.args(["-icount", "shift=0"]);
    let file = std::fs::File::create(log).expect("create the defmt log file");
    c.stdout(Stdio::from(file)).stderr(Stdio::inherit());
    paced(c, baud)
}

/// The firmware's defmt log so far, decoded by `defmt-print` (message only, one line each).
pub fn device_log(log: &Path) -> Vec<String> {
    let input = std::fs::File::open(log).expect("open the defmt log");
    let out = Command::new("defmt-print")
        .arg("-e")
        .arg(firmware())
        .args(["--log-format", "{s}"])
        .stdin(Stdio::from(input))
        .stderr(Stdio::null())
        .output()
        .expect("run defmt-print (scripts/install-defmt-print.sh installs it)");
    String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(str::to_string)
        .collect()
}

/// The device-side times in the log ([`device_log`]) of the QEMU board's latency lines
/// (`request ID in at TICK`, `reply ID out at TICK`: `src/firmware/board/mod.rs`), by id: when
/// each request's frame ended, and when each small reply to it was handed to the UART.
pub fn device_times(lines: &[String]) -> (HashMap<u32, u64>, HashMap<u32, Vec<u64>>) {
    let mut ins = HashMap::new();
    let mut outs: HashMap<u32, Vec<u64>> = HashMap::new();
    for l in lines {
        let w: Vec<&str> = l.split_whitespace().collect();
        let num = |i: usize| w.get(i).and_then(|v| v.parse::<u64>().ok());
        match (w.first().copied(), num(1), w.get(2).copied(), num(4)) {
            (Some("request"), Some(id), Some("in"), Some(t)) => {
                ins.insert(id as u32, t);
            }
            (Some("reply"), Some(id), Some("out"), Some(t)) => {
                outs.entry(id as u32).or_default().push(t);
            }
            _ => {}
        }
    }
    (ins, outs)
}

fn paced(mut c: Command, baud: u32) -> (PacedQemu, Link<RelayStream>, Arc<Counters>) {
    let (child, relay) = Relay::spawn_qemu(&mut c, baud).expect("start QEMU behind the relay");
    let counters = relay.counters();
    let q = PacedQemu { child, relay };
    let mut link = Link::new(q.relay.client(), TIMEOUT).expect("a link over the relay");
    // As on a real board, bytes sent before the firmware takes them are lost (QEMU reads its
    // socket only once the UART receives, and the socket holds a few bytes): say Hello until the
    // device answers, then forget the strays of the partial frames.
    link.set_timeout(Duration::from_millis(300));
    let t0 = Instant::now();
    while link.hello().is_err() {
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "the firmware never answered Hello"
        );
        let _ = link.send_raw(&[0]);
    }
    // Every reply the paced tests wait for comes within seconds: fail in 30 s, not 120.
    link.set_timeout(PACED_TIMEOUT);
    link.take_strays();
    (q, link, counters)
}

// ---- reply frames on the line ---------------------------------------------------------

/// One reply frame as it arrived: its id, its length on the wire (with the delimiter), and the
/// clocks of its first and last byte.
#[derive(Debug)]
pub struct Frame {
    pub id: u32,
    pub kind: &'static str,
    pub len: u64,
    pub first: Stamp,
    pub last: Stamp,
}

/// Split what arrived into reply frames (the protocol's own reader and decoder).
pub fn frames(arrivals: &[Arrival]) -> Vec<Frame> {
    let mut reader = Box::new(ohaca::protocol::ReplyReader::new());
    let mut out = Vec::new();
    let mut start = 0;
    for (i, a) in arrivals.iter().enumerate() {
        if a.byte == 0 && start == i {
            // A delimiter with no frame before it.
            start = i + 1;
            let _ = reader.push(0);
            continue;
        }
        if let Some(f) = reader
            .push(a.byte)
            .into_frame(ohaca::protocol::MAX_REPLY_WIRE)
        {
            let (id, kind) = match f.and_then(ohaca::protocol::decode_reply) {
                Ok((id, r)) => (id, ohaca_host::link::Response::from(&r).kind()),
                Err(_) => (0, "undecodable"),
            };
            out.push(Frame {
                id,
                kind,
                len: (i + 1 - start) as u64,
                first: arrivals[start].stamp,
                last: a.stamp,
            });
            start = i + 1;
        }
    }
    out
}

// ---- frames --------------------------------------------------------------------------------

/// COBS encode (the protocol's own encoder is private): for building broken frames.
pub fn cobs(data: &[u8]) -> Vec<u8> {
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
pub fn frame_of(body: &[u8]) -> Vec<u8> {
    let mut p = body.to_vec();
    p.extend_from_slice(&crc32(body).to_le_bytes());
    let mut f = cobs(&p);
    f.push(0);
    f
}

/// What the firmware must answer to `bytes` (starting at a frame boundary), computed with the
/// protocol's own reader and decoder (exactly what the device runs): one `(id, error)` per
/// broken frame, nothing for empty ones. `None` if a frame in `bytes` decodes as a request.
pub fn try_expected_errors(bytes: &[u8]) -> Option<Vec<(u32, ErrorReply)>> {
    let mut r = RequestReader::new();
    let mut out = Vec::new();
    for &b in bytes {
        if let Some(f) = r.push(b).into_frame(MAX_REQUEST_WIRE) {
            match f.and_then(decode_request) {
                Ok(_) => return None,
                Err(e) => out.push((e.id(), e.reply())),
            }
        }
    }
    Some(out)
}

/// [`try_expected_errors`] for bytes known to hold no valid request.
pub fn expected_errors(bytes: &[u8]) -> Vec<(u32, ErrorReply)> {
    try_expected_errors(bytes).unwrap_or_else(|| panic!("test frame decodes: {bytes:02x?}"))
}

// ---- the host's reference ------------------------------------------------------------------

/// The longest scenario of a Moving AI scenario file under `maps/` (start, goal): the largest
/// optimum, the first of equals.
pub fn longest_scenario(scen: &str) -> (Point, Point) {
    let text = std::fs::read_to_string(maps().join(scen)).expect("scenario file");
    let mut best: Option<(f64, Point, Point)> = None;
    for l in text.lines().skip(1) {
        let f: Vec<&str> = l.split('\t').collect();
        let n = |i: usize| f.get(i).and_then(|v| v.trim().parse::<u16>().ok());
        let (Some(sx), Some(sy), Some(gx), Some(gy)) = (n(4), n(5), n(6), n(7)) else {
            continue;
        };
        let Some(len) = f.get(8).and_then(|v| v.trim().parse::<f64>().ok()) else {
            continue;
        };
        if best.is_none_or(|(b, _, _)| len > b) {
            best = Some((len, Point::new(sx, sy), Point::new(gx, gy)));
        }
    }
    let (_, s, g) = best.expect("scenarios");
    (s, g)
}

/// A plan as the host's copy of the core computes it: every field of a `Path` reply but
/// `ticks`.
#[derive(Clone, Debug, PartialEq)]
pub struct CorePath {
    pub raw_length: f32,
    pub length: f32,
    pub turns: u32,
    pub iterations: u16,
    pub best_iteration: u16,
    pub moves: u64,
    pub raw_cells: u32,
    pub origin: ohaca::planner::Origin,
    pub waypoints: Vec<Point>,
    pub directions: Vec<u8>,
}

/// The default QEMU firmware's longest ant path, the STM32F411's (`ohaca::board::F411`, Hello's
/// `capacity.max_steps`; `qemu/e2e.rs`'s maze test checks it against Hello).
pub const DEVICE_STEPS: usize = ohaca::board::F411.max_steps;

/// Plan as the firmware does (`ohaca::plan` on the map's grid), on the host: the path, or the
/// error reply the device must send.
pub fn core_plan(
    map: &Map,
    start: Point,
    goal: Point,
    params: &Params,
) -> Result<CorePath, ErrorReply> {
    core_plan_on(ohaca::board::F411, map, start, goal, params)
}

/// Plan as `board`'s firmware does, in the buffers `ohaca plan --board` lends the core
/// (`ohaca_host::board::BoardStorage`, from the board's description `ohaca::board`).
pub fn core_plan_on(
    board: ohaca::board::Board,
    map: &Map,
    start: Point,
    goal: Point,
    params: &Params,
) -> Result<CorePath, ErrorReply> {
    use ohaca_host::board::BoardError;
    let grid = map.grid().map_err(ErrorReply::from)?;
    params.validate().map_err(ErrorReply::from)?;
    let reply = |e: BoardError| match e {
        BoardError::Core(e) => ErrorReply::from(e),
        BoardError::TooLarge {
            cells, capacity, ..
        } => ErrorReply::with(ErrorCode::MapTooLarge, cells as u32, capacity as u32),
        BoardError::Storage(e) => panic!("host storage: {e}"),
    };
    let iterations = usize::from(params.iterations);
    let mut storage =
        ohaca_host::board::BoardStorage::new(board, map.cells(), iterations).map_err(reply)?;
    let ws = storage.workspace().map_err(reply)?;
    let plan = ohaca::plan(&grid, start, goal, params, ws)?;
    Ok(core_path(&plan))
}

/// [`core_plan`] for a device that keeps ant paths of up to `steps` steps (Hello's
/// `capacity.max_steps`), with the device's workspace shape: links for `steps` (at most
/// tightening's smallest table for them, at least the coarse route's blocks: the STM32H743's
/// 16,384), the move table only on maps of up to 1024 cells, as the firmware has it
/// (`firmware::buffers`). The host keeps
/// the iteration's best and worst paths where the firmware (every board) walks those ants again, so a
/// match also checks that both ways plan alike.
pub fn core_plan_steps(
    map: &Map,
    start: Point,
    goal: Point,
    params: &Params,
    steps: usize,
) -> Result<CorePath, ErrorReply> {
    core_plan_with(map, start, goal, params, steps, map.cells() <= 1024)
}

fn core_plan_with(
    map: &Map,
    start: Point,
    goal: Point,
    params: &Params,
    steps: usize,
    moves: bool,
) -> Result<CorePath, ErrorReply> {
    let grid = map.grid().map_err(ErrorReply::from)?;
    params.validate().map_err(ErrorReply::from)?;
    let links = ohaca::tighten::hash_words(steps + 1).max(ohaca::route::GUIDE_BLOCKS);
    let mut storage =
        HeapStorage::with_steps(map.cells(), steps, moves, usize::from(params.iterations))
            .expect("host storage")
            .with_links(links);
    let plan = ohaca::plan(&grid, start, goal, params, storage.workspace())?;
    Ok(core_path(&plan))
}

/// The fields of a `Path` reply from a host plan.
fn core_path(plan: &ohaca::Plan<'_>) -> CorePath {
    CorePath {
        raw_length: plan.raw_length,
        length: plan.length,
        turns: plan.turns,
        iterations: plan.iterations,
        best_iteration: plan.best_iteration,
        moves: plan.moves,
        raw_cells: u32::try_from(plan.raw_len()).expect("raw cells"),
        origin: plan.origin,
        waypoints: plan.waypoints().to_vec(),
        directions: plan.directions().to_vec(),
    }
}

/// The device's path must be the host core's, bit for bit (floats compared by their bits).
pub fn assert_core_path(what: &str, core: &CorePath, dev: &DevicePath) {
    let bits = |p: &CorePath| (p.raw_length.to_bits(), p.length.to_bits());
    let dev_core = CorePath {
        raw_length: dev.raw_length,
        length: dev.length,
        turns: dev.turns,
        iterations: dev.iterations,
        best_iteration: dev.best_iteration,
        moves: dev.moves,
        raw_cells: dev.raw_cells,
        origin: dev.origin,
        waypoints: dev.waypoints.clone(),
        directions: dev.directions.clone(),
    };
    assert_eq!(dev_core, *core, "{what}: device path vs host core");
    assert_eq!(bits(&dev_core), bits(core), "{what}: length bits");
}

/// A reply as a reader thread hands it on: decoded (the parts of a long path put together), or
/// why the link failed.
pub type Incoming = Result<(u32, ohaca_host::link::Response), String>;

/// Reply frames that were parts of long paths, the paths begun in parts (first parts: the
/// device's `parted` counts them, cancelled ones included), and the paths put together from
/// them, as a [`read_replies_counting`] thread counts them.
#[derive(Debug, Default)]
pub struct PartCounts {
    pub frames: std::sync::atomic::AtomicU64,
    pub begun: std::sync::atomic::AtomicU64,
    pub paths: std::sync::atomic::AtomicU64,
}

/// Read reply frames until the connection closes (a TCP socket to QEMU, or a relay client:
/// [`PacedQemu::relay`]); every reply goes to `tx`, decoded, the parts of a long path as one
/// `Path` ([`ohaca_host::link::Assembler`]).
pub fn read_replies(s: impl Read, tx: std::sync::mpsc::Sender<Incoming>) {
    read_replies_counting(s, tx, &PartCounts::default());
}

/// [`read_replies`], counting the part frames and the paths made of them in `counts` (the
/// device's `tx_frames` counts every frame, so each parted path adds its parts less one).
pub fn read_replies_counting(
    mut s: impl Read,
    tx: std::sync::mpsc::Sender<Incoming>,
    counts: &PartCounts,
) {
    use ohaca::protocol::{decode_reply, ReplyReader, MAX_REPLY_WIRE};
    use ohaca_host::link::{Assembler, Response};
    use std::sync::atomic::Ordering;
    let mut reader = Box::new(ReplyReader::new());
    let mut parts = Assembler::default();
    let mut buf = vec![0u8; 8192];
    loop {
        let n = match s.read(&mut buf) {
            Ok(0) => {
                let _ = tx.send(Err("the device closed the connection".into()));
                return;
            }
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => {
                let _ = tx.send(Err(format!("read: {e}")));
                return;
            }
        };
        for &b in &buf[..n] {
            if let Some(f) = reader.push(b).into_frame(MAX_REPLY_WIRE) {
                let mut part = false;
                let r = f
                    .and_then(decode_reply)
                    .and_then(|(id, r)| {
                        let resp = Response::from(&r);
                        part = matches!(resp, Response::Part(_));
                        if matches!(&resp, Response::Part(p) if p.offset == 0) {
                            counts.begun.fetch_add(1, Ordering::AcqRel);
                        }
                        Ok((id, parts.push(id, resp)?))
                    })
                    .map_err(|e| format!("undecodable reply frame: {e}"));
                if part {
                    counts.frames.fetch_add(1, Ordering::AcqRel);
                }
                let r = match r {
                    Ok((_, None)) => continue, // a part; the path comes with its last
                    Ok((id, Some(resp))) => {
                        if part {
                            counts.paths.fetch_add(1, Ordering::AcqRel);
                        }
                        Ok((id, resp))
                    }
                    Err(e) => Err(e),
                };
                if tx.send(r).is_err() {
                    return;
                }
            }
        }
    }
}
