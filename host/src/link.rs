//! The host side of the firmware link: a blocking client of the wire protocol
//! ([`ohaca::protocol`], `docs/PROTOCOL.md`) over any byte stream that implements [`Transport`]
//! — a TCP socket to QEMU ([`Link::tcp`]) or a serial port ([`Link::serial`]).
//!
//! * Request ids start at 1 and increase (0 is [`UNKNOWN_ID`], never used).
//! * Every call waits for the reply carrying its id, at most [`Link::timeout`] (default
//!   [`DEFAULT_TIMEOUT`]); nothing blocks longer than that, reads and writes included.
//! * Replies for other requests still in flight are kept for their caller; replies nobody waits
//!   for (a late answer to a timed-out request, the device's `id 0` answers to frames it could
//!   not read) are *strays*: skipped, counted and kept for the caller to report
//!   ([`Link::take_strays`]).
//! * Maps are uploaded in chunks of at most [`MAX_CHUNK`] bytes (less if the device says so),
//!   run-length coded when that is shorter ([`Link::set_map`], [`MapCode`]), with up to
//!   [`UPLOAD_WINDOW`] chunks in flight.
//! * [`Link::plan_many`] pipelines plans, keeping up to the device's `plan_queue` in flight, and
//!   returns the outcomes in request order.
//! * Every failure is a [`LinkError`]: a timeout, a device error reply (with its code), a closed
//!   connection, an undecodable frame, ...
//!
//! ```no_run
//! use ohaca::Point;
//! use ohaca_host::link::Link;
//! use ohaca_host::Map;
//! # fn main() -> Result<(), Box<dyn std::error::Error>> {
//! let mut link = Link::tcp("127.0.0.1:4444", ohaca_host::link::DEFAULT_TIMEOUT)?;
//! let hello = link.hello()?;
//! let map = Map::load("maps/complex-26.map")?;
//! link.set_map(&map)?;
//! let path = link.plan(Point::new(0, 0), Point::new(25, 25), None)?;
//! println!("{} on {}: {} waypoints", path.length, hello.board, path.waypoints.len());
//! # Ok(()) }
//! ```

use std::collections::{BTreeMap, HashMap, HashSet, VecDeque};
use std::io::{self, Read, Write};
use std::net::{TcpStream, ToSocketAddrs};
use std::time::{Duration, Instant};

use ohaca::grid::{DX, DY};
use ohaca::protocol::{
    decode_reply, encode_request, Capacity, DecodeError, EncodeError, ErrorCode, ErrorReply,
    HelloReply, PathReply, Reply, ReplyReader, Request, RleEncoder, StatsReply, Waypoints,
    MAX_CHUNK, MAX_REPLY_WIRE, MAX_REQUEST_WIRE, MAX_UPDATE_CELLS, UNKNOWN_ID, VERSION,
};
use ohaca::{Params, Point};

use crate::map::Map;

/// How long a call waits for its reply unless told otherwise.
pub const DEFAULT_TIMEOUT: Duration = Duration::from_secs(10);

/// The serial line speed unless told otherwise (the firmware's UART: 115200 8N1).
pub const DEFAULT_BAUD: u32 = 115_200;

/// Map chunks in flight during an upload: 3 frames of at most ~150 bytes stay well within a
/// board's 1 KiB receive ring (docs/FIRMWARE.md), and hide the round trip of each `Ack`.
pub const UPLOAD_WINDOW: usize = 3;

/// How a map goes on the wire: the packed bits (`SetMap`) or their run-length code
/// (`SetMapRle`), whichever is shorter.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum MapCode {
    /// The packed bits.
    Raw(Vec<u8>),
    /// The run-length code ([`RleEncoder`]).
    Rle(Vec<u8>),
}

impl MapCode {
    /// The shorter coding of `map`.
    pub fn of(map: &Map) -> Self {
        let cells = u32::from(map.width) * u32::from(map.height);
        let rle: Vec<u8> = RleEncoder::new(&map.bits, cells).collect();
        if rle.len() < map.bits.len() {
            MapCode::Rle(rle)
        } else {
            MapCode::Raw(map.bits.clone())
        }
    }

    /// The bytes uploaded.
    pub fn bytes(&self) -> &[u8] {
        match self {
            MapCode::Raw(b) | MapCode::Rle(b) => b,
        }
    }

    /// The request carrying `chunk` at `offset`.
    fn request<'a>(&self, width: u16, height: u16, offset: usize, chunk: &'a [u8]) -> Request<'a> {
        let offset = u32::try_from(offset).unwrap_or(u32::MAX);
        let total_len = u32::try_from(self.bytes().len()).unwrap_or(u32::MAX);
        match self {
            MapCode::Raw(_) => Request::SetMap {
                width,
                height,
                offset,
                total_len,
                chunk,
            },
            MapCode::Rle(_) => Request::SetMapRle {
                width,
                height,
                offset,
                total_len,
                chunk,
            },
        }
    }
}

/// Most stray frames kept for [`Link::take_strays`] (older ones are only counted).
const MAX_STRAYS: usize = 64;

/// A byte stream to the device whose reads and writes can be bounded in time.
pub trait Transport: Read + Write {
    /// Make every later `read` and `write` give up (with `TimedOut` or `WouldBlock`) after
    /// `timeout`.
    fn set_io_timeout(&mut self, timeout: Duration) -> io::Result<()>;
}

impl Transport for TcpStream {
    fn set_io_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        let t = Some(timeout.max(Duration::from_millis(1)));
        self.set_read_timeout(t)?;
        self.set_write_timeout(t)
    }
}

impl<T: Transport + ?Sized> Transport for Box<T> {
    fn set_io_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        (**self).set_io_timeout(timeout)
    }
}

/// A serial port (a USB-serial adapter, a pty) as a [`Transport`].
pub struct Serial(pub Box<dyn serialport::SerialPort>);

impl Read for Serial {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        self.0.read(buf)
    }
}

impl Write for Serial {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.0.write(buf)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.0.flush()
    }
}

impl Transport for Serial {
    fn set_io_timeout(&mut self, timeout: Duration) -> io::Result<()> {
        self.0
            .set_timeout(timeout.max(Duration::from_millis(1)))
            .map_err(io::Error::from)
    }
}

/// What the device said in its [`Reply::Hello`], owned.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceInfo {
    /// Its protocol version ([`VERSION`] if it matches this tool).
    pub protocol_version: u16,
    /// Its firmware version.
    pub firmware_version: String,
    /// Its board, e.g. `qemu-mps2-an386`.
    pub board: String,
    /// Its limits.
    pub capacity: Capacity,
    /// The parameters it uses until told otherwise.
    pub defaults: Params,
}

