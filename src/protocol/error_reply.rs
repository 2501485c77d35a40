//! Errors on the wire: [`ErrorReply`] and its one-byte [`ErrorCode`], and the one mapping between
//! them and the planner's [`Error`] (both ways, so a host gets back the error the device had).

use core::fmt;

use serde::{Deserialize, Serialize};

use crate::error::{Endpoint, Error, Param};

#[cfg(doc)] // the doc links
use super::{Request, UNKNOWN_ID};

/// Why a request failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ErrorReply {
    /// What went wrong.
    pub code: ErrorCode,
    /// A number that goes with the code (see [`ErrorCode`]), else 0.
    pub detail: u32,
    /// The limit `detail` broke (see [`ErrorCode`]), else 0.
    pub limit: u32,
}

impl ErrorReply {
    /// An error with no numbers.
    pub const fn new(code: ErrorCode) -> Self {
        ErrorReply {
            code,
            detail: 0,
            limit: 0,
        }
    }

    /// An error with its numbers.
    pub const fn with(code: ErrorCode, detail: u32, limit: u32) -> Self {
        ErrorReply {
            code,
            detail,
            limit,
        }
    }
}

/// The one mapping between the planner's errors and the wire: each [`Error`] is an [`ErrorCode`]
/// from 1 to 11 with its numbers (`MapTooLarge`: cells and capacity; `PathTooLong`: ants dropped
/// and the step limit; `BadParam`: the parameter's
/// [`Param`] index). [`TryFrom<ErrorReply>`](#impl-TryFrom%3CErrorReply%3E-for-Error) is its
/// inverse.
impl From<Error> for ErrorReply {
    fn from(e: Error) -> Self {
        match e {
            Error::BadMap => ErrorReply::new(ErrorCode::BadMap),
            Error::MapTooLarge { cells, capacity } => {
                ErrorReply::with(ErrorCode::MapTooLarge, cells, capacity)
            }
            Error::OutOfBounds(Endpoint::Start) => ErrorReply::new(ErrorCode::StartOutOfBounds),
            Error::OutOfBounds(Endpoint::Goal) => ErrorReply::new(ErrorCode::GoalOutOfBounds),
            Error::Blocked(Endpoint::Start) => ErrorReply::new(ErrorCode::StartBlocked),
            Error::Blocked(Endpoint::Goal) => ErrorReply::new(ErrorCode::GoalBlocked),
            Error::BadParam(p) => ErrorReply::with(ErrorCode::BadParam, p.index(), 0),
            Error::NoPath => ErrorReply::new(ErrorCode::NoPath),
            Error::Cancelled => ErrorReply::new(ErrorCode::Cancelled),
            Error::NoAntArrived => ErrorReply::new(ErrorCode::NoAntArrived),
            Error::PathTooLong { ants, limit } => {
                ErrorReply::with(ErrorCode::PathTooLong, ants, limit)
            }
        }
    }
}

/// The planner error a reply stands for (codes 1 to 11), so a host can show the core's own
/// message; the reply itself back when it is one of the protocol's own codes, or a `BadParam`
/// whose `detail` names no parameter.
impl TryFrom<ErrorReply> for Error {
    type Error = ErrorReply;

