//! The messages: what a host asks ([`Request`]) and what a device answers ([`Reply`] and the
//! reply bodies). Their byte layout is postcard's encoding of these types, so a field's order and
//! type are part of the protocol ([`VERSION`]); `docs/PROTOCOL.md` specifies every message.

use serde::{Deserialize, Serialize};

use crate::map::grid::Point;
use crate::planner::{Origin, Params};

use super::wire::PointDef;
#[cfg(doc)] // the doc links
use super::{
    ErrorCode, RleEncoder, MAX_CHUNK, MAX_DIRECTIONS, MAX_REPLY, MAX_REQUEST, MAX_STEPS,
    MAX_UPDATE_CELLS, MAX_WAYPOINTS, PART_BYTES, VERSION,
};
use super::{ErrorReply, PathPart, Waypoints};

/// Host to device.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Request<'a> {
    /// `0`: who are you? Answered with [`Reply::Hello`].
    Hello,
    /// `1`: one chunk of a map upload, answered with [`Reply::Ack`]. The map is `width x
    /// height` cells, bit-packed exactly as [`crate::map::grid`] stores it (row-major, LSB first,
    /// `1` = blocked), `total_len = ceil(width * height / 8)` bytes, sent as chunks of at most
    /// [`MAX_CHUNK`] bytes. A chunk with `offset` 0 starts an upload; every further chunk must
    /// have the same `width`, `height` and `total_len`, and `offset <=` the bytes received so far
    /// (re-sending a chunk is allowed). The new map becomes active when the last byte arrives;
    /// until then the previous map stays in force.
    SetMap {
        /// Columns.
        width: u16,
        /// Rows.
        height: u16,
        /// Byte offset of `chunk` in the packed map.
        offset: u32,
        /// Bytes of the whole packed map.
        total_len: u32,
        /// The bytes.
        chunk: &'a [u8],
    },
    /// `2`: the planner parameters for every later [`Request::Plan`], answered with
    /// [`Reply::Ack`] (or [`ErrorCode::BadParam`], and the old parameters stay).
    SetParams(Params),
    /// `3`: plan a path on the active map with the active parameters, answered with
    /// [`Reply::Path`] or [`Reply::Error`].
    Plan {
        /// Start cell.
        #[serde(with = "PointDef")]
        start: Point,
        /// Goal cell.
        #[serde(with = "PointDef")]
        goal: Point,
        /// Overrides the parameters' seed for this plan only.
        seed: Option<u64>,
    },
    /// `4`: stop the running plan and drop the queued ones (each answered with
    /// [`ErrorCode::Cancelled`]); answered with [`Reply::Ack`].
    Cancel,
    /// `5`: counters, answered with [`Reply::Stats`].
    Stats,
    /// `6`: one chunk of a run-length coded map upload (see [`RleEncoder`]): the same fields
    /// and rules as [`Request::SetMap`], but `offset` and `total_len` count bytes of the code.
    SetMapRle {
        /// Columns.
        width: u16,
        /// Rows.
        height: u16,
        /// Byte offset of `chunk` in the code.
        offset: u32,
        /// Bytes of the whole code.
        total_len: u32,
        /// The bytes.
        chunk: &'a [u8],
    },
    /// `7`: block (`blocked`) or clear every cell of a rectangle of the active map, answered
    /// with [`Reply::Ack`] (or `NoMap`, `OutsideMap`: nothing changes). Cancels the running and
    /// queued plans, as a new map does.
    SetRect {
        /// Left column.
        x: u16,
        /// Top row.
        y: u16,
        /// Columns.
        width: u16,
        /// Rows.
        height: u16,
        /// Block (true) or clear (false).
        blocked: bool,
    },
    /// `8`: block or clear a list of at most [`MAX_UPDATE_CELLS`] cells, 4 bytes each on the
    /// wire as [`PathReply::waypoints`]; answered and cancelling like [`Request::SetRect`] (and
    /// `TooLarge` for a longer list).
    SetCells {
        /// Block (true) or clear (false).
        blocked: bool,
        /// The cells.
        #[serde(borrow)]
        cells: Waypoints<'a>,
    },
    /// `9`: as [`Request::Plan`], asking for a warm start: keep the colony (pheromone) of the
    /// previous plan to the same goal on this map, across cell updates (the firmware does when
    /// its last started plan was to this goal on a map of this size, see `docs/PROTOCOL.md`;
    /// else it plans cold), or answers with the rest of the last answer when no change since can
    /// block or shorten it (`ohaca::planner::reuse`). [`PathReply::origin`] says which; the path
    /// is valid either way.
    PlanWarm {
        /// Start cell (the robot's cell now).
        #[serde(with = "PointDef")]
        start: Point,
        /// Goal cell.
        #[serde(with = "PointDef")]
        goal: Point,
        /// Overrides the parameters' seed for this plan only.
        seed: Option<u64>,
    },
}