impl From<&HelloReply<'_>> for DeviceInfo {
    fn from(h: &HelloReply<'_>) -> Self {
        DeviceInfo {
            protocol_version: h.protocol_version,
            firmware_version: h.firmware_version.to_string(),
            board: h.board.to_string(),
            capacity: h.capacity,
            defaults: h.defaults,
        }
    }
}

/// A [`Reply::Path`], owned.
#[derive(Clone, Debug, PartialEq)]
pub struct DevicePath {
    /// Length of the raw 8-connected path.
    pub raw_length: f32,
    /// Length through the waypoints.
    pub length: f32,
    /// Turns along the waypoints.
    pub turns: u32,
    /// Iterations run.
    pub iterations: u16,
    /// 0-based iteration that found the best path.
    pub best_iteration: u16,
    /// Ant moves over the run.
    pub moves: u64,
    /// Device time of the run, in `tick_hz` units.
    pub ticks: u64,
    /// Cells of the raw path.
    pub raw_cells: u32,
    /// The device kept its previous colony (`PlanWarm` planned warm).
    pub warm: bool,
    /// Waypoints, start first.
    pub waypoints: Vec<Point>,
    /// The raw path as directions from the start (`0..8` = E, SE, S, SW, W, NW, N, NE).
    pub directions: Vec<u8>,
}

impl From<&PathReply<'_>> for DevicePath {
    fn from(p: &PathReply<'_>) -> Self {
        DevicePath {
            raw_length: p.raw_length,
            length: p.length,
            turns: p.turns,
            iterations: p.iterations,
            best_iteration: p.best_iteration,
            moves: p.moves,
            ticks: p.ticks,
            raw_cells: p.raw_cells,
            warm: p.warm,
            waypoints: p.waypoints.iter().collect(),
            directions: p.directions.to_vec(),
        }
    }
}

impl DevicePath {
    /// The raw path's cells from `start`, decoded from [`DevicePath::directions`]. Fails if a
    /// direction is not `0..8` or a step leaves the `u16` coordinate range.
    pub fn raw(&self, start: Point) -> Result<Vec<Point>, LinkError> {
        raw_path(start, &self.directions)
    }
}

/// Follow `directions` from `start`: every cell of the raw path, `start` first.
pub fn raw_path(start: Point, directions: &[u8]) -> Result<Vec<Point>, LinkError> {
    let mut out = Vec::with_capacity(directions.len() + 1);
    let mut p = start;
    out.push(p);
    for (i, &d) in directions.iter().enumerate() {
        let (Some(dx), Some(dy)) = (DX.get(usize::from(d)), DY.get(usize::from(d))) else {
            return Err(LinkError::BadPath(format!(
                "step {i} has direction {d} (expected 0..8)"
            )));
        };
        let x = u16::try_from(i32::from(p.x) + dx);
        let y = u16::try_from(i32::from(p.y) + dy);
        let (Ok(x), Ok(y)) = (x, y) else {
            return Err(LinkError::BadPath(format!(
                "step {i} leaves the coordinate range at ({}, {})",
                p.x, p.y
            )));
        };
        p = Point::new(x, y);
        out.push(p);
    }
    Ok(out)
}

/// A reply, owned (decoded replies borrow the frame buffer).
#[derive(Clone, Debug, PartialEq)]
pub enum Response {
    /// [`Reply::Hello`].
    Hello(DeviceInfo),
    /// [`Reply::Ack`].
    Ack,
    /// [`Reply::Path`].
    Path(DevicePath),
    /// [`Reply::Error`].
    Error(ErrorReply),
    /// [`Reply::Stats`].
    Stats(StatsReply),
}

impl From<&Reply<'_>> for Response {
    fn from(r: &Reply<'_>) -> Self {
        match r {
            Reply::Hello(h) => Response::Hello(h.into()),
            Reply::Ack => Response::Ack,
            Reply::Path(p) => Response::Path(p.into()),
            Reply::Error(e) => Response::Error(*e),
            Reply::Stats(s) => Response::Stats(*s),
        }
    }
}

impl Response {
    /// The reply's name: `Hello`, `Ack`, `Path`, `Error`, `Stats`.
    pub fn kind(&self) -> &'static str {
        match self {
            Response::Hello(_) => "Hello",
            Response::Ack => "Ack",
            Response::Path(_) => "Path",
            Response::Error(_) => "Error",
            Response::Stats(_) => "Stats",
        }
    }
}

/// The name of a request, for messages.
pub fn request_name(r: &Request<'_>) -> &'static str {
    match r {
        Request::Hello => "Hello",
        Request::SetMap { .. } => "SetMap",
        Request::SetParams(_) => "SetParams",
        Request::Plan { .. } => "Plan",
        Request::Cancel => "Cancel",
        Request::Stats => "Stats",
        Request::SetMapRle { .. } => "SetMapRle",
        Request::SetRect { .. } => "SetRect",
        Request::SetCells { .. } => "SetCells",
        Request::PlanWarm { .. } => "PlanWarm",
    }
}

/// A reply nobody was waiting for.
#[derive(Clone, Debug, PartialEq)]
pub enum Stray {
    /// A reply whose id is not in flight (0: the device could not read some frame).
    Reply {
        /// Its id.
        id: u32,
        /// What it said.
        response: Response,
    },
}

impl std::fmt::Display for Stray {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Stray::Reply {
                id,
                response: Response::Error(e),
            } => write!(f, "reply {id}: error {} ({e})", e.code.code()),
            Stray::Reply { id, response } => write!(f, "reply {id}: {}", response.kind()),
        }
    }
}

/// Why a call failed.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// The transport could not be opened.
    #[error("cannot open {target}: {source}")]
    Open {
        /// The address or device path.
        target: String,
        /// What the operating system said.
        #[source]
        source: io::Error,
    },
    /// No reply in time.
    #[error("no reply to {request} (request {id}) within {}", secs(*.timeout))]
    Timeout {
        /// The request waited for.
        request: &'static str,
        /// Its id.
        id: u32,
        /// How long the call waited.
        timeout: Duration,
    },
    /// The device (or QEMU) closed the connection.
    #[error("the device closed the connection")]
    Disconnected,
    /// Reading or writing failed.
    #[error("i/o error on the link: {0}")]
    Io(#[source] io::Error),
    /// The device answered with an error reply.
    #[error("device refused {request}: {error} (error code {})", .error.code.code())]
    Device {
        /// The request it refused.
        request: &'static str,
        /// Its error reply.
        error: ErrorReply,
    },
    /// A frame from the device did not decode (corrupted on the line, or a different protocol).
    #[error("undecodable frame from the device: {0}")]
    Decode(DecodeError),
    /// The device answered with the wrong kind of reply.
    #[error("device answered {request} with {got}")]
    Unexpected {
        /// The request.
        request: &'static str,
        /// The reply's kind.
        got: &'static str,
    },
    /// A request could not be encoded (over the protocol's limits).
    #[error("cannot encode {request}: {error}")]
    Encode {
        /// The request.
        request: &'static str,
        /// Why.
        error: EncodeError,
    },
    /// The device speaks another protocol version.
    #[error(
        "the device speaks protocol version {device}, this tool version {host}: \
         rebuild the firmware or the tool from the same sources"
    )]
    Version {
        /// The device's version.
        device: u16,
        /// [`VERSION`].
        host: u16,
    },
    /// The device sent a path that cannot be followed.
    #[error("bad path from the device: {0}")]
    BadPath(String),
}