    fn try_from(r: ErrorReply) -> Result<Self, ErrorReply> {
        Ok(match r.code {
            ErrorCode::BadMap => Error::BadMap,
            ErrorCode::MapTooLarge => Error::MapTooLarge {
                cells: r.detail,
                capacity: r.limit,
            },
            ErrorCode::StartOutOfBounds => Error::OutOfBounds(Endpoint::Start),
            ErrorCode::GoalOutOfBounds => Error::OutOfBounds(Endpoint::Goal),
            ErrorCode::StartBlocked => Error::Blocked(Endpoint::Start),
            ErrorCode::GoalBlocked => Error::Blocked(Endpoint::Goal),
            ErrorCode::BadParam => Error::BadParam(Param::from_index(r.detail).ok_or(r)?),
            ErrorCode::NoPath => Error::NoPath,
            ErrorCode::Cancelled => Error::Cancelled,
            ErrorCode::NoAntArrived => Error::NoAntArrived,
            ErrorCode::PathTooLong => Error::PathTooLong {
                ants: r.detail,
                limit: r.limit,
            },
            ErrorCode::BadCrc
            | ErrorCode::Undecodable
            | ErrorCode::TooLarge
            | ErrorCode::NoMap
            | ErrorCode::Busy
            | ErrorCode::BadChunk
            | ErrorCode::BadRle
            | ErrorCode::OutsideMap
            | ErrorCode::Internal => return Err(r),
        })
    }
}

impl fmt::Display for ErrorReply {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.code)?;
        match self.code {
            ErrorCode::MapTooLarge => {
                // An upload's side over `max_side` (side, max_side) or its cells over `cells`
                // (cells, cells); a plan's map over the planner's capacity (cells, cells).
                write!(f, " ({} over the limit {})", self.detail, self.limit)
            }
            ErrorCode::TooLarge => write!(f, " ({} bytes, limit {})", self.detail, self.limit),
            ErrorCode::BadChunk => write!(
                f,
                " (expected offset <= {} of {} bytes)",
                self.detail, self.limit
            ),
            ErrorCode::Busy => write!(f, " ({} of {} queued)", self.detail, self.limit),
            ErrorCode::BadParam => write!(f, " (parameter #{})", self.detail),
            ErrorCode::BadRle => write!(f, " ({} of {} cells)", self.detail, self.limit),
            ErrorCode::OutsideMap => write!(f, " (cell {}, {})", self.detail, self.limit),
            ErrorCode::PathTooLong => write!(
                f,
                " ({} ants dropped, limit {} steps)",
                self.detail, self.limit
            ),
            _ => Ok(()),
        }
    }
}

/// Error codes on the wire (one byte). 1 to 11 are the planner's [`Error`]s (mapped by
/// `From<Error> for ErrorReply` and back by `TryFrom<ErrorReply> for Error`); 16 and up are the
/// protocol's own. `detail` / `limit` of the [`ErrorReply`] are given where they mean
/// something.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(into = "u8", try_from = "u8")]
#[repr(u8)]
pub enum ErrorCode {
    /// The map has a zero side or too few bytes.
    BadMap = 1,
    /// The map has more cells than the device holds: `detail` = cells, `limit` = capacity.
    MapTooLarge = 2,
    /// The start lies outside the map.
    StartOutOfBounds = 3,
    /// The goal lies outside the map.
    GoalOutOfBounds = 4,
    /// The start is an obstacle.
    StartBlocked = 5,
    /// The goal is an obstacle.
    GoalBlocked = 6,
    /// A parameter is out of range: `detail` = which ([`crate::error::Param`] order: ants 0,
    /// iterations 1, alpha 2, beta 3, rho 4, q 5, a 6, xi 7, tau 8).
    BadParam = 7,
    /// The goal cannot be reached.
    NoPath = 8,
    /// The plan was cancelled (by [`Request::Cancel`] or a new map).
    Cancelled = 9,
    /// The goal is reachable but no ant reached it (every ant died at a dead end with
    /// [`crate::DeadEnd::Die`]; ants dropped for long paths give [`ErrorCode::PathTooLong`]).
    NoAntArrived = 10,
    /// The goal is reachable but no ant reached it, and ants were dropped for paths longer than
    /// the device keeps: `detail` = ants dropped, `limit` = the longest path kept, in steps.
    PathTooLong = 11,
    /// The frame's CRC did not match (id: [`UNKNOWN_ID`]).
    BadCrc = 16,
    /// The frame was not valid COBS, or too short, or its message did not decode (id: the
    /// request's if it could be read, else [`UNKNOWN_ID`]).
    Undecodable = 17,
    /// A frame or chunk was too long: `detail` = its bytes, `limit` = the most allowed.
    TooLarge = 18,
    /// A plan was requested before any map was set.
    NoMap = 19,
    /// The plan queue is full: `detail` = plans waiting, `limit` = queue size.
    Busy = 20,
    /// A map chunk does not continue the upload: `detail` = bytes received so far, `limit` =
    /// the upload's `total_len` (0 when no upload is open).
    BadChunk = 21,
    /// The device could not build the reply (e.g. a path longer than the protocol's limits).
    Internal = 22,
    /// A run-length map code overruns the map or ends short of it: `detail` = cells decoded,
    /// `limit` = the map's cells. The upload is dropped.
    BadRle = 23,
    /// A cell update reaches outside the active map: `detail` = x, `limit` = y of the first cell
    /// outside.
    OutsideMap = 24,
}

