//! What travels on the link, as the host holds it: a map upload's coding ([`MapCode`]), the
//! device's replies owned ([`Response`], [`DeviceInfo`], [`DevicePath`], the raw path from its
//! directions) and the names of requests for messages.

use super::*;

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
    pub(super) fn request<'a>(
        &self,
        width: u16,
        height: u16,
        offset: usize,
        chunk: &'a [u8],
    ) -> Request<'a> {
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
    /// Where the path comes from: cold, warm (`PlanWarm` kept the colony), or reused (the rest
    /// of the previous answer).
    pub origin: ohaca::planner::Origin,
    /// Waypoints, start first.
    pub waypoints: Vec<Point>,
    /// The raw path as directions from the start (`0..8` = E, SE, S, SW, W, NW, N, NE).
    pub directions: Vec<u8>,
}

impl DevicePath {
    /// The reply it came in, borrowing its points and directions (to encode it again).
    pub fn reply(&self) -> PathReply<'_> {
        PathReply {
            raw_length: self.raw_length,
            length: self.length,
            turns: self.turns,
            iterations: self.iterations,
            best_iteration: self.best_iteration,
            moves: self.moves,
            ticks: self.ticks,
            raw_cells: self.raw_cells,
            origin: self.origin,
            waypoints: Waypoints::Points(&self.waypoints),
            directions: &self.directions,
        }
    }
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
            origin: p.origin,
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
    /// [`Reply::PathPart`]: [`super::Link`] puts the parts of a path together and returns a
    /// [`Response::Path`]; a part is seen only by whoever reads frames one by one.
    Part(OwnedPart),
}

/// Puts the parts of long paths together ([`Reply::PathPart`], `docs/PROTOCOL.md`, "Long paths
/// in parts"), for whoever reads reply frames: [`super::Link`] and the tests' own readers.
#[derive(Debug, Default)]
pub struct Assembler {
    parts: HashMap<u32, Vec<u8>>,
}

impl Assembler {
    /// Take one decoded reply of request `id`: a whole reply comes back at once (and ends any
    /// parts of `id`: a path stopped by `Cancel` is answered `Cancelled` after some parts); a
    /// part is kept, and the last one gives back the whole [`Response::Path`]. A part out of
    /// order, too long or whose bytes do not decode is [`DecodeError::Undecodable`].
    pub fn push(&mut self, id: u32, resp: Response) -> Result<Option<Response>, DecodeError> {
        let Response::Part(part) = resp else {
            self.parts.remove(&id);
            return Ok(Some(resp));
        };
        let broken = DecodeError::Undecodable { id: Some(id) };
        let body = self.parts.entry(id).or_default();
        if usize::try_from(part.offset).ok() != Some(body.len())
            || body.len() + part.bytes.len() > MAX_REPLY
        {
            self.parts.remove(&id);
            return Err(broken);
        }
        body.extend_from_slice(&part.bytes);
        if !usize::try_from(part.total_len).is_ok_and(|t| body.len() >= t) {
            return Ok(None);
        }
        let body = self.parts.remove(&id).unwrap_or_default();
        let path = decode_path_body(&body).ok_or(broken)?;
        Ok(Some(Response::Path((&path).into())))
    }

    /// Requests with parts received and the rest to come.
    pub fn pending(&self) -> usize {
        self.parts.len()
    }
}

/// A [`ohaca::protocol::PathPart`], owned.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct OwnedPart {
    /// Where its bytes start in the path's body.
    pub offset: u32,
    /// The body's length.
    pub total_len: u32,
    /// Its bytes.
    pub bytes: Vec<u8>,
}

impl From<&Reply<'_>> for Response {
    fn from(r: &Reply<'_>) -> Self {
        match r {
            Reply::Hello(h) => Response::Hello(h.into()),
            Reply::Ack => Response::Ack,
            Reply::Path(p) => Response::Path(p.into()),
            Reply::Error(e) => Response::Error(*e),
            Reply::Stats(s) => Response::Stats(*s),
            Reply::PathPart(p) => Response::Part(OwnedPart {
                offset: p.offset,
                total_len: p.total_len,
                bytes: p.bytes.to_vec(),
            }),
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
            Response::Part(_) => "PathPart",
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