impl LinkError {
    /// The device's error code, for [`LinkError::Device`].
    pub fn code(&self) -> Option<ErrorCode> {
        match self {
            LinkError::Device { error, .. } => Some(error.code),
            _ => None,
        }
    }
}

/// `10 s`, `0.5 s`.
fn secs(d: Duration) -> String {
    format!("{} s", d.as_secs_f64())
}

/// An io error that means the peer went away.
fn is_disconnect(e: &io::Error) -> bool {
    use io::ErrorKind::*;
    // EIO: the other side of a pty was closed (QEMU exited).
    matches!(
        e.kind(),
        BrokenPipe | ConnectionReset | ConnectionAborted | UnexpectedEof | NotConnected
    ) || (cfg!(unix) && e.raw_os_error() == Some(5))
}

/// An io error that means "nothing yet".
fn is_timeout(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut | io::ErrorKind::Interrupted
    )
}

/// One plan of a [`Link::plan_many`] batch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlanJob {
    /// Start cell.
    pub start: Point,
    /// Goal cell.
    pub goal: Point,
    /// Seed for this plan only (`None`: the parameters' seed).
    pub seed: Option<u64>,
}

/// The answer to one [`PlanJob`].
#[derive(Clone, Debug, PartialEq)]
pub struct PlanOutcome {
    /// Id of the request that was answered.
    pub id: u32,
    /// The path, or the device's error (e.g. `NoPath`, `GoalBlocked`).
    pub result: Result<DevicePath, ErrorReply>,
    /// From sending the request to receiving its reply.
    pub round_trip: Duration,
}

/// A blocking protocol client over a [`Transport`]. See the module docs.
pub struct Link<T: Transport> {
    io: T,
    reader: Box<ReplyReader>,
    rx: Vec<u8>,
    rx_pos: usize,
    rx_len: usize,
    next_id: u32,
    timeout: Duration,
    /// Ids sent and not yet answered.
    outstanding: HashSet<u32>,
    /// Replies to outstanding ids that arrived while another was awaited.
    buffered: VecDeque<(u32, Response)>,
    strays: Vec<Stray>,
    stray_count: u64,
    info: Option<DeviceInfo>,
}

impl Link<TcpStream> {
    /// Connect over TCP (`HOST:PORT`, e.g. QEMU's `-serial tcp:...`), with `TCP_NODELAY`.
    /// `timeout` bounds the connection attempt and becomes the link's [`Link::timeout`].
    pub fn tcp(addr: &str, timeout: Duration) -> Result<Self, LinkError> {
        let open_err = |source| LinkError::Open {
            target: addr.to_string(),
            source,
        };
        let addrs: Vec<_> = addr.to_socket_addrs().map_err(open_err)?.collect();
        let mut last = io::Error::new(io::ErrorKind::NotFound, "no address");
        for a in addrs {
            match TcpStream::connect_timeout(&a, timeout.max(Duration::from_millis(1))) {
                Ok(s) => {
                    s.set_nodelay(true).map_err(open_err)?;
                    return Link::new(s, timeout);
                }
                Err(e) => last = e,
            }
        }
        Err(open_err(last))
    }
}

impl Link<Serial> {
    /// Open a serial device (`/dev/ttyUSB0`, `/dev/ttyACM0`, a pty, `COM3`) at `baud`, 8N1, no
    /// flow control; unread input is discarded.
    pub fn serial(path: &str, baud: u32, timeout: Duration) -> Result<Self, LinkError> {
        let open_err = |e: serialport::Error| LinkError::Open {
            target: path.to_string(),
            source: io::Error::from(e),
        };
        let port = serialport::new(path, baud)
            .data_bits(serialport::DataBits::Eight)
            .parity(serialport::Parity::None)
            .stop_bits(serialport::StopBits::One)
            .flow_control(serialport::FlowControl::None)
            .timeout(timeout.max(Duration::from_millis(1)))
            .open()
            .map_err(open_err)?;
        // Ignore a failure: a pty, for one, may not support it, and nothing depends on it.
        let _ = port.clear(serialport::ClearBuffer::Input);
        Link::new(Serial(port), timeout)
    }
}

impl<T: Transport> Link<T> {
    /// A link over an open transport. Sends one `00` byte, so a partial frame left in the
    /// device's reader (from an earlier client) is flushed out instead of swallowing the first
    /// request.
    pub fn new(io: T, timeout: Duration) -> Result<Self, LinkError> {
        let mut link = Link {
            io,
            reader: Box::new(ReplyReader::new()),
            rx: vec![0; 4096],
            rx_pos: 0,
            rx_len: 0,
            next_id: 1,
            timeout,
            outstanding: HashSet::new(),
            buffered: VecDeque::new(),
            strays: Vec::new(),
            stray_count: 0,
            info: None,
        };
        link.send_raw(&[0])?;
        Ok(link)
    }

    /// How long each call waits for its reply.
    pub fn timeout(&self) -> Duration {
        self.timeout
    }

    /// Change [`Link::timeout`].
    pub fn set_timeout(&mut self, timeout: Duration) {
        self.timeout = timeout;
    }

    /// What the device said in the last [`Link::hello`].
    pub fn info(&self) -> Option<&DeviceInfo> {
        self.info.as_ref()
    }

    /// The transport.
    pub fn transport(&mut self) -> &mut T {
        &mut self.io
    }

    /// Stray replies skipped so far (the last [`MAX_STRAYS`]), emptied.
    pub fn take_strays(&mut self) -> Vec<Stray> {
        std::mem::take(&mut self.strays)
    }

    /// How many stray replies were skipped since the link was opened.
    pub fn stray_count(&self) -> u64 {
        self.stray_count
    }