impl ErrorCode {
    /// Every code, in numeric order.
    pub const ALL: [ErrorCode; 20] = [
        ErrorCode::BadMap,
        ErrorCode::MapTooLarge,
        ErrorCode::StartOutOfBounds,
        ErrorCode::GoalOutOfBounds,
        ErrorCode::StartBlocked,
        ErrorCode::GoalBlocked,
        ErrorCode::BadParam,
        ErrorCode::NoPath,
        ErrorCode::Cancelled,
        ErrorCode::NoAntArrived,
        ErrorCode::PathTooLong,
        ErrorCode::BadCrc,
        ErrorCode::Undecodable,
        ErrorCode::TooLarge,
        ErrorCode::NoMap,
        ErrorCode::Busy,
        ErrorCode::BadChunk,
        ErrorCode::Internal,
        ErrorCode::BadRle,
        ErrorCode::OutsideMap,
    ];

    /// The byte on the wire.
    pub const fn code(self) -> u8 {
        self as u8
    }

    /// The code with this byte.
    pub fn from_code(b: u8) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.code() == b)
    }

    /// A short description.
    pub const fn describe(self) -> &'static str {
        match self {
            ErrorCode::BadMap => "bad map",
            ErrorCode::MapTooLarge => "map too large",
            ErrorCode::StartOutOfBounds => "start is outside the map",
            ErrorCode::GoalOutOfBounds => "goal is outside the map",
            ErrorCode::StartBlocked => "start is on an obstacle",
            ErrorCode::GoalBlocked => "goal is on an obstacle",
            ErrorCode::BadParam => "bad parameter",
            ErrorCode::NoPath => "no path",
            ErrorCode::Cancelled => "cancelled",
            ErrorCode::NoAntArrived => "no ant reached the goal",
            ErrorCode::PathTooLong => "path longer than the device keeps",
            ErrorCode::BadCrc => "bad CRC",
            ErrorCode::Undecodable => "undecodable frame",
            ErrorCode::TooLarge => "too large",
            ErrorCode::NoMap => "no map set",
            ErrorCode::Busy => "busy: plan queue full",
            ErrorCode::BadChunk => "map chunk out of sequence",
            ErrorCode::Internal => "internal error",
            ErrorCode::BadRle => "bad run-length map code",
            ErrorCode::OutsideMap => "cell outside the map",
        }
    }
}

impl From<ErrorCode> for u8 {
    fn from(c: ErrorCode) -> u8 {
        c.code()
    }
}

impl TryFrom<u8> for ErrorCode {
    type Error = UnknownCode;
    fn try_from(b: u8) -> Result<Self, UnknownCode> {
        ErrorCode::from_code(b).ok_or(UnknownCode(b))
    }
}

impl fmt::Display for ErrorCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.describe())
    }
}

/// A byte that is no [`ErrorCode`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UnknownCode(pub u8);

impl fmt::Display for UnknownCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "unknown error code {}", self.0)
    }
}