/// Device to host.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub enum Reply<'a> {
    /// `0`: answer to [`Request::Hello`].
    Hello(#[serde(borrow)] HelloReply<'a>),
    /// `1`: the request was carried out.
    Ack,
    /// `2`: a planned path.
    Path(#[serde(borrow)] PathReply<'a>),
    /// `3`: the request failed.
    Error(ErrorReply),
    /// `4`: answer to [`Request::Stats`].
    Stats(StatsReply),
    /// `5`: one part of a planned path too long for one frame (its body is longer than
    /// [`PART_BYTES`]): the parts, in order, carry the bytes a [`Reply::Path`] would after its
    /// id and variant; other replies may come between them (`docs/PROTOCOL.md`, "Long paths").
    PathPart(#[serde(borrow)] PathPart<'a>),
}

/// What the device is and can do.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct HelloReply<'a> {
    /// [`VERSION`] of the device's protocol.
    pub protocol_version: u16,
    /// The firmware's version (its crate version).
    pub firmware_version: &'a str,
    /// Board name, e.g. `qemu-mps2-an386`.
    pub board: &'a str,
    /// Limits.
    pub capacity: Capacity,
    /// The parameters in force until a [`Request::SetParams`].
    pub defaults: Params,
}

/// The device's limits.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Capacity {
    /// Most cells (`width * height`) of a map the device holds and plans on, whatever its
    /// shape: an upload of more cells gets `MapTooLarge` (detail = cells, limit = `cells`).
    pub cells: u32,
    /// Longest side of a map the device takes, in cells (an upload with a longer side gets
    /// `MapTooLarge`, detail = the side, limit = `max_side`).
    pub max_side: u16,
    /// Longest ant path the planner keeps, in steps: a way longer than this gets
    /// `Error PathTooLong`. At most [`MAX_STEPS`], so every path the device plans fits one
    /// [`PathReply`] of at most [`MAX_REPLY`] bytes.
    pub max_steps: u32,
    /// Most bytes per [`Request::SetMap`] chunk.
    pub max_chunk: u16,
    /// Largest request payload accepted ([`MAX_REQUEST`] or less).
    pub max_request: u16,
    /// Plan requests that can wait while one runs; one more gets [`ErrorCode::Busy`].
    pub plan_queue: u8,
    /// Ticks per second of [`PathReply::ticks`] and [`StatsReply::uptime`].
    pub tick_hz: u32,
    /// Requests a host may have outstanding (sent, and not answered in full) at once: within
    /// `window` requests and `window_bytes` bytes nothing is lost, at any baud rate.
    pub window: u8,
    /// Bytes of request frames a host may have outstanding at once (the device's receive
    /// buffer): see `window`.
    pub window_bytes: u16,
}

/// A planned path: the planner's [`crate::Plan`] plus the time it took.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PathReply<'a> {
    /// Length of the raw 8-connected path, in cells.
    pub raw_length: f32,
    /// Length through the waypoints (smoothed for OHACA).
    pub length: f32,
    /// Turns along the waypoints.
    pub turns: u32,
    /// Iterations run.
    pub iterations: u16,
    /// Iteration (0-based) in which the best path was found.
    pub best_iteration: u16,
    /// Ant moves over the whole run.
    pub moves: u64,
    /// Ticks ([`Capacity::tick_hz`]) from accepting the plan to finishing it, on the device.
    pub ticks: u64,
    /// Cells of the raw path (`directions.len() + 1` unless the directions were cut short).
    pub raw_cells: u32,
    /// Where the path comes from, one byte: `0` cold (a colony run from scratch), `1` warm (a
    /// `PlanWarm` that kept the previous plan's colony), `2` reused (a `PlanWarm` answered with
    /// the rest of the previous answer, no colony run: [`crate::planner::reuse`]). Protocol 8's
    /// `warm` flag, as a byte that says more: `0` and `1` are its bytes.
    pub origin: Origin,
    /// Waypoints, start first, goal last. At most [`MAX_WAYPOINTS`].
    #[serde(borrow)]
    pub waypoints: Waypoints<'a>,
    /// The raw path from the start as one direction per step (`0..8` = E, SE, S, SW, W, NW, N,
    /// NE; see [`crate::map::grid::DX`]). At most [`MAX_DIRECTIONS`].
    pub directions: &'a [u8],
}

/// Counters since boot.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct StatsReply {
    /// Ticks ([`Capacity::tick_hz`]) since boot.
    pub uptime: u64,
    /// Boots since power-on (1 after a cold start; counts resets that keep RAM).
    pub boots: u32,
    /// Frames received that decoded.
    pub frames_ok: u32,
    /// Frames received that did not (bad CRC, bad COBS, undecodable, too long).
    pub frames_bad: u32,
    /// Received bytes lost because the receive buffer was full, plus UART overrun events.
    pub rx_overruns: u32,
    /// Bytes received.
    pub rx_bytes: u32,
    /// Frames sent (this reply not counted).
    pub tx_frames: u32,
    /// Plans answered with a path.
    pub plans: u32,
    /// Plans answered with a planner error (every [`ErrorCode`] below 16 but `Cancelled`).
    pub plan_errors: u32,
    /// Plans cancelled.
    pub cancelled: u32,
    /// Plans refused with [`ErrorCode::Busy`].
    pub busy: u32,
    /// Ticks of the last plan answered with a path.
    pub last_plan_ticks: u64,
    /// Active map's width (0: no map yet).
    pub map_width: u16,
    /// Active map's height (0: no map yet).
    pub map_height: u16,
    /// Plans waiting in the queue.
    pub queued: u8,
    /// True while a plan runs.
    pub planning: bool,
    /// Most stack the device has used since boot, in bytes (its high-water mark, interrupts
    /// included; 0 if the device does not measure it).
    pub stack_peak: u32,
    /// Replies not sent because the reply queue was full (a host beyond its window).
    pub replies_dropped: u32,
    /// Path replies sent in parts ([`Reply::PathPart`]).
    pub parted: u32,
}