    /// Write bytes as they are (a test may send broken frames). Bounded by [`Link::timeout`].
    pub fn send_raw(&mut self, bytes: &[u8]) -> Result<(), LinkError> {
        self.io
            .set_io_timeout(self.timeout)
            .map_err(LinkError::Io)?;
        match self.io.write_all(bytes).and_then(|()| self.io.flush()) {
            Ok(()) => Ok(()),
            Err(e) if is_timeout(&e) => Err(LinkError::Timeout {
                request: "write",
                id: 0,
                timeout: self.timeout,
            }),
            Err(e) if is_disconnect(&e) => Err(LinkError::Disconnected),
            Err(e) => Err(LinkError::Io(e)),
        }
    }

    /// The id the next request will get.
    pub fn next_id(&self) -> u32 {
        self.next_id
    }

    /// Send a request without waiting; returns its id. Its reply is kept until
    /// [`Link::wait_for`] (or [`Link::recv`]) takes it.
    pub fn send(&mut self, req: &Request<'_>) -> Result<u32, LinkError> {
        let id = self.next_id;
        self.next_id = self.next_id.checked_add(1).unwrap_or(1);
        let mut buf = [0u8; MAX_REQUEST_WIRE];
        let n = encode_request(id, req, &mut buf).map_err(|error| LinkError::Encode {
            request: request_name(req),
            error,
        })?;
        self.send_raw(buf.get(..n).unwrap_or(&[]))?;
        self.outstanding.insert(id);
        Ok(id)
    }

    /// Wait for the reply to request `id` (named `request` in a timeout message), at most
    /// [`Link::timeout`]. Replies to other requests in flight are kept; strays are skipped.
    pub fn wait_for(&mut self, id: u32, request: &'static str) -> Result<Response, LinkError> {
        let r = self.wait_matching(|i| i == id, request, id);
        if r.is_err() {
            self.outstanding.remove(&id);
        }
        r.map(|(_, resp)| resp)
    }

    /// The next reply of any id (a kept one first), at most [`Link::timeout`]: for callers that
    /// drive the protocol themselves.
    pub fn recv(&mut self) -> Result<(u32, Response), LinkError> {
        if let Some(r) = self.buffered.pop_front() {
            self.outstanding.remove(&r.0);
            return Ok(r);
        }
        let deadline = Instant::now() + self.timeout;
        let (id, resp) = self.read_frame(deadline, "any request", 0)?;
        self.outstanding.remove(&id);
        Ok((id, resp))
    }

    /// Send `req` and wait for its reply.
    pub fn call(&mut self, req: &Request<'_>) -> Result<Response, LinkError> {
        let id = self.send(req)?;
        self.wait_for(id, request_name(req))
    }

    /// Send `req` and expect `Ack`.
    fn call_ack(&mut self, req: &Request<'_>) -> Result<(), LinkError> {
        let request = request_name(req);
        match self.call(req)? {
            Response::Ack => Ok(()),
            other => Err(unexpected(request, other)),
        }
    }

    /// `Hello`: who the device is and what it can do. Fails with [`LinkError::Version`] if it
    /// speaks another protocol version.
    pub fn hello(&mut self) -> Result<DeviceInfo, LinkError> {
        match self.call(&Request::Hello)? {
            Response::Hello(info) => {
                if info.protocol_version != VERSION {
                    return Err(LinkError::Version {
                        device: info.protocol_version,
                        host: VERSION,
                    });
                }
                self.info = Some(info.clone());
                Ok(info)
            }
            other => Err(unexpected("Hello", other)),
        }
    }

    /// Upload `map`, run-length coded if that is shorter ([`MapCode::of`]), in chunks of at most
    /// [`MAX_CHUNK`] bytes (or the device's `max_chunk`, if smaller), [`UPLOAD_WINDOW`] in
    /// flight. The device has no map from the first chunk on; `map` becomes its map when the
    /// last chunk is acknowledged.
    pub fn set_map(&mut self, map: &Map) -> Result<(), LinkError> {
        self.upload(map.width, map.height, &MapCode::of(map))
    }

    /// [`Link::set_map`], calling `progress(bytes acknowledged, bytes in all)` after every chunk
    /// the device acknowledged (for a progress bar).
    pub fn set_map_with_progress(
        &mut self,
        map: &Map,
        progress: impl FnMut(usize, usize),
    ) -> Result<(), LinkError> {
        self.upload_with(map.width, map.height, &MapCode::of(map), progress)
    }

    /// [`Link::set_map`] from raw parts, always as `SetMap`: `bits` packed as [`ohaca::grid`]
    /// stores them (the device checks their length).
    pub fn set_map_bits(&mut self, width: u16, height: u16, bits: &[u8]) -> Result<(), LinkError> {
        self.upload(width, height, &MapCode::Raw(bits.to_vec()))
    }

    /// Upload a map coded as `code`: its chunks, [`UPLOAD_WINDOW`] in flight. The first device
    /// error ends the upload (the replies of the chunks behind it are awaited and dropped).
    pub fn upload(&mut self, width: u16, height: u16, code: &MapCode) -> Result<(), LinkError> {
        self.upload_with(width, height, code, |_, _| {})
    }

