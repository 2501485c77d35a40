//! The planner's error enum: small, `Copy`, with `Display` and (behind the `defmt` feature)
//! `defmt::Format`. The wire protocol maps every value to an error code and back, in one place
//! (`ohaca::protocol::ErrorReply`); [`Param::index`] is the number it carries for a bad parameter.

use core::fmt;

/// Which end of a path a [`Error::OutOfBounds`] or [`Error::Blocked`] refers to.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Endpoint {
    /// The start cell.
    Start,
    /// The goal cell.
    Goal,
}

/// Which parameter a [`Error::BadParam`] rejects.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Param {
    /// `ants` must be at least 1.
    Ants,
    /// `iterations` must be at least 1.
    Iterations,
    /// `alpha` must be finite and in `[0, 16]`.
    Alpha,
    /// `beta` must be finite and in `[0, 16]`.
    Beta,
    /// `rho` must be in `(0, 1]`.
    Rho,
    /// `q` must be finite and `> 0`.
    Q,
    /// `a` (goal-attraction base) must be in `(0, 1]`.
    A,
    /// `xi` (potential-field gain) must be finite and `>= 0`.
    Xi,
    /// `tau0`, `tau_min`, `tau_max` must satisfy `0 < tau_min <= tau0 <= tau_max`, all finite.
    Tau,
}

/// Everything that can go wrong when planning.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Error {
    /// The grid has a zero side, or its bit buffer is shorter than `width * height` bits.
    BadMap,
    /// The map has more cells than the storage was sized for.
    MapTooLarge {
        /// Cells in the map.
        cells: u32,
        /// Cells the storage can hold.
        capacity: u32,
    },
    /// The start or goal lies outside the map.
    OutOfBounds(Endpoint),
    /// The start or goal is an obstacle cell.
    Blocked(Endpoint),
    /// A parameter is outside its valid range.
    BadParam(Param),
    /// The goal cannot be reached from the start (decided by a flood fill before any ant runs).
    NoPath,
    /// The goal is reachable, but no ant reached it: with [`crate::DeadEnd::Die`] every ant
    /// died at a dead end (or the run was finished before its first iteration).
    NoAntArrived,
    /// The goal is reachable, but no ant reached it and some ants were dropped because their
    /// paths grew longer than the workspace keeps (`Workspace::steps`; 4,095 steps on the
    /// STM32F411 and the default QEMU board, 2,047 on maps of up to 68,256 cells there, 16,384
    /// on the STM32H743): the way to the goal is longer than that (backtracking ants found no way
    /// within it), or the ants wandered that far.
    PathTooLong {
        /// Ants dropped over the run.
        ants: u32,
        /// The longest path the workspace keeps, in steps.
        limit: u32,
    },
    /// The run was cancelled before it finished.
    Cancelled,
}

impl Param {
    /// Every parameter, in index order ([`Param::index`]).
    pub const ALL: [Param; 9] = [
        Param::Ants,
        Param::Iterations,
        Param::Alpha,
        Param::Beta,
        Param::Rho,
        Param::Q,
        Param::A,
        Param::Xi,
        Param::Tau,
    ];

    /// A stable number (ants 0, iterations 1, ... tau 8: the declaration order), which the wire
    /// protocol carries.
    pub const fn index(self) -> u32 {
        self as u32
    }

    /// The parameter with this [`Param::index`].
    pub fn from_index(i: u32) -> Option<Param> {
        Param::ALL.into_iter().find(|p| p.index() == i)
    }
}

impl fmt::Display for Endpoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Endpoint::Start => "start",
            Endpoint::Goal => "goal",
        })
    }
}

impl fmt::Display for Param {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Param::Ants => "ants must be at least 1",
            Param::Iterations => "iterations must be at least 1",
            Param::Alpha => "alpha must be finite and in [0, 16]",
            Param::Beta => "beta must be finite and in [0, 16]",
            Param::Rho => "rho must be in (0, 1]",
            Param::Q => "q must be finite and > 0",
            Param::A => "a must be in (0, 1]",
            Param::Xi => "xi must be finite and >= 0",
            Param::Tau => "need 0 < tau_min <= tau0 <= tau_max, all finite",
        })
    }
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::BadMap => f.write_str("map has a zero side or too few cell bits"),
            Error::MapTooLarge { cells, capacity } => {
                write!(f, "map has {cells} cells, capacity is {capacity}")
            }
            Error::OutOfBounds(e) => write!(f, "{e} is outside the map"),
            Error::Blocked(e) => write!(f, "{e} is on an obstacle"),
            Error::BadParam(p) => write!(f, "bad parameter: {p}"),
            Error::NoPath => f.write_str("no path: the goal is not reachable from the start"),
            Error::Cancelled => f.write_str("cancelled"),
            Error::NoAntArrived => {
                f.write_str("no ant reached the goal (every ant died at a dead end)")
            }
            Error::PathTooLong { ants, limit } => write!(
                f,
                "no ant reached the goal within {limit} steps ({ants} ants dropped: the path is \
                 longer than the planner keeps)"
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn param_indices_are_the_declaration_order() {
        for (i, p) in Param::ALL.into_iter().enumerate() {
            assert_eq!(p.index() as usize, i, "{p:?}");
            assert_eq!(Param::from_index(p.index()), Some(p));
        }
        assert_eq!(Param::from_index(9), None);
    }
}
