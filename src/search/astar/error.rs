//! What can stop an exact A* search ([`AstarError`]), and which end a bad cell is ([`End`]).
//! Small `Copy` values with a `Display`; nothing here panics.

use core::fmt;

use super::MAX_LENGTH;

/// Which end of the search an [`AstarError::BadCell`] refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum End {
    /// The start cell.
    Start,
    /// The goal cell.
    Goal,
}

/// Everything that can stop a search.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AstarError {
    /// The goal is not reachable from the start.
    NoPath,
    /// The goal was not reached within [`MAX_LENGTH`]; it may be reachable by a longer path.
    TooFar,
    /// The start or goal is outside the map or blocked.
    BadCell(End),
    /// The per-cell slice is shorter than the map needs, or the map has more than
    /// [`MAX_CELLS`] cells.
    StorageTooSmall {
        /// Elements needed (bytes for [`search`], words for [`search_costs`]).
        needed: usize,
        /// Elements given.
        got: usize,
    },
    /// The open list outgrew its slice (`capacity` entries).
    HeapFull {
        /// Entries the slice holds.
        capacity: usize,
    },
    /// The path's cells do not fit the output slice.
    PathTooLong {
        /// Cells on the path.
        cells: usize,
        /// Cells the slice holds.
        capacity: usize,
    },
    /// The per-cell storage does not hold a path from the start to the goal (not the storage of
    /// a successful search on this map).
    NoTree,
}

impl fmt::Display for AstarError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            AstarError::NoPath => f.write_str("no path: the goal is not reachable from the start"),
            AstarError::TooFar => write!(f, "no path of length {MAX_LENGTH} or less"),
            AstarError::BadCell(End::Start) => f.write_str("start is off the map or blocked"),
            AstarError::BadCell(End::Goal) => f.write_str("goal is off the map or blocked"),
            AstarError::StorageTooSmall { needed, got } => {
                write!(f, "per-cell storage: {needed} needed, {got} given")
            }
            AstarError::HeapFull { capacity } => {
                write!(f, "open list full at {capacity} entries")
            }
            AstarError::PathTooLong { cells, capacity } => {
                write!(f, "path has {cells} cells, the slice holds {capacity}")
            }
            AstarError::NoTree => f.write_str("no path from the start to the goal in the storage"),
        }
    }
}