    /// [`Link::upload`] with a progress callback (see [`Link::set_map_with_progress`]).
    pub fn upload_with(
        &mut self,
        width: u16,
        height: u16,
        code: &MapCode,
        mut progress: impl FnMut(usize, usize),
    ) -> Result<(), LinkError> {
        let chunk = self
            .info
            .as_ref()
            .map_or(MAX_CHUNK, |i| usize::from(i.capacity.max_chunk))
            .clamp(1, MAX_CHUNK);
        let bytes = code.bytes();
        let mut in_flight: VecDeque<(u32, &'static str, usize)> = VecDeque::new();
        let mut first_error = None;
        let mut offset = 0usize;
        // An empty map (a zero side) still goes out once, as one zero byte, so the device says
        // what is wrong with it (`BadMap`; an empty chunk would be `TooLarge` 0 before that).
        loop {
            let end = (offset + chunk).min(bytes.len());
            let piece = match bytes.get(offset..end) {
                Some(p) if !p.is_empty() => p,
                _ => &[0u8][..],
            };
            let req = code.request(width, height, offset, piece);
            in_flight.push_back((self.send(&req)?, request_name(&req), end));
            offset = end;
            let last = offset >= bytes.len();
            while in_flight.len() >= UPLOAD_WINDOW
                || ((last || first_error.is_some()) && !in_flight.is_empty())
            {
                let (id, name, acked) = in_flight.pop_front().unwrap_or((0, "SetMap", 0));
                match self.wait_for(id, name)? {
                    Response::Ack => progress(acked, bytes.len()),
                    other => {
                        first_error.get_or_insert(unexpected(name, other));
                    }
                }
            }
            if let Some(e) = first_error {
                return Err(e);
            }
            if last {
                return Ok(());
            }
        }
    }

    /// `SetRect`: block (`blocked`) or clear the cells of a rectangle of the device's map (its
    /// running and queued plans are cancelled).
    pub fn set_rect(
        &mut self,
        (x, y): (u16, u16),
        (width, height): (u16, u16),
        blocked: bool,
    ) -> Result<(), LinkError> {
        self.call_ack(&Request::SetRect {
            x,
            y,
            width,
            height,
            blocked,
        })
    }

    /// `SetCells`: block or clear a list of cells, in requests of at most
    /// [`MAX_UPDATE_CELLS`] (each cancels the device's running and queued plans).
    pub fn set_cells(&mut self, cells: &[Point], blocked: bool) -> Result<(), LinkError> {
        for part in cells.chunks(MAX_UPDATE_CELLS) {
            self.call_ack(&Request::SetCells {
                blocked,
                cells: Waypoints::Points(part),
            })?;
        }
        Ok(())
    }

    /// `PlanWarm`: [`Link::plan`], asking the device to keep the colony of its previous plan to
    /// the same goal (a device may plan cold).
    pub fn plan_warm(
        &mut self,
        start: Point,
        goal: Point,
        seed: Option<u64>,
    ) -> Result<DevicePath, LinkError> {
        match self.call(&Request::PlanWarm { start, goal, seed })? {
            Response::Path(p) => Ok(p),
            other => Err(unexpected("PlanWarm", other)),
        }
    }

    /// `SetParams`: the parameters of every later plan.
    pub fn set_params(&mut self, params: &Params) -> Result<(), LinkError> {
        self.call_ack(&Request::SetParams(*params))
    }

    /// `Plan` on the active map; `seed` overrides the parameters' seed for this plan.
    pub fn plan(
        &mut self,
        start: Point,
        goal: Point,
        seed: Option<u64>,
    ) -> Result<DevicePath, LinkError> {
        match self.call(&Request::Plan { start, goal, seed })? {
            Response::Path(p) => Ok(p),
            other => Err(unexpected("Plan", other)),
        }
    }

    /// `Cancel`: stop the running plan and drop the queued ones (their replies, `Cancelled`,
    /// are kept for their callers, or become strays).
    pub fn cancel(&mut self) -> Result<(), LinkError> {
        self.call_ack(&Request::Cancel)
    }

    /// `Stats`: the device's counters.
    pub fn stats(&mut self) -> Result<StatsReply, LinkError> {
        match self.call(&Request::Stats)? {
            Response::Stats(s) => Ok(s),
            other => Err(unexpected("Stats", other)),
        }
    }

    /// Plan every job, pipelined: up to the device's `plan_queue` (from the last
    /// [`Link::hello`]; 1 without one) requests in flight. `each(index, outcome)` is called in
    /// job order as soon as an outcome and all before it are in. A device error for one job
    /// (`NoPath`, `GoalBlocked`, ...) is that job's outcome; a transport failure (timeout,
    /// disconnect, undecodable frame) ends the batch with an error. A plan refused with `Busy`
    /// (another client filling the queue) is sent again later. The timeout applies to each
    /// reply: the batch fails only if the device stays silent that long.
    pub fn plan_each(
        &mut self,
        jobs: &[PlanJob],
        mut each: impl FnMut(usize, PlanOutcome),
    ) -> Result<(), LinkError> {
        let window = self
            .info
            .as_ref()
            .map_or(1, |i| usize::from(i.capacity.plan_queue))
            .max(1);
        let mut next = 0usize;
        let mut retry: VecDeque<usize> = VecDeque::new();
        let mut inflight: HashMap<u32, (usize, Instant)> = HashMap::new();
        let mut done: BTreeMap<usize, PlanOutcome> = BTreeMap::new();
        let mut emitted = 0usize;
        let mut busy_since: Option<Instant> = None;
        while emitted < jobs.len() {
            while inflight.len() < window {
                let Some(i) = retry
                    .pop_front()
                    .or_else(|| (next < jobs.len()).then_some(next))
                else {
                    break;
                };
                if i == next {
                    next += 1;
                }
                let Some(job) = jobs.get(i) else { break };
                let id = self.send(&Request::Plan {
                    start: job.start,
                    goal: job.goal,
                    seed: job.seed,
                })?;
                inflight.insert(id, (i, Instant::now()));
            }
            if inflight.is_empty() {
                // Everything left was refused as Busy with nothing of ours in flight: the
                // queue is someone else's. Wait a little, give up after the timeout.
                let since = *busy_since.get_or_insert_with(Instant::now);
                if since.elapsed() > self.timeout {
                    return Err(LinkError::Device {
                        request: "Plan",
                        error: ErrorReply::new(ErrorCode::Busy),
                    });
                }
                std::thread::sleep(Duration::from_millis(20));
                continue;
            }
            let first = inflight.keys().min().copied().unwrap_or(0);
            let (id, resp) =
                match self.wait_matching(|id| inflight.contains_key(&id), "Plan", first) {
                    Ok(r) => r,
                    Err(e) => {
                        for id in inflight.keys() {
                            self.outstanding.remove(id);
                        }
                        return Err(e);
                    }
                };
            let Some((i, sent)) = inflight.remove(&id) else {
                continue;
            };
            let result = match resp {
                Response::Path(p) => Ok(p),
                Response::Error(e) if e.code == ErrorCode::Busy => {
                    retry.push_back(i);
                    continue;
                }
                Response::Error(e) => Err(e),
                other => return Err(unexpected("Plan", other)),
            };
            busy_since = None;
            done.insert(
                i,
                PlanOutcome {
                    id,
                    result,
                    round_trip: sent.elapsed(),
                },
            );
            while let Some(o) = done.remove(&emitted) {
                each(emitted, o);
                emitted += 1;
            }
        }
        Ok(())
    }

    /// [`Link::plan_each`], collected: one outcome per job, in job order.
    pub fn plan_many(&mut self, jobs: &[PlanJob]) -> Result<Vec<PlanOutcome>, LinkError> {
        let mut out = Vec::with_capacity(jobs.len());
        self.plan_each(jobs, |_, o| out.push(o))?;
        Ok(out)
    }

    /// Wait for a reply whose id satisfies `want` (kept replies first). `request` and `id`
    /// name what is awaited in a timeout message.
    fn wait_matching(
        &mut self,
        want: impl Fn(u32) -> bool,
        request: &'static str,
        id: u32,
    ) -> Result<(u32, Response), LinkError> {
        if let Some(pos) = self.buffered.iter().position(|(i, _)| want(*i)) {
            if let Some(r) = self.buffered.remove(pos) {
                self.outstanding.remove(&r.0);
                return Ok(r);
            }
        }
        let deadline = Instant::now() + self.timeout;
        loop {
            let (got, resp) = self.read_frame(deadline, request, id)?;
            if want(got) {
                self.outstanding.remove(&got);
                return Ok((got, resp));
            }
            if got != UNKNOWN_ID && self.outstanding.contains(&got) {
                self.buffered.push_back((got, resp));
            } else {
                self.stray_count += 1;
                if self.strays.len() >= MAX_STRAYS {
                    self.strays.remove(0);
                }
                self.strays.push(Stray::Reply {
                    id: got,
                    response: resp,
                });
            }
        }
    }

    /// The next complete frame from the wire, decoded, before `deadline`.
    fn read_frame(
        &mut self,
        deadline: Instant,
        request: &'static str,
        id: u32,
    ) -> Result<(u32, Response), LinkError> {
        loop {
            while self.rx_pos < self.rx_len {
                let Some(&b) = self.rx.get(self.rx_pos) else {
                    break;
                };
                self.rx_pos += 1;
                if let Some(frame) = self.reader.push(b).into_frame(MAX_REPLY_WIRE) {
                    let (got, reply) = frame.and_then(decode_reply).map_err(LinkError::Decode)?;
                    return Ok((got, Response::from(&reply)));
                }
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(LinkError::Timeout {
                    request,
                    id,
                    timeout: self.timeout,
                });
            }
            self.io
                .set_io_timeout(deadline - now)
                .map_err(LinkError::Io)?;
            match self.io.read(&mut self.rx) {
                Ok(0) => return Err(LinkError::Disconnected),
                Ok(n) => {
                    self.rx_pos = 0;
                    self.rx_len = n;
                }
                Err(e) if is_timeout(&e) => {}
                Err(e) if is_disconnect(&e) => return Err(LinkError::Disconnected),
                Err(e) => return Err(LinkError::Io(e)),
            }
        }
    }
}

fn unexpected(request: &'static str, got: Response) -> LinkError {
    match got {
        Response::Error(error) => LinkError::Device { request, error },
        other => LinkError::Unexpected {
            request,
            got: other.kind(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use ohaca::protocol::{decode_request, encode_reply, RequestReader, Waypoints};

    /// The fake device's script: the replies to one request.
    type Answer = dyn FnMut(u32, Request<'_>) -> Vec<(u32, Response)>;

    /// A fake device: answers requests written to it from a scripted function.
    struct Fake {
        input: RequestReader,
        out: VecDeque<u8>,
        answer: Box<Answer>,
        timeouts: u32,
    }

    fn encode(id: u32, r: &Response) -> Vec<u8> {
        let mut buf = vec![0u8; MAX_REPLY_WIRE];
        let (pts, hello);
        let reply = match r {
            Response::Hello(h) => {
                hello = h.clone();
                Reply::Hello(HelloReply {
                    protocol_version: hello.protocol_version,
                    firmware_version: &hello.firmware_version,
                    board: &hello.board,
                    capacity: hello.capacity,
                    defaults: hello.defaults,
                })
            }
            Response::Ack => Reply::Ack,
            Response::Path(p) => {
                pts = p.clone();
                Reply::Path(PathReply {
                    raw_length: pts.raw_length,
                    length: pts.length,
                    turns: pts.turns,
                    iterations: pts.iterations,
                    best_iteration: pts.best_iteration,
                    moves: pts.moves,
                    ticks: pts.ticks,
                    raw_cells: pts.raw_cells,
                    warm: pts.warm,
                    waypoints: Waypoints::Points(&pts.waypoints),
                    directions: &pts.directions,
                })
            }
            Response::Error(e) => Reply::Error(*e),
            Response::Stats(s) => Reply::Stats(*s),
        };
        let n = encode_reply(id, &reply, &mut buf).unwrap();
        buf.truncate(n);
        buf
    }

    impl Read for Fake {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            if self.out.is_empty() {
                self.timeouts += 1;
                return Err(io::Error::new(io::ErrorKind::TimedOut, "nothing"));
            }
            let n = buf.len().min(self.out.len()).min(7);
            for (slot, b) in buf.iter_mut().zip(self.out.drain(..n)) {
                *slot = b;
            }
            Ok(n)
        }
    }

    impl Write for Fake {
        fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
            for &b in buf {
                if let Some(Ok(f)) = self.input.push(b).into_frame(MAX_REQUEST_WIRE) {
                    let (id, req) = decode_request(f).unwrap();
                    for (rid, r) in (self.answer)(id, req) {
                        self.out.extend(encode(rid, &r));
                    }
                }
            }
            Ok(buf.len())
        }
        fn flush(&mut self) -> io::Result<()> {
            Ok(())
        }
    }

    impl Transport for Fake {
        fn set_io_timeout(&mut self, _: Duration) -> io::Result<()> {
            Ok(())
        }
    }

    fn fake(answer: impl FnMut(u32, Request<'_>) -> Vec<(u32, Response)> + 'static) -> Link<Fake> {
        Link::new(
            Fake {
                input: RequestReader::new(),
                out: VecDeque::new(),
                answer: Box::new(answer),
                timeouts: 0,
            },
            Duration::from_millis(50),
        )
        .unwrap()
    }

    fn info(queue: u8) -> DeviceInfo {
        DeviceInfo {
            protocol_version: VERSION,
            firmware_version: "0.1.0".into(),
            board: "fake".into(),
            capacity: Capacity {
                cells: 1024,
                max_side: 1024,
                max_steps: 1023,
                max_chunk: 100,
                max_request: 256,
                plan_queue: queue,
                tick_hz: 1_000_000,
            },
            defaults: Params::default(),
        }
    }

    fn path(seed: u64) -> DevicePath {
        DevicePath {
            raw_length: 1.0,
            length: 1.0,
            turns: 0,
            iterations: 1,
            best_iteration: 0,
            moves: seed,
            ticks: 5,
            raw_cells: 2,
            warm: false,
            waypoints: vec![Point::new(0, 0), Point::new(1, 0)],
            directions: vec![0],
        }
    }

    #[test]
    fn ids_increase_and_strays_are_skipped() {
        let mut link = fake(|id, req| match req {
            // A stray id-0 error and a reply to nobody before the real answer.
            Request::Hello => vec![
                (0, Response::Error(ErrorReply::new(ErrorCode::BadCrc))),
                (77, Response::Ack),
                (id, Response::Hello(info(4))),
            ],
            _ => vec![(id, Response::Ack)],
        });
        assert_eq!(link.next_id(), 1);
        let h = link.hello().unwrap();
        assert_eq!(h.board, "fake");
        assert_eq!(link.next_id(), 2);
        link.cancel().unwrap();
        assert_eq!(link.next_id(), 3);
        assert_eq!(link.stray_count(), 2);
        let s = link.take_strays();
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].to_string(), "reply 0: error 16 (bad CRC)");
        assert_eq!(s[1].to_string(), "reply 77: Ack");
    }

    #[test]
    fn timeouts_and_device_errors_are_typed() {
        let mut link = fake(|id, req| match req {
            Request::Stats => vec![],
            _ => vec![(
                id,
                Response::Error(ErrorReply::with(ErrorCode::MapTooLarge, 1600, 1024)),
            )],
        });
        let e = link.stats().unwrap_err();
        assert!(matches!(e, LinkError::Timeout { id: 1, .. }), "{e}");
        assert_eq!(e.to_string(), "no reply to Stats (request 1) within 0.05 s");
        let m = Map::from_fn(40, 40, |_, _| false);
        let e = link.set_map(&m).unwrap_err();
        assert_eq!(e.code(), Some(ErrorCode::MapTooLarge));
        assert_eq!(
            e.to_string(),
            "device refused SetMapRle: map too large (1600 over the limit 1024) (error code 2)"
        );
    }

    #[test]
    fn version_mismatch_is_refused() {
        let mut link = fake(|id, _| {
            let mut i = info(4);
            i.protocol_version = VERSION + 1;
            vec![(id, Response::Hello(i))]
        });
        assert!(matches!(link.hello(), Err(LinkError::Version { .. })));
    }

    #[test]
    fn maps_go_in_chunks_of_the_device() {
        let chunks = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
        let seen = chunks.clone();
        let mut link = fake(move |id, req| match req {
            Request::Hello => vec![(id, Response::Hello(info(4)))],
            Request::SetMap {
                offset,
                total_len,
                chunk,
                ..
            } => {
                seen.borrow_mut().push((offset, total_len, chunk.len()));
                vec![(id, Response::Ack)]
            }
            _ => vec![],
        });
        // Without a Hello: MAX_CHUNK. A checkerboard: its run-length code is longer, so raw.
        let m = Map::from_fn(32, 32, |x, y| (x + y) % 2 == 0);
        link.set_map(&m).unwrap();
        assert_eq!(*chunks.borrow(), vec![(0, 128, MAX_CHUNK)]);
        chunks.borrow_mut().clear();
        link.hello().unwrap();
        link.set_map(&m).unwrap();
        assert_eq!(*chunks.borrow(), vec![(0, 128, 100), (100, 128, 28)]);
    }

    /// A fake device that applies uploads and cell updates with the protocol's own state
    /// machine (`ohaca::protocol::Upload`), answering each chunk only when the next request
    /// arrives or the window would stall, so the link's window is exercised.
    #[test]
    fn maps_go_run_length_coded_when_shorter_and_arrive_whole() {
        use ohaca::protocol::{set_cells, set_rect, Encoding, MapChunk, MapLimits, Upload};
        use std::cell::RefCell;
        use std::rc::Rc;
        let limits = MapLimits {
            max_cells: 512 * 512,
            max_side: 512,
        };
        let state = Rc::new(RefCell::new((
            Upload::new(),
            vec![0u8; limits.bytes()],
            None::<(u16, u16)>,
            Vec::<&'static str>::new(),
        )));
        let st = state.clone();
        let mut link = fake(move |id, req| {
            let mut g = st.borrow_mut();
            let (up, buf, size, log) = &mut *g;
            log.push(request_name(&req));
            let chunk = match req {
                Request::SetMap {
                    width,
                    height,
                    offset,
                    total_len,
                    chunk,
                } => Some((Encoding::Raw, width, height, offset, total_len, chunk)),
                Request::SetMapRle {
                    width,
                    height,
                    offset,
                    total_len,
                    chunk,
                } => Some((Encoding::Rle, width, height, offset, total_len, chunk)),
                _ => None,
            };
            let r = if let Some((encoding, width, height, offset, total_len, chunk)) = chunk {
                let c = MapChunk {
                    encoding,
                    width,
                    height,
                    offset,
                    total_len,
                    chunk,
                };
                up.accept(&c, limits).and_then(|start| {
                    if start {
                        *size = None;
                    }
                    up.write(&c, buf).map(|done| {
                        if done.is_some() {
                            *size = done;
                        }
                    })
                })
            } else {
                match (req, *size) {
                    (
                        Request::SetRect {
                            x,
                            y,
                            width,
                            height,
                            blocked,
                        },
                        Some(sz),
                    ) => set_rect(sz, buf, (x, y, width, height), blocked),
                    (Request::SetCells { blocked, cells }, Some(sz)) => {
                        set_cells(sz, buf, &cells, blocked)
                    }
                    _ => Err(ErrorReply::new(ErrorCode::NoMap)),
                }
            };
            vec![(
                id,
                match r {
                    Ok(()) => Response::Ack,
                    Err(e) => Response::Error(e),
                },
            )]
        });
        // A 256x256 map of long runs: run-length coded, far fewer bytes than 8 KiB.
        let m = Map::from_fn(256, 256, |x, y| (x / 16 + y / 32) % 3 == 0 && y % 7 != 0);
        let code = MapCode::of(&m);
        assert!(matches!(code, MapCode::Rle(_)));
        assert!(
            code.bytes().len() < m.bits.len() / 2,
            "{}",
            code.bytes().len()
        );
        link.set_map(&m).unwrap();
        {
            let g = state.borrow();
            assert_eq!(g.2, Some((256, 256)));
            assert!(
                (0..65536).all(|i| (g.1[i / 8] >> (i % 8)) & 1 == (m.bits[i / 8] >> (i % 8)) & 1)
            );
            assert!(g.3.iter().all(|n| *n == "SetMapRle"));
            assert_eq!(g.3.len(), code.bytes().len().div_ceil(MAX_CHUNK));
        }
        // Cell updates change the device's map.
        link.set_rect((1, 1), (3, 2), true).unwrap();
        let many: Vec<Point> = (0..130).map(|i| Point::new(i, 200)).collect();
        link.set_cells(&many, true).unwrap();
        {
            let g = state.borrow();
            let at = |x: usize, y: usize| (g.1[(y * 256 + x) / 8] >> ((y * 256 + x) % 8)) & 1 == 1;
            assert!(at(1, 1) && at(3, 2) && at(129, 200));
            // 130 cells went as 60 + 60 + 10.
            assert_eq!(g.3.iter().filter(|n| **n == "SetCells").count(), 3);
        }
        let e = link.set_rect((250, 0), (10, 1), false).unwrap_err();
        assert_eq!(e.code(), Some(ErrorCode::OutsideMap));
        // A broken run-length code: the error of its chunk, and no stray afterwards.
        let bad = MapCode::Rle(vec![0xFF; 300]);
        let e = link.upload(16, 16, &bad).unwrap_err();
        assert_eq!(e.code(), Some(ErrorCode::BadRle), "{e}");
        assert_eq!(state.borrow().2, None);
        assert_eq!(link.stray_count(), 0);
        assert!(link.outstanding.is_empty());
    }

    #[test]
    fn plan_many_pipelines_and_keeps_order() {
        // The fake answers plans only once 3 are waiting (or the last job arrives), newest
        // first, and refuses goal x = 9 at once: the link must keep 3 in flight and still
        // return the outcomes in job order.
        let jobs: Vec<PlanJob> = (0..9)
            .map(|k| PlanJob {
                start: Point::new(0, 0),
                goal: Point::new(if k == 4 { 9 } else { 1 }, 0),
                seed: Some(k),
            })
            .collect();
        let mut link2 = {
            let mut waiting: Vec<(u32, Option<u64>)> = Vec::new();
            fake(move |id, req| match req {
                Request::Hello => vec![(id, Response::Hello(info(3)))],
                Request::Plan { seed, goal, .. } => {
                    if goal.x == 9 {
                        return vec![(
                            id,
                            Response::Error(ErrorReply::new(ErrorCode::GoalBlocked)),
                        )];
                    }
                    waiting.push((id, seed));
                    if waiting.len() < 3 && seed != Some(8) {
                        return vec![];
                    }
                    waiting
                        .drain(..)
                        .rev()
                        .map(|(i, s)| (i, Response::Path(path(s.unwrap_or(0)))))
                        .collect()
                }
                _ => vec![],
            })
        };
        link2.hello().unwrap();
        let out = link2.plan_many(&jobs).unwrap();
        assert_eq!(out.len(), 9);
        for (k, o) in out.iter().enumerate() {
            if k == 4 {
                assert_eq!(o.result.as_ref().unwrap_err().code, ErrorCode::GoalBlocked);
            } else {
                assert_eq!(o.result.as_ref().unwrap().moves, k as u64, "{k}");
            }
        }
        let ids: Vec<u32> = out.iter().map(|o| o.id).collect();
        let mut sorted = ids.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), 9, "distinct ids {ids:?}");
        assert_eq!(link2.stray_count(), 0);
    }

    #[test]
    fn busy_plans_are_sent_again() {
        let mut refused = 0;
        let mut link = fake(move |id, req| match req {
            Request::Hello => vec![(id, Response::Hello(info(2)))],
            Request::Plan { seed, .. } => {
                if seed == Some(1) && refused < 2 {
                    refused += 1;
                    return vec![(id, Response::Error(ErrorReply::with(ErrorCode::Busy, 2, 2)))];
                }
                vec![(id, Response::Path(path(seed.unwrap_or(0))))]
            }
            _ => vec![],
        });
        link.hello().unwrap();
        let jobs: Vec<PlanJob> = (0..3)
            .map(|k| PlanJob {
                start: Point::new(0, 0),
                goal: Point::new(1, 0),
                seed: Some(k),
            })
            .collect();
        let out = link.plan_many(&jobs).unwrap();
        let moves: Vec<u64> = out
            .iter()
            .map(|o| o.result.as_ref().unwrap().moves)
            .collect();
        assert_eq!(moves, vec![0, 1, 2]);
    }

    #[test]
    fn raw_paths_follow_the_directions() {
        let p = raw_path(Point::new(1, 1), &[0, 1, 2, 3, 4, 5, 6, 7]).unwrap();
        let xy: Vec<(u16, u16)> = p.iter().map(|p| (p.x, p.y)).collect();
        assert_eq!(
            xy,
            vec![
                (1, 1),
                (2, 1),
                (3, 2),
                (3, 3),
                (2, 4),
                (1, 4),
                (0, 3),
                (0, 2),
                (1, 1)
            ]
        );
        assert!(raw_path(Point::new(0, 0), &[8]).is_err());
        assert!(raw_path(Point::new(0, 0), &[4]).is_err());
    }
}

/// Upload sizes of real maps, raw against run-length coded, in bytes on the wire (frames
/// included) and seconds at 115200 baud: `cargo test --release -p ohaca-host --target
/// host-tuple --lib upload_sizes -- --ignored --nocapture` (needs `../shared/maps/large`).
#[cfg(test)]
mod upload_sizes {
    use super::*;
    use std::path::Path;

    /// Bytes on the wire of `code`'s upload: every frame, delimiters included, ids from 2.
    fn wire_bytes(w: u16, h: u16, code: &MapCode) -> (usize, usize) {
        let b = code.bytes();
        let mut total = 0;
        let mut frames = 0;
        let mut buf = [0u8; MAX_REQUEST_WIRE];
        for (k, c) in b.chunks(MAX_CHUNK).enumerate() {
            let req = code.request(w, h, k * MAX_CHUNK, c);
            total += encode_request(2 + k as u32, &req, &mut buf).unwrap();
            frames += 1;
        }
        (total, frames)
    }

    #[test]
    #[ignore = "prints upload sizes of the shared large maps and lab.yaml"]
    fn print_upload_sizes() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut maps: Vec<(String, Map)> = vec![];
        let lab = root.join("host/assets/ros/lab.yaml");
        let (m, _) = crate::map::prepare(&lab, Default::default(), Some(0.2), None).unwrap();
        maps.push(("lab.yaml (5 cm, inflated 0.2 m)".into(), m));
        let large = root.join("../shared/maps/large");
        let mut names: Vec<_> = std::fs::read_dir(&large)
            .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).collect())
            .unwrap_or_default();
        names.retain(|p| p.extension().is_some_and(|e| e == "map"));
        names.sort();
        for p in names {
            if let Ok(m) = Map::load(&p) {
                if m.width <= 512 && m.height <= 512 {
                    maps.push((p.file_name().unwrap().to_string_lossy().into(), m));
                }
            }
        }
        println!("| map | cells | packed | run-length code | on the wire (RLE) | frames | at 115200 baud | raw upload at 115200 |");
        println!("| --- | --- | --- | --- | --- | --- | --- | --- |");
        for (name, m) in maps {
            let cells = u32::from(m.width) * u32::from(m.height);
            let rle: Vec<u8> = RleEncoder::new(&m.bits, cells).collect();
            let (wr, fr) = wire_bytes(m.width, m.height, &MapCode::Rle(rle.clone()));
            let (ww, _) = wire_bytes(m.width, m.height, &MapCode::Raw(m.bits.clone()));
            println!(
                "| {name} | {}x{} | {} | {} ({:.1} %) | {wr} | {fr} | {:.2} s | {:.2} s |",
                m.width,
                m.height,
                m.bits.len(),
                rle.len(),
                100.0 * rle.len() as f64 / m.bits.len() as f64,
                wr as f64 / 11520.0,
                ww as f64 / 11520.0
            );
        }
    }
}
